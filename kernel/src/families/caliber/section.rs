//! One section of the groove through the roll's axis: half an ellipse
//! (docs/math.md §3.1), its edges, where the table gives it, rounded or chamfered
//! into the roll's periphery.
//!
//! The section is a curve of one parameter `psi` from -90 to 90 deg. On
//! the ellipse `psi` is the polar angle about its centre, from the depth
//! direction (S001-3), as the seed has it. With an edge the ellipse runs to
//! where the edge meets it, at polar angle `psi_e`; from there to 90 deg
//! `psi` runs evenly along the edge to where it meets the periphery,
//! `edge_x` from the middle:
//!
//! - a rounding of radius `r` is the circle tangent to the ellipse and to
//!   the periphery: the curve keeps its tangent through both joints;
//! - a chamfer `c` x 45 deg is the straight line from the periphery `c`
//!   beyond the ellipse's edge, rising at 45 deg from it, to where it
//!   meets the ellipse (on a straight wall it would take `c` off each
//!   face). Its two corners are convex: a wheel rolls round each, so the
//!   parameter spends part of its range on each corner, the point
//!   standing and the normal turning (as much per degree as a wheel's
//!   centre `c` from it travels, against the line's length).
//!
//! Either way the section's normal turns continuously with `psi`, so the
//! wheel's pose, the seed's model and the passes follow it without a
//! special case.

use crate::input::InputError;
use crate::math::Real;
use crate::profile::{EllipseSection, ProfileError};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// How a groove's edge meets the roll's periphery.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Edge {
    /// Square: the ellipse meets the periphery at its end.
    Sharp,
    /// Rounded by a circle of this radius (mm) tangent to both.
    Rounded(Real),
    /// Chamfered `c` x 45 deg (mm).
    Chamfered(Real),
}

/// The kinds of edge a table may give, by size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeKind {
    /// A rounding, by its radius.
    Rounding,
    /// A 45 deg chamfer, by its leg.
    Chamfer,
}

impl EdgeKind {
    /// The edge of this kind and `size` (mm).
    pub fn of(self, size: Real) -> Edge {
        match self {
            Self::Rounding => Edge::Rounded(size),
            Self::Chamfer => Edge::Chamfered(size),
        }
    }

    /// The size's name in tables and errors.
    pub fn name(self) -> &'static str {
        match self {
            Self::Rounding => "r_edge",
            Self::Chamfer => "c_edge",
        }
    }

    /// What the size is, in words.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Rounding => "the edge's rounding radius",
            Self::Chamfer => "the edge's 45 deg chamfer",
        }
    }
}

/// A section of the groove: the ellipse, and its edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrooveSection {
    /// Half-width `B/2` and depth `Hp` of the ellipse (mm).
    pub ellipse: EllipseSection,
    /// The edges (either side alike).
    edge: Edge,
    /// Where the edge meets the ellipse and the periphery, found once.
    shape: Option<Shape>,
}

/// Where an edge meets the ellipse and the periphery, and how `psi` runs
/// along it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shape {
    /// The rounding of radius `r`.
    Round {
        r: Real,
        /// The polar angle of the point it touches the ellipse at (rad).
        psi_e: Real,
        /// The ellipse's eccentric angle there (rad): `x = a sin t`,
        /// `z = b cos t`.
        t: Real,
        /// The normal's angle there, from the depth direction (rad).
        phi_e: Real,
        /// Its centre along the roll's axis (mm); it lies `r` deep.
        x_c: Real,
    },
    /// The chamfer from the joint `j` on the ellipse to `x_e` on the
    /// periphery.
    Chamfer {
        psi_e: Real,
        t: Real,
        phi_e: Real,
        /// The joint `(x, z)`.
        j: (Real, Real),
        /// Where it meets the periphery.
        x_e: Real,
        /// The shares of the range of `psi` ending the first corner and
        /// the line.
        shares: (Real, Real),
    },
}

impl Shape {
    fn psi_e(&self) -> Real {
        match *self {
            Self::Round { psi_e, .. } | Self::Chamfer { psi_e, .. } => psi_e,
        }
    }

