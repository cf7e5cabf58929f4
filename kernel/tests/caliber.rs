//! The caliber's geometry (MATH §3) checked by geometry: points on the
//! ellipse, distances along normals, circles intersected numerically, the
//! torus against the groove's surface.

use pilgrim_kernel::families::caliber::{
    exact_pose, scallop_height, seed_pose, step_for_scallop, Groove, GrooveError,
};
use pilgrim_kernel::math::Vec3;
use std::f64::consts::FRAC_PI_2;

/// A roll of radius 150 mm whose groove runs through a reduction zone (the
/// depth falling from the hollow's radius, 24 mm, to the tube's, 14.1 mm,
/// over 0..120 deg), a sizing section of constant depth (120..160 deg), the
/// width 2.1 times the depth (slightly oval): rows every 2 deg.
fn reduction_groove() -> Groove {
    let theta: Vec<f64> = (0..=80).map(|i| 2.0 * i as f64).collect();
    let hp: Vec<f64> = theta
        .iter()
        .map(|&t| {
            let s = (t / 120.0).min(1.0);
            14.1 + 9.9 * (1.0 - s).powi(2)
        })
        .collect();
    let b: Vec<f64> = hp.iter().map(|h| 2.1 * h).collect();
    Groove::new(150.0, (&theta, &theta), &hp, &b).unwrap()
}

/// The cusp of two circles of radius `r_k` centred `d = r - r_k` from the
/// origin, `dpsi` apart, inside a circle of radius `r`, intersected in
/// Cartesian coordinates (the radical line), as its depth below `r`.
fn cusp_by_intersection(r: f64, r_k: f64, dpsi: f64) -> f64 {
    let d = r - r_k;
    let (c1, c2) = (
        (d * (dpsi / 2.0).sin(), d * (dpsi / 2.0).cos()),
        (-d * (dpsi / 2.0).sin(), d * (dpsi / 2.0).cos()),
    );
    // Equal radii: the intersections lie on the perpendicular bisector of
    // the centres, at half-chord h from their midpoint.
    let (mx, my) = (0.5 * (c1.0 + c2.0), 0.5 * (c1.1 + c2.1));
    let half = 0.5 * ((c1.0 - c2.0).powi(2) + (c1.1 - c2.1).powi(2)).sqrt();
    let h = (r_k * r_k - half * half).sqrt();
    // The perpendicular to the centres' line (along x) is y: two points.
    let far = (mx.hypot(my + h)).max(mx.hypot(my - h));
    r - far
}

#[test]
fn the_scallop_is_where_two_rounding_circles_meet() {
    for (r, r_k, deg) in [
        (20.0, 5.0, 1.0),
        (20.0, 5.0, 5.0),
        (14.1, 10.0, 3.0),
        (30.0, 2.0, 8.0),
    ] {
        let dpsi = f64::to_radians(deg);
        let rz = scallop_height(r, r_k, dpsi).unwrap();
        let numeric = cusp_by_intersection(r, r_k, dpsi);
        assert!(
            (rz - numeric).abs() < 1e-12,
            "{r} {r_k} {deg}: {rz} vs {numeric}"
        );
        // The inverse: the largest step for that scallop is the step.
        let back = step_for_scallop(r, r_k, rz).unwrap();
        assert!(
            (back - dpsi).abs() < 1e-7,
            "{deg} deg: back {}",
            back.to_degrees()
        );
    }
    // The seed's recommendation, 1 deg finishing, gives microns: 2.3 um
    // for a 5 mm rounding in a 20 mm section (Rz ~ dpsi^2 d (d + r_k) / (8 r_k)).
    let rz = scallop_height(20.0, 5.0, 1f64.to_radians()).unwrap();
    assert!(
        (rz - 0.0174533f64.powi(2) * 15.0 * 20.0 / 40.0).abs() < 1e-5,
        "{rz}"
    );
    // Circles too far apart to meet, a rounding as large as the section.
    assert!(scallop_height(20.0, 2.0, 3.0).is_err());
    assert!(step_for_scallop(10.0, 10.0, 0.001).is_err());
}

