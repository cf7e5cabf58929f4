//! The envelope of many positions of one tool circle: the surface a swept
//! wheel leaves.

use super::Side;
use crate::input::InputError;
use crate::math::{positive, Real};
use crate::profile::ProfileError;

/// The surface left by a circle of one radius placed at many centres: for
/// [`Side::Outside`] (a wheel above the surface) the lower envelope of the
/// circles' lower arcs, `min_i xc_i - sqrt(r^2 - (z - zc_i)^2)`; for
/// [`Side::Inside`] the upper envelope of their upper arcs. Where no circle
/// reaches, the value is `+inf` (Outside) or `-inf` (Inside): nothing was
/// removed there.
///
/// # Method
/// The arcs are translates of one convex function, so any two of them cross
/// at most once: the later circle (in z) is below the earlier one from a
/// single "takeover" z onward. That makes the lower envelope a sequence of
/// pieces ordered like the centres, built in one sweep with a stack (as
/// Felzenszwalb and Huttenlocher build the lower envelope of parabolas).
/// Building costs O(N log N) for N circles (the sort), evaluating M sorted
/// points O(M + N): no N x M scan, and no window to tune. Takeovers are
/// exact circle intersections, so the envelope is exact to rounding.
///
/// ```
/// use pilgrim_kernel::{CircleEnvelope, Side};
/// // Two wheel positions 2 mm apart, radius 5, centres at x = 5: a cusp between them.
/// let env = CircleEnvelope::new(&[0.0, 2.0], &[5.0, 5.0], 5.0, Side::Outside).unwrap();
/// assert_eq!(env.eval(0.0), 0.0);
/// assert!((env.eval(1.0) - (5.0 - 24.0_f64.sqrt())).abs() < 1e-12);
/// assert_eq!(env.eval(20.0), f64::INFINITY);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct CircleEnvelope {
    radius: Real,
    side: Side,
    /// Pieces in z order: (start z, centre z, centre y) with y = sign * x,
    /// so both sides are a lower envelope in y.
    pieces: Vec<(Real, Real, Real)>,
    /// For each piece, the index of its circle in the input.
    sources: Vec<usize>,
}

impl CircleEnvelope {
    /// The envelope of circles of `radius` centred at `(zc[i], xc[i])`, in
    /// any order.
    ///
    /// # Failures
    /// A radius that is not positive; arrays of different lengths or empty;
    /// a non-finite centre (named by index).
    pub fn new(zc: &[Real], xc: &[Real], radius: Real, side: Side) -> Result<Self, ProfileError> {
        positive("envelope circle radius", radius)?;
        if zc.len() != xc.len() {
            return Err(InputError::LengthMismatch {
                what: "envelope centres z and x".into(),
                left: zc.len(),
                right: xc.len(),
            }
            .into());
        }
        if zc.is_empty() {
            return Err(InputError::TooFew {
                what: "envelope circles".into(),
                got: 0,
                min: 1,
            }
            .into());
        }
        crate::math::all_finite("envelope centre z", zc)?;
        crate::math::all_finite("envelope centre x", xc)?;
        let sigma = side.sign();
        let mut c: Vec<(Real, Real, usize)> = zc
            .iter()
            .zip(xc)
            .enumerate()
            .map(|(i, (&z, &x))| (z, sigma * x, i))
            .collect();
        c.sort_unstable_by(|a, b| {
            a.0.total_cmp(&b.0)
                .then(a.1.total_cmp(&b.1))
                .then(a.2.cmp(&b.2))
        });
        c.dedup_by(|later, kept| later.0 == kept.0); // equal z: keep the lowest
        let mut pieces: Vec<(Real, Real, Real)> = Vec::with_capacity(c.len());
        let mut sources: Vec<usize> = Vec::with_capacity(c.len());
        for &(z, y, i) in &c {
            loop {
                match pieces.last() {
                    None => {
                        pieces.push((Real::NEG_INFINITY, z, y));
                        sources.push(i);
                        break;
                    }
                    Some(&(start, zi, yi)) => {
                        let s = takeover(zi, yi, z, y, radius);
                        if s <= start {
                            pieces.pop();
                            sources.pop();
                        } else {
                            pieces.push((s, z, y));
                            sources.push(i);
                            break;
                        }
                    }
                }
            }
        }
        Ok(Self {
            radius,
            side,
            pieces,
            sources,
        })
    }

