//! Verification by replay, and the adaptive spacing it justifies.

use pilgrim_kernel::offset::{swept_circles, CapsuleEnvelope};
use pilgrim_kernel::profile::simplify_polyline;
use pilgrim_kernel::{equidistant, MandrelLaw, Profile, ProfileBuilder, Side};

const R_S: f64 = 20.0;

/// A grindable mandrel: a cone leading tangentially into the working part
/// and one leaving it tangentially (no corner a wheel cannot reach).
fn mandrel() -> (MandrelLaw, Profile) {
    let law = MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap();
    let p = ProfileBuilder::start(-150.0, law.x(0.0) - 150.0 * law.dx(0.0))
        .line_to(0.0, law.x(0.0))
        .law(law)
        .line_to(500.0, law.x(400.0) + 100.0 * law.dx(400.0))
        .build(1e-5, 0.02)
        .unwrap();
    (law, p)
}

/// The surface the wheel's rounding leaves swept continuously along the
/// centres `(z, x)`: its circles placed closely enough that their scallops
/// stay under 1e-5 mm.
fn sweep(z: &[f64], x: &[f64]) -> CapsuleEnvelope {
    let (cz, cx, _) = swept_circles(z, x, R_S, 1e-5).unwrap();
    CapsuleEnvelope::new(&cz, &cx, R_S, 0.0, Side::Outside).unwrap()
}

/// The sweep of the wheel's rounding along the centres `(z, x)` against
/// the profile `p` over [0, 400] every 0.01 mm: the largest |deviation|, the
/// deepest (signed) and where it is.
fn sweep_deviation(z: &[f64], x: &[f64], p: &Profile) -> (f64, f64, f64) {
    let zs: Vec<f64> = (0..=40_000).map(|i| i as f64 * 0.01).collect();
    let (s, n) = (sweep(z, x).eval_many(&zs), p.eval_many(&zs).unwrap());
    let (mut worst, mut below, mut at) = (0.0f64, f64::INFINITY, 0.0);
    for ((z, s), n) in zs.iter().zip(s).zip(n) {
        worst = worst.max((s - n).abs());
        if s - n < below {
            (below, at) = (s - n, *z);
        }
    }
    (worst, below, at)
}

/// The chordal selection keeps the tolerance, never needs more blocks than
/// the uniform step that keeps it on the most curved place, and spends no
/// block inside a straight run (its saving grows with the part's straight
/// length and the unevenness of its curvature).
#[test]
fn adaptive_blocks_keep_the_tolerance_and_skip_straight_runs() {
    let (law, p) = mandrel();
    let e = equidistant(&p, R_S, Side::Outside).unwrap();
    let tol = 1e-3;
    let keep = simplify_polyline(&e.z, &e.x, tol / 2.0);
    let (z, x): (Vec<f64>, Vec<f64>) = keep.iter().map(|&i| (e.z[i], e.x[i])).unzip();
    let (worst, _, _) = sweep_deviation(&z, &x, &p);
    assert!(worst <= tol, "adaptive: {worst}");
    // The uniform step that keeps the same chordal tolerance on the most
    // curved place of the equidistant: s = sqrt(8 tol/2 / kappa_max).
    let kappa = p
        .curvature()
        .iter()
        .filter(|k| k.is_finite())
        .fold(0.0f64, |m, k| m.max(k.abs()));
    let kappa_eq = kappa / (1.0 - R_S * kappa);
    let s = (8.0 * tol / 2.0 / kappa_eq).sqrt();
    let uniform = (650.0 / s).ceil() as usize;
    assert!(
        uniform >= keep.len(),
        "adaptive {} blocks, uniform {uniform}",
        keep.len()
    );
    // The leading cone (z < 0) and the trailing one (z > 400): straight,
    // so only the ends of each equidistant line are kept.
    let inside = |a: f64, b: f64| keep.iter().filter(|&&i| e.z[i] > a && e.z[i] < b).count();
    assert_eq!(inside(-150.0 + 1e-6, -R_S * 0.006 - 1e-3), 0);
    assert_eq!(inside(400.0 + 1.0, 500.0 - R_S * 0.04), 0);
    // The law itself is met on the working part.
    assert!((sweep(&z, &x).eval(200.0) - law.x(200.0)).abs() <= tol);
}

/// A centre 10 um too deep leaves a gouge under it (the replay through a
/// program names the block: `tests/mandrel.rs`).
#[test]
fn a_corrupted_block_gouges_under_it() {
    let (_, p) = mandrel();
    let e = equidistant(&p, R_S, Side::Outside).unwrap();
    let keep = simplify_polyline(&e.z, &e.x, 0.5e-3);
    let (z, mut x): (Vec<f64>, Vec<f64>) = keep.iter().map(|&i| (e.z[i], e.x[i])).unzip();
    let k = z.iter().position(|&v| v > 200.0).unwrap();
    x[k] -= 0.01; // the wheel goes 10 um too deep at block k
    let (_, below, at) = sweep_deviation(&z, &x, &p);
    assert!(below < -0.009, "{below}");
    // The deepest point is under the corrupted centre.
    assert!((at - z[k]).abs() < 1.0, "{at} vs {}", z[k]);
}
