//! A corpus of programs written by hand as shops write them, from the
//! controls' documented examples (`tests/corpus/`), each beside its plain
//! twin (the same motion as plain blocks, written out from the rules the
//! control follows): Fanuc's two-block G76 (its depths by docs/math.md's
//! law, "Threading cycles"), G92's modal passes, a macro B loop, M98 into
//! the same file and into a file beside it. Every program verifies, with
//! the twin's figures exactly; what the reader refuses is refused naming
//! the construct, in the control's words.

use crate::common::{pilgrim, s, scratch};
use std::path::{Path, PathBuf};

/// The corpus's folder.
fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

/// `file` of the corpus verified on `machine` against `family` into a
/// folder of `dir`: the exit code, the message, the report.
fn verified(
    dir: &Path,
    file: &str,
    machine: &str,
    family: &str,
) -> (i32, String, serde_json::Value) {
    let out = dir.join(file.replace('/', "-"));
    let (code, _, err) = pilgrim(&[
        "verify",
        s(&corpus().join(file)),
        "--machine",
        machine,
        "--family",
        family,
        "--out",
        s(&out),
        "-q",
    ]);
    let report = std::fs::read_to_string(out.join("report.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or(serde_json::Value::Null);
    (code, err, report)
}

/// The figures of a verification: its family's section and the verdict,
/// without the names of passes and blocks (a comment names them, and a
/// twin's comments are its own) and the program's file.
fn figures(report: &serde_json::Value) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.retain(|k, _| !matches!(k.as_str(), "name" | "block_name" | "program_file"));
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            serde_json::Value::String(t) => {
                // A message names blocks by the program's own lines.
                *t = String::new();
            }
            _ => {}
        }
    }
    let mut v = serde_json::json!({
        "thread": report["thread_verification"],
        "verification": report["verification"],
        "status": report["verdict"]["status"],
    });
    strip(&mut v);
    v
}

/// `file` of the corpus refused on `machine` against `family`: exit 1, a
/// message that says `says`, and no Rust text in it.
fn refused(dir: &Path, file: &str, machine: &str, family: &str, says: &str) {
    let (code, err, _) = verified(dir, file, machine, family);
    assert_eq!(code, 1, "{file}: {err}");
    assert!(err.contains(says), "{file}: {err}");
    assert_eq!(crate::common::rust_text(&err), None, "{file}: {err}");
}

/// LinuxCNC program `program` of the corpus, with the axis program its
/// verification in `dir` read, left for CI's `rs274` check
/// (`.ci/rs274_check.py`: LinuxCNC's own interpreter must make its moves).
fn leave_for_rs274(dir: &Path, program: &str) {
    let exe = std::env::current_exe().unwrap();
    let name = Path::new(program).file_stem().unwrap().to_str().unwrap();
    let left = (exe.ancestors().nth(3).unwrap())
        .join("linuxcnc-check")
        .join(format!("corpus-{name}"));
    std::fs::create_dir_all(&left).unwrap();
    std::fs::copy(corpus().join(program), left.join("program.ngc")).unwrap();
    let read = dir.join(program.replace('/', "-")).join("program.json");
    std::fs::copy(read, left.join("program.json")).unwrap();
}

/// The Fanuc 0i-TC lathe with a LinuxCNC control, as a machine file in
/// `dir`.
fn linuxcnc_lathe(dir: &Path) -> PathBuf {
    let lathe = pilgrim_kernel::machine::machine_file(&fanuc_0i_tc::describe(), "its crate");
    let file = dir.join("linuxcnc-lathe.toml");
    std::fs::write(&file, crate::common::with_control(&lathe, "linuxcnc")).unwrap();
    file
}

/// `program` of the corpus and its plain `twin`, verified on `machine`
/// against `family`: both pass with the same figures and the same moves;
/// their reports.
fn as_twins(
    dir: &Path,
    program: &str,
    twin: &str,
    machine: &str,
    family: &str,
) -> (serde_json::Value, serde_json::Value) {
    let (code, err, report) = verified(dir, program, machine, family);
    assert_eq!(code, 0, "{program}: {err}");
    let (tcode, terr, treport) = verified(dir, twin, machine, family);
    assert_eq!(tcode, 0, "{twin}: {terr}");
    assert_eq!(figures(&report), figures(&treport), "{program}");
    assert_eq!(report["blocks"], treport["blocks"], "{program}");
    (report, treport)
}

