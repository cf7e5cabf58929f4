//! The finished worm as a closed solid: the simulated section swept
//! helically, right-handed about +Z (the section at the part's angle
//! `phi` is the one at 0 shifted `+lead phi / 2 pi` along the axis), from
//! z = -length to 0, with flat ends.
//!
//! The rings are sections across the axis; a ring's points are `n` angles
//! round the axis, the rings `lead / n` apart, so that the sweep's
//! diagonals (ring j point k to ring j + 1 point k + 1) run along the
//! helices and the profile is sampled every `lead / n` along it; `n` is
//! set by the chordal tolerance at the tip. The end rings are at exactly 0
//! and -length.

use super::WormCheck;
use crate::math::Real;
use crate::mesh::{sweep, MeshError, TriMesh};
use std::f64::consts::TAU;

/// The most points round the axis (and so the finest sampling).
pub const MAX_AROUND: usize = 2048;

/// The worm of `check`'s finished section, `length` long, its round
/// sampling within `tol` of the tip circle (at least 24 points).
///
/// # Failures
/// A length or tolerance not positive; a mesh that cannot be closed.
pub fn worm_solid(check: &WormCheck, length: Real, tol: Real) -> Result<TriMesh, MeshError> {
    crate::math::positive("worm length", length)
        .map_err(|e| MeshError::Degenerate(e.to_string()))?;
    crate::math::positive("mesh tolerance", tol)
        .map_err(|e| MeshError::Degenerate(e.to_string()))?;
    let lead = check.window.1;
    let r_tip = (0..64)
        .map(|i| check.radius_at(check.window.0 + lead * i as Real / 64.0))
        .fold(0.0, Real::max);
    let step = 2.0 * (1.0 - (tol / r_tip).min(1.0)).acos();
    let n = ((TAU / step).ceil() as usize).clamp(24, MAX_AROUND);
    let dz = lead / n as Real;
    // Ring heights: multiples of dz down from 0, then -length.
    let mut zs: Vec<Real> = (0..)
        .map(|j| -(j as Real) * dz)
        .take_while(|z| *z > -length + 1e-9)
        .collect();
    zs.push(-length);
    zs.reverse();
    let rings: Vec<Vec<[Real; 3]>> = zs
        .iter()
        .map(|&z| {
            (0..n)
                .map(|k| {
                    let phi = TAU * k as Real / n as Real;
                    let r = check.radius_at(z - lead * phi / TAU);
                    [r * phi.cos(), r * phi.sin(), z]
                })
                .collect()
        })
        .collect();
    sweep(&rings)
}
