//! The CNC steady rest (axis U) riding the current surface (MATH §2.3).
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
//! the O(R_o^2 s'') of MATH §2.3. On a ground surface with a cusp or a step
//! (the edge of the current pass) the seed's model has no such bound: that
//! is why the exact model is the default.

use super::{drop_circle, Drop, Side};
use crate::math::{finite, positive, Real};
use crate::profile::{Profile, ProfileError};
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
/// use pilgrim_kernel::{rest, Profile};
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

/// The steady rest along one pass: for each block, the support's centre x
/// on the current surface (the exact drop), the contact point, and the
/// seed's formula on the same surface.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RestTrack {
    /// The support centre's x at each block (exact model).
    pub centre_x: Vec<Real>,
    /// The contact point's z at each block.
    pub contact_z: Vec<Real>,
    /// The contact point's x at each block.
    pub contact_x: Vec<Real>,
    /// The support centre's x by the seed's formula.
    pub seed_centre_x: Vec<Real>,
    /// The largest |seed - exact| over the pass (mm).
    pub max_model_difference: Real,
    /// The block where it is (from 0).
    pub max_difference_block: usize,
}

/// What the rest rides on during a pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestSetup {
    /// The support's radius R_o (mm).
    pub radius: Real,
    /// The offset B: the support's centre stands at z_r = z_k + B.
    pub offset_b: Real,
    /// Spacing of the surface samples under the support (mm).
    pub sample: Real,
    /// Resolution of the wheel's swept surface (mm), as in [`swept_circles`](super::swept_circles).
    pub resolution: Real,
}

/// The steady rest's track along a pass whose wheel rounding (radius
/// `wheel_radius`) moves through the centres `(z[k], x[k])` in order (a
/// pass runs one way along z), over a workpiece whose surface before the
/// pass is `previous`. At block k the rest at `z_r = z[k] + B` rides the
/// current surface: the previous surface where the wheel has not been, the
/// surface the wheel has left where it has, their minimum where the
/// support's reach straddles both (MATH §2.3). The surface under the
/// support is sampled at `setup.sample` and the exact drop taken on it.
///
/// # Failures
/// Bad numbers; centres of different lengths or fewer than one; a rest
/// position whose support misses the previous surface altogether.
pub fn track(
    previous: &Profile,
    z: &[Real],
    x: &[Real],
    wheel_radius: Real,
    setup: &RestSetup,
) -> Result<RestTrack, ProfileError> {
    positive("rest support radius R_o", setup.radius)?;
    positive("rest surface sample", setup.sample)?;
    finite("rest offset B", setup.offset_b)?;
    let (cz, cx, block_of) = super::swept_circles(z, x, wheel_radius, setup.resolution)?;
    let full = super::CircleEnvelope::new(&cz, &cx, wheel_radius, Side::Outside)?;
    // The last circle placed by each block (where the wheel stands then).
    let mut last_of_block = vec![0usize; z.len()];
    for (i, &b) in block_of.iter().enumerate() {
        last_of_block[b] = i;
    }
    let increasing = z.last() >= z.first();
    let reach = setup.radius + wheel_radius;
    let (lo_prev, hi_prev) = previous.z_range();
    let slopes = previous.slopes();
    let prev_at = |zq: Real| crate::profile::hermite(previous.z(), previous.x(), &slopes, zq);
    let mut out = RestTrack {
        centre_x: Vec::with_capacity(z.len()),
        contact_z: Vec::with_capacity(z.len()),
        contact_x: Vec::with_capacity(z.len()),
        seed_centre_x: Vec::with_capacity(z.len()),
        max_model_difference: 0.0,
        max_difference_block: 0,
    };
    for k in 0..z.len() {
        let z_r = z[k] + setup.offset_b;
        let (a, b) = (
            (z_r - setup.radius).max(lo_prev),
            (z_r + setup.radius).min(hi_prev),
        );
        if a >= b {
            return Err(ProfileError::OutsideProfile {
                what: format!(
                    "the steady rest's support at block {} of the pass (z_r = z + B, B = {} mm) has nothing under it: its centre",
                    k + 1,
                    crate::math::fixed(setup.offset_b, 4)
                ),
                z: z_r,
                z_min: lo_prev,
                z_max: hi_prev,
            });
        }
        // Circles whose reach meets the support's: a run of the pass.
        let near = if increasing {
            cz.partition_point(|&c| c < z_r - reach)..cz.partition_point(|&c| c <= z_r + reach)
        } else {
            cz.partition_point(|&c| c > z_r + reach)..cz.partition_point(|&c| c >= z_r - reach)
        };
        // Of those, the ones the wheel has placed by now: none, all (the
        // pass's whole envelope serves), or the first few.
        let now = last_of_block[k];
        let partial;
        let cut = if near.is_empty() || near.start > now {
            None
        } else if near.end - 1 <= now {
            Some(&full)
        } else {
            let (pz, px): (Vec<Real>, Vec<Real>) =
                (near.start..=now).map(|i| (cz[i], cx[i])).unzip();
            partial = super::CircleEnvelope::new(&pz, &px, wheel_radius, Side::Outside)?;
            Some(&partial)
        };
        let grid = crate::profile::uniform_grid(a, b, setup.sample)?;
        let surface: Vec<Real> = grid
            .iter()
            .map(|&g| match cut {
                Some(env) => prev_at(g).min(env.eval(g)),
                None => prev_at(g),
            })
            .collect();
        let window = Profile::new(grid, surface)?;
        let d = super::drop_circle(&window, z_r, setup.radius, Side::Outside)?;
        let seed = seed_u(&window, z_r.clamp(a, b), setup.radius)?;
        if (seed - d.centre_x).abs() > out.max_model_difference {
            out.max_model_difference = (seed - d.centre_x).abs();
            out.max_difference_block = k;
        }
        out.centre_x.push(d.centre_x);
        out.contact_z.push(d.contact_z);
        out.contact_x.push(d.contact_x);
        out.seed_centre_x.push(seed);
    }
    Ok(out)
}

/// The surface after a pass: the lower of `previous` and the surface the
/// wheel's rounding (radius `wheel_radius`) leaves moving through
/// `(z[k], x[k])`, at `previous`'s nodes (the pass's own scallops, below
/// `resolution`, are what lies between).
///
/// # Failures
/// As [`swept_circles`](super::swept_circles) and [`Profile::new`].
pub fn after_pass(
    previous: &Profile,
    z: &[Real],
    x: &[Real],
    wheel_radius: Real,
    resolution: Real,
) -> Result<Profile, ProfileError> {
    let (cz, cx, _) = super::swept_circles(z, x, wheel_radius, resolution)?;
    let env = super::CircleEnvelope::new(&cz, &cx, wheel_radius, Side::Outside)?;
    let cut = env.eval_many(previous.z());
    let xs = previous
        .x()
        .iter()
        .zip(cut)
        .map(|(p, c)| p.min(c))
        .collect();
    Profile::new(previous.z().to_vec(), xs)
}