/// `file` of the corpus verified on the Fanuc 0i-TC lathe against the
/// thread family's default (M20x2.5-6g), as [`verified`].
fn on_fanuc(dir: &Path, file: &str) -> (i32, String, serde_json::Value) {
    verified(dir, file, "fanuc-0i-tc", "scripts/thread.rhai")
}

/// `a` and `b` alike, every number within `tol`: `what` in the message.
fn alike(a: &serde_json::Value, b: &serde_json::Value, tol: f64, what: &str) {
    use serde_json::Value::{Array, Number, Object};
    match (a, b) {
        (Number(x), Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!((x - y).abs() <= tol, "{what}: {x} against {y}");
        }
        (Object(x), Object(y)) => {
            assert_eq!(x.len(), y.len(), "{what}: {x:?} against {y:?}");
            for (k, v) in x {
                alike(v, &y[k], tol, &format!("{what}.{k}"));
            }
        }
        (Array(x), Array(y)) => {
            assert_eq!(x.len(), y.len(), "{what}");
            for (i, (v, w)) in x.iter().zip(y).enumerate() {
                alike(v, w, tol, &format!("{what}[{i}]"));
            }
        }
        _ => assert_eq!(a, b, "{what}"),
    }
}

/// The Fanuc corpus on the 0i-TC lathe against the thread family's
/// default (M20x2.5-6g): each program and its twin verify, alike.
#[test]
fn fanuc_programs_verify_as_their_plain_twins() {
    let dir = scratch("corpus", "fanuc");
    for name in [
        "g76_m20",
        "g92_m20",
        "macro_while",
        "m98_same_file",
        "m98_beside",
    ] {
        let program = format!("fanuc/{name}.nc");
        let twin = format!("fanuc/{name}.plain.nc");
        let (code, err, report) = on_fanuc(&dir, &program);
        assert_eq!(code, 0, "{program}: {err}");
        let (tcode, terr, treport) = on_fanuc(&dir, &twin);
        assert_eq!(tcode, 0, "{twin}: {terr}");
        assert!(report["thread_verification"].is_object(), "{program}");
        assert_eq!(
            figures(&report),
            figures(&treport),
            "{program} and its twin"
        );
        assert_eq!(
            report["blocks"], treport["blocks"],
            "{program}: the moves the control makes"
        );
    }
}

/// A pass ends where the tool leaves the material, not only where a rapid
/// takes it away: M20x2.5's G32 passes each left at feed (`G01 X23.790
/// F500.`) and returned at feed above the thread (`Z2.562`) are the
/// thirteen cutting passes of the twin that leaves and returns in rapids,
/// with the same figures; the returns, clear of the material, cut nothing.
#[test]
fn a_return_at_feed_clear_of_the_material_is_no_pass() {
    let dir = scratch("corpus", "feed-return");
    let (code, err, report) = on_fanuc(&dir, "fanuc/g32_feed_return.nc");
    assert_eq!(code, 0, "{err}");
    let (tcode, terr, twin) = on_fanuc(&dir, "fanuc/g76_m20.plain.nc");
    assert_eq!(tcode, 0, "{terr}");
    assert_eq!(twin["cutting_passes"], 13);
    assert_eq!(report["cutting_passes"], twin["cutting_passes"]);
    assert_eq!(figures(&report), figures(&twin));
}