/// The seed's rounding centre is r_k from the section's ellipse, and the
/// ellipse's nearest point to it is the contact A (so the normal is the
/// ellipse's); R(0) = Hp, R(90 deg) = B/2.
#[test]
fn the_rounding_centre_is_r_k_along_the_ellipses_normal() {
    let g = reduction_groove();
    let r_k = 10.0;
    for theta_deg in [0.0, 37.0, 90.0, 140.0] {
        let theta = f64::to_radians(theta_deg);
        let s = g.section(theta).unwrap().ellipse;
        assert!((s.radius(0.0) - g.depth().eval(theta).unwrap()).abs() < 1e-12);
        assert!((s.radius(FRAC_PI_2) - g.width().eval(theta).unwrap() / 2.0).abs() < 1e-12);
        for psi_deg in [-60.0, -20.0, 0.0, 15.0, 45.0, 70.0] {
            let psi = f64::to_radians(psi_deg);
            let p = seed_pose(&g, theta, psi, 150.0, r_k).unwrap();
            // A on the ellipse.
            let on = (p.x_a / s.a).powi(2) + (p.z_a / s.b).powi(2);
            assert!((on - 1.0).abs() < 1e-12);
            // The nearest point of the ellipse to the centre: a fine search
            // over its parameter, then golden sections.
            let d2 = |t: f64| (s.a * t.sin() - p.x_k).powi(2) + (s.b * t.cos() - p.z_k).powi(2);
            let mut best = 0.0;
            for i in 0..=20_000 {
                let t = -FRAC_PI_2 + std::f64::consts::PI * i as f64 / 20_000.0;
                if d2(t) < d2(best) {
                    best = t;
                }
            }
            let (mut lo, mut hi) = (best - 2e-4, best + 2e-4);
            for _ in 0..80 {
                let (m1, m2) = (lo + 0.382 * (hi - lo), lo + 0.618 * (hi - lo));
                if d2(m1) < d2(m2) {
                    hi = m2;
                } else {
                    lo = m1;
                }
            }
            let t = 0.5 * (lo + hi);
            assert!(
                (d2(t).sqrt() - r_k).abs() < 1e-9,
                "{theta_deg} {psi_deg}: {}",
                d2(t).sqrt()
            );
            let (nx, nz) = (s.a * t.sin(), s.b * t.cos());
            assert!(
                (nx - p.x_a).hypot(nz - p.z_a) < 1e-6,
                "{theta_deg} {psi_deg}"
            );
        }
    }
}

/// Where the groove neither lifts nor widens (the sizing section), the
/// pressure angle and the swivel are 0, the roll angle needs no
/// correction, and R_e = R_m + R_k; in the reduction zone the groove lifts:
/// mu > 0 as theta grows (the depth falls, the contact's radius grows).
#[test]
fn the_seeds_corrections_vanish_on_the_sizing_section() {
    let g = reduction_groove();
    let p = seed_pose(&g, f64::to_radians(140.0), 0.3, 150.0, 10.0).unwrap();
    assert!(
        p.mu.abs() < 1e-9 && p.epsilon.abs() < 1e-9 && p.dtheta.abs() < 1e-9,
        "{p:?}"
    );
    assert!((p.r_e - (p.r_m + p.r_k)).abs() < 1e-9);
    let q = seed_pose(&g, f64::to_radians(40.0), 0.0, 150.0, 10.0).unwrap();
    assert!(q.mu > 0.0 && q.dtheta > 0.0, "{q:?}");
    // At psi = 0 the contact stays on the groove's middle: no swivel.
    assert!(q.epsilon.abs() < 1e-9);
    let f = seed_pose(&g, f64::to_radians(40.0), 0.8, 150.0, 10.0).unwrap();
    assert!(f.epsilon < 0.0, "the flank narrows as theta grows: {f:?}");
}

