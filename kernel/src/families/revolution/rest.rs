//! The CNC steady rest (axis U) riding the current surface (docs/math.md §2.3).
//!
//! The rest's support is a circle of radius `R_o` in the axial section,
//! its centre at `z_r = z_k + B`. Two models give the centre's x:
//! - [`seed_u`], the seed's first-order formula (S000-3..10): the circle
//!   tangent to the chord of the surface array at the first node past z_r;
//! - [`exact_u`], the exact drop of the circle onto the surface.
//!
//! # How far apart they are
//! Let the surface `s(z)` have `|s''| <= K` and `|sin(slope angle)| <= S`
//! near `z_r`, and node spacing `h`. The seed's `u` is the exact drop onto
//! the chord line `L` through `z_3` and the next node. A circle resting on a
//! line or a smooth curve touches it where the normal passes through its
//! centre, within `R_o S` of `z_r`; there `|s - L| <= K (R_o S + h)(R_o S + 2h) / 2`
//! (linear interpolation error), and the sampled surface is within `K h^2 / 8`
//! of `s`. Since the drop onto `s` is at least the value of `s + circle` at the
//! line's contact and at most `L + circle` plus `s - L` at its own contact,
//!
//! `|seed_u - exact_u| <= K (R_o S + h)(R_o S + 2h) / 2 + K h^2 / 8`
//! ([`seed_error_bound`]),
//!
//! the O(R_o^2 s'') of docs/math.md §2.3. On a ground surface with a cusp or a step
//! (the edge of the current pass) the seed's model has no such bound: that
//! is why the exact model is the default.

use super::phases::Infeed;
pub use super::surface::WheelSection;
use super::surface::{GroundSurface, PassLayer};
use crate::math::{finite, positive, Real};
use crate::offset::{drop_circle, Drop, Side};
use crate::profile::{Polyline, Profile, ProfileError};
use serde::{Deserialize, Serialize};

/// Which model of the rest to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RestModel {
    /// The exact drop onto the current surface (default).
    #[default]
    Exact,
    /// The seed's first-order formula.
    Seed,
}

impl RestModel {
    /// The rest centre's x at `z_r` on `surface` under this model.
    pub fn u(self, surface: &Profile, z_r: Real, r_o: Real) -> Result<Real, ProfileError> {
        match self {
            RestModel::Exact => Ok(exact_u(surface, z_r, r_o)?.centre_x),
            RestModel::Seed => seed_u(surface, z_r, r_o),
        }
    }
}

/// The seed's rest model: with `z_3` the first node at or past `z_r` and
/// `alpha` the angle of the chord from it to the next node,
/// `u = x_3 + R_o / cos(alpha) + (z_r - z_3) tan(alpha)`.
///
/// # Failures
/// A non-positive `R_o`; `z_r` outside the surface's range.
///
/// ```
/// use pilgrim_kernel::families::revolution::rest;
/// use pilgrim_kernel::Profile;
/// let cone = Profile::new(vec![0.0, 10.0, 20.0], vec![10.0, 11.0, 12.0]).unwrap();
/// let u = rest::seed_u(&cone, 5.0, 3.0).unwrap();
/// assert!((u - (10.5 + 3.0 * (1.0_f64 + 0.01).sqrt())).abs() < 1e-12);
/// ```
pub fn seed_u(surface: &Profile, z_r: Real, r_o: Real) -> Result<Real, ProfileError> {
    positive("rest support radius R_o", r_o)?;
    finite("rest position z_r", z_r)?;
    let (z, x) = (surface.z(), surface.x());
    let (lo, hi) = surface.z_range();
    if !(lo..=hi).contains(&z_r) {
        return Err(ProfileError::OutsideProfile {
            what: "the steady rest".into(),
            z: z_r,
            z_min: lo,
            z_max: hi,
        });
    }
    let i3 = z.partition_point(|&v| v < z_r);
    let i = i3.min(z.len() - 2);
    let tan_a = (x[i + 1] - x[i]) / (z[i + 1] - z[i]);
    Ok(x[i3] + r_o * (1.0 + tan_a * tan_a).sqrt() + (z_r - z[i3]) * tan_a)
}

