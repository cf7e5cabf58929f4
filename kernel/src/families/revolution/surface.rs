//! The surface of a part being ground, as the machine makes it (docs/math.md §2.4):
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
//!   highest surface any spindle phase leaves ([`super::phases`]), what a
//!   steady rest's support riding the turning part meets. The verification
//!   cuts the same section at the same moments on each generatrix
//!   ([`crate::families::revolution::check_grinding`]) and reports how far the crest
//!   stands above its own highest generatrix.
//! - [`GroundSurface`] is the blank (a polyline: a step stays a step)
//!   lowered by each pass's crest.
//!
//! # Generatrices
//! The replay starts from 16 generatrices and doubles them until the
//! finish's worst moves by less than 0.1 um from every other one to all
//! ([`crate::families::revolution::replay_grinding`]); [`GENERATRICES`] = 8 is the
//! half it first compares with. On a straight generatrix the ridge
//! pattern is the same on every one, shifted by `f/m` along the part: the
//! highest of `m` is within `h (1 - (1 - 1/m)^2) < 2 h / m` of the true
//! crest `h`, and the lowest of them reaches the valleys (the touches
//! themselves); where the path turns or its feed changes the pattern
//! shifts, which the doubling measures.

use super::phases::{Infeed, PhaseCrest, TimedPath};
use crate::math::Real;
use crate::profile::{Profile, ProfileError};

/// The z (mm) where one part of the surface takes over from another is
/// found to a nanometre.
const TAKEOVER: Real = 1e-6;

/// The fewest generatrices a pass is compared on: the replay simulates
/// twice as many and doubles from there.
pub const GENERATRICES: usize = 8;

/// The wheel's reference at the moments each generatrix passes under it.
#[derive(Debug, Clone, PartialEq)]
pub struct Touches {
    /// For each generatrix: the touches' z.
    pub z: Vec<Vec<Real>>,
    /// For each generatrix: the touches' x.
    pub x: Vec<Vec<Real>>,
    /// For each generatrix and touch: the path's point (from 0) nearest in
    /// time to it, whose block's words place the wheel there (a touch just
    /// past a corner is the corner's: the block to edit).
    pub block: Vec<Vec<usize>>,
    /// The time at each point of the path (minutes from the pass's start).
    pub time: Vec<Real>,
}

/// The most touches a pass may have, over all its generatrices.
pub const MAX_TOUCHES: usize = 50_000_000;

