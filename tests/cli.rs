//! The `pilgrim` program, run as a user runs it.

use std::path::{Path, PathBuf};

use crate::common;
use common::shared_lib as lib;
use common::{pilgrim, s};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    common::scratch("cli", name)
}

/// The machine file of the built-in `name`, as `pilgrim machines --toml`
/// writes it.
fn builtin_source(name: &str) -> String {
    let (code, out, err) = pilgrim(&["machines", "--toml", name]);
    assert_eq!(code, 0, "{err}");
    out
}

const DEMO: &str = "scripts/examples/mill_circle.rhai";

#[test]
fn version_and_machines() {
    let (code, out, _) = pilgrim(&["--version"]);
    assert_eq!(code, 0);
    assert!(
        out.starts_with(&format!("pilgrim {}", env!("CARGO_PKG_VERSION"))),
        "{out}"
    );
    let (code, out, _) = pilgrim(&["machines"]);
    assert_eq!(code, 0);
    for name in [
        "3K152VF20  (sinumerik), built-in plugin",
        "LZ-250",
        "Mannesmann",
        "fanuc-0i-tc",
        "vertical-mill",
    ] {
        assert!(out.contains(name), "{name} missing:\n{out}");
    }
    assert!(
        out.contains("U   linear   [0, 150] mm, up to 2000 mm/min [moves the rest]"),
        "{out}"
    );
    assert!(out.contains("A   rotary   [-370, 370] deg"), "{out}");
    let grinder = lib("grinder_3k152vf20");
    let (code, out, _) = pilgrim(&["machines", "--only-files", "--plugin", s(&grinder)]);
    assert_eq!(code, 0);
    assert!(
        out.contains("3K152VF20  (sinumerik), plugin") && !out.contains("LZ-250"),
        "{out}"
    );
}

#[test]
fn machine_file_errors_name_file_and_line() {
    let dir = scratch("machines");
    let text = builtin_source("fanuc-0i-tc");
    let good = dir.join("lathe.toml");
    std::fs::write(&good, text.replace("fanuc-0i-tc", "my-lathe")).unwrap();
    let (code, out, _) = pilgrim(&["machines", "--only-files", "--file", s(&good)]);
    assert_eq!(code, 0);
    assert!(
        out.contains("my-lathe") && !out.contains("3K152VF20"),
        "{out}"
    );
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text.replace("max_feed = 12000.0", "max_feed = -1.0")).unwrap();
    let (code, _, err) = pilgrim(&["machines", "--file", s(&bad)]);
    assert_eq!(code, 1);
    assert!(
        err.contains("bad.toml:") && err.contains("axis X: the maximum feed must be > 0"),
        "{err}"
    );
    let (code, _, err) = pilgrim(&["machines", "--file", "/no/such.toml"]);
    assert_eq!(code, 1);
    assert!(err.contains("/no/such.toml"), "{err}");
    let (code, _, _) = pilgrim(&["frobnicate"]);
    assert_eq!(code, 2);
}

const FILES: [&str; 11] = [
    "toolpath.json",
    "program.json",
    "program.mpf",
    "program.cld",
    "report.json",
    "part.stl",
    "cutter.stl",
    "scene.glb",
    "part.step",
    "cutter.step",
    "report.html",
];

