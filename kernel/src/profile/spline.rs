//! The natural cubic spline's node slopes, and how far an interpolation
//! swings beyond the stations it passes through.
//!
//! Both are written here: the spline is one tridiagonal solve (the Thomas
//! algorithm, stable for its diagonally dominant matrix) whose slopes feed
//! the profile's own cubic Hermite evaluation, so a spline crate's own
//! evaluator would be a second interpolation beside it; a cubic's
//! extremes are the roots of its derivative, a quadratic.

use crate::math::Real;

/// The node slopes of the natural cubic spline through `(z, x)` (z
/// strictly increasing, at least 3 nodes): the cubic Hermite with these
/// slopes has a continuous second derivative, zero at both ends.
pub(super) fn natural_slopes(z: &[Real], x: &[Real]) -> Vec<Real> {
    let n = z.len();
    let h: Vec<Real> = z.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<Real> = (0..n - 1).map(|i| (x[i + 1] - x[i]) / h[i]).collect();
    // Row i: lower[i] m[i-1] + diag[i] m[i] + upper[i] m[i+1] = rhs[i].
    let mut diag = vec![0.0; n];
    let mut upper = vec![0.0; n];
    let mut lower = vec![0.0; n];
    let mut rhs = vec![0.0; n];
    (diag[0], upper[0], rhs[0]) = (2.0, 1.0, 3.0 * d[0]);
    for i in 1..n - 1 {
        let (a, b) = (1.0 / h[i - 1], 1.0 / h[i]);
        (lower[i], diag[i], upper[i]) = (a, 2.0 * (a + b), b);
        rhs[i] = 3.0 * (d[i - 1] * a + d[i] * b);
    }
    (lower[n - 1], diag[n - 1], rhs[n - 1]) = (1.0, 2.0, 3.0 * d[n - 2]);
    for i in 1..n {
        let w = lower[i] / diag[i - 1];
        diag[i] -= w * upper[i - 1];
        rhs[i] -= w * rhs[i - 1];
    }
    let mut m = vec![0.0; n];
    m[n - 1] = rhs[n - 1] / diag[n - 1];
    for i in (0..n - 1).rev() {
        m[i] = (rhs[i] - upper[i] * m[i + 1]) / diag[i];
    }
    m
}

/// Where an interpolation goes furthest beyond the two stations of its
/// interval: the curve between stations `x[i]` and `x[i+1]` outside the
/// range of the two.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Swing {
    /// Where (z, mm).
    pub z: Real,
    /// The interpolated value there (mm).
    pub x: Real,
    /// How far beyond the nearer station's value (mm, positive).
    pub beyond: Real,
}

/// The largest swing of the cubic Hermite through `(z, x)` with node
/// `slopes` beyond its intervals' stations, the intervals `straight`
/// holds of left out, or `None` where it stays within them everywhere.
pub(super) fn largest_swing(
    z: &[Real],
    x: &[Real],
    slopes: &[Real],
    straight: &dyn Fn(usize) -> bool,
) -> Option<Swing> {
    let mut worst: Option<Swing> = None;
    for i in (0..z.len() - 1).filter(|&i| !straight(i)) {
        let h = z[i + 1] - z[i];
        // x(t) = x0 + a t + b t^2 + c t^3 on t in [0, 1].
        let (x0, dx) = (x[i], x[i + 1] - x[i]);
        let (m0, m1) = (h * slopes[i], h * slopes[i + 1]);
        let (a, b, c) = (m0, 3.0 * dx - 2.0 * m0 - m1, m0 + m1 - 2.0 * dx);
        let at = |t: Real| x0 + t * (a + t * (b + t * c));
        // x'(t) = a + 2 b t + 3 c t^2 = 0.
        let (qa, qb, qc) = (3.0 * c, 2.0 * b, a);
        let roots: Vec<Real> = if qa.abs() <= Real::EPSILON * (qb.abs() + qc.abs()) {
            match qb {
                0.0 => Vec::new(),
                _ => vec![-qc / qb],
            }
        } else {
            let disc = qb * qb - 4.0 * qa * qc;
            match disc >= 0.0 {
                true => {
                    let s = disc.sqrt();
                    vec![(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)]
                }
                false => Vec::new(),
            }
        };
        let (lo, hi) = (x[i].min(x[i + 1]), x[i].max(x[i + 1]));
        for t in roots.into_iter().filter(|t| *t > 0.0 && *t < 1.0) {
            let v = at(t);
            let beyond = (lo - v).max(v - hi);
            if beyond > 0.0 && worst.is_none_or(|w| beyond > w.beyond) {
                worst = Some(Swing {
                    z: z[i] + t * h,
                    x: v,
                    beyond,
                });
            }
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::{Interpolation, Profile};

    /// The natural spline is C2 inside and straight at its ends; through
    /// points of a cubic with no curvature at the ends it is that cubic.
    #[test]
    fn the_natural_spline_is_c2_with_free_ends() {
        let z: Vec<Real> = vec![0.0, 1.0, 2.5, 3.0, 4.5, 6.0];
        let x: Vec<Real> = z.iter().map(|&t| (0.7 * t).sin() + 0.1 * t * t).collect();
        let p = Profile::new(z.clone(), x.clone())
            .unwrap()
            .with_interpolation(Interpolation::Natural);
        let m = p.slopes().into_owned();
        // The second derivative of interval i's cubic at its ends.
        let second = |i: usize, end: Real| {
            let h = z[i + 1] - z[i];
            let (dx, m0, m1) = (x[i + 1] - x[i], h * m[i], h * m[i + 1]);
            let (b, c) = (3.0 * dx - 2.0 * m0 - m1, m0 + m1 - 2.0 * dx);
            (2.0 * b + 6.0 * c * end) / (h * h)
        };
        for i in 1..z.len() - 1 {
            let (left, right) = (second(i - 1, 1.0), second(i, 0.0));
            assert!(
                (left - right).abs() < 1e-9 * (1.0 + left.abs()),
                "node {i}: {left} {right}"
            );
        }
        assert!(second(0, 0.0).abs() < 1e-9);
        assert!(second(z.len() - 2, 1.0).abs() < 1e-9);
    }

    /// Beside a flat run the parabolic slopes overshoot, the monotone
    /// ones never do; the swing is found where the curve turns.
    #[test]
    fn a_swing_beyond_the_stations_is_found_where_it_turns() {
        let z = vec![0.0, 10.0, 20.0, 30.0, 40.0];
        let x = vec![20.0, 20.0, 20.0, 25.0, 30.0];
        let at = |i| {
            Profile::new(z.clone(), x.clone())
                .unwrap()
                .with_interpolation(i)
        };
        let parabolic = at(Interpolation::Parabolic).swing().unwrap();
        assert!(parabolic.z > 10.0 && parabolic.z < 20.0, "{parabolic:?}");
        assert!(
            parabolic.x < 20.0 && parabolic.beyond > 0.1,
            "{parabolic:?}"
        );
        let exact = at(Interpolation::Parabolic).eval(parabolic.z).unwrap();
        assert!((exact - parabolic.x).abs() < 1e-12);
        assert_eq!(at(Interpolation::Monotone).swing(), None);
        assert_eq!(at(Interpolation::Linear).swing(), None);
    }
}