/// The verify page of a program that calls a subprogram beside it names,
/// for the moves the calls made, the file and lines they were read from
/// and the line of each call: `M98 P0102000` on line 10 runs O2000's four
/// moves (its lines 6 to 9) ten times, `M98 P0022000` on line 12 twice.
#[test]
fn the_verify_page_names_what_a_call_expanded() {
    let dir = scratch("corpus", "expanded");
    let (code, err, report) = on_fanuc(&dir, "fanuc/m98_beside.nc");
    assert_eq!(code, 0, "{err}");
    let page =
        std::fs::read_to_string(dir.join("fanuc-m98_beside.nc").join("report.html")).unwrap();
    assert!(page.contains("Expanded from cycles, loops and subprograms"));
    let rows: Vec<&str> = (page.lines())
        .filter(|l| l.starts_with("<tr data-block=") && l.contains("O2000.nc"))
        .collect();
    assert_eq!(rows.len(), 2, "{rows:?}");
    assert!(
        rows[0].contains("<td>40</td><td>O2000.nc lines 6 to 9, called at line 10</td>"),
        "{}",
        rows[0]
    );
    assert!(
        rows[1].contains("<td>8</td><td>O2000.nc lines 6 to 9, called at line 12</td>"),
        "{}",
        rows[1]
    );
    // The first call's moves follow the line before it, and the program's
    // blocks are every move the calls made.
    let first: usize = rows[0]["<tr data-block=\"".len()..]
        .split('"')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(
        first + 48 + 1,
        report["blocks"].as_u64().unwrap() as usize,
        "{}",
        report["blocks"]
    );
    crate::common::leave_page_for_chromium(&dir.join("fanuc-m98_beside.nc"), "corpus-m98-beside");
}

/// The Sinumerik corpus on the mandrel grinder: the default mandrel's
/// motion with its feeds in a `DEF REAL` local and an R parameter's
/// place, a jump over a block never run (`GOTOF` to a label), a counting
/// `WHILE` loop, the finishing pass a subprogram called by its name
/// (`FINISH.SPF` beside it, ended by `M17`): verified as its plain twin;
/// arcs by their radius and angle and a switch to diameter programming
/// among the moves (both in exact stop, G60), as their twin by the arcs'
/// centres; the continuous-path mode G64 refused.
#[test]
fn sinumerik_programs_verify_as_their_plain_twins() {
    let dir = scratch("corpus", "sinumerik");
    let (code, err, report) = verified(
        &dir,
        "sinumerik/mandrel_r.mpf",
        "3K152VF20",
        "scripts/mandrel.rhai",
    );
    assert_eq!(code, 0, "{err}");
    let (tcode, terr, treport) = verified(
        &dir,
        "sinumerik/mandrel.plain.mpf",
        "3K152VF20",
        "scripts/mandrel.rhai",
    );
    assert_eq!(tcode, 0, "{terr}");
    assert!(report["verification"].is_object());
    assert_eq!(figures(&report), figures(&treport));
    assert_eq!(report["blocks"], treport["blocks"]);
    // The approach as arcs (G3 by its radius CR= and by its opening angle
    // AR=; the twin by its centre I, K) and, in the third, the approach
    // and the second pass on diameter (DIAMON, then DIAMOF again). The
    // centres the twin writes to 4 decimals differ from those the radius
    // and the angle give by that rounding, which moves every later move's
    // time by nanoseconds: the figures agree within 0.01 um.
    let (_, terr, arcs_twin) = verified(
        &dir,
        "sinumerik/mandrel_arcs.plain.mpf",
        "3K152VF20",
        "scripts/mandrel.rhai",
    );
    assert!(arcs_twin["verification"].is_object(), "{terr}");
    for program in ["sinumerik/mandrel_arcs.mpf", "sinumerik/mandrel_diamon.mpf"] {
        let (code, err, report) = verified(&dir, program, "3K152VF20", "scripts/mandrel.rhai");
        assert_eq!(code, 0, "{program}: {err}");
        assert_eq!(report["blocks"], arcs_twin["blocks"], "{program}");
        alike(&figures(&report), &figures(&arcs_twin), 1e-5, program);
    }
    // The arcs are more moves than the plain program's, the same passes.
    assert!(arcs_twin["blocks"].as_u64() > report["blocks"].as_u64());
    for (file, says) in [
        ("sinumerik/refused/cycle97.mpf", "CYCLE97: a Siemens cycle"),
        ("sinumerik/refused/system_variable.mpf", "a system variable"),
        (
            "sinumerik/refused/r_unset.mpf",
            "R7 is read before the program sets it",
        ),
        ("sinumerik/refused/no_subprogram.mpf", "no file CONTOUR.SPF"),
        (
            "sinumerik/refused/arc_off_circle.mpf",
            "N30: G3: the end is 100.0523 mm from the centre I, K",
        ),
        (
            "sinumerik/refused/arc_i_on_diameter.mpf",
            "G3 with I under diameter programming",
        ),
        (
            "sinumerik/refused/g64.mpf",
            "N1: G64 (continuous-path mode, its corners blended off the programmed points on sinumerik)",
        ),
    ] {
        refused(&dir, file, "3K152VF20", "scripts/mandrel.rhai", says);
    }
}

