//! Thinning a polyline to a tolerance (Douglas–Peucker).

use crate::math::Real;

/// Indices of the points of the polyline `(z_i, x_i)` to keep so that every
/// dropped point lies within `tol` of the chord between the kept points
/// around it (Douglas and Peucker's method: split at the farthest point
/// until every chord fits). The first and last points are always kept.
///
/// A wheel's rounding moved in straight lines between the kept points of
/// its equidistant sweeps a surface within `tol` of the one swept along all
/// the points (a swept disc's surface moves no more than its path does), so
/// this is the fewest blocks for a chordal tolerance: straight stretches
/// need only their ends.
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
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let mut stack = vec![(0, n - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (dz, dx) = (z[b] - z[a], x[b] - x[a]);
        let len = dz.hypot(dx);
        let (mut worst, mut at) = (-1.0, a);
        for k in a + 1..b {
            let d = if len > 0.0 {
                ((z[k] - z[a]) * dx - (x[k] - x[a]) * dz).abs() / len
            } else {
                (z[k] - z[a]).hypot(x[k] - x[a])
            };
            // Beyond the chord's ends the distance is to the nearer end.
            let t = if len > 0.0 {
                ((z[k] - z[a]) * dz + (x[k] - x[a]) * dx) / (len * len)
            } else {
                0.0
            };
            let d = if t < 0.0 {
                (z[k] - z[a]).hypot(x[k] - x[a])
            } else if t > 1.0 {
                (z[k] - z[b]).hypot(x[k] - x[b])
            } else {
                d
            };
            if d > worst {
                worst = d;
                at = k;
            }
        }
        if worst > tol {
            keep[at] = true;
            stack.push((a, at));
            stack.push((at, b));
        }
    }
    (0..n).filter(|&i| keep[i]).collect()
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
        // A straight run keeps its ends only.
        assert_eq!(
            simplify_polyline(&[0.0, 1.0, 2.0, 3.0], &[1.0, 2.0, 3.0, 4.0], 1e-12),
            vec![0, 3]
        );
    }
}
