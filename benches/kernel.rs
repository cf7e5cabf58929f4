//! Kernel benchmarks (issue: geometry kernel). Run: `cargo bench --bench kernel`.
//!
//! Groups and targets:
//! - `chain_fk`: the universal 15-factor chain, forward kinematics of a batch
//!   of 1M poses (<= 50 ns per pose);
//! - `ik_5axis`: inverse kinematics on the Mannesmann 5-axis chain (<= 10 us
//!   per pose), cold (from the machine's home) and warm (from the previous
//!   pose's solution, as along a toolpath);
//! - `equidistant_1m`: the equidistant of a 1M-point profile (<= 30 ms);
//! - `envelope_100k`: the envelope of 100k wheel positions evaluated at a
//!   100k-point profile (<= 100 ms);
//! - `lint_1m`: a program of 1M blocks in one pass (a circle of the demo
//!   family at its largest `points`) read back by the lint, CL file and
//!   Sinumerik: linear in the blocks (the CL file's lint was quadratic,
//!   about 30 minutes).

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use pilgrim_kernel::{
    equidistant, Chain, CircleEnvelope, IkOptions, Machine, MandrelLaw, Point3, Pose, Side, Target,
    ToolFrame,
};
use std::hint::black_box;
use std::time::Duration;

fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

fn chain_fk(c: &mut Criterion) {
    const N: usize = 1_000_000;
    let chain = Chain::universal();
    let mut s = 1u64;
    let rows: Vec<f64> = (0..N * 15).map(|_| 400.0 * lcg(&mut s) - 200.0).collect();
    let tool = ToolFrame::default();
    let mut out: Vec<Pose> = Vec::with_capacity(N);
    let mut g = c.benchmark_group("chain_fk");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("universal_1M_poses", |b| {
        b.iter(|| {
            chain.poses_into(black_box(&rows), &tool, &mut out).unwrap();
            black_box(out.len())
        })
    });
    g.finish();
}

/// Reachable Mannesmann poses along a path: a wheel winding round the roll.
fn mannesmann_targets(n: usize) -> (Machine, ToolFrame, Vec<Target>) {
    let m = Machine::from_info(mannesmann::describe()).unwrap();
    let tool = ToolFrame {
        point: Point3::new(-60.0, 0.0, 0.0),
        ..ToolFrame::default()
    };
    let chain = m.chain().clone();
    let targets = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64;
            // X, Z, Y, A, B
            let q = [
                40.0 * (6.0 * t).sin(),
                300.0 + 20.0 * (9.0 * t).cos(),
                10.0 * t,
                (300.0 * t - 150.0).to_radians(),
                (25.0 * (4.0 * t).sin()).to_radians(),
            ];
            let p = chain.pose(&q, &tool).unwrap();
            Target::pose(p.point, p.axis)
        })
        .collect();
    (m, tool, targets)
}

fn ik_5axis(c: &mut Criterion) {
    const N: usize = 1000;
    let (m, tool, targets) = mannesmann_targets(N);
    let opts = IkOptions::default();
    let mut g = c.benchmark_group("ik_5axis");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("cold_from_home", |b| {
        b.iter(|| {
            for t in &targets {
                black_box(m.inverse(t, &tool, None, &opts).unwrap());
            }
        })
    });
    g.bench_function("warm_along_path", |b| {
        b.iter(|| {
            let mut seed = m.inverse(&targets[0], &tool, None, &opts).unwrap().q;
            for t in &targets {
                seed = m.inverse(t, &tool, Some(&seed), &opts).unwrap().q;
            }
            black_box(seed)
        })
    });
    g.finish();
}

fn law() -> MandrelLaw {
    MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap()
}

fn equidistant_1m(c: &mut Criterion) {
    const N: usize = 1_000_000;
    let analytic = law().profile(400.0 / (N - 1) as f64, 0.0).unwrap();
    assert_eq!(analytic.len(), N);
    let estimated = analytic.clone().without_derivatives();
    let mut g = c.benchmark_group("equidistant_1m");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("analytic_derivatives", |b| {
        b.iter(|| black_box(equidistant(&analytic, 20.0, Side::Outside).unwrap()))
    });
    g.bench_function("divided_differences", |b| {
        b.iter(|| black_box(equidistant(&estimated, 20.0, Side::Outside).unwrap()))
    });
    g.finish();
}