/// The exact rest model: the lowest position of the support circle over
/// the surface, `max over |z - z_r| <= R_o of s(z) + sqrt(R_o^2 - (z - z_r)^2)`.
///
/// # Failures
/// As [`drop_circle`].
pub fn exact_u(surface: &Profile, z_r: Real, r_o: Real) -> Result<Drop, ProfileError> {
    drop_circle(surface, z_r, r_o, Side::Outside)
}

/// The bound `K (R_o S + h)(R_o S + 2h) / 2 + K h^2 / 8` on
/// `|seed_u - exact_u|` for a surface with `|s''| <= max_curvature` (K),
/// `|sin(slope angle)| <= max_sin_slope` (S) over the support's reach, and
/// node spacing at most `h` (see the [module docs](self)).
pub fn seed_error_bound(max_curvature: Real, max_sin_slope: Real, h: Real, r_o: Real) -> Real {
    let k = max_curvature.abs();
    let reach = r_o * max_sin_slope.abs().min(1.0);
    0.5 * k * (reach + h) * (reach + 2.0 * h) + 0.125 * k * h * h
}

/// The steady rest along one pass: the pass's path with the blocks the
/// rest needs added; at each block the support's centre x on the current
/// surface (the exact drop), the contact point, and the seed's formula on
/// the same surface; and how far the control's straight line of U between
/// blocks stands off the surface or presses into it.
#[derive(Debug, Clone, PartialEq)]
pub struct RestTrack {
    /// The wheel's path: the pass's points and, on its moves, the points
    /// added for the rest (same line, same feed).
    pub path: Polyline,
    /// The support centre's x at each point of the path (exact model).
    pub centre_x: Vec<Real>,
    /// The contact point's z at each point.
    pub contact_z: Vec<Real>,
    /// The contact point's x at each point.
    pub contact_x: Vec<Real>,
    /// The support centre's x by the seed's formula at each point.
    pub seed_centre_x: Vec<Real>,
    /// The largest |seed - exact| over the pass (mm).
    pub max_model_difference: Real,
    /// The point where it is (from 0).
    pub max_difference_block: usize,
    /// The largest amount U, moving in a straight line between points,
    /// stands off the surface (above the exact drop, mm, >= 0).
    pub max_gap: Real,
    /// The largest amount it presses into the surface (mm, >= 0).
    pub max_press: Real,
    /// Points the rest added to the pass.
    pub added: usize,
    /// Where U's straight line between blocks stands: at each place it was
    /// checked, the support centre's z (`z + B`) and the line's x minus the
    /// exact drop's (mm; + off the surface, - into it), blocks included (0).
    pub stand_off: Vec<[Real; 2]>,
}

impl RestTrack {
    /// The stand-off on a grid of z (increasing, evenly spaced): at each
    /// grid point the checked value of largest size within half a step;
    /// where none lies that close, the straight line between the nearest
    /// checks either side; 0 beyond the pass's reach.
    pub fn stand_off_on(&self, grid: &[Real]) -> Vec<Real> {
        let mut s = self.stand_off.clone();
        s.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let n = grid.len();
        if n == 0 || s.is_empty() {
            return vec![0.0; n];
        }
        let half = if n > 1 {
            0.5 * (grid[1] - grid[0])
        } else {
            Real::INFINITY
        };
        grid.iter()
            .map(|&z| {
                let from = s.partition_point(|p| p[0] < z - half);
                let to = s.partition_point(|p| p[0] <= z + half);
                if from < to {
                    return s[from..to].iter().map(|p| p[1]).fold(0.0, |a: Real, v| {
                        if v.abs() > a.abs() {
                            v
                        } else {
                            a
                        }
                    });
                }
                if from == 0 || from == s.len() {
                    return 0.0;
                }
                let (a, b) = (s[from - 1], s[from]);
                a[1] + (b[1] - a[1]) * (z - a[0]) / (b[0] - a[0])
            })
            .collect()
    }
}

/// What the rest rides on during a pass, and how closely its U follows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestSetup {
    /// The support's radius R_o (mm).
    pub radius: Real,
    /// The offset B: the support's centre stands at z_r = z_k + B.
    pub offset_b: Real,
    /// Spacing of the surface samples under the support (mm).
    pub sample: Real,
    /// How far the straight line of U between blocks may stray from the
    /// exact drop (mm): blocks are added until it holds.
    pub tolerance: Real,
}

