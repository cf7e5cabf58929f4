//! The thread family (`scripts/thread.rhai`): standard threads named as
//! drawings name them, each default run verified by simulating its program
//! pass by pass, its figures held against the standards' dimensions and
//! against a gauge's arithmetic done here.

use crate::common::{self, pilgrim, s, scratch, word};
use std::path::PathBuf;

const SCRIPT: &str = "scripts/thread.rhai";

/// The thread run into a fresh directory `name` with `args`, succeeding:
/// the run's directory.
fn run(name: &str, args: &[&str]) -> PathBuf {
    let out = scratch("thread", name).join("out");
    let mut all = vec!["run", SCRIPT, "--out", s(&out), "--quiet"];
    all.extend(args);
    let (code, _, err) = pilgrim(&all);
    assert_eq!(code, 0, "{name}: {err}");
    out
}

/// The default tool table copied into `dir`, beside a copy of the script
/// that reads it there.
fn copy_tools(dir: &std::path::Path) {
    let table = "scripts/thread-tools.csv";
    std::fs::copy(common::root().join(table), dir.join("thread-tools.csv")).unwrap();
}

/// The built-in lathe with a LinuxCNC control, written into `dir`: its
/// file.
fn linuxcnc_lathe(dir: &std::path::Path) -> PathBuf {
    let (code, toml, err) = pilgrim(&["machines", "--toml", "fanuc-0i-tc"]);
    assert_eq!(code, 0, "{err}");
    assert!(toml.contains("control = \"fanuc\""), "{toml}");
    let machine = dir.join("lathe.toml");
    std::fs::write(&machine, crate::common::with_control(&toml, "linuxcnc")).unwrap();
    machine
}

/// What a standard prints for a thread (mm): its pitch diameter's, its
/// crest's and its root's limits, and its flanks (deg).
struct Printed {
    pitch_diameter: [f64; 2],
    crest: [f64; 2],
    root: [f64; 2],
    flanks: [f64; 2],
}

const INCH: f64 = 25.4;