/// The groove's 3-D normal: on a section that neither lifts nor widens it
/// is the section's ellipse normal turned to theta, pointing out of the
/// material (toward the groove's centre).
#[test]
fn the_grooves_normal_is_the_sections_where_it_does_not_change() {
    let g = reduction_groove();
    let theta = f64::to_radians(140.0);
    for psi in [-1.2, -0.4, 0.0, 0.5, 1.3] {
        let psi_1 = g.section(theta).unwrap().normal_angle(psi);
        let expected = Vec3::new(
            psi_1.cos() * theta.cos(),
            psi_1.cos() * theta.sin(),
            -psi_1.sin(),
        );
        let n = g.normal(theta, psi).unwrap();
        assert!(
            (n - expected).norm() < 1e-7,
            "psi {psi}: {n:?} vs {expected:?}"
        );
    }
}

/// The exact pose touches the groove without penetrating it: the wheel's
/// axis across the contact's trajectory, its surface through the contact
/// (distance 0 within 1 nm), every groove point of a patch round it at
/// distance >= -0.1 um. A rounding larger than the groove's curvature
/// radius, placed the same way, cuts in: the check can fail.
#[test]
fn the_exact_pose_touches_without_penetrating() {
    let g = reduction_groove();
    let (r_k0, r_k) = (150.0, 10.0);
    let (r_min, _) = g.min_curvature_radius().unwrap();
    assert!(r_k < r_min, "{r_min}");
    let worst_at = |theta_deg: f64, psi: f64, r_k: f64| {
        let theta = f64::to_radians(theta_deg);
        let p = g.point(theta, psi).unwrap();
        let n = g.normal(theta, psi).unwrap();
        let h = 1e-6;
        let t = (g.point(theta + h, psi).unwrap() - g.point(theta - h, psi).unwrap()).normalize();
        let wheel = exact_pose(p, n, t.cross(&n), r_k0, r_k).unwrap();
        assert!(wheel.distance(&p).abs() < 1e-9, "{}", wheel.distance(&p));
        let mut worst = f64::INFINITY;
        for i in -40..=40 {
            for j in -40..=40 {
                let th = theta + f64::to_radians(0.05 * i as f64);
                let ps = (psi + 0.02 * j as f64).clamp(-1.5, 1.5);
                let q = g.point(th, ps).unwrap();
                worst = worst.min(wheel.distance(&q));
            }
        }
        worst
    };
    for (theta_deg, psi) in [(30.0, 0.0), (60.0, 0.6), (100.0, -0.9), (140.0, 0.3)] {
        let worst = worst_at(theta_deg, psi, r_k);
        assert!(worst >= -1e-7, "theta {theta_deg}, psi {psi}: {worst}");
    }
    // At the sizing section's bottom the curvature radius is b^2/a = 13.4 mm
    // across: a 20 mm rounding cuts the flanks beside the contact.
    assert!(worst_at(140.0, 0.0, 20.0) < -1e-3);
}

/// Bad tables are refused naming table, row and angle.
#[test]
fn bad_groove_tables_are_named() {
    let t = [0.0, 10.0, 20.0];
    let e = Groove::new(150.0, (&t, &[0.0, 10.0, 25.0]), &[20.0; 3], &[40.0; 3]).unwrap_err();
    assert!(
        matches!(e, GrooveError::DifferentTheta { row: 3, .. }),
        "{e}"
    );
    let e = Groove::new(150.0, (&t, &t), &[20.0, -1.0, 20.0], &[40.0; 3]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "groove table Hp, row 2 (theta = 10 deg): Hp = -1 mm must be a positive number"
    );
    let e = Groove::new(150.0, (&t, &t), &[20.0; 3], &[40.0, 40.0, 0.0]).unwrap_err();
    assert!(e.to_string().contains("groove table B, row 3"), "{e}");
    let e = Groove::new(15.0, (&t, &t), &[20.0; 3], &[40.0; 3]).unwrap_err();
    assert!(
        e.to_string()
            .contains("less than the roll's radius R_d = 15 mm"),
        "{e}"
    );
    let back = [0.0, 20.0, 10.0];
    let e = Groove::new(150.0, (&back, &back), &[20.0; 3], &[40.0; 3]).unwrap_err();
    assert!(e.to_string().contains("groove table Hp"), "{e}");
    let e = Groove::new(150.0, (&t, &t[..2]), &[20.0; 3], &[40.0; 2]).unwrap_err();
    assert!(matches!(e, GrooveError::DifferentRows { .. }), "{e}");
}

