//! The surface of a part being ground, as the machine makes it (MATH §2.4):
//! the part turns at S rpm while the wheel moves along its path at F mm/min,
//! so each generatrix of the part meets the wheel only at the moments it
//! passes under it, `f = F / S` mm apart along the path; between those
//! touches the wheel's rounding leaves a helical ridge.
//!
//! - [`touches`] places the wheel (its reference: the middle of its flat,
//!   the rounding's centre for a wheel without one) where each of `m`
//!   generatrices, `360/m` degrees apart, meets it, moving along straight
//!   moves at their feeds, the control's linear interpolation in time.
//! - [`PassLayer`] is what one pass leaves as a surface of revolution: the
//!   wheel's true section swept along the path (the valleys) and the
//!   ridges' crests above it: what a steady rest's support riding the
//!   turning part meets. (The verification simulates each generatrix's
//!   touches instead: [`crate::verify::check_grinding`].)
//! - [`GroundSurface`] is the blank (a polyline: a step stays a step)
//!   lowered by each pass's layer, exact at any z.
//!
//! # Generatrices
//! [`GENERATRICES`] = 8, 45 degrees apart. On a straight generatrix the
//! ridge pattern is the same on every one, shifted by `f/8` along the
//! part: the highest of the 8 is within `h (1 - (1 - 1/8)^2) < h / 4` of
//! the true crest `h` (0.1 um for the default finish's 0.4 um ridge), and
//! the lowest of them reaches the valleys (the touches themselves).

use super::{CapsuleEnvelope, Side};
use crate::math::Real;
use crate::profile::{Profile, ProfileError};

/// The generatrices a pass is simulated on.
pub const GENERATRICES: usize = 8;

/// The wheel's reference at the moments each generatrix passes under it.
#[derive(Debug, Clone, PartialEq)]
pub struct Touches {
    /// For each generatrix: the touches' z.
    pub z: Vec<Vec<Real>>,
    /// For each generatrix: the touches' x.
    pub x: Vec<Vec<Real>>,
    /// For each generatrix and touch: the move (block index in the path,
    /// from 1: the move from point k-1 to k; 0 for a touch at the first
    /// point) that placed it.
    pub block: Vec<Vec<usize>>,
    /// The time at each point of the path (minutes from the pass's start).
    pub time: Vec<Real>,
}

/// The most touches a pass may have, over all its generatrices.
pub const MAX_TOUCHES: usize = 50_000_000;

