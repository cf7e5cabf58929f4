//! Fuzz targets for every parser and entry point that takes outside input
//! (issue 10): parameter files, machine files, tables (CSV and
//! spreadsheets), Rhai families under the engine's limits, plugin
//! descriptors, and the report `export` reads. Each must answer any input
//! with a value or an error: no panic, no abort, no hang.
//!
//! `cargo test` runs each target over its corpus
//! (`tests/fuzz/tests/__fuzz__/<target without fuzz_>/corpus/`: real inputs and the
//! reproducers of defects found) and a few hundred random inputs. A long
//! run with a coverage-guided engine (stable Rust, no sanitizer):
//!
//! ```sh
//! cargo install cargo-bolero --no-default-features
//! cargo bolero test -p pilgrim-fuzz fuzz_params_toml --sanitizer NONE -T 10min
//! ```

use pilgrim_kernel::job::Report;
use pilgrim_kernel::machine::{check_description, Machine, MachineInfo};
use pilgrim_kernel::params::{resolve, ParamSource, ParamSpec, ParamValue};
use pilgrim_kernel::profile::{read_table_bytes, read_table_str};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::PartFamily;
use std::time::Duration;

/// The mandrel family's parameters (its specs, with their bounds).
fn mandrel_specs() -> Vec<ParamSpec> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/mandrel.rhai");
    ScriptFamily::load(&path, &Limits::default(), &Access::default())
        .unwrap()
        .params()
        .to_vec()
}

#[test]
fn fuzz_params_toml() {
    let mut specs = mandrel_specs();
    specs.push(ParamSpec::new("name", ParamValue::Text("x".into()), "", ""));
    bolero::check!()
        .with_iterations(500)
        .for_each(|bytes: &[u8]| {
            let text = String::from_utf8_lossy(bytes).into_owned();
            let sources = [
                ParamSource::Toml {
                    label: "p.toml".into(),
                    text: text.clone(),
                },
                ParamSource::Pairs {
                    label: "--set".into(),
                    pairs: text
                        .lines()
                        .filter_map(|l| l.split_once('='))
                        .map(|(k, v)| (k.trim().to_owned(), v.to_owned()))
                        .collect(),
                },
            ];
            if let Err(e) = resolve(&specs, &Default::default(), &sources) {
                // Messages quote short excerpts, whatever the input's size.
                assert!(e.to_string().len() < 4096, "{} bytes", e.to_string().len());
            }
        });
}

#[test]
fn fuzz_machine_toml() {
    bolero::check!()
        .with_iterations(500)
        .for_each(|bytes: &[u8]| {
            let text = String::from_utf8_lossy(bytes);
            if let Err(e) = Machine::from_toml_str(&text, "m.toml") {
                assert!(e.to_string().len() < 4096);
            }
        });
}

#[test]
fn fuzz_tables() {
    bolero::check!()
        .with_iterations(500)
        .for_each(|bytes: &[u8]| {
            let text = String::from_utf8_lossy(bytes);
            if let Ok(t) = read_table_str(&text, "t.csv") {
                for h in t.headers() {
                    let _ = t.column(h);
                }
                let _ = t.profile("A", "B");
            }
            // The same bytes as each spreadsheet format (most are refused).
            for name in ["t.xlsx", "t.ods", "t.xls"] {
                if let Ok(t) = read_table_bytes(bytes, name) {
                    let _ = t.column("A");
                }
            }
        });
}

#[test]
fn fuzz_rhai_family() {
    let limits = Limits {
        max_operations: 200_000,
        max_seconds: 2.0,
        max_memory_mb: 2048,
        ..Limits::default()
    };
    bolero::check!()
        .with_iterations(200)
        .for_each(|bytes: &[u8]| {
            let source = String::from_utf8_lossy(bytes);
            let Ok(fam) = ScriptFamily::from_source(&source, "f.rhai", &limits, &Access::default())
            else {
                return;
            };
            let Ok(values) = resolve(fam.params(), &Default::default(), &[]) else {
                return;
            };
            let _ = fam.default_machine();
            let _ = fam.checks(&values);
            let _ = fam.part(&values);
            let _ = fam.verification(&values);
            let start = std::time::Instant::now();
            let _ = fam.toolpath(&values);
            // Bounded in time by the engine's limits (a native call may add a
            // little beyond the limit).
            assert!(start.elapsed() < Duration::from_secs(30));
        });
}