    fn t(&self) -> Real {
        match *self {
            Self::Round { t, .. } | Self::Chamfer { t, .. } => t,
        }
    }
}

/// Iterations the tangent point may take (bracketed Newton: some four in
/// practice; 200 reach any double even halving the bracket).
const MAX_ITERATIONS: usize = 200;

impl GrooveSection {
    /// The section of half-width `a`, depth `b` (mm) with `edge`.
    ///
    /// # Failures
    /// A size not positive and finite; a chamfer meeting the ellipse where
    /// its wall is flatter than 45 deg (a concave corner no wheel
    /// reaches).
    pub fn new(a: Real, b: Real, edge: Edge) -> Result<Self, ProfileError> {
        let ellipse = EllipseSection::new(a, b)?;
        match edge {
            Edge::Sharp => {}
            Edge::Rounded(r) => {
                crate::math::positive("the groove edge's rounding radius r_edge", r)?;
            }
            Edge::Chamfered(c) => {
                crate::math::positive("the groove edge's 45 deg chamfer c_edge", c)?;
            }
        }
        let shape = match edge {
            Edge::Sharp => None,
            Edge::Rounded(r) => Some(rounding(&ellipse, r)),
            Edge::Chamfered(c) => Some(chamfer(&ellipse, c)),
        };
        let s = Self {
            ellipse,
            edge,
            shape,
        };
        if let (Edge::Chamfered(c), Some(Shape::Chamfer { phi_e, j, .. })) = (edge, s.shape()) {
            if !(phi_e > FRAC_PI_4) {
                return Err(InputError::out_of_range(
                    "the groove edge's 45 deg chamfer c_edge (mm)",
                    c,
                    format!(
                        "small enough to meet the groove's wall where it is steeper than 45 deg (it meets it {:.3} mm deep, {:.3} mm from the middle, where the wall is at {:.1} deg: a concave corner)",
                        j.1,
                        j.0,
                        90.0 - phi_e.to_degrees()
                    ),
                )
                .into());
            }
        }
        Ok(s)
    }

    /// Half the groove's width where the ellipse meets the periphery,
    /// `B/2` (mm).
    pub fn half_width(&self) -> Real {
        self.ellipse.a
    }

    /// How far from the middle the section meets the roll's periphery
    /// (mm): `B/2`, or where the edge's rounding or chamfer meets it.
    pub fn edge_x(&self) -> Real {
        match self.shape() {
            None => self.ellipse.a,
            Some(Shape::Round { x_c, .. }) => x_c,
            Some(Shape::Chamfer { x_e, .. }) => x_e,
        }
    }

    /// The edge.
    pub fn edge(&self) -> Edge {
        self.edge
    }

    /// Where the edge meets the ellipse and the periphery.
    fn shape(&self) -> Option<Shape> {
        self.shape
    }

    /// The polar angle (rad) beyond which, either side, the section is the
    /// edge's rounding or chamfer: 90 deg for a sharp edge.
    pub fn edge_from(&self) -> Real {
        self.shape().map_or(FRAC_PI_2, |s| s.psi_e())
    }

    /// The point at `psi` (rad): `(x_A, z_A)`, along the roll's axis and
    /// depth from the periphery.
    pub fn point(&self, psi: Real) -> (Real, Real) {
        match self.on_edge(psi) {
            None => self.ellipse.point(psi),
            Some((x, z, _)) => (psi.signum() * x, z),
        }
    }

    /// The angle of the normal at `psi` (into the roll's material, from
    /// the depth direction; S001-6 on the ellipse).
    pub fn normal_angle(&self, psi: Real) -> Real {
        match self.on_edge(psi) {
            None => self.ellipse.normal_angle(psi),
            Some((_, _, phi)) => psi.signum() * phi,
        }
    }