#[test]
fn demo_writes_every_file_and_the_same_bytes_twice() {
    let dir = scratch("demo");
    let (a, b) = (dir.join("a"), dir.join("b"));
    for out in [&a, &b] {
        let (code, stdout, err) = pilgrim(&["run", DEMO, "--out", s(out)]);
        assert_eq!(code, 0, "{err}");
        assert!(stdout.contains("368 blocks for vertical-mill"), "{stdout}");
    }
    for f in FILES {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(!x.is_empty(), "{f} empty");
        assert_eq!(x, y, "{f} differs between two runs");
    }
    let mpf = std::fs::read_to_string(a.join("program.mpf")).unwrap();
    assert!(
        mpf.starts_with("%_N_MILL_CIRCLE_MPF\n;$PATH=/_N_MPF_DIR\n"),
        "{mpf}"
    );
    assert!(
        mpf.contains(
            "N5 M8\n; start\nN10 G0 Z50.000\nN20 X45.000 Y0.000 C0.000\n; approach\nN30 Z5.000\n"
        ) && mpf.ends_with("; end\nN3680 Z50.000\nN3690 M9\nN3700 M5\nN3710 M30\n"),
        "{mpf}"
    );
    let report: serde_json::Value = common::report_of(&a);
    assert_eq!(report["blocks"], 368);
    // The demo declares no verification, and its page says so first.
    assert_eq!(report["verdict"]["status"], "not_verified");
    let page = std::fs::read_to_string(a.join("report.html")).unwrap();
    assert!(page.contains("<b>NOT VERIFIED: the family declares no verification"));
    assert_eq!(report["parameters"]["radius"]["value"], 40.0);
    // The disc and the cutter, placed at the middle of the last cutting pass
    // (the contour, blocks 6..=366 at C = 0..=360 deg, after the machine's
    // two start blocks): block 186, C = 180 deg.
    assert_eq!(report["pose_block"], 186);
    let disc = pilgrim_kernel::mesh::read_stl(&a.join("part.stl")).unwrap();
    disc.check_closed().unwrap();
    let exact = std::f64::consts::PI * 40.0 * 40.0 * 10.0;
    assert!(
        (exact - disc.volume()).abs() < 0.01 * exact,
        "{}",
        disc.volume()
    );
    let cutter = pilgrim_kernel::mesh::read_stl(&a.join("cutter.stl")).unwrap();
    cutter.check_closed().unwrap();
    let (lo, hi) = cutter.bounds();
    // On the contour at C = 180 deg: the tip 5 mm below the top face, the
    // axis at (-45, 0).
    assert!(
        (lo[2] + 5.0).abs() < 1e-4
            && (0.5 * (lo[0] + hi[0]) + 45.0).abs() < 1e-3
            && (0.5 * (lo[1] + hi[1])).abs() < 1e-3,
        "{lo:?} {hi:?}"
    );
    common::leave_for_checkers(&a, "demo");
    // The exact solids: the disc and the end mill (a cylinder as deep as
    // three depths), their volumes exact.
    let param = |n: &str| report["parameters"][n]["value"].as_f64().unwrap();
    let cutter =
        std::f64::consts::PI * (param("tool_diameter") / 2.0).powi(2) * 3.0 * param("depth");
    for (name, v) in [("part", exact), ("cutter", cutter)] {
        let solid = report["solids"]
            .as_array()
            .unwrap()
            .iter()
            .find(|b| b["name"] == name)
            .unwrap();
        assert!(
            (solid["volume_mm3"].as_f64().unwrap() - v).abs() < 1e-3,
            "{name}"
        );
        common::leave_step_for_freecad(&a, "demo", name, v, 1e-6 * v);
    }
    // Export at another block: block 202 is the contour point at C = 196 deg
    // (block 6 is C = 0).
    let (code, out, err) = pilgrim(&["export", s(&a), "--block", "202"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("block 202"), "{out}");
    let moved = pilgrim_kernel::mesh::read_stl(&a.join("cutter.stl")).unwrap();
    let (lo, hi) = moved.bounds();
    let c = 196f64.to_radians();
    let (cx, cy) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
    assert!(
        (cx - 45.0 * c.cos()).abs() < 0.01 && (cy - 45.0 * c.sin()).abs() < 0.01,
        "{cx} {cy}"
    );
    assert!((lo[2] + 5.0).abs() < 1e-4);
    assert_eq!(
        std::fs::read(a.join("part.stl")).unwrap(),
        std::fs::read(b.join("part.stl")).unwrap()
    );
    let report: serde_json::Value = common::report_of(&a);
    assert_eq!(report["pose_block"], 202);
    // The cutter's solid moved with it; the part's did not.
    let step = |d: &std::path::Path, f: &str| std::fs::read(d.join(f)).unwrap();
    assert_ne!(step(&a, "cutter.step"), step(&b, "cutter.step"));
    assert_eq!(step(&a, "part.step"), step(&b, "part.step"));
    assert_eq!(report["solids"].as_array().unwrap().len(), 2);
    common::leave_for_checkers(&a, "demo-block200");
    // The page shows the scene as exported (its data URI is the new
    // scene.glb).
    common::check_page(&a, "program.mpf", 6.0);
    // It plays the run's program at the run's times: the program as its
    // control reads it.
    assert_eq!(common::Playback::of(&a).keys, common::Playback::of(&b).keys);
    common::leave_page_for_chromium(&a, "demo-block202");
    // On request: ASCII STL, and .gltf with its .bin.
    let c = dir.join("c");
    let (code, _, err) = pilgrim(&["run", DEMO, "--stl-ascii", "--gltf", "--out", s(&c)]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(c.join("part.stl")).unwrap();
    assert!(text.starts_with("solid part\n"), "{}", &text[..40]);
    pilgrim_kernel::mesh::read_stl(&c.join("part.stl"))
        .unwrap()
        .check_closed()
        .unwrap();
    let gltf_doc = gltf::Gltf::from_slice(&std::fs::read(c.join("scene.gltf")).unwrap()).unwrap();
    assert_eq!(
        gltf_doc.buffers().next().unwrap().length(),
        std::fs::read(c.join("scene.bin")).unwrap().len()
    );
    let exe = std::env::current_exe().unwrap();
    let check = exe.ancestors().nth(3).unwrap().join("mesh-check");
    for f in ["scene.gltf", "scene.bin"] {
        std::fs::copy(c.join(f), check.join(f)).unwrap();
    }
    // A parameter file and --set, a TOML machine and a Rhai machine.
    let params = dir.join("p.toml");
    std::fs::write(&params, "radius = 30.0\npoints = 36\n").unwrap();
    let toml_machine = dir.join("mill.toml");
    std::fs::write(&toml_machine, builtin_source("vertical-mill")).unwrap();
    let (code, out, err) = pilgrim(&[
        "run",
        DEMO,
        "--params",
        s(&params),
        "--set",
        "turn_table=false",
        "--machine",
        s(&toml_machine),
        "--out",
        s(&a),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("44 blocks"), "{out}");
    let rhai_machine = dir.join("mill.rhai");
    std::fs::write(
        &rhai_machine,
        r#"fn machine() {
    let lin = |n, v| #{ name: n, kind: "linear", min: -v, max: v, max_feed: 5000.0, moves: [0.0, 0.0, 0.0] };
    let x = lin.call("X", 300.0); x.moves = [1.0, 0.0, 0.0];
    let y = lin.call("Y", 300.0); y.moves = [0.0, 1.0, 0.0];
    let z = lin.call("Z", 300.0); z.moves = [0.0, 0.0, 1.0];
    let c = #{ name: "C", kind: "rotary", min_deg: -720.0, max_deg: 720.0, max_feed_deg: 3600.0, turns: [0.0, 0.0, 1.0] };
    #{ name: "scripted-mill", control: "fanuc", axes: [x, y, z, c],
       chain: [#{ factor: "rz", axis: "C" }, #{ factor: "tx", axis: "X" }, #{ factor: "ty", axis: "Y" }, #{ factor: "tz", axis: "Z" }] }
}"#,
    )
    .unwrap();
    let (code, out, err) = pilgrim(&[
        "run",
        DEMO,
        "--machine",
        s(&rhai_machine),
        "--out",
        s(&b),
        "--quiet",
        "--program-number",
        "1",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.is_empty());
    let nc = std::fs::read_to_string(b.join("program.nc")).unwrap();
    assert!(nc.starts_with("%\nO0001 (MILL_CIRCLE)\n"), "{nc}");
}

#[test]
fn bad_input_is_refused_and_nothing_is_written() {
    let dir = scratch("bad");
    let out = dir.join("out");
    let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&out)]);
    assert_eq!(code, 0, "{err}");
    let before: Vec<Vec<u8>> = FILES
        .iter()
        .map(|f| std::fs::read(out.join(f)).unwrap())
        .collect();
    // An unknown parameter lists the valid names.
    let (code, _, err) = pilgrim(&["run", DEMO, "--set", "radious=3", "--out", s(&out)]);
    assert_eq!(code, 1);
    assert!(err.contains("unknown parameter 'radious' from --set (parameters: clearance, depth, feed, points, radius"), "{err}");
    // A block outside travel: X would reach 505 mm on a 400 mm axis.
    let (code, _, err) = pilgrim(&[
        "run",
        DEMO,
        "--set",
        "radius=500",
        "--set",
        "turn_table=false",
        "--out",
        s(&out),
    ]);
    assert_eq!(code, 1);
    assert!(
        err.contains(
            "N30 in \"approach\": axis X would need 505.0000 mm, outside its travel [-400, 400] mm"
        ),
        "{err}"
    );
    // A syntax error names file, line and column.
    let broken = dir.join("broken.rhai");
    std::fs::write(
        &broken,
        "fn params() { #{} }\nfn toolpath(p) {\n  let x = 1 +;\n}\n",
    )
    .unwrap();
    let (code, _, err) = pilgrim(&[
        "run",
        s(&broken),
        "--machine",
        "vertical-mill",
        "--out",
        s(&out),
    ]);
    assert_eq!(code, 1);
    assert!(err.contains("broken.rhai:3:"), "{err}");
    // The first output is untouched, and no temporary directory is left.
    let after: Vec<Vec<u8>> = FILES
        .iter()
        .map(|f| std::fs::read(out.join(f)).unwrap())
        .collect();
    assert_eq!(before, after);
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name())
        .collect();
    assert_eq!(leftovers.len(), 2, "{leftovers:?}");
    // A tolerance that is not positive, a pose block beyond the program.
    let (code, _, err) = pilgrim(&["run", DEMO, "--mesh-tolerance", "0", "--out", s(&out)]);
    assert_eq!(code, 1);
    assert!(err.contains("chordal tolerance must be > 0"), "{err}");
    let (code, _, err) = pilgrim(&["run", DEMO, "--pose-block", "9999", "--out", s(&out)]);
    assert_eq!(code, 1);
    assert!(
        err.contains("block 9999 is beyond the program's 368 blocks"),
        "{err}"
    );
    let after: Vec<Vec<u8>> = FILES
        .iter()
        .map(|f| std::fs::read(out.join(f)).unwrap())
        .collect();
    assert_eq!(before, after);
    // A machine that does not exist.
    let (code, _, err) = pilgrim(&["run", DEMO, "--machine", "planer", "--out", s(&out)]);
    assert_eq!(code, 1);
    assert!(err.contains("unknown machine 'planer'"), "{err}");
}

