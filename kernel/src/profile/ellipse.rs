//! The caliber groove's elliptical section (docs/math.md §3.1, S001-3, S001-4).

use super::{Profile, ProfileError};
use crate::input::InputError;
use crate::math::{positive, Real};
use serde::{Deserialize, Serialize};

/// Half an ellipse: half-width `a = B/2` along the roll axis, depth `b = Hp`,
/// centred on the roll's periphery. The polar angle `psi` about the centre
/// is measured from the depth direction.
///
/// ```
/// use pilgrim_kernel::EllipseSection;
/// let e = EllipseSection::new(12.0, 5.0).unwrap(); // a = B/2, b = Hp
/// assert!((e.radius(0.0) - 5.0).abs() < 1e-12);                          // groove bottom
/// assert!((e.radius(std::f64::consts::FRAC_PI_2) - 12.0).abs() < 1e-12); // groove edge
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EllipseSection {
    /// Half-width along the roll axis (mm).
    pub a: Real,
    /// Depth (mm).
    pub b: Real,
}

impl EllipseSection {
    /// A section from its half-width `a` and depth `b`.
    ///
    /// # Failures
    /// Either not positive and finite.
    pub fn new(a: Real, b: Real) -> Result<Self, ProfileError> {
        Ok(Self {
            a: positive("ellipse half-width a", a)?,
            b: positive("ellipse depth b", b)?,
        })
    }

    /// `R(psi) = a b / sqrt(a^2 cos^2 psi + b^2 sin^2 psi)` (S001-4).
    pub fn radius(&self, psi: Real) -> Real {
        let (s, c) = psi.sin_cos();
        self.a * self.b / (self.a * self.a * c * c + self.b * self.b * s * s).sqrt()
    }

    /// The contact point `(x_A, z_A) = R(psi) (sin psi, cos psi)` (S001-3):
    /// along the roll axis, and depth from the periphery.
    pub fn point(&self, psi: Real) -> (Real, Real) {
        let r = self.radius(psi);
        (r * psi.sin(), r * psi.cos())
    }

    /// The angle `psi_1` of the ellipse's normal at `psi`, from the depth
    /// direction: `atan2(b^2 x_A, a^2 z_A)` (S001-6).
    pub fn normal_angle(&self, psi: Real) -> Real {
        let (x, z) = self.point(psi);
        (self.b * self.b * x).atan2(self.a * self.a * z)
    }

    /// The smallest radius of curvature of the section, `min(a^2/b, b^2/a)`
    /// (at the bottom or at the edge).
    pub fn min_curvature_radius(&self) -> Real {
        (self.a * self.a / self.b).min(self.b * self.b / self.a)
    }

    /// The section as a profile of depth against axial position, sampled at
    /// `count` uniform steps of psi over `[-psi_max, psi_max]`, with analytic
    /// derivatives. `psi_max` must be below 90 degrees (the edge is vertical).
    ///
    /// # Failures
    /// `psi_max` not in (0, pi/2); `count < 2`.
    pub fn depth_profile(&self, psi_max: Real, count: usize) -> Result<Profile, ProfileError> {
        if !(psi_max > 0.0 && psi_max < std::f64::consts::FRAC_PI_2) {
            return Err(
                InputError::out_of_range("ellipse psi_max", psi_max, "(0, pi/2) rad").into(),
            );
        }
        if count < 2 {
            return Err(InputError::TooFew {
                what: "ellipse section steps".into(),
                got: count,
                min: 2,
            }
            .into());
        }
        let (a, b) = (self.a, self.b);
        let (mut xs, mut zs, mut d1, mut d2) = (vec![], vec![], vec![], vec![]);
        for i in 0..=count {
            let psi = -psi_max + 2.0 * psi_max * i as Real / count as Real;
            let (x, z) = self.point(psi);
            // depth z(x) = b sqrt(1 - x^2/a^2)
            let q = 1.0 - x * x / (a * a);
            xs.push(x);
            zs.push(z);
            d1.push(-b * x / (a * a * q.sqrt()));
            d2.push(-b / (a * a * q.powf(1.5)));
        }
        Profile::with_derivatives(xs, zs, d1, d2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    #[test]
    fn points_lie_on_the_ellipse_and_normals_are_normal() {
        let e = EllipseSection::new(9.0, 4.0).unwrap();
        for i in 0..=20 {
            let psi = -1.5 + 0.15 * i as Real;
            let (x, z) = e.point(psi);
            assert_near!(x * x / 81.0 + z * z / 16.0, 1.0, 1e-12);
            // The normal is perpendicular to the tangent (dx, dz)/dt of the
            // parametrisation x = a sin t, z = b cos t.
            let t = (x / 9.0).atan2(z / 4.0);
            let tangent = (9.0 * t.cos(), -4.0 * t.sin());
            let n = e.normal_angle(psi);
            assert_near!(tangent.0 * n.sin() + tangent.1 * n.cos(), 0.0, 1e-10);
        }
        let p = e.depth_profile(1.2, 64).unwrap();
        let rho_min = p
            .curvature_radius()
            .iter()
            .cloned()
            .fold(Real::INFINITY, Real::min);
        // The section's tightest sampled place is at its ends (psi = 1.2);
        // with x = a sin t, z = b cos t, rho = (a^2 cos^2 t + b^2 sin^2 t)^1.5 / (a b).
        let (x, z) = e.point(1.2);
        let t = (x / 9.0).atan2(z / 4.0);
        let rho_end = (81.0 * t.cos().powi(2) + 16.0 * t.sin().powi(2)).powf(1.5) / 36.0;
        assert_near!(rho_min, rho_end, 1e-9);
        assert!(rho_min >= e.min_curvature_radius());
        assert!(e.depth_profile(1.6, 10).is_err());
        assert!(EllipseSection::new(0.0, 1.0).is_err());
    }
}