/// What the reader refuses, it refuses by name: the construct, its line
/// or block, why; never a Rust type or debug text.
#[test]
fn what_is_not_read_is_refused_by_name() {
    let dir = scratch("corpus", "refused");
    for (file, says) in [
        (
            "fanuc/refused/g76_second_alone.nc",
            "G76's second block before its first",
        ),
        ("fanuc/refused/endless.nc", "loop turns"),
        (
            "fanuc/refused/system_variable.nc",
            "#5001: a system variable",
        ),
        ("fanuc/refused/m99_main.nc", "M99 in the main program"),
        (
            "fanuc/refused/common_unset.nc",
            "#100 is read before the program sets it",
        ),
        ("fanuc/refused/goto_twice.nc", "stands on 2 lines"),
        ("fanuc/refused/recursion.nc", "calls nested deeper than 16"),
        (
            "fanuc/refused/nose_radius.nc",
            "G42 (tool nose radius compensation right",
        ),
    ] {
        refused(&dir, file, "fanuc-0i-tc", "scripts/thread.rhai", says);
    }
}

/// `text` (a program in the dialect whose comments open with `open`)
/// without its comments: a comment line goes, a comment after a block's
/// words is cut off.
fn uncommented(text: &str, open: &str, close: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let code = match (line.find(open), close.is_empty()) {
            (Some(p), true) => &line[..p],
            (Some(p), false) => {
                let end = line[p..].find(close).map_or(line.len(), |q| p + q + 1);
                // Fanuc's `O0001 (NAME)`: the number stays.
                let (a, b) = (&line[..p], &line[end..]);
                if a.trim().is_empty() && b.trim().is_empty() {
                    ""
                } else {
                    out.push_str(a.trim_end());
                    out.push_str(b);
                    out.push('\n');
                    continue;
                }
            }
            (None, _) => line,
        };
        if !code.trim().is_empty() || line.starts_with('%') {
            out.push_str(code.trim_end());
            out.push('\n');
        }
    }
    out
}

/// The default jobs' programs with every comment taken out verify with
/// the program's own figures and the same passes: the passes are the
/// motion's, the comments only name them.
#[test]
fn the_default_programs_without_comments_verify_alike() {
    for (job, file, machine, open, close) in [
        ("mandrel", "program.mpf", "3K152VF20", ";", ""),
        ("caliber", "program.mpf", "Mannesmann", ";", ""),
        ("worm", "program.nc", "fanuc-0i-tc", "(", ")"),
        ("thread", "program.nc", "fanuc-0i-tc", "(", ")"),
    ] {
        let run = crate::common::default_run("corpus", job, &format!("bare-{job}"));
        let text = std::fs::read_to_string(run.join(file)).unwrap();
        let bare = uncommented(&text, open, close);
        assert!(!bare.contains(open), "{job}: {bare}");
        let dir = run.parent().unwrap();
        let verify = |name: &str, text: &str| {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            let out = dir.join(format!("{name}.verify"));
            let family = format!("scripts/{job}.rhai");
            let (code, _, err) = pilgrim(&[
                "verify",
                s(&path),
                "--machine",
                machine,
                "--family",
                &family,
                "--out",
                s(&out),
                "-q",
            ]);
            assert_eq!(code, 0, "{job} {name}: {err}");
            let report: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                    .unwrap();
            report
        };
        let ext = file.rsplit('.').next().unwrap();
        let own = verify(&format!("OWN.{ext}"), &text);
        let stripped = verify(&format!("BARE.{ext}"), &bare);
        let section = ["verification", "groove_verification", "thread_verification"]
            .into_iter()
            .find(|k| own.get(k).is_some())
            .unwrap();
        let strip = |r: &serde_json::Value| {
            let mut r = serde_json::json!({ "v": r[section], "verdict": r["verdict"]["status"] });
            fn names_out(v: &mut serde_json::Value) {
                match v {
                    serde_json::Value::Object(m) => {
                        m.remove("name");
                        m.values_mut().for_each(names_out);
                    }
                    serde_json::Value::Array(a) => a.iter_mut().for_each(names_out),
                    serde_json::Value::String(t) => t.clear(),
                    _ => {}
                }
            }
            names_out(&mut r);
            r
        };
        assert_eq!(strip(&own), strip(&stripped), "{job}: the figures");
        for key in ["cutting_passes", "blocks"] {
            assert_eq!(own[key], stripped[key], "{job}: {key}");
        }
    }
}

