//! `pilgrim compensate` benchmarks. Run: `cargo bench --bench compensate`.
//!
//! - `compensate/mandrel_end_to_end`: the default mandrel's run (made once,
//!   written to a scratch directory) compensated by the example
//!   measurement (`scripts/examples/mandrel-measured.csv`) through the
//!   kernel's `job::compensate`, in process: the run's report and program
//!   read, the family's nominal, the measurement read and fitted, the
//!   correction, the corrected job run and verified, the program's diff
//!   and path moved, every file's bytes (not written) (target <= 1 s).

use criterion::{criterion_group, criterion_main, Criterion};
use pilgrim_kernel::catalog::{Catalog, CompiledPlugin};
use pilgrim_kernel::job::{self, CompensateOptions, JobOptions};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::PartFamily;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn compensate(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let catalog = Catalog::new(&[CompiledPlugin {
        symbol: "pilgrim_plugin_grinder_3k152vf20",
        entry: grinder_3k152vf20::pilgrim_plugin_grinder_3k152vf20,
    }])
    .unwrap();
    // The run to compensate, as `pilgrim run` writes it (its report names
    // the script by the path it was given: here an absolute one).
    let script = root.join("scripts/mandrel.rhai");
    let family = ScriptFamily::load(&script, &Limits::default(), &Access::default()).unwrap();
    let machine = catalog
        .open(&family.default_machine().unwrap().unwrap())
        .unwrap();
    let options = JobOptions {
        program_name: "mandrel".into(),
        ..JobOptions::default()
    };
    let out = job::run(&family, &machine, &[], &options, &mut |_| {}).unwrap();
    let dir = std::env::temp_dir().join(format!("pilgrim-bench-compensate-{}", std::process::id()));
    pilgrim_kernel::output::write_dir(&dir, &out.files).unwrap();
    let measured =
        pilgrim_kernel::profile::read_table(root.join("scripts/examples/mandrel-measured.csv"))
            .unwrap();
    let options = CompensateOptions {
        gain: 1.0,
        uncertainty: 0.001,
        limit: 0.1,
        limits: Limits::default(),
    };
    let run = || job::compensate(&dir, &catalog, &measured, &options).unwrap();
    let (_, record) = run();
    assert_eq!(record.quantities[0].places.len(), 45);
    let mut g = c.benchmark_group("compensate");
    g.sample_size(20).measurement_time(Duration::from_secs(12));
    g.bench_function("mandrel_end_to_end", |b| b.iter(|| black_box(run())));
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, compensate);
criterion_main!(benches);