#[test]
fn fuzz_plugin_descriptor() {
    bolero::check!()
        .with_iterations(500)
        .for_each(|bytes: &[u8]| {
            if let Ok(info) = serde_json::from_slice::<MachineInfo>(bytes) {
                let _ = check_description(&info);
                let _ = Machine::from_info(info);
            }
        });
}

#[test]
fn fuzz_export_report() {
    let run = run_dir();
    let catalog = pilgrim_kernel::catalog::Catalog::new(&[]).unwrap();
    bolero::check!()
        .with_iterations(100)
        .for_each(|bytes: &[u8]| {
            let Ok(report) = serde_json::from_slice::<Report>(bytes) else {
                return;
            };
            // The report as export reads it, beside a real run's other files.
            let dir = tempdir(&run);
            std::fs::write(
                dir.join("report.json"),
                serde_json::to_vec(&report).unwrap(),
            )
            .unwrap();
            let Ok(opened) = pilgrim_kernel::output::RunDir::open(&dir) else {
                panic!("the copy of the run is a run");
            };
            let _ = pilgrim_kernel::job::export(
                &opened,
                &catalog,
                None,
                Some(2),
                pilgrim_kernel::job::Formats::default(),
            );
            let _ = std::fs::remove_dir_all(&dir);
        });
}

/// A finished run of the demo (once per test process).
fn run_dir() -> std::path::PathBuf {
    use pilgrim_kernel::job::{self, JobOptions};
    let dir = std::env::temp_dir().join(format!("pilgrim-fuzz-run-{}", std::process::id()));
    if dir.exists() {
        return dir;
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scripts/examples/mill_circle.rhai");
    let fam = ScriptFamily::load(&path, &Limits::default(), &Access::default()).unwrap();
    let catalog = pilgrim_kernel::catalog::Catalog::new(&[]).unwrap();
    let machine = catalog.open("vertical-mill").unwrap();
    let out = job::run(&fam, &machine, &[], &JobOptions::default(), &mut |_| {}).unwrap();
    pilgrim_kernel::output::write_dir(&dir, &out.files).unwrap();
    dir
}

/// A copy of the run's files in a new directory.
fn tempdir(run: &std::path::Path) -> std::path::PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = run.with_extension(format!("{}", N.fetch_add(1, Ordering::Relaxed)));
    std::fs::create_dir_all(&dir).unwrap();
    for e in std::fs::read_dir(run).unwrap().flatten() {
        std::fs::copy(e.path(), dir.join(e.file_name())).unwrap();
    }
    dir
}

/// The directory of this build's artifacts (`target/<profile>`), with the
/// `pilgrim` program and the fixture plugin library built in it (once per
/// test process): the damaged libraries are loaded as the program loads
/// them, in `pilgrim plugin-server` child processes.
fn plugin_artifacts() -> std::path::PathBuf {
    static BUILT: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    BUILT
        .get_or_init(|| {
            let exe = std::env::current_exe().unwrap();
            let dir = exe
                .parent()
                .and_then(std::path::Path::parent)
                .unwrap()
                .to_owned();
            let profile = dir.file_name().unwrap().to_string_lossy().into_owned();
            let mut cmd = std::process::Command::new(env!("CARGO"));
            // As `cargo test --workspace` selects them: the same features,
            // so nothing is built a second time with others.
            cmd.args(["build", "--workspace", "--lib", "--bins", "--tests"])
                .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
            if profile != "debug" {
                cmd.args([
                    "--profile",
                    if profile == "release" {
                        "release"
                    } else {
                        &profile
                    },
                ]);
            }
            assert!(cmd.status().unwrap().success(), "building pilgrim failed");
            pilgrim_kernel::plugin::configure(
                Some(dir.join("pilgrim")),
                pilgrim_kernel::plugin::Bounds {
                    load: Duration::from_secs(5),
                    call: Duration::from_secs(5),
                },
            );
            dir
        })
        .clone()
}