#[test]
fn params_and_plugin_check() {
    let (code, out, _) = pilgrim(&["params", DEMO]);
    assert_eq!(code, 0);
    assert!(
        out.lines().any(|l| l.starts_with("radius")
            && l.contains("40")
            && l.contains("mm")
            && l.contains("finished edge")),
        "{out}"
    );
    let (code, out, err) = pilgrim(&["plugin-check", s(&lib("grinder_3k152vf20"))]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(&format!(
            "ABI {}.{}, machine 3K152VF20 (sinumerik), solves Z, X",
            pilgrim_plugin_abi::ABI_MAJOR,
            pilgrim_plugin_abi::ABI_MINOR
        )),
        "{out}"
    );
    let dir = scratch("check");
    let other = dir.join(format!(
        "{}other_abi{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    std::fs::copy(lib("plugin_fixture"), &other).unwrap();
    let (code, _, err) = pilgrim(&["plugin-check", s(&other)]);
    assert_eq!(code, 1);
    assert!(
        err.contains("ABI 99.3")
            && err.contains(&format!(
                "pilgrim ABI {}.{}",
                pilgrim_plugin_abi::ABI_MAJOR,
                pilgrim_plugin_abi::ABI_MINOR
            )),
        "{err}"
    );
}

/// Every script under scripts/ runs with its defaults.
#[test]
fn every_script_runs_with_its_defaults() {
    let found = crate::common::files_with_ext(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts"),
        "rhai",
    );
    assert!(!found.is_empty());
    let dir = scratch("scripts");
    for (i, script) in found.iter().enumerate() {
        let out = dir.join(format!("run{i}"));
        let (code, _, err) = pilgrim(&["run", s(script), "--out", s(&out), "--quiet"]);
        assert_eq!(code, 0, "{}: {err}", script.display());
        assert!(out.join("report.json").exists());
        let stem = script.file_stem().unwrap().to_str().unwrap();
        common::leave_for_checkers(&out, &format!("script-{stem}"));
    }
}

/// A family written from the first release's script API runs: each
/// renamed or re-shaped function answers under its old form, says its
/// replacement in the report's warnings, and gives what its replacement
/// gives in the same family written in today's API. An old form not kept
/// is an error naming its replacement, not "function not found".
#[test]
fn scripts_of_the_first_release_still_run() {
    let dir = scratch("first-release");
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scripts");
    let run = |name: &str| {
        let out = dir.join(name);
        let script = fixtures.join(format!("{name}.rhai"));
        let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&out), "--quiet"]);
        assert_eq!(code, 0, "{name}: {err}");
        let r: serde_json::Value = common::report_of(&out);
        r
    };
    let (old, today) = (run("first-release"), run("today"));
    let warnings: Vec<&str> = old["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();
    for (old_form, new_form) in [
        ("raise(", "raised("),
        ("resample(", "resampled("),
        ("smooth(", "smoothed("),
        ("simplify(", ".simplified(tol)"),
        ("envelope(zc", "envelope(path(zc, xc)"),
        ("cut(previous", "cut(ground_surface(previous)"),
        ("transform(\"rz\"", "rz_deg(value)"),
        ("transform(\"tx\"", "tx(value)"),
        ("universal(q)", "universal_deg(q)"),
        ("reverse(v)", "reversed(v)"),
        ("dx(law", "slope(law"),
        ("rest_seed_u(", "seed_centre_x"),
        ("rest_exact_u(", ".centre_x"),
    ] {
        assert!(
            warnings
                .iter()
                .any(|w| w.contains(old_form) && w.contains(new_form)),
            "no warning for {old_form}: {warnings:?}"
        );
    }
    // Today's twin has none (the report leaves out an empty list).
    assert!(!today.to_string().contains("earlier release"));
    let notes = today["notes"].as_object().unwrap();
    assert!(notes.len() >= 9);
    for (name, value) in notes {
        assert_eq!(&old["notes"][name], value, "{name}");
    }
    // The old cut: what the wheel's rounding leaves over the blank, no
    // lower than the blank, at the blank's nodes.
    let cut = old["notes"]["cut_x_at_60"].as_f64().unwrap();
    assert!(
        cut <= old["notes"]["x_at_50"].as_f64().unwrap() + 1.0,
        "{cut}"
    );

    // An old form not kept: refused naming what replaces it.
    let gone = dir.join("gone.rhai");
    std::fs::write(
        &gone,
        "fn params() { #{} }\n\
         fn toolpath(p) {\n\
           let b = profile(floats([0.0, 5.0, 10.0]), floats([5.0, 5.0, 5.0]));\n\
           cut(b, path(floats([0.0, 10.0]), floats([13.0, 13.0])), wheel_tool(\"wheel\", 1, 100.0, 8.0, 16.0), 100.0)\n\
         }\n",
    )
    .unwrap();
    let out = dir.join("gone");
    let (code, _, err) = pilgrim(&[
        "run",
        s(&gone),
        "--machine",
        "vertical-mill",
        "--out",
        s(&out),
    ]);
    assert_ne!(code, 0);
    assert!(
        err.contains("earlier release")
            && err.contains("cut(ground_surface(previous), centres, wheel, feed, spindle_rpm)"),
        "{err}"
    );
    assert!(!out.exists());
}