/// How many times the second differences change sign.
fn sign_changes(d2: &[f64]) -> usize {
    d2.windows(2).filter(|w| w[0] * w[1] < 0.0).count()
}

/// Smoothing a groove table (MATH §3.2): an already smooth table moves by
/// less than the rule's bound, `m h^2 / 4 (L max|f'''| + m max|f''|)` for m
/// iterations, steps h and distance L from the anchor; a dent planted in a
/// convex table makes its second differences change sign, and five
/// iterations remove every sign change.
#[test]
fn smoothing_keeps_smooth_tables_and_removes_a_planted_dent() {
    let theta: Vec<f64> = (0..=80).map(|i| 2.0 * i as f64).collect();
    let smooth: Vec<f64> = theta
        .iter()
        .map(|t| 20.0 + 3.0 * (t / 30.0).sin())
        .collect();
    let p = pilgrim_kernel::Profile::new(theta.clone(), smooth.clone()).unwrap();
    let s = p.smooth_derivative(5, 40).unwrap();
    let (m, h, l) = (5.0, 2.0, 80.0);
    let bound = m * h * h / 4.0 * (l * 3.0 / 30f64.powi(3) + m * 3.0 / 30f64.powi(2));
    assert!(s.max_change <= bound, "{} > {bound}", s.max_change);
    assert_eq!(s.profile.x()[40], smooth[40], "the anchor stays");
    // A dent of 10 um at 60 deg in a convex table.
    let mut dented: Vec<f64> = theta.iter().map(|t| 14.1 + 0.001 * t * t / 4.0).collect();
    dented[30] -= 0.01;
    let p = pilgrim_kernel::Profile::new(theta, dented).unwrap();
    let s = p.smooth_derivative(5, 40).unwrap();
    assert!(sign_changes(&s.d2_before) >= 2, "{:?}", s.d2_before);
    assert_eq!(sign_changes(&s.d2_after), 0, "{:?}", s.d2_after);
    assert!(
        s.max_change > 0.0 && (s.max_change_z - 60.0).abs() <= 10.0,
        "{s:?}"
    );
}

/// The example groove (`scripts/caliber-groove.csv`, with a notes
/// column) reads into a groove: its depth falls from the hollow's radius
/// through the reduction zone to the tube's, constant over the sizing
/// section, and its sections are rounder than a 10 mm wheel rounding.
#[test]
fn the_example_groove_reads_from_its_table() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/caliber-groove.csv");
    let t = pilgrim_kernel::read_table(&path).unwrap();
    let g =
        Groove::from_tables(150.0, (&t, "theta_deg", "Hp_mm"), (&t, "theta_deg", "B_mm")).unwrap();
    let hp = |deg: f64| g.depth().eval(deg.to_radians()).unwrap();
    assert!((hp(20.0) - 24.0).abs() < 1e-9 && (hp(200.0) - 14.1).abs() < 1e-9);
    assert!((hp(225.0) - 14.1).abs() < 1e-9, "the sizing section");
    assert!(hp(100.0) < hp(60.0) && hp(60.0) < hp(30.0));
    let (r_min, at) = g.min_curvature_radius().unwrap();
    assert!(
        r_min > 10.0 && r_min < 14.1,
        "{r_min} at {} deg",
        at.to_degrees()
    );
}

