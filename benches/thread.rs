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
//!   A of `scripts/examples/thread-g1-2a.toml`.

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
    ] {
        let run = || {
            let family = ScriptFamily::load(
                &root.join("scripts/thread.rhai"),
                &Limits::default(),
                &Access::default(),
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

criterion_group!(benches, thread_job);
criterion_main!(benches);
