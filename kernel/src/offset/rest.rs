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