/// Where `m` generatrices meet a wheel whose reference moves along the
/// path `(z[k], x[k])` (straight moves, each at `feed[k]` mm/min, `feed[0]`
/// unused) while the part turns at `rpm`: generatrix `g` passes under the
/// wheel at the times `(g/m + j) / rpm` minutes after the pass's start.
///
/// # Failures
/// Arrays of different lengths or empty; a feed or speed that is not
/// positive and finite; more than [`MAX_TOUCHES`] touches.
pub fn touches(
    z: &[Real],
    x: &[Real],
    feed: &[Real],
    rpm: Real,
    m: usize,
) -> Result<Touches, ProfileError> {
    use crate::input::InputError;
    crate::math::positive("spindle speed", rpm)?;
    if z.len() != x.len() || z.len() != feed.len() || z.is_empty() || m == 0 {
        return Err(InputError::LengthMismatch {
            what: "pass points z, x and feeds".into(),
            left: z.len(),
            right: x.len().min(feed.len()),
        }
        .into());
    }
    let mut time = Vec::with_capacity(z.len());
    time.push(0.0);
    for k in 1..z.len() {
        let len = (z[k] - z[k - 1]).hypot(x[k] - x[k - 1]);
        let f = feed[k];
        if !(f.is_finite() && f > 0.0) {
            return Err(InputError::NotPositive {
                what: format!("feed of move {k}"),
                value: f,
            }
            .into());
        }
        time.push(time[k - 1] + len / f);
    }
    let total = time[time.len() - 1];
    let expected = total * rpm * m as Real;
    if !(expected <= MAX_TOUCHES as Real) {
        return Err(InputError::out_of_range(
            "touches of the wheel on the part's generatrices",
            expected,
            format!("at most {MAX_TOUCHES}: a feed too slow for the pass's length"),
        )
        .into());
    }
    let mut out = Touches {
        z: vec![vec![]; m],
        x: vec![vec![]; m],
        block: vec![vec![]; m],
        time,
    };
    for g in 0..m {
        let mut k = 1;
        let mut j = 0usize;
        loop {
            let t = (g as Real / m as Real + j as Real) / rpm;
            if t > total {
                break;
            }
            while k + 1 < out.time.len() && out.time[k] < t {
                k += 1;
            }
            let (p, zz, xx) = if out.time.len() == 1 {
                (0, z[0], x[0])
            } else {
                let (t0, t1) = (out.time[k - 1], out.time[k]);
                let s = if t1 > t0 {
                    ((t - t0) / (t1 - t0)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                (
                    k,
                    z[k - 1] + s * (z[k] - z[k - 1]),
                    x[k - 1] + s * (x[k] - x[k - 1]),
                )
            };
            out.z[g].push(zz);
            out.x[g].push(xx);
            out.block[g].push(p);
            j += 1;
        }
    }
    Ok(out)
}

/// The wheel's roundings and flat in the axial section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelSection {
    /// R_s (mm).
    pub radius: Real,
    /// The flat between the roundings (mm; 0 for none).
    pub flat: Real,
}

impl WheelSection {
    /// The ridge on a straight generatrix at `f` mm per revolution (as
    /// [`crate::tool::Wheel::ridge`]: the rounding's).
    pub fn ridge(&self, f: Real) -> Real {
        crate::tool::rounding_ridge(self.radius, f)
    }
}

/// How finely a pass's sweep is placed: the scallops of the continuous
/// sweep's circles stay below this (mm).
pub const SWEEP_RESOLUTION: Real = 1e-5;

/// What one pass leaves, as a surface of revolution: the wheel's true
/// section swept continuously along the path (the valleys, where a
/// generatrix met the wheel), and above it the crests of the helical ridge
/// (what a support riding the turning part meets): the sweep raised by the
/// ridge of the pass's feed per revolution. On a straight generatrix both
/// are exact; on a curved one the crest is off by the path's sagitta over
/// `f`, `f^2 / (8 rho)` (0.3 um for f = 5 mm on the mandrel's 11.6 m).
#[derive(Debug, Clone)]
pub struct PassLayer {
    swept: CapsuleEnvelope,
    ridge: Real,
    /// The sweep's circles (z, x) and the time each was placed (minutes
    /// from the pass's start): what a partial pass has cut.
    circles: (Vec<Real>, Vec<Real>, Vec<Real>),
    wheel: WheelSection,
}

impl PassLayer {
    /// The layer of `wheel` moved along `(z[k], x[k])` at `feed` mm/min
    /// while the part turns at `rpm`.
    ///
    /// # Failures
    /// Bad numbers; a path of no points; more circles than a sweep may have.
    pub fn new(
        z: &[Real],
        x: &[Real],
        wheel: WheelSection,
        feed: Real,
        rpm: Real,
    ) -> Result<Self, ProfileError> {
        crate::math::positive("feed", feed)?;
        crate::math::positive("spindle speed", rpm)?;
        let (cz, cx, block_of) = super::swept_circles(z, x, wheel.radius, SWEEP_RESOLUTION)?;
        // Times: each circle's place along its move.
        let mut time = Vec::with_capacity(cz.len());
        let mut start = vec![0.0; z.len()];
        for k in 1..z.len() {
            start[k] = start[k - 1] + (z[k] - z[k - 1]).hypot(x[k] - x[k - 1]) / feed;
        }
        for (i, &k) in block_of.iter().enumerate() {
            let t = if k == 0 {
                0.0
            } else {
                start[k - 1] + (cz[i] - z[k - 1]).hypot(cx[i] - x[k - 1]) / feed
            };
            time.push(t);
        }
        Ok(Self {
            swept: CapsuleEnvelope::new(&cz, &cx, wheel.radius, wheel.flat, Side::Outside)?,
            ridge: wheel.ridge(feed / rpm),
            circles: (cz, cx, time),
            wheel,
        })
    }

    /// The ridge's height (mm).
    pub fn ridge(&self) -> Real {
        self.ridge
    }

    /// The valleys at sorted `zs`: the continuous sweep (infinite where the
    /// wheel never reached).
    pub fn valleys(&self, zs: &[Real]) -> Vec<Real> {
        self.swept.eval_many(zs)
    }

    /// The crests at sorted `zs`: the sweep raised by the ridge.
    pub fn crests(&self, zs: &[Real]) -> Vec<Real> {
        self.swept
            .eval_many(zs)
            .into_iter()
            .map(|v| v + self.ridge)
            .collect()
    }

    /// The part of this pass cut by `time` (minutes from its start) near
    /// `[a, b]`: `None` if nothing there yet, the whole layer if all of it.
    ///
    /// # Failures
    /// As [`CapsuleEnvelope::new`].
    pub fn by_time(
        &self,
        time: Real,
        a: Real,
        b: Real,
    ) -> Result<Option<PartLayer<'_>>, ProfileError> {
        let reach = self.wheel.radius + self.wheel.flat / 2.0;
        let (cz, cx, ct) = &self.circles;
        // A pass runs one way along z, and its circles are in its order:
        // the near ones are a run, the placed ones a prefix of the times.
        let up = cz.last() >= cz.first();
        let (lo, hi) = (a - reach, b + reach);
        let near = if up {
            cz.partition_point(|&c| c < lo)..cz.partition_point(|&c| c <= hi)
        } else {
            cz.partition_point(|&c| c > hi)..cz.partition_point(|&c| c >= lo)
        };
        let placed_end = near.start + ct[near.clone()].partition_point(|&t| t <= time);
        let (pz, px) = (&cz[near.start..placed_end], &cx[near.start..placed_end]);
        let near = near.len();
        Ok(if pz.is_empty() {
            None
        } else if pz.len() == near {
            Some(PartLayer::Whole(self))
        } else {
            Some(PartLayer::Part(
                CapsuleEnvelope::new(pz, px, self.wheel.radius, self.wheel.flat, Side::Outside)?,
                self.ridge,
            ))
        })
    }
}

