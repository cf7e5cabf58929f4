//! Meshes: closed and manifold for every body type over random parameters,
//! volumes against analytic ones, files that other programs read.

use pilgrim_kernel::math::simpson;
use pilgrim_kernel::mesh::{
    body_of_revolution, cylinder, revolve, sweep, wheel, write_glb, write_stl, MeshError, Scene,
    StlFormat, TriMesh,
};
use pilgrim_kernel::{MandrelLaw, Mat4, ProfileBuilder, Wheel};
use proptest::prelude::*;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Where the tests leave files for the external checkers (`.ci/run` runs
/// the Khronos glTF validator and FreeCAD over them): target/mesh-check.
fn check_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let target = exe.ancestors().nth(3).unwrap().to_owned();
    let d = target.join("mesh-check");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The mesh is closed and oriented, by our check and, after a trip through
/// a binary STL, by stl_io's own reader and validator.
fn assert_solid(m: &TriMesh, what: &str) {
    m.check_closed().unwrap_or_else(|e| panic!("{what}: {e}"));
    let mut bytes = Vec::new();
    write_stl(m, what, StlFormat::Binary, &mut bytes).unwrap();
    assert_eq!(bytes.len(), 84 + 50 * m.triangle_count());
    assert!(
        bytes.starts_with(b"pilgrim ")
            && String::from_utf8_lossy(&bytes[..80]).contains("units=mm")
    );
    let read = stl_io::read_stl(&mut std::io::Cursor::new(&bytes)).unwrap();
    read.validate()
        .unwrap_or_else(|e| panic!("{what}: stl_io: {e}"));
    assert_eq!(read.faces.len(), m.triangle_count());
    // Normals point outward: each facet's normal agrees with its winding, and the volume is positive.
    assert!(m.volume() > 0.0, "{what}");
}

fn law_profile(d_min: f64, d_max: f64, l: f64, k: f64, n: f64) -> pilgrim_kernel::Profile {
    MandrelLaw::new(d_min, d_max, l, k, n)
        .unwrap()
        .profile(l / 200.0, 0.0)
        .unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    #[test]
    fn bodies_of_revolution_are_solids(d_min in 10.0..60.0f64, extra in 0.0..20.0f64, l in 20.0..400.0f64,
                                       n in 1.0..4.0f64, tol in 0.005..0.5f64) {
        let p = law_profile(d_min, d_min + extra, l, 0.0, n);
        assert_solid(&body_of_revolution(&p, tol).unwrap(), "law body");
    }

    #[test]
    fn wheels_are_solids(d in 20.0..600.0f64, w in 2.0..80.0f64, frac in 0.05..1.0f64, tol in 0.005..0.5f64) {
        let rho = (frac * 0.5 * w).min(0.5 * d);
        let m = wheel(&Wheel::new(d, rho, w).unwrap(), tol).unwrap();
        assert_solid(&m, "wheel");
        // The lowest point of the periphery is at the origin (the programmed point).
        let (lo, _) = m.bounds();
        prop_assert!(lo[0].abs() < 1e-9);
    }

    #[test]
    fn cylinders_are_solids(r in 0.5..100.0f64, l in 0.5..500.0f64, tol in 0.001..1.0f64) {
        assert_solid(&cylinder(r, l, tol).unwrap(), "cylinder");
    }

    #[test]
    fn swept_sections_are_solids(a0 in 2.0..20.0f64, b0 in 1.0..10.0f64, grow in 0.5..1.5f64, bend in 0.0..0.8f64, m in 8usize..64) {
        // A half-elliptical groove section closed by a chord, carried round
        // an arc while its depth and width change (a caliber's groove).
        let rings: Vec<Vec<[f64; 3]>> = (0..30).map(|j| {
            let t = j as f64 / 29.0;
            let (a, b) = (a0 * (1.0 + (grow - 1.0) * t), b0 * (1.0 + (grow - 1.0) * t));
            let phi = bend * t;
            (0..m).map(|k| {
                let psi = -PI / 2.0 + PI * k as f64 / (m - 1) as f64;
                let (x, r) = (a * psi.sin(), 100.0 - b * psi.cos());
                [r * phi.cos(), r * phi.sin(), x]
            }).collect()
        }).collect();
        assert_solid(&sweep(&rings).unwrap(), "swept groove");
    }
}

#[test]
fn cylinder_volume_within_the_polygon_bound() {
    for (r, l, tol) in [(10.0, 20.0, 0.01), (50.0, 5.0, 0.1), (2.0, 100.0, 0.001)] {
        let m = cylinder(r, l, tol).unwrap();
        let exact = PI * r * r * l;
        let n = (2.0 * PI / (2.0 * (1.0f64 - tol / r).acos()))
            .ceil()
            .max(8.0);
        let n = n + n % 2.0; // even
        let bound = exact * (2.0 * PI / n).powi(2) / 6.0;
        let deficit = exact - m.volume();
        assert!(
            deficit >= 0.0 && deficit <= bound,
            "r {r}: deficit {deficit} bound {bound}"
        );
        // Exactly the inscribed polygon's area times the length.
        assert!((m.volume() - 0.5 * n * r * r * (2.0 * PI / n).sin() * l).abs() < 1e-9 * exact);
    }
}

#[test]
fn body_of_revolution_volume_within_its_bound() {
    let law = MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap();
    let p = law.profile(0.05, 0.0).unwrap();
    for tol in [0.01, 0.1] {
        let m = body_of_revolution(&p, tol).unwrap();
        // pi * integral of x^2 (Simpson, fine) and the lateral area.
        let steps = 40_000;
        let h = 400.0 / steps as f64;
        let zs: Vec<f64> = (0..=steps).map(|i| i as f64 * h).collect();
        let squares: Vec<f64> = zs.iter().map(|&z| law.x(z).powi(2)).collect();
        let bands: Vec<f64> = zs
            .iter()
            .map(|&z| law.x(z) * (1.0 + law.dx(z).powi(2)).sqrt())
            .collect();
        let (v, a) = (PI * simpson(&squares, h), 2.0 * PI * simpson(&bands, h));
        let r_max = 26.0;
        let n = (2.0 * PI / (2.0 * (1.0 - tol / 2.0 / r_max).acos())).ceil();
        let bound = v * (2.0 * PI / n).powi(2) / 6.0 + tol / 2.0 * a;
        let err = (m.volume() - v).abs();
        assert!(err <= bound, "tol {tol}: |dV| {err} > {bound}");
    }
}

#[test]
fn wheel_volume_by_pappus() {
    for (d, rho, w, tol) in [
        (500.0, 25.0, 50.0, 0.01),
        (400.0, 10.0, 40.0, 0.05),
        (100.0, 3.0, 20.0, 0.01),
    ] {
        let m = wheel(&Wheel::new(d, rho, w).unwrap(), tol).unwrap();
        let r = d / 2.0;
        // Each rounded corner removes a square of rho^2 less a quarter disc,
        // whose centroid stands rho / 6 / (1 - pi/4) beyond r - rho.
        let corner = rho * rho * (1.0 - PI / 4.0);
        let rc = r - rho + rho / 6.0 / (1.0 - PI / 4.0);
        let exact = PI * r * r * w - 2.0 * 2.0 * PI * rc * corner;
        let n = (2.0 * PI / (2.0 * (1.0f64 - tol / 2.0 / r).acos())).ceil();
        let arc_len = PI * rho; // both quarter arcs
        let bound = exact * (2.0 * PI / n).powi(2) / 6.0 + tol / 2.0 * arc_len * 2.0 * PI * r;
        let err = (m.volume() - exact).abs();
        assert!(err <= bound, "wheel {d}: |dV| {err} > {bound}");
    }
}

#[test]
fn swept_elliptic_cylinder_volume_is_the_polygons() {
    let (a, b, m, l) = (12.0, 5.0, 90, 30.0);
    let ring = |z: f64| -> Vec<[f64; 3]> {
        (0..m)
            .map(|k| {
                let t = 2.0 * PI * k as f64 / m as f64;
                [a * t.cos(), b * t.sin(), z]
            })
            .collect()
    };
    let s = sweep(&[ring(0.0), ring(l / 2.0), ring(l)]).unwrap();
    let polygon = 0.5 * m as f64 * a * b * (2.0 * PI / m as f64).sin();
    assert!((s.volume() - polygon * l).abs() < 1e-9 * polygon * l);
}

#[test]
fn bad_input_is_refused() {
    // A bow-tie section crosses itself.
    let e = revolve(
        &[[0.0, 1.0], [10.0, 5.0], [10.0, 1.0], [0.0, 5.0], [0.0, 1.0]],
        0.01,
    )
    .unwrap_err();
    assert!(matches!(e, MeshError::SelfIntersecting(_)), "{e}");
    // An open section.
    let e = revolve(&[[0.0, 0.0], [10.0, 0.0], [10.0, 5.0], [0.0, 5.0]], 0.01).unwrap_err();
    assert!(e.to_string().contains("the section is open"), "{e}");
    // Below the axis, and touching it at a point.
    assert!(revolve(&[[0.0, 0.0], [10.0, 0.0], [10.0, -5.0], [0.0, 0.0]], 0.01).is_err());
    let e = revolve(
        &[
            [0.0, 2.0],
            [5.0, 0.0],
            [10.0, 2.0],
            [10.0, 4.0],
            [0.0, 4.0],
            [0.0, 2.0],
        ],
        0.01,
    )
    .unwrap_err();
    assert!(e.to_string().contains("pinch"), "{e}");
    // A profile that reaches the axis inside.
    let p = pilgrim_kernel::Profile::new(vec![0.0, 1.0, 2.0], vec![3.0, 0.0, 3.0]).unwrap();
    let e = body_of_revolution(&p, 0.01).unwrap_err().to_string();
    assert!(e.contains("z = 1") && e.contains("positive radius"), "{e}");
    // Zero radii, tolerances.
    assert!(cylinder(0.0, 10.0, 0.01)
        .unwrap_err()
        .to_string()
        .contains("cylinder radius"));
    assert!(cylinder(1.0, 10.0, 0.0)
        .unwrap_err()
        .to_string()
        .contains("chordal tolerance"));
    assert!(cylinder(1.0, 10.0, -1.0).is_err());
    let e = Wheel::new(500.0, 30.0, 50.0).unwrap_err().to_string();
    assert!(e.contains("half the width"), "{e}");
    let w = Wheel::new(500.0, 20.0, 50.0).unwrap();
    assert!(wheel(&w, 0.0).is_err());
    // A section no point sees whole (a deep notch) makes a solid: its caps
    // are ear-clipped, its volume the section's area (100 - 81 = 19 mm^2)
    // times 5.
    let notched = |z: f64| -> Vec<[f64; 3]> {
        vec![
            [0.0, 0.0, z],
            [10.0, 0.0, z],
            [10.0, 10.0, z],
            [9.0, 1.0, z],
            [1.0, 1.0, z],
            [0.0, 10.0, z],
        ]
    };
    let m = sweep(&[notched(0.0), notched(5.0)]).unwrap();
    m.check_closed().unwrap();
    assert!((m.volume() - 19.0 * 5.0).abs() < 1e-9, "{}", m.volume());
    // A section that crosses itself is refused.
    let bow = |z: f64| {
        vec![
            [0.0, 0.0, z],
            [10.0, 10.0, z],
            [10.0, 0.0, z],
            [0.0, 10.0, z],
        ]
    };
    let e = sweep(&[bow(0.0), bow(5.0)]).unwrap_err().to_string();
    assert!(e.contains("section 0"), "{e}");
}

/// The meshes in a scene written as .glb, read back by the gltf crate, and
/// left with STL files for the external checkers.
#[test]
fn scene_glb_reads_back_and_files_are_left_for_checkers() {
    let law = MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap();
    let profile = ProfileBuilder::start(-60.0, 16.0)
        .cylinder(30.0)
        .line_to(-25.0, 19.0)
        .cylinder(25.0)
        .law(law)
        .line_to(440.0, 20.0)
        .build(1e-3, 1.0)
        .unwrap();
    let part = body_of_revolution(&profile, 0.01).unwrap();
    let w = wheel(&Wheel::new(500.0, 25.0, 50.0).unwrap(), 0.01).unwrap();
    let rest = cylinder(25.0, 40.0, 0.01).unwrap();
    let groove: Vec<Vec<[f64; 3]>> = (0..20)
        .map(|j| {
            (0..24)
                .map(|k| {
                    let psi = -PI / 2.0 + PI * k as f64 / 23.0;
                    [6.0 * psi.sin(), 3.0 * psi.cos() + 0.1 * j as f64, j as f64]
                })
                .collect()
        })
        .collect();
    let groove = sweep(&groove).unwrap();
    let mut scene = Scene::new();
    let place = Mat4::new_translation(&pilgrim_kernel::Vec3::new(30.0, 0.0, 200.0));
    scene.add(
        "part",
        part.clone(),
        Mat4::identity(),
        [0.7, 0.7, 0.75, 1.0],
    );
    scene.add("wheel", w.clone(), place, [0.3, 0.4, 0.8, 1.0]);
    scene.add(
        "rest",
        rest.clone(),
        Mat4::new_rotation(pilgrim_kernel::Vec3::new(0.0, 0.3, 0.0)),
        [0.8, 0.5, 0.2, 1.0],
    );
    scene.add(
        "groove",
        groove.clone(),
        Mat4::identity(),
        [0.5, 0.8, 0.5, 1.0],
    );
    let mut bytes = Vec::new();
    write_glb(&scene, &mut bytes).unwrap();
    let doc = gltf::Gltf::from_slice(&bytes).unwrap();
    assert_eq!(doc.meshes().count(), 4);
    let root = doc.scenes().next().unwrap().nodes().next().unwrap();
    assert_eq!(root.transform().decomposed().2, [0.001; 3]);
    let names: Vec<String> = root
        .children()
        .map(|n| n.name().unwrap().to_owned())
        .collect();
    assert_eq!(names, ["part", "wheel", "rest", "groove"]);
    let wheel_node = root.children().nth(1).unwrap();
    assert_eq!(wheel_node.transform().decomposed().0, [30.0, 0.0, 200.0]);
    // Same input, same bytes.
    let mut again = Vec::new();
    write_glb(&scene, &mut again).unwrap();
    assert_eq!(bytes, again);
    let dir = check_dir();
    std::fs::write(dir.join("scene-kernel.glb"), &bytes).unwrap();
    for (name, m) in [
        ("part", &part),
        ("wheel", &w),
        ("rest", &rest),
        ("groove", &groove),
    ] {
        let mut f = std::fs::File::create(dir.join(format!("kernel-{name}.stl"))).unwrap();
        write_stl(m, name, StlFormat::Binary, &mut f).unwrap();
    }
    let mut ascii = Vec::new();
    write_stl(&rest, "rest support", StlFormat::Ascii, &mut ascii).unwrap();
    let text = String::from_utf8(ascii.clone()).unwrap();
    assert!(
        text.starts_with("solid rest_support\n  facet normal ")
            && text.ends_with("endsolid rest_support\n")
    );
    let read = stl_io::read_stl(&mut std::io::Cursor::new(&ascii)).unwrap();
    read.validate().unwrap();
    std::fs::write(dir.join("kernel-rest-ascii.stl"), &ascii).unwrap();
}