/// Each default run: the default M20x2.5-6g and the examples' M30x2-6H
/// nut (cut from inside its bore), Tr 40x7, 1"-5 ACME 2G, 2"-8 7/45
/// buttress and the pipe thread G 1/2 A. Their limits are the standards'
/// printed dimensions (ISO 965-2's M20 6g, ASME B1.5's 1-5 2G, ISO
/// 228-1's G 1/2 A) or the drawing's
/// stated ones; the run passes; each start's pitch diameter, as the gauge
/// takes it on the simulated section, lies within its limits and within
/// 5 um of the band's middle the cut aims at; the root and the crest are
/// within theirs; the flanks stand at the standard's angles; and the
/// measurement over wires is what a gauge's arithmetic gives for the pitch
/// diameter measured, the wire the best size (P / 2 / cos a).
#[test]
fn each_default_thread_is_verified_against_its_standard() {
    let cases: [(&str, Option<&str>, Printed); 6] = [
        (
            "m20",
            None,
            Printed {
                pitch_diameter: [18.164, 18.334],
                crest: [19.623, 19.958],
                root: [16.721, 16.891],
                flanks: [30.0, 30.0],
            },
        ),
        (
            // ISO 965-2 prints the nut's least major diameter only: the
            // most is left unchecked here (NaN).
            "m30-nut",
            Some("scripts/examples/thread-m30x2-6h.toml"),
            Printed {
                pitch_diameter: [28.701, 28.925],
                crest: [27.835, 28.210],
                root: [30.0, f64::NAN],
                flanks: [30.0, 30.0],
            },
        ),
        (
            "tr40x7",
            Some("scripts/examples/thread-tr40x7.toml"),
            Printed {
                pitch_diameter: [36.2, 36.4],
                crest: [39.6, 39.9],
                root: [31.4, 31.9],
                flanks: [15.0, 15.0],
            },
        ),
        (
            "acme",
            Some("scripts/examples/thread-acme-1-5.toml"),
            Printed {
                pitch_diameter: [0.8726 * INCH, 0.8920 * INCH],
                crest: [0.9900 * INCH, 1.0000 * INCH],
                root: [0.7509 * INCH, 0.7800 * INCH],
                flanks: [14.5, 14.5],
            },
        ),
        (
            "buttress",
            Some("scripts/examples/thread-buttress-2-8.toml"),
            // B1.9's form: E = D - 0.6 P, the external thread's depth
            // 0.66271 P; the load flank (7 deg) on the space's +Z side.
            Printed {
                pitch_diameter: [
                    2.0 * INCH - 0.6 * INCH / 8.0 - 0.2,
                    2.0 * INCH - 0.6 * INCH / 8.0,
                ],
                crest: [2.0 * INCH - 0.3, 2.0 * INCH],
                root: [
                    2.0 * INCH - 2.0 * 0.66271 * INCH / 8.0 - 0.5,
                    2.0 * INCH - 2.0 * 0.66271 * INCH / 8.0,
                ],
                flanks: [45.0, 7.0],
            },
        ),
        (
            // ISO 228-1's G 1/2 A; the root's least is d1 less class A's
            // band (the standard prints d1 and TD2 only).
            "g1-2a",
            Some("scripts/examples/thread-g1-2a.toml"),
            Printed {
                pitch_diameter: [19.651, 19.793],
                crest: [20.671, 20.955],
                root: [18.631 - 0.142, 18.631],
                flanks: [27.5, 27.5],
            },
        ),
    ];
    for (name, file, printed) in cases {
        let args: Vec<&str> = file.map(|f| vec!["--params", f]).unwrap_or_default();
        let out = run(name, &args);
        let r = common::report_of(&out);
        assert_eq!(r["verdict"]["status"], "passed", "{name}: {}", r["verdict"]);
        let v = &r["thread_verification"];
        let l = &v["limits"];
        let band = |k: &str| [l[k]["min"].as_f64().unwrap(), l[k]["max"].as_f64().unwrap()];
        // The standards print to 0.001 mm or 0.0001 in.
        // ISO 228-1 subtracts its depth rounded to 0.001 twice for d1.
        let printed_to = match name {
            "acme" => 0.00005 * INCH,
            "g1-2a" => 0.001,
            _ => 0.0005,
        };
        for (k, want) in [
            ("pitch_diameter", printed.pitch_diameter),
            ("crest", printed.crest),
            ("root", printed.root),
        ] {
            let got = band(k);
            assert!(
                (got[0] - want[0]).abs() <= printed_to
                    && (want[1].is_nan() || (got[1] - want[1]).abs() <= printed_to),
                "{name}: {k} {got:?}, printed {want:?}"
            );
        }
        let pd = band("pitch_diameter");
        for st in v["starts"].as_array().unwrap() {
            let f = |k: &str| st[k].as_f64().unwrap();
            let d2 = f("pitch_diameter");
            assert!(pd[0] < d2 && d2 < pd[1], "{name}: {d2} outside {pd:?}");
            let aim = 0.5 * (pd[0] + pd[1]);
            assert!((d2 - aim).abs() < 0.005, "{name}: {d2} vs the aim {aim}");
            // The GO gauge goes on: the functional pitch diameter within
            // the maximum-material limit (a bolt's greatest, a nut's
            // least), beyond the simple one by what the flanks and the
            // lead add (a few micrometres on a cut this true).
            let functional = f("functional_pitch_diameter");
            let (go, sign) = if v["internal"] == true {
                (pd[0], -1.0)
            } else {
                (pd[1], 1.0)
            };
            assert!(
                sign * (go - functional) > 0.0,
                "{name}: functional {functional}"
            );
            let over = sign * (functional - d2);
            assert!(
                (-1e-3..0.01).contains(&over),
                "{name}: functional {functional}, simple {d2}"
            );
            for (k, lim) in [
                ("root_diameter", band("root")),
                ("tip_diameter", band("crest")),
            ] {
                assert!(
                    lim[0] <= f(k) && f(k) <= lim[1],
                    "{name}: {k} {} outside {lim:?}",
                    f(k)
                );
            }
            for (k, want) in [
                ("left_angle_deg", printed.flanks[0]),
                ("right_angle_deg", printed.flanks[1]),
            ] {
                // The pipe thread's flank is measured over 0.5 mm between
                // its rounded root and crest: 0.1 degree there is under a
                // micrometre, the form the run holds to 10 um.
                let angle_tol = if name == "g1-2a" { 0.1 } else { 0.05 };
                assert!((f(k) - want).abs() < angle_tol, "{name}: {k} {}", f(k));
            }
            if printed.flanks[0] == printed.flanks[1] {
                // A gauge's arithmetic (ASME B1.2): over wires M = d2 +
                // w (1 + 1 / sin a) - (P / 2) / tan a, plus the lead angle's
                // (w / 2) tan^2(lambda) cos a cot a; a nut's between balls
                // the same terms taken from d2.
                let a = printed.flanks[0].to_radians();
                let p = r["notes"]["pitch_mm"].as_f64().unwrap();
                let lead = r["notes"]["lead_mm"].as_f64().unwrap();
                let w = p / 2.0 / a.cos();
                assert!((v["wire"].as_f64().unwrap() - w).abs() < 1e-9, "{name}");
                let sign = if v["internal"] == true { -1.0 } else { 1.0 };
                let tan_lead = lead / (std::f64::consts::PI * d2);
                let lead_term = 0.5 * w * tan_lead.powi(2) * a.cos() / a.tan();
                let m = d2 + sign * (w * (1.0 + 1.0 / a.sin()) - p / 2.0 / a.tan() + lead_term);
                // The formula is the first term of a series: the wire's
                // exact rest differs from it by a fraction of a micrometre.
                assert!(
                    (f("over_wires") - m).abs() < 0.5e-3,
                    "{name}: M {} vs {m}",
                    f("over_wires")
                );
                let ml = v["over_wires_limits"].as_array().unwrap();
                assert!(
                    ml[0].as_f64().unwrap() < f("over_wires")
                        && f("over_wires") < ml[1].as_f64().unwrap()
                );
            } else {
                // Unequal flanks (a buttress): the wire whose contacts
                // straddle the pitch line equally (0.5112 P at 7 and 45
                // degrees), resting within what the limits allow.
                let p = r["notes"]["pitch_mm"].as_f64().unwrap();
                let [l, rt] = printed.flanks.map(f64::to_radians);
                let k =
                    0.5 * (l.cos() + rt.cos()) - 0.25 * (rt.sin() - l.sin()) * (l.tan() - rt.tan());
                let w = v["wire"].as_f64().unwrap();
                assert!((w - p / 2.0 / k).abs() < 1e-9, "{name}: wire {w}");
                let ml = v["over_wires_limits"].as_array().unwrap();
                assert!(
                    ml[0].as_f64().unwrap() < f("over_wires")
                        && f("over_wires") < ml[1].as_f64().unwrap(),
                    "{name}: {ml:?}"
                );
            }
        }
        if name == "m30-nut" {
            // On the boring bar, the tailstock away: the bar clear of the
            // nut along the whole program, no holder or tailstock.
            let pairs = r["collisions"]["clearances"].as_array().unwrap();
            let pair = |a: &str, b: &str| {
                pairs
                    .iter()
                    .find(|c| c["bodies"][0] == a && c["bodies"][1] == b)
            };
            let bar = pair("boring_bar", "thread").expect("the bar and the nut are checked");
            assert!(bar["clearance_mm"].as_f64().unwrap() > 0.5, "{bar}");
            assert!(pairs
                .iter()
                .all(|c| !c["bodies"].to_string().contains("holder")
                    && !c["bodies"].to_string().contains("tailstock")));
            assert!(out.join("thread.step").is_file() && out.join("boring_bar.stl").is_file());
        }
        crate::worm::check_workbook(&out);
        // The STL, the scene and the page for CI's FreeCAD, glTF
        // validator and headless Chromium.
        common::leave_for_checkers(&out, &format!("thread-{name}"));
        common::check_page(&out, "program.nc", 12.0);
        common::leave_page_for_chromium(&out, &format!("thread-{name}"));
        for f in [
            "passes.csv",
            "passes.svg",
            "chip_area.svg",
            "program.nc",
            "thread.stl",
            "report.html",
        ] {
            assert!(out.join(f).is_file(), "{name}: {f}");
        }
    }
}

