//! Runtime benchmarks (issue: runtime). Run: `cargo bench --bench runtime`.
//!
//! - `rhai_overhead`: the demo family's toolpath for 100k points through
//!   Rhai, against the same computation written in Rust (target: ratio <= 1.5);
//! - `plugin_batch`: inverse kinematics of 10k poses through the 3K152VF20
//!   plugin loaded as a shared library, against the compiled-in machine
//!   (target: <= 5% slower);
//! - `verify_deadline`: the demo family's program of 1M blocks verified
//!   under `--run-seconds 1` (the whole verification takes several): how
//!   long until the run's deadline stops it (target: within 2x the limit);
//! - `verify_loop`: the demo family's contour written by hand as a
//!   Sinumerik `WHILE` loop of one block (`C=R1*360/N`), 10k and 100k
//!   turns, read and verified as the program's (target: linear in the
//!   blocks: the 100k loop within 12x the 10k's).

use criterion::{criterion_group, criterion_main, Criterion};
use pilgrim_kernel::params::{resolve, ParamSource};
use pilgrim_kernel::plugin::PluginMachine;
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::{
    ClPoint, MachineKinematics, Motion, PartFamily, Pass, Point3, Tool, ToolFrame, Toolpath, Vec3,
};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

const POINTS: usize = 100_000;

/// The demo's toolpath, written in Rust with the same steps as the script.
fn demo_in_rust(
    radius: f64,
    tool_d: f64,
    depth: f64,
    feed: f64,
    rpm: f64,
    clearance: f64,
) -> Toolpath {
    let tool = Tool::end_mill("end mill", 1, tool_d, 3.0 * depth).unwrap();
    let r = radius + tool_d / 2.0;
    let n = POINTS + 1;
    let beta: Vec<f64> = (0..n)
        .map(|i| 2.0 * std::f64::consts::PI * i as f64 / (n - 1) as f64)
        .collect();
    let deg = 180.0 / std::f64::consts::PI;
    let xs: Vec<f64> = beta.iter().map(|b| b.cos() * r).collect();
    let ys: Vec<f64> = beta.iter().map(|b| b.sin() * r).collect();
    let cs: Vec<f64> = beta.iter().map(|b| b * deg).collect();
    let mut tp = Toolpath::new("mill_circle", tool, rpm, vec!["C".into()]);
    let pt = |x: f64, y: f64, z: f64, motion, feed, c: f64| ClPoint {
        point: [x, y, z],
        axis: [0.0, 0.0, 1.0],
        motion,
        feed,
        aux: vec![c],
    };
    tp.passes.push(Pass {
        name: "approach".into(),
        points: vec![
            pt(r, 0.0, clearance, Motion::Rapid, 0.0, 0.0),
            pt(r, 0.0, 1.0, Motion::Rapid, 0.0, 0.0),
        ],
    });
    tp.passes.push(Pass {
        name: "plunge".into(),
        points: vec![pt(r, 0.0, -depth, Motion::Linear, feed / 3.0, 0.0)],
    });
    tp.passes.push(Pass {
        name: "contour".into(),
        points: (0..n)
            .map(|i| pt(xs[i], ys[i], -depth, Motion::Linear, feed / r * deg, cs[i]))
            .collect(),
    });
    tp.passes.push(Pass {
        name: "retract".into(),
        points: vec![pt(r, 0.0, clearance, Motion::Rapid, 0.0, 360.0)],
    });
    tp
}

fn rhai_overhead(c: &mut Criterion) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/examples/mill_circle.rhai");
    let family = ScriptFamily::load(&script, &Limits::default(), &Access::default()).unwrap();
    let values = resolve(
        family.params(),
        &Default::default(),
        &[ParamSource::Pairs {
            label: "--set".into(),
            pairs: vec![("points".into(), POINTS.to_string())],
        }],
    )
    .unwrap();
    let from_script = family.toolpath(&values).unwrap();
    let native = demo_in_rust(40.0, 10.0, 5.0, 600.0, 3000.0, 5.0);
    assert_eq!(from_script.point_count(), native.point_count());
    let mut g = c.benchmark_group("rhai_overhead");
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("demo_100k_points_rhai", |b| {
        b.iter(|| black_box(family.toolpath(&values).unwrap()))
    });
    g.bench_function("demo_100k_points_rust", |b| {
        b.iter(|| black_box(demo_in_rust(40.0, 10.0, 5.0, 600.0, 3000.0, 5.0)))
    });
    g.finish();
}

