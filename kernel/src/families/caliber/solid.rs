//! The caliber as a solid: the roll's sector over the groove tables'
//! angles, the groove cut in its periphery (for `caliber.stl`).

use super::groove::{Groove, GrooveError};
use super::section::{EdgeKind, GrooveSection};
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
/// `R_d`, the groove cut in its middle) carried round the roll's axis (Z),
/// flat ends at the tables' first and last angle. Its section's pieces, in
/// order: up the left face, along the periphery to the groove, the groove
/// (psi from -pi/2 to pi/2: the ellipse, and where the edges are rounded
/// or chamfered the left edge before it and the right one after, each its
/// own piece, a rounding smooth, a chamfer straight), the periphery to the
/// right face, down it, back along the hub; `v` runs over the tables'
/// angles.
#[derive(Debug, Clone, PartialEq)]
pub struct Roll {
    groove: Groove,
    width: Real,
    hub: Real,
}

/// What a piece of the roll's section is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// A straight line between two corners of the section.
    Line(Corner, Corner),
    /// A stretch of the groove.
    Groove(Span),
}

/// A stretch of the groove in a section.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Span {
    /// Edge to edge: a sharp-edged groove.
    Whole,
    /// The ellipse, between the joints of the edges' rounding or chamfer.
    Ellipse,
    /// The left edge's rounding or chamfer, from the periphery.
    LeftEdge,
    /// The right edge's, to the periphery.
    RightEdge,
}

/// The pieces of a section with sharp edges, in order round it.
const SHARP: [Piece; 6] = [
    Piece::Line(Corner::LeftHub, Corner::LeftTop),
    Piece::Line(Corner::LeftTop, Corner::LeftEdge),
    Piece::Groove(Span::Whole),
    Piece::Line(Corner::RightEdge, Corner::RightTop),
    Piece::Line(Corner::RightTop, Corner::RightHub),
    Piece::Line(Corner::RightHub, Corner::LeftHub),
];

/// The pieces of a section whose edges are rounded or chamfered.
const EDGED: [Piece; 8] = [
    Piece::Line(Corner::LeftHub, Corner::LeftTop),
    Piece::Line(Corner::LeftTop, Corner::LeftEdge),
    Piece::Groove(Span::LeftEdge),
    Piece::Groove(Span::Ellipse),
    Piece::Groove(Span::RightEdge),
    Piece::Line(Corner::RightEdge, Corner::RightTop),
    Piece::Line(Corner::RightTop, Corner::RightHub),
    Piece::Line(Corner::RightHub, Corner::LeftHub),
];

/// A corner of the roll's section.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Corner {
    LeftHub,
    LeftTop,
    LeftEdge,
    RightEdge,
    RightTop,
    RightHub,
}

impl Roll {
    /// The roll of `groove` with a rim `width` wide from radius `hub`.
    ///
    /// # Failures
    /// A width not wider than every section's groove, its edges included;
    /// a hub not inside the groove's deepest point.
    pub fn new(groove: &Groove, width: Real, hub: Real) -> Result<Self, SolidError> {
        let r_d = groove.roll_radius();
        let (widest, deepest) = extremes(groove)?;
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

    /// The section's pieces, in order round it.
    fn pieces_list(&self) -> &'static [Piece] {
        if self.groove.edge().is_some() {
            &EDGED
        } else {
            &SHARP
        }
    }

    /// Whether a stretch of the groove is straight in every section: a
    /// chamfer (its corners are its ends).
    fn straight_span(&self, span: Span) -> bool {
        matches!(span, Span::LeftEdge | Span::RightEdge)
            && matches!(self.groove.edge(), Some((EdgeKind::Chamfer, _)))
    }

    /// The stretch `span` of the groove in the section `s`: psi from and
    /// to (rad).
    fn psi_range(s: &GrooveSection, span: Span) -> (Real, Real) {
        use std::f64::consts::FRAC_PI_2;
        let e = s.edge_from();
        match span {
            Span::Whole => (-FRAC_PI_2, FRAC_PI_2),
            Span::Ellipse => (-e, e),
            Span::LeftEdge => (-FRAC_PI_2, -e),
            Span::RightEdge => (e, FRAC_PI_2),
        }
    }