/// A buttress cut with its roughing passes on the load flank: `auto` takes
/// the steeper flank (the space's +Z side, 7 deg, when the load is taken
/// towards the chuck), the open 45 deg flank taking the chip; with the
/// load the other way, the other flank.
#[test]
fn a_buttress_is_roughed_along_its_load_flank() {
    for (load, side) in [("chuck", "right"), ("tailstock", "left")] {
        let out = run(
            &format!("buttress-{load}"),
            &[
                "--params",
                "scripts/examples/thread-buttress-2-8.toml",
                "--set",
                &format!("load={load}"),
            ],
        );
        let r = common::report_of(&out);
        let flanks = r["tables"]["passes"]["flank"].as_array().unwrap();
        let kinds = r["tables"]["passes"]["kind"].as_array().unwrap();
        let want = if side == "right" { 1.0 } else { -1.0 };
        for (f, k) in flanks.iter().zip(kinds) {
            if k.as_f64() == Some(0.0) {
                assert_eq!(
                    f.as_f64(),
                    Some(want),
                    "{load}: a roughing pass off the load flank"
                );
            }
        }
        let nominal = r["thread_verification"]["nominal_flanks_deg"]
            .as_array()
            .unwrap();
        let seven = if side == "right" { 1 } else { 0 };
        assert_eq!(nominal[seven].as_f64().unwrap().round(), 7.0, "{load}");
    }
}

/// Designations as drawings spell them (ISO 2904's `Tr 40x7`, spaces
/// round the `x`, a two-part class) run and verify on the defaults, the
/// report naming the thread as the standard prints it.
#[test]
fn designations_as_drawings_spell_them_run_and_verify() {
    let dir = scratch("thread", "spelled");
    for (spelled, printed) in [("Tr 40x7", "Tr40x7"), ("m20 x 2.5-4g6g", "M20-4g6g")] {
        let out = dir.join(printed);
        let set = format!("designation={spelled}");
        let (code, _, err) = pilgrim(&["run", SCRIPT, "--out", s(&out), "-q", "--set", &set]);
        assert_eq!(code, 0, "{spelled}: {err}");
        let r = common::report_of(&out);
        assert_eq!(r["verdict"]["status"], "passed", "{spelled}");
        assert!(
            r.to_string().contains(&format!("\"{printed}")),
            "{spelled}: no {printed}"
        );
    }
}

/// What the family cannot read or cannot yet cut is refused before any
/// output, naming the value: a designation of no standard, a class the
/// standard lacks, a drawing's unknown word; a nut whose outside is inside
/// its thread stops at its check with the FAILED report and no program.
#[test]
fn bad_threads_are_refused_with_clear_errors() {
    let dir = scratch("thread", "bad");
    for (set, says) in [
        (
            "designation=UNC 1/2-13",
            "thread designation 'UNC 1/2-13': not a form pilgrim reads",
        ),
        ("designation=M20x2.5-9g", "tolerance class '9g'"),
        ("designation=1-5 ACME-3G", "ACME class"),
        (
            "load=sideways",
            "load = 'sideways' is not chuck or tailstock",
        ),
        (
            "internal=maybe",
            "internal = 'maybe' is not auto, internal or external",
        ),
    ] {
        let out = dir.join(set.replace(|c: char| !c.is_ascii_alphanumeric(), "_"));
        let (code, _, err) = pilgrim(&["run", SCRIPT, "--out", s(&out), "--quiet", "--set", set]);
        assert_ne!(code, 0, "{set}");
        assert!(err.contains(says), "{set}: {err}");
        assert!(!out.exists(), "{set}: output written");
    }
    for (sets, says) in [(
        &["designation=M30x2-6H", "outside_diameter=29"][..],
        "the nut's outside is beyond its thread",
    )] {
        let set = sets.join(" ");
        let out = dir.join(set.replace(|c: char| !c.is_ascii_alphanumeric(), "_"));
        let mut args = vec!["run", SCRIPT, "--out", s(&out), "--quiet"];
        for one in sets {
            args.extend(["--set", one]);
        }
        let (code, _, err) = pilgrim(&args);
        assert_ne!(code, 0, "{set}");
        assert!(err.contains(says), "{set}: {err}");
        assert!(
            !out.join("program.nc").exists() && out.join("report.html").is_file(),
            "{set}"
        );
    }
}

