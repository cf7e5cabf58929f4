//! Equidistants, envelopes and the steady rest, checked by geometry.
use pilgrim_kernel::families::revolution::rest;

use pilgrim_kernel::{
    assert_near, equidistant, Bulge, CircleEnvelope, MandrelLaw, Profile, ProfileBuilder,
    ProfileError, Side,
};

/// A realistic mandrel working part (d 38 -> 52 mm over 400 mm).
fn law() -> MandrelLaw {
    MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap()
}

#[test]
fn mandrel_law_meets_its_end_conditions() {
    let l = law();
    assert_near!(l.x(0.0), 38.0 / 2.0, 1e-12);
    assert_near!(l.x(400.0), 52.0 / 2.0, 1e-12);
    assert_near!(l.dx(0.0), 0.012 / 2.0, 1e-15);
    // The sampled array says the same, by divided differences.
    let p = l.profile(0.01, 0.0).unwrap().without_derivatives();
    let (z, x) = (p.z(), p.x());
    assert_eq!(x[0], 19.0);
    assert_near!(x[x.len() - 1], 26.0, 1e-12);
    assert_near!(p.slopes()[0], 0.006, 1e-6);
    assert_near!(z[z.len() - 1], 400.0, 0.0);
}

/// The upper half of a circle of radius r about the origin, as x(z).
fn circle(r: f64, h: f64, analytic: bool) -> Profile {
    let n = (1.6 * r / h).round() as usize;
    let z: Vec<f64> = (0..=n)
        .map(|i| -0.8 * r + 1.6 * r * i as f64 / n as f64)
        .collect();
    let x: Vec<f64> = z.iter().map(|z| (r * r - z * z).sqrt()).collect();
    if analytic {
        let d1 = z.iter().zip(&x).map(|(z, x)| -z / x).collect();
        let d2 = x.iter().map(|x| -r * r / (x * x * x)).collect();
        Profile::with_derivatives(z, x, d1, d2).unwrap()
    } else {
        Profile::new(z, x).unwrap()
    }
}

#[test]
fn equidistant_of_a_circle_is_the_concentric_circle() {
    let (r, big_r) = (30.0, 12.5);
    // Analytic derivatives: exact to rounding.
    let e = equidistant(&circle(r, 0.05, true), big_r, Side::Outside).unwrap();
    for (z, x) in e.z.iter().zip(&e.x) {
        assert_near!(z.hypot(*x), r + big_r, 1e-9);
    }
    // Divided differences: within the documented bound R h^2 max|x'''| / 3,
    // x''' = -3 r^2 z / (r^2 - z^2)^(5/2), largest at the ends |z| = 0.8 r.
    for h in [0.5, 0.1, 0.02] {
        let p = circle(r, h, false);
        let step = p.z()[1] - p.z()[0];
        let zmax: f64 = 0.8 * r;
        let m3 = 3.0 * r * r * zmax / (r * r - zmax * zmax).powf(2.5);
        let bound = big_r * step * step * m3 / 3.0;
        let e = equidistant(&p, big_r, Side::Outside).unwrap();
        let worst =
            e.z.iter()
                .zip(&e.x)
                .map(|(z, x)| (z.hypot(*x) - r - big_r).abs())
                .fold(0.0, f64::max);
        assert!(
            worst <= bound,
            "h = {h}: deviation {worst:e} > bound {bound:e}"
        );
        assert!(worst > 0.0);
    }
    // Inside: the circle r - R.
    let e = equidistant(&circle(r, 0.05, true), big_r, Side::Inside).unwrap();
    for (z, x) in e.z.iter().zip(&e.x) {
        assert_near!(z.hypot(*x), r - big_r, 1e-9);
    }
}

