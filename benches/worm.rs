//! Worm benchmarks (issue 13). Run: `cargo bench --bench worm`.
//!
//! - `worm_job`: the default job (a two-start module-5 worm on the Fanuc
//!   0i-TC) through the kernel's job call, in process: the script loaded,
//!   the plan, inverse kinematics, the pass-by-pass simulation, the posts,
//!   the charts, the meshes and the bytes of every file (not written to
//!   disk) (target <= 0.5 s);
//! - `worm_simulate`: the simulation alone on the default program; the
//!   thread passes it cut are printed, with passes per second.

use criterion::{criterion_group, criterion_main, Criterion};
use pilgrim_kernel::catalog::{Catalog, CompiledPlugin};
use pilgrim_kernel::families::thread::simulate;
use pilgrim_kernel::job::{self, JobOptions};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::{PartFamily, ToolShape};
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

fn catalog() -> Catalog {
    Catalog::new(&[CompiledPlugin {
        symbol: "pilgrim_plugin_fanuc_0i_tc",
        entry: fanuc_0i_tc::pilgrim_plugin_fanuc_0i_tc,
    }])
    .unwrap()
}

fn family() -> ScriptFamily {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/worm.rhai");
    ScriptFamily::load(&script, &Limits::default(), &Access::default()).unwrap()
}

fn worm_job(c: &mut Criterion) {
    let catalog = catalog();
    let options = JobOptions {
        program_name: "worm".into(),
        ..JobOptions::default()
    };
    let run = || {
        let family = family();
        let machine = catalog.open("fanuc-0i-tc").unwrap();
        job::run(&family, &machine, &[], &options, &mut |_| {}).unwrap()
    };
    let out = run();
    assert!(
        out.check::<pilgrim_kernel::families::thread::ThreadOutcome>()
            .is_some()
            && out.files.len() >= 12,
        "{} files",
        out.files.len()
    );
    let mut g = c.benchmark_group("worm_job");
    g.sample_size(20).measurement_time(Duration::from_secs(10));
    g.bench_function("default_job_end_to_end", |b| b.iter(|| black_box(run())));
    g.finish();
}

fn worm_simulate(c: &mut Criterion) {
    let catalog = catalog();
    let machine = catalog.open("fanuc-0i-tc").unwrap();
    let family = family();
    let out = job::run(&family, &machine, &[], &JobOptions::default(), &mut |_| {}).unwrap();
    let Some(req) = family.verification(&out.params).unwrap().and_then(|v| {
        v.request::<pilgrim_kernel::families::thread::ThreadRequest>()
            .cloned()
    }) else {
        panic!("the worm asks for the simulation")
    };
    let ToolShape::ThreadCutter(cutter) = out.toolpath.tool.shape else {
        panic!("the worm's tool is a thread cutter")
    };
    let kin = machine.kinematics.as_ref();
    let sim = || {
        simulate(
            &out.program,
            kin,
            &out.toolpath.tool.reference,
            &cutter,
            &req,
        )
        .unwrap()
    };
    let t = Instant::now();
    let check = sim();
    let secs = t.elapsed().as_secs_f64();
    println!(
        "worm_simulate: {} thread passes, one simulation {:.4} s: {:.0} passes/s",
        check.passes.len(),
        secs,
        check.passes.len() as f64 / secs
    );
    let mut g = c.benchmark_group("worm_simulate");
    g.sample_size(20).measurement_time(Duration::from_secs(10));
    g.bench_function("default_program", |b| b.iter(|| black_box(sim())));
    g.finish();
}

criterion_group!(benches, worm_job, worm_simulate);
criterion_main!(benches);
