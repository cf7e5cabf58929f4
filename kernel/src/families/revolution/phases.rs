//! The highest surface a pass can leave, whatever the spindle's phase.
//!
//! A wheel's reference moves along a pass's path in time (straight moves
//! at their feeds, the control's linear interpolation) while the part turns
//! once every `T = 1/rpm` minutes. A generatrix at phase `phi` meets the
//! wheel at the times `(j + phi) T`; between them the wheel's section
//! leaves a ridge. Which phase a generatrix has is not in the program (the
//! spindle turns between passes), so what a steady rest riding the part
//! meets is the highest of them:
//!
//! `crest(z) = sup over phi of min over j of H_z((j + phi) T)`,
//!
//! with `H_z(t)` the height of the wheel's true section (flat and
//! roundings) above the axis at `z` when its reference is at the path's
//! point of time `t` (infinite where the section does not reach `z`).
//! Where the wheel passes over `z` once, `H_z` falls and rises again
//! (quasi-convex): only the two touches either side of its lowest point
//! count, and the highest phase puts them where `H_z(t) = H_z(t + T)`, found
//! by bisection. Where the wheel covers `z` for less than a revolution,
//! some phase it never touches: the pass leaves it uncut (infinite).
//!
//! The grinding replay cuts the same section at the same moments on
//! [`super::surface::GENERATRICES`] phases ([`super::surface::touches`]);
//! the crest is the limit of its highest generatrix as the phases fill in.

use super::surface::WheelSection;
use crate::input::InputError;
use crate::math::Real;
use crate::profile::ProfileError;

/// How far (mm) the wheel may move in the time left to a crossing and the
/// crossing count as found: a nanometre.
const SETTLED: Real = 1e-6;

/// A wheel reference's path in time: points `(z, x)` and the time (minutes
/// from the first point) it reaches each, moving along straight moves at
/// their feeds.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPath {
    z: Vec<Real>,
    x: Vec<Real>,
    time: Vec<Real>,
    /// The fastest it moves (mm/min).
    top_speed: Real,
    /// How many points before the path's own are where its infeed started
    /// (0 or 1).
    lead: usize,
}

/// How a wheel came to a pass's first point: from `(z, x)` in a straight
/// move at `feed` mm/min (the program's infeed block). While it comes down
/// the part turns, so the last revolution of the infeed leaves each
/// generatrix a little higher than the pass's first point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Infeed {
    /// Where the infeed starts: z (mm).
    pub z: Real,
    /// Where the infeed starts: x (mm).
    pub x: Real,
    /// The infeed's feed (mm/min).
    pub feed: Real,
}

