//! The worm job end to end (issue 13): the default two-start worm and a
//! three-start one simulated pass by pass from `program.nc` as a control
//! reads it, a corrupted pass named by the simulation, the LinuxCNC
//! program read by LinuxCNC's own interpreter, and bad input refused with
//! no output.

use crate::common;

use common::{pilgrim, s, scratch, word};
use pilgrim_kernel::families::thread::{
    simulate, ThreadCheck, ThreadRequest, ThreadTolerances, WormSizes,
};
use pilgrim_kernel::plugin::PluginMachine;
use pilgrim_kernel::program::{AxisProgram, Block, ProgramAxis};
use pilgrim_kernel::step::Sections;
use pilgrim_kernel::tool::{Tool, ToolShape};
use pilgrim_kernel::Motion;
use std::path::{Path, PathBuf};

const SCRIPT: &str = "scripts/worm.rhai";

fn lathe() -> PluginMachine {
    PluginMachine::from_entry(
        "fanuc-0i-tc",
        "pilgrim_plugin_fanuc_0i_tc",
        fanuc_0i_tc::pilgrim_plugin_fanuc_0i_tc,
    )
    .unwrap()
}

/// The worm job run into a fresh `out` under a scratch directory called
/// `name`, quietly, with `args` after it (`--set k=v`, `--post d`): the
/// scratch directory and `out`, the run having succeeded.
fn run_worm(name: &str, args: &[&str]) -> (PathBuf, PathBuf) {
    let dir = scratch("worm", name);
    let out = dir.join("out");
    let mut all = vec!["run", SCRIPT, "--out", s(&out), "--quiet"];
    all.extend(args);
    let (code, _, err) = pilgrim(&all);
    assert_eq!(code, 0, "{err}");
    (dir, out)
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

/// A Fanuc program (`program.nc`) read as the control reads it, from the
/// first pass on: modal G00/G01/G32, X, Z and F; Q (0.001 deg) for its
/// block only; each pass's comment on its first block.
fn read_nc(nc: &str, rpm: f64) -> AxisProgram {
    let (mut g, mut x, mut z, mut f) = (0, f64::NAN, f64::NAN, 0.0);
    let mut comment: Option<String> = None;
    let mut in_passes = false;
    let mut blocks = Vec::new();
    for line in nc.lines() {
        let (code, note) = match line.split_once('(') {
            Some((c, n)) => (c, Some(n.trim_end_matches(')').to_owned())),
            None => (line, None),
        };
        if let Some(n) = note {
            if n.starts_with("PASS ") {
                in_passes = true;
                comment = Some(n.to_lowercase());
            } else if n == "END" {
                in_passes = false;
            }
        }
        for w in code.split_whitespace() {
            match w {
                "G00" => g = 0,
                "G01" => g = 1,
                "G32" => g = 32,
                _ => {}
            }
        }
        let (nx, nz) = (word(code, 'X'), word(code, 'Z'));
        x = nx.unwrap_or(x);
        z = nz.unwrap_or(z);
        f = word(code, 'F').unwrap_or(f);
        if !in_passes || (nx.is_none() && nz.is_none()) {
            continue;
        }
        let motion = match g {
            0 => Motion::Rapid,
            1 => Motion::Linear,
            _ => Motion::Thread {
                lead: f,
                start_deg: word(code, 'Q').unwrap_or(0.0) / 1000.0,
            },
        };
        blocks.push(Block {
            motion,
            values: vec![x, z],
            feed: if g == 32 { f * rpm } else { f },
            spindle: None,
            comment: comment.take(),
            keep: vec![],
            number: None,
            line: None,
            dwell_s: 0.0,
        });
    }
    let axis = |n: &str| ProgramAxis {
        name: n.into(),
        unit: "mm".into(),
    };
    AxisProgram {
        name: "WORM".into(),
        number: 0,
        machine: "fanuc-0i-tc".into(),
        control: "fanuc".into(),
        tool_number: 1,
        tool_name: "thread cutter".into(),
        spindle_rpm: rpm,
        decimals: None,
        axes: vec![axis("X"), axis("Z")],
        blocks,
        setup: Default::default(),
        cycles: Vec::new(),
        fanuc_cycles: Vec::new(),
    }
}

/// The run's cutter, as its toolpath.json says.
fn cutter(dir: &Path) -> pilgrim_kernel::families::thread::ThreadCutter {
    let tp: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("toolpath.json")).unwrap()).unwrap();
    let tool: Tool = serde_json::from_value(tp["tool"].clone()).unwrap();
    match tool.shape {
        ToolShape::ThreadCutter(c) => c,
        other => panic!("not a thread cutter: {other:?}"),
    }
}

/// What the family asks the simulation to hold for a worm of module `m`,
/// `z1` starts, pitch diameter `d1`, `b1` long, placed as the run's report
/// `r` says: the family's default tolerances.
fn request(r: &serde_json::Value, m: f64, z1: i64, d1: f64, b1: f64) -> ThreadRequest {
    ThreadRequest::worm(
        &WormSizes::new(m, z1, d1, 0.2, 20f64.to_radians(), None).unwrap(),
        b1,
        r["notes"]["space_centre_mm"].as_f64().unwrap(),
        ThreadTolerances {
            form: 0.01,
            thickness: 0.02,
            diameter: 0.02,
            position: 0.01,
            flank_angle: 0.05f64.to_radians(),
            lead: 0.01,
        },
    )
}

/// The run in `dir` simulated again from its `program.nc`.
fn simulate_nc(
    dir: &Path,
    nc: &str,
    m: f64,
    z1: i64,
    d1: f64,
    b1: f64,
) -> Result<ThreadCheck, String> {
    let r = report(dir);
    let rpm = r["parameters"]["spindle"]["value"].as_f64().unwrap();
    let program = read_nc(nc, rpm);
    let req = request(&r, m, z1, d1, b1);
    simulate(&program, &lathe(), &Default::default(), &cutter(dir), &req)
        .and_then(|c| c.verified())
        .map_err(|e| e.to_string())
}