/// The default M20 posted for LinuxCNC: every thread block a G33 with the
/// pitch as its K, at the axis program's Z; left for `.ci/run`, where
/// LinuxCNC's `rs274` reads it and its canonical moves are compared with
/// the axis program (`.ci/rs274_check.py`).
#[test]
fn the_linuxcnc_program_is_left_for_its_interpreter() {
    let out = run("linuxcnc", &["--post", "linuxcnc"]);
    let ngc = std::fs::read_to_string(out.join("program.ngc")).unwrap();
    assert!(ngc.starts_with("%\n") && ngc.contains(" G7\n"), "{ngc}");
    let program: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("program.json")).unwrap()).unwrap();
    let threads: Vec<&serde_json::Value> = program["blocks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["motion"]["type"] == "thread")
        .collect();
    let g33: Vec<&str> = ngc.lines().filter(|l| l.contains(" G33 ")).collect();
    assert!(
        !threads.is_empty() && g33.len() == threads.len(),
        "{} vs {}",
        g33.len(),
        threads.len()
    );
    for (line, b) in g33.iter().zip(&threads) {
        assert_eq!(word(line, 'K'), Some(2.5), "{line}");
        let z = b["values"][1].as_f64().unwrap();
        assert_eq!(
            word(line, 'Z'),
            Some((z * 1000.0).round() / 1000.0),
            "{line}"
        );
    }
    common::leave_for_rs274(&out, "thread");
}

/// A left hand, M20x2.5-6g-LH, posted for LinuxCNC: the spindle in M3,
/// every thread block runs towards +Z (the tailstock), from beyond the
/// thread's far end by at least S1 to past the face by at least S2, each
/// as the cutter's edges reach; the simulation finds it left-handed and
/// its pitch diameter within 6g (ISO 965-2: 18.164 to 18.334). Left for
/// rs274, and its solids for FreeCAD and the glTF validator.
#[test]
fn a_left_hand_is_cut_towards_the_tailstock() {
    let out = run(
        "lh",
        &["--set", "designation=M20x2.5-6g-LH", "--post", "linuxcnc"],
    );
    let r = common::report_of(&out);
    assert_eq!(r["verdict"]["status"], "passed", "{}", r["verdict"]);
    let v = &r["thread_verification"];
    assert_eq!(v["hand"], "left");
    let d2 = v["starts"][0]["pitch_diameter"].as_f64().unwrap();
    assert!((18.164..=18.334).contains(&d2), "{d2}");
    let notes = &r["notes"];
    let (s1, s2) = (
        notes["s1_mm"].as_f64().unwrap(),
        notes["s2_mm"].as_f64().unwrap(),
    );
    for p in v["passes"].as_array().unwrap() {
        let (approach, runout) = (
            p["approach_mm"].as_f64().unwrap(),
            p["runout_mm"].as_f64().unwrap(),
        );
        assert!(approach >= s1 - 1e-6 && runout >= s2 - 1e-6, "{p}");
    }
    let ngc = std::fs::read_to_string(out.join("program.ngc")).unwrap();
    assert!(ngc.contains(" M3") && !ngc.contains("M4"), "{ngc}");
    let program: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("program.json")).unwrap()).unwrap();
    let blocks = program["blocks"].as_array().unwrap();
    let mut threads = 0;
    for (i, b) in blocks.iter().enumerate() {
        if b["motion"]["type"] == "thread" {
            let (from, to) = (
                blocks[i - 1]["values"][1].as_f64().unwrap(),
                b["values"][1].as_f64().unwrap(),
            );
            assert!(from < -30.0 && to > 0.0, "block {}: {from} to {to}", i + 1);
            threads += 1;
        }
    }
    assert!(threads > 5, "{threads}");
    common::leave_for_rs274(&out, "thread-lh");
    // Its solids (the mesh and the STEP mirrored from a right hand's) for
    // CI's FreeCAD and glTF checks.
    common::leave_for_checkers(&out, "thread-lh");
    let mesh = pilgrim_kernel::mesh::read_stl(&out.join("thread.stl")).unwrap();
    let v = mesh.volume();
    assert!(v > 0.0, "{v}");
    common::leave_step_for_freecad(&out, "thread-lh", "thread", v, 0.01 * v);
}

