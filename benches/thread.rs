//! Thread benchmarks. Run: `cargo bench --bench thread`.
//!
//! - `thread_job`: the default job (`scripts/thread.rhai`: an external
//!   M20x2.5-6g, 30 mm, on the Fanuc 0i-TC) through the kernel's job call,
//!   in process: the script loaded, the designation read, the plan,
//!   inverse kinematics, the pass-by-pass simulation against ISO 965-1's
//!   limits with the measurement over wires, the collision check, the
//!   posts, the charts, `passes.xlsx`, the meshes, `report.html` and the
//!   bytes of every file (not written to disk) (target <= 0.5 s); and the
//!   same for the Tr 40x7 of `scripts/examples/thread-tr40x7.toml` and
//!   the M30x2-6H nut of `scripts/examples/thread-m30x2-6h.toml` (cut
//!   inside its bore on the boring bar); the default M20 planned as
//!   LinuxCNC's G76 makes it (`cycle = "g76"`), posted for LinuxCNC too
//!   (the cycle written, its lint expanding it); and the pipe thread G 1/2
//!   A of `scripts/examples/thread-g1-2a.toml`; and the common sizes the
//!   default tool table (`scripts/thread-tools.csv`) makes go through:
//!   M8x1.25-6g (chuck alone, the long holder), M10x1.5-6g, M12x1.5-6H
//!   (the 7 mm bar), M36x4-6H, M42x4.5-6H (the 20 mm bar) and `Tr 40x7`
//!   as ISO 2904 spells it (30 mm each).
//! - `thread_verify_text`: `verify` of a shop's M20x2.5 program read from
//!   its text (`tests/corpus/fanuc/g76_m20.plain.nc`: G32 passes left and
//!   returned in rapids), and the same passes left and returned at feed
//!   (`g32_feed_return.nc`), whose thirteen returns clear of the material
//!   the contact test finds and the verification is made again without:
//!   what the regrouping costs.

use criterion::{criterion_group, criterion_main, Criterion};
use pilgrim_kernel::catalog::{Catalog, CompiledPlugin};
use pilgrim_kernel::job::{self, JobOptions};
use pilgrim_kernel::params::ParamSource;
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn thread_job(c: &mut Criterion) {
    let catalog = Catalog::new(&[CompiledPlugin {
        symbol: "pilgrim_plugin_fanuc_0i_tc",
        entry: fanuc_0i_tc::pilgrim_plugin_fanuc_0i_tc,
    }])
    .unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let options = JobOptions {
        program_name: "thread".into(),
        ..JobOptions::default()
    };
    let mut g = c.benchmark_group("thread_job");
    g.sample_size(20).measurement_time(Duration::from_secs(10));
    let example = |file: &str| {
        vec![ParamSource::Toml {
            label: file.into(),
            text: std::fs::read_to_string(root.join("scripts/examples").join(file)).unwrap(),
        }]
    };
    let designation = |d: &str| {
        vec![ParamSource::Toml {
            label: d.into(),
            text: format!("designation = \"{d}\"\n"),
        }]
    };
    let g76 = vec![ParamSource::Toml {
        label: "cycle".into(),
        text: "cycle = \"g76\"\n".into(),
    }];
    let linuxcnc = JobOptions {
        also_post: vec!["linuxcnc".into()],
        ..options.clone()
    };
    for (name, sets, options) in [
        ("default_m20_end_to_end", vec![], &options),
        ("tr40x7_end_to_end", example("thread-tr40x7.toml"), &options),
        (
            "m30_nut_end_to_end",
            example("thread-m30x2-6h.toml"),
            &options,
        ),
        ("m20_g76_linuxcnc_end_to_end", g76, &linuxcnc),
        ("g1_2a_end_to_end", example("thread-g1-2a.toml"), &options),
        (
            "worm_zi_end_to_end",
            example("thread-worm-zi.toml"),
            &options,
        ),
        ("m8x1_25_6g_end_to_end", designation("M8x1.25-6g"), &options),
        ("m10x1_5_6g_end_to_end", designation("M10x1.5-6g"), &options),
        ("m12x1_5_6h_end_to_end", designation("M12x1.5-6H"), &options),
        ("m36x4_6h_end_to_end", designation("M36x4-6H"), &options),
        ("m42x4_5_6h_end_to_end", designation("M42x4.5-6H"), &options),
        (
            "tr_40x7_spelled_end_to_end",
            designation("Tr 40x7"),
            &options,
        ),
    ] {
        let run = || {
            let family = ScriptFamily::load(
                &root.join("scripts/thread.rhai"),
                &Limits::default(),
                &Access {
                    input_dirs: vec![root.join("scripts")],
                    ..Access::default()
                },
            )
            .unwrap();
            let machine = catalog.open("fanuc-0i-tc").unwrap();
            job::run(&family, &machine, &sets, options, &mut |_| {}).unwrap()
        };
        let out = run();
        assert!(
            out.check::<pilgrim_kernel::families::thread::ThreadOutcome>()
                .is_some()
                && out.files.len() >= 12,
            "{name}: {} files",
            out.files.len()
        );
        g.bench_function(name, |b| b.iter(|| black_box(run())));
    }
    g.finish();
}

fn thread_verify_text(c: &mut Criterion) {
    let catalog = Catalog::new(&[CompiledPlugin {
        symbol: "pilgrim_plugin_fanuc_0i_tc",
        entry: fanuc_0i_tc::pilgrim_plugin_fanuc_0i_tc,
    }])
    .unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let family = ScriptFamily::load(
        &root.join("scripts/thread.rhai"),
        &Limits::default(),
        &Access {
            input_dirs: vec![root.join("scripts")],
            ..Access::default()
        },
    )
    .unwrap();
    let machine = catalog.open("fanuc-0i-tc").unwrap();
    let options = JobOptions::default();
    let mut g = c.benchmark_group("thread_verify_text");
    g.sample_size(20).measurement_time(Duration::from_secs(10));
    for (name, file) in [
        ("m20_g32_rapid_returns", "g76_m20.plain.nc"),
        ("m20_g32_feed_returns", "g32_feed_return.nc"),
    ] {
        let text = std::fs::read_to_string(root.join("tests/corpus/fanuc").join(file)).unwrap();
        let verify = || job::verify(&family, &machine, &[], &text, &options, &mut |_| {});
        let passes = verify().unwrap().report.cutting_passes;
        assert_eq!(passes, 13, "{file}");
        g.bench_function(name, |b| b.iter(|| black_box(verify().is_ok())));
    }
    g.finish();
}

criterion_group!(benches, thread_job, thread_verify_text);
criterion_main!(benches);
