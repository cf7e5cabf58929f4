//! A run keeps its inputs beside its files: the family's script, the
//! tables it read, the machine file; `verify DIR` and `compensate` use
//! the kept copies, refuse a changed one or another given on the command
//! line naming it, and work on a folder that was moved, the files it was
//! made from gone.

use crate::common::{pilgrim, s, scratch};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// `files` of `scripts/` copied into `dir/src`, and a run of the first
/// (the family) from there into `dir/run` with `extra` options.
fn run_from_copy(dir: &Path, files: &[&str], extra: &[&str]) -> PathBuf {
    let src = dir.join("src");
    std::fs::create_dir_all(&src).unwrap();
    for f in files {
        std::fs::copy(Path::new("scripts").join(f), src.join(f)).unwrap();
    }
    let out = dir.join("run");
    let script = src.join(files[0]);
    let mut args = vec!["run", s(&script), "--out", s(&out), "-q"];
    args.extend(extra);
    let (code, _, err) = pilgrim(&args);
    assert_eq!(code, 0, "{err}");
    out
}

fn hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

/// The caliber's run keeps its script and the groove's table, byte for
/// byte, their digests in the report; moved, with the copies it was made
/// from deleted, it verifies; a kept file edited is refused naming it.
#[test]
fn a_moved_run_verifies_from_the_inputs_it_kept() {
    let dir = scratch("kept", "caliber");
    let run = run_from_copy(&dir, &["caliber.rhai", "caliber-groove.csv"], &[]);
    let inputs = report(&run)["inputs"].as_array().unwrap().clone();
    let roles: Vec<(&str, &str)> = inputs
        .iter()
        .map(|i| (i["role"].as_str().unwrap(), i["file"].as_str().unwrap()))
        .collect();
    assert_eq!(
        roles,
        [("family", "caliber.rhai"), ("table", "caliber-groove.csv")]
    );
    for i in &inputs {
        let file = i["file"].as_str().unwrap();
        let kept = std::fs::read(run.join(file)).unwrap();
        assert_eq!(
            kept,
            std::fs::read(Path::new("scripts").join(file)).unwrap()
        );
        assert_eq!(i["sha256"].as_str().unwrap(), hex(&kept), "{file}");
    }
    std::fs::remove_dir_all(dir.join("src")).unwrap();
    let moved = dir.join("moved");
    std::fs::rename(&run, &moved).unwrap();
    let (code, out, err) = pilgrim(&["verify", s(&moved), "--out", s(&dir.join("v1")), "-q"]);
    assert_eq!(code, 0, "{out}{err}");
    // A kept table edited: refused naming it.
    let table = moved.join("caliber-groove.csv");
    let mut text = std::fs::read_to_string(&table).unwrap();
    text.push('\n');
    std::fs::write(&table, text).unwrap();
    let (code, _, err) = pilgrim(&["verify", s(&moved), "--out", s(&dir.join("v2")), "-q"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("caliber-groove.csv") && err.contains("changed since the run kept it"),
        "{err}"
    );
}

/// A run on a machine file keeps the file: with the file deleted, `verify
/// DIR` uses the copy; a script or a machine on the command line that is
/// not the run's is refused naming it, as is another built-in than the
/// run's.
#[test]
fn verify_refuses_a_script_or_machine_other_than_the_runs() {
    let dir = scratch("kept", "machine-file");
    let (code, toml, err) = pilgrim(&["machines", "--toml", "3K152VF20"]);
    assert_eq!(code, 0, "{err}");
    let machine = dir.join("grinder.toml");
    std::fs::write(&machine, &toml).unwrap();
    let run = run_from_copy(&dir, &["mandrel.rhai"], &["--machine", s(&machine)]);
    assert_eq!(
        std::fs::read_to_string(run.join("grinder.toml")).unwrap(),
        toml
    );
    std::fs::remove_file(&machine).unwrap();
    let (code, out, err) = pilgrim(&["verify", s(&run), "--out", s(&dir.join("v1")), "-q"]);
    assert_eq!(code, 0, "{out}{err}");
    // Another family's script.
    let (code, _, err) = pilgrim(&[
        "verify",
        s(&run),
        "--family",
        "scripts/worm.rhai",
        "--out",
        s(&dir.join("v2")),
        "-q",
    ]);
    assert_eq!(code, 1);
    assert!(
        err.contains("worm.rhai") && err.contains("not the family's script the run was made with"),
        "{err}"
    );
    // Another machine file, one word changed.
    let other = dir.join("other.toml");
    std::fs::write(
        &other,
        toml.replacen("description = \"", "description = \"edited ", 1),
    )
    .unwrap();
    let (code, _, err) = pilgrim(&[
        "verify",
        s(&run),
        "--machine",
        s(&other),
        "--out",
        s(&dir.join("v3")),
        "-q",
    ]);
    assert_eq!(code, 1);
    assert!(
        err.contains("other.toml") && err.contains("not the machine the run was made with"),
        "{err}"
    );
    // A built-in's run and another built-in.
    let builtin = dir.join("builtin");
    let (code, _, err) = pilgrim(&["run", "scripts/worm.rhai", "--out", s(&builtin), "-q"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = pilgrim(&[
        "verify",
        s(&builtin),
        "--machine",
        "3K152VF20",
        "--out",
        s(&dir.join("v4")),
        "-q",
    ]);
    assert_eq!(code, 1);
    assert!(
        err.contains("3K152VF20") && err.contains("not the machine the run was made on"),
        "{err}"
    );
}

/// `compensate` works from what the run kept: the mandrel run moved, the
/// script it was made from deleted, is compensated, and the corrected run
/// keeps the script in turn (it verifies).
#[test]
fn a_moved_run_is_compensated_from_its_kept_inputs() {
    let dir = scratch("kept", "compensate");
    let run = run_from_copy(&dir, &["mandrel.rhai"], &[]);
    std::fs::remove_dir_all(dir.join("src")).unwrap();
    let moved = dir.join("moved");
    std::fs::rename(&run, &moved).unwrap();
    let corrected = dir.join("corrected");
    let (code, out, err) = pilgrim(&[
        "compensate",
        s(&moved),
        "--measured",
        "scripts/examples/mandrel-measured.csv",
        "--out",
        s(&corrected),
    ]);
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(
        std::fs::read(corrected.join("mandrel.rhai")).unwrap(),
        std::fs::read("scripts/mandrel.rhai").unwrap()
    );
    let (code, out, err) = pilgrim(&["verify", s(&corrected), "--out", s(&dir.join("v")), "-q"]);
    assert_eq!(code, 0, "{out}{err}");
}