/// Where `m` generatrices meet a wheel whose reference moves along `path`
/// (its infeed included, if it has one) while the part turns at `rpm`:
/// generatrix `g` passes under the wheel at the times `(g/m + j) / rpm`
/// minutes after the path's start.
///
/// # Failures
/// A speed that is not positive and finite; no generatrices; more than
/// [`MAX_TOUCHES`] touches.
pub fn touches(path: &TimedPath, rpm: Real, m: usize) -> Result<Touches, ProfileError> {
    crate::math::positive("spindle speed", rpm)?;
    if m == 0 {
        return Err(crate::input::InputError::TooFew {
            what: "generatrices".into(),
            got: 0,
            min: 1,
        }
        .into());
    }
    let total = path.duration();
    let expected = total * rpm * m as Real;
    if !(expected <= MAX_TOUCHES as Real) {
        return Err(crate::input::InputError::out_of_range(
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
        time: path.times().to_vec(),
    };
    for g in 0..m {
        let mut j = 0usize;
        loop {
            let t = (g as Real / m as Real + j as Real) / rpm;
            if t > total {
                break;
            }
            let (zz, xx, _) = path.at(t);
            out.z[g].push(zz);
            out.x[g].push(xx);
            out.block[g].push(path.nearest_point(t));
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

/// What one pass leaves, as a surface of revolution: the highest surface
/// any spindle phase leaves ([`PhaseCrest`]: the same section at the same
/// moments as the replay's generatrices, over every phase), what a steady
/// rest's support riding the turning part meets.
#[derive(Debug, Clone)]
pub struct PassLayer {
    crest: PhaseCrest,
}

impl PassLayer {
    /// The layer of `wheel` moved along `(z[k], x[k])` at `feed` mm/min,
    /// entered by `infeed` (without one, the wheel stood a revolution at the
    /// first point), while the part turns at `rpm`.
    ///
    /// # Failures
    /// Bad numbers; a path of no points; a pass too long for its crest's
    /// grid.
    pub fn new(
        z: &[Real],
        x: &[Real],
        wheel: WheelSection,
        feed: Real,
        infeed: Option<Infeed>,
        rpm: Real,
    ) -> Result<Self, ProfileError> {
        crate::math::positive("feed", feed)?;
        let path = TimedPath::entered(infeed, z, x, &vec![feed; z.len()])?;
        Self::timed(path, wheel, rpm)
    }

    /// The layer of `wheel` moved along `path` (each move at its feed)
    /// while the part turns at `rpm`.
    ///
    /// # Failures
    /// As [`Self::new`].
    pub fn timed(path: TimedPath, wheel: WheelSection, rpm: Real) -> Result<Self, ProfileError> {
        Ok(Self {
            crest: PhaseCrest::new(path, wheel, rpm)?,
        })
    }

    /// The path and its times.
    pub fn path(&self) -> &TimedPath {
        self.crest.path()
    }

    /// The crests at `zs`: the highest surface over spindle phases
    /// (infinite where some phase is never touched).
    pub fn crests(&self, zs: &[Real]) -> Vec<Real> {
        self.crest.eval_many(zs, Real::INFINITY)
    }

    /// The part of this pass cut by `time` (minutes from its start): the
    /// crests counting the wheel's moments up to then.
    pub fn by_time(&self, time: Real) -> PartLayer<'_> {
        if time >= self.path().duration() {
            PartLayer::Whole(self)
        } else {
            PartLayer::Until(self, time)
        }
    }
}

/// A pass's layer, whole or as far as it has cut.
#[derive(Debug, Clone, Copy)]
pub enum PartLayer<'a> {
    /// All of it.
    Whole(&'a PassLayer),
    /// What it has cut by a time (minutes from its start).
    Until(&'a PassLayer, Real),
}

impl PartLayer<'_> {
    fn crests(&self, zs: &[Real]) -> Vec<Real> {
        match *self {
            Self::Whole(l) => l.crests(zs),
            Self::Until(l, t) => l.crest.eval_many(zs, t),
        }
    }
}

/// The surface of revolution a steady rest meets on a part being ground:
/// the blank (taken as the polyline through its nodes) lowered by each
/// pass's crests.
#[derive(Debug, Clone)]
pub struct GroundSurface {
    blank: Profile,
    /// Shared: a surface after one more pass keeps the ones before.
    layers: Vec<std::sync::Arc<PassLayer>>,
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
        s.layers.push(std::sync::Arc::new(layer));
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

    /// Pass `i`'s layer (from 0).
    pub fn layer(&self, i: usize) -> Option<&PassLayer> {
        self.layers.get(i).map(|l| l.as_ref())
    }

    /// The lowest of the passes' crests at `zs`, without the blank
    /// (infinite where no pass has cut).
    pub fn cut_many(&self, zs: &[Real]) -> Vec<Real> {
        let mut out = vec![Real::INFINITY; zs.len()];
        for l in &self.layers {
            for (o, c) in out.iter_mut().zip(l.crests(zs)) {
                *o = o.min(c);
            }
        }
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

    /// Where a circle of `radius` in the axial section, its centre over
    /// `z`, comes to rest on the surface (lowered further by `extra`):
    /// dropped on [`Self::window`] of its width at `step`; `None` where no
    /// part of the surface lies under it.
    ///
    /// # Failures
    /// A step or radius that is not positive.
    pub fn support(
        &self,
        z: Real,
        radius: Real,
        step: Real,
        extra: Option<&PartLayer<'_>>,
    ) -> Result<Option<crate::offset::Drop>, ProfileError> {
        let (lo, hi) = self.z_range();
        let (a, b) = ((z - radius).max(lo), (z + radius).min(hi));
        if a >= b {
            return Ok(None);
        }
        let window = self.window(a, b, step, extra)?;
        crate::offset::drop_circle(&window, z, radius, crate::offset::Side::Outside).map(Some)
    }

    /// The surface over `[a, b]` (within the blank's range) as a polyline:
    /// samples `step` apart, every node of the blank in the range, and the
    /// points where one part of the surface takes over from another (found
    /// to 1 nm). Between its points the surface is one segment of the blank
    /// or one part of a pass's crest; the crest is flat along a steady
    /// pass, and where it bends between two samples (a pass's first
    /// millimetres, after its infeed's last revolution) the polyline cuts
    /// the bend's corner: by a few tenths of a micron at `step` = 0.05 mm
    /// on the mandrel's infeeds (`tests/mandrel_fidelity.rs`).
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
                    while r - l > TAKEOVER {
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
    use crate::offset::{CapsuleEnvelope, Side};

    /// On a straight generatrix the ridges between touches `f` apart are
    /// `R - sqrt(R^2 - f^2/4)` high, `f^2 / (8 R)` to first order; the
    /// layer's crests are that high above its valleys.
    #[test]
    fn ridges_between_touches() {
        let (r, rpm, feed) = (20.0, 400.0, 2000.0); // f = 5 mm
        let z = [0.0, 200.0];
        let x = [r, r];
        let t = touches(&TimedPath::new(&z, &x, &[0.0, feed]).unwrap(), rpm, 4).unwrap();
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
        let layer = PassLayer::new(&z, &x, w, feed, None, rpm).unwrap();
        let c = layer.crests(&[100.3])[0];
        // The continuous sweep (the valleys) within its circles' scallops.
        let resolution = 1e-5;
        let (cz, cx, _) = crate::offset::swept_circles(&z, &x, r, resolution).unwrap();
        let swept = CapsuleEnvelope::new(&cz, &cx, r, 0.0, Side::Outside).unwrap();
        let v = swept.eval(100.3);
        assert!(
            v.abs() <= 1.01 * resolution && (c - exact).abs() < 1e-9,
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
