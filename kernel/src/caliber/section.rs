//! One section of the groove through the roll's axis: half an ellipse
//! (MATH §3.1), its edges, where the table gives it, rounded into the
//! roll's periphery by a circle tangent to both.
//!
//! The section is a curve of one parameter `psi` from -90 to 90 deg. On
//! the ellipse `psi` is the polar angle about its centre, from the depth
//! direction (S001-3), as the seed has it. With a rounding of radius `r`
//! the ellipse runs to the point where the rounding touches it, at polar
//! angle `psi_t`; from there to 90 deg `psi` runs evenly along the
//! rounding's arc, from that point to where it touches the periphery,
//! `edge_x` from the middle. The curve keeps its tangent through the
//! joint, so the groove's normal, the wheel's pose and the seed's model
//! follow it without a special case.

use crate::math::Real;
use crate::profile::{EllipseSection, ProfileError};
use std::f64::consts::FRAC_PI_2;

/// A section of the groove: the ellipse, and the rounding of its edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrooveSection {
    /// Half-width `B/2` and depth `Hp` of the ellipse (mm).
    pub ellipse: EllipseSection,
    /// The edge's rounding radius (mm), if it has one: where it meets the
    /// ellipse is found when asked (most points lie deeper than it, on the
    /// ellipse, and need not know).
    edge_r: Option<Real>,
}

/// Where a rounding of radius `r` meets the ellipse and the periphery.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rounding {
    /// Its radius (mm).
    r: Real,
    /// The polar angle of the point it touches the ellipse at (rad).
    psi_t: Real,
    /// The ellipse's eccentric angle there (rad): `x = a sin t`,
    /// `z = b cos t`.
    t: Real,
    /// The normal's angle there, from the depth direction (rad).
    phi_t: Real,
    /// Its centre along the roll's axis (mm); it lies `r` deep.
    x_c: Real,
}

/// Iterations the tangent point may take (bracketed Newton: some five in
/// practice; 200 reach any double even halving the bracket).
const MAX_ITERATIONS: usize = 200;

impl GrooveSection {
    /// The section of half-width `a`, depth `b` (mm), its edges rounded by
    /// `edge_r` (mm) if given.
    ///
    /// # Failures
    /// A size or a rounding not positive and finite.
    pub fn new(a: Real, b: Real, edge_r: Option<Real>) -> Result<Self, ProfileError> {
        let ellipse = EllipseSection::new(a, b)?;
        if let Some(r) = edge_r {
            crate::math::positive("the groove edge's rounding radius r_edge", r)?;
        }
        Ok(Self { ellipse, edge_r })
    }

    /// Half the groove's width where the ellipse meets the periphery,
    /// `B/2` (mm).
    pub fn half_width(&self) -> Real {
        self.ellipse.a
    }

    /// How far from the middle the section meets the roll's periphery
    /// (mm): `B/2`, or where the rounding touches it.
    pub fn edge_x(&self) -> Real {
        self.rounding().map_or(self.ellipse.a, |r| r.x_c)
    }

    /// The edge's rounding radius (mm), if it has one.
    pub fn edge_rounding(&self) -> Option<Real> {
        self.edge_r
    }

    /// Where the rounding meets the ellipse and the periphery.
    fn rounding(&self) -> Option<Rounding> {
        self.edge_r.map(|r| Rounding::of(&self.ellipse, r))
    }

    /// The polar angle (rad) beyond which, either side, the section is the
    /// edge's rounding: 90 deg for a sharp edge.
    pub fn rounding_from(&self) -> Real {
        self.rounding().map_or(FRAC_PI_2, |r| r.psi_t)
    }

    /// The point at `psi` (rad): `(x_A, z_A)`, along the roll's axis and
    /// depth from the periphery.
    pub fn point(&self, psi: Real) -> (Real, Real) {
        match self.on_rounding(psi) {
            None => self.ellipse.point(psi),
            Some((r, phi)) => (
                psi.signum() * (r.x_c - r.r * phi.sin()),
                r.r * (1.0 - phi.cos()),
            ),
        }
    }

    /// The angle of the normal at `psi` (into the roll's material, from
    /// the depth direction; S001-6 on the ellipse, toward the rounding's
    /// centre on it).
    pub fn normal_angle(&self, psi: Real) -> Real {
        match self.on_rounding(psi) {
            None => self.ellipse.normal_angle(psi),
            Some((_, phi)) => psi.signum() * phi,
        }
    }

