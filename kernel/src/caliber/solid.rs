//! The caliber as a solid: the roll's sector over the groove tables'
//! angles, the groove cut in its periphery (for `caliber.stl`).

use super::groove::{Groove, GrooveError};
use crate::math::Real;
use crate::mesh::{MeshError, TriMesh};

/// Why the caliber's solid cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolidError {
    /// The groove cannot be evaluated.
    #[error(transparent)]
    Groove(#[from] GrooveError),
    /// The mesh cannot be built.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Sizes that leave no solid.
    #[error("caliber solid: {0}")]
    Size(String),
}

/// The roll's sector over the tables' angles as a closed triangle mesh in
/// the roll's frame: the section (the roll's rim `width` wide, from the
/// hub radius `hub` to the periphery `R_d`, the groove's half ellipse cut
/// in its middle) carried round the roll's axis, flat ends at the tables'
/// first and last angle. Sampled so that its chords stay within `tol` of
/// the groove and the periphery (each section's groove with the same
/// number of points, evenly in psi: the widest section sets it).
///
/// # Failures
/// A width not wider than every section's groove; a hub not inside the
/// groove's deepest point; a tolerance not positive, or more triangles
/// than [`crate::mesh::MAX_TRIANGLES`].
pub fn caliber_solid(
    groove: &Groove,
    width: Real,
    hub: Real,
    tol: Real,
) -> Result<TriMesh, SolidError> {
    crate::math::positive("chordal tolerance", tol).map_err(MeshError::from)?;
    let r_d = groove.roll_radius();
    let widest = groove.width().x().iter().copied().fold(0.0, Real::max);
    let deepest = groove.depth().x().iter().copied().fold(0.0, Real::max);
    if !(width > widest) {
        return Err(SolidError::Size(format!(
            "the rim's width {width} mm must exceed the widest groove, {widest} mm"
        )));
    }
    if !(hub > 0.0 && hub < r_d - deepest) {
        return Err(SolidError::Size(format!(
            "the hub radius {hub} mm must be positive and below the groove's deepest point, {} mm from the axis",
            r_d - deepest
        )));
    }
    // The groove's arc: chords within tol on its tightest curvature.
    let (r_min, _) = groove.min_curvature_radius()?;
    let chord = (8.0 * tol * r_min).sqrt();
    let arc = std::f64::consts::PI * (widest / 2.0).max(deepest);
    let n_psi = ((arc / chord).ceil() as usize).max(8);
    let (t0, t1) = groove.theta_range();
    let d_theta = (8.0 * tol / r_d).sqrt();
    let n_theta = (((t1 - t0) / d_theta).ceil() as usize).max(2);
    crate::mesh::check_triangles(2 * (n_theta + 1) * (n_psi + 6), tol)?;
    let mut rings = Vec::with_capacity(n_theta + 1);
    for i in 0..=n_theta {
        let theta = t0 + (t1 - t0) * i as Real / n_theta as Real;
        let s = groove.section(theta)?;
        // (axial x, radius rho): the rim from the hub up the left face, the
        // periphery to the groove, the groove, the periphery, down the right.
        let mut sec: Vec<(Real, Real)> = vec![(-width / 2.0, hub), (-width / 2.0, r_d)];
        for j in 0..=n_psi {
            let psi =
                -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * j as Real / n_psi as Real;
            let (x, z) = s.point(psi);
            sec.push((x, r_d - z));
        }
        sec.push((width / 2.0, r_d));
        sec.push((width / 2.0, hub));
        let (si, c) = theta.sin_cos();
        rings.push(
            sec.into_iter()
                .map(|(x, rho)| [rho * c, rho * si, x])
                .collect(),
        );
    }
    Ok(crate::mesh::sweep(&rings)?)
}