/// LinuxCNC's G76 (`cycle = g76`) on the lathe with a LinuxCNC control,
/// Tr40x14(P7): the program the control reads holds one G76 per start and
/// no G33; the run verifies the moves the cycle makes (the lint's
/// expansion, which rs274 holds to LinuxCNC's own in CI), each start's
/// pitch diameter within its stated limits; the same passes posted for
/// Fanuc are G32 blocks, one per cycle pass. The file verified as it
/// stands passes; with a tapered end (E) it is refused, naming the word;
/// on a machine whose control is Fanuc it is refused as another
/// control's program.
#[test]
fn a_g76_cycle_is_verified_as_the_control_makes_it() {
    let dir = scratch("thread", "g76-machine");
    let machine = linuxcnc_lathe(&dir);
    let sets = ["--set", "cycle=g76", "--set", "designation=Tr40x14(P7)"];
    let mut args = vec!["--machine", s(&machine), "--post", "fanuc"];
    args.extend(sets);
    let out = run("g76", &args);
    let r = common::report_of(&out);
    assert_eq!(r["verdict"]["status"], "passed", "{}", r["verdict"]);
    let ngc = std::fs::read_to_string(out.join("program.ngc")).unwrap();
    let cycles: Vec<&str> = ngc.lines().filter(|l| l.contains(" G76 P")).collect();
    assert!(cycles.len() == 2 && !ngc.contains("G33"), "{ngc}");
    for c in &cycles {
        assert_eq!(word(c, 'P'), Some(14.0), "{c}");
        assert_eq!(word(c, 'Q'), Some(14.5), "{c}");
    }
    let v = &r["thread_verification"];
    let l = &v["limits"]["pitch_diameter"];
    let (lo, hi) = (l["min"].as_f64().unwrap(), l["max"].as_f64().unwrap());
    let starts = v["starts"].as_array().unwrap();
    assert_eq!(starts.len(), 2);
    for st in starts {
        let d2 = st["pitch_diameter"].as_f64().unwrap();
        assert!(lo <= d2 && d2 <= hi, "{lo} {d2} {hi}");
    }
    let passes = v["passes"].as_array().unwrap().len();
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    assert_eq!(nc.matches("G32 ").count(), passes, "{nc}");
    common::leave_for_rs274(&out, "thread-g76");
    // Radial infeed asked: Q 0, every pass straight in.
    let radial = run(
        "g76-radial",
        &[
            "--set",
            "cycle=g76",
            "--set",
            "flank_order=radial",
            "--machine",
            s(&machine),
        ],
    );
    let text = std::fs::read_to_string(radial.join("program.ngc")).unwrap();
    let line = text.lines().find(|l| l.contains(" G76 P")).unwrap();
    assert_eq!(word(line, 'Q'), Some(0.0), "{line}");
    // The page's listing: a cycle's moves all stand on its G76 line.
    common::check_page(&out, "program.ngc", 12.0);
    common::leave_page_for_chromium(&out, "thread-g76");
    let verify = |file: &std::path::Path, name: &str| {
        let report = dir.join(name);
        let mut args = vec![
            "verify",
            s(file),
            "--machine",
            s(&machine),
            "--family",
            SCRIPT,
            "--out",
            s(&report),
            "--quiet",
        ];
        args.extend(sets);
        pilgrim(&args)
    };
    let (code, _, err) = verify(&out.join("program.ngc"), "as-it-stands");
    assert_eq!(code, 0, "{err}");
    // On the built-in lathe, whose control is Fanuc, a .ngc file is
    // refused, naming both dialects.
    let wrong = dir.join("wrong");
    let (code, _, err) = pilgrim(&[
        "verify",
        s(&out.join("program.ngc")),
        "--family",
        SCRIPT,
        "--out",
        s(&wrong),
        "--quiet",
    ]);
    assert_ne!(code, 0);
    assert!(
        err.contains("a .ngc file is a linuxcnc program")
            && err.contains("control reads fanuc (.nc)")
            && !wrong.exists(),
        "{err}"
    );
    let tapered = dir.join("tapered.ngc");
    std::fs::write(&tapered, ngc.replacen(" H2\n", " H2 E1.0\n", 1)).unwrap();
    let (code, _, err) = verify(&tapered, "tapered");
    assert_ne!(code, 0);
    assert!(
        err.contains("G76 E1") && err.contains("tapered ends"),
        "{err}"
    );
    // The failure is a report to look at, naming the block and why, and
    // no program.
    let failed = dir.join("tapered");
    let report = std::fs::read_to_string(failed.join("report.json")).unwrap();
    assert!(
        report.contains("N40") && report.contains("tapered ends"),
        "{report}"
    );
    assert!(failed.join("report.html").is_file());
    assert!(std::fs::read_dir(&failed).unwrap().all(|f| !f
        .unwrap()
        .file_name()
        .to_string_lossy()
        .starts_with("program.n")));
}