/// docs/script-api.md is what `pilgrim api-docs` writes now.
#[test]
fn api_reference_is_current() {
    let (code, out, _) = pilgrim(&["api-docs"]);
    assert_eq!(code, 0);
    let committed =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/script-api.md"))
            .unwrap();
    assert!(
        committed == out,
        "docs/script-api.md is stale: run `cargo run -- api-docs --out docs/script-api.md`"
    );
    for f in [
        "linspace",
        "add_pass",
        "equidistant",
        "wheel_tool",
        "read_table",
        "mandrel_law",
    ] {
        assert!(out.contains(&format!("## `{f}(")), "{f} missing");
    }
}

/// A family whose name begins like a word LinuxCNC acts on in a comment
/// (`(PY,..)`, `(LOG,..)`, `(PRINT,..)`), without the comma that makes it
/// one, writes its LinuxCNC program: the header's comment is a name, not
/// an instruction.
#[test]
fn families_named_like_active_comments_write_linuxcnc_programs() {
    let dir = common::scratch("cli", "active-names");
    let script = std::fs::read_to_string("scripts/examples/mill_circle.rhai").unwrap();
    for name in ["pyramid", "logo", "printer", "message", "debugger"] {
        let family = dir.join(format!("{name}.rhai"));
        std::fs::write(&family, &script).unwrap();
        let out = dir.join(name);
        let (code, _, err) = pilgrim(&[
            "run",
            common::s(&family),
            "--post",
            "linuxcnc",
            "--out",
            common::s(&out),
            "-q",
        ]);
        assert_eq!(code, 0, "{name}: {err}");
        let ngc = std::fs::read_to_string(out.join("program.ngc")).unwrap();
        let header = ngc.lines().nth(1).unwrap();
        assert!(
            header.starts_with(&format!("({} for ", name.to_uppercase())),
            "{ngc:.200}"
        );
    }
}