    /// The smallest radius of curvature of the section's concave part,
    /// the ellipse (mm): the largest a wheel's rounding may be. The
    /// ellipse's curvature radius `(a^2 cos^2 t + b^2 sin^2 t)^1.5 / (a b)`
    /// changes monotonically from the bottom to the edge, so the smallest
    /// is at one of the two ends the section keeps; the edge is convex and
    /// bounds no wheel.
    pub fn min_curvature_radius(&self) -> Real {
        let (a, b) = (self.ellipse.a, self.ellipse.b);
        let t = self.shape().map_or(FRAC_PI_2, |s| s.t());
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
            self.edge_from()
        }
    }

    /// The point on the edge at `psi` (on the positive side: `x`, `z`) and
    /// its normal's angle, if `psi` lies on the edge. On a rounding the
    /// normal's angle runs evenly from the ellipse's at the joint to 0 at
    /// 90 deg (on past 90 deg along the same circle, for the
    /// derivatives); on a chamfer round the first corner, along the line,
    /// round the second.
    fn on_edge(&self, psi: Real) -> Option<(Real, Real, Real)> {
        let shape = self.shape?;
        let p = psi.abs();
        let psi_e = shape.psi_e();
        if p <= psi_e {
            return None;
        }
        let u = (p - psi_e) / (FRAC_PI_2 - psi_e);
        Some(match shape {
            Shape::Round { r, phi_e, x_c, .. } => {
                let phi = phi_e * (1.0 - u);
                (x_c - r * phi.sin(), r * (1.0 - phi.cos()), phi)
            }
            Shape::Chamfer {
                phi_e,
                j,
                x_e,
                shares: (first, line),
                ..
            } => {
                if u <= first {
                    (j.0, j.1, phi_e + (FRAC_PI_4 - phi_e) * u / first)
                } else if u <= line {
                    let v = (u - first) / (line - first);
                    (j.0 + (x_e - j.0) * v, j.1 * (1.0 - v), FRAC_PI_4)
                } else {
                    (x_e, 0.0, FRAC_PI_4 * (1.0 - u) / (1.0 - line))
                }
            }
        })
    }

    /// The step of `psi` (rad) on the edge that keeps the scallop of a
    /// wheel's rounding `r_k` within `rz` (mm): on a rounding the convex
    /// arc's ([`super::step_for_scallop_convex`]), on a chamfer the line's
    /// (circles `s` apart on a flat leave `r_k - sqrt(r_k^2 - s^2 / 4)`;
    /// the corners leave none, the wheel touching the corner itself from
    /// both sides). `None` for a sharp edge.
    ///
    /// # Failures
    /// A radius or `rz` not positive, or `rz` not below `r_k`.
    pub fn edge_psi_step(&self, r_k: Real, rz: Real) -> Result<Option<Real>, InputError> {
        crate::math::positive("wheel rounding radius r_k", r_k)?;
        crate::math::positive("scallop height Rz", rz)?;
        Ok(match self.shape() {
            None => None,
            Some(Shape::Round {
                r, psi_e, phi_e, ..
            }) => {
                let dphi = super::step_for_scallop_convex(r, r_k, rz)?;
                Some(dphi * (FRAC_PI_2 - psi_e) / phi_e)
            }
            Some(Shape::Chamfer {
                psi_e,
                j,
                x_e,
                shares: (first, line),
                ..
            }) => {
                let rz = rz.min(r_k);
                let s = 2.0 * (r_k * r_k - (r_k - rz) * (r_k - rz)).sqrt();
                let length = (x_e - j.0).hypot(j.1);
                Some(s / length * (line - first) * (FRAC_PI_2 - psi_e))
            }
        })
    }
}

