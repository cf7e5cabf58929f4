//! Thinning a polyline to a tolerance (greedy longest chords).

use crate::math::Real;

/// Indices of the points of the polyline `(z_i, x_i)` to keep so that every
/// dropped point lies within `tol` of the chord between the kept points
/// around it. The first and last points are always kept.
///
/// From each kept point the chord reaches as far along the polyline as it
/// can while every point it skips stays within `tol` (found by doubling the
/// reach, then bisecting). On a curve this gives chords as long as the
/// local curvature allows, `sqrt(8 tol / kappa)`, so the count follows
/// `integral of sqrt(kappa / (8 tol))` rather than the sharpest place's
/// uniform step; Douglas and Peucker's halving overshoots that by up to 2x
/// on evenly curved stretches. Straight stretches need only their ends.
///
/// A wheel's rounding moved in straight lines between the kept points of
/// its equidistant sweeps a surface within `tol` of the one swept along all
/// the points (a swept disc's surface moves no more than its path does).
///
/// # Cost
/// `O(n log m)` chord checks of `m` points for chords of `m` points.
///
/// ```
/// use pilgrim_kernel::profile::simplify_polyline;
/// let z = [0.0, 1.0, 2.0, 3.0, 4.0];
/// let x = [0.0, 0.0, 0.0, 1.0, 2.0]; // a line, then a slope
/// assert_eq!(simplify_polyline(&z, &x, 1e-9), vec![0, 2, 4]);
/// ```
pub fn simplify_polyline(z: &[Real], x: &[Real], tol: Real) -> Vec<usize> {
    let n = z.len().min(x.len());
    if n <= 2 {
        return (0..n).collect();
    }
    // Does the chord a -> b pass within tol of every point between?
    let fits = |a: usize, b: usize| {
        let (dz, dx) = (z[b] - z[a], x[b] - x[a]);
        let len2 = dz * dz + dx * dx;
        (a + 1..b).all(|k| {
            let (pz, px) = (z[k] - z[a], x[k] - x[a]);
            let t = if len2 > 0.0 {
                (pz * dz + px * dx) / len2
            } else {
                0.0
            };
            // Beyond the chord's ends the distance is to the nearer end.
            let d = if t <= 0.0 {
                pz.hypot(px)
            } else if t >= 1.0 {
                (z[k] - z[b]).hypot(x[k] - x[b])
            } else {
                (pz * dx - px * dz).abs() / len2.sqrt()
            };
            d <= tol
        })
    };
    let mut keep = vec![0];
    let mut a = 0;
    while a < n - 1 {
        // Double the reach while the chord fits, then bisect the last gap.
        let (mut good, mut step) = (a + 1, 1);
        let mut bad = n;
        while good < n - 1 {
            let b = (a + 2 * step).min(n - 1);
            if fits(a, b) {
                good = b;
                step *= 2;
            } else {
                bad = b;
                break;
            }
        }
        while bad - good > 1 {
            let mid = good + (bad - good) / 2;
            if fits(a, mid) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        keep.push(good);
        a = good;
    }
    keep
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dropped_points_lie_within_tolerance_of_their_chord() {
        let z: Vec<Real> = (0..2000).map(|i| i as Real * 0.01).collect();
        let x: Vec<Real> = z.iter().map(|z| (z * 0.7).sin() * 3.0).collect();
        for tol in [1e-4, 1e-3, 1e-2] {
            let keep = simplify_polyline(&z, &x, tol);
            assert_eq!((keep[0], *keep.last().unwrap()), (0, 1999));
            for w in keep.windows(2) {
                let (a, b) = (w[0], w[1]);
                let (dz, dx) = (z[b] - z[a], x[b] - x[a]);
                for k in a..=b {
                    let d = ((z[k] - z[a]) * dx - (x[k] - x[a]) * dz).abs() / dz.hypot(dx);
                    assert!(d <= tol, "tol {tol}: point {k} is {d} from its chord");
                }
            }
            // Chords of a sine of amplitude 3 stray h^2 / 8 * 1.47 from it: at
            // 0.01 mm only a few dozen points are needed.
            if tol == 1e-2 {
                assert!(keep.len() < 100, "{}", keep.len());
            }
        }
        // On an evenly curved arc the chords are as long as the tolerance
        // allows: the count is within a chord of arc / sqrt(8 tol R).
        let r = 20.0;
        let t: Vec<Real> = (0..=20_000).map(|i| i as Real * 1e-4).collect();
        let (z, x): (Vec<Real>, Vec<Real>) = t.iter().map(|t| (r * t.sin(), r * t.cos())).unzip();
        for tol in [1e-4, 5e-4, 1e-3] {
            let chords = simplify_polyline(&z, &x, tol).len() - 1;
            let ideal = 2.0 * r / (8.0 * tol * r).sqrt();
            assert!(
                (chords as Real) < ideal * 1.01 + 1.0 && chords as Real >= ideal * 0.99,
                "tol {tol}: {chords} chords, ideal {ideal}"
            );
        }
        // A straight run keeps its ends only.
        assert_eq!(
            simplify_polyline(&[0.0, 1.0, 2.0, 3.0], &[1.0, 2.0, 3.0, 4.0], 1e-12),
            vec![0, 3]
        );
    }
}

/// A polyline in the axial section: points `(z[i], x[i])` in order, z in
/// any direction (a wheel's centres along a pass, one way or the other).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Polyline {
    /// The points' z (mm).
    pub z: Vec<Real>,
    /// The points' x (mm).
    pub x: Vec<Real>,
}

impl Polyline {
    /// The polyline through `(z[i], x[i])`.
    ///
    /// # Failures
    /// Arrays of different lengths; a value that is not finite.
    pub fn new(z: Vec<Real>, x: Vec<Real>) -> Result<Self, crate::input::InputError> {
        if z.len() != x.len() {
            return Err(crate::input::InputError::LengthMismatch {
                what: "polyline z and x".into(),
                left: z.len(),
                right: x.len(),
            });
        }
        crate::math::all_finite("polyline z", &z)?;
        crate::math::all_finite("polyline x", &x)?;
        Ok(Self { z, x })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.z.len()
    }

    /// Whether it has no points.
    pub fn is_empty(&self) -> bool {
        self.z.is_empty()
    }

    /// The fewest of its points keeping every dropped one within `tol` of
    /// the chords ([`simplify_polyline`]).
    pub fn simplified(&self, tol: Real) -> Self {
        let keep = simplify_polyline(&self.z, &self.x, tol);
        Self {
            z: keep.iter().map(|&i| self.z[i]).collect(),
            x: keep.iter().map(|&i| self.x[i]).collect(),
        }
    }

    /// The same points in reverse order.
    pub fn reversed(&self) -> Self {
        Self {
            z: self.z.iter().rev().copied().collect(),
            x: self.x.iter().rev().copied().collect(),
        }
    }

    /// Every point moved by `dx` in x.
    pub fn shifted(&self, dx: Real) -> Self {
        Self {
            z: self.z.clone(),
            x: self.x.iter().map(|x| x + dx).collect(),
        }
    }
}
