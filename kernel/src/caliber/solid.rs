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

/// The roll's sector over the groove tables' angles, exactly: the section
/// (the roll's rim `width` wide, from the hub radius `hub` to the periphery
/// `R_d`, the groove's half ellipse cut in its middle) carried round the
/// roll's axis (Z), flat ends at the tables' first and last angle. Its
/// section's pieces, in order: up the left face, along the periphery to the
/// groove, the groove (psi from -pi/2 to pi/2), the periphery to the right
/// face, down it, back along the hub; `v` runs over the tables' angles.
#[derive(Debug, Clone, PartialEq)]
pub struct Roll {
    groove: Groove,
    width: Real,
    hub: Real,
}

impl Roll {
    /// The roll of `groove` with a rim `width` wide from radius `hub`.
    ///
    /// # Failures
    /// A width not wider than every section's groove; a hub not inside the
    /// groove's deepest point.
    pub fn new(groove: &Groove, width: Real, hub: Real) -> Result<Self, SolidError> {
        let r_d = groove.roll_radius();
        let (widest, deepest) = extremes(groove);
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
        Ok(Roll {
            groove: groove.clone(),
            width,
            hub,
        })
    }

    /// The angle (rad) at `v` along the tables.
    fn theta(&self, v: Real) -> Real {
        let (t0, t1) = self.groove.theta_range();
        t0 + (t1 - t0) * v
    }

    /// The groove's point at `psi` in the section at `theta`, `(x, rho)`.
    fn groove_at(&self, theta: Real, psi: Real) -> (Real, Real) {
        self.groove
            .section(theta)
            .map_or((Real::NAN, Real::NAN), |s| {
                let (x, z) = s.point(psi);
                (x, self.groove.roll_radius() - z)
            })
    }

    /// The roll as a closed triangle mesh in its frame, sampled so that its
    /// chords stay within `tol` of the groove and the periphery (each
    /// section's groove with the same number of points, evenly in psi: the
    /// widest section sets it).
    ///
    /// # Failures
    /// A tolerance not positive, or more triangles than
    /// [`crate::mesh::MAX_TRIANGLES`]; a groove that cannot be evaluated.
    pub fn mesh(&self, tol: Real) -> Result<TriMesh, SolidError> {
        use crate::step::Sections;
        crate::math::positive("chordal tolerance", tol).map_err(MeshError::from)?;
        let groove = &self.groove;
        let r_d = groove.roll_radius();
        let (widest, deepest) = extremes(groove);
        // The groove's arc: chords within tol on its tightest curvature.
        let (r_min, _) = groove.min_curvature_radius()?;
        let chord = (8.0 * tol * r_min).sqrt();
        let arc = std::f64::consts::PI * (widest / 2.0).max(deepest);
        let n_psi = ((arc / chord).ceil() as usize).max(8);
        let (t0, t1) = groove.theta_range();
        let d_theta = (8.0 * tol / r_d).sqrt();
        let n_theta = (((t1 - t0) / d_theta).ceil() as usize).max(2);
        crate::mesh::check_triangles(2 * (n_theta + 1) * (n_psi + 6), tol)?;
        // Each ring: the section's corners and the groove's points, in the
        // order of the roll's pieces.
        let rings = (0..=n_theta)
            .map(|i| {
                let v = i as Real / n_theta as Real;
                let mut ring = vec![self.point(0, 0.0, v), self.point(1, 0.0, v)];
                ring.extend((0..=n_psi).map(|j| self.point(2, j as Real / n_psi as Real, v)));
                ring.extend([self.point(4, 0.0, v), self.point(5, 0.0, v)]);
                ring
            })
            .collect::<Vec<_>>();
        if rings.iter().flatten().flatten().any(|c| !c.is_finite()) {
            // The tables cover every angle of their own range: a section
            // that cannot be evaluated is the groove's own error.
            groove.section(t0)?;
            groove.section(t1)?;
            return Err(SolidError::Size(
                "the groove's sections are not finite".into(),
            ));
        }
        Ok(crate::mesh::sweep(&rings)?)
    }
}

impl crate::step::Sections for Roll {
    fn pieces(&self) -> usize {
        6
    }

    fn straight(&self, k: usize) -> bool {
        k != 2
    }

    fn point(&self, k: usize, u: Real, v: Real) -> [Real; 3] {
        use std::f64::consts::FRAC_PI_2;
        let theta = self.theta(v);
        let (half, r_d, hub) = (self.width / 2.0, self.groove.roll_radius(), self.hub);
        let lerp =
            |a: (Real, Real), b: (Real, Real)| (a.0 + u * (b.0 - a.0), a.1 + u * (b.1 - a.1));
        let (x, rho) = match k {
            0 => lerp((-half, hub), (-half, r_d)),
            1 => lerp((-half, r_d), self.groove_at(theta, -FRAC_PI_2)),
            2 => self.groove_at(theta, -FRAC_PI_2 + std::f64::consts::PI * u),
            3 => lerp(self.groove_at(theta, FRAC_PI_2), (half, r_d)),
            4 => lerp((half, r_d), (half, hub)),
            _ => lerp((half, hub), (-half, hub)),
        };
        let (s, c) = theta.sin_cos();
        [rho * c, rho * s, x]
    }

    fn along(&self) -> usize {
        let (t0, t1) = self.groove.theta_range();
        // About every 5 degrees to start.
        ((t1 - t0) / 0.09).ceil() as usize + 1
    }
}

/// The roll's sector over the tables' angles ([`Roll`]) as a closed
/// triangle mesh in the roll's frame ([`Roll::mesh`]).
///
/// # Failures
/// As [`Roll::new`] and [`Roll::mesh`].
pub fn caliber_solid(
    groove: &Groove,
    width: Real,
    hub: Real,
    tol: Real,
) -> Result<TriMesh, SolidError> {
    Roll::new(groove, width, hub)?.mesh(tol)
}

/// The widest and the deepest the groove is in its tables (mm).
fn extremes(groove: &Groove) -> (Real, Real) {
    let max = |t: &crate::profile::Profile| t.x().iter().copied().fold(0.0, Real::max);
    (max(groove.width()), max(groove.depth()))
}