/// The simulation read back from the program: every chip summed is the
/// thread spaces' area (less the root's fillets the nose radius leaves);
/// the profile within its tolerances at every start; alternating flanks
/// share the load.
fn holds(check: &ThreadCheck, z1: usize, m: f64, nose: f64) {
    // Each space keeps at most two fillets of r^2 (tan(phi/2) - phi/2),
    // phi = 70 deg, where the nose radius turns the root's corners (the
    // last roughing passes on the flanks take part of them).
    // And the program's 0.001 mm steps: a flank may stand half a step off
    // its line over its length (h1 / cos alpha).
    let phi = 70f64.to_radians();
    let fillets = 2.0 * z1 as f64 * nose * nose * ((phi / 2.0).tan() - phi / 2.0);
    let flanks = 2.0 * z1 as f64 * (2.2 * m / 20f64.to_radians().cos()) * 0.0005;
    let left = check.space_area - check.removed_area;
    assert!(
        left > 0.0 && left <= fillets + flanks,
        "space {} mm^2, removed {} mm^2: {left} left, fillets {fillets}, flanks {flanks}",
        check.space_area,
        check.removed_area
    );
    assert_eq!(check.starts.len(), z1);
    for s in &check.starts {
        assert!(
            s.left_form.abs() < 0.002 && s.right_form.abs() < 0.002,
            "{s:?}"
        );
        assert!(
            (s.left_angle_deg - 20.0).abs() < 0.01 && (s.right_angle_deg - 20.0).abs() < 0.01,
            "{s:?}"
        );
        assert!(s.position_error.abs() < 0.001, "{s:?}");
    }
    let [l, r] = check.flank_loads;
    assert!(l / r > 0.9 && l / r < 1.1, "left {l} mm^2, right {r} mm^2");
}

