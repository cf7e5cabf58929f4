//! Shared by the integration tests: the plugins' shared libraries.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The directory of this build's artifacts (target/<profile>).
#[allow(dead_code)]
pub fn artifact_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().and_then(Path::parent).unwrap().to_owned()
}

/// The path of shared library `name` (file `lib<name>.so` on Linux), built
/// first: `cargo test` builds a dependency's rlib only, so the tests ask
/// cargo for the cdylibs of the plugin crates, once per test process, in
/// the profile of the running tests (always, so a changed plugin is never
/// stale; an up-to-date build takes a fraction of a second).
#[allow(dead_code)]
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
            "-p",
            "pilgrim-lz-250",
            "-p",
            "pilgrim-mannesmann",
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

/// The 3K152VF20 compiled into the tests, through the plugin ABI as the
/// program has it.
#[allow(dead_code)]
pub fn grinder() -> pilgrim_kernel::plugin::PluginMachine {
    pilgrim_kernel::plugin::PluginMachine::from_entry(
        "3K152VF20",
        "pilgrim_plugin_grinder_3k152vf20",
        grinder_3k152vf20::pilgrim_plugin_grinder_3k152vf20,
    )
    .unwrap()
}

/// The family's parameters: its defaults, then `NAME=VALUE` pairs (as
/// `--set` gives them), on a machine with `constants`.
#[allow(dead_code)]
pub fn params_on(
    family: &dyn pilgrim_kernel::PartFamily,
    constants: &std::collections::BTreeMap<String, f64>,
    sets: &[(&str, &str)],
) -> pilgrim_kernel::Params {
    pilgrim_kernel::params::resolve(
        family.params(),
        constants,
        &[pilgrim_kernel::ParamSource::Pairs {
            label: "--set".into(),
            pairs: sets
                .iter()
                .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
                .collect(),
        }],
    )
    .unwrap()
}