/// Bad table files are refused naming the file, the row as the file
/// numbers it, and the column.
#[test]
fn bad_table_files_are_named() {
    let read = |text: &str| pilgrim_kernel::read_table_str(text, "g.csv").unwrap();
    let build = |t: &pilgrim_kernel::Table| {
        Groove::from_tables(150.0, (t, "theta", "Hp"), (t, "theta", "B"))
            .unwrap_err()
            .to_string()
    };
    let e = build(&read("theta,Hp,B\n0,20,40\n10,-1,40\n20,20,40\n"));
    assert_eq!(
        e,
        "g.csv: row 3, column B (Hp): Hp = -1 mm at theta = 10 deg must be a positive number"
    );
    let e = build(&read("theta,Hp,B\n0,20,40\n20,20,40\n10,20,40\n"));
    assert!(
        e.contains("g.csv") && e.contains("row 4") && e.contains("theta"),
        "{e}"
    );
    let e = build(&read("theta,Hp,B\n0,20,40\n10,,40\n20,20,40\n"));
    assert!(
        e.contains("g.csv") && e.contains("row 3") && e.contains("Hp"),
        "{e}"
    );
    let e = build(&read("theta,Hp,B\n0,20,40\n10,deep,40\n20,20,40\n"));
    assert!(
        e.contains("g.csv") && e.contains("row 3") && e.contains("deep"),
        "{e}"
    );
    let (h, b) = (
        pilgrim_kernel::read_table_str("theta,Hp\n0,20\n10,20\n20,20\n", "hp.csv").unwrap(),
        pilgrim_kernel::read_table_str("theta,B\n0,40\n15,40\n20,40\n", "b.csv").unwrap(),
    );
    let e = Groove::from_tables(150.0, (&h, "theta", "Hp"), (&b, "theta", "B"))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "hp.csv: row 3: theta = 10 deg, but b.csv row 3 gives B at theta = 15 deg: the tables of Hp and B must be at the same angles"
    );
}

/// Passes across the groove: evenly spread, no more than dpsi apart, the
/// scallop of that step in the widest section (the inverse gives the step
/// back); a rounding as round as the groove's tightest section is refused
/// naming where that is.
#[test]
fn passes_are_spread_across_the_groove() {
    let g = reduction_groove();
    let (psi, rz) = g.pass_angles(10.0, 1f64.to_radians(), 1.4).unwrap();
    assert!((psi[0] + 1.4).abs() < 1e-12 && (psi[psi.len() - 1] - 1.4).abs() < 1e-12);
    let step = psi[1] - psi[0];
    assert!(step <= 1f64.to_radians() + 1e-12);
    assert!(psi.windows(2).all(|w| (w[1] - w[0] - step).abs() < 1e-12));
    // The widest section: B/2 = 2.1 x 24 / 2 = 25.2 mm.
    let back = step_for_scallop(25.2, 10.0, rz).unwrap();
    assert!((back - step).abs() < 1e-7);
    let e = g.pass_angles(14.0, 0.02, 1.4).unwrap_err().to_string();
    // b^2/a = 14.1 / 1.05 on the sizing section, at the edge (the
    // interpolation between rows dips 0.2 um below it beside 120 deg).
    assert!(
        e.contains("tightest curvature radius 13.428") && e.contains("deg, psi = 90 deg"),
        "{e}"
    );
}

