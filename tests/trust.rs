//! Trust (issue 10): no user file is ever lost, nothing reaches outside,
//! every input is bounded. Each test reproduces a defect found by trying
//! pilgrim as a hostile or careless user would, from the command line.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::common;
#[path = "../kernel/tests/support/ods.rs"]
mod ods;
use common::{pilgrim, pilgrim_in, root, s};

fn pilgrim_within(args: &[&str], limit: Duration) -> Option<(i32, String)> {
    measured(args, limit).map(|m| (m.code.unwrap_or(-1), m.err))
}

/// Runs pilgrim with `args`, killed after `limit` (then `None`).
fn measured(args: &[&str], limit: Duration) -> Option<common::Measured> {
    common::measured(args, &[], limit)
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("trust", name)
}

const DEMO: &str = "scripts/examples/mill_circle.rhai";

/// Every file below `dir` with its bytes, sorted.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = vec![];
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(snapshot(&p));
        } else {
            out.push((p.clone(), std::fs::read(&p).unwrap()));
        }
    }
    out.sort();
    out
}

/// `--out` at a directory pilgrim did not write is refused and every file
/// in it stays; a regular file given as `--out` is refused too; a previous
/// output is replaced as a whole.
#[test]
fn out_never_replaces_what_pilgrim_did_not_write() {
    let dir = scratch("out");
    let user = dir.join("d");
    std::fs::create_dir(&user).unwrap();
    std::fs::write(user.join("notes.txt"), "x\n").unwrap();
    let before = snapshot(&dir);
    let abs_demo = root().join(DEMO);
    let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&user), "--quiet"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("was not written by pilgrim") && err.contains("notes.txt"),
        "{err}"
    );
    // --out "$PWD": the user's working directory.
    let (code, _, err) = pilgrim_in(&user, &["run", s(&abs_demo), "--out", s(&user), "--quiet"]);
    assert_eq!(code, 1, "{err}");
    let file = dir.join("f");
    std::fs::write(&file, "keep me\n").unwrap();
    let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&file), "--quiet"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("is not a directory"), "{err}");
    let mut expected = before.clone();
    expected.push((file.clone(), b"keep me\n".to_vec()));
    expected.sort();
    assert_eq!(snapshot(&dir), expected);
    // A new directory, then the same run again: replaced as a whole.
    let out = dir.join("run");
    for _ in 0..2 {
        let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&out), "--quiet"]);
        assert_eq!(code, 0, "{err}");
    }
    assert!(out.join(".pilgrim-output").is_file());
    // A previous output to which the user added a file is refused, naming it.
    std::fs::write(out.join("mine.txt"), "mine\n").unwrap();
    let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&out), "--quiet"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("mine.txt"), "{err}");
    assert_eq!(std::fs::read(out.join("mine.txt")).unwrap(), b"mine\n");
    std::fs::remove_dir_all(&dir).ok();
}

/// Temporary directories of killed runs are cleaned by the next run, but
/// only when their process is gone.
#[test]
fn stale_temporaries_of_dead_runs_are_cleaned() {
    let dir = scratch("stale");
    // A process that is gone: a child that has exited.
    let dead = Command::new("true").spawn().unwrap();
    let dead_pid = dead.id();
    let mut dead = dead;
    dead.wait().unwrap();
    let stale = dir.join(format!(".out.tmp-{dead_pid}.0"));
    std::fs::create_dir(&stale).unwrap();
    // Its marker lists what it wrote: only that is removed.
    std::fs::write(
        stale.join(".pilgrim-output"),
        "pilgrim output directory: the next run to it replaces it as a whole.\npart.stl\n",
    )
    .unwrap();
    std::fs::write(stale.join("part.stl"), "half").unwrap();
    // One of a live process (this test).
    let live = dir.join(format!(".out.tmp-{}.0", std::process::id()));
    std::fs::create_dir(&live).unwrap();
    std::fs::write(live.join(".pilgrim-output"), "").unwrap();
    let out = dir.join("out");
    let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    assert!(!stale.exists(), "the dead run's temporary is still there");
    assert!(live.exists(), "a live run's temporary was removed");
    std::fs::remove_dir_all(&dir).ok();
}