/// The LinuxCNC corpus on the lathe with a LinuxCNC control: o-word
/// subroutines, `while`, `if`, `do`/`while`, `repeat`, numbered and named
/// parameters (`##30`, `#<depth>`), each verified as its plain twin; each
/// left for CI, where LinuxCNC's own `rs274` must make the moves the
/// reader read (`.ci/rs274_check.py`).
#[test]
fn linuxcnc_programs_verify_as_their_plain_twins_and_as_rs274_reads_them() {
    let dir = scratch("corpus", "linuxcnc");
    let lathe = pilgrim_kernel::machine::machine_file(&fanuc_0i_tc::describe(), "its crate");
    let machine = dir.join("linuxcnc-lathe.toml");
    std::fs::write(&machine, crate::common::with_control(&lathe, "linuxcnc")).unwrap();
    for name in ["osub_while", "repeat_params"] {
        let program = format!("linuxcnc/{name}.ngc");
        let twin = format!("linuxcnc/{name}.plain.ngc");
        let (code, err, report) = verified(&dir, &program, s(&machine), "scripts/thread.rhai");
        assert_eq!(code, 0, "{program}: {err}");
        let (tcode, terr, treport) = verified(&dir, &twin, s(&machine), "scripts/thread.rhai");
        assert_eq!(tcode, 0, "{twin}: {terr}");
        assert_eq!(
            figures(&report),
            figures(&treport),
            "{program} and its twin"
        );
        leave_for_rs274(&dir, &program);
    }
}

/// A dwell (`G4`) in each control's own units: Fanuc's P in milliseconds,
/// X with its point in seconds, U without one in the least input
/// increment (0.001 s); Sinumerik's F in seconds and S in turns of the
/// spindle; LinuxCNC's P in seconds (left for CI's `rs274`, whose DWELL
/// calls must be the blocks' dwells). Each program verifies as its twin
/// without the dwells, with the same moves, and its programmed time is the
/// twin's and the dwells' seconds; the time with the axes' acceleration
/// is longer by at least as much (the axes stop before a dwell). Fanuc's
/// refusals: a point in P, a move in the dwell's block, a dwell with no
/// move after it.
#[test]
fn dwells_stand_for_their_time_in_each_controls_units() {
    let dir = scratch("corpus", "dwell");
    let linuxcnc = linuxcnc_lathe(&dir);
    let thread = "scripts/thread.rhai";
    for (program, twin, machine, family, seconds) in [
        (
            "fanuc/g92_dwell.nc",
            "fanuc/g92_m20.plain.nc",
            "fanuc-0i-tc",
            thread,
            1.5 + 0.5 + 0.25,
        ),
        (
            "sinumerik/mandrel_dwell.mpf",
            "sinumerik/mandrel.plain.mpf",
            "3K152VF20",
            "scripts/mandrel.rhai",
            2.0 + 10.0 * 60.0 / 399.0,
        ),
        (
            "linuxcnc/osub_dwell.ngc",
            "linuxcnc/osub_while.plain.ngc",
            s(&linuxcnc),
            thread,
            1.5 + 12.0 * 0.25,
        ),
    ] {
        let (report, treport) = as_twins(&dir, program, twin, machine, family);
        let minutes = |r: &serde_json::Value, k: &str| r["times"][k].as_f64().unwrap();
        let programmed = minutes(&report, "programmed_min") - minutes(&treport, "programmed_min");
        assert!(
            (programmed * 60.0 - seconds).abs() < 1e-9,
            "{program}: {} s for dwells of {seconds} s",
            programmed * 60.0
        );
        let accelerated =
            minutes(&report, "accelerated_min") - minutes(&treport, "accelerated_min");
        assert!(
            accelerated * 60.0 >= seconds - 1e-9,
            "{program}: {accelerated}"
        );
    }
    leave_for_rs274(&dir, "linuxcnc/osub_dwell.ngc");
    for (file, says) in [
        (
            "fanuc/refused/dwell_point_in_p.nc",
            "line 7: P1.5: a decimal point in a dwell of milliseconds",
        ),
        (
            "fanuc/refused/dwell_with_move.nc",
            "Z5.0: another word in a dwell's block, which holds only G4 and its time (X, U or P on fanuc)",
        ),
        (
            "fanuc/refused/dwell_last.nc",
            "line 23: a dwell of 2 s after the last move",
        ),
    ] {
        refused(&dir, file, "fanuc-0i-tc", thread, says);
    }
}