/// A pass's layer, whole or as far as it has cut.
#[derive(Debug, Clone)]
pub enum PartLayer<'a> {
    /// All of it.
    Whole(&'a PassLayer),
    /// The sweep so far, with the pass's ridge.
    Part(CapsuleEnvelope, Real),
}

impl PartLayer<'_> {
    fn crests(&self, zs: &[Real]) -> Vec<Real> {
        match self {
            Self::Whole(l) => l.crests(zs),
            Self::Part(env, ridge) => env.eval_many(zs).into_iter().map(|v| v + ridge).collect(),
        }
    }
}

/// The surface of revolution a steady rest meets on a part being ground:
/// the blank (taken as the polyline through its nodes) lowered by each
/// pass's crests.
#[derive(Debug, Clone)]
pub struct GroundSurface {
    blank: Profile,
    layers: Vec<PassLayer>,
}

impl GroundSurface {
    /// The blank, not yet ground.
    pub fn new(blank: Profile) -> Self {
        Self {
            blank,
            layers: vec![],
        }
    }

    /// The surface after one more pass.
    pub fn with(&self, layer: PassLayer) -> Self {
        let mut s = self.clone();
        s.layers.push(layer);
        s
    }

    /// The blank.
    pub fn blank(&self) -> &Profile {
        &self.blank
    }

    /// The z range (the blank's).
    pub fn z_range(&self) -> (Real, Real) {
        self.blank.z_range()
    }

    /// Each part of the surface at sorted `zs`: the blank, then each layer's
    /// crests, then `extra`'s.
    fn parts(&self, zs: &[Real], extra: Option<&PartLayer<'_>>) -> Vec<Vec<Real>> {
        let mut out = vec![linear(&self.blank, zs)];
        out.extend(self.layers.iter().map(|l| l.crests(zs)));
        out.extend(extra.map(|e| e.crests(zs)));
        out
    }

    /// The surface at sorted `zs` (the blank clamped to its range), lowered
    /// further by `extra` (a pass in progress) if given.
    pub fn eval_many(&self, zs: &[Real], extra: Option<&PartLayer<'_>>) -> Vec<Real> {
        let parts = self.parts(zs, extra);
        (0..zs.len())
            .map(|i| parts.iter().map(|p| p[i]).fold(Real::INFINITY, Real::min))
            .collect()
    }

