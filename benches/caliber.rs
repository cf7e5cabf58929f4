//! Caliber benchmarks (issue 12). Run: `cargo bench --bench caliber`.
//!
//! - `caliber_job`: the default job (the example groove on the Mannesmann)
//!   through the kernel's job call, in process: the script loaded, the
//!   tables read and smoothed, every pass's exact poses, inverse
//!   kinematics, the 3-D replay, the posts, the meshes and the bytes of
//!   every file (not written to disk) (target <= 2 s); and the same with
//!   the groove's edges rounded (`edge_r = 2`): the passes on the
//!   roundings and the step-overs between them;
//! - `caliber_verify`: the 3-D replay alone on the default program; its
//!   grid (561 x 329 points of (theta, psi)) and the wheel positions
//!   replayed are printed, with points per second.

use criterion::{criterion_group, criterion_main, Criterion};
use pilgrim_kernel::catalog::{Catalog, CompiledPlugin};
use pilgrim_kernel::families::caliber::check_groove;
use pilgrim_kernel::job::{self, JobOptions};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::PartFamily;
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

fn catalog() -> Catalog {
    Catalog::new(&[CompiledPlugin {
        symbol: "pilgrim_plugin_mannesmann",
        entry: mannesmann::pilgrim_plugin_mannesmann,
    }])
    .unwrap()
}

fn family() -> ScriptFamily {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/caliber.rhai");
    ScriptFamily::load(&script, &Limits::default(), &Access::default()).unwrap()
}

fn caliber_job(c: &mut Criterion) {
    let catalog = catalog();
    let options = JobOptions {
        program_name: "caliber".into(),
        ..JobOptions::default()
    };
    let run = || {
        let family = family();
        let machine = catalog.open("Mannesmann").unwrap();
        job::run(&family, &machine, &[], &options, &mut |_| {}).unwrap()
    };
    let out = run();
    assert!(
        out.check::<pilgrim_kernel::families::caliber::GrooveOutcome>()
            .is_some()
            && out.files.len() >= 11,
        "{} files",
        out.files.len()
    );
    let rounded = [pilgrim_kernel::params::ParamSource::Pairs {
        label: "--set".into(),
        pairs: vec![("edge_r".into(), "2".into())],
    }];
    let run_rounded = || {
        let family = family();
        let machine = catalog.open("Mannesmann").unwrap();
        job::run(&family, &machine, &rounded, &options, &mut |_| {}).unwrap()
    };
    assert!(run_rounded().toolpath.passes.len() > out.toolpath.passes.len());
    let mut g = c.benchmark_group("caliber_job");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.bench_function("default_job_end_to_end", |b| b.iter(|| black_box(run())));
    g.bench_function("rounded_edge_job_end_to_end", |b| {
        b.iter(|| black_box(run_rounded()))
    });
    g.finish();
}

fn caliber_verify(c: &mut Criterion) {
    let catalog = catalog();
    let machine = catalog.open("Mannesmann").unwrap();
    let family = family();
    let out = job::run(&family, &machine, &[], &JobOptions::default(), &mut |_| {}).unwrap();
    let Some(req) = family.verification(&out.params).unwrap().and_then(|v| {
        v.request::<pilgrim_kernel::families::caliber::GrooveRequest>()
            .cloned()
    }) else {
        panic!("the caliber asks for the groove's replay")
    };
    let pilgrim_kernel::ToolShape::Wheel(wheel) = out.toolpath.tool.shape else {
        panic!("the caliber's tool is a wheel")
    };
    let kin = machine.kinematics.as_ref();
    let replay = || {
        check_groove(
            &out.program,
            kin,
            &out.toolpath.tool.reference,
            &wheel,
            &pilgrim_kernel::program::pass_blocks(&out.program, &out.toolpath.passes),
            &req,
        )
        .unwrap()
    };
    let t = Instant::now();
    let check = replay();
    let secs = t.elapsed().as_secs_f64();
    let points = check.grid_theta * check.grid_psi;
    println!(
        "caliber_verify: grid {} x {} = {points} points, {} wheel positions, one replay {:.3} s: {:.0} points/s",
        check.grid_theta,
        check.grid_psi,
        check.samples,
        secs,
        points as f64 / secs
    );
    let mut g = c.benchmark_group("caliber_verify");
    g.sample_size(10).measurement_time(Duration::from_secs(12));
    g.bench_function("replay_default_program", |b| b.iter(|| black_box(replay())));
    // The process's rules over the same program: the wheel's depth in the
    // turned groove at every block's end (a local search from the block
    // before's nearest point), the rapids in sub-steps.
    let allowance = req.stock.expect("the caliber states its stock");
    let limits = pilgrim_kernel::process::ProcessLimits::of(kin.info());
    let process = || {
        let stock = pilgrim_kernel::families::caliber::GrooveStock::new(
            &req,
            allowance,
            &wheel,
            &pilgrim_kernel::program::pass_blocks(&out.program, &out.toolpath.passes),
        );
        pilgrim_kernel::process::check(
            &out.program,
            kin,
            &out.toolpath.tool.reference,
            Some(&stock),
            &limits,
        )
        .unwrap()
    };
    assert!(process().errors.is_empty());
    g.bench_function("process_rules_default_program", |b| {
        b.iter(|| black_box(process()))
    });
    g.finish();
}

criterion_group!(benches, caliber_job, caliber_verify);
criterion_main!(benches);
