//! The axial sections of worm flanks that are straight in another plane
//! (DIN 3975's ZN and ZI).
//!
//! A helicoid is fixed by its axial section: turning the section about
//! the axis while it advances by the lead sweeps the whole flank. So a
//! worm's flank, whatever plane its straight generator lies in, is a
//! curve in the axial section, and the planning, the cut and its
//! measurement all work there (a cutter ground to that curve, standing in
//! the axial plane, cuts the flank exactly):
//!
//! - **ZA** ([`FlankForm::Axial`]): straight in the axial section; the
//!   section's own flank angles give it, so it has no curve here.
//! - **ZN** ([`FlankForm::Normal`]): straight in the normal section of the
//!   space, the plane through the space's middle at the reference (pitch)
//!   radius, containing the radial direction, tilted from the axial plane
//!   by the lead angle there. Its flanks are at the normal pressure angle
//!   in that plane.
//! - **ZI** ([`FlankForm::Involute`]): involute helicoids, the tangents of
//!   a helix on the base cylinder: straight in every plane tangent to that
//!   cylinder, an involute of the base circle in every section normal to
//!   the axis. The base cylinder follows from the normal pressure angle
//!   and the lead angle at the reference radius: `cos gamma_b = cos
//!   alpha_n cos gamma`, `r_b = p / tan gamma_b`.
//!
//! The flanks are symmetric: each stands [`FlankForm::half_space`] from the
//! space's middle along the axis. A left hand's axial section is a right
//! hand's mirror, so the half-space is the same. `p` is the lead over two
//! pi (the helical parameter, taken positive); lengths in mm, angles in
//! radians.
//!
//! The curves are written here from their definitions, not taken from a
//! crate: no maintained Rust crate gives worm flank geometry. The tests
//! hold each against its definition by the inverse way: a ZN section's
//! points, carried along their helices into the tilted plane, lie on one
//! straight line at the normal angle; a ZI section's, carried into a plane
//! tangent to the base cylinder, on one straight line.

use crate::math::Real;
use serde::{Deserialize, Serialize};

/// Newton's step (mm) below which the half-width has converged to the
/// rounding of the half-space it is solved from.
const CONVERGED: Real = 1e-14;

/// The step (mm) of the central difference of the flank's half-space over
/// the radius: the curve is smooth, and the difference is exact to 1e-10.
const CURVE_STEP: Real = 1e-4;

/// How a thread's flanks are generated: see the module's docs.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "form", rename_all = "lowercase")]
pub enum FlankForm {
    /// Straight in the axial section (every standard thread, ZA worms).
    #[default]
    Axial,
    /// ZN: straight in the space's normal section.
    Normal {
        /// The plane's tilt from the axial plane: the lead angle at the
        /// reference radius.
        tilt: Real,
        /// The flanks' angle from the radial direction in that plane.
        angle: Real,
        /// The space's half-width in that plane at the reference radius.
        half_width: Real,
        /// The reference radius (the pitch radius).
        reference: Real,
        /// The helical parameter `p`.
        parameter: Real,
    },
    /// ZI: involute helicoids.
    Involute {
        /// The base cylinder's radius.
        base: Real,
        /// The reference radius (the pitch radius).
        reference: Real,
        /// The space's half-width along the axis at the reference radius.
        half_space: Real,
        /// The helical parameter `p`.
        parameter: Real,
    },
}

impl FlankForm {
    /// The ZN form whose space is `half_space` wide along the axis either
    /// side of its middle at radius `reference`, its flanks at `angle`
    /// (the normal pressure angle) in the normal plane, for the helical
    /// parameter `p`.
    pub fn zn(angle: Real, half_space: Real, reference: Real, p: Real) -> Self {
        let p = p.abs();
        let tilt = (p / reference).atan();
        let form = |half_width| FlankForm::Normal {
            tilt,
            angle,
            half_width,
            reference,
            parameter: p,
        };
        // The normal half-width whose axial half-space at the reference is
        // `half_space`: near half_space cos(tilt), the map nearly linear.
        let mut w = half_space * tilt.cos();
        for _ in 0..50 {
            let g = |w: Real| form(w).half_space(reference).unwrap_or(0.0) - half_space;
            let (g0, dw) = (g(w), crate::tolerance::DERIVATIVE_STEP);
            let slope = (g(w + dw) - g0) / dw;
            let step = g0 / slope;
            w -= step;
            if step.abs() < CONVERGED {
                break;
            }
        }
        form(w)
    }