/// On the edges' rounding the passes run closer: between any two
/// neighbouring passes on it, in every row's section, the cusp their
/// rounding circles leave on the convex arc (the circles intersected here)
/// is no higher than the scallop the step leaves in the widest section.
#[test]
fn passes_run_closer_on_the_edges_rounding() {
    let g = reduction_groove()
        .with_edge(
            pilgrim_kernel::families::caliber::EdgeKind::Rounding,
            &[2.0; 81],
        )
        .unwrap();
    let r_k = 10.0;
    let (psi, rz) = g.pass_angles(r_k, 1f64.to_radians(), FRAC_PI_2).unwrap();
    assert!((psi[0] + FRAC_PI_2).abs() < 1e-12 && (psi[psi.len() - 1] - FRAC_PI_2).abs() < 1e-12);
    assert!(psi.windows(2).all(|w| w[1] > w[0]));
    let main = psi[psi.len() / 2 + 1] - psi[psi.len() / 2];
    let edge = psi[psi.len() - 1] - psi[psi.len() - 2];
    assert!(edge < 0.5 * main, "{edge} vs {main}");
    let mut on = 0;
    for &theta in g.depth().z() {
        let s = g.section(theta).unwrap();
        let from = s.edge_from();
        for w in psi.windows(2).filter(|w| w[0] >= from) {
            let dphi = (s.normal_angle(w[0]) - s.normal_angle(w[1])).abs();
            // Rounding circles r_k from the arc, 2 + r_k from its centre,
            // dphi apart: the cusp where they cross nearer that centre.
            let d = 2.0 + r_k;
            let half = d * (dphi / 2.0).sin();
            let cusp = d * (dphi / 2.0).cos() - (r_k * r_k - half * half).sqrt();
            assert!(
                cusp - 2.0 <= rz * (1.0 + 1e-9),
                "{} um at theta {theta}",
                1e3 * (cusp - 2.0)
            );
            on += 1;
        }
    }
    assert!(on > 81 * 5, "{on} steps on the rounding");
}

/// At a chamfer's corners the point stands while psi turns the normal:
/// the groove's normal there is unit and turns with it, between the two
/// faces', round the corner from the ellipse's to the line's and on to the
/// periphery's.
#[test]
fn the_normal_turns_round_a_chamfers_corners() {
    use pilgrim_kernel::families::caliber::EdgeKind;
    let g = reduction_groove()
        .with_edge(EdgeKind::Chamfer, &[1.5; 81])
        .unwrap();
    let theta = 50f64.to_radians();
    let s = g.section(theta).unwrap();
    let from = s.edge_from();
    let radial = Vec3::new(theta.cos(), theta.sin(), 0.0);
    let mut last = f64::INFINITY;
    for k in 0..=400 {
        let psi = from + (FRAC_PI_2 - from) * k as f64 / 400.0;
        let n = g.normal(theta, psi).unwrap();
        assert!((n.norm() - 1.0).abs() < 1e-12, "{psi}: {n}");
        // Its angle in the section from the outward radius, toward the
        // groove's middle (-Z on this side).
        let angle = (-n.z).atan2(n.dot(&radial));
        assert!(angle <= last + 1e-6, "the normal turns back at psi {psi}");
        last = angle;
        let phi = s.normal_angle(psi);
        assert!(
            (angle - phi).abs() < 0.01,
            "{} vs {}",
            angle.to_degrees(),
            phi.to_degrees()
        );
    }
    assert!(last.abs() < 1e-6, "{last}");
}

/// An edge's rounding that cannot be: refused naming the row and the angle.
#[test]
fn a_bad_edge_rounding_is_named() {
    let g = reduction_groove();
    let mut radii = vec![2.0; 81];
    radii[7] = -0.5;
    let e = g
        .clone()
        .with_edge(
            pilgrim_kernel::families::caliber::EdgeKind::Rounding,
            &radii,
        )
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("row 8") && e.contains("theta = 14 deg") && e.contains("positive"),
        "{e}"
    );
    let e = g
        .with_edge(
            pilgrim_kernel::families::caliber::EdgeKind::Rounding,
            &[2.0; 80],
        )
        .unwrap_err()
        .to_string();
    // The sizes are the edge's, not B's.
    assert!(
        e.contains("81") && e.contains("80") && e.contains("r_edge") && !e.contains(" in B"),
        "{e}"
    );
}