/// Along each move the straight line of U is checked against the exact
/// drop at least this often (mm of the wheel's travel along z).
pub const REST_CHECK_STEP: Real = 1.0;

/// Each move is checked at this many places at least.
pub const MIN_REST_CHECKS: usize = 4;

/// A kink of U (the support's contact jumping between features of the
/// surface) is located to this much of the wheel's travel (mm): a kink
/// inside a move this short bends U's line by at most a quarter of it times
/// the change of slope (below 0.3 um).
pub const KINK_WIDTH: Real = 1e-3;

/// The largest number of rest points a pass may get.
const MAX_REST_POINTS: usize = 200_000;

/// The steady rest along a pass (docs/math.md §2.3, §2.4): the wheel's reference
/// moves along `path` (one way along z) at `feed` (mm/min), having come to
/// its first point by `infeed` (without one: it stood there a revolution),
/// while the part turns at `rpm`, over a part whose surface before the
/// pass is `before`.
/// At each moment the rest at `z_r = z + B` rides the current surface: the
/// highest surface the earlier passes and this one as far as the wheel
/// has come can leave, whatever the spindle's phase ([`PassLayer`]: the
/// wheel's true section at the moments it meets the part). U is the exact
/// drop of the support on that surface (sampled `setup.sample` mm apart under the
/// support) at every block, and at [`MIN_REST_CHECKS`] or more places a
/// move, at most [`REST_CHECK_STEP`] apart; where the control's straight
/// line of U between two blocks strays more than `setup.tolerance` from
/// the exact drop, a block is added on the wheel's line at the worst
/// place, or, where the support's contact jumps from one feature of the
/// surface to another (a kink of U), a block either side of the kink,
/// until it holds.
///
/// # Failures
/// Bad numbers; a rest position whose support misses the part altogether
/// (naming the point and z); more than 200,000 rest points in a pass.
pub fn track(
    before: &GroundSurface,
    path: &Polyline,
    wheel: WheelSection,
    feed: Real,
    infeed: Option<Infeed>,
    rpm: Real,
    setup: &RestSetup,
) -> Result<RestTrack, ProfileError> {
    positive("rest support radius R_o", setup.radius)?;
    positive("rest surface sample", setup.sample)?;
    positive("rest tolerance", setup.tolerance)?;
    finite("rest offset B", setup.offset_b)?;
    if path.is_empty() {
        return Err(crate::input::InputError::TooFew {
            what: "pass points".into(),
            got: 0,
            min: 1,
        }
        .into());
    }
    let layer = PassLayer::new(&path.z, &path.x, wheel, feed, infeed, rpm)?;
    let time = layer.path().times();
    let rider = Rider {
        before,
        layer: &layer,
        setup,
    };
    // Exact U at every point, then at samples along each move, adding the
    // worst sample as a point where the straight line strays.
    let mut pts: Vec<Point> = path
        .z
        .iter()
        .zip(&path.x)
        .zip(time)
        .map(|((&z, &x), &tm)| (z, x, tm))
        .collect();
    let mut drops: Vec<(Drop, Real)> = pts
        .iter()
        .enumerate()
        .map(|(k, p)| rider.drop_at(p.0, p.2, k, true))
        .collect::<Result<_, _>>()?;
    let (mut max_gap, mut max_press) = (0.0 as Real, 0.0 as Real);
    let mut stand_off = vec![[pts[0].0 + setup.offset_b, 0.0]];
    let mut k = 1;
    let original = pts.len();
    while k < pts.len() {
        crate::budget::check("the steady rest's track")?;
        let (a, b) = (pts[k - 1], pts[k]);
        let along = rider.along(a, b, k, [drops[k - 1].0, drops[k].0])?;
        let add = along.added();
        if add.is_empty() {
            max_gap = max_gap.max(along.gap);
            max_press = max_press.max(along.press);
            stand_off.extend(along.checked);
            stand_off.push([b.0 + setup.offset_b, 0.0]);
            k += 1;
            continue;
        }
        if pts.len() >= original + MAX_REST_POINTS {
            return Err(crate::input::InputError::out_of_range(
                "points the steady rest adds to a pass",
                pts.len() as Real,
                format!("at most {MAX_REST_POINTS}: a coarser rest tolerance"),
            )
            .into());
        }
        for (j, s) in add.into_iter().enumerate() {
            let p = (
                a.0 + s * (b.0 - a.0),
                a.1 + s * (b.1 - a.1),
                a.2 + s * (b.2 - a.2),
            );
            let d = rider.drop_at(p.0, p.2, k + j, true)?;
            pts.insert(k + j, p);
            drops.insert(k + j, d);
        }
    }
    let added = pts.len() - original;
    Ok(RestTrack::of(
        &pts,
        &drops,
        [max_gap, max_press],
        added,
        stand_off,
    ))
}

