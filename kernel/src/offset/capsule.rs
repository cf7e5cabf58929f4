//! A grinding wheel as it is: in the part's axial section its periphery is
//! a flat of width `w = width - 2 R_s` between two roundings of radius
//! `R_s` (docs/math.md §2.4), a "capsule": the segment between the two rounding
//! centres, thickened by `R_s`. With `w = 0` it is the one circle of the
//! seed's model.
//!
//! The wheel's reference point is the middle of that segment (the centre of
//! its rounding when `w = 0`). Two facts give everything exactly from the
//! circle's model:
//!
//! - the surface a capsule at centres `c_i` leaves is the circles' surface
//!   `S` eroded by the flat: `min over |t| <= w/2 of S(z - t)`
//!   ([`CapsuleEnvelope`]);
//! - the lowest the capsule's reference can stand over a profile is the
//!   circle's equidistant `E` dilated by the flat:
//!   `max over |t| <= w/2 of E(z + t)` ([`flat_path`]).

use super::{CircleEnvelope, Side};
use crate::math::Real;
use crate::profile::{Polyline, ProfileError};

/// The path of a capsule's reference over a profile whose circle
/// equidistant (for the roundings' radius) is the polyline `(z, x)`, z
/// increasing: the running maximum of the equidistant over a window of the
/// flat's width `flat` (running minimum for [`Side::Inside`]). Exact for
/// the polyline: the result's nodes are the equidistant's nodes shifted by
/// `±flat/2` and the points where the window's two ends and its inside
/// take over from one another. The path runs `flat/2` beyond each end of
/// the equidistant, so that each rounding reaches each end (beyond its ends
/// the equidistant is taken as its end values): the wheel covers the whole
/// length the equidistant was made for.
///
/// # Failures
/// A flat that is negative or not finite; z not increasing.
pub fn flat_path(z: &[Real], x: &[Real], flat: Real, side: Side) -> Result<Polyline, ProfileError> {
    if !(flat.is_finite() && flat >= 0.0) {
        return Err(
            crate::input::InputError::out_of_range("wheel flat", flat, ">= 0 and finite").into(),
        );
    }
    let path = Polyline::new(z.to_vec(), x.to_vec())?;
    if flat == 0.0 || z.len() < 2 {
        return Ok(path);
    }
    if let Some(i) = (1..z.len()).find(|&i| z[i] <= z[i - 1]) {
        return Err(crate::input::InputError::NotIncreasing {
            what: "equidistant z".into(),
            index: i,
            prev: z[i - 1],
            value: z[i],
        }
        .into());
    }
    let s = side.sign();
    let h = flat / 2.0;
    // y = s x: a running maximum either way.
    let y: Vec<Real> = x.iter().map(|v| s * v).collect();
    let at = |q: Real| -> Real {
        let k = z.partition_point(|&v| v <= q);
        if k == 0 {
            y[0]
        } else if k >= z.len() {
            y[z.len() - 1]
        } else {
            let t = (q - z[k - 1]) / (z[k] - z[k - 1]);
            y[k - 1] + t * (y[k] - y[k - 1])
        }
    };
    // The window over z[0]..z[n-1] (the path beyond its ends is the ends').
    let value = |q: Real| -> Real {
        let (a, b) = (q - h, q + h);
        let lo = z.partition_point(|&v| v <= a);
        let hi = z.partition_point(|&v| v < b);
        let inner = y[lo..hi]
            .iter()
            .copied()
            .fold(Real::NEG_INFINITY, Real::max);
        at(a).max(at(b)).max(inner)
    };
    // Candidate nodes: every node shifted both ways, within the path's span.
    let (z0, z1) = (z[0] - h, z[z.len() - 1] + h);
    let mut q: Vec<Real> = z
        .iter()
        .flat_map(|&v| [v - h, v + h])
        .filter(|v| (z0..=z1).contains(v))
        .chain([z0, z1])
        .collect();
    q.sort_by(Real::total_cmp);
    q.dedup();
    // Between candidates the window's ends run along single segments and
    // its inside holds a fixed set of nodes: the value is the largest of
    // two lines and a constant. Add the points where they cross.
    let mut out_z = Vec::with_capacity(q.len() * 2);
    for w in q.windows(2) {
        let (a, b) = (w[0], w[1]);
        out_z.push(a);
        let mid = 0.5 * (a + b);
        let lo = z.partition_point(|&v| v <= mid - h);
        let hi = z.partition_point(|&v| v < mid + h);
        let inner = y[lo..hi]
            .iter()
            .copied()
            .fold(Real::NEG_INFINITY, Real::max);
        let left = |t: Real| at(t - h);
        let right = |t: Real| at(t + h);
        let lines = [(left(a), left(b)), (right(a), right(b)), (inner, inner)];
        let mut cross = vec![];
        for i in 0..3 {
            for j in i + 1..3 {
                let (da, db) = (lines[i].0 - lines[j].0, lines[i].1 - lines[j].1);
                if da.is_finite() && db.is_finite() && da * db < 0.0 {
                    let t = da / (da - db);
                    cross.push(a + t * (b - a));
                }
            }
        }
        cross.sort_by(Real::total_cmp);
        out_z.extend(cross.into_iter().filter(|&c| c > a && c < b));
    }
    out_z.push(q[q.len() - 1]);
    let out_x: Vec<Real> = out_z.iter().map(|&v| s * value(v)).collect();
    // Drop points on straight runs: the path only needs its corners.
    let keep = crate::profile::simplify_polyline(&out_z, &out_x, crate::tolerance::SAME_LENGTH);
    Polyline::new(
        keep.iter().map(|&i| out_z[i]).collect(),
        keep.iter().map(|&i| out_x[i]).collect(),
    )
    .map_err(Into::into)
}