    /// The circle radius.
    pub fn radius(&self) -> Real {
        self.radius
    }

    /// The side the circles stand on.
    pub fn side(&self) -> Side {
        self.side
    }

    /// The z in `[a, b]` where one circle takes over from another (the
    /// envelope's cusps), in order.
    pub fn breakpoints(&self, a: Real, b: Real) -> Vec<Real> {
        let lo = self.pieces.partition_point(|p| p.0 < a);
        let hi = self.pieces.partition_point(|p| p.0 <= b);
        self.pieces[lo..hi]
            .iter()
            .map(|p| p.0)
            .filter(|z| z.is_finite())
            .collect()
    }

    /// How many circles appear on the envelope.
    pub fn piece_count(&self) -> usize {
        self.pieces.len()
    }

    #[inline]
    fn value(&self, k: usize, z: Real) -> Real {
        let (_, zc, yc) = self.pieces[k];
        let dz = z - zc;
        let q = self.radius * self.radius - dz * dz;
        let y = if q >= 0.0 {
            yc - q.sqrt()
        } else {
            Real::INFINITY
        };
        y * self.side.sign()
    }

    /// The envelope's x at `z`.
    pub fn eval(&self, z: Real) -> Real {
        self.value(self.piece_at(z), z)
    }

    fn piece_at(&self, z: Real) -> usize {
        self.pieces.partition_point(|p| p.0 <= z).saturating_sub(1)
    }

    /// The index (in the input) of the circle that forms the envelope at
    /// `z`, or `None` where no circle reaches.
    pub fn source_at(&self, z: Real) -> Option<usize> {
        let k = self.piece_at(z);
        self.value(k, z).is_finite().then(|| self.sources[k])
    }

    /// The envelope at many z; linear time when `zs` is sorted ascending
    /// (any order is accepted).
    pub fn eval_many(&self, zs: &[Real]) -> Vec<Real> {
        if !zs.windows(2).all(|w| w[0] <= w[1]) {
            return zs.iter().map(|&z| self.eval(z)).collect();
        }
        let mut k = zs.first().map_or(0, |&z| self.piece_at(z));
        zs.iter()
            .map(|&z| {
                while k + 1 < self.pieces.len() && self.pieces[k + 1].0 <= z {
                    k += 1;
                }
                self.value(k, z)
            })
            .collect()
    }
}

/// Circle centres (z, x) and, for each, the block whose move placed it.
pub type SweptCircles = (Vec<Real>, Vec<Real>, Vec<usize>);

/// The circles a wheel's rounding of `radius` leaves along straight moves:
/// circles along the moves through `(z[i], x[i])`, at most
/// `sqrt(8 radius resolution)` apart: their centres, and for each the block
/// whose move placed it (block 0 places the first). Their envelope differs
/// from the continuously swept circle by at most `resolution` (the scallop
/// `spacing^2 / (8 radius)`).
///
/// # Failures
/// More than 50 million circles.
pub fn swept_circles(
    z: &[Real],
    x: &[Real],
    radius: Real,
    resolution: Real,
) -> Result<SweptCircles, ProfileError> {
    let spacing = (8.0 * radius * resolution).sqrt();
    let (mut cz, mut cx, mut block_of) = (vec![z[0]], vec![x[0]], vec![0]);
    for k in 1..z.len() {
        let len = (z[k] - z[k - 1]).hypot(x[k] - x[k - 1]);
        let n = (len / spacing).ceil().max(1.0);
        if cz.len() as Real + n > 5e7 {
            return Err(crate::input::InputError::out_of_range(
                "verification resolution",
                resolution,
                "coarse enough for at most 50 million circles",
            )
            .into());
        }
        let n = n as usize;
        for j in 1..=n {
            let t = j as Real / n as Real;
            cz.push(z[k - 1] + t * (z[k] - z[k - 1]));
            cx.push(x[k - 1] + t * (x[k] - x[k - 1]));
            block_of.push(k);
        }
    }
    Ok((cz, cx, block_of))
}

