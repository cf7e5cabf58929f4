//! Containment: nothing outside the output directory is read or written,
//! nothing pilgrim did not write is removed, and a run's files are read
//! back only as pilgrim wrote them. Each test is a reproducer a hostile or
//! careless user could make, run from the command line.

use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};

use crate::common;
use common::{pilgrim, s};

const DEMO: &str = "scripts/examples/mill_circle.rhai";

fn scratch(name: &str) -> PathBuf {
    common::scratch("containment", name)
}

/// Every entry below `dir` (links as links, not followed) with its bytes.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = vec![];
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        let meta = std::fs::symlink_metadata(&p).unwrap();
        if meta.file_type().is_symlink() {
            let target = std::fs::read_link(&p).unwrap();
            out.push((p, format!("-> {}", target.display()).into_bytes()));
        } else if meta.is_dir() {
            out.push((p.clone(), b"/".to_vec()));
            out.extend(snapshot(&p));
        } else {
            out.push((p.clone(), std::fs::read(&p).unwrap()));
        }
    }
    out.sort();
    out
}

/// A finished run of the demo in `dir/run`.
fn demo_run(dir: &Path) -> PathBuf {
    let out = dir.join("run");
    let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    out
}

/// Links planted under the names pilgrim once used for its temporaries
/// (`.NAME.tmp-PID` inside an output, `.OUT.tmp-PID` beside it, for the
/// process ids the next commands will likely get) are never written
/// through and never removed: an export refuses the output that holds
/// them, naming them; a run beside them writes its own, and the files the
/// links point to are as they were.
#[test]
fn planted_links_are_neither_followed_nor_removed() {
    let dir = scratch("links");
    let out = demo_run(&dir);
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "precious\n").unwrap();
    let victim_dir = dir.join("victim-dir");
    std::fs::create_dir(&victim_dir).unwrap();
    std::fs::write(victim_dir.join("thesis.tex"), "precious\n").unwrap();
    let me = std::process::id();
    for pid in me..me + 64 {
        for name in ["scene.glb", "report.html", "cutter.stl"] {
            symlink(&victim, out.join(format!(".{name}.tmp-{pid}"))).unwrap();
        }
        symlink(&victim_dir, dir.join(format!(".run.tmp-{pid}"))).unwrap();
        symlink(&victim_dir, dir.join(format!(".run.tmp-{pid}.0"))).unwrap();
    }
    let before = snapshot(&dir);
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("holds files pilgrim did not write") && err.contains(".cutter.stl.tmp-"),
        "{err}"
    );
    assert_eq!(snapshot(&dir), before, "the export touched something");
    // The links inside the output gone (the user's move), the run writes
    // beside the links outside it and leaves them.
    for pid in me..me + 64 {
        for name in ["scene.glb", "report.html", "cutter.stl"] {
            std::fs::remove_file(out.join(format!(".{name}.tmp-{pid}"))).unwrap();
        }
    }
    let (code, _, err) = pilgrim(&["run", DEMO, "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read(&victim).unwrap(), b"precious\n");
    assert_eq!(
        std::fs::read_dir(&victim_dir).unwrap().count(),
        1,
        "something was written into the linked directory"
    );
    for pid in me..me + 64 {
        assert!(std::fs::symlink_metadata(dir.join(format!(".run.tmp-{pid}.0"))).is_ok());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A run's program replaced by a link to a file elsewhere, or a plot the
/// report and the marker were edited to list and that is such a link, is
/// not followed: export refuses it, naming the file, and the file's text
/// lands nowhere in the output.
#[test]
fn a_run_file_that_is_a_link_is_not_read() {
    let dir = scratch("leak");
    let out = demo_run(&dir);
    let secret = dir.join("secret.txt");
    std::fs::write(&secret, "SECRET-7f3a (the user's private notes)\n").unwrap();
    // The plot, listed where a run lists its files.
    let report_path = out.join("report.json");
    let mut report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report_path).unwrap()).unwrap();
    report["files"]
        .as_array_mut()
        .unwrap()
        .push("leak.svg".into());
    std::fs::write(&report_path, serde_json::to_vec(&report).unwrap()).unwrap();
    let marker = out.join(".pilgrim-output");
    let mut listed = std::fs::read_to_string(&marker).unwrap();
    listed.push_str("leak.svg\n");
    std::fs::write(&marker, listed).unwrap();
    symlink(&secret, out.join("leak.svg")).unwrap();
    let no_secret = |what: &str| {
        for (p, bytes) in snapshot(&out) {
            if !std::fs::symlink_metadata(&p)
                .unwrap()
                .file_type()
                .is_symlink()
            {
                let text = String::from_utf8_lossy(&bytes);
                assert!(
                    !text.contains("SECRET-7f3a"),
                    "{what}: {} holds the secret",
                    p.display()
                );
            }
        }
    };
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("leak.svg") && err.contains("link"), "{err}");
    no_secret("leak.svg");
    std::fs::remove_file(out.join("leak.svg")).unwrap();
    std::fs::write(out.join("leak.svg"), "<svg/>").unwrap();
    // The program.
    let program = out.join("program.mpf");
    std::fs::remove_file(&program).unwrap();
    symlink(&secret, &program).unwrap();
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("program.mpf") && err.contains("link"), "{err}");
    no_secret("program.mpf");
    std::fs::remove_dir_all(&dir).ok();
}