impl TimedPath {
    /// The path through `(z[k], x[k])`, move `k` (from point `k-1`) at
    /// `feed[k]` mm/min (`feed[0]` unused).
    ///
    /// # Failures
    /// Arrays of different lengths or empty; a feed that is not positive
    /// and finite.
    pub fn new(z: &[Real], x: &[Real], feed: &[Real]) -> Result<Self, ProfileError> {
        if z.len() != x.len() || z.len() != feed.len() || z.is_empty() {
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
        let top_speed = feed.iter().skip(1).copied().fold(0.0, Real::max);
        Ok(Self {
            z: z.to_vec(),
            x: x.to_vec(),
            time,
            top_speed,
            lead: 0,
        })
    }

    /// The path as [`Self::new`], entered by `infeed` if given: its move
    /// comes first, and times count from where the infeed started.
    ///
    /// # Failures
    /// As [`Self::new`]; an infeed start that is not finite or a feed that
    /// is not positive.
    pub fn entered(
        infeed: Option<Infeed>,
        z: &[Real],
        x: &[Real],
        feed: &[Real],
    ) -> Result<Self, ProfileError> {
        let Some(i) = infeed else {
            return Self::new(z, x, feed);
        };
        crate::math::finite("infeed start z", i.z)?;
        crate::math::finite("infeed start x", i.x)?;
        let mut path = Self::new(
            &[&[i.z], z].concat(),
            &[&[i.x], x].concat(),
            &[&[0.0, i.feed], feed.get(1..).unwrap_or_default()].concat(),
        )?;
        path.lead = 1;
        Ok(path)
    }

    /// The path at one feed.
    ///
    /// # Failures
    /// As [`Self::new`].
    pub fn at_feed(z: &[Real], x: &[Real], feed: Real) -> Result<Self, ProfileError> {
        Self::new(z, x, &vec![feed; z.len()])
    }

    /// The time at each point (minutes from the first).
    pub fn times(&self) -> &[Real] {
        &self.time[self.lead..]
    }

    /// The points' z.
    pub fn z(&self) -> &[Real] {
        &self.z[self.lead..]
    }

    /// The points' x.
    pub fn x(&self) -> &[Real] {
        &self.x[self.lead..]
    }

    /// How long the path takes (minutes).
    pub fn duration(&self) -> Real {
        self.time[self.time.len() - 1]
    }

    /// The reference at time `t` (clamped to the path's), and the move of
    /// the path's own it is on (from 1; 0 on the infeed, or at the first
    /// point of a one-point path).
    pub fn at(&self, t: Real) -> (Real, Real, usize) {
        let n = self.time.len();
        if n == 1 {
            return (self.z[0], self.x[0], 0);
        }
        let k = self.time.partition_point(|&v| v < t).clamp(1, n - 1);
        let (t0, t1) = (self.time[k - 1], self.time[k]);
        let s = if t1 > t0 {
            ((t - t0) / (t1 - t0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        (
            self.z[k - 1] + s * (self.z[k] - self.z[k - 1]),
            self.x[k - 1] + s * (self.x[k] - self.x[k - 1]),
            k.saturating_sub(self.lead),
        )
    }

    /// The path's own point (from 0) nearest in time to `t`: the block
    /// whose written position the reference is nearest then (a touch just
    /// after a corner is the corner's block's, whose words place it).
    pub fn nearest_point(&self, t: Real) -> usize {
        let own = &self.time[self.lead..];
        let k = own.partition_point(|&v| v < t);
        match k {
            0 => 0,
            k if k >= own.len() => own.len() - 1,
            k if t - own[k - 1] < own[k] - t => k - 1,
            k => k,
        }
    }

    /// The first and last times the reference is within `reach` of `z`
    /// along z, if ever.
    fn coverage(&self, z: Real, reach: Real) -> Option<(Real, Real)> {
        let n = self.z.len();
        if n == 1 {
            return ((self.z[0] - z).abs() <= reach).then_some((0.0, 0.0));
        }
        // On move k the times within reach: an interval of its parameter.
        let within = |k: usize| -> Option<(Real, Real)> {
            let (z0, z1) = (self.z[k - 1], self.z[k]);
            let (t0, t1) = (self.time[k - 1], self.time[k]);
            let (mut a, mut b) = if z1 == z0 {
                if (z0 - z).abs() > reach {
                    return None;
                }
                (0.0, 1.0)
            } else {
                let p = (z - reach - z0) / (z1 - z0);
                let q = (z + reach - z0) / (z1 - z0);
                (p.min(q), p.max(q))
            };
            (a, b) = (a.max(0.0), b.min(1.0));
            (a <= b).then_some((t0 + a * (t1 - t0), t0 + b * (t1 - t0)))
        };
        let first = (1..n).find_map(within)?;
        let last = (1..n).rev().find_map(within)?;
        Some((first.0, last.1))
    }
}

impl WheelSection {
    /// How far each point's reach (the rounding and half the flat) extends
    /// along z from the reference.
    pub fn reach(&self) -> Real {
        self.radius + 0.5 * self.flat
    }

    /// The height above the axis of the section's lower edge at `dz` along
    /// z from its reference standing at `x` (infinite beyond its reach).
    pub fn height(&self, dz: Real, x: Real) -> Real {
        let d = (dz.abs() - 0.5 * self.flat).max(0.0);
        if d > self.radius {
            return Real::INFINITY;
        }
        x - (self.radius * self.radius - d * d).sqrt()
    }
}

/// The highest surface (over spindle phases) at `z` that `wheel` leaves
/// moving along `path` while the part turns once every `period` minutes,
/// counting only the moments up to `until` (minutes from the path's
/// start; infinite: all of it). Infinite where some phase is never touched.
/// A path without its infeed ([`TimedPath::entered`]) is taken to have
/// stood a revolution at its first point (how the wheel came there is not
/// said; a pass's infeed takes at least that at a grinding infeed feed).
pub fn crest_at(path: &TimedPath, wheel: WheelSection, period: Real, z: Real, until: Real) -> Real {
    let covered = path.coverage(z, wheel.reach());
    crest_covered(path, wheel, period, z, until, covered)
}

/// [`crest_at`], the first and last times the wheel reaches `z` given.
fn crest_covered(
    path: &TimedPath,
    wheel: WheelSection,
    period: Real,
    z: Real,
    until: Real,
    covered: Option<(Real, Real)>,
) -> Real {
    let end = path.duration().min(until);
    let Some((t_in, t_out)) = covered else {
        return Real::INFINITY;
    };
    let t_in = if t_in <= 0.0 && path.lead == 0 {
        -period
    } else {
        t_in
    };
    let t_out = t_out.min(end);
    if t_out - t_in < period {
        return Real::INFINITY;
    }
    let h = |t: Real| {
        if t < t_in || t > t_out {
            Real::INFINITY
        } else {
            let (zc, xc, _) = path.at(t.max(0.0));
            wheel.height(z - zc, xc)
        }
    };
    // h(t) > h(t + T) before the crossing, < after it: found until the
    // wheel moves less than a nanometre in the time left.
    let speed = path.top_speed;
    let (mut lo, mut hi) = (t_in - period, t_out);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi || (hi - lo) * speed < SETTLED {
            break;
        }
        if h(mid) > h(mid + period) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    h(lo).min(h(lo + period)).max(h(hi).min(h(hi + period)))
}

/// The spacing of a [`PhaseCrest`]'s grid (mm).
pub const CREST_STEP: Real = 0.1;

/// How far a straight line between a [`PhaseCrest`]'s grid points may stand
/// off the crest (mm, estimated from its second differences); a cell where
/// it could stand further (where a pass begins or ends, or the feed or the
/// path bends the ridges' pattern) gets points between its ends until it
/// holds.
pub const CREST_LINEAR_ERROR: Real = 1e-4;

/// The most grid points a [`PhaseCrest`] may have.
pub const MAX_CREST_POINTS: usize = 5_000_000;

/// A pass's [`crest_at`] on an even grid over its reach, with the first
/// and last times the wheel covers each grid point (for a pass still in
/// progress).
#[derive(Debug, Clone)]
pub struct PhaseCrest {
    path: TimedPath,
    wheel: WheelSection,
    period: Real,
    z0: Real,
    crest: Vec<Real>,
    last_touch: Vec<Real>,
    first_touch: Vec<Real>,
    /// Cells (from grid point i to i + 1) where the line is not within
    /// [`CREST_LINEAR_ERROR`]: the crest at points evenly between their
    /// ends (ends excluded), fine enough that it is; empty for the others.
    refined: Vec<Vec<Real>>,
}

impl PhaseCrest {
    /// The crest of `wheel` along `path` with the part turning at `rpm`.
    ///
    /// # Failures
    /// A speed that is not positive; a pass so long its grid would pass
    /// [`MAX_CREST_POINTS`].
    pub fn new(path: TimedPath, wheel: WheelSection, rpm: Real) -> Result<Self, ProfileError> {
        crate::math::positive("spindle speed", rpm)?;
        let reach = wheel.reach();
        let lo = path.z.iter().copied().fold(Real::INFINITY, Real::min) - reach;
        let hi = path.z.iter().copied().fold(Real::NEG_INFINITY, Real::max) + reach;
        let n = ((hi - lo) / CREST_STEP).ceil() + 1.0;
        if !(n <= MAX_CREST_POINTS as Real) {
            return Err(InputError::out_of_range(
                "points of a pass's crest",
                n,
                format!("at most {MAX_CREST_POINTS}: a pass this long"),
            )
            .into());
        }
        let period = 1.0 / rpm;
        let n = n as usize;
        let mut crest = Vec::with_capacity(n);
        let mut first_touch = Vec::with_capacity(n);
        let mut last_touch = Vec::with_capacity(n);
        for i in 0..n {
            let z = lo + i as Real * CREST_STEP;
            let covered = path.coverage(z, reach);
            crest.push(crest_covered(
                &path,
                wheel,
                period,
                z,
                Real::INFINITY,
                covered,
            ));
            let (a, b) = covered.unwrap_or((Real::INFINITY, Real::INFINITY));
            first_touch.push(a);
            last_touch.push(b);
        }
        // A line through two grid points is off the curve by about an
        // eighth of the second difference at either end.
        let second = |i: usize| {
            if i == 0 || i + 1 >= n {
                return 0.0;
            }
            let d = crest[i - 1] - 2.0 * crest[i] + crest[i + 1];
            if d.is_nan() {
                Real::INFINITY
            } else {
                d.abs()
            }
        };
        let refined = (0..n)
            .map(|i| {
                let d = second(i).max(second(i + 1));
                if d / 8.0 <= CREST_LINEAR_ERROR
                    || i + 1 >= n
                    || !(crest[i].is_finite() && crest[i + 1].is_finite())
                {
                    return Vec::new();
                }
                // A line over 1/m of the cell is off by 1/m^2 as much.
                let m = ((d / (8.0 * CREST_LINEAR_ERROR)).sqrt().ceil() as usize).clamp(2, 256);
                let z = lo + i as Real * CREST_STEP;
                (1..m)
                    .map(|k| {
                        let zk = z + k as Real * CREST_STEP / m as Real;
                        crest_at(&path, wheel, period, zk, Real::INFINITY)
                    })
                    .collect()
            })
            .collect();
        Ok(Self {
            path,
            wheel,
            period,
            z0: lo,
            crest,
            last_touch,
            first_touch,
            refined,
        })
    }

    /// The path it was made of.
    pub fn path(&self) -> &TimedPath {
        &self.path
    }

    /// The crest at `z`, counting the moments up to `until` (minutes from
    /// the pass's start): the grid's line (within [`CREST_LINEAR_ERROR`])
    /// where the wheel has left both neighbouring points, computed there
    /// where it has not or where the cut begins between them.
    pub fn eval(&self, z: Real, until: Real) -> Real {
        let u = (z - self.z0) / CREST_STEP;
        if !(u >= 0.0) || u > (self.crest.len() - 1) as Real {
            return Real::INFINITY;
        }
        let i = (u.floor() as usize).min(self.crest.len().saturating_sub(2));
        let j = (i + 1).min(self.crest.len() - 1);
        if self.first_touch[i].min(self.first_touch[j]) > until {
            return Real::INFINITY;
        }
        let (a, b) = (self.crest[i], self.crest[j]);
        if self.last_touch[i].max(self.last_touch[j]) > until || a.is_finite() != b.is_finite() {
            // The wheel still on it, or where a pass's cut begins.
            return crest_at(&self.path, self.wheel, self.period, z, until);
        }
        if !a.is_finite() {
            return Real::INFINITY;
        }
        let s = u - i as Real;
        let fine = &self.refined[i];
        if fine.is_empty() {
            return a + s * (b - a);
        }
        // The cell's own finer points, its ends around them.
        let m = fine.len() + 1;
        let v = s * m as Real;
        let k = (v.floor() as usize).min(m - 1);
        let at = |q: usize| match q {
            0 => a,
            q if q == m => b,
            q => fine[q - 1],
        };
        at(k) + (v - k as Real) * (at(k + 1) - at(k))
    }

    /// [`Self::eval`] at each of `zs`.
    pub fn eval_many(&self, zs: &[Real], until: Real) -> Vec<Real> {
        zs.iter().map(|&z| self.eval(z, until)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a straight generatrix the crest over phases is the ridge of the
    /// section: the rounding's `R - sqrt(R^2 - (f/2)^2)` without a flat,
    /// `R - sqrt(R^2 - ((f - w)/2)^2)` with a flat `w` narrower than `f`,
    /// none with one wider.
    #[test]
    fn the_crest_of_a_straight_pass_is_the_sections_ridge() {
        let (r, rpm, feed) = (20.0, 400.0, 2000.0); // f = 5 mm
        let f: Real = feed / rpm;
        let path = TimedPath::at_feed(&[0.0, 200.0], &[r, r], feed).unwrap();
        for (flat, ridge) in [
            (0.0, r - (r * r - f * f / 4.0).sqrt()),
            (3.0, r - (r * r - 1.0).sqrt()),
            (6.0, 0.0),
        ] {
            let w = WheelSection { radius: r, flat };
            let c = PhaseCrest::new(path.clone(), w, rpm).unwrap();
            for z in [50.0, 100.013, 150.7] {
                let v = c.eval(z, Real::INFINITY);
                assert!(
                    (v - ridge).abs() < 1e-9,
                    "flat {flat} z {z}: {v} vs {ridge}"
                );
                let exact = crest_at(&path, w, 1.0 / rpm, z, Real::INFINITY);
                assert!((exact - ridge).abs() < 1e-9, "{exact} vs {ridge}");
            }
            // Not yet reached, or reached for less than a revolution.
            let t = 100.0 / feed;
            assert!(c.eval(150.0, t).is_infinite());
            assert!(c.eval(100.0 + r - 0.5, t).is_infinite());
            assert!((c.eval(50.0, t) - ridge).abs() < 1e-9);
        }
    }

    /// The replay's generatrices never stand above the crest, and their
    /// highest comes within the phase sampling's error of it.
    #[test]
    fn the_generatrices_lie_under_the_crest() {
        let (r, rpm) = (8.0, 300.0);
        // A slope, a bend and two feeds.
        let z = [0.0, 40.0, 80.0, 120.0];
        let x = [30.0, 29.0, 27.0, 27.0];
        let feeds = [0.0, 900.0, 900.0, 1500.0];
        // Entered from 0.2 mm above, 5 um a revolution.
        let infeed = Infeed {
            z: 0.0,
            x: 30.2,
            feed: 1.5,
        };
        let path = TimedPath::entered(Some(infeed), &z, &x, &feeds).unwrap();
        let w = WheelSection {
            radius: r,
            flat: 1.5,
        };
        let c = PhaseCrest::new(path.clone(), w, rpm).unwrap();
        let m = 64;
        let t = super::super::surface::touches(&path, rpm, m).unwrap();
        let envs: Vec<_> = (0..m)
            .map(|g| {
                crate::offset::CapsuleEnvelope::new(
                    &t.z[g],
                    &t.x[g],
                    r,
                    1.5,
                    crate::offset::Side::Outside,
                )
                .unwrap()
            })
            .collect();
        let mut worst: Real = 0.0;
        for i in 0..2000 {
            let zz = 10.0 + i as Real * 0.05;
            let crest = c.eval(zz, Real::INFINITY);
            let highest = envs.iter().map(|e| e.eval(zz)).fold(Real::MIN, Real::max);
            assert!(highest <= crest + 1e-6, "z {zz}: {highest} above {crest}");
            worst = worst.max(crest - highest);
        }
        // m phases stand within about 2h/m of the crest of a ridge h high
        // (h(1 - (1 - 1/m)^2) on a straight generatrix): the fastest move
        // (f = 5 mm) leaves the highest ridge.
        let h = 8.0 - (64.0 - (5.0 - 1.5) * (5.0 - 1.5) / 4.0 as Real).sqrt();
        assert!(
            worst > 0.0 && worst < 4.0 * h / m as Real,
            "{worst} vs h {h}"
        );
    }

    /// A wheel that came down onto a pass's first point while the part
    /// turned leaves each generatrix where the infeed's last revolution met
    /// it: up to a revolution's infeed higher there than a wheel that stood
    /// at the point, the same a wheel's width further on.
    #[test]
    fn the_infeeds_last_revolution_stands_at_the_first_point() {
        let (r, rpm, feed) = (20.0, 400.0, 1200.0); // 3 mm a revolution
        let (z, x) = ([0.0, 200.0], [r, r]);
        let w = WheelSection {
            radius: r,
            flat: 0.0,
        };
        let stood = TimedPath::at_feed(&z, &x, feed).unwrap();
        let infeed = Infeed {
            z: 0.0,
            x: r + 0.1,
            feed: 2.0, // 5 um a revolution
        };
        let entered = TimedPath::entered(Some(infeed), &z, &x, &[0.0, feed]).unwrap();
        assert_eq!(entered.times().len(), 2);
        assert!((entered.times()[0] - 0.1 / 2.0).abs() < 1e-12);
        let crest = |p: &TimedPath, z: Real| crest_at(p, w, 1.0 / rpm, z, Real::INFINITY);
        let (a, b) = (crest(&stood, 0.0), crest(&entered, 0.0));
        let per_rev = 2.0 / rpm;
        assert!(b > a + 0.5 * per_rev && b < a + per_rev, "{a} {b}");
        let ridge = w.ridge(feed / rpm);
        for q in [50.0, 120.0] {
            assert!((crest(&stood, q) - ridge).abs() < 1e-9);
            assert!((crest(&entered, q) - ridge).abs() < 1e-9);
        }
    }
}