/// The z from which circle j (centre zj > zi) is below circle i on the lower
/// envelope of lower arcs (or i has ended).
fn takeover(zi: Real, yi: Real, zj: Real, yj: Real, r: Real) -> Real {
    let (lo, hi) = (zj - r, zi + r); // common domain
    if lo >= hi {
        return hi; // disjoint reaches: i ends before j begins
    }
    let arc = |zc: Real, yc: Real, z: Real| yc - (r * r - (z - zc) * (z - zc)).max(0.0).sqrt();
    // d(z) = arc_j - arc_i decreases on [lo, hi].
    if arc(zj, yj, lo) <= arc(zi, yi, lo) {
        return lo;
    }
    if arc(zj, yj, hi) >= arc(zi, yi, hi) {
        return hi;
    }
    // The arcs cross inside: at the lower of the circles' two intersections,
    // the midpoint of the centres moved by h along the perpendicular
    // (dy, -dz)/d, which points down in y since dz > 0.
    let (dz, dy) = (zj - zi, yj - yi);
    let d = dz.hypot(dy);
    let h = (r * r - 0.25 * d * d).max(0.0).sqrt();
    let s = zi + 0.5 * dz + h * dy / d;
    s.clamp(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    /// The envelope by brute force over all circles.
    fn brute(zc: &[Real], xc: &[Real], r: Real, z: Real) -> Real {
        zc.iter()
            .zip(xc)
            .filter(|(c, _)| (z - *c).abs() <= r)
            .map(|(c, x)| x - (r * r - (z - c) * (z - c)).sqrt())
            .fold(Real::INFINITY, Real::min)
    }

    #[test]
    fn matches_brute_force_on_scattered_circles() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as Real / (1u64 << 53) as Real
        };
        for trial in 0..50 {
            let n = 2 + trial * 3;
            let r = 0.5 + 3.0 * rnd();
            let zc: Vec<Real> = (0..n).map(|_| 40.0 * rnd()).collect();
            let xc: Vec<Real> = (0..n).map(|_| 10.0 * rnd()).collect();
            let env = CircleEnvelope::new(&zc, &xc, r, Side::Outside).unwrap();
            let zs: Vec<Real> = (0..2000)
                .map(|i| -5.0 + 50.0 * i as Real / 2000.0)
                .collect();
            for (z, v) in zs.iter().zip(env.eval_many(&zs)) {
                let b = brute(&zc, &xc, r, *z);
                if b.is_finite() {
                    assert_near!(v, b, 1e-9, "trial {trial} z {z}");
                } else {
                    assert_eq!(v, Real::INFINITY, "trial {trial} z {z}");
                }
                assert_eq!(env.eval(*z), v);
                // The source circle is the one that gives that value.
                if let Some(i) = env.source_at(*z) {
                    let own = xc[i] - (r * r - (z - zc[i]).powi(2)).sqrt();
                    assert_near!(own, v, 1e-9);
                } else {
                    assert_eq!(v, Real::INFINITY);
                }
            }
            // Inside is the mirror image.
            let neg: Vec<Real> = xc.iter().map(|x| -x).collect();
            let inside = CircleEnvelope::new(&zc, &neg, r, Side::Inside).unwrap();
            for z in zs.iter().step_by(7) {
                let (a, b) = (inside.eval(*z), env.eval(*z));
                assert!(a == -b, "{a} {b}");
            }
        }
    }

    #[test]
    fn bad_input_is_named() {
        assert!(CircleEnvelope::new(&[], &[], 1.0, Side::Outside).is_err());
        assert!(CircleEnvelope::new(&[0.0], &[0.0], 0.0, Side::Outside).is_err());
        let e = CircleEnvelope::new(&[0.0, f64::NAN], &[0.0, 0.0], 1.0, Side::Outside).unwrap_err();
        assert!(e.to_string().contains("envelope centre z[1]"), "{e}");
    }
}