/// The blocks (from 0) of the program a verification in `dir`'s folder
/// `out` read that set the spindle's speed, with the speed (rpm), and the
/// program's blocks.
fn read_speeds(dir: &Path, out: &str) -> (Vec<(usize, f64)>, usize) {
    let text = std::fs::read_to_string(dir.join(out).join("program.json")).unwrap();
    let program: serde_json::Value = serde_json::from_str(&text).unwrap();
    let blocks = program["blocks"].as_array().unwrap();
    let set = (blocks.iter().enumerate())
        .filter_map(|(k, b)| Some((k, b["spindle"].as_f64()?)))
        .collect();
    (set, blocks.len())
}

/// Constant surface speed (`G96`, S in m/min) as each control clamps it:
/// Fanuc's `G50 S`, LinuxCNC's `D` in the G96 block, Sinumerik's `LIMS=`.
/// Each program verifies as its twin, the same moves at the speeds in rpm
/// written out by hand (`1000 v / (pi D)`, D the diameter a rapid ends
/// at, the larger a cut passes, within the clamp); the speeds it reads
/// are the formula's to the last bit, set where they change: a face at
/// 150 m/min turns 1193.66 rpm at D40 and stays there cutting to D30, the
/// rapid to D24 is held at 1800; the mandrel's approach and retraction at
/// X100 (on radius, D200) turn 127.32 rpm at 80 m/min, every pass at
/// LIMS=399. Refused: a thread under G96, G97 after it without its S, G50
/// with an axis (a coordinate system setting).
#[test]
fn constant_surface_speed_turns_as_each_control_clamps_it() {
    let dir = scratch("corpus", "g96");
    let linuxcnc = linuxcnc_lathe(&dir);
    let thread = "scripts/thread.rhai";
    let rpm = |v: f64, d: f64| 1000.0 * v / (std::f64::consts::PI * d);
    let face = rpm(150.0, 40.0);
    for (program, twin, machine, family, speeds) in [
        (
            "fanuc/g96_face.nc",
            "fanuc/g96_face.plain.nc",
            "fanuc-0i-tc",
            thread,
            vec![(0, face), (2, 1800.0), (4, 300.0)],
        ),
        (
            "linuxcnc/osub_g96.ngc",
            "linuxcnc/osub_g96.plain.ngc",
            s(&linuxcnc),
            thread,
            // Its first pass goes straight to its depth.
            vec![(0, face), (2, 1800.0), (3, 300.0)],
        ),
        (
            "sinumerik/mandrel_g96.mpf",
            "sinumerik/mandrel.plain.mpf",
            "3K152VF20",
            "scripts/mandrel.rhai",
            // The last but one block the retraction to X100.
            vec![
                (0, rpm(80.0, 200.0)),
                (2, 399.0),
                (usize::MAX, rpm(80.0, 200.0)),
            ],
        ),
    ] {
        as_twins(&dir, program, twin, machine, family);
        let (read, n) = read_speeds(&dir, &program.replace('/', "-"));
        let want: Vec<(usize, f64)> = (speeds.iter())
            .map(|&(k, v)| (if k == usize::MAX { n - 2 } else { k }, v))
            .collect();
        assert_eq!(read, want, "{program}");
        if program.ends_with(".ngc") {
            leave_for_rs274(&dir, program);
        }
    }
    for (file, says) in [
        (
            "fanuc/refused/g96_thread.nc",
            "line 15: a threading cycle (G92) before constant spindle speed (G97)",
        ),
        (
            "fanuc/refused/g97_without_s.nc",
            "line 15: G97 after G96 without S",
        ),
        (
            "fanuc/refused/g50_axis.nc",
            "line 7: G50 with an axis: a coordinate system setting",
        ),
    ] {
        refused(&dir, file, "fanuc-0i-tc", thread, says);
    }
}