#[test]
fn the_default_two_start_worm_holds_its_profile_read_back_from_the_program() {
    let dir = scratch("worm", "default");
    let out = dir.join("out");
    let (code, stdout, err) = pilgrim(&["run", SCRIPT, "--out", s(&out)]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("thread within tolerance"), "{stdout}");
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    // The block to paste after the tool call: G97 before any thread, G32
    // with F the lead, the second start by the spindle's start angle.
    assert!(!nc.contains("O0") && !nc.contains("T0101"), "{nc}");
    let g97 = nc.find("G97").unwrap();
    assert!(g97 < nc.find("G32").unwrap());
    assert!(
        nc.contains("G32 Z-64.124 F31.4159\n") && nc.contains("Q180000"),
        "{nc}"
    );
    assert!(nc.trim_end().ends_with("M30"), "{nc}");
    let check = simulate_nc(&out, &nc, 5.0, 2, 50.0, 60.0).unwrap();
    holds(&check, 2, 5.0, 0.3);
    // The finished worm's solid: closed, and its volume the section's swept
    // along the helix, pi b1 / L * integral of r(u)^2 over a lead (for any
    // length: every section across the axis meets a whole lead of it).
    let solid = pilgrim_kernel::families::thread::thread_solid(&check, 60.0, 0.01, None).unwrap();
    solid.check_closed().unwrap();
    // Every vertex between the root's and the tip's circles (the axis's
    // points of the flat ends aside).
    for p in &solid.positions {
        let r = p[0].hypot(p[1]);
        assert!(
            r < 1e-9 || (19.0 - 1e-6..=30.0 + 1e-6).contains(&r),
            "{p:?}: r = {r}"
        );
    }
    let (w0, lead) = check.window;
    // The mesh and the exact body for STEP (two samplings of one sweep)
    // both put at the part's angle phi and height z the section's radius at
    // z - lead phi / 2 pi: right-handed, as the program cuts it.
    let on_helix = |p: [f64; 3]| {
        let (r, phi) = (p[0].hypot(p[1]), p[1].atan2(p[0]));
        let u = w0 + (p[2] - lead * phi / std::f64::consts::TAU - w0).rem_euclid(lead);
        (r - check.radius_at(u)).abs()
    };
    let worst_mesh = solid
        .positions
        .iter()
        .filter(|p| p[0].hypot(p[1]) > 1e-9)
        .map(|p| on_helix(*p))
        .fold(0.0, f64::max);
    assert!(
        worst_mesh < 1e-3,
        "worm.stl strays {worst_mesh} mm from the helix"
    );
    let sweep =
        pilgrim_kernel::families::thread::ThreadSweep::new(&check, 60.0, 2.5e-4, None).unwrap();
    let mut worst_sweep: f64 = 0.0;
    for k in 0..sweep.pieces() {
        for (u, v) in [(0.0, 0.0), (0.37, 0.5), (0.81, 0.93)] {
            worst_sweep = worst_sweep.max(on_helix(sweep.point(k, u, v)));
        }
    }
    assert!(
        worst_sweep <= 2.5e-4 + 1e-9,
        "the STEP body strays {worst_sweep} mm from the helix"
    );
    let n = 200_000;
    let integral: f64 = (0..n)
        .map(|i| {
            check
                .radius_at(w0 + lead * (i as f64 + 0.5) / n as f64)
                .powi(2)
        })
        .sum::<f64>()
        * lead
        / n as f64;
    let want = std::f64::consts::PI * 60.0 / lead * integral;
    assert!(
        // The chords round the axis (within 0.01 mm of the tip circle:
        // 122 of them) lose (2 pi / 122)^2 / 6 = 4.4e-4 of the area.
        (solid.volume() - want).abs() < 1e-3 * want && solid.volume() < want,
        "{} vs {want}",
        solid.volume()
    );
    // The run's own simulation says the same.
    let r = report(&out);
    let w = &r["thread_verification"];
    assert_eq!(w["passes"].as_array().unwrap().len(), check.passes.len());
    assert!((w["removed_area"].as_f64().unwrap() - check.removed_area).abs() < 1e-6);
    // S1 and S2 are the minimums of Fanuc's exact form at 100 rpm.
    let v = 31.415_926_5 * 100.0 / 60.0;
    let s1 = r["notes"]["s1_mm"].as_f64().unwrap();
    assert!(
        (s1 - 0.033 * v * (-1.0 - 0.01f64.ln() + 0.01)).abs() < 1e-6,
        "{s1}"
    );
    // Every pass's planned and simulated areas in passes.csv; the law's
    // equal areas are not what a flat-tipped cutter cuts.
    let csv = std::fs::read_to_string(out.join("passes.csv")).unwrap();
    assert_eq!(csv.lines().count(), check.passes.len() + 1);
    assert!(
        csv.starts_with("block,name,start,x_mm,offset_mm,chip_area_mm2"),
        "{csv}"
    );
    // The same per pass in passes.xlsx, numbers as numbers with their
    // units; each start's finished profile; the verification's figures.
    check_workbook(&out);
    for f in [
        "passes.svg",
        "chip_area.svg",
        "worm.stl",
        "cutter.stl",
        "scene.glb",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    // The run's own worm.stl (f32 binary STL): the same radii and volume.
    let stl = std::fs::read(out.join("worm.stl")).unwrap();
    let facets = u32::from_le_bytes(stl[80..84].try_into().unwrap()) as usize;
    assert_eq!(stl.len(), 84 + 50 * facets);
    let mut volume = 0.0;
    for f in 0..facets {
        let at = |k: usize| -> [f64; 3] {
            let o = 84 + 50 * f + 12 + 12 * k;
            let c = |j: usize| {
                f32::from_le_bytes(stl[o + 4 * j..o + 4 * j + 4].try_into().unwrap()) as f64
            };
            [c(0), c(1), c(2)]
        };
        let (a, b, c) = (at(0), at(1), at(2));
        for p in [a, b, c] {
            let r = p[0].hypot(p[1]);
            assert!(
                (19.0 - 1e-4..=30.0 + 1e-4).contains(&r),
                "worm.stl facet {f}: r = {r}"
            );
        }
        volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))
            / 6.0;
    }
    assert!(
        (volume - want).abs() < 1e-3 * want,
        "worm.stl: {volume} vs {want}"
    );
    // Deterministic: a second run writes the same bytes, file by file.
    let (_, again) = run_worm("default-again", &[]);
    for e in std::fs::read_dir(&out).unwrap().flatten() {
        let name = e.file_name();
        assert!(
            std::fs::read(e.path()).unwrap() == std::fs::read(again.join(&name)).unwrap(),
            "{name:?} differs between two runs"
        );
    }
    common::leave_for_checkers(&out, "worm");
    // The cutter's blade as an exact solid: the rounded trapezoid (tip =
    // the root space, flanks at alpha 20 deg, 13 mm high, nose 0.3 mm; a
    // corner of turning angle phi = 90 - alpha rounded by r loses r^2
    // (tan(phi/2) - phi/2)) in each section, 6 mm of them across the
    // cutting plane, each shifted along the helix (which keeps its area)
    // and shrunk about the profile's top by 1 - c (y/3)^2, c such that the
    // tip stands back 3 degrees at the faces: the area times the integral
    // of the shrink squared.
    let report: serde_json::Value = common::report_of(&out);
    let tip = report["notes"]["root_space_mm"].as_f64().unwrap();
    let (a, h, r) = (20f64.to_radians(), 13.0, 0.3);
    let phi = std::f64::consts::FRAC_PI_2 - a;
    let area =
        0.5 * (2.0 * tip + 2.0 * h * a.tan()) * h - 2.0 * r * r * ((phi / 2.0).tan() - phi / 2.0);
    let c = 3.0 * 3f64.to_radians().tan() / h;
    let samples: Vec<f64> = (0..=64)
        .map(|i| (1.0 - c * (-1.0 + i as f64 / 32.0).powi(2)).powi(2))
        .collect();
    let shrink = pilgrim_kernel::math::simpson(&samples, 1.0 / 32.0);
    let v = area * 3.0 * shrink;
    let solid = &report["solids"][1];
    assert_eq!(solid["name"], "cutter");
    // Within the STEP tolerance (1 um) over the blade's surface (its two
    // faces and its outline's 43 mm round 6 mm: 470 mm^2 at most).
    common::check_fitted_solid(&out, "worm", "cutter", v, 470.0);
    // At the default pose, halfway through the last pass's thread block,
    // the cutter stands in the thread it cut: no point of cutter.stl (its
    // corners and its facets' middles) lies inside the worm this test
    // simulated from program.nc, whose surface at angle phi and height z
    // is the section's at z - lead phi / 2 pi. (The scene placed the
    // thread at angle 0 and the blade as a flat prism: it cut 3.48 mm^3
    // of the worm in FreeCAD.)
    assert!((report["pose_along"].as_f64().unwrap() - 0.5).abs() < 1e-12);
    let blade = std::fs::read(out.join("cutter.stl")).unwrap();
    let facets = u32::from_le_bytes(blade[80..84].try_into().unwrap()) as usize;
    let (w0, lead) = check.window;
    let mut deepest: f64 = 0.0;
    let mut inside_thread = 0;
    for f in 0..facets {
        let at = |k: usize| -> [f64; 3] {
            let o = 84 + 50 * f + 12 + 12 * k;
            [0, 1, 2].map(|j| {
                f32::from_le_bytes(blade[o + 4 * j..o + 4 * j + 4].try_into().unwrap()) as f64
            })
        };
        let (p, q, t) = (at(0), at(1), at(2));
        let mid = [0, 1, 2].map(|j| (p[j] + q[j] + t[j]) / 3.0);
        for x in [p, mid] {
            let (rho, phi) = (x[0].hypot(x[1]), x[1].atan2(x[0]));
            if !(-60.0..0.0).contains(&x[2]) {
                continue;
            }
            inside_thread += 1;
            let u = w0 + (x[2] - lead * phi / std::f64::consts::TAU - w0).rem_euclid(lead);
            deepest = deepest.max(check.radius_at(u) - rho);
        }
    }
    assert!(inside_thread > 100, "the cutter is not in the thread");
    assert!(
        deepest < 2e-3,
        "cutter.stl reaches {deepest} mm into the worm at the pose"
    );
    // The worm as an exact solid: the volume found above, within the
    // tolerance over its lateral surface (the section's outline over a lead,
    // wound round the tip's circle along 60 mm, an upper bound).
    let outline = check.outline();
    let run: f64 = outline
        .windows(2)
        .map(|p| (p[1][0] - p[0][0]).hypot(p[1][1] - p[0][1]))
        .sum();
    let area = std::f64::consts::TAU * 30.0 * 60.0 * (run + 30.0) / lead;
    common::check_fitted_solid(&out, "worm", "worm", want, area);
    common::check_page(&out, "program.nc", 4.5);
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.contains("Verification: the thread cut simulated"));
    for f in ["passes.svg", "chip_area.svg"] {
        assert!(page.contains(&format!("alt=\"{f}\"")), "{f}");
    }
    common::leave_page_for_chromium(&out, "worm");
}