    /// The surface over `[a, b]` (within the blank's range) as a polyline:
    /// samples `step` apart, every node of the blank in the range, and the
    /// points where one part of the surface takes over from another (found
    /// to 1 nm). Between its points the surface is one arc of the sweep or
    /// one segment of the blank: the polyline lies above it by at most the
    /// arcs' sag, `step^2 / (8 R_s)`, and never below.
    ///
    /// # Failures
    /// An empty range; a step that is not positive.
    pub fn window(
        &self,
        a: Real,
        b: Real,
        step: Real,
        extra: Option<&PartLayer<'_>>,
    ) -> Result<Profile, ProfileError> {
        let (lo, hi) = self.z_range();
        let (a, b) = (a.max(lo), b.min(hi));
        let mut zs = crate::profile::uniform_grid(a, b, step)?;
        let bz = self.blank.z();
        let i0 = bz.partition_point(|&v| v < a);
        let i1 = bz.partition_point(|&v| v <= b);
        zs.extend_from_slice(&bz[i0..i1]);
        zs.sort_by(Real::total_cmp);
        zs.dedup();
        let parts = self.parts(&zs, extra);
        let lowest = |i: usize| {
            (0..parts.len())
                .min_by(|&p, &q| parts[p][i].total_cmp(&parts[q][i]))
                .unwrap_or(0)
        };
        let mut out_z = Vec::with_capacity(zs.len() + 8);
        let mut out_x = Vec::with_capacity(zs.len() + 8);
        for i in 0..zs.len() {
            if i > 0 {
                let (p, q) = (lowest(i - 1), lowest(i));
                if p != q && parts[p][i - 1].is_finite() && parts[q][i].is_finite() {
                    // Where part q takes over from part p: bisection.
                    let (mut l, mut r) = (zs[i - 1], zs[i]);
                    let diff = |z: Real| {
                        let v = self.parts(&[z], extra);
                        v[q][0] - v[p][0]
                    };
                    while r - l > 1e-6 {
                        let m = 0.5 * (l + r);
                        if diff(m) < 0.0 {
                            r = m;
                        } else {
                            l = m;
                        }
                    }
                    let m = 0.5 * (l + r);
                    if m > zs[i - 1] && m < zs[i] {
                        out_z.push(m);
                        out_x.push(self.eval_many(&[m], extra)[0]);
                    }
                }
            }
            out_z.push(zs[i]);
            out_x.push(parts.iter().map(|p| p[i]).fold(Real::INFINITY, Real::min));
        }
        Profile::new(out_z, out_x)
    }
}

/// A profile taken as the polyline through its nodes, at sorted `zs`
/// (clamped to its range).
fn linear(p: &Profile, zs: &[Real]) -> Vec<Real> {
    let (z, x) = (p.z(), p.x());
    let mut k = 1;
    zs.iter()
        .map(|&q| {
            if q <= z[0] {
                return x[0];
            }
            if q >= z[z.len() - 1] {
                return x[x.len() - 1];
            }
            while z[k] < q {
                k += 1;
            }
            let t = (q - z[k - 1]) / (z[k] - z[k - 1]);
            x[k - 1] + t * (x[k] - x[k - 1])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a straight generatrix the ridges between touches `f` apart are
    /// `R - sqrt(R^2 - f^2/4)` high, `f^2 / (8 R)` to first order; the
    /// layer's crests are that high above its valleys.
    #[test]
    fn ridges_between_touches() {
        let (r, rpm, feed) = (20.0, 400.0, 2000.0); // f = 5 mm
        let z = [0.0, 200.0];
        let x = [r, r];
        let t = touches(&z, &x, &[0.0, feed], rpm, 4).unwrap();
        assert_eq!(t.z.len(), 4);
        let f = feed / rpm;
        // Generatrix 0: touches at 0, 5, 10, ...
        assert!((t.z[0][1] - f).abs() < 1e-9 && (t.z[2][0] - f / 2.0).abs() < 1e-9);
        let g = CapsuleEnvelope::new(&t.z[0], &t.x[0], r, 0.0, Side::Outside).unwrap();
        let crest = g.eval(100.0 + f / 2.0);
        let exact = r - (r * r - f * f / 4.0).sqrt();
        assert!((crest - exact).abs() < 1e-12, "{crest} vs {exact}");
        assert!((exact - f * f / (8.0 * r)).abs() < 0.01 * exact);
        // A flat at least as wide as f leaves none.
        let flat = CapsuleEnvelope::new(&t.z[0], &t.x[0], r, 5.0, Side::Outside).unwrap();
        assert!(flat.eval(100.0 + f / 2.0).abs() < 1e-12);
        let w = WheelSection {
            radius: r,
            flat: 0.0,
        };
        let layer = PassLayer::new(&z, &x, w, feed, rpm).unwrap();
        let (v, c) = (layer.valleys(&[100.3])[0], layer.crests(&[100.3])[0]);
        // The continuous sweep within its resolution.
        assert!(
            v.abs() <= 1.01 * SWEEP_RESOLUTION && (c - v - exact).abs() < 1e-12,
            "{v} {c}"
        );
    }

    /// A blank with a step stays a step, and the window follows it.
    #[test]
    fn the_blank_is_a_polyline() {
        let blank = Profile::new(vec![0.0, 10.0, 10.5, 20.0], vec![5.0, 5.0, 5.3, 5.3]).unwrap();
        let s = GroundSurface::new(blank);
        let v = s.eval_many(&[9.0, 10.25, 15.0], None);
        assert_eq!(v, vec![5.0, 5.15, 5.3]);
        let w = s.window(8.0, 12.0, 1.0, None).unwrap();
        assert!(w.z().contains(&10.5));
    }
}