/// A reader that closes the pipe early (`pilgrim api-docs | head -0`) ends
/// the output, not in a panic: no "internal error", exit 0 (what was
/// wanted of the output was read). `--quiet` silences every command whose
/// output is a status line (run, verify, compensate, export,
/// plugin-check), never the data a command was asked for (params).
#[test]
fn a_closed_pipe_and_quiet_are_honoured() {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pilgrim"))
        .current_dir(common::root())
        .arg("api-docs")
        .stdout(writer)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.is_empty(), "{err}");
    let dir = common::scratch("cli", "quiet");
    let run = dir.join("run");
    let (code, said, err) = pilgrim(&["run", DEMO, "--out", s(&run), "-q"]);
    assert_eq!((code, said.as_str()), (0, ""), "{err}");
    let (code, said, err) = pilgrim(&["export", s(&run), "--block", "10", "-q"]);
    assert_eq!((code, said.as_str()), (0, ""), "{err}");
    let (code, said, _) = pilgrim(&["params", DEMO, "-q"]);
    assert!(code == 0 && !said.is_empty());
}

/// A name from outside reaches the terminal escaped (a carriage return,
/// an escape sequence, an OSC 52 clipboard write, a right-to-left
/// override shown as `\u{..}`), so no name can make "FAILED" display as
/// something else; and a message is cut at a stated length (20,000
/// column names do not make a 2 MB message).
#[test]
fn names_reach_the_terminal_escaped_and_messages_are_bounded() {
    let dir = common::scratch("cli", "escaped");
    let evil = dir.join("a\rverified\u{1b}]52;c;aGk=\u{7}\u{202e}FPM.MPF");
    std::fs::write(&evil, "%_N_A_MPF\nN1 G4711\n").unwrap();
    let (code, said, err) = pilgrim(&["verify", s(&evil), "--family", "scripts/mandrel.rhai"]);
    assert_eq!(code, 1, "{said}");
    for bad in ['\r', '\u{1b}', '\u{7}', '\u{202e}'] {
        assert!(
            !err.contains(bad) && !said.contains(bad),
            "{bad:?} in {err:?}"
        );
    }
    assert!(err.contains("\\r") && err.contains("\\u{202e}"), "{err}");
    // A measurement with 20,000 columns, none the one wanted.
    let run = dir.join("run");
    let (code, _, err) = pilgrim(&["run", "scripts/mandrel.rhai", "--out", s(&run), "-q"]);
    assert_eq!(code, 0, "{err}");
    let wide = dir.join("wide.csv");
    let header: Vec<String> = (0..20_000).map(|i| format!("column_{i}")).collect();
    std::fs::write(
        &wide,
        format!("{}\n{}\n", header.join(","), vec!["1"; 20_000].join(",")),
    )
    .unwrap();
    let (code, _, err) = pilgrim(&["compensate", s(&run), "--measured", s(&wide)]);
    assert_eq!(code, 1);
    assert!(err.len() < 10_000, "{} bytes: {:.300}", err.len(), err);
}

/// A value typed far out of range is named short: `--set tolerance=1e308`
/// is refused as `1e308`, not as 309 digits.
#[test]
fn huge_values_are_named_short() {
    let out = common::scratch("cli", "huge").join("run");
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/mandrel.rhai",
        "--set",
        "tolerance=1e308",
        "--out",
        s(&out),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("1e308 is above the ceiling 1"), "{err}");
    assert!(err.len() < 300, "{err}");
}