#[test]
fn a_three_start_worm_cut_each_start_completely_holds_its_profile() {
    let (_, out) = run_worm(
        "three",
        &[
            "--set",
            "z1=3",
            "--set",
            "m=4",
            "--set",
            "d1=60",
            "--set",
            "starts_by_depth=false",
            "--set",
            "b1=40",
            "--set",
            "spindle=60",
        ],
    );
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    assert!(nc.contains("Q120000") && nc.contains("Q240000"), "{nc}");
    let check = simulate_nc(&out, &nc, 4.0, 3, 60.0, 40.0).unwrap();
    holds(&check, 3, 4.0, 0.3);
    // Each start completely: the first third of the passes cut start 1.
    let third = check.passes.len() / 3;
    assert!(check.passes[..third].iter().all(|p| p.start == 0));
    assert!(check.passes[2 * third..].iter().all(|p| p.start == 2));
}

/// A one-start worm cut with a universal cutter (a tip 1 mm narrower
/// than the root's space): stepped along the axis by a_1z to each flank
/// on the finishing passes, it holds the same profile.
#[test]
fn a_one_start_worm_with_a_universal_cutter_holds_its_profile() {
    let (_, out) = run_worm(
        "one",
        &[
            "--set",
            "z1=1",
            "--set",
            "tip_width=2.486",
            "--set",
            "axial_step=0.2",
        ],
    );
    let r = report(&out);
    let a1z = r["notes"]["axial_offset_a1z_mm"].as_f64().unwrap();
    assert!((a1z - 0.5).abs() < 1e-3, "{a1z}");
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    assert!(!nc.contains('Q'), "one start: no start angle");
    let check = simulate_nc(&out, &nc, 5.0, 1, 50.0, 60.0).unwrap();
    holds(&check, 1, 5.0, 0.3);
    // ceil(0.5 / 0.2) = 3 steps to each flank at each of the 2 finishing depths.
    let sides = check
        .passes
        .iter()
        .filter(|p| p.name.contains(", side,"))
        .count();
    assert_eq!(sides, 3 * 2 * 2);
    // The plan's chip area of each side step is the area the step removes
    // beside the passes before it (it had planned the step's width times
    // the depth, 4.087 mm^2, where the simulated cut is 0.02 to 0.22):
    // the simulation of the program agrees within its 0.001 mm steps.
    let t = &r["tables"]["passes"];
    let (kind, planned) = (
        t["kind"].as_array().unwrap(),
        t["planned_area"].as_array().unwrap(),
    );
    let mut seen = 0;
    for (i, p) in check.passes.iter().enumerate() {
        if kind[i].as_f64() != Some(2.0) {
            continue;
        }
        let plan = planned[i].as_f64().unwrap();
        assert!(
            (plan - p.chip_area).abs() < 0.01 + 0.05 * p.chip_area,
            "{}: planned {plan} mm^2, simulated {} mm^2",
            p.name,
            p.chip_area
        );
        seen += 1;
    }
    assert_eq!(seen, sides);
}

/// One pass 0.2 mm deeper on diameter in the program: the simulation
/// names it.
#[test]
fn a_corrupted_pass_is_named() {
    let (_, out) = run_worm("corrupt", &[]);
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    let lines: Vec<&str> = nc.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with("(PASS 60,"))
        .unwrap();
    // The pass's infeed: its block that brings X in to depth (before G32).
    let g32 = at
        + lines[at..]
            .iter()
            .position(|l| l.starts_with("G32"))
            .unwrap();
    let infeed = g32 - 1;
    let x = word(lines[infeed], 'X').unwrap();
    let mut bad: Vec<String> = lines.iter().map(|l| (*l).to_owned()).collect();
    bad[infeed] = format!("X{:.3}", x - 0.2);
    let e = simulate_nc(&out, &(bad.join("\n") + "\n"), 5.0, 2, 50.0, 60.0).unwrap_err();
    assert!(
        e.contains("\"pass 60, start") && e.contains("beyond the nominal thread space"),
        "{e}"
    );
}

