//! The plugin SDK as a vendor meets it: the Rust and C plugins of
//! `docs/plugins.md`, taken from the page as written, built outside this
//! workspace against a copy of the ABI crate (by path only) and its C
//! header, checked with `plugin-check` and used to run the worm family.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::{pilgrim, s};

/// The files of the page's blocks marked `file=NAME`, by name.
fn page_files() -> Vec<(String, String)> {
    let page = std::fs::read_to_string(common::root().join("docs/plugins.md")).unwrap();
    let mut files = vec![];
    let mut lines = page.lines();
    while let Some(line) = lines.next() {
        let Some(name) = line.strip_prefix("```").and_then(|info| {
            info.split_whitespace()
                .find_map(|w| w.strip_prefix("file="))
        }) else {
            continue;
        };
        let body: Vec<&str> = lines.by_ref().take_while(|l| *l != "```").collect();
        files.push((name.to_owned(), body.join("\n") + "\n"));
    }
    files
}

/// A fresh directory holding the page's files, with the path the page
/// gives to pilgrim's source (`../pilgrim/`) pointing at `pilgrim`.
fn vendor_dir(name: &str, pilgrim: &Path) -> PathBuf {
    let dir = common::scratch("sdk", name);
    std::fs::create_dir_all(dir.join("src")).unwrap();
    for (file, text) in page_files() {
        let text = text.replace("../pilgrim/", &format!("{}/", pilgrim.display()));
        std::fs::write(dir.join(file), text).unwrap();
    }
    dir
}

/// A copy of the ABI crate, outside the workspace: what a vendor has.
fn abi_copy(dir: &Path) -> PathBuf {
    let to = dir.join("pilgrim");
    let from = common::root().join("plugins/abi");
    for sub in ["", "src", "include"] {
        std::fs::create_dir_all(to.join("plugins/abi").join(sub)).unwrap();
        for e in std::fs::read_dir(from.join(sub)).unwrap().flatten() {
            if e.file_type().unwrap().is_file() {
                std::fs::copy(
                    e.path(),
                    to.join("plugins/abi").join(sub).join(e.file_name()),
                )
                .unwrap();
            }
        }
    }
    to
}

/// `plugin-check` passes the library, and the worm family runs on it.
fn check_and_run(lib: &Path, dir: &Path) {
    let (code, out, err) = pilgrim(&["plugin-check", s(lib)]);
    assert_eq!(code, 0, "{out}\n{err}");
    assert!(out.contains("acme-lathe"), "{out}");
    assert!(
        out.contains("kinematics over the travel") && out.contains("agree"),
        "{out}"
    );
    let run = dir.join("run");
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/worm.rhai",
        "--machine",
        s(lib),
        "--out",
        s(&run),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let program = std::fs::read_to_string(run.join("program.nc")).unwrap();
    assert!(program.contains("G32"), "{program}");
}

/// The Rust plugin of the page: a crate of its own (its own workspace,
/// its own target directory), depending on a copy of the ABI crate by
/// path, built offline from this repository's lock file.
#[test]
fn the_rust_plugin_of_the_docs_builds_outside_the_workspace_and_runs() {
    let base = common::scratch("sdk", "rust-base");
    let pilgrim_copy = abi_copy(&base);
    let dir = vendor_dir("rust", &pilgrim_copy);
    // Its own workspace, and the versions this repository has locked (the
    // build is offline).
    let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
    std::fs::write(dir.join("Cargo.toml"), manifest + "\n[workspace]\n").unwrap();
    std::fs::copy(common::root().join("Cargo.lock"), dir.join("Cargo.lock")).unwrap();
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sdk-rust-target");
    let build = Command::new(env!("CARGO"))
        .current_dir(&dir)
        .args(["build", "--offline", "--quiet"])
        .env("CARGO_TARGET_DIR", &target)
        .env_remove("RUSTFLAGS")
        .output()
        .unwrap();
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    check_and_run(&target.join("debug/libacme_lathe.so"), &dir);
}

/// The C plugin of the page, built with the system's C compiler against
/// the checked-in header, by the page's own build lines.
#[test]
fn the_c_plugin_of_the_docs_builds_and_runs() {
    let base = common::scratch("sdk", "c-base");
    let pilgrim_copy = abi_copy(&base);
    let dir = vendor_dir("c", &pilgrim_copy);
    let build = Command::new("sh")
        .current_dir(&dir)
        .arg("build.sh")
        .output()
        .expect("sh and a C compiler (cc) build the plugin");
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    check_and_run(&dir.join("libacme_lathe.so"), &dir);
}