/// The wheel's rounding circles centred on the equidistant of the mandrel
/// profile, sampled at step s, leave the profile back within the scallop
/// s^2 / (8 R) + 1e-5 mm at s = 0.1 mm, R = 20 mm, and never cut below it.
/// s^2/(8R) is the first-order cusp; the coarser cases are held to the exact
/// cusp R - sqrt(R^2 - d^2/4) of circles d = s sqrt(1 + x'^2) apart along the
/// surface, raised by rho / (rho - R) where the part is concave seen from
/// the wheel.
#[test]
fn envelope_of_the_wheel_reproduces_the_mandrel_profile() {
    let l = law();
    let slope2 = (0..=4000)
        .map(|i| l.dx(i as f64 * 0.1).powi(2))
        .fold(0.0, f64::max);
    let rho_min = (0..=4000)
        .map(|i| 1.0 / l.d2x(i as f64 * 0.1).abs().max(1e-300))
        .fold(f64::MAX, f64::min);
    for (s, big_r) in [(0.1, 20.0), (0.5, 20.0), (1.0, 5.0), (0.05, 40.0)] {
        let p = l.profile(s, 0.0).unwrap();
        let e = equidistant(&p, big_r, Side::Outside).unwrap();
        let env = CircleEnvelope::new(&e.z, &e.x, big_r, Side::Outside).unwrap();
        let fine: Vec<f64> = (0..=400_000).map(|i| i as f64 * 0.001).collect();
        let dev: Vec<f64> = env
            .eval_many(&fine)
            .iter()
            .zip(&fine)
            .map(|(v, z)| v - l.x(*z))
            .collect();
        let first_order = s * s / (8.0 * big_r);
        let bound = if (s, big_r) == (0.1, 20.0) {
            first_order + 1e-5
        } else {
            // The exact cusp of two circles d apart on a line, d the step along
            // the surface, raised by the concavity seen from the wheel.
            let d2 = s * s * (1.0 + slope2);
            (big_r - (big_r * big_r - d2 / 4.0).sqrt()) * rho_min / (rho_min - big_r) + 1e-5
        };
        let (lo, hi) = dev
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), d| (a.min(*d), b.max(*d)));
        assert!(
            hi <= bound,
            "s = {s}, R = {big_r}: scallop {hi:e} > {bound:e}"
        );
        assert!(lo >= -1e-9, "s = {s}, R = {big_r}: gouge {lo:e}");
        // The scallop is there (the check could fail): at least a third of the
        // ideal cusp s^2/(8R) appears between nodes.
        assert!(
            hi >= s * s / (8.0 * big_r) / 3.0,
            "s = {s}: scallop {hi:e} suspiciously small"
        );
    }
    // At s = 0.1 mm, R = 20 mm the bound is 6.25e-5 + 1e-5 mm: under 0.1 um.
}

/// At a convex corner the centres swing round the corner point on an arc of
/// the tool's radius, and the circles at them leave the corner itself: the
/// envelope meets the profile there and on both sides (outside and inside).
#[test]
fn convex_corners_get_an_arc_of_centres() {
    let big_r = 20.0;
    let peak = ProfileBuilder::start(0.0, 20.0)
        .line_to(30.0, 20.3)
        .line_to(40.0, 19.0)
        .build(1e-4, 0.5)
        .unwrap();
    let valley = ProfileBuilder::start(0.0, 20.0)
        .line_to(30.0, 19.7)
        .line_to(40.0, 21.0)
        .build(1e-4, 0.5)
        .unwrap();
    for (p, side, corner_x) in [(&peak, Side::Outside, 20.3), (&valley, Side::Inside, 19.7)] {
        let e = equidistant(p, big_r, side).unwrap();
        let round: Vec<usize> = (0..e.z.len())
            .filter(|&i| ((e.z[i] - 30.0).hypot(e.x[i] - corner_x) - big_r).abs() < 1e-9)
            .collect();
        // From the normal of one line to the other's: the turn is
        // atan(0.01) + atan(0.13), at steps whose sag is at most 1 nm.
        let turn = 0.01_f64.atan() + 0.13_f64.atan();
        let step = 2.0 * (2.0 * pilgrim_kernel::offset::CORNER_SAG / big_r).sqrt();
        assert_eq!(round.len(), (turn / step).ceil() as usize + 1, "{side:?}");
        assert!(
            e.z.windows(2).all(|w| w[1] > w[0]),
            "{side:?}: centres go back"
        );
        let env = CircleEnvelope::new(&e.z, &e.x, big_r, side).unwrap();
        // Exact at the nodes (the corner is one), and between them off by no
        // more than the scallop of centres 0.5 mm apart, never into the part.
        for (z, g) in p.z().iter().zip(env.eval_many(p.z())) {
            let w = p.eval(*z).unwrap();
            assert_near!(g, w, 1e-9, "{side:?} at node z = {z}");
        }
        let at: Vec<f64> = (0..=400).map(|i| i as f64 * 0.1).collect();
        let scallop = 0.5 * 0.5 / (8.0 * big_r);
        for ((z, g), w) in at
            .iter()
            .zip(env.eval_many(&at))
            .zip(p.eval_many(&at).unwrap())
        {
            let off = (g - w) * side.sign();
            assert!(
                (-1e-9..=scallop + 1e-9).contains(&off),
                "{side:?} at z = {z}: {off:e}"
            );
        }
    }
    // Without the arc (one centre at the corner's mean normal), the envelope
    // cuts into the corner: what the arc is for.
    let e = equidistant(&peak, big_r, Side::Outside).unwrap();
    let on_arc = |i: usize| ((e.z[i] - 30.0).hypot(e.x[i] - 20.3) - big_r).abs() < 1e-9;
    let arc: Vec<usize> = (0..e.z.len()).filter(|&i| on_arc(i)).collect();
    let mid = arc[arc.len() / 2];
    let (cz, cx): (Vec<f64>, Vec<f64>) = (0..e.z.len())
        .filter(|&i| i == mid || !on_arc(i))
        .map(|i| (e.z[i], e.x[i]))
        .unzip();
    let (sz, sx, _) = pilgrim_kernel::offset::swept_circles(&cz, &cx, big_r, 0.01).unwrap();
    let env = CircleEnvelope::new(&sz, &sx, big_r, Side::Outside).unwrap();
    let at: Vec<f64> = (0..=200).map(|i| 29.0 + i as f64 * 0.01).collect();
    let gouge = env
        .eval_many(&at)
        .iter()
        .zip(peak.eval_many(&at).unwrap())
        .map(|(g, w)| g - w)
        .fold(f64::INFINITY, f64::min);
    // Chords over a quarter of the turn each: R (1 - cos(turn / 4)), 12 um.
    assert!(gouge < -0.01, "{gouge}");
}