impl RestTrack {
    /// The track through `pts` with the rest's `drops` there (each with
    /// the seed's formula's U beside it), the straight lines' largest
    /// `[gap, press]`, the points `added` and the stand-off samples.
    fn of(
        pts: &[Point],
        drops: &[(Drop, Real)],
        [max_gap, max_press]: [Real; 2],
        added: usize,
        stand_off: Vec<[Real; 2]>,
    ) -> Self {
        let mut out = RestTrack {
            path: Polyline {
                z: pts.iter().map(|p| p.0).collect(),
                x: pts.iter().map(|p| p.1).collect(),
            },
            centre_x: Vec::with_capacity(pts.len()),
            contact_z: Vec::with_capacity(pts.len()),
            contact_x: Vec::with_capacity(pts.len()),
            seed_centre_x: Vec::with_capacity(pts.len()),
            max_model_difference: 0.0,
            max_difference_block: 0,
            max_gap,
            max_press,
            added,
            stand_off,
        };
        for (k, (d, seed)) in drops.iter().enumerate() {
            if (seed - d.centre_x).abs() > out.max_model_difference {
                out.max_model_difference = (seed - d.centre_x).abs();
                out.max_difference_block = k;
            }
            out.centre_x.push(d.centre_x);
            out.contact_z.push(d.contact_z);
            out.contact_x.push(d.contact_x);
            out.seed_centre_x.push(*seed);
        }
        out
    }
}

/// A point of the wheel's path: (z, x (mm), time from the pass's start
/// (min)).
type Point = (Real, Real, Real);

/// The rest riding the surface before a pass while the pass cuts it.
struct Rider<'a> {
    before: &'a GroundSurface,
    layer: &'a PassLayer,
    setup: &'a RestSetup,
}

/// What a straight move of U between two points does against the rest's
/// exact drops along it.
struct Along {
    /// The line's largest gap above the exact U, and its largest press
    /// below it (mm).
    gap: Real,
    press: Real,
    /// The samples between the points: [z_r, line - exact] (mm).
    checked: Vec<[Real; 2]>,
    /// The largest deviation over the tolerance and its place along the
    /// move (0..1).
    worst: Option<(Real, Real)>,
    /// Where the support's contact jumps (0..1, narrowed to
    /// [`KINK_WIDTH`]).
    kink: Option<(Real, Real)>,
}

impl Along {
    /// Where the line strays, the places (0..1) a block goes: a kink in
    /// the move gets one either side of it (the short move between them
    /// has no room to stray), else one goes at the worst place.
    fn added(&self) -> Vec<Real> {
        match (self.kink, self.worst) {
            (Some((lo, hi)), Some(_)) => [lo, hi]
                .into_iter()
                .filter(|s| *s > 0.0 && *s < 1.0)
                .collect(),
            (_, w) => w.map(|w| w.1).into_iter().collect(),
        }
    }
}