    /// The ZI form whose space is `half_space` wide along the axis either
    /// side of its middle at radius `reference`, its normal pressure angle
    /// there `angle`, for the helical parameter `p`.
    pub fn zi(angle: Real, half_space: Real, reference: Real, p: Real) -> Self {
        let p = p.abs();
        let lead_angle = (p / reference).atan();
        let base_lead = (angle.cos() * lead_angle.cos()).acos();
        FlankForm::Involute {
            base: p / base_lead.tan(),
            reference,
            half_space,
            parameter: p,
        }
    }

    /// The base cylinder's radius of a ZI form (`None` for any other).
    pub fn base_radius(&self) -> Option<Real> {
        match *self {
            FlankForm::Involute { base, .. } => Some(base),
            _ => None,
        }
    }

    /// How far each flank stands from the space's middle along the axis
    /// at radius `r` (`None` for [`FlankForm::Axial`], whose section's
    /// flank angles give it). A ZI form below its base cylinder has no
    /// flank: there, the half-space at the base.
    pub fn half_space(&self, r: Real) -> Option<Real> {
        match *self {
            FlankForm::Axial => None,
            FlankForm::Normal {
                tilt,
                angle,
                half_width,
                reference,
                parameter,
            } => {
                let (st, ct, ta) = (tilt.sin(), tilt.cos(), angle.tan());
                // The point of the plane's flank line at radius r: u its
                // radial coordinate in the plane, s its distance from the
                // space's middle along the plane (r^2 = u^2 + (s sin t)^2).
                let s = |u: Real| half_width + (u - reference) * ta;
                let mut u = r;
                for _ in 0..50 {
                    let f = u * u + (s(u) * st).powi(2) - r * r;
                    let df = 2.0 * u + 2.0 * s(u) * st * st * ta;
                    let step = f / df;
                    u -= step;
                    if step.abs() < crate::tolerance::ULP * r.abs().max(1.0) {
                        break;
                    }
                }
                // Carried along its helix into the axial section.
                let s = s(u);
                Some(s * ct + parameter * (s * st).atan2(u))
            }
            FlankForm::Involute {
                base,
                reference,
                half_space,
                parameter,
            } => {
                let inv = |r: Real| {
                    let r = r.max(base);
                    ((r / base).powi(2) - 1.0).sqrt() - (base / r).acos()
                };
                Some(half_space + parameter * (inv(r) - inv(reference)))
            }
        }
    }

    /// The flank's angle from the radial direction in the axial section at
    /// radius `r` (`None` for [`FlankForm::Axial`]).
    pub fn axial_angle(&self, r: Real) -> Option<Real> {
        match *self {
            FlankForm::Axial => None,
            FlankForm::Involute {
                base, parameter, ..
            } => {
                let r = r.max(base);
                Some((parameter * (r * r - base * base).sqrt() / (r * base)).atan())
            }
            FlankForm::Normal { .. } => {
                // The curve is smooth: a central difference over 1e-4 mm
                // is exact to 1e-10.
                let h = CURVE_STEP;
                let (a, b) = (self.half_space(r + h)?, self.half_space(r - h)?);
                Some(((a - b) / (2.0 * h)).atan())
            }
        }
    }

    /// The reference radius the form is defined at (`None` for
    /// [`FlankForm::Axial`]).
    pub fn reference(&self) -> Option<Real> {
        match *self {
            FlankForm::Axial => None,
            FlankForm::Normal { reference, .. } | FlankForm::Involute { reference, .. } => {
                Some(reference)
            }
        }
    }