/// A fillet tighter than the wheel is refused, naming every z.
#[test]
fn profile_tighter_than_the_wheel_is_refused_naming_z() {
    let p = ProfileBuilder::start(0.0, 30.0)
        .cylinder(20.0)
        .arc_to(26.0, 27.0, 8.0, Bulge::In)
        .arc_to(32.0, 24.0, 8.0, Bulge::Out)
        .cylinder(20.0)
        .build(1e-3, 0.5)
        .unwrap();
    let err = equidistant(&p, 10.0, Side::Outside).unwrap_err();
    let ProfileError::CurvatureBelowTool {
        violations,
        tool_radius,
    } = &err
    else {
        panic!("{err}")
    };
    assert_eq!(*tool_radius, 10.0);
    // Every node inside the concave fillet (20 < z < 26), and the two concave
    // corners where the segments meet with a jump of slope upward (z = 26,
    // from the fillet into the convex arc, and z = 32, from that arc onto the
    // cylinder); not the convex corner at z = 20.
    let zs: Vec<f64> = violations.iter().map(|v| v.z).collect();
    let expected: Vec<f64> = p
        .z()
        .iter()
        .copied()
        .filter(|z| (*z > 20.0 && *z <= 26.0) || *z == 32.0)
        .collect();
    assert_eq!(zs, expected);
    assert!(
        err.to_string().contains("z = 20.") || err.to_string().contains("z = 21."),
        "{err}"
    );
    // Without the corners (a smooth fillet alone), a wheel of 7.9 fits.
    let fillet = ProfileBuilder::start(20.0, 30.0)
        .arc_to(26.0, 27.0, 8.0, Bulge::In)
        .build(1e-3, 0.5)
        .unwrap();
    assert!(equidistant(&fillet, 7.9, Side::Outside).is_ok());
    assert!(equidistant(&fillet, 8.1, Side::Outside).is_err());
}

/// On a smooth profile the seed's first-order rest formula agrees with the
/// exact drop within K (R_o + h)(R_o + 2h) / 2, and does differ from it.
#[test]
fn seed_rest_formula_agrees_with_the_exact_drop_within_its_bound() {
    let l = MandrelLaw::new(38.0, 60.0, 400.0, 0.0, 3.0).unwrap();
    for h in [0.1, 0.5, 2.0] {
        let p = l.profile(h, 0.0).unwrap().without_derivatives();
        let r_o = 25.0;
        let mut largest: f64 = 0.0;
        let mut tightest = f64::MAX;
        for i in 0..=70 {
            let z_r = 30.0 + 5.0 * i as f64;
            // K and S over the support's reach.
            let reach: Vec<f64> = (0..=200)
                .map(|j| {
                    (z_r - r_o - 2.0 * h + (2.0 * r_o + 4.0 * h) * j as f64 / 200.0)
                        .clamp(0.0, 400.0)
                })
                .collect();
            let k = reach.iter().map(|&z| l.d2x(z).abs()).fold(0.0, f64::max);
            let slope = reach.iter().map(|&z| l.dx(z).abs()).fold(0.0, f64::max);
            let bound = rest::seed_error_bound(k, slope / (1.0 + slope * slope).sqrt(), h, r_o);
            let seed = rest::seed_u(&p, z_r, r_o).unwrap();
            let exact = rest::exact_u(&p, z_r, r_o).unwrap().centre_x;
            assert!(
                (seed - exact).abs() <= bound,
                "h {h}, z_r {z_r}: {seed} vs {exact}, bound {bound}"
            );
            largest = largest.max((seed - exact).abs());
            tightest = tightest.min(bound / (seed - exact).abs().max(1e-300));
        }
        assert!(largest > 0.0);
        // The bound is close to the truth somewhere (within a factor 5).
        assert!(
            tightest < 5.0,
            "h {h}: the bound is never within 5x of the difference ({tightest})"
        );
    }
}

#[test]
fn exact_rest_sits_on_the_surface() {
    // The drop touches: the contact point is on the profile and at R_o from the centre.
    let l = law();
    let p = l.profile(0.2, 0.0).unwrap();
    for z_r in [40.0, 200.0, 380.0] {
        let d = rest::exact_u(&p, z_r, 25.0).unwrap();
        assert_near!(
            (d.contact_z - z_r).hypot(d.contact_x - d.centre_x),
            25.0,
            1e-9
        );
        assert_near!(d.contact_x, p.eval(d.contact_z).unwrap(), 1e-4);
    }
    assert!(rest::seed_u(&p, 500.0, 25.0).is_err());
    assert!(rest::exact_u(&p, 200.0, 0.0).is_err());
}