fn envelope_100k(c: &mut Criterion) {
    const N: usize = 100_000;
    let profile = law().profile(400.0 / (N - 1) as f64, 0.0).unwrap();
    let e = equidistant(&profile, 20.0, Side::Outside).unwrap();
    let mut g = c.benchmark_group("envelope_100k");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("build_and_evaluate", |b| {
        b.iter_batched(
            || (e.z.clone(), e.x.clone()),
            |(z, x)| {
                let env = CircleEnvelope::new(&z, &x, 20.0, Side::Outside).unwrap();
                black_box(env.eval_many(profile.z()))
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

/// A one-pass program of `n` blocks round a circle on X, Y, Z.
fn circle_program(n: usize) -> pilgrim_kernel::program::AxisProgram {
    use pilgrim_kernel::program::{AxisProgram, Block, ProgramAxis, ProgramSetup};
    use pilgrim_kernel::toolpath::Motion;
    let axis = |name: &str| ProgramAxis {
        name: name.into(),
        unit: "mm".into(),
    };
    let blocks = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            Block {
                motion: if i == 0 {
                    Motion::Rapid
                } else {
                    Motion::Linear
                },
                values: vec![50.0 * t.cos(), 50.0 * t.sin(), -2.0],
                feed: if i == 0 { 0.0 } else { 1000.0 },
                spindle: None,
                comment: (i == 0).then(|| "circle".to_owned()),
                keep: Vec::new(),
                number: None,
                line: None,
                dwell_s: 0.0,
            }
        })
        .collect();
    AxisProgram {
        name: "CIRCLE".into(),
        number: 1,
        machine: "vertical-mill".into(),
        control: "sinumerik".into(),
        tool_number: 1,
        tool_name: "end mill".into(),
        spindle_rpm: 1000.0,
        decimals: None,
        axes: vec![axis("X"), axis("Y"), axis("Z")],
        blocks,
        setup: ProgramSetup::default(),
        cycles: Vec::new(),
        fanuc_cycles: Vec::new(),
    }
}

fn lint_1m(c: &mut Criterion) {
    use pilgrim_kernel::program::lint::lint;
    use pilgrim_kernel::program::post::{post, CLD, SINUMERIK};
    const N: usize = 1_000_000;
    let program = circle_program(N);
    let axes: Vec<_> = ["X", "Y", "Z"]
        .iter()
        .map(|n| pilgrim_kernel::machine::Axis::linear(n, -500.0, 500.0, 1e4, [0.0; 3], ""))
        .collect();
    let mut g = c.benchmark_group("lint_1m");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for d in [&CLD, &SINUMERIK] {
        let text = post(&program, d).unwrap();
        assert_eq!(lint(&text, &program, d, &axes).unwrap().moves, N);
        g.bench_function(d.name, |b| {
            b.iter(|| lint(black_box(&text), &program, d, &axes).unwrap())
        });
    }
    g.finish();
}

/// A DXF drawing's nominal read from 1,000 entities: the upper half of a
/// turned outline as LINEs (a wave over 500 mm) on layer PROFILE, its
/// faces and axis besides, in millimetres.
fn dxf_1000(c: &mut Criterion) {
    let n = 996;
    let x = |i: usize| 20.0 + 2.0 * (i as f64 * 0.02).sin();
    let z = |i: usize| 0.5 * i as f64;
    let mut text = String::from(
        "0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1015\n9\n$INSUNITS\n70\n4\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n",
    );
    let mut line = |h: usize, a: (f64, f64), b: (f64, f64)| {
        text += &format!(
            "0\nLINE\n5\n{h:X}\n8\nPROFILE\n10\n{}\n20\n{}\n30\n0\n11\n{}\n21\n{}\n31\n0\n",
            a.0, a.1, b.0, b.1
        );
    };
    for i in 0..n {
        line(i + 16, (z(i), x(i)), (z(i + 1), x(i + 1)));
    }
    line(2000, (0.0, 0.0), (0.0, x(0)));
    line(2001, (z(n), x(n)), (z(n), 0.0));
    line(2002, (0.0, 0.0), (z(n), 0.0));
    line(2003, (0.0, -x(0)), (z(n), -x(n)));
    text += "0\nENDSEC\n0\nEOF\n";
    let bytes = text.into_bytes();
    let options = pilgrim_kernel::profile::DxfOptions {
        layer: "PROFILE".into(),
        diameter: false,
        chordal: 1e-4,
    };
    let mut g = c.benchmark_group("dxf");
    g.throughput(Throughput::Elements(1000));
    g.bench_function("dxf_import_1000_entities", |b| {
        b.iter(|| pilgrim_kernel::profile::profile_from_dxf(&bytes, "wave.dxf", &options).unwrap())
    });
    g.finish();
}

criterion_group!(
    kernel,
    chain_fk,
    ik_5axis,
    equidistant_1m,
    envelope_100k,
    lint_1m,
    dxf_1000
);
criterion_main!(kernel);