/// On a control of Fanuc's kind (the default lathe), `cycle = g76` writes
/// Fanuc's two-block G76, one per start: Tr40x14(P7) by a 30 degree tool,
/// `m` = finish_passes + 1 passes at the full height, its passes those of
/// the two-block law computed here from the words the file holds (D_n =
/// dd sqrt(n), at least dd_min more, capped at k - d; each shifted towards
/// the start by (k - D_n) tan 15 deg), both starts within their pitch
/// diameter's band. The file verified as it stands gives the run's
/// figures; with start 1's root edited 0.1 mm deeper it fails, naming the
/// cycle's line (the file has no N words). A buttress is
/// refused by a check naming the tool angle, and cut straight in (P..00)
/// with flank_order radial.
#[test]
fn fanuc_g76_is_written_for_a_fanuc_lathe() {
    let out = run(
        "fanuc-g76",
        &["--set", "cycle=g76", "--set", "designation=Tr40x14(P7)"],
    );
    let r = common::report_of(&out);
    assert_eq!(r["verdict"]["status"], "passed", "{}", r["verdict"]);
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    let firsts: Vec<&str> = nc.lines().filter(|l| l.starts_with("G76 P")).collect();
    let seconds: Vec<&str> = nc.lines().filter(|l| l.starts_with("G76 X")).collect();
    assert!(
        firsts.len() == 2 && seconds.len() == 2 && !nc.contains("G32"),
        "{nc}"
    );
    assert!(firsts.iter().all(|l| l.starts_with("G76 P030030 ")), "{nc}");
    let w = |c: char| word(seconds[0], c).unwrap();
    let unit = 0.001;
    let (x, k, dd, lead) = (w('X'), w('P') * unit, w('Q') * unit, w('F'));
    let dd_min = word(firsts[0], 'Q').unwrap() * unit;
    let allowance = word(firsts[0], 'R').unwrap();
    assert_eq!(lead, 14.0);
    let mut law = Vec::new();
    let mut last: f64 = 0.0;
    for n in 1.. {
        let d = (dd * f64::from(n).sqrt())
            .max(last + dd_min)
            .min(k - allowance);
        law.push(d);
        if d >= k - allowance {
            break;
        }
        last = d;
    }
    law.extend([k; 3]);
    let v = &r["thread_verification"];
    let l = &v["limits"]["pitch_diameter"];
    let (lo, hi) = (l["min"].as_f64().unwrap(), l["max"].as_f64().unwrap());
    let passes = v["passes"].as_array().unwrap();
    let tan = 15f64.to_radians().tan();
    for start in 0..2 {
        let of: Vec<&serde_json::Value> = passes.iter().filter(|p| p["start"] == start).collect();
        assert_eq!(of.len(), law.len(), "start {start}");
        let full = of.last().unwrap()["offset"].as_f64().unwrap();
        for (n, (p, d)) in of.iter().zip(&law).enumerate() {
            // The control's moves are in its least increment.
            let px = p["x"].as_f64().unwrap();
            assert!(
                (px - (x + 2.0 * (k - d))).abs() < 6e-4,
                "start {start} pass {}: X {px}, depth {d}",
                n + 1
            );
            let shift = p["offset"].as_f64().unwrap() - full;
            assert!(
                (shift - (k - d) * tan).abs() < 1.1e-3,
                "start {start} pass {}: shift {shift}",
                n + 1
            );
        }
        let d2 = v["starts"][start]["pitch_diameter"].as_f64().unwrap();
        assert!(lo <= d2 && d2 <= hi, "{lo} {d2} {hi}");
    }
    // Read back as it stands: the same figures.
    let dir = scratch("thread", "fanuc-g76-verify");
    let verify = |file: &std::path::Path, name: &str| {
        let report = dir.join(name);
        let (code, _, err) = pilgrim(&[
            "verify",
            s(file),
            "--family",
            SCRIPT,
            "--out",
            s(&report),
            "--quiet",
            "--set",
            "cycle=g76",
            "--set",
            "designation=Tr40x14(P7)",
        ]);
        (code, err, report)
    };
    let (code, err, report) = verify(&out.join("program.nc"), "as-it-stands");
    assert_eq!(code, 0, "{err}");
    let again = common::report_of(&report);
    for start in 0..2 {
        assert_eq!(
            again["thread_verification"]["starts"][start]["pitch_diameter"],
            v["starts"][start]["pitch_diameter"]
        );
    }
    // Start 1's root edited 0.1 mm deeper: refused at the cycle's line.
    let deeper = dir.join("deeper.nc");
    let line = nc.lines().position(|l| l == seconds[0]).unwrap() + 1;
    let edited = seconds[0].replacen(&format!("X{x:.3}"), &format!("X{:.3}", x - 0.2), 1);
    std::fs::write(&deeper, nc.replacen(seconds[0], &edited, 1)).unwrap();
    let (code, err, _) = verify(&deeper, "deeper");
    assert_ne!(code, 0, "a root 0.1 mm deeper verified");
    assert!(
        err.contains(&format!("line {line} in \"START 1, G76 PASS 1\""))
            && err.contains("beyond the nominal thread space"),
        "{err}"
    );
    // A buttress: no Fanuc tool angle for flanks of 45 and 7 degrees.
    let buttress = scratch("thread", "fanuc-g76-buttress").join("out");
    let (code, _, err) = pilgrim(&[
        "run",
        SCRIPT,
        "--out",
        s(&buttress),
        "--quiet",
        "--set",
        "cycle=g76",
        "--set",
        "designation=2-8 BUTT 7/45",
    ]);
    assert_ne!(code, 0);
    assert!(
        err.contains("Fanuc's G76 has the thread's tool angle")
            && err.contains("flank_order = radial"),
        "{err}"
    );
    let radial = run(
        "fanuc-g76-radial",
        &[
            "--set",
            "cycle=g76",
            "--set",
            "designation=2-8 BUTT 7/45",
            "--set",
            "flank_order=radial",
        ],
    );
    let text = std::fs::read_to_string(radial.join("program.nc")).unwrap();
    assert!(
        text.lines().any(|l| l.starts_with("G76 P")
            && word(l, 'P').is_some_and(|p| (p as u64).is_multiple_of(100))),
        "{text}"
    );
}

/// A script whose verify map gives the nut's outside as text is refused,
/// naming the key and the value, and writes nothing.
#[test]
fn a_verify_map_with_a_bad_outside_is_refused() {
    let dir = scratch("thread", "bad-outside");
    let text = std::fs::read_to_string(SCRIPT).unwrap();
    let from = "outside_diameter: outside_diameter(p, t),";
    assert!(text.contains(from));
    let script = dir.join("thread.rhai");
    std::fs::write(&script, text.replace(from, "outside_diameter: \"wide\",")).unwrap();
    copy_tools(&dir);
    let out = dir.join("out");
    let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&out), "--quiet"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("outside_diameter must be a number above 0") && err.contains("wide"),
        "{err}"
    );
    assert!(!out.join("program.nc").exists(), "{err}");
}