/// A family's body names become file names only when they are plain names.
#[test]
fn part_names_cannot_reach_outside() {
    let dir = scratch("names");
    let victim = dir.join("victim");
    for name in [format!("{}/x", dir.display()), "../../victim".to_owned()] {
        let script = dir.join("f.rhai");
        std::fs::write(
            &script,
            format!(
                "fn params() {{ #{{}} }}\n\
                 fn default_machine() {{ \"vertical-mill\" }}\n\
                 fn toolpath(p) {{ let tp = new_toolpath(\"t\", end_mill(\"m\", 1, 6.0, 10.0), 1000.0, [\"C\"]);\n\
                   tp.add_pass(\"a\", #{{ x: [50.0], y: [0.0], z: [5.0], motion: \"rapid\", aux: #{{ C: 0.0 }} }}); tp }}\n\
                 fn part(p) {{ #{{ \"{name}\": profile([-1.0, 0.0, 1.0], [5.0, 5.0, 5.0]) }} }}\n"
            ),
        )
        .unwrap();
        let out = dir.join("out").join("run");
        let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&out), "--quiet"]);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(
            err.contains(&format!("'{name}'")) && err.contains("plain name"),
            "{err}"
        );
        assert!(!dir.join("x.stl").exists() && !victim.with_extension("stl").exists());
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `export` reads only the run's own files by plain name, and loads a
/// plugin only when the command line names it.
#[test]
fn export_trusts_nothing_in_the_report() {
    let dir = scratch("export");
    let out = dir.join("run");
    let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let report_path = out.join("report.json");
    let original = std::fs::read_to_string(&report_path).unwrap();
    let mut report: serde_json::Value = serde_json::from_str(&original).unwrap();
    // A plugin named by the report is not loaded.
    let lib = common::shared_lib("plugin_fixture");
    report["machine_spec"] = lib.display().to_string().into();
    std::fs::write(&report_path, serde_json::to_string(&report).unwrap()).unwrap();
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--machine"), "{err}");
    // A body's file outside the directory is not opened.
    let secret = dir.join("secret.stl");
    std::fs::copy(out.join("part.stl"), &secret).unwrap();
    report["machine_spec"] = "vertical-mill".into();
    report["bodies"][0]["file"] = "../secret.stl".into();
    std::fs::write(&report_path, serde_json::to_string(&report).unwrap()).unwrap();
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("../secret.stl"), "{err}");
    // The run's own report exports, with the machine it names by a built-in's name.
    std::fs::write(&report_path, &original).unwrap();
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 0, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `read_table` gives the same answer for a file outside the input
/// directories whether or not it exists.
#[test]
fn outside_files_are_not_told_apart() {
    let dir = scratch("outside");
    let inside = dir.join("in");
    std::fs::create_dir(&inside).unwrap();
    std::fs::write(dir.join("exists.csv"), "a,b\n1,2\n").unwrap();
    let mut answers = vec![];
    for target in ["../exists.csv", "../missing.csv"] {
        let script = inside.join("f.rhai");
        std::fs::write(
            &script,
            format!(
                "fn params() {{ #{{}} }}\nfn default_machine() {{ \"vertical-mill\" }}\n\
                 fn toolpath(p) {{ read_table(\"{target}\") }}\n"
            ),
        )
        .unwrap();
        let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&dir.join("o")), "--quiet"]);
        assert_eq!(code, 1);
        answers.push(err.replace(target, "FILE"));
    }
    assert_eq!(answers[0], answers[1]);
    assert!(
        answers[0].contains("not a readable file beside the script or the parameter file"),
        "{}",
        answers[0]
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A 2 KB spreadsheet with one cell at XFD1048576 is read, not an abort
/// (the bound on cells itself: `kernel/tests/tables.rs`).
#[test]
fn a_far_spreadsheet_cell_is_bounded() {
    let dir = scratch("xlsx");
    let path = dir.join("far.xlsx");
    let mut book = rust_xlsxwriter::Workbook::new();
    let sheet = book.add_worksheet();
    sheet.write_number(0, 0, 1.0).unwrap();
    sheet.write_number(1, 0, 2.0).unwrap();
    sheet.write_number(1_048_575, 16_383, 3.0).unwrap();
    book.save(&path).unwrap();
    let script = dir.join("f.rhai");
    std::fs::write(
        &script,
        "fn params() { #{} }\nfn default_machine() { \"vertical-mill\" }\nfn toolpath(p) { read_table(\"far.xlsx\")[\"A\"] }\n",
    )
    .unwrap();
    let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&dir.join("o")), "--quiet"]);
    // Read cell by cell: the far cell is a row of its own, named when the
    // column it lacks is asked for.
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("far.xlsx, row 1048576, column A: the cell is empty"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A shared library cut short is refused before it is loaded, in every
/// command that loads one; a failed load says the system's reason; a bare
/// file name is a path in the working directory, not a library search.
#[test]
fn truncated_plugins_do_not_crash_the_host() {
    let dir = scratch("truncated");
    let good = std::fs::read(common::shared_lib("grinder_3k152vf20")).unwrap();
    let cut = dir.join("libgrinder_3k152vf20.so");
    std::fs::write(&cut, &good[..4096]).unwrap();
    let out = dir.join("o");
    for args in [
        vec!["plugin-check", s(&cut)],
        vec!["run", DEMO, "--machine", s(&cut), "--out", s(&out)],
        vec!["machines", "--plugin", s(&cut)],
    ] {
        let (code, _, err) = pilgrim(&args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.contains("not a complete"), "{args:?}: {err}");
    }
    // Not ELF at all.
    let text = dir.join("libtext.so");
    std::fs::write(&text, "not a library").unwrap();
    let (code, _, err) = pilgrim(&["plugin-check", s(&text)]);
    assert_eq!(code, 1);
    assert!(err.contains("not an ELF"), "{err}");
    // A bare name is looked up in the working directory only.
    let (code, _, err) = pilgrim_in(&dir, &["plugin-check", "libc.so.6"]);
    assert_eq!(code, 1);
    assert!(err.contains("libc.so.6"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Parameters that drive work have ceilings, checked before the work, and
/// the error names the parameter, its value and the ceiling; feeds below
/// the machine's minimum are refused.
#[test]
fn parameters_that_drive_work_are_bounded() {
    let dir = scratch("bounds");
    let out = dir.join("o");
    let small = "scripts/examples/mandrel-small.toml";
    for (sets, params, expected) in [
        (vec!["passes=99999999999"], None, "passes"),
        (vec!["tolerance=1e-12"], None, "tolerance"),
        (vec!["cone_d=-1000000"], Some(small), "cone_d"),
        (vec!["wheel_d=1e9"], None, "wheel_d"),
        (vec!["feed=1e-320"], None, "feed"),
    ] {
        let mut args = vec!["run", "scripts/mandrel.rhai", "--out", s(&out), "--quiet"];
        if let Some(p) = params {
            args.extend(["--params", p]);
        }
        for set in &sets {
            args.extend(["--set", set]);
        }
        let Some((code, err)) = pilgrim_within(&args, Duration::from_secs(60)) else {
            panic!("{sets:?} ran past a minute");
        };
        assert_eq!(code, 1, "{sets:?}: {err}");
        assert!(
            err.contains(&format!("parameter '{expected}'")) || err.contains("minimum"),
            "{sets:?}: {err}"
        );
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A script cannot pass its limits, and each limit that stops it is the
/// one it passed, said by name, with the work stopped within its bound as
/// the system accounts it (peak memory and CPU time, compared with a run
/// that passes on the same machine, so a slow machine changes nothing):
/// memory through Floats (the kernel's ceiling), time through operations
/// that each cost more as an array grows, memory through a map grown by
/// index (which Rhai 1.27 does not count against its map size), and time
/// inside a kernel call (the steady rest's track of a pass at a feed of
/// 5e-324 mm/min, which once ran 108 s past a 5 s limit).
#[test]
fn scripts_are_bounded_in_memory_and_time() {
    let dir = scratch("rhai");
    let out = dir.join("o");
    let head = "fn params() { #{} }\nfn default_machine() { \"vertical-mill\" }\n";
    let within = Duration::from_secs(300);
    let run = |args: &[&str]| measured(args, within).expect("the run was not stopped");
    // What runs that pass take here: the small family and the mandrel.
    let small = run(&["run", DEMO, "--out", s(&out), "--quiet"]);
    assert_eq!(small.code, Some(0), "{}", small.err);
    let mandrel = run(&["run", "scripts/mandrel.rhai", "--out", s(&out), "--quiet"]);
    assert_eq!(mandrel.code, Some(0), "{}", mandrel.err);
    let script = dir.join("f.rhai");
    let family = |body: &str| {
        std::fs::write(&script, format!("{head}{body}\n")).unwrap();
        s(&script).to_owned()
    };
    // The kernel's ceiling on Floats.
    let f = family("fn toolpath(p) { let v = linspace(0.0, 1.0, 1000); for i in 0..40 { v = concat(v, v); } v }");
    let m = run(&["run", &f, "--out", s(&out), "--quiet"]);
    assert_eq!(m.code, Some(1), "{}", m.err);
    assert!(m.err.contains("ceiling of 10000000"), "{}", m.err);
    assert!(m.peak_mb < small.peak_mb + 400.0, "{} MB", m.peak_mb);
    // Time, between a script's operations.
    let f = family("fn toolpath(p) { let a = []; loop { a.push(1); } }");
    let m = run(&[
        "run",
        &f,
        "--out",
        s(&out),
        "--quiet",
        "--script-seconds",
        "2",
    ]);
    assert_eq!(m.code, Some(1), "{}", m.err);
    assert!(
        m.err.contains("the script's time limit of 2 s passed"),
        "{}",
        m.err
    );
    assert!(
        m.cpu_seconds < 2.0 + small.cpu_seconds + 1.0,
        "{} s of CPU",
        m.cpu_seconds
    );
    // Memory, after every operation.
    let f = family("fn toolpath(p) { let m = #{}; for i in 0..100000000 { m[`k${i}`] = i; } m }");
    let m = run(&[
        "run",
        &f,
        "--out",
        s(&out),
        "--quiet",
        "--script-memory-mb",
        "200",
    ]);
    assert_eq!(m.code, Some(1), "{}", m.err);
    assert!(m.err.contains("memory limit of 200 MB"), "{}", m.err);
    assert!(
        m.peak_mb < 200.0 + small.peak_mb + 20.0,
        "{} MB at its peak",
        m.peak_mb
    );
    // Time, inside a kernel call made by the script, and the run's own
    // limit over the whole run.
    for (limit, flag, whose) in [
        ("2", "--script-seconds", "the script's"),
        ("1", "--run-seconds", "the run's"),
    ] {
        let m = run(&[
            "run",
            "scripts/mandrel.rhai",
            // A support of 500 mm held to 0.1 um: the rest's track
            // samples a metre of surface for each of its many blocks.
            "--set",
            "rest_tol=0.0001",
            "--set",
            "rest_r=500",
            "--out",
            s(&out),
            "--quiet",
            flag,
            limit,
        ]);
        assert_eq!(m.code, Some(1), "{}", m.err);
        let said = format!("{whose} time limit of {limit} s passed (in the steady rest's track)");
        assert!(m.err.contains(&said), "{}", m.err);
        let limit: f64 = limit.parse().unwrap();
        assert!(
            m.cpu_seconds < limit + mandrel.cpu_seconds + 1.0,
            "{} s of CPU",
            m.cpu_seconds
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Only regular files are read: a FIFO given as a parameter file or read
/// as a table is refused, not waited on.
#[test]
fn fifos_are_refused() {
    let dir = scratch("fifo");
    let fifo = dir.join("p.toml");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let Some((code, err)) = pilgrim_within(
        &[
            "run",
            DEMO,
            "--params",
            s(&fifo),
            "--out",
            s(&dir.join("o")),
        ],
        Duration::from_secs(20),
    ) else {
        panic!("the run waited on a FIFO");
    };
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("not a regular file"), "{err}");
    let table = dir.join("t.csv");
    assert!(Command::new("mkfifo")
        .arg(&table)
        .status()
        .unwrap()
        .success());
    let script = dir.join("f.rhai");
    std::fs::write(
        &script,
        "fn params() { #{} }\nfn default_machine() { \"vertical-mill\" }\nfn toolpath(p) { read_table(\"t.csv\") }\n",
    )
    .unwrap();
    let Some((code, err)) = pilgrim_within(
        &["run", s(&script), "--out", s(&dir.join("o"))],
        Duration::from_secs(20),
    ) else {
        panic!("read_table waited on a FIFO");
    };
    assert_eq!(code, 1, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// An error about a 1 MB line quotes a short excerpt of it.
#[test]
fn errors_quote_short_excerpts() {
    let dir = scratch("long");
    for (name, text) in [
        ("p.toml", format!("radius = {}\n", "9".repeat(1 << 20))),
        ("q.toml", format!("radius = \"{}\n", "x".repeat(1 << 20))),
    ] {
        let params = dir.join(name);
        std::fs::write(&params, text).unwrap();
        let (code, _, err) = pilgrim(&[
            "run",
            DEMO,
            "--params",
            s(&params),
            "--out",
            s(&dir.join("o")),
        ]);
        assert_eq!(code, 1);
        assert!(err.len() < 2000, "{name}: {} bytes of error", err.len());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A run killed part way leaves the previous output whole, never a
/// half-written one, and the next run cleans what the killed one left. The
/// kills land at points the test knows were reached (a preloaded shim kills
/// the run as it creates its K-th file, or just before or after it swaps
/// the new output in), so the test proves the same whatever the machine's
/// speed.
#[test]
fn killed_runs_leave_the_old_output_whole() {
    let dir = scratch("kill");
    let shim = dir.join("libkill.so");
    let cc = Command::new("cc")
        .args(["-shared", "-fPIC", "-O1", "-o"])
        .arg(&shim)
        .arg(root().join("tests/fixtures/kill-shim/kill.c"))
        .arg("-ldl")
        .output()
        .expect("a C compiler (cc) builds the test's shim");
    assert!(
        cc.status.success(),
        "{}",
        String::from_utf8_lossy(&cc.stderr)
    );
    let out = dir.join("o");
    let args = ["run", "scripts/mandrel.rhai", "--out", s(&out), "--quiet"];
    let (code, _, err) = pilgrim(&args);
    assert_eq!(code, 0, "{err}");
    let before = snapshot(&out);
    // The marker and every file (the snapshot holds both): that many
    // exclusive creations.
    let files = before.len();
    let killed = |var: &str, value: &str| {
        let status = Command::new(env!("CARGO_BIN_EXE_pilgrim"))
            .current_dir(root())
            .args(args)
            .env("LD_PRELOAD", &shim)
            .env(var, value)
            .stderr(Stdio::null())
            .status()
            .unwrap();
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(
            status.signal(),
            Some(libc::SIGKILL),
            "{var}={value}: the run did not reach its kill point ({status})"
        );
        // Either untouched, or the whole new output: the same bytes.
        assert_eq!(snapshot(&out), before, "after a kill at {var}={value}");
    };
    for k in [0, 1, files / 2, files - 1] {
        killed("PILGRIM_KILL_AT_CREATE", &k.to_string());
    }
    killed("PILGRIM_KILL_AT_SWAP", "before");
    killed("PILGRIM_KILL_AT_SWAP", "after");
    // The next run replaces the output and cleans what the killed ones left.
    let (code, _, err) = pilgrim(&args);
    assert_eq!(code, 0, "{err}");
    assert_eq!(snapshot(&out), before);
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".o."))
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A lathe (the Fanuc 0i-TC's machine file, written from its plugin's
/// descriptor) whose control is `control` and whose name or description
/// is `name` / `description`.
fn lathe(control: &str, name: &str, description: &str) -> String {
    let text = pilgrim_kernel::machine::machine_file(&fanuc_0i_tc::describe(), "its crate");
    for key in [
        "name = \"fanuc-0i-tc\"",
        "description = \"two-axis CNC lathe, Fanuc 0i-TC, X on diameter\"",
        "control = \"fanuc\"",
    ] {
        assert!(text.contains(key), "{key} not in\n{text}");
    }
    // A TOML basic string, control characters as \uXXXX.
    let quote = |t: &str| {
        let body: String = t
            .chars()
            .map(|c| match c {
                '"' | '\\' => format!("\\{c}"),
                c if c.is_control() => format!("\\u{:04X}", u32::from(c)),
                c => c.to_string(),
            })
            .collect();
        format!("\"{body}\"")
    };
    let text = text
        .replace("name = \"fanuc-0i-tc\"", &format!("name = {}", quote(name)))
        .replace(
            "description = \"two-axis CNC lathe, Fanuc 0i-TC, X on diameter\"",
            &format!("description = {}", quote(description)),
        );
    crate::common::with_control(&text, control)
}

/// A turning family whose tool and pass are named by the script's text
/// `tool` and `pass`, and a parameter `label` that becomes a pass's name.
fn turning(tool: &str, pass: &str) -> String {
    format!(
        "fn params() {{ #{{ label: #{{ value: \"finish\", unit: \"\", doc: \"the last pass's name\" }} }} }}\n\
         fn toolpath(p) {{\n\
           let tp = new_toolpath(\"turn\", end_mill({tool}, 1, 10.0, 30.0), 500.0, []);\n\
           tp.add_pass({pass}, #{{ x: [30.0, 20.0, 20.0], y: 0.0, z: [2.0, 2.0, -40.0], motion: [\"rapid\", \"linear\", \"linear\"], feed: 100.0 }});\n\
           tp.add_pass(p.label, #{{ x: [19.0, 19.0, 30.0], y: 0.0, z: [-40.0, 2.0, 2.0], motion: [\"linear\", \"linear\", \"rapid\"], feed: 100.0 }});\n\
           tp\n\
         }}\n"
    )
}

/// Text that would break a comment or a block, through every source that
/// reaches a program (tool, pass and machine names, a parameter string, a
/// machine's description), into every dialect (the control's, `--post`
/// ones, the CL file): each run is refused, naming the source, and writes
/// nothing. A tool named `T1)`, a line break and `G00 X0 Z0 (` once put an
/// uncommented rapid to the spindle's axis into `program.nc`.
#[test]
fn injected_words_never_reach_a_program() {
    let dir = scratch("inject");
    let out = dir.join("o");
    let clean_script = dir.join("turn.rhai");
    std::fs::write(&clean_script, turning("\"turning tool\"", "\"rough\"")).unwrap();
    for control in ["sinumerik", "fanuc", "linuxcnc"] {
        let machine = dir.join("lathe.toml");
        let run = |script: &Path, machine: &Path, extra: &[&str]| {
            let mut args = vec![
                "run",
                s(script),
                "--machine",
                s(machine),
                "--out",
                s(&out),
                "--quiet",
                "--post",
                "linuxcnc",
                "--post",
                "fanuc",
                "--post",
                "sinumerik",
            ];
            args.extend(extra);
            pilgrim(&args)
        };
        std::fs::write(&machine, lathe(control, "my lathe", "a lathe")).unwrap();
        let (code, _, err) = run(&clean_script, &machine, &[]);
        assert_eq!(code, 0, "{control}: the clean run: {err}");
        std::fs::remove_dir_all(&out).unwrap();
        // Names in the script.
        for (tool, pass, source, shown) in [
            (
                r#""T1)\nG00 X0 Z0 (""#,
                r#""rough""#,
                "tool name",
                r#""T1)\nG00 X0 Z0 (""#,
            ),
            (r#""T1) G00 X0 Z0 (""#, r#""rough""#, "tool name", "')'"),
            (r#""tool""#, r#""rough\rG00 X0""#, "pass name", r#"\r"#),
            (r#""tool""#, r#""rough; SF=90""#, "pass name", "';'"),
            (r#""tool""#, r#""MSG, PROBEOPEN x""#, "", ""),
        ] {
            let script = dir.join("inject.rhai");
            std::fs::write(&script, turning(tool, pass)).unwrap();
            let (code, _, err) = run(&script, &machine, &[]);
            if source.is_empty() {
                // Words of no dialect's comment syntax pass as names; the
                // LinuxCNC writer keeps its comment from acting.
                assert_eq!(code, 0, "{control}: {pass}: {err}");
                let ngc = std::fs::read_to_string(out.join("program.ngc")).unwrap();
                assert!(
                    ngc.contains("(_MSG, PROBEOPEN x)") && !ngc.contains("(MSG"),
                    "{ngc}"
                );
                std::fs::remove_dir_all(&out).unwrap();
                continue;
            }
            assert_eq!(code, 1, "{control}: {tool} {pass}");
            assert!(
                err.contains("inject.rhai") && err.contains(source) && err.contains(shown),
                "{control}: {err}"
            );
            assert!(!out.exists(), "{control}: {tool} {pass}");
        }
        // A parameter string that becomes a pass's name.
        let params = dir.join("p.toml");
        std::fs::write(&params, "label = \"finish\\nG00 X0 Z0\"\n").unwrap();
        let (code, _, err) = run(&clean_script, &machine, &["--params", s(&params)]);
        assert_eq!(code, 1);
        assert!(
            err.contains("p.toml") && err.contains("label") && err.contains("U+000A"),
            "{control}: {err}"
        );
        std::fs::write(&params, "label = \"finish) G00 X0 Z0 (\"\n").unwrap();
        let (code, _, err) = run(&clean_script, &machine, &["--params", s(&params)]);
        assert_eq!(code, 1);
        assert!(
            err.contains("pass name") && err.contains("')'"),
            "{control}: {err}"
        );
        assert!(!out.exists());
        // The machine's name (a lone carriage return passed all four
        // lints) and its description.
        for (name, description, source) in [
            ("lathe\rG00 X0 Z0", "a lathe", "machine name"),
            ("lathe) G00 X0 (", "a lathe", "machine name"),
            ("lathe", "a lathe\u{1b}[2J", "machine description"),
        ] {
            std::fs::write(&machine, lathe(control, name, description)).unwrap();
            let (code, _, err) = run(&clean_script, &machine, &[]);
            assert_eq!(code, 1, "{control}: {name:?} {description:?}");
            assert!(
                err.contains("lathe.toml") && err.contains(source),
                "{control}: {err}"
            );
            assert!(!out.exists());
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A spindle speed a program writes as `S0` is refused, naming the block;
/// so is one below the spindle's least speed. A speed of 0.3 rpm was
/// written `S0 M3` and followed by cutting moves.
#[test]
fn a_spindle_that_writes_as_zero_is_refused() {
    let dir = scratch("s0");
    let out = dir.join("o");
    let script = dir.join("turn.rhai");
    std::fs::write(
        &script,
        turning("\"tool\"", "\"rough\"").replace(
            "label: #{",
            "rpm: #{ value: 500.0, min: 0.0001, max: 5000.0, unit: \"rpm\", doc: \"spindle\" }, label: #{",
        ).replace("500.0, []", "p.rpm, []"),
    )
    .unwrap();
    let machine = dir.join("lathe.toml");
    std::fs::write(&machine, lathe("fanuc", "lathe", "a lathe")).unwrap();
    let run = |rpm: &str| {
        pilgrim(&[
            "run",
            s(&script),
            "--machine",
            s(&machine),
            "--set",
            &format!("rpm={rpm}"),
            "--out",
            s(&out),
            "--quiet",
        ])
    };
    let (code, _, err) = run("0.3");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("written S0") && err.contains("block 1 in \"start\""),
        "{err}"
    );
    assert!(!out.exists());
    let (code, _, err) = run("4000");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("S4000") && err.contains("[0, 3500] rpm"),
        "{err}"
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// Every message quotes outside text short (at most 120 characters) with
/// its control characters escaped, whatever its source: a 1 MB table
/// cell, a 3 MB parameter key (in a file and on the command line), a 3 MB
/// axis name, a script's `print` of escape sequences (OSC 52 writes the
/// clipboard); and `report.csv` neutralises a pass name a spreadsheet
/// would evaluate (`=1+2`).
#[test]
fn every_message_quotes_outside_text_short() {
    let dir = scratch("quotes");
    let out = dir.join("o");
    let escape = "\u{1b}]52;c;cHduZWQ=\u{7}\u{1b}[31m";
    let clean = |what: &str, err: &str| {
        assert!(
            !err.contains('\u{1b}') && !err.contains('\u{7}'),
            "{what}: raw escapes in {err:?}"
        );
        assert!(err.len() < 2000, "{what}: {} bytes of message", err.len());
    };
    // A table cell.
    let table = dir.join("t.csv");
    std::fs::write(&table, format!("a,b\n1,{escape}{}\n", "9x".repeat(1 << 19))).unwrap();
    let script = dir.join("f.rhai");
    std::fs::write(
        &script,
        "fn params() { #{} }\nfn default_machine() { \"vertical-mill\" }\nfn toolpath(p) { read_table(\"t.csv\")[\"b\"] }\n",
    )
    .unwrap();
    let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&out)]);
    assert_eq!(code, 1, "{err}");
    clean("table cell", &err);
    assert!(
        err.contains("t.csv") && err.contains("column B (b)"),
        "{err}"
    );
    // A parameter key, from a file and from --set.
    let key = format!("{escape}{}", "k".repeat(3 << 20));
    // The key as a TOML string spells its control characters.
    let toml_key = key.replace('\u{1b}', "\\u001b").replace('\u{7}', "\\u0007");
    let params = dir.join("p.toml");
    std::fs::write(&params, format!("\"{toml_key}\" = 1\n")).unwrap();
    let (code, _, err) = pilgrim(&["run", DEMO, "--params", s(&params), "--out", s(&out)]);
    assert_eq!(code, 1, "{err}");
    clean("parameter key in a file", &err);
    assert!(err.contains("unknown parameter"), "{err}");
    // (one argument is at most 128 KiB on Linux)
    let set = format!("{}=1", &key[..100_000]);
    let (code, _, err) = pilgrim(&["run", DEMO, "--set", &set, "--out", s(&out)]);
    assert_eq!(code, 1, "{err}");
    clean("parameter key on the command line", &err);
    // An axis name.
    let mill = pilgrim_kernel::machine::BUILTIN_SOURCES
        .iter()
        .find(|(n, _)| *n == "vertical-mill")
        .unwrap()
        .1;
    let machine = dir.join("m.toml");
    std::fs::write(
        &machine,
        mill.replacen("name = \"X\"", &format!("name = \"{toml_key}\""), 1),
    )
    .unwrap();
    let (code, _, err) = pilgrim(&["run", DEMO, "--machine", s(&machine), "--out", s(&out)]);
    assert_eq!(code, 1, "{err}");
    clean("axis name", &err);
    // A script's print.
    std::fs::write(
        &script,
        format!(
            "fn params() {{ #{{}} }}\nfn default_machine() {{ \"vertical-mill\" }}\n\
             fn toolpath(p) {{ print(\"{}\" + \"x\".pad(1000000, \"x\")); throw \"stop\"; }}\n",
            escape.replace('\u{1b}', "\\x1b").replace('\u{7}', "\\x07")
        ),
    )
    .unwrap();
    let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&out)]);
    assert_eq!(code, 1, "{err}");
    clean("print", &err);
    assert!(err.contains("\\u{1b}]52"), "{err}");
    // A pass name a spreadsheet would evaluate.
    std::fs::write(
        &script,
        "fn params() { #{} }\nfn default_machine() { \"vertical-mill\" }\n\
         fn toolpath(p) {\n\
           let tp = new_toolpath(\"t\", end_mill(\"m\", 1, 6.0, 10.0), 1000.0, [\"C\"]);\n\
           tp.add_pass(\"=1+2\", #{ x: [50.0, 50.0], y: [0.0, 0.0], z: [5.0, 5.0], motion: \"rapid\", aux: #{ C: 0.0 } });\n\
           tp\n\
         }\n",
    )
    .unwrap();
    let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let csv = std::fs::read_to_string(out.join("report.csv")).unwrap();
    assert!(csv.contains(",'=1+2,"), "{csv}");
    assert!(!csv.contains(",=1+2"), "{csv}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A workbook that says more than it holds is refused before it is
/// expanded: an ODS of a few hundred bytes whose row of a thousand values is
/// repeated 90,000 times, which the reader (calamine, up to 100 million
/// cells) once expanded into some 6 GB before the table's 10 million-cell
/// limit was seen.
#[test]
fn spreadsheets_are_bounded_before_they_expand() {
    let dir = scratch("bomb");
    let bytes = ods::ods_bytes(
        "<?xml version=\"1.0\"?><office:document-content><office:body><office:spreadsheet>\
          <table:table table:name=\"S\"><table:table-row table:number-rows-repeated=\"90000\">\
          <table:table-cell table:number-columns-repeated=\"1000\" office:value-type=\"float\" office:value=\"1\"/>\
          </table:table-row></table:table></office:spreadsheet></office:body></office:document-content>",
    );
    assert!(bytes.len() < 1000, "{} bytes", bytes.len());
    std::fs::write(dir.join("t.ods"), &bytes).unwrap();
    let script = dir.join("f.rhai");
    std::fs::write(
        &script,
        "fn params() { #{} }\nfn default_machine() { \"vertical-mill\" }\nfn toolpath(p) { read_table(\"t.ods\") }\n",
    )
    .unwrap();
    let Some(m) = measured(
        &["run", s(&script), "--out", s(&dir.join("o"))],
        Duration::from_secs(60),
    ) else {
        panic!("the ODS was expanded");
    };
    assert_eq!(m.code, Some(1), "{}", m.err);
    assert!(
        m.err.contains("t.ods") && m.err.contains("more than 10000000 cells"),
        "{}",
        m.err
    );
    // Refused before it was expanded: no more memory than a small run.
    assert!(m.peak_mb < 200.0, "{} MB at its peak", m.peak_mb);
    std::fs::remove_dir_all(&dir).ok();
}

/// A deadline already past stops every default job's verification at its
/// first look at the clock, naming the limit and where it was, never a
/// verdict, never a panic: each loop that grows with the program (the
/// reader, the replays, the process's rules, the steady rest's ride, the
/// collisions) looks at the clock, and so does every stage of the run as
/// it starts. The verification leaves its report, FAILED, saying so.
#[test]
fn a_deadline_already_past_stops_every_verification() {
    for job in ["mandrel", "caliber", "worm", "thread"] {
        let out = common::default_run("trust", job, &format!("deadline-{job}"));
        let (code, said, err) = pilgrim(&["verify", s(&out), "--run-seconds", "1e-9"]);
        assert_eq!(code, 1, "{job}: {said}");
        assert!(
            err.contains("the verification's time limit of 0.000000001 s passed"),
            "{job}: {err}"
        );
        assert!(!err.contains("internal error"), "{job}: {err}");
        // It leaves its report, FAILED, saying why.
        let verified = out.with_extension("verify");
        let report = common::report_of(&verified);
        let failures = report["verdict"]["failures"].as_array().unwrap();
        assert!(
            failures
                .iter()
                .any(|f| f["message"].as_str().unwrap().contains("time limit")),
            "{job}: {report}"
        );
        assert!(verified.join("report.html").is_file(), "{job}");
    }
}

/// A caller's cancel token (`budget::Cancel`, what a workbench fires when
/// a newer calculation replaces an older one) stops a run at its next
/// look at the clock: fired before the run, the run ends at its first
/// stage naming the cancel, and leaves no report; the same run without
/// the token completes.
#[test]
fn a_cancelled_run_stops_at_its_first_look_at_the_clock() {
    use pilgrim_kernel::budget::{with_cancel, Cancel};
    use pilgrim_kernel::catalog::{OpenMachine, Origin};
    use pilgrim_kernel::job::{self, JobOptions};
    use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
    let family = ScriptFamily::load(
        Path::new("scripts/mandrel.rhai"),
        &Limits::default(),
        &Access::default(),
    )
    .unwrap();
    let machine = OpenMachine::plugin(common::grinder(), "3K152VF20", Origin::BuiltinPlugin);
    let token = Cancel::new();
    token.fire();
    let run = || job::run(&family, &machine, &[], &JobOptions::default(), &mut |_| {});
    let e = with_cancel(Some(token), run).unwrap_err();
    assert!(
        matches!(&e, pilgrim_kernel::Error::OverTime(o) if o.cancelled),
        "{e}"
    );
    assert!(e.to_string().contains("cancelled by its caller"), "{e}");
    assert!(run().is_ok());
}
