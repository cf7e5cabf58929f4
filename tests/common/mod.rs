//! Shared by the integration tests: the plugins' shared libraries.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The directory of this build's artifacts (target/<profile>).
pub fn artifact_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().and_then(Path::parent).unwrap().to_owned()
}

/// The path of shared library `name` (file `lib<name>.so` on Linux), built
/// first: `cargo test` builds a dependency's rlib only, so the tests ask
/// cargo for the cdylibs of the plugin crates, once per test process, in
/// the profile of the running tests (always, so a changed plugin is never
/// stale; an up-to-date build takes a fraction of a second).
pub fn shared_lib(name: &str) -> PathBuf {
    static BUILT: OnceLock<()> = OnceLock::new();
    BUILT.get_or_init(|| {
        let dir = artifact_dir();
        let mut cmd = std::process::Command::new(env!("CARGO"));
        cmd.args([
            "build",
            "--lib",
            "-p",
            "pilgrim-grinder-3k152vf20",
            "-p",
            "pilgrim-plugin-fixture",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"));
        if dir.file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        let status = cmd.status().expect("cargo runs");
        assert!(
            status.success(),
            "building the plugins' shared libraries failed"
        );
    });
    let p = artifact_dir().join(format!(
        "{}{name}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    assert!(p.exists(), "{} was not built", p.display());
    p
}