/// A worm named as the thread family reads worms (`ZI m5 z2 d50`, its
/// example file) is cut by the form cutter and verified against its
/// stated limits: each start's pitch diameter within 5 um of the band's
/// middle (49.9, the cut 0.05 mm deeper on radius than the basic), its
/// flanks within 1 um of their curve. The run's `thread.stl` puts every
/// flank vertex on the involute helicoid computed here from DIN 3975's
/// definition (`cos gamma_b = cos alpha_n cos gamma`), moved 0.05 mm
/// towards the axis, within 2 um. With `cycle = g76` on LinuxCNC it is
/// written as one G76 per start (radial: Q0) and left for rs274; as a nut
/// it is refused by name (a worm is external).
#[test]
fn a_worm_named_by_its_designation_is_cut_on_its_curved_flanks() {
    use std::f64::consts::{PI, TAU};
    let out = run(
        "worm-zi",
        &["--params", "scripts/examples/thread-worm-zi.toml"],
    );
    let r = common::report_of(&out);
    assert_eq!(r["verdict"]["status"], "passed", "{}", r["verdict"]);
    let v = &r["thread_verification"];
    for st in v["starts"].as_array().unwrap() {
        let f = |k: &str| st[k].as_f64().unwrap();
        assert!((f("pitch_diameter") - 49.9).abs() < 0.005, "{st}");
        assert!(
            f("left_form").abs() < 1e-3 && f("right_form").abs() < 1e-3,
            "{st}"
        );
        assert!(st.get("over_wires").is_none(), "{st}");
    }
    let (px, p, r1, an) = (PI * 5.0, 2.0 * PI * 5.0 / TAU, 25.0, 20f64.to_radians());
    let rb = p / (an.cos() * (p / r1).atan().cos()).acos().tan();
    let inv = |r: f64| ((r / rb).powi(2) - 1.0).sqrt() - (rb / r).acos();
    let points = crate::worm::flank_points(&out, "thread.stl", (19.5, 29.4));
    assert!(points.len() > 1000, "{}", points.len());
    let worst = points
        .iter()
        .map(|&(rho, d)| (d.abs() - (px / 4.0 + p * (inv(rho + 0.05) - inv(r1)))).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 2e-3,
        "ZI flanks {worst} mm off the involute helicoid"
    );
    // G76 on LinuxCNC: straight in, one cycle per start.
    let lathe = linuxcnc_lathe(&scratch("thread", "worm-zi-g76-machine"));
    let g76 = run(
        "worm-zi-g76",
        &[
            "--params",
            "scripts/examples/thread-worm-zi.toml",
            "--set",
            "cycle=g76",
            "--machine",
            s(&lathe),
        ],
    );
    let ngc = std::fs::read_to_string(g76.join("program.ngc")).unwrap();
    let cycles: Vec<&str> = ngc
        .lines()
        .filter(|l| l.starts_with('N') && l.contains(" G76 "))
        .collect();
    assert_eq!(cycles.len(), 2, "{ngc}");
    assert!(cycles.iter().all(|l| l.contains("Q0.0000")), "{cycles:?}");
    common::leave_for_rs274(&g76, "thread-worm-zi");
    let (code, _, err) = pilgrim(&[
        "run",
        SCRIPT,
        "--out",
        s(&scratch("thread", "worm-nut").join("out")),
        "--set",
        "designation=ZI m5 z2 d50",
        "--set",
        "internal=internal",
    ]);
    assert_ne!(code, 0);
    assert!(
        err.contains("an external thread's, and the drawing says internal"),
        "{err}"
    );
}

/// A start corrected so that the passes' depths, rounded to the program's
/// digit, leave its root a little above the root it aims at (Tr40x14(P7),
/// start 1 moved by -0.0231 mm of pitch diameter) is still measured: its
/// pitch diameter is sought from the cut root up, where the aimed root's
/// band would start below the material left and find no space.
#[test]
fn a_corrected_start_is_measured_from_its_cut_root() {
    let dir = scratch("thread", "corrected-root");
    let script = dir.join("thread.rhai");
    std::fs::copy(common::root().join(SCRIPT), &script).unwrap();
    copy_tools(&dir);
    std::fs::write(
        dir.join("correction.csv"),
        "z_mm,dd2_1_mm,dd2_2_mm\n-30,-0.0231,-0.05\n-15,-0.0231,-0.05\n0,-0.0231,-0.05\n",
    )
    .unwrap();
    let out = dir.join("out");
    let (code, _, err) = pilgrim(&[
        "run",
        s(&script),
        "--set",
        "designation=Tr40x14(P7)",
        "--set",
        "correction=correction.csv",
        "--out",
        s(&out),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let first = run(
        "corrected-root-first",
        &["--set", "designation=Tr40x14(P7)"],
    );
    let d2 = |dir: &std::path::Path, k: usize| {
        common::report_of(dir)["thread_verification"]["starts"][k]["pitch_diameter"]
            .as_f64()
            .unwrap()
    };
    for (k, moved) in [(0, -0.0231), (1, -0.05)] {
        let now = d2(&out, k) - d2(&first, k);
        assert!((now - moved).abs() < 2e-3, "start {}: moved {now}", k + 1);
    }
}

/// The radius of a body's solid about the part's axis (mm): its STL's
/// vertices farthest from the axis of its own cylinder (the file's own
/// frame: the cylinder along Z), read back from the file the run wrote.
fn cylinder_radius(file: &std::path::Path) -> f64 {
    let vertices = crate::worm::stl_vertices(file);
    let extent = |k: usize| {
        let (lo, hi) = vertices
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v[k]), hi.max(v[k]))
            });
        hi - lo
    };
    0.25 * (extent(0) + extent(1))
}