/// The LinuxCNC program: `%`-framed, G7 (X on diameter), every
/// synchronised move a G33 with its K, at the places and leads of the
/// axis program; left for `.ci/run`, where LinuxCNC's own `rs274`
/// interpreter reads it and its canonical moves are compared with the
/// axis program (`.ci/rs274_check.py`).
#[test]
fn the_linuxcnc_program_is_left_for_its_interpreter() {
    let (dir, out) = run_worm(
        "linuxcnc",
        &["--set", "start_shift=z", "--post", "linuxcnc"],
    );
    let ngc = std::fs::read_to_string(out.join("program.ngc")).unwrap();
    assert!(ngc.starts_with("%\n") && ngc.ends_with("M2\n%\n"), "{ngc}");
    assert!(ngc.contains(" G7\n"), "{ngc}");
    let program: AxisProgram =
        serde_json::from_str(&std::fs::read_to_string(out.join("program.json")).unwrap()).unwrap();
    let threads: Vec<&Block> = program
        .blocks
        .iter()
        .filter(|b| matches!(b.motion, Motion::Thread { .. }))
        .collect();
    let g33: Vec<&str> = ngc.lines().filter(|l| l.contains(" G33 ")).collect();
    assert_eq!(g33.len(), threads.len());
    for (line, b) in g33.iter().zip(&threads) {
        assert_eq!(word(line, 'K'), Some(31.4159), "{line}");
        assert_eq!(
            word(line, 'Z'),
            Some((b.values[1] * 1000.0).round() / 1000.0),
            "{line}"
        );
    }
    // Without the Z shift the second start needs a start angle, which
    // LinuxCNC's G33 has not: refused, naming the block.
    let (code, _, err) = pilgrim(&[
        "run",
        SCRIPT,
        "--out",
        s(&dir.join("angle")),
        "--quiet",
        "--post",
        "linuxcnc",
    ]);
    assert_ne!(code, 0);
    assert!(
        err.contains("N90 in \"pass 2, start 2") && err.contains("shift the starts along Z"),
        "{err}"
    );
    common::leave_for_rs274(&out, "worm");
}

