//! The finished worm as a closed solid: the simulated section swept
//! helically, right-handed about +Z (the section at the part's angle
//! `phi` is the one at 0 shifted `+lead phi / 2 pi` along the axis), from
//! z = -length to 0, with flat ends.
//!
//! The rings are sections across the axis; a ring's points are `n` angles
//! round the axis, the rings evenly spaced from -length to 0 as near
//! `lead / n` apart as a whole number of them allows, so that the sweep's
//! diagonals (ring j point k to ring j + 1 point k + 1) run along the
//! helices (within a small fraction of the spacing) and the profile is
//! sampled every `lead / n` along them; `n` is set by the chordal
//! tolerance at the tip.

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
    let (w0, lead) = check.window;
    let outline = check.outline();
    let r_tip = outline.iter().map(|p| p[1]).fold(0.0, Real::max);
    // The outline between its corners, repeated with the lead.
    let radius = |z: Real| -> Real {
        let u = w0 + (z - w0).rem_euclid(lead);
        let k = outline
            .partition_point(|p| p[0] < u)
            .clamp(1, outline.len() - 1);
        let (a, b) = (outline[k - 1], outline[k]);
        let t = if b[0] > a[0] {
            ((u - a[0]) / (b[0] - a[0])).clamp(0.0, 1.0)
        } else {
            0.0
        };
        a[1] + t * (b[1] - a[1])
    };
    if outline.len() < 2 || !(r_tip > 0.0) {
        return Err(MeshError::Degenerate("the worm's section is empty".into()));
    }
    let step = 2.0 * (1.0 - (tol / r_tip).min(1.0)).acos();
    let n = ((TAU / step).ceil() as usize).clamp(24, MAX_AROUND);
    // Rings evenly from -length to 0, as near lead / n apart as a whole
    // number of them allows: each quad's diagonal then strays from its
    // helix by at most a (2 rings)-th of a ring's spacing.
    let rings = (length * n as Real / lead).round();
    crate::mesh::check_triangles((2.0 * n as Real * (rings + 1.0)).min(1e18) as usize, tol)?;
    let rings_between = (rings as usize).max(1);
    let zs: Vec<Real> = (0..=rings_between)
        .map(|j| -length + length * j as Real / rings_between as Real)
        .collect();
    let rings: Vec<Vec<[Real; 3]>> = zs
        .iter()
        .map(|&z| {
            (0..n)
                .map(|k| {
                    let phi = TAU * k as Real / n as Real;
                    let r = radius(z - lead * phi / TAU);
                    [r * phi.cos(), r * phi.sin(), z]
                })
                .collect()
        })
        .collect();
    sweep(&rings)
}
