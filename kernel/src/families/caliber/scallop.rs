//! The scallop between two passes (docs/math.md §3.3, S001-2).

use crate::input::InputError;
use crate::math::{positive, Real};

/// The cusp two neighbouring rounding circles (radius `r_k`) leave inside a
/// section circle of radius `r_section` (the groove's largest profile
/// radius) when their passes are `dpsi` apart (rad): with
/// `d = r_section - r_k`, `sin(beta) = (d / r_k) sin(dpsi / 2)` and
/// `Rz = r_section - (d cos(dpsi / 2) + r_k cos(beta))` (mm).
///
/// ```
/// let rz = pilgrim_kernel::families::caliber::scallop_height(20.0, 5.0, 1f64.to_radians()).unwrap();
/// assert!((rz - 2.28e-3).abs() < 1e-5); // 1 degree (the seed's finish): 2.3 um
/// ```
///
/// # Failures
/// A radius or step that is not positive; a rounding not smaller than the
/// section; steps so far apart that the circles do not meet.
pub fn scallop_height(r_section: Real, r_k: Real, dpsi: Real) -> Result<Real, InputError> {
    let d = centre_distance(r_section, r_k)?;
    positive("pass step dpsi", dpsi)?;
    let sin_beta = d / r_k * (dpsi / 2.0).sin();
    if !(sin_beta <= 1.0) || dpsi >= std::f64::consts::PI {
        return Err(InputError::out_of_range(
            "pass step dpsi (rad)",
            dpsi,
            format!(
                "the rounding circles of neighbouring passes must meet: at most {} rad for R = {r_section} mm, r_k = {r_k} mm",
                2.0 * (r_k / d).min(1.0).asin()
            ),
        ));
    }
    Ok(r_section - (d * (dpsi / 2.0).cos() + r_k * sin_beta.asin().cos()))
}

/// The largest pass step `dpsi` (rad) whose scallop is at most `rz` mm: the
/// inverse of [`scallop_height`]. The cusp lies on the bisector at
/// `rho = r_section - rz` from the centre, `r_k` from both rounding
/// centres: `cos(dpsi / 2) = (rho^2 + d^2 - r_k^2) / (2 rho d)`.
///
/// # Failures
/// A radius or `rz` that is not positive; a rounding not smaller than the
/// section; `rz` as deep as the rounding or more.
pub fn step_for_scallop(r_section: Real, r_k: Real, rz: Real) -> Result<Real, InputError> {
    let d = centre_distance(r_section, r_k)?;
    positive("scallop height Rz", rz)?;
    if rz >= r_k {
        return Err(InputError::out_of_range(
            "scallop height Rz (mm)",
            rz,
            format!("below the rounding radius r_k = {r_k} mm"),
        ));
    }
    Ok(cusp_step(r_section - rz, d, r_k))
}

/// The largest pass step (rad of the rounding circles' angle about their
/// centre) whose scallop is at most `rz` mm on a convex arc of radius
/// `r_arc` (an edge's rounding) ground by a rounding `r_k`: the rounding
/// centres lie on the circle of `D = r_arc + r_k`, the cusp on the
/// bisector at `rho = r_arc + rz`, `r_k` from both centres:
/// `cos(dphi / 2) = (rho^2 + D^2 - r_k^2) / (2 rho D)`. For small steps
/// the cusp is `(r_arc dphi)^2 / 8 (1 / r_k + 1 / r_arc)`: a convex arc
/// needs finer steps than a flat or concave one.
///
/// # Failures
/// A radius or `rz` that is not positive.
pub fn step_for_scallop_convex(r_arc: Real, r_k: Real, rz: Real) -> Result<Real, InputError> {
    positive("edge rounding radius", r_arc)?;
    positive("wheel rounding radius r_k", r_k)?;
    positive("scallop height Rz", rz)?;
    Ok(cusp_step(r_arc + rz, r_arc + r_k, r_k))
}

/// The angle between two rounding centres `d` from a section's centre
/// whose circles (radius `r_k`) meet on the bisector `rho` from it:
/// `2 acos((rho^2 + d^2 - r_k^2) / (2 rho d))`, the law of cosines in the
/// triangle of the section's centre, a rounding centre and the cusp.
fn cusp_step(rho: Real, d: Real, r_k: Real) -> Real {
    let c = ((rho * rho + d * d - r_k * r_k) / (2.0 * rho * d)).clamp(-1.0, 1.0);
    2.0 * c.acos()
}

fn centre_distance(r_section: Real, r_k: Real) -> Result<Real, InputError> {
    positive("section radius", r_section)?;
    positive("wheel rounding radius r_k", r_k)?;
    if r_k >= r_section {
        return Err(InputError::out_of_range(
            "wheel rounding radius r_k (mm)",
            r_k,
            format!("smaller than the groove section's radius {r_section} mm"),
        ));
    }
    Ok(r_section - r_k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_convex_step_leaves_its_scallop() {
        // Two rounding circles dphi apart about the arc's centre: the
        // point of the bisector rz above the arc is on both.
        let (r_arc, r_k, rz) = (2.0, 8.0, 0.003);
        let dphi = step_for_scallop_convex(r_arc, r_k, rz).unwrap();
        let d = r_arc + r_k;
        let centre = (d * (dphi / 2.0).sin(), d * (dphi / 2.0).cos());
        let cusp = (0.0, r_arc + rz);
        let far = (centre.0 - cusp.0).hypot(centre.1 - cusp.1);
        assert!((far - r_k).abs() < 1e-12, "{far}");
        // The small-step rule, s^2 / 8 (1 / r_k + 1 / r_arc), within 1 %.
        let s = r_arc * dphi;
        let h = s * s / 8.0 * (1.0 / r_k + 1.0 / r_arc);
        assert!((h - rz).abs() < 1e-2 * rz, "{h}");
        // Finer than on a flat or concave section.
        assert!(dphi * r_arc < step_for_scallop(1e6, r_k, rz).unwrap() * 1e6);
    }
}