/// Bad input: each a clear message; no output for the errors, and for a
/// failed check or verification the FAILED report and no program; S1
/// below its minimum a warning naming the lead error.
#[test]
fn bad_input_is_refused_with_no_output() {
    let dir = scratch("worm", "bad");
    // The cases whose run fails a check or its verification: they leave
    // their diagnostic.
    let failed = [
        "tip_width=5",
        "m=0.1 b1=2 z1=1 nose_r=0.01 a_min=0.01 finish_depth=0.01",
    ];
    for (set, says) in [
        ("z1=0", "z1"),
        ("m=-1", "m"),
        ("tip_width=5", "the cutter's tip fits the space at the root"),
        (
            "a_min=5 m=1",
            "minimum depth of cut a_min = 5 is out of range: at most the roughing depth 2.1000 mm",
        ),
        ("spindle=400", "a thread of lead 31.4159 mm at 400 rpm"),
        // A fine thread 700 mm long: its solid would be too large (its lead,
        // 0.314159 mm, is written F0.3142: 0.09 mm over 700 mm, hence the
        // wider place tolerance).
        (
            "m=0.1 b1=700 z1=1 nose_r=0.01 a_min=0.01 finish_depth=0.01 tol_angle_deg=1 tol_position=0.1",
            "worm: the mesh would have 55900544 triangles",
        ),
        // Its flanks, 0.2 mm high, cannot hold 0.05 deg at 0.001 mm steps
        // (2 mm of it: its failed run's diagnostic is some 18 MB, as the
        // 60 mm default's would be 490 MB).
        (
            "m=0.1 b1=2 z1=1 nose_r=0.01 a_min=0.01 finish_depth=0.01",
            "flank: angle",
        ),
    ] {
        let out = dir.join(set.replace(['=', ' '], "_"));
        let mut args = vec!["run", SCRIPT, "--out", s(&out), "--quiet"];
        for one in set.split(' ') {
            args.extend(["--set", one]);
        }
        let (code, _, err) = pilgrim(&args);
        assert_ne!(code, 0, "{set}");
        assert!(err.contains(says), "{set}: {err}");
        if failed.contains(&set) {
            let page = std::fs::read_to_string(out.join("report.html")).unwrap();
            assert!(page.contains("FAILED: no program was written"), "{set}");
            let r = report(&out);
            assert!(
                r["verdict"]["failures"][0]["message"].as_str().unwrap().contains(says),
                "{set}: {}",
                r["verdict"]
            );
            assert!(!out.join("program.nc").exists() && !out.join("program.cld").exists());
        } else {
            assert!(!out.exists(), "{set}: output written");
        }
    }
    assert!(pilgrim(&[
        "run",
        SCRIPT,
        "--out",
        s(&dir.join("x")),
        "--quiet",
        "--set",
        "spindle=400"
    ])
    .2
    .contains("needs axis Z at 12566.4 mm/min, above its maximum 10000 mm/min"));
    // An approach shorter than S1: the lead is out of the thread's
    // tolerance where the first pass's leading edge meets the face, and
    // the run says so, naming the pass; with a wider tolerance it runs,
    // warning of the error it causes.
    let out = dir.join("short_s1");
    let (code, _, err) = pilgrim(&["run", SCRIPT, "--out", s(&out), "--set", "s1=5"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("\"pass 1, start 1, rough, left")
            && err.contains(
                "the lead is 2.08% off where the leading cutting edge meets the worm's face"
            ),
        "{err}"
    );
    let (code, stdout, err) = pilgrim(&[
        "run",
        SCRIPT,
        "--out",
        s(&out),
        "--set",
        "s1=5",
        "--set",
        "tol_lead=0.025",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains("warning: S1 = 5.000 mm is below its minimum 6.247 mm: the lead is"),
        "{stdout}"
    );
}

/// The half width of `c`'s section at `h` above its tip on its left (-z)
/// or right side: the flank's line, or the nose's arc below the point where
/// the flank touches it (this test's own geometry of the rounded
/// trapezoid).
fn extent(c: &pilgrim_kernel::families::thread::ThreadCutter, h: f64, left: bool) -> f64 {
    let a = if left { c.left_angle } else { c.right_angle };
    let (w, r) = (c.tip_width / 2.0, c.nose_radius);
    if h >= r * (1.0 - a.sin()) {
        w + h * a.tan()
    } else {
        let centre = w - r * (1.0 - a.sin()) / a.cos();
        centre + (r * r - (r - h) * (r - h)).sqrt()
    }
}

/// The lead's error as a ratio after the carriage, a first-order servo of
/// time constant `t` commanded to `v`, has travelled `s` (docs/math.md §4.2):
/// `s = T V (-1 - ln a + a)`, solved for `a` by bisection.
fn lead_error_after(t: f64, v: f64, s: f64) -> f64 {
    let (mut lo, mut hi) = (1e-300f64, 1.0f64);
    for _ in 0..200 {
        let a = (lo * hi).sqrt();
        if t * v * (-1.0 - a.ln() + a) > s {
            lo = a;
        } else {
            hi = a;
        }
    }
    (lo * hi).sqrt()
}

/// S1 and S2 are lengths of the thread (docs/math.md §4.2): read back from
/// `program.nc`, every thread block's leading cutting edge at the blank's
/// radius meets the worm's face only after S1 of travel, and its trailing
/// edge leaves the far end of the thread at least S2 before the block ends
/// (and the X retract begins), on alternating and radial flanks and with a
/// universal cutter's side steps; the report's lead error where each
/// block's edge meets the face is the servo model's there. The default
/// worm's leading edge once met the face after 3.85 mm of run-up for S1 =
/// 6.25 mm (0.5 mm on radial flanks), its trailing edge still 0.67 mm inside
/// the worm when G32 ended.
#[test]
fn threads_run_at_full_lead_from_edge_to_edge() {
    for (name, sets) in [
        ("edges-alternating", vec![]),
        ("edges-radial", vec!["--set", "flank_order=radial"]),
        ("edges-universal", vec!["--set", "tip_width=2.0"]),
    ] {
        let (dir, out) = run_worm(name, &sets);
        let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
        let r = report(&out);
        let rpm = r["parameters"]["spindle"]["value"].as_f64().unwrap();
        let program = read_nc(&nc, rpm);
        let c = cutter(&out);
        let (t, lead, b1, r_a) = (0.033, 10.0 * std::f64::consts::PI, 60.0, 30.0);
        let v = lead * rpm / 60.0;
        let s1 = t * v * (-1.0 - 0.01f64.ln() + 0.01);
        let s2 = t * v;
        let sim = r["thread_verification"]["passes"].as_array().unwrap();
        let mut k = 0;
        for (i, b) in program.blocks.iter().enumerate() {
            if !matches!(b.motion, Motion::Thread { .. }) {
                continue;
            }
            let (z0, z1) = (program.blocks[i - 1].values[1], b.values[1]);
            let h = r_a - b.values[0] / 2.0;
            let leading = z0 - extent(&c, h, true);
            let trailing = z1 + extent(&c, h, false);
            assert!(
                leading >= s1 - 1e-9,
                "{name}: thread block {k}: the leading edge meets the face after {leading:.4} mm, S1 = {s1:.4} mm"
            );
            assert!(
                trailing <= -b1 - s2 + 1e-9,
                "{name}: thread block {k}: the trailing edge at z = {trailing:.4} when G32 ends, S2 = {s2:.4} mm beyond -{b1}"
            );
            let reported = sim[k]["face_lead_error"].as_f64().unwrap();
            let own = lead_error_after(t, v, leading);
            assert!(
                (reported - own).abs() < 1e-6 && reported <= 0.01,
                "{name}: block {k}: {reported} reported, {own} by the servo model"
            );
            k += 1;
        }
        assert_eq!(k, sim.len(), "{name}");
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// The simulation reads the program as the control does: the lead F as
/// written (31.4159 for 10 pi mm), so the lead's error over the thread is
/// that rounding's, 60 mm / lead of it (it had read the axis program's
/// exact lead and found none).
#[test]
fn the_replay_reads_the_lead_as_written() {
    let (dir, out) = run_worm("lead-as-written", &[]);
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    let f = nc
        .lines()
        .find(|l| l.starts_with("G32"))
        .and_then(|l| word(l, 'F'))
        .unwrap();
    let lead = 10.0 * std::f64::consts::PI;
    let want = (f - lead).abs() * 60.0 / lead;
    let r = report(&out);
    let got = r["thread_verification"]["lead_error"].as_f64().unwrap();
    assert!(want > 1e-5 && (got - want).abs() < 1e-9, "{got} vs {want}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `pilgrim export` places the cutter at another block and keeps the
/// run's verification in `report.json` and on the page (it had dropped
/// the worm's).
#[test]
fn export_keeps_the_verification() {
    let (dir, out) = run_worm("export", &[]);
    let before = report(&out);
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "20", "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let after = report(&out);
    assert_eq!(after["pose_block"], 20);
    assert_eq!(after["thread_verification"], before["thread_verification"]);
    assert!(
        after["thread_verification"]["passes"]
            .as_array()
            .unwrap()
            .len()
            > 10
    );
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        page.contains("Verification: the thread cut simulated"),
        "no verification on the page"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The process's rules on the worm's program: the default passes them (its
/// rapids go round the blank, 2 mm above the tip, and come in beyond the
/// face; every finishing pass takes 0.05 mm); a return along the worm
/// lowered to the root is a rapid through the stock, named by block.
#[test]
fn a_rapid_through_the_stock_is_refused() {
    let (dir, out) = run_worm("rapid", &[]);
    let program: AxisProgram =
        serde_json::from_str(&std::fs::read_to_string(out.join("program.json")).unwrap()).unwrap();
    let r = report(&out);
    assert_eq!(r["verdict"]["status"], "passed");
    let req = request(&r, 5.0, 2, 50.0, 60.0);
    let c = cutter(&out);
    use pilgrim_kernel::MachineKinematics;
    let errors = |p: &AxisProgram| {
        let check = simulate(p, &lathe(), &Default::default(), &c, &req).unwrap();
        let stock = pilgrim_kernel::families::thread::ThreadStock::new(&check, &req, &c);
        let limits = pilgrim_kernel::process::ProcessLimits::of(lathe().info());
        pilgrim_kernel::process::check(p, &lathe(), &Default::default(), Some(&stock), &limits)
            .unwrap()
    };
    let found = errors(&program);
    assert!(found.errors.is_empty(), "{:?}", found.errors);
    // The return to pass 2's start, along the worm at X60 + 4 (2 mm over
    // the tip), lowered to the root's diameter.
    let k = program
        .blocks
        .iter()
        .position(|b| {
            b.comment
                .as_deref()
                .is_some_and(|c| c.starts_with("pass 2,"))
        })
        .unwrap();
    let mut low = program.clone();
    low.blocks[k].values[0] = 38.0;
    let found = errors(&low);
    let name = pilgrim_kernel::program::block_name(&program, k);
    assert!(
        found
            .errors
            .iter()
            .any(|f| f.rule == pilgrim_kernel::process::RAPID
                && f.message
                    .starts_with(&format!("{name}: a rapid into the material"))),
        "{:?}",
        found.errors
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `passes.xlsx` read back with calamine: a sheet of passes (one row each,
/// the report's figures as numbers, units in the header), one of starts
/// (each start's finished profile against its nominal) and one of the
/// verification's figures.
pub(crate) fn check_workbook(out: &std::path::Path) {
    use calamine::{open_workbook, Data, Reader, Xlsx};
    let report = common::report_of(out);
    let v = &report["thread_verification"];
    let mut book: Xlsx<_> = open_workbook(out.join("passes.xlsx")).unwrap();
    assert_eq!(book.sheet_names(), ["passes", "starts", "figures"]);
    let number = |d: &Data| match d {
        Data::Float(f) => *f,
        Data::Int(i) => *i as f64,
        other => panic!("not a number: {other:?}"),
    };
    let passes = book.worksheet_range("passes").unwrap();
    let rows: Vec<&[Data]> = passes.rows().collect();
    // A sheet's column by its header.
    let column_of = |rows: &[&[Data]], name: &str| {
        let head: Vec<String> = rows[0].iter().map(|c| c.to_string()).collect();
        head.iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {head:?}"))
    };
    let col = |name: &str| column_of(&rows, name);
    let want = v["passes"].as_array().unwrap();
    assert_eq!(rows.len(), want.len() + 1);
    for (row, p) in rows[1..].iter().zip(want) {
        assert_eq!(number(&row[col("block")]), p["block"].as_f64().unwrap());
        assert_eq!(row[col("name")].to_string(), p["name"].as_str().unwrap());
        for (name, key) in [
            ("chip area (mm²)", "chip_area"),
            ("left flank load (mm²)", "left_area"),
            ("X (mm)", "x"),
            ("lead error at the face (ratio)", "face_lead_error"),
        ] {
            assert_eq!(number(&row[col(name)]), p[key].as_f64().unwrap(), "{name}");
        }
    }
    let starts = book.worksheet_range("starts").unwrap();
    let rows: Vec<&[Data]> = starts.rows().collect();
    let want = v["starts"].as_array().unwrap();
    assert_eq!(rows.len(), want.len() + 1);
    let at = |name: &str| column_of(&rows, name);
    let wires = v["over_wires_limits"].as_array();
    for (row, s) in rows[1..].iter().zip(want) {
        for (name, key) in [
            ("thickness (mm)", "thickness"),
            ("pitch diameter (mm)", "pitch_diameter"),
            ("root diameter (mm)", "root_diameter"),
            ("tip diameter (mm)", "tip_diameter"),
        ] {
            assert_eq!(number(&row[at(name)]), s[key].as_f64().unwrap(), "{name}");
        }
        if let Some(d) = s["functional_pitch_diameter"].as_f64() {
            assert_eq!(number(&row[at("functional pitch diameter (mm)")]), d);
        }
        if let Some(m) = s["over_wires"].as_f64() {
            assert_eq!(number(&row[at("over wires M (mm)")]), m);
            let m_limits = wires.expect("the over-wire limits");
            assert_eq!(
                number(&row[at("least M (mm)")]),
                m_limits[0].as_f64().unwrap()
            );
            assert_eq!(
                number(&row[at("greatest M (mm)")]),
                m_limits[1].as_f64().unwrap()
            );
        }
        for (k, side) in ["left", "right"].iter().enumerate() {
            let nominal = v["nominal_flanks_deg"][k].as_f64().unwrap();
            let got = number(&row[at(&format!("nominal {side} flank angle (deg)"))]);
            assert_eq!(got, nominal, "{side}");
        }
    }
    // Every column but the counts and the codes carries its unit.
    for sheet in ["passes", "starts"] {
        let range = book.worksheet_range(sheet).unwrap();
        let first = range.rows().next().unwrap();
        for h in first.iter().map(|c| c.to_string()) {
            let bare = [
                "block",
                "name",
                "start",
                "plan: pass",
                "plan: kind",
                "plan: flank",
                "plan: start",
            ];
            assert!(
                h.ends_with(')') || bare.contains(&h.as_str()),
                "{sheet}: {h}"
            );
        }
    }
    let figures = book.worksheet_range("figures").unwrap();
    let removed = figures
        .rows()
        .find(|r| r[0] == "area removed")
        .expect("the area removed");
    assert_eq!(number(&removed[1]), v["removed_area"].as_f64().unwrap());
    assert_eq!(removed[2].to_string(), "mm²");
}

/// The vertices of a run's STL (`worm.stl`, a body's; f32 binary), each
/// once per facet.
pub(crate) fn stl_vertices(path: &Path) -> Vec<[f64; 3]> {
    let stl = std::fs::read(path).unwrap();
    let facets = u32::from_le_bytes(stl[80..84].try_into().unwrap()) as usize;
    (0..facets)
        .flat_map(|f| {
            let stl = &stl;
            (0..3).map(move |k| {
                let o = 84 + 50 * f + 12 + 12 * k;
                [0, 1, 2].map(|j| {
                    f32::from_le_bytes(stl[o + 4 * j..o + 4 * j + 4].try_into().unwrap()) as f64
                })
            })
        })
        .collect()
}

/// Each flank vertex of a run's solid `part` (`worm.stl`) with its radius
/// within `band`, carried along the right-handed helix to the axial
/// section at angle 0: its radius and its distance along the axis from
/// the middle of its space (the spaces a pitch apart from the run's space
/// centre).
pub(crate) fn flank_points(out: &Path, part: &str, band: (f64, f64)) -> Vec<(f64, f64)> {
    let r = common::report_of(out);
    let note = |k: &str| r["notes"][k].as_f64();
    let (lead, c0) = (note("lead_mm").unwrap(), note("space_centre_mm").unwrap());
    let px = note("axial_pitch_mm").or(note("pitch_mm")).unwrap();
    stl_vertices(&out.join(part))
        .into_iter()
        .filter_map(|p| {
            let (rho, phi) = (p[0].hypot(p[1]), p[1].atan2(p[0]));
            (band.0..band.1).contains(&rho).then(|| {
                let u = p[2] - lead * phi / std::f64::consts::TAU;
                let d = (u - c0).rem_euclid(px);
                (rho, if d > px / 2.0 { d - px } else { d })
            })
        })
        .collect()
}

/// ZN and ZI worms (m 5, two starts, d1 50, alpha_n 20 deg) run from the
/// command line: each verified, and its finished solid's flanks what the
/// kind says, computed here from DIN 3975's definitions and not from the
/// kernel's curves. ZI: every flank vertex's distance from its space's
/// middle is the involute helicoid's, `s/2 + p (inv r - inv r1)` with
/// `inv r = sqrt(r^2/r_b^2 - 1) - acos(r_b / r)` and `cos gamma_b = cos
/// alpha_n cos gamma`, within 2 um; a straight flank on its tangent at
/// the pitch line would be 20 um off. ZN: each vertex carried along its
/// helix into the plane through its space's middle tilted by the lead
/// angle lies on a straight line at 20 deg there, within 2 um.
#[test]
fn zn_and_zi_worms_are_cut_on_their_flanks_curves() {
    use std::f64::consts::{PI, TAU};
    let (px, p, r1) = (PI * 5.0, 2.0 * PI * 5.0 / TAU, 25.0);
    let (an, gamma) = (20f64.to_radians(), (p / r1).atan());
    let half = px / 4.0;
    // ZI.
    let (_, out) = run_worm("zi", &["--set", "profile=ZI"]);
    let r = common::report_of(&out);
    assert_eq!(r["verdict"]["status"], "passed", "{}", r["verdict"]);
    let rb = p / (an.cos() * gamma.cos()).acos().tan();
    let inv = |r: f64| ((r / rb).powi(2) - 1.0).sqrt() - (rb / r).acos();
    let points = flank_points(&out, "worm.stl", (19.5, 29.5));
    assert!(points.len() > 1000, "{}", points.len());
    let tangent = p * (r1 * r1 - rb * rb).sqrt() / (r1 * rb);
    let (mut worst, mut straight) = (0.0f64, 0.0f64);
    for &(rho, d) in &points {
        worst = worst.max((d.abs() - (half + p * (inv(rho) - inv(r1)))).abs());
        straight = straight.max((d.abs() - (half + (rho - r1) * tangent)).abs());
    }
    assert!(
        worst < 2e-3,
        "ZI flanks {worst} mm off the involute helicoid"
    );
    assert!(straight > 0.02, "{straight}");
    let v = &r["thread_verification"];
    for s in v["starts"].as_array().unwrap() {
        assert!(
            (s["thickness"].as_f64().unwrap() - px / 2.0).abs() < 1e-3,
            "{s}"
        );
    }
    // ZN.
    let (_, out) = run_worm("zn", &["--set", "profile=ZN"]);
    let r = common::report_of(&out);
    assert_eq!(r["verdict"]["status"], "passed", "{}", r["verdict"]);
    let (st, ct) = (gamma.sin(), gamma.cos());
    // The plane holds the radial x and (0, -sin g, cos g): a point at
    // (r, 0, d) reaches it at the helix angle f where r sin f cos g + (d +
    // p f) sin g = 0; there its distance along the plane from the space's
    // middle is s and its radial coordinate x.
    let widths: Vec<f64> = flank_points(&out, "worm.stl", (19.5, 29.5))
        .into_iter()
        .map(|(rho, d)| {
            let g = |f: f64| rho * f.sin() * ct + (d + p * f) * st;
            let mut f = 0.0f64;
            for _ in 0..60 {
                f -= g(f) / (rho * f.cos() * ct + p * st);
            }
            let (x, s) = (rho * f.cos(), -rho * f.sin() * st + (d + p * f) * ct);
            // On a straight flank at alpha_n: |s| - (x - r1) tan alpha_n
            // is the half-width at x = r1, the same for every point.
            s.abs() - (x - r1) * an.tan()
        })
        .collect();
    assert!(widths.len() > 1000, "{}", widths.len());
    let (lo, hi) = widths
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &w| (a.min(w), b.max(w)));
    assert!(
        hi - lo < 2e-3,
        "ZN flanks spread {} mm in the normal plane",
        hi - lo
    );
    assert!((lo - half * gamma.cos()).abs() < 0.01, "{lo}");
}