/// Damaged plugin libraries, checked as `pilgrim plugin-check` checks them
/// (loaded in a child process, their kinematics tried): every damage is
/// an error or a plugin that loads, never a crash or a hang of the host.
/// An input is up to 8 damages of 5 bytes each (where, as a `u32`, and the
/// new byte); its first byte picks the part of the file they fall in: the
/// whole file, its first 4 KiB (headers), or its dynamic section.
#[test]
fn fuzz_damaged_plugin() {
    use pilgrim_kernel::plugin::PluginMachine;
    let dir = plugin_artifacts();
    let good = std::fs::read(dir.join("libplugin_fixture.so")).unwrap();
    let dynamic = dynamic_range(&good);
    let scratch = std::env::temp_dir().join(format!("pilgrim-fuzz-so-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).unwrap();
    let path = scratch.join("liblathe.so");
    // What became of the inputs (shown with --nocapture).
    let seen = std::sync::Mutex::new(std::collections::BTreeMap::<&str, usize>::new());
    bolero::check!()
        .with_iterations(300)
        .for_each(|bytes: &[u8]| {
            let Some((&pick, damages)) = bytes.split_first() else {
                return;
            };
            let range = match pick % 3 {
                0 => 0..good.len(),
                1 => 0..good.len().min(4096),
                _ => dynamic.clone(),
            };
            let mut lib = good.clone();
            for d in damages.chunks_exact(5).take(8) {
                let at = u32::from_le_bytes([d[0], d[1], d[2], d[3]]) as usize;
                lib[range.start + at % range.len().max(1)] = d[4];
            }
            // A new file each time: a library is never written over in place.
            let _ = std::fs::remove_file(&path);
            std::fs::write(&path, &lib).unwrap();
            let outcome = match PluginMachine::load_checked(&path) {
                Ok(_) => "loaded",
                Err(e) => {
                    let text = e.to_string();
                    assert!(text.len() < 4096, "{} bytes of error", text.len());
                    assert!(text.contains("liblathe.so"), "{text}");
                    if text.contains("crashed") {
                        "crashed in its child process"
                    } else if text.contains("did not answer") {
                        "hung in its child process, stopped"
                    } else if text.contains("not a complete") || text.contains("no entry") {
                        "refused from its bytes"
                    } else {
                        "another error"
                    }
                }
            };
            if let Ok(mut s) = seen.lock() {
                *s.entry(outcome).or_default() += 1;
            }
        });
    eprintln!(
        "fuzz_damaged_plugin: {:?}",
        seen.lock().map(|s| s.clone()).unwrap_or_default()
    );
    std::fs::remove_dir_all(&scratch).ok();
}

/// The file range of a library's dynamic section.
fn dynamic_range(lib: &[u8]) -> std::ops::Range<usize> {
    // The dynamic section's program header, read by hand from the ELF64
    // header (`e_phoff` at 32, `e_phentsize` at 54, `e_phnum` at 56).
    let u16_at = |i: usize| u16::from_le_bytes([lib[i], lib[i + 1]]) as usize;
    let u64_at = |i: usize| u64::from_le_bytes(lib[i..i + 8].try_into().unwrap()) as usize;
    let (phoff, size, count) = (u64_at(32), u16_at(54), u16_at(56));
    for k in 0..count {
        let h = phoff + k * size;
        if u32::from_le_bytes(lib[h..h + 4].try_into().unwrap()) == 2 {
            // PT_DYNAMIC: p_offset at 8, p_filesz at 32.
            return u64_at(h + 8)..u64_at(h + 8) + u64_at(h + 32);
        }
    }
    panic!("the fixture library has no dynamic section");
}