    /// Whether the flanks are straight in the axial section.
    pub fn is_axial(&self) -> bool {
        *self == FlankForm::Axial
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default worm's numbers: m 5, two starts, d1 50, alpha_n 20 deg.
    fn worm() -> (Real, Real, Real, Real) {
        let px = std::f64::consts::PI * 5.0;
        let p = 2.0 * px / std::f64::consts::TAU;
        (20f64.to_radians(), px / 4.0, 25.0, p)
    }

    /// The least-squares line `z = a + b u` through `points` and the
    /// largest distance of a point from it along z.
    fn straightness(points: &[[Real; 2]]) -> (Real, Real) {
        let n = points.len() as Real;
        let (mu, mz) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), p| (a + p[0] / n, b + p[1] / n));
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for p in points {
            sxy += (p[0] - mu) * (p[1] - mz);
            sxx += (p[0] - mu).powi(2);
        }
        let b = sxy / sxx;
        let off = points
            .iter()
            .map(|p| (p[1] - (mz + b * (p[0] - mu))).abs())
            .fold(0.0, Real::max);
        (b, off)
    }

    /// A ZN section's points, each carried along its helix until it meets
    /// the tilted plane through the space's middle, lie on one straight
    /// line there at the normal angle, and the space is as wide as asked
    /// at the reference radius.
    #[test]
    fn a_zn_flank_is_straight_in_the_normal_plane() {
        let (angle, half, r1, p) = worm();
        let form = FlankForm::zn(angle, half, r1, p);
        assert!((form.half_space(r1).unwrap() - half).abs() < 1e-12);
        let tilt = (p / r1).atan();
        let (st, ct) = (tilt.sin(), tilt.cos());
        let points: Vec<[Real; 2]> = (0..=22)
            .map(|i| {
                let r = 19.0 + 0.5 * i as Real;
                let z = form.half_space(r).unwrap();
                // The helix through (r, 0, z): (r cos f, r sin f, z + p f).
                // The plane holds the radial x and (0, -sin t, cos t): its
                // normal is (0, cos t, sin t).
                let g = |f: Real| r * f.sin() * ct + (z + p * f) * st;
                let mut f: Real = 0.0;
                for _ in 0..60 {
                    let d = r * f.cos() * ct + p * st;
                    f -= g(f) / d;
                }
                assert!(g(f).abs() < 1e-12);
                let (y, zz) = (r * f.sin(), z + p * f);
                [r * f.cos(), -y * st + zz * ct]
            })
            .collect();
        let (slope, off) = straightness(&points);
        assert!(off < 1e-9, "{off}");
        assert!(
            (slope.atan() - angle).abs() < 1e-9,
            "{}",
            slope.atan().to_degrees()
        );
        // In the axial section it is a curve: 11.7 um off its chord over
        // the default worm's depth, more than the form tolerance.
        let axial: Vec<[Real; 2]> = (0..=22)
            .map(|i| {
                let r = 19.0 + 0.5 * i as Real;
                [r, form.half_space(r).unwrap()]
            })
            .collect();
        assert!(straightness(&axial).1 > 0.004);
    }

    /// A ZI section's points, each carried along its helix into the plane
    /// tangent to the base cylinder, lie on one straight line there (the
    /// base helix's tangent at the base lead angle), and the axial angle at
    /// the reference radius is DIN 3975's `tan alpha_x = tan alpha_n / cos
    /// gamma`.
    #[test]
    fn a_zi_flank_is_straight_in_a_plane_tangent_to_its_base_cylinder() {
        let (angle, half, r1, p) = worm();
        let form = FlankForm::zi(angle, half, r1, p);
        let rb = form.base_radius().unwrap();
        assert!((rb - 11.858_690).abs() < 1e-6, "{rb}");
        let gamma = (p / r1).atan();
        let want = (angle.tan() / gamma.cos()).atan();
        assert!((form.axial_angle(r1).unwrap() - want).abs() < 1e-12);
        // Through a central difference of the curve too.
        let h = 1e-5;
        let d = (form.half_space(r1 + h).unwrap() - form.half_space(r1 - h).unwrap()) / (2.0 * h);
        assert!((d.atan() - want).abs() < 1e-8);
        let points: Vec<[Real; 2]> = (0..=22)
            .map(|i| {
                let r = 19.0 + 0.5 * i as Real;
                let z = form.half_space(r).unwrap();
                // Along the helix to the plane y = -r_b, where the flank
                // towards +z (its helix going back as it turns) lies.
                let f = -(rb / r).asin();
                [r * f.cos(), z + p * f]
            })
            .collect();
        let (slope, off) = straightness(&points);
        assert!(off < 1e-9, "{off}");
        // The line's slope there is the base helix's: p / r_b along x.
        assert!((slope - p / rb).abs() < 1e-9, "{slope}");
    }

    #[test]
    fn the_axial_form_has_no_curve() {
        assert_eq!(FlankForm::Axial.half_space(20.0), None);
        assert_eq!(FlankForm::Axial.axial_angle(20.0), None);
    }
}