impl Rider<'_> {
    /// The exact drop with the wheel at `(z, time)` (point `k` of the
    /// pass, from 0), and the seed's formula there where `seed` (else NaN).
    fn drop_at(
        &self,
        z: Real,
        time: Real,
        k: usize,
        seed: bool,
    ) -> Result<(Drop, Real), ProfileError> {
        let setup = self.setup;
        let (lo, hi) = self.before.z_range();
        let z_r = z + setup.offset_b;
        let part = Some(self.layer.by_time(time));
        let Some(d) = self
            .before
            .support(z_r, setup.radius, setup.sample, part.as_ref())?
        else {
            return Err(ProfileError::OutsideProfile {
                what: format!(
                    "the steady rest's support at point {} of the pass (z_r = z + B, B = {} mm) has nothing under it: its centre",
                    k + 1,
                    crate::math::fixed(setup.offset_b, 4)
                ),
                z: z_r,
                z_min: lo,
                z_max: hi,
            });
        };
        if !seed {
            return Ok((d, Real::NAN));
        }
        // The seed's formula reads the surface as an array at an even step.
        let (a, b) = ((z_r - setup.radius).max(lo), (z_r + setup.radius).min(hi));
        let grid = crate::profile::uniform_grid(a, b, setup.sample)?;
        let even = Profile::new(grid.clone(), self.before.eval_many(&grid, part.as_ref()))?;
        let seed = seed_u(&even, z_r.clamp(a, b), setup.radius)?;
        Ok((d, seed))
    }

    /// The move from `a` to `b` (point `k`, from 0, is `b`; `ends` the
    /// exact drops there) sampled at [`REST_CHECK_STEP`], at least
    /// [`MIN_REST_CHECKS`] times.
    fn along(&self, a: Point, b: Point, k: usize, ends: [Drop; 2]) -> Result<Along, ProfileError> {
        let (ua, ub) = (ends[0].centre_x, ends[1].centre_x);
        let n = ((b.0 - a.0).abs() / REST_CHECK_STEP)
            .ceil()
            .max(MIN_REST_CHECKS as Real) as usize;
        let mut out = Along {
            gap: 0.0,
            press: 0.0,
            checked: Vec::with_capacity(n),
            worst: None,
            kink: None,
        };
        let mut contact = ends[0].contact_z;
        let at_s = |s: Real| self.drop_at(a.0 + s * (b.0 - a.0), a.2 + s * (b.2 - a.2), k, false);
        let dz = (b.0 - a.0).abs() / n as Real;
        for i in 1..=n {
            crate::budget::check("the steady rest's track")?;
            let s = i as Real / n as Real;
            let d = if i == n { ends[1] } else { at_s(s)?.0 };
            // The support's contact jumping from one feature of the
            // surface to another (a corner, a step, where a pass's cut
            // begins) is a kink in U: found to within KINK_WIDTH and made
            // a block, so the straight lines either side follow smooth arcs.
            if out.kink.is_none()
                && dz > KINK_WIDTH
                && (d.contact_z - contact).abs() > 2.0 * dz + 1e-3
            {
                let (mut lo, mut hi) = ((i - 1) as Real / n as Real, s);
                while (hi - lo) * (b.0 - a.0).abs() > KINK_WIDTH {
                    let m = 0.5 * (lo + hi);
                    if (at_s(m)?.0.contact_z - contact).abs()
                        > 2.0 * (m - lo) * (b.0 - a.0).abs() + 1e-3
                    {
                        hi = m;
                    } else {
                        lo = m;
                    }
                }
                out.kink = Some((lo, hi));
            }
            contact = d.contact_z;
            if i == n {
                break;
            }
            let (exact, line) = (d.centre_x, ua + s * (ub - ua));
            out.checked
                .push([a.0 + s * (b.0 - a.0) + self.setup.offset_b, line - exact]);
            out.gap = out.gap.max(line - exact);
            out.press = out.press.max(exact - line);
            let dev = (line - exact).abs();
            if dev > self.setup.tolerance && out.worst.is_none_or(|w| dev > w.0) {
                out.worst = Some((dev, s));
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod stand_off_tests {
    use super::*;

    /// The stand-off on a grid keeps the checked extremes within half a
    /// step, interpolates between checks farther apart than that, and is 0
    /// beyond them.
    #[test]
    fn stand_off_on_a_grid() {
        let t = RestTrack {
            path: Polyline {
                z: vec![],
                x: vec![],
            },
            centre_x: vec![],
            contact_z: vec![],
            contact_x: vec![],
            seed_centre_x: vec![],
            max_model_difference: 0.0,
            max_difference_block: 0,
            max_gap: 0.0,
            max_press: 0.0,
            added: 0,
            stand_off: vec![
                [10.0, 0.0],
                [10.3, 0.002],
                [10.4, -0.003],
                [12.0, 0.001],
                [16.0, 0.0],
            ],
        };
        let v = t.stand_off_on(&[9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 17.0]);
        assert_eq!((v[0], v[1], v[3], v[6]), (0.0, -0.003, 0.001, 0.0));
        for (got, want) in [(v[2], -0.0015), (v[4], 0.00075), (v[5], 0.0005)] {
            assert!((got - want).abs() < 1e-15, "{got} {want}");
        }
    }
}