    /// The smallest radius of curvature of the section's concave part,
    /// the ellipse (mm): the largest a wheel's rounding may be. The
    /// ellipse's curvature radius `(a^2 cos^2 t + b^2 sin^2 t)^1.5 / (a b)`
    /// changes monotonically from the bottom to the edge, so the smallest
    /// is at one of the two ends the section keeps; the edge's rounding is
    /// convex and bounds no wheel.
    pub fn min_curvature_radius(&self) -> Real {
        let (a, b) = (self.ellipse.a, self.ellipse.b);
        let t = self.rounding().map_or(FRAC_PI_2, |r| r.t);
        let at_t = ((a * t.cos()).powi(2) + (b * t.sin()).powi(2)).powf(1.5) / (a * b);
        (a * a / b).min(at_t)
    }

    /// Where the section's concave part is most curved (rad of psi): the
    /// bottom, or where the ellipse ends.
    pub fn tightest_psi(&self) -> Real {
        let (a, b) = (self.ellipse.a, self.ellipse.b);
        if a * a / b <= self.min_curvature_radius() {
            0.0
        } else {
            self.rounding_from()
        }
    }

    /// The rounding and the normal's angle `phi` on it at `psi`, if `psi`
    /// lies on it: `phi` runs evenly from `phi_t` at `psi_t` to 0 at 90
    /// deg (on past 90 deg along the same circle, for the derivatives).
    fn on_rounding(&self, psi: Real) -> Option<(Rounding, Real)> {
        // The rounding touches the ellipse at most its radius deep (its
        // centre is that deep), and the ellipse rises toward the edge: a
        // point deeper lies before it.
        if self.ellipse.point(psi).1 > self.edge_r? {
            return None;
        }
        let r = self.rounding()?;
        let p = psi.abs();
        (p > r.psi_t).then(|| {
            let u = (p - r.psi_t) / (FRAC_PI_2 - r.psi_t);
            (r, r.phi_t * (1.0 - u))
        })
    }

    /// The step of `psi` (rad) on the rounding that moves the normal by
    /// `dphi` (rad): how finely passes must run there. `None` for a sharp
    /// edge.
    pub fn rounding_psi_step(&self, dphi: Real) -> Option<Real> {
        self.rounding()
            .map(|r| dphi * (FRAC_PI_2 - r.psi_t) / r.phi_t)
    }
}

