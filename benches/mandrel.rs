//! Mandrel benchmarks (issue: mandrel family). Run: `cargo bench --bench mandrel`.
//!
//! - `mandrel_job`: the default job as a user runs it, through the release
//!   `pilgrim` program: the family's script, inverse kinematics and limits,
//!   the replay verification, the meshes and every file (target <= 0.5 s).

use criterion::{criterion_group, criterion_main, Criterion};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

fn mandrel_job(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::env::temp_dir().join(format!("pilgrim-bench-mandrel-{}", std::process::id()));
    let run = || {
        let status = Command::new(env!("CARGO_BIN_EXE_pilgrim"))
            .current_dir(root)
            .args(["run", "scripts/mandrel.rhai", "--quiet", "--out"])
            .arg(&out)
            .status()
            .unwrap();
        assert!(status.success());
    };
    run();
    let mut g = c.benchmark_group("mandrel_job");
    g.sample_size(20).measurement_time(Duration::from_secs(8));
    g.bench_function("default_job_end_to_end", |b| b.iter(run));
    g.finish();
    let _ = std::fs::remove_dir_all(&out);
}

criterion_group!(mandrel, mandrel_job);
criterion_main!(mandrel);