    /// The points `(x, rho)` of the stretch `span` of the section at
    /// `theta` at each of `at` across it, fractions `(j, n)` of its range
    /// (`j / n`, taken as `(to - from) * j / n`): evenly in psi, or along
    /// the straight chord of a chamfer (psi stands at each of its corners
    /// while the normal turns). NaN where the section cannot be evaluated.
    fn span_points(&self, theta: Real, span: Span, at: &[(Real, Real)]) -> Vec<(Real, Real)> {
        let Ok(s) = self.groove.section(theta) else {
            return vec![(Real::NAN, Real::NAN); at.len()];
        };
        let r_d = self.groove.roll_radius();
        let point = |psi: Real| {
            let (x, z) = s.point(psi);
            (x, r_d - z)
        };
        let (from, to) = Self::psi_range(&s, span);
        if self.straight_span(span) {
            let (a, b) = (point(from), point(to));
            at.iter()
                .map(|&(j, n)| {
                    let u = j / n;
                    (a.0 + u * (b.0 - a.0), a.1 + u * (b.1 - a.1))
                })
                .collect()
        } else {
            at.iter()
                .map(|&(j, n)| point(from + (to - from) * j / n))
                .collect()
        }
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

    /// A corner of the section at `theta`, `(x, rho)`.
    fn corner(&self, c: Corner, theta: Real) -> (Real, Real) {
        use std::f64::consts::FRAC_PI_2;
        let (half, r_d, hub) = (self.width / 2.0, self.groove.roll_radius(), self.hub);
        match c {
            Corner::LeftHub => (-half, hub),
            Corner::LeftTop => (-half, r_d),
            Corner::LeftEdge => self.groove_at(theta, -FRAC_PI_2),
            Corner::RightEdge => self.groove_at(theta, FRAC_PI_2),
            Corner::RightTop => (half, r_d),
            Corner::RightHub => (half, hub),
        }
    }

    /// The roll as a closed triangle mesh in its frame, sampled so that its
    /// chords stay within `tol` of the groove and the periphery (each
    /// section's ellipse with the same number of points, evenly in psi, the
    /// widest section setting it; each rounding likewise, the largest
    /// setting it; a chamfer by its ends).
    ///
    /// # Failures
    /// A tolerance not positive, or more triangles than
    /// [`crate::mesh::MAX_TRIANGLES`]; a groove that cannot be evaluated.
    pub fn mesh(&self, tol: Real) -> Result<TriMesh, SolidError> {
        use std::f64::consts::{FRAC_PI_2, PI};
        crate::math::positive("chordal tolerance", tol).map_err(MeshError::from)?;
        let groove = &self.groove;
        let r_d = groove.roll_radius();
        let (widest, deepest) = (max(groove.width()), max(groove.depth()));
        // The ellipse's arc: chords within tol on its tightest curvature;
        // the roundings' (a quarter circle at most) on the smallest.
        let (r_min, _) = groove.min_curvature_radius()?;
        let points =
            |arc: Real, radius: Real| ((arc / (8.0 * tol * radius).sqrt()).ceil() as usize).max(8);
        let n_ellipse = points(PI * (widest / 2.0).max(deepest), r_min);
        // A chamfer is straight in every section: its ends alone.
        let n_edge = match groove.edge() {
            None | Some((EdgeKind::Chamfer, _)) => 1,
            Some((EdgeKind::Rounding, e)) => points(FRAC_PI_2 * max(e), min(e)),
        };
        let (t0, t1) = groove.theta_range();
        let d_theta = (8.0 * tol / r_d).sqrt();
        let n_theta = (((t1 - t0) / d_theta).ceil() as usize).max(2);
        let pieces = self.pieces_list();
        // Points of each piece in a ring: the ellipse's (from edge to edge,
        // or between the edges' joints) or an edge's; a line's start.
        let points_of = |p: &Piece| match *p {
            Piece::Line(..) => 1,
            Piece::Groove(Span::Whole | Span::Ellipse) => n_ellipse,
            Piece::Groove(_) => n_edge,
        };
        let per_ring: usize = pieces.iter().map(points_of).sum();
        crate::mesh::check_triangles(2 * (n_theta + 1) * per_ring, tol)?;
        // Each ring: every piece from its start, up to the next one's.
        let rings = (0..=n_theta)
            .map(|i| {
                let v = i as Real / n_theta as Real;
                let theta = self.theta(v);
                let mut ring = Vec::with_capacity(per_ring);
                for p in pieces {
                    match *p {
                        Piece::Line(a, _) => ring.push(self.xyz(self.corner(a, theta), theta)),
                        Piece::Groove(span) => {
                            let n = points_of(p);
                            let at: Vec<(Real, Real)> =
                                (0..n).map(|j| (j as Real, n as Real)).collect();
                            ring.extend(
                                self.span_points(theta, span, &at)
                                    .into_iter()
                                    .map(|q| self.xyz(q, theta)),
                            );
                        }
                    }
                }
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

    /// The point `(x, rho)` of the section at `theta` in the roll's frame.
    fn xyz(&self, (x, rho): (Real, Real), theta: Real) -> [Real; 3] {
        let (s, c) = theta.sin_cos();
        [rho * c, rho * s, x]
    }
}

impl crate::step::Sections for Roll {
    fn pieces(&self) -> usize {
        self.pieces_list().len()
    }

    fn straight(&self, k: usize) -> bool {
        match self.pieces_list()[k] {
            Piece::Line(..) => true,
            Piece::Groove(span) => self.straight_span(span),
        }
    }

    fn point(&self, k: usize, u: Real, v: Real) -> [Real; 3] {
        let theta = self.theta(v);
        let p = match self.pieces_list()[k] {
            Piece::Line(a, b) => {
                let (a, b) = (self.corner(a, theta), self.corner(b, theta));
                (a.0 + u * (b.0 - a.0), a.1 + u * (b.1 - a.1))
            }
            Piece::Groove(span) => self.span_points(theta, span, &[(u, 1.0)])[0],
        };
        self.xyz(p, theta)
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

/// The widest the groove is, its edges included, and the
/// deepest, over its tables' rows and the midpoints between them (mm).
fn extremes(groove: &Groove) -> Result<(Real, Real), GrooveError> {
    let mut widest = max(groove.width());
    for t in groove.rows_and_midpoints() {
        widest = widest.max(2.0 * groove.section(t)?.edge_x());
    }
    Ok((widest, max(groove.depth())))
}

/// The largest value of a table.
fn max(t: &crate::profile::Profile) -> Real {
    t.x().iter().copied().fold(0.0, Real::max)
}

/// The smallest value of a table.
fn min(t: &crate::profile::Profile) -> Real {
    t.x().iter().copied().fold(Real::INFINITY, Real::min)
}

impl crate::family::SweptSolid for Roll {
    fn sections(&self) -> &dyn crate::step::Sections {
        self
    }
}