/// A tampered `program.json` (a block holding fewer values than the
/// program has axes) and a `report.json` listing the part body 27,000
/// times are refused before any work, naming the file and what is wrong;
/// the output stays as it was.
#[test]
fn tampered_run_files_are_checked_before_work() {
    let dir = scratch("tamper");
    let out = demo_run(&dir);
    let program_path = out.join("program.json");
    let good_program = std::fs::read(&program_path).unwrap();
    let mut program: serde_json::Value = serde_json::from_slice(&good_program).unwrap();
    program["blocks"][3]["values"]
        .as_array_mut()
        .unwrap()
        .truncate(1);
    std::fs::write(&program_path, serde_json::to_vec(&program).unwrap()).unwrap();
    let before = snapshot(&dir);
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("program.json") && err.contains("1 values for the program's"),
        "{err}"
    );
    assert_eq!(snapshot(&dir), before);
    std::fs::write(&program_path, &good_program).unwrap();

    let report_path = out.join("report.json");
    let mut report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report_path).unwrap()).unwrap();
    let part = report["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["kind"] == "part")
        .unwrap()
        .clone();
    report["bodies"] = serde_json::Value::Array(vec![part; 27_000]);
    std::fs::write(&report_path, serde_json::to_vec(&report).unwrap()).unwrap();
    let before = snapshot(&dir);
    let (code, _, err) = pilgrim(&["export", s(&out), "--block", "5"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("report.json") && err.contains("27000 part bodies"),
        "{err}"
    );
    assert_eq!(snapshot(&dir), before);
    std::fs::remove_dir_all(&dir).ok();
}

/// Files a user put in an earlier output under names like pilgrim's
/// temporaries (`.thesis.old-2024`, `.photos.tmp-7/`) are not taken for
/// pilgrim's: the next run and an export refuse the directory, naming
/// them, and they stay.
#[test]
fn user_files_named_like_temporaries_are_kept() {
    let dir = scratch("names");
    let out = demo_run(&dir);
    std::fs::write(out.join(".thesis.old-2024"), "chapter 1\n").unwrap();
    std::fs::create_dir(out.join(".photos.tmp-7")).unwrap();
    std::fs::write(out.join(".photos.tmp-7").join("a.jpg"), "jpeg\n").unwrap();
    let before = snapshot(&dir);
    for args in [
        vec!["run", DEMO, "--out", s(&out), "--quiet"],
        vec!["export", s(&out), "--block", "5"],
    ] {
        let (code, _, err) = pilgrim(&args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(
            err.contains(".thesis.old-2024") && err.contains(".photos.tmp-7"),
            "{err}"
        );
        assert_eq!(snapshot(&dir), before, "{args:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `api-docs --out` writes a new file or replaces the reference it wrote
/// before; a user's file or a link there is refused and left as it is.
#[test]
fn api_docs_never_overwrites_a_user_file() {
    let dir = scratch("apidocs");
    let mine = dir.join("f.txt");
    std::fs::write(&mine, "my notes\n").unwrap();
    let (code, _, err) = pilgrim(&["api-docs", "--out", s(&mine)]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("f.txt") && err.contains("not a file pilgrim generated"),
        "{err}"
    );
    assert_eq!(std::fs::read(&mine).unwrap(), b"my notes\n");
    let link = dir.join("link.md");
    symlink(&mine, &link).unwrap();
    let (code, _, err) = pilgrim(&["api-docs", "--out", s(&link)]);
    assert_eq!(code, 1, "{err}");
    assert_eq!(std::fs::read(&mine).unwrap(), b"my notes\n");
    let reference = dir.join("api.md");
    for _ in 0..2 {
        let (code, _, err) = pilgrim(&["api-docs", "--out", s(&reference)]);
        assert_eq!(code, 0, "{err}");
    }
    let (_, text, _) = pilgrim(&["api-docs"]);
    assert_eq!(std::fs::read_to_string(&reference).unwrap(), text);
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 3, "temporaries left: {names:?}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A script reads tables beside itself and beside the parameter file, by
/// file name alone: a table in a folder below either, above, or by an
/// absolute path gets the answer a missing file gets.
#[test]
fn scripts_read_only_beside_the_script_and_the_parameter_file() {
    let dir = scratch("below");
    let params_dir = dir.join("job");
    std::fs::create_dir_all(params_dir.join("private")).unwrap();
    std::fs::write(params_dir.join("private").join("salaries.csv"), "a\n1\n").unwrap();
    std::fs::write(params_dir.join("t.csv"), "a\n1\n2\n").unwrap();
    std::fs::write(dir.join("up.csv"), "a\n1\n").unwrap();
    let params = params_dir.join("p.toml");
    std::fs::write(&params, "").unwrap();
    let script = dir.join("scripts").join("f.rhai");
    std::fs::create_dir_all(script.parent().unwrap()).unwrap();
    let run = |name: &str| {
        std::fs::write(
            &script,
            format!(
                "fn params() {{ #{{}} }}\nfn default_machine() {{ \"vertical-mill\" }}\n\
                 fn toolpath(p) {{ let t = read_table(\"{name}\"); throw `read ${{t.rows}} rows`; }}\n"
            ),
        )
        .unwrap();
        let (code, _, err) = pilgrim(&[
            "run",
            s(&script),
            "--params",
            s(&params),
            "--out",
            s(&dir.join("o")),
            "--quiet",
        ]);
        assert_eq!(code, 1, "{err}");
        err.replace(name, "NAME")
    };
    let missing = run("missing.csv");
    assert!(
        missing.contains("not a readable file beside the script"),
        "{missing}"
    );
    let abs = params_dir.join("t.csv").display().to_string();
    for name in ["private/salaries.csv", "../up.csv", "./t.csv", abs.as_str()] {
        assert_eq!(run(name), missing, "{name}");
    }
    assert!(run("t.csv").contains("read 2 rows"));
    std::fs::remove_dir_all(&dir).ok();
}

/// A command that writes a directory holds it for the whole command: a
/// second command on it (an export racing a run put the older run's
/// program back after the new run said "written") fails at once, naming
/// the command and process that hold it, and writes nothing; a lock whose
/// process is gone is taken over.
#[test]
fn a_directory_being_written_is_held() {
    let dir = scratch("locked");
    let run = demo_run(&dir);
    let before = snapshot(&run);
    let lock = dir.join(format!(
        ".{}.lock",
        run.file_name().unwrap().to_str().unwrap()
    ));
    // Held by a live process (this test's).
    std::fs::write(&lock, format!("{}\npilgrim run\n", std::process::id())).unwrap();
    for args in [
        vec!["export", s(&run), "--block", "3"],
        vec!["run", DEMO, "--out", s(&run)],
    ] {
        let (code, _, err) = pilgrim(&args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(
            err.contains("pilgrim run") && err.contains(&std::process::id().to_string()),
            "{args:?}: {err}"
        );
    }
    assert_eq!(snapshot(&run), before);
    // Held by a process that is gone: taken over, and let go after.
    let gone = std::process::Command::new("true").spawn().unwrap();
    let pid = gone.id();
    let mut gone = gone;
    gone.wait().unwrap();
    std::fs::write(&lock, format!("{pid}\npilgrim export\n")).unwrap();
    let (code, _, err) = pilgrim(&["export", s(&run), "--block", "3"]);
    assert_eq!(code, 0, "{err}");
    assert!(!lock.exists());
}