/// The circle of radius `r` tangent to the periphery (`z = 0`) and, from
/// outside, to the ellipse: its centre lies `r` deep and `r` from the
/// ellipse along the ellipse's normal at the tangent point,
/// `f(t) = b cos t + r a cos t / N - r = 0` with
/// `N = sqrt(b^2 sin^2 t + a^2 cos^2 t)`. `f` falls from `b` at the bottom
/// to `-r` at the edge (`f' = -b sin t - r a b^2 sin t / N^3`), so the root
/// is one, found by Newton's method kept in its bracket.
fn rounding(e: &EllipseSection, r: Real) -> Shape {
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
    // Newton's method from the edge (f(pi/2) = -r), kept in the bracket
    // [lo, hi] of the root by halving it where a step would leave it;
    // done when a step no longer moves t (some four steps).
    let (mut lo, mut hi) = (0.0, FRAC_PI_2);
    let mut t = FRAC_PI_2;
    let (mut v, mut dv) = (-r, -b - r * a / b);
    for _ in 0..MAX_ITERATIONS {
        let newton = t - v / dv;
        if (newton - t).abs() <= crate::tolerance::ULP
            || v == 0.0
            || hi - lo <= crate::tolerance::ULP
        {
            break;
        }
        t = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        (v, dv) = eval(t);
        if v > 0.0 {
            lo = t;
        } else {
            hi = t;
        }
    }
    let (x, z) = (a * t.sin(), b * t.cos());
    let phi_e = (b * t.sin()).atan2(a * t.cos());
    Shape::Round {
        r,
        psi_e: x.atan2(z),
        t,
        phi_e,
        x_c: x + r * phi_e.sin(),
    }
}

/// How deep the chamfer `c` x 45 deg meets the ellipse: the line
/// `(a + c - s, s)` (`s` deep) from the periphery first meets it at
/// `s^2 (1/a^2 + 1/b^2) - 2 s (a + c) / a^2 + (a + c)^2 / a^2 - 1 = 0`, the
/// smaller root (the line starts outside the ellipse and runs on into or
/// past it, so the root is real).
fn chamfer_depth(e: &EllipseSection, c: Real) -> Real {
    let (a, b) = (e.a, e.b);
    let x_e = a + c;
    let qa = 1.0 / (a * a) + 1.0 / (b * b);
    let qb = -2.0 * x_e / (a * a);
    let qc = x_e * x_e / (a * a) - 1.0;
    let disc = (qb * qb - 4.0 * qa * qc).max(0.0);
    // The smaller root, written so that it does not cancel.
    2.0 * qc / (-qb + disc.sqrt())
}

