//! `pilgrim compensate` benchmarks. Run: `cargo bench --bench compensate`.
//!
//! Each: a default job's run (made once, written to a scratch directory)
//! compensated by its example measurement (`scripts/examples/*-measured.csv`)
//! through the kernel's `job::compensate`, in process: the run's report and
//! program read, the family's nominal, the measurement read and fitted, the
//! correction, the corrected job run and verified, the program's lines and
//! path compared, every file's bytes (not written) (target <= 1 s).
//!
//! - `compensate/mandrel_end_to_end`: the mandrel, its radius along z (44
//!   places);
//! - `compensate/caliber_end_to_end`: the caliber, its groove's depth and
//!   width over theta (the corrected run is the caliber's whole job);
//! - `compensate/thread_end_to_end`: the M20 thread, its pitch diameter.

use criterion::{criterion_group, criterion_main, Criterion};
use pilgrim_kernel::catalog::{Catalog, CompiledPlugin};
use pilgrim_kernel::job::{self, CompensateOptions, JobOptions};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::PartFamily;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

/// The default job of `family` run once into a scratch directory, as
/// `pilgrim run` writes it (its report names the script by an absolute
/// path).
fn first_run(catalog: &Catalog, family: &str) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let script = root.join(format!("scripts/{family}.rhai"));
    // A script reads its tables (the thread's tool table) beside itself.
    let access = Access {
        input_dirs: vec![root.join("scripts")],
        ..Access::default()
    };
    let loaded = ScriptFamily::load(&script, &Limits::default(), &access).unwrap();
    let machine = catalog
        .open(&loaded.default_machine().unwrap().unwrap())
        .unwrap();
    let options = JobOptions {
        program_name: family.into(),
        ..JobOptions::default()
    };
    let out = job::run(&loaded, &machine, &[], &options, &mut |_| {}).unwrap();
    let dir = std::env::temp_dir().join(format!(
        "pilgrim-bench-compensate-{family}-{}",
        std::process::id()
    ));
    pilgrim_kernel::output::write_dir(&dir, &out.files).unwrap();
    dir
}

fn compensate(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let catalog = Catalog::new(&[
        CompiledPlugin {
            symbol: "pilgrim_plugin_grinder_3k152vf20",
            entry: grinder_3k152vf20::pilgrim_plugin_grinder_3k152vf20,
        },
        CompiledPlugin {
            symbol: "pilgrim_plugin_mannesmann",
            entry: mannesmann::pilgrim_plugin_mannesmann,
        },
        CompiledPlugin {
            symbol: "pilgrim_plugin_fanuc_0i_tc",
            entry: fanuc_0i_tc::pilgrim_plugin_fanuc_0i_tc,
        },
    ])
    .unwrap();
    let options = CompensateOptions {
        gain: 1.0,
        uncertainty: 0.001,
        limit: 0.1,
        limits: Limits::default(),
        columns: Vec::new(),
    };
    let mut g = c.benchmark_group("compensate");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for (family, places) in [("mandrel", 44), ("caliber", 57), ("thread", 5)] {
        let dir = first_run(&catalog, family);
        let measured = pilgrim_kernel::profile::read_table(
            root.join(format!("scripts/examples/{family}-measured.csv")),
        )
        .unwrap();
        let run = || job::compensate(&dir, &catalog, &measured, &options).unwrap();
        let (out, record) = run();
        assert_eq!(record.quantities[0].places.len(), places);
        assert_eq!(
            out.report.verdict.status,
            pilgrim_kernel::verdict::Status::Passed
        );
        g.bench_function(format!("{family}_end_to_end"), |b| {
            b.iter(|| black_box(run()))
        });
        let _ = std::fs::remove_dir_all(&dir);
    }
    g.finish();
}

criterion_group!(benches, compensate);
criterion_main!(benches);