fn plugin_batch(c: &mut Criterion) {
    const N: usize = 10_000;
    let exe = std::env::current_exe().unwrap();
    let lib = exe.parent().and_then(Path::parent).unwrap().join(format!(
        "{}grinder_3k152vf20{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    {
        // `cargo bench` builds the plugin crate as a dependency (rlib) only:
        // build its shared library, in this same profile (a no-op when current).
        let status = std::process::Command::new(env!("CARGO"))
            .args([
                "build",
                "--release",
                "-p",
                "pilgrim-grinder-3k152vf20",
                "--lib",
            ])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .status()
            .expect("cargo runs");
        assert!(
            status.success(),
            "building the plugin's shared library failed"
        );
    }
    // The library runs in a child process (`pilgrim plugin-server`): the
    // batch crosses a pipe both ways.
    pilgrim_kernel::plugin::configure(
        Some(env!("CARGO_BIN_EXE_pilgrim").into()),
        pilgrim_kernel::plugin::Bounds::default(),
    );
    let loaded = PluginMachine::load(&lib).unwrap();
    // Compiled in: the same ABI, without the library.
    let built_in = PluginMachine::from_entry(
        "3K152VF20",
        "pilgrim_plugin_grinder_3k152vf20",
        grinder_3k152vf20::pilgrim_plugin_grinder_3k152vf20,
    )
    .unwrap();
    let tool = ToolFrame {
        point: Point3::new(20.0, 0.0, 0.0),
        axis: Vec3::z(),
    };
    let poses: Vec<f64> = (0..N)
        .flat_map(|i| {
            [
                45.0 + (i as f64 * 0.01).sin(),
                0.0,
                0.04 * i as f64,
                0.0,
                0.0,
                1.0,
            ]
        })
        .collect();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    built_in.inverse(&poses, &tool, &mut a).unwrap();
    loaded.inverse(&poses, &tool, &mut b).unwrap();
    assert_eq!(a, b);
    let mut g = c.benchmark_group("plugin_batch");
    g.sample_size(50).measurement_time(Duration::from_secs(4));
    g.bench_function("ik_10k_in_process", |bch| {
        bch.iter(|| {
            built_in.inverse(black_box(&poses), &tool, &mut a).unwrap();
            black_box(a.len())
        })
    });
    g.bench_function("ik_10k_shared_library", |bch| {
        bch.iter(|| {
            loaded.inverse(black_box(&poses), &tool, &mut b).unwrap();
            black_box(b.len())
        })
    });
    g.finish();
}

/// The demo family's script and the vertical mill it runs on.
fn demo_on_mill() -> (ScriptFamily, pilgrim_kernel::catalog::OpenMachine) {
    let family = ScriptFamily::load(
        Path::new("scripts/examples/mill_circle.rhai"),
        &Limits::default(),
        &Access::default(),
    )
    .unwrap();
    let catalog = pilgrim_kernel::catalog::Catalog::new(&[]).unwrap();
    (family, catalog.open("vertical-mill").unwrap())
}

/// The time limit the 1M-block verification is given (s).
const LIMIT_SECONDS: f64 = 1.0;

fn verify_deadline(c: &mut Criterion) {
    use pilgrim_kernel::job::{self, JobOptions};
    let (family, machine) = demo_on_mill();
    let sources = vec![ParamSource::Pairs {
        label: "the bench".into(),
        pairs: vec![("points".into(), "1000000".into())],
    }];
    let options = JobOptions::default();
    let out = job::run(&family, &machine, &sources, &options, &mut |_| {}).unwrap();
    let text = out
        .files
        .iter()
        .find(|f| f.0 == "program.mpf")
        .map(|f| String::from_utf8(f.1.clone()).unwrap())
        .unwrap();
    assert!(text.lines().count() > 1_000_000);
    let stopped = || {
        pilgrim_kernel::budget::with_limit(LIMIT_SECONDS, "the run's", || {
            job::verify(&family, &machine, &sources, &text, &options, &mut |_| {})
        })
    };
    // It stops, and by the deadline, not by a fault.
    let started = std::time::Instant::now();
    let e = stopped().map(|_| ()).unwrap_err().to_string();
    assert!(e.contains("time limit"), "{e}");
    eprintln!(
        "verify_deadline: 1M blocks under a {LIMIT_SECONDS} s limit stopped after {:.3} s ({:.2}x): {e}",
        started.elapsed().as_secs_f64(),
        started.elapsed().as_secs_f64() / LIMIT_SECONDS
    );
    let mut g = c.benchmark_group("verify_deadline");
    g.sample_size(10).measurement_time(Duration::from_secs(15));
    g.bench_function("verify_1m_blocks_limit_1s", |b| {
        b.iter(|| black_box(stopped().is_err()))
    });
    g.finish();
}

/// The demo family's program for `n` points with its contour written as a
/// Sinumerik loop of one block: what the shop writes by hand.
fn loop_program(plain: &str, n: usize) -> String {
    let mut out = String::new();
    let mut lines = plain.lines();
    for l in lines.by_ref() {
        if l.starts_with("N70 ") {
            out.push_str(&format!(
                "{l}\nR1=2\nWHILE R1<={n}\nC=R1*360/{n}\nR1=R1+1\nENDWHILE\n"
            ));
            break;
        }
        out.push_str(l);
        out.push('\n');
    }
    // After the contour's blocks (`N.. C..`): the retract and the end.
    for l in lines.skip_while(|l| l.starts_with('N') && l.contains(" C")) {
        out.push_str(l);
        out.push('\n');
    }
    out
}

fn verify_loop(c: &mut Criterion) {
    use pilgrim_kernel::job::{self, JobOptions};
    let (family, machine) = demo_on_mill();
    let options = JobOptions::default();
    let mut g = c.benchmark_group("verify_loop");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    let mut per_block = Vec::new();
    for n in [10_000usize, 100_000] {
        let sources = vec![ParamSource::Pairs {
            label: "the bench".into(),
            pairs: vec![("points".into(), n.to_string())],
        }];
        let out = job::run(&family, &machine, &sources, &options, &mut |_| {}).unwrap();
        let plain = out
            .files
            .iter()
            .find(|f| f.0 == "program.mpf")
            .map(|f| String::from_utf8(f.1.clone()).unwrap())
            .unwrap();
        let text = loop_program(&plain, n);
        assert!(text.lines().count() < 40, "{text}");
        let verify = || job::verify(&family, &machine, &sources, &text, &options, &mut |_| {});
        // The loop is read as the control runs it: the plain program's moves.
        let verified = verify().unwrap();
        assert_eq!(verified.program.blocks.len(), out.program.blocks.len());
        let c = |p: &pilgrim_kernel::program::AxisProgram| p.blocks.last().unwrap().values[3];
        assert!((c(&verified.program) - c(&out.program)).abs() < 1e-9);
        let started = std::time::Instant::now();
        verify().unwrap();
        per_block.push(started.elapsed().as_secs_f64() / n as f64);
        g.bench_function(format!("verify_{}k_turns", n / 1000), |b| {
            b.iter(|| black_box(verify().is_ok()))
        });
    }
    eprintln!(
        "verify_loop: {:.2} us per block at 10k, {:.2} us at 100k",
        per_block[0] * 1e6,
        per_block[1] * 1e6
    );
    g.finish();
}

criterion_group!(
    runtime,
    rhai_overhead,
    plugin_batch,
    verify_deadline,
    verify_loop
);
criterion_main!(runtime);