/// The chamfer `c` x 45 deg: the line from the periphery to where it first
/// meets the ellipse ([`chamfer_depth`]). The range of `psi` beyond the
/// joint is shared by the first corner, the line and the second corner as
/// `c` times each corner's turn against the line's length.
fn chamfer(e: &EllipseSection, c: Real) -> Shape {
    let (a, b) = (e.a, e.b);
    let x_e = a + c;
    let s = chamfer_depth(e, c);
    let j = (x_e - s, s);
    let t = (j.0 / a).clamp(-1.0, 1.0).asin();
    let phi_e = (b * b * j.0).atan2(a * a * j.1);
    let length = std::f64::consts::SQRT_2 * s;
    let (turn_1, turn_2) = (c * (phi_e - FRAC_PI_4).max(0.0), c * FRAC_PI_4);
    let total = turn_1 + length + turn_2;
    Shape::Chamfer {
        psi_e: j.0.atan2(j.1),
        t,
        phi_e,
        j,
        x_e,
        shares: (turn_1 / total, (turn_1 + length) / total),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rounded() -> GrooveSection {
        GrooveSection::new(20.0, 14.0, Edge::Rounded(3.0)).unwrap()
    }

    #[test]
    fn a_sharp_section_is_the_ellipse() {
        let s = GrooveSection::new(20.0, 14.0, Edge::Sharp).unwrap();
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
        let Some(Shape::Round {
            r,
            psi_e: psi_t,
            x_c,
            ..
        }) = s.shape()
        else {
            panic!("a rounded section")
        };
        let (a, b) = (s.ellipse.a, s.ellipse.b);
        let centre = (x_c, r);
        // Every point of the rounding is r from its centre; the ellipse
        // points near it are farther (it touches from outside).
        for k in 0..=100 {
            let psi = psi_t + (FRAC_PI_2 - psi_t) * k as Real / 100.0;
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
        assert!((x - x_c).abs() < 1e-12 && z.abs() < 1e-12);
        assert!(s.normal_angle(FRAC_PI_2).abs() < 1e-12);
        // The joint: the same point and normal from either side.
        let below = s.ellipse.point(psi_t);
        let above = s.point(psi_t + 1e-12);
        assert!((below.0 - above.0).hypot(below.1 - above.1) < 1e-9);
        assert!((s.ellipse.normal_angle(psi_t) - s.normal_angle(psi_t + 1e-12)).abs() < 1e-9);
        // Mirrored on the other side.
        let (xl, zl) = s.point(-1.4);
        let (xr, zr) = s.point(1.4);
        assert_eq!((xl, zl), (-xr, zr));
    }

    #[test]
    fn a_round_groove_is_rounded_where_the_circles_meet() {
        // A circle of radius R: the rounding's centre is R + r from the
        // groove's centre and r deep, so it touches at cos(psi_t) = r / (R + r).
        let s = GrooveSection::new(15.0, 15.0, Edge::Rounded(2.0)).unwrap();
        let psi_t = s.edge_from();
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
        let sharp = GrooveSection::new(20.0, 10.0, Edge::Sharp).unwrap();
        let s = GrooveSection::new(20.0, 10.0, Edge::Rounded(2.0)).unwrap();
        assert!(s.min_curvature_radius() > sharp.min_curvature_radius());
        assert_eq!(s.tightest_psi(), s.edge_from());
        // A deep one at its bottom, with or without.
        let deep = GrooveSection::new(10.0, 20.0, Edge::Rounded(2.0)).unwrap();
        assert_eq!(deep.min_curvature_radius(), 5.0);
        assert_eq!(deep.tightest_psi(), 0.0);
    }

    #[test]
    fn the_chamfer_runs_at_45_deg_and_the_wheel_rolls_round_its_corners() {
        let (a, b, c) = (20.0, 14.0, 1.5);
        let s = GrooveSection::new(a, b, Edge::Chamfered(c)).unwrap();
        let Some(Shape::Chamfer {
            psi_e, phi_e, j, ..
        }) = s.shape()
        else {
            panic!("a chamfered section")
        };
        // The joint on the ellipse and on the line x + z = a + c.
        assert!(((j.0 / a).powi(2) + (j.1 / b).powi(2) - 1.0).abs() < 1e-12);
        assert!((j.0 + j.1 - (a + c)).abs() < 1e-12);
        assert_eq!(s.edge_x(), a + c);
        // Along psi: the joint standing while the normal turns to 45 deg,
        // the line, the periphery's point standing while it turns to 0.
        let mut last = (j.0, j.1, phi_e);
        let mut turned = (0, 0);
        for k in 1..=1000 {
            let psi = psi_e + (FRAC_PI_2 - psi_e) * k as Real / 1000.0;
            let (x, z) = s.point(psi);
            let phi = s.normal_angle(psi);
            assert!((x + z - (a + c)).abs() < 1e-12, "{psi}: off the line");
            assert!(phi <= last.2 + 1e-15, "the normal turns back at {psi}");
            if (x, z) == (last.0, last.1) {
                if z > 0.0 {
                    turned.0 += 1
                } else {
                    turned.1 += 1
                }
            }
            last = (x, z, phi);
        }
        assert!(turned.0 > 10 && turned.1 > 10, "{turned:?}");
        assert_eq!(s.point(FRAC_PI_2), (a + c, 0.0));
        assert_eq!(s.normal_angle(FRAC_PI_2), 0.0);
        // A chamfer reaching where the wall is flatter than 45 deg would
        // leave a concave corner: refused, saying where.
        let e = GrooveSection::new(a, b, Edge::Chamfered(12.0)).unwrap_err();
        assert!(e.to_string().contains("concave corner"), "{e}");
    }

    #[test]
    fn a_size_not_positive_is_refused() {
        for r in [0.0, -1.0, Real::NAN] {
            let e = GrooveSection::new(20.0, 14.0, Edge::Rounded(r)).unwrap_err();
            assert!(e.to_string().contains("r_edge"), "{e}");
            let e = GrooveSection::new(20.0, 14.0, Edge::Chamfered(r)).unwrap_err();
            assert!(e.to_string().contains("c_edge"), "{e}");
        }
    }
}