/// The surface a capsule (a flat of width `flat` between two roundings of
/// radius `radius`) leaves at many centres: the circles' envelope eroded by
/// the flat, `min over |t| <= flat/2 of S(z - t)` (Outside; the maximum,
/// Inside).
///
/// # Method
/// `S` is the lower envelope of convex arcs, so over a window its minimum
/// is at one of the window's ends or at the bottom of an arc inside it: a
/// circle centre. So the eroded surface at `z` is the least of `S(z - w/2)`,
/// `S(z + w/2)` and `S` at the centres within `w/2` of `z`: exact, and
/// linear in the points evaluated (a sliding-window minimum).
#[derive(Debug, Clone)]
pub struct CapsuleEnvelope {
    circles: CircleEnvelope,
    flat: Real,
    /// Circle centres' z, sorted, with `sign * S` there (lowest first at
    /// equal z), for the window's inside.
    bottoms: Vec<(Real, Real)>,
}

impl CapsuleEnvelope {
    /// The surface of a capsule at centres `(zc[i], xc[i])`.
    ///
    /// # Failures
    /// As [`CircleEnvelope::new`]; a negative or non-finite flat.
    pub fn new(
        zc: &[Real],
        xc: &[Real],
        radius: Real,
        flat: Real,
        side: Side,
    ) -> Result<Self, ProfileError> {
        if !(flat.is_finite() && flat >= 0.0) {
            return Err(crate::input::InputError::out_of_range(
                "wheel flat",
                flat,
                ">= 0 and finite",
            )
            .into());
        }
        let circles = CircleEnvelope::new(zc, xc, radius, side)?;
        let bottoms = if flat > 0.0 {
            let mut zs = zc.to_vec();
            zs.sort_by(Real::total_cmp);
            zs.dedup();
            let s = side.sign();
            let v = circles.eval_many(&zs);
            zs.into_iter().zip(v).map(|(z, v)| (z, s * v)).collect()
        } else {
            vec![]
        };
        Ok(Self {
            circles,
            flat,
            bottoms,
        })
    }

    /// The circles' envelope (the roundings alone).
    pub fn circles(&self) -> &CircleEnvelope {
        &self.circles
    }

    /// The flat's width.
    pub fn flat(&self) -> Real {
        self.flat
    }

    /// The surface at `z` (infinite where the wheel never reached).
    pub fn eval(&self, z: Real) -> Real {
        self.eval_many(&[z])[0]
    }

    /// The surface at many z (any order; linear time when sorted).
    pub fn eval_many(&self, zs: &[Real]) -> Vec<Real> {
        if self.flat == 0.0 {
            return self.circles.eval_many(zs);
        }
        let h = self.flat / 2.0;
        let s = self.circles.side().sign();
        let lefts: Vec<Real> = zs.iter().map(|z| z - h).collect();
        let rights: Vec<Real> = zs.iter().map(|z| z + h).collect();
        let (l, r) = (
            self.circles.eval_many(&lefts),
            self.circles.eval_many(&rights),
        );
        zs.iter()
            .enumerate()
            .map(|(i, &z)| {
                let lo = self.bottoms.partition_point(|b| b.0 < z - h);
                let hi = self.bottoms.partition_point(|b| b.0 <= z + h);
                let inner = self.bottoms[lo..hi]
                    .iter()
                    .map(|b| b.1)
                    .fold(Real::INFINITY, Real::min);
                s * (s * l[i]).min(s * r[i]).min(inner)
            })
            .collect()
    }

    /// The index (in the input) of a circle forming the surface at `z`.
    pub fn source_at(&self, z: Real) -> Option<usize> {
        if self.flat == 0.0 {
            return self.circles.source_at(z);
        }
        let h = self.flat / 2.0;
        let target = self.eval(z);
        if !target.is_finite() {
            return None;
        }
        // The window's point where the eroded value is reached.
        let mut best = (Real::INFINITY, z);
        let s = self.circles.side().sign();
        for q in [z - h, z + h] {
            let v = s * self.circles.eval(q);
            if v < best.0 {
                best = (v, q);
            }
        }
        let lo = self.bottoms.partition_point(|b| b.0 < z - h);
        let hi = self.bottoms.partition_point(|b| b.0 <= z + h);
        for b in &self.bottoms[lo..hi] {
            if b.1 < best.0 {
                best = (b.1, b.0);
            }
        }
        self.circles.source_at(best.1)
    }