/// The caliber's solid: the example groove's roll sector is a closed mesh
/// whose volume is the section's first moment about the axis integrated
/// over theta (Pappus, section by section) within 0.1 %, refused when the
/// rim is narrower than the groove; left in target/mesh-check for FreeCAD.
#[test]
fn the_caliber_solid_is_closed_and_holds_its_volume() {
    use pilgrim_kernel::families::caliber::caliber_solid;
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/caliber-groove.csv");
    let t = pilgrim_kernel::read_table(&path).unwrap();
    let g =
        Groove::from_tables(150.0, (&t, "theta_deg", "Hp_mm"), (&t, "theta_deg", "B_mm")).unwrap();
    let (width, hub) = (80.0, 60.0);
    let m = caliber_solid(&g, width, hub, 0.01).unwrap();
    m.check_closed().unwrap();
    // V = int dtheta int rho dA over the section.
    let (t0, t1) = g.theta_range();
    let (n_t, n_x) = (2000, 4000);
    let mut v = 0.0;
    for i in 0..n_t {
        let theta = t0 + (t1 - t0) * (i as f64 + 0.5) / n_t as f64;
        let s = g.section(theta).unwrap();
        let mut moment = width * (150.0f64.powi(2) - hub * hub) / 2.0;
        for j in 0..n_x {
            let (a, b) = (s.ellipse.a, s.ellipse.b);
            let x = -a + 2.0 * a * (j as f64 + 0.5) / n_x as f64;
            let z = b * (1.0 - (x / a).powi(2)).max(0.0).sqrt();
            moment -= (150.0f64.powi(2) - (150.0 - z).powi(2)) / 2.0 * (2.0 * a / n_x as f64);
        }
        v += moment * (t1 - t0) / n_t as f64;
    }
    assert!((m.volume() - v).abs() < 1e-3 * v, "{} vs {v}", m.volume());
    assert!(caliber_solid(&g, 50.0, hub, 0.01).is_err());
    assert!(caliber_solid(&g, width, 130.0, 0.01).is_err());
    let exe = std::env::current_exe().unwrap();
    let dir = exe.ancestors().nth(3).unwrap().join("mesh-check");
    std::fs::create_dir_all(&dir).unwrap();
    let mut f = std::fs::File::create(dir.join("caliber.stl")).unwrap();
    pilgrim_kernel::mesh::write_stl(
        &m,
        "caliber",
        pilgrim_kernel::mesh::StlFormat::Binary,
        &mut f,
    )
    .unwrap();
}

/// The caliber's geometry from a script: the example table read, the
/// groove, the pass angles and the seed's pose give what the kernel does.
#[test]
fn scripts_reach_the_caliber_geometry() {
    use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts");
    let src = "fn params() { #{} }\n\
         fn toolpath(p) { () }\n\
         fn probe(p) {\n\
           let g = groove(150.0, read_table(\"caliber-groove.csv\"), \"theta_deg\", \"Hp_mm\", \"B_mm\");\n\
           let passes = g.pass_angles(10.0, 0.02, 1.4);\n\
           let s = g.seed_pose(0.5, 0.3, 150.0, 10.0);\n\
           [g.min_curvature_radius, passes.psi.len, passes.scallop, s.x_k, s.mu, g.point(0.5, 0.3)[2]]\n\
         }";
    let access = Access {
        input_dirs: vec![examples.clone()],
        ..Access::default()
    };
    let fam = ScriptFamily::from_source(src, "probe.rhai", &Limits::default(), &access).unwrap();
    let values = pilgrim_kernel::params::resolve(
        pilgrim_kernel::PartFamily::params(&fam),
        &Default::default(),
        &[],
    )
    .unwrap();
    let got: Vec<f64> = fam
        .call_with_params("probe", &values)
        .unwrap()
        .into_array()
        .unwrap()
        .into_iter()
        .map(|d| d.as_float().unwrap_or_else(|_| d.as_int().unwrap() as f64))
        .collect();
    let t = pilgrim_kernel::read_table(examples.join("caliber-groove.csv")).unwrap();
    let g =
        Groove::from_tables(150.0, (&t, "theta_deg", "Hp_mm"), (&t, "theta_deg", "B_mm")).unwrap();
    let (psi, rz) = g.pass_angles(10.0, 0.02, 1.4).unwrap();
    let s = seed_pose(&g, 0.5, 0.3, 150.0, 10.0).unwrap();
    let want = [
        g.min_curvature_radius().unwrap().0,
        psi.len() as f64,
        rz,
        s.x_k,
        s.mu,
        g.point(0.5, 0.3).unwrap().z,
    ];
    assert_eq!(got, want);
}