impl Rounding {
    /// The circle of radius `r` tangent to the periphery (`z = 0`) and,
    /// from outside, to the ellipse: its centre lies `r` deep and `r` from
    /// the ellipse along the ellipse's normal at the tangent point,
    /// `f(t) = b cos t + r a cos t / N - r = 0` with
    /// `N = sqrt(b^2 sin^2 t + a^2 cos^2 t)`. `f` falls from `b` at the
    /// bottom to `-r` at the edge (`f' = -b sin t - r a b^2 sin t / N^3`),
    /// so the root is one, found by Newton's method kept in its bracket.
    fn of(e: &EllipseSection, r: Real) -> Self {
        let (a, b) = (e.a, e.b);
        // f and f' at t, from one sine and cosine.
        let eval = |t: Real| {
            let (sin, cos) = t.sin_cos();
            let n = (b * b * sin * sin + a * a * cos * cos).sqrt();
            (
                b * cos + r * a * cos / n - r,
                -b * sin - r * a * b * b * sin / (n * n * n),
            )
        };
        // The bracket's ends, (t, f, f'): f(0) = b, f(pi/2) = -r. Newton's
        // step from the end nearer the root (smaller |f|), else halving:
        // from the far end it overshoots the bracket where f bends away.
        let mut lo = (0.0, b, 0.0);
        let mut hi = (FRAC_PI_2, -r, -b - r * a / b);
        let mut t = FRAC_PI_2;
        for _ in 0..MAX_ITERATIONS {
            let near = if lo.1.abs() < hi.1.abs() { lo } else { hi };
            let newton = near.0 - near.1 / near.2;
            let next = if newton > lo.0 && newton < hi.0 && near.2 != 0.0 {
                newton
            } else {
                0.5 * (lo.0 + hi.0)
            };
            let moved = (next - t).abs();
            t = next;
            let (v, dv) = eval(t);
            if v > 0.0 {
                lo = (t, v, dv);
            } else {
                hi = (t, v, dv);
            }
            if v == 0.0 || moved <= 1e-15 || hi.0 - lo.0 <= 1e-15 {
                break;
            }
        }
        let (x, z) = (a * t.sin(), b * t.cos());
        let phi_t = (b * t.sin()).atan2(a * t.cos());
        Rounding {
            r,
            psi_t: x.atan2(z),
            t,
            phi_t,
            x_c: x + r * phi_t.sin(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rounded() -> GrooveSection {
        GrooveSection::new(20.0, 14.0, Some(3.0)).unwrap()
    }

    #[test]
    fn a_sharp_section_is_the_ellipse() {
        let s = GrooveSection::new(20.0, 14.0, None).unwrap();
        for k in -90..=90 {
            let psi = (k as Real).to_radians();
            assert_eq!(s.point(psi), s.ellipse.point(psi));
            assert_eq!(s.normal_angle(psi), s.ellipse.normal_angle(psi));
        }
        assert_eq!(s.edge_x(), 20.0);
        assert_eq!(s.min_curvature_radius(), s.ellipse.min_curvature_radius());
    }

    #[test]
    fn the_rounding_touches_the_ellipse_and_the_periphery() {
        let s = rounded();
        let r = s.rounding().unwrap();
        let (a, b) = (s.ellipse.a, s.ellipse.b);
        let centre = (r.x_c, r.r);
        // Every point of the rounding is r from its centre; the ellipse
        // points near it are farther (it touches from outside).
        for k in 0..=100 {
            let psi = r.psi_t + (FRAC_PI_2 - r.psi_t) * k as Real / 100.0;
            let (x, z) = s.point(psi);
            let d = (x - centre.0).hypot(z - centre.1);
            assert!((d - 3.0).abs() < 1e-12, "{psi}: {d}");
        }
        for k in 0..=1000 {
            let t = FRAC_PI_2 * k as Real / 1000.0;
            let (x, z) = (a * t.sin(), b * t.cos());
            let d = (x - centre.0).hypot(z - centre.1);
            assert!(
                d >= 3.0 - 1e-12,
                "the ellipse at t = {t} is {d} from the centre"
            );
        }
        // On the periphery at 90 deg, the normal along the depth there.
        let (x, z) = s.point(FRAC_PI_2);
        assert!((x - r.x_c).abs() < 1e-12 && z.abs() < 1e-12);
        assert!(s.normal_angle(FRAC_PI_2).abs() < 1e-12);
        // The joint: the same point and normal from either side.
        let below = s.ellipse.point(r.psi_t);
        let above = s.point(r.psi_t + 1e-12);
        assert!((below.0 - above.0).hypot(below.1 - above.1) < 1e-9);
        assert!((s.ellipse.normal_angle(r.psi_t) - s.normal_angle(r.psi_t + 1e-12)).abs() < 1e-9);
        // Mirrored on the other side.
        let (xl, zl) = s.point(-1.4);
        let (xr, zr) = s.point(1.4);
        assert_eq!((xl, zl), (-xr, zr));
    }

    #[test]
    fn a_round_groove_is_rounded_where_the_circles_meet() {
        // A circle of radius R: the rounding's centre is R + r from the
        // groove's centre and r deep, so it touches at cos(psi_t) = r / (R + r).
        let s = GrooveSection::new(15.0, 15.0, Some(2.0)).unwrap();
        let psi_t = s.rounding_from();
        assert!(
            (psi_t.cos() - 2.0 / 17.0).abs() < 1e-12,
            "{}",
            psi_t.to_degrees()
        );
        assert!((s.edge_x() - (17.0f64 * 17.0 - 4.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn the_rounding_leaves_the_concave_part_its_curvature() {
        // A shallow section is tightest at its edge: the rounding cuts the
        // tightest part off.
        let sharp = GrooveSection::new(20.0, 10.0, None).unwrap();
        let s = GrooveSection::new(20.0, 10.0, Some(2.0)).unwrap();
        assert!(s.min_curvature_radius() > sharp.min_curvature_radius());
        assert_eq!(s.tightest_psi(), s.rounding_from());
        // A deep one at its bottom, with or without.
        let deep = GrooveSection::new(10.0, 20.0, Some(2.0)).unwrap();
        assert_eq!(deep.min_curvature_radius(), 5.0);
        assert_eq!(deep.tightest_psi(), 0.0);
    }

    #[test]
    fn a_rounding_not_positive_is_refused() {
        for r in [0.0, -1.0, Real::NAN] {
            let e = GrooveSection::new(20.0, 14.0, Some(r)).unwrap_err();
            assert!(e.to_string().contains("r_edge"), "{e}");
        }
    }
}