/// What finds Rust's text in a message finds the examples and
/// passes the control's words.
#[test]
fn rust_text_is_found_where_it_is() {
    use crate::common::rust_text;
    for (m, found) in [
        (
            "not G-code: Some(Unexpected { actual: \"C\" }) in 'N3000'",
            "Some(",
        ),
        ("Some(UnknownContent { text: \"=\" })", "Some("),
        ("expected [Number], got Unexpected { .. }", "Unexpected {"),
        ("pilgrim_kernel::program::Error", "::"),
        ("the value was None", "None"),
        ("Err(\"x\")", "Err("),
    ] {
        assert_eq!(rust_text(m), Some(found), "{m}");
    }
    for m in [
        "N30: G3: the end is 100.0523 mm from the centre I, K",
        "#5001: a system variable (the control's own)",
        "M99 in the main program (Fanuc: a return)",
        "Nonexistent words: none; Noneless",
        "at 10:30 (local) it ran",
    ] {
        assert_eq!(rust_text(m), None, "{m}");
    }
}

/// The one-block G76 (`G76 X Z I K D A P F`) on a Haas lathe, whose
/// control takes the least cut, the finishing allowance and the chamfer
/// from its settings, which the machine file states: the 0i-TC's two-block
/// cycle of M20x2.5-6g written in one block (its one finishing pass, where
/// the two-block form wrote two), verified as its G32 twin; alternating
/// edges (P2) refused by name, and so is the cycle on a machine that does
/// not state its settings.
#[test]
fn a_one_block_g76_verifies_as_its_plain_twin() {
    let dir = scratch("corpus", "haas");
    let lathe = pilgrim_kernel::machine::machine_file(&fanuc_0i_tc::describe(), "its crate");
    let haas = crate::common::with_control(&lathe, "haas");
    let bare = dir.join("haas-bare.toml");
    std::fs::write(&bare, &haas).unwrap();
    let machine = dir.join("haas-lathe.toml");
    let settings = "[constants]\nthread_min_cut = 0.05\nthread_finish_allowance = 0.03\nthread_chamfer_leads = 0.0\nthread_chamfer_deg = 45.0\n";
    assert!(haas.contains("[constants]\n"));
    std::fs::write(&machine, haas.replacen("[constants]\n", settings, 1)).unwrap();
    let (code, err, report) = verified(&dir, "haas/g76_m20.nc", s(&machine), "scripts/thread.rhai");
    assert_eq!(code, 0, "{err}");
    let (tcode, terr, treport) = verified(
        &dir,
        "haas/g76_m20.plain.nc",
        s(&machine),
        "scripts/thread.rhai",
    );
    assert_eq!(tcode, 0, "{terr}");
    assert!(report["thread_verification"].is_object());
    assert_eq!(figures(&report), figures(&treport));
    assert_eq!(report["blocks"], treport["blocks"]);
    for (file, on, says) in [
        (
            "haas/refused/alternating.nc",
            &machine,
            "G76 P2: alternating edges",
        ),
        (
            "haas/g76_m20.nc",
            &bare,
            "give thread_min_cut (the least depth a roughing pass adds (mm)), thread_finish_allowance",
        ),
    ] {
        let apart = dir.join(on.file_stem().unwrap());
        std::fs::create_dir_all(&apart).unwrap();
        refused(&apart, file, s(on), "scripts/thread.rhai", says);
    }
}
