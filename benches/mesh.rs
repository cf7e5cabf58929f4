//! Mesh benchmarks (issue: 3-D models). Run: `cargo bench --bench mesh`.
//!
//! - `stl_2m`: tessellate a 2M-triangle body of revolution and write it as
//!   binary STL (target: >= 10M triangles/s);
//! - `glb_2m`: the same written as `.glb`.
//!
//! Before timing, each is run once under a counting allocator to measure
//! the peak memory above what was in use before, against the mesh's own
//! data (positions and normals as f64, indices as u32): target <= 2x.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pilgrim_kernel::mesh::{revolve, write_glb, write_stl, Scene, StlFormat, TriMesh};
use pilgrim_kernel::{MandrelLaw, Mat4};
use std::alloc::{GlobalAlloc, Layout, System};
use std::io::BufWriter;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use std::time::Duration;

struct Counting;
static NOW: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = NOW.fetch_add(l.size(), Relaxed) + l.size();
            PEAK.fetch_max(now, Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        NOW.fetch_sub(l.size(), Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, l, new) };
        if !q.is_null() {
            if new > l.size() {
                let now = NOW.fetch_add(new - l.size(), Relaxed) + new - l.size();
                PEAK.fetch_max(now, Relaxed);
            } else {
                NOW.fetch_sub(l.size() - new, Relaxed);
            }
        }
        q
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// A mandrel's section, 1000 points of the law, turned in 1000 steps: 2M triangles.
fn section() -> (Vec<[f64; 2]>, f64) {
    let law = MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap();
    let mut s = vec![[0.0, 0.0], [400.0, 0.0]];
    s.extend((0..1000).rev().map(|i| {
        let z = 400.0 * i as f64 / 999.0;
        [z, law.x(z)]
    }));
    s.push([0.0, 0.0]);
    // The chordal tolerance that gives 1000 steps on the largest radius (26 mm).
    let tol = 26.0 * (1.0 - (std::f64::consts::PI / 1000.0).cos()) * 1.0001;
    (s, tol)
}

fn out_file(name: &str) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let d = exe.ancestors().nth(3).unwrap().join("bench-out");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn stl_job(s: &[[f64; 2]], tol: f64) -> TriMesh {
    let m = revolve(s, tol).unwrap();
    let mut f = BufWriter::new(std::fs::File::create(out_file("body.stl")).unwrap());
    write_stl(&m, "body", StlFormat::Binary, &mut f).unwrap();
    m
}

fn glb_job(s: &[[f64; 2]], tol: f64) -> TriMesh {
    let m = revolve(s, tol).unwrap();
    let mut scene = Scene::new();
    scene.add("body", m, Mat4::identity(), [0.7, 0.7, 0.7, 1.0]);
    let mut f = BufWriter::new(std::fs::File::create(out_file("body.glb")).unwrap());
    write_glb(&scene, &mut f).unwrap();
    scene.nodes.pop().unwrap().mesh
}

/// Peak bytes allocated by `job` above the level before it, and the mesh.
fn peak(job: impl FnOnce() -> TriMesh) -> (usize, TriMesh) {
    let base = NOW.load(Relaxed);
    PEAK.store(base, Relaxed);
    let m = job();
    (PEAK.load(Relaxed) - base, m)
}

fn mesh_benches(c: &mut Criterion) {
    let (s, tol) = section();
    for (name, job) in [
        ("stl_2m", stl_job as fn(&[[f64; 2]], f64) -> TriMesh),
        ("glb_2m", glb_job),
    ] {
        let (bytes, m) = peak(|| job(&s, tol));
        let ratio = bytes as f64 / m.byte_size() as f64;
        eprintln!(
            "{name}: {} triangles, mesh data {:.1} MB, peak {:.1} MB above the start: {ratio:.2}x",
            m.triangle_count(),
            m.byte_size() as f64 / 1e6,
            bytes as f64 / 1e6
        );
        assert!(m.triangle_count() >= 2_000_000, "{}", m.triangle_count());
        assert!(
            ratio <= 2.0,
            "{name}: peak memory {ratio:.2}x the mesh data"
        );
        let mut g = c.benchmark_group(name);
        g.throughput(Throughput::Elements(m.triangle_count() as u64));
        g.sample_size(10).measurement_time(Duration::from_secs(6));
        g.bench_function("tessellate_and_write", |b| b.iter(|| job(&s, tol)));
        g.finish();
    }
}

criterion_group!(mesh, mesh_benches);
criterion_main!(mesh);