/// The common sizes on the default lathe and the default tool table
/// (`scripts/thread-tools.csv`), the machine's bodies as built in: small
/// bolts held in the chuck alone on the long holder, small nuts on the
/// small bars, deep nuts on the bar whose insert reaches their depth. Each
/// run passes, its program calls the table's tool, and the boring bar in
/// the scene is the row's (its solid's radius read back from the STL).
#[test]
fn common_sizes_run_on_the_default_tool_table() {
    for (designation, tool, bar_radius) in [
        (
            "M8x1.25-6g",
            "16ER 60 DEG ON A LONG 20 MM HOLDER FOR SMALL PARTS",
            None,
        ),
        // Turned to the middle of 6g's major band, 9.85 mm: below the
        // 25 mm holder's least major of 10.
        (
            "M10x1.5-6g",
            "16ER 60 DEG ON A LONG 20 MM HOLDER FOR SMALL PARTS",
            None,
        ),
        ("M24x3-6g", "16ER 60 DEG ON A 25 MM HOLDER", None),
        ("M12x1.5-6H", "CARBIDE BAR 7 MM FOR SMALL BORES", Some(3.5)),
        ("M36x4-6H", "22IR 60 DEG ON A 20 MM BAR", Some(10.0)),
        ("M42x4.5-6H", "22IR 60 DEG ON A 20 MM BAR", Some(10.0)),
        ("Tr 40x7", "27ER TRAPEZOIDAL 30 DEG ON A 25 MM HOLDER", None),
    ] {
        let name = designation.replace(|c: char| !c.is_ascii_alphanumeric(), "_");
        let out = run(&name, &["--set", &format!("designation={designation}")]);
        let r = common::report_of(&out);
        assert_eq!(r["verdict"]["status"], "passed", "{designation}");
        let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
        assert!(nc.contains(&format!(": {tool})")), "{designation}: {nc}");
        if let Some(radius) = bar_radius {
            let got = cylinder_radius(&out.join("boring_bar.stl"));
            assert!(
                (got - radius).abs() < 0.05,
                "{designation}: bar radius {got}"
            );
        }
        assert_eq!(r["machine"], "fanuc-0i-tc", "{designation}");
    }
}

/// A thread no tool of the table cuts is refused before any output, the
/// message naming the table, the nearest tool and what it lacks; a shop's
/// own table beside its parameter file is read in place of the default,
/// and a size it gives for a body that does not ride with the tool is
/// refused naming the constants it may give.
#[test]
fn the_tool_table_is_the_shops_and_a_misfit_names_the_nearest_tool() {
    let dir = scratch("thread", "tool-table");
    // The run refused, writing nothing into `out`: its message.
    let refused = |out: &std::path::Path, args: [&str; 2]| {
        let mut all = vec!["run", SCRIPT, "--out", s(out), "--quiet"];
        all.extend(args);
        let (code, _, err) = pilgrim(&all);
        assert_ne!(code, 0, "{args:?}");
        assert!(!out.exists(), "{args:?}: output written");
        err
    };
    let err = refused(&dir.join("m8-nut"), ["--set", "designation=M8x1.25-6H"]);
    assert!(err.contains("no tool of"), "{err}");
    assert!(err.contains("thread-tools.csv cuts M8-6H"), "{err}");
    assert!(
        err.contains("'carbide bar 5 mm for small bores', needs a bore of 8 mm or more"),
        "{err}"
    );

    let shop = dir.join("shop");
    std::fs::create_dir_all(&shop).unwrap();
    let head = "name,number,side,profile_deg,pitch_min_mm,pitch_max_mm,nose_mm,depth_mm,shank_mm,least_diameter_mm,longest_mm,body:bar_radius,body:bar_tip,body:bar_length,body:chuck_gap";
    std::fs::write(
        shop.join("our-tools.csv"),
        format!("{head}\nour 12 mm bar,14,internal,60,1,2.5,,1.5,12,18,50,6,8.5,60,\n"),
    )
    .unwrap();
    let params = shop.join("nut.toml");
    std::fs::write(
        &params,
        "designation = \"M24x2-6H\"\ntools = \"our-tools.csv\"\n",
    )
    .unwrap();
    let out = run("shop-nut", &["--params", s(&params)]);
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    assert!(nc.contains("TOOL T14: OUR 12 MM BAR)"), "{nc}");
    let got = cylinder_radius(&out.join("boring_bar.stl"));
    assert!((got - 6.0).abs() < 0.05, "bar radius {got}");

    std::fs::write(
        shop.join("our-tools.csv"),
        format!("{head}\nour 12 mm bar,14,internal,60,1,2.5,,1.5,12,18,50,6,8.5,60,10\n"),
    )
    .unwrap();
    let err = refused(&dir.join("bad-body"), ["--params", s(&params)]);
    assert!(
        err.contains("tool 'our 12 mm bar' gives the machine's constant 'chuck_gap'"),
        "{err}"
    );
    assert!(err.contains("bar_length, bar_radius, bar_tip"), "{err}");
}