    /// The z in `[a, b]` where the surface has a corner (its cusps, and the
    /// ends of its flats), sorted: with them, a polyline through samples
    /// follows the surface within the arcs' sag between samples.
    pub fn kinks(&self, a: Real, b: Real) -> Vec<Real> {
        let h = self.flat / 2.0;
        let mut out: Vec<Real> = self
            .circles
            .breakpoints(a - h, b + h)
            .into_iter()
            .flat_map(|k| [k - h, k + h])
            .chain(
                self.bottoms
                    .iter()
                    .filter(|p| p.0 >= a - h && p.0 <= b + h)
                    .flat_map(|p| [p.0 - h, p.0 + h]),
            )
            .filter(|k| *k >= a && *k <= b)
            .collect();
        out.sort_by(Real::total_cmp);
        out.dedup();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::offset::equidistant;

    /// The eroded envelope equals the envelope of many circles spread along
    /// each flat, computed the long way.
    #[test]
    fn capsule_surface_is_the_circles_along_the_flat() {
        let zc = [0.0, 3.0, 7.5, 9.0, 14.0];
        let xc = [10.0, 10.2, 9.9, 10.4, 10.1];
        let (r, w) = (4.0, 2.5);
        let cap = CapsuleEnvelope::new(&zc, &xc, r, w, Side::Outside).unwrap();
        let (mut bz, mut bx) = (vec![], vec![]);
        for (z, x) in zc.iter().zip(&xc) {
            for k in 0..=2000 {
                bz.push(z - w / 2.0 + w * k as Real / 2000.0);
                bx.push(*x);
            }
        }
        let brute = CircleEnvelope::new(&bz, &bx, r, Side::Outside).unwrap();
        for i in 0..=400 {
            let z = -6.0 + 26.0 * i as Real / 400.0;
            let (a, b) = (cap.eval(z), brute.eval(z));
            if a.is_finite() || b.is_finite() {
                assert!((a - b).abs() < 1e-6, "z {z}: {a} vs {b}");
            }
        }
        assert_eq!(cap.source_at(3.0), Some(1));
    }

    /// A wheel with a flat on its path over a profile touches it and never
    /// cuts into it, on a slope, a curve and over a peak.
    #[test]
    fn flat_path_touches_without_gouging() {
        // Rising like a mandrel's law (x'' = 8/4900), then a peak and a
        // falling cone: a kink the wheel's centre swings round.
        let law = crate::profile::MandrelLaw::new(40.0, 48.0, 70.0, 0.0, 2.0).unwrap();
        let p = crate::profile::ProfileBuilder::start(0.0, 20.0)
            .law(law)
            .line_to(100.0, 21.0)
            .build(1e-6, 0.25)
            .unwrap();
        let z: Vec<Real> = (0..=400).map(|i| i as Real * 0.25).collect();
        let (r, w) = (15.0, 10.0);
        let e = equidistant(&p, r, Side::Outside).unwrap();
        let path = flat_path(&e.z, &e.x, w, Side::Outside).unwrap();
        let cap = CapsuleEnvelope::new(&path.z, &path.x, r, w, Side::Outside).unwrap();
        let inner: Vec<Real> = z
            .iter()
            .copied()
            .filter(|z| (8.0..=92.0).contains(z))
            .collect();
        let s = cap.eval_many(&inner);
        let px = p.eval_many(&inner).unwrap();
        let (worst_below, at) = inner
            .iter()
            .zip(s.iter().zip(&px))
            .map(|(z, (s, p))| (s - p, *z))
            .fold((Real::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a });
        // The corner's arc is followed within its chords' sag (CORNER_SAG).
        assert!(
            worst_below > -2.0 * crate::offset::CORNER_SAG,
            "gouge of {worst_below} at z = {at}"
        );
        // On a rising curve the flat's uphill end does the cutting: every
        // place is reached, nothing is left but the chords' sag.
        let worst_above = inner
            .iter()
            .zip(s.iter().zip(&px))
            .filter(|(z, _)| **z < 60.0)
            .map(|(_, (s, p))| s - p)
            .fold(0.0, Real::max);
        assert!(worst_above < 1e-4, "{worst_above}");
        // A straight slope: the flat rests on its uphill end, and the path
        // runs half the flat beyond each end, so each rounding reaches it.
        let line = flat_path(&[0.0, 10.0], &[0.0, 1.0], 2.0, Side::Outside).unwrap();
        let n = line.len() - 1;
        assert_eq!((line.z[0], line.z[n]), (-1.0, 11.0));
        assert!(line.x[0].abs() < 1e-12 && (line.x[n] - 1.0).abs() < 1e-12);
        // The slope's line from (-1, 0) through (0, 0.1) to (9, 1), then
        // the end's value.
        assert_eq!(line.len(), 3, "{line:?}");
        assert!((line.z[1] - 9.0).abs() < 1e-12 && (line.x[1] - 1.0).abs() < 1e-12);
    }
}
