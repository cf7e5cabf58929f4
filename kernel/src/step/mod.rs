//! Exact solids as STEP files (ISO 10303-21, AP214) for CAD systems.
//!
//! A body of revolution is written as a boundary representation whose
//! lateral faces are `SURFACE_OF_REVOLUTION`s of its section's curves (lines,
//! circular arcs, and cubic Bezier segments for a family's profile, fitted
//! within a stated tolerance by [`profile_section`]), closed by planar end
//! faces: a CAD system reads it as the exact solid, not as facets. (The ends
//! are planes bounded by circles rather than radial lines revolved into
//! faces with a pole: OpenCASCADE, FreeCAD's kernel, loses a sliver round a
//! pole, 1e-4 of a cylinder's volume.)
//!
//! The topology and the file's entities come from `truck-modeling` and
//! `truck-stepio`; this module builds the section, checks it, and writes the
//! file's header itself (truck-stepio 0.3 writes the header's author and
//! organisation lists in doubled parentheses, which OpenCASCADE reports as
//! unresolved, a schema name no reader knows, and the clock's time: the
//! header here names AP214's schema and no time, so that two runs are
//! byte-identical).

mod fit;
mod sweep;

pub use fit::{profile_section, ProfileFit};
pub use sweep::{swept_step, Sections, SweptFit, MAX_CONTROL_POINTS};

use crate::math::{Mat4, Real};
use crate::tool::Wheel;
use std::f64::consts::FRAC_1_SQRT_2;
use truck_modeling::{builder, Point3, Rad, Vector3, Wire};

/// AP214's schema as `FILE_SCHEMA` names it (the entities are AP214's
/// automotive-design ones, which AP203 readers read as well).
pub const SCHEMA: &str = "AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }";

/// The default largest deviation of a solid's B-spline from the family's
/// profile (mm): a micrometre, far below any grinding tolerance.
pub const DEFAULT_TOLERANCE: Real = 1e-3;

/// Errors of exact solids.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// A section that cannot be turned into a solid, and why.
    #[error("body '{body}': {message}")]
    Section {
        /// The body.
        body: String,
        /// What is wrong.
        message: String,
    },
    /// A rejected number.
    #[error(transparent)]
    Input(#[from] crate::input::InputError),
}

/// One piece of a section in the axial plane `(z, r)`, from the end of the
/// piece before it.
#[derive(Debug, Clone, PartialEq)]
pub enum Piece {
    /// A straight line to this point.
    Line([Real; 2]),
    /// A circular arc through `through` to `to`.
    Arc {
        /// A point on the arc between its ends.
        through: [Real; 2],
        /// Its end.
        to: [Real; 2],
    },
    /// Cubic Bezier segments joined end to end (one B-spline curve): three
    /// points each, two control points and the segment's end.
    Cubic(Vec<[Real; 2]>),
}

/// A body of revolution's section about Z: its outline in `(z, r)` from
/// the end face at the lower z to the one at the higher z, off the axis;
/// flat end faces close it.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// The first point: the edge of the lower end face (`r > 0`).
    pub start: [Real; 2],
    /// The pieces in order.
    pub pieces: Vec<Piece>,
}

impl Section {
    /// Every point the section names (ends and control points), in order.
    fn points(&self) -> impl Iterator<Item = [Real; 2]> + '_ {
        std::iter::once(self.start).chain(self.pieces.iter().flat_map(|p| match p {
            Piece::Line(to) => vec![*to],
            Piece::Arc { through, to } => vec![*through, *to],
            Piece::Cubic(c) => c.clone(),
        }))
    }

    /// The last point.
    fn end(&self) -> [Real; 2] {
        self.points().last().unwrap_or(self.start)
    }

    /// The signed area the section encloses with the straight line from
    /// its end back to its start (+ counter-clockwise in `(z, r)`), from
    /// its own curves (Green's theorem).
    pub fn area(&self) -> Real {
        let mut sum = 0.0;
        let mut from = self.start;
        // z dr - r dz over a straight line, exact from its ends.
        let line = |a: [Real; 2], b: [Real; 2]| a[0] * b[1] - b[0] * a[1];
        for p in &self.pieces {
            match p {
                Piece::Line(to) => {
                    sum += line(from, *to);
                    from = *to;
                }
                Piece::Arc { through, to } => {
                    let (c, rho, a0, sweep) = arc_of(from, *through, *to);
                    // z dr - r dz round the circle, in closed form.
                    sum += sweep * rho * rho
                        + rho
                            * (c[0] * ((a0 + sweep).sin() - a0.sin())
                                + c[1] * (a0.cos() - (a0 + sweep).cos()));
                    from = *to;
                }
                Piece::Cubic(pts) => {
                    sum += over_beziers(from, pts, |p, d| p[0] * d[1] - p[1] * d[0]);
                    from = pts.last().copied().unwrap_or(from);
                }
            }
        }
        0.5 * (sum + line(from, self.start))
    }

    /// The point `u` (0 to 1) along piece `k` (from 0; the piece after the
    /// last is the closing line back to the start): by length along a
    /// line, by angle along an arc, by the curve's parameter across a
    /// Bezier piece's segments.
    pub fn point_on(&self, k: usize, u: Real) -> [Real; 2] {
        let mut from = self.start;
        for p in &self.pieces[..k.min(self.pieces.len())] {
            from = match p {
                Piece::Line(to) | Piece::Arc { to, .. } => *to,
                Piece::Cubic(pts) => pts.last().copied().unwrap_or(from),
            };
        }
        let lerp =
            |a: [Real; 2], b: [Real; 2]| [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])];
        match self.pieces.get(k) {
            None => lerp(from, self.start),
            Some(Piece::Line(to)) => lerp(from, *to),
            Some(Piece::Arc { through, to }) => {
                let (c, rho, a0, sweep) = arc_of(from, *through, *to);
                let a = a0 + u * sweep;
                [c[0] + rho * a.cos(), c[1] + rho * a.sin()]
            }
            Some(Piece::Cubic(pts)) => {
                let segments: Vec<[[Real; 2]; 4]> = beziers(from, pts).collect();
                let n = segments.len().max(1) as Real;
                let i = ((u * n).floor() as usize).min(segments.len().saturating_sub(1));
                let t = u * n - i as Real;
                let Some(b) = segments.get(i) else {
                    return from;
                };
                let m = 1.0 - t;
                let w = [m * m * m, 3.0 * m * m * t, 3.0 * m * t * t, t * t * t];
                [0, 1].map(|j| (0..4).map(|q| w[q] * b[q][j]).sum())
            }
        }
    }

    /// The volume of the solid the section sweeps turning about Z, from the
    /// section's own curves: `pi |integral of r^2 dz|` along it (the end
    /// faces and the axis add nothing). Gauss-Legendre quadrature, exact
    /// for the Bezier segments (degree 8) and to rounding for the arcs.
    pub fn volume(&self) -> Real {
        let mut sum = 0.0;
        let mut from = self.start;
        for p in &self.pieces {
            match p {
                Piece::Line(to) => {
                    // r^2 linear in t times dz: Simpson is exact.
                    let m = 0.5 * (from[1] + to[1]);
                    sum +=
                        (to[0] - from[0]) * (from[1].powi(2) + 4.0 * m * m + to[1].powi(2)) / 6.0;
                    from = *to;
                }
                Piece::Arc { through, to } => {
                    let (c, rho, a0, sweep) = arc_of(from, *through, *to);
                    // In 16 stretches: to rounding for any sweep.
                    sum += (0..16)
                        .map(|k| {
                            gauss(|t| {
                                let a = a0 + sweep * (k as Real + t) / 16.0;
                                let r = c[1] + rho * a.sin();
                                let dz = -rho * a.sin() * sweep / 16.0;
                                r * r * dz
                            })
                        })
                        .sum::<Real>();
                    from = *to;
                }
                Piece::Cubic(pts) => {
                    sum += over_beziers(from, pts, |p, d| p[1] * p[1] * d[0]);
                    from = pts.last().copied().unwrap_or(from);
                }
            }
        }
        std::f64::consts::PI * sum.abs()
    }
}

/// An arc's centre `(z, r)`, radius, start angle and signed sweep, the
/// angle measured from +z towards +r.
fn arc_of(a: [Real; 2], m: [Real; 2], b: [Real; 2]) -> ([Real; 2], Real, Real, Real) {
    let (ax, ay, bx, by, cx, cy) = (a[0], a[1], m[0], m[1], b[0], b[1]);
    let d = 2.0 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by));
    let sq = |x: Real, y: Real| x * x + y * y;
    let ux = (sq(ax, ay) * (by - cy) + sq(bx, by) * (cy - ay) + sq(cx, cy) * (ay - by)) / d;
    let uy = (sq(ax, ay) * (cx - bx) + sq(bx, by) * (ax - cx) + sq(cx, cy) * (bx - ax)) / d;
    let ang = |p: [Real; 2]| (p[1] - uy).atan2(p[0] - ux);
    let (a0, am, a1) = (ang(a), ang(m), ang(b));
    let tau = std::f64::consts::TAU;
    let ccw = (am - a0).rem_euclid(tau) < (a1 - a0).rem_euclid(tau);
    let sweep = if ccw {
        (a1 - a0).rem_euclid(tau)
    } else {
        -(a0 - a1).rem_euclid(tau)
    };
    ([ux, uy], (ax - ux).hypot(ay - uy), a0, sweep)
}

/// The Bezier segments of a [`Piece::Cubic`]'s points starting at `from`:
/// each its four control points.
fn beziers(from: [Real; 2], pts: &[[Real; 2]]) -> impl Iterator<Item = [[Real; 2]; 4]> + '_ {
    let starts = std::iter::once(from).chain(pts.iter().skip(2).step_by(3).copied());
    starts
        .zip(pts.chunks_exact(3))
        .map(|(a, seg)| [a, seg[0], seg[1], seg[2]])
}

/// The integral of `f(point, derivative)` along a [`Piece::Cubic`]'s
/// segments from `from`, by Gauss-Legendre on each.
fn over_beziers(
    from: [Real; 2],
    pts: &[[Real; 2]],
    f: impl Fn([Real; 2], [Real; 2]) -> Real,
) -> Real {
    beziers(from, pts)
        .map(|b| {
            gauss(|t| {
                let (p, d) = bezier_at(&b, t);
                f(p, d)
            })
        })
        .sum()
}

/// A cubic Bezier's point and derivative at `t`.
fn bezier_at(b: &[[Real; 2]; 4], t: Real) -> ([Real; 2], [Real; 2]) {
    let s = 1.0 - t;
    let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
    let dw = [
        -3.0 * s * s,
        3.0 * s * (s - 2.0 * t),
        3.0 * t * (2.0 * s - t),
        3.0 * t * t,
    ];
    let mut p = [0.0; 2];
    let mut d = [0.0; 2];
    for k in 0..4 {
        for c in 0..2 {
            p[c] += w[k] * b[k][c];
            d[c] += dw[k] * b[k][c];
        }
    }
    (p, d)
}

/// The integral of `f` over [0, 1] by 8-point Gauss-Legendre (exact for
/// polynomials up to degree 15).
fn gauss(f: impl Fn(Real) -> Real) -> Real {
    const X: [Real; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [Real; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    (0..4)
        .map(|k| 0.5 * W[k] * (f(0.5 + 0.5 * X[k]) + f(0.5 - 0.5 * X[k])))
        .sum()
}

/// The section of a grinding wheel as [`crate::mesh::wheel`] meshes it: in
/// the wheel's own axis frame (its axis along Z, its mid-plane at z = 0),
/// the faces, the rounding arcs and the flat of the periphery.
pub fn wheel_section(w: &Wheel) -> Section {
    let (half, r_out, rho) = (0.5 * w.width, 0.5 * w.diameter, w.rounding_radius);
    let cr = r_out - rho;
    // The arcs' midpoints, at 45 degrees.
    let (s, c) = (FRAC_1_SQRT_2, FRAC_1_SQRT_2);
    let mut pieces = vec![Piece::Arc {
        through: [-half + rho - rho * c, cr + rho * s],
        to: [-half + rho, r_out],
    }];
    if half - rho > 0.0 {
        pieces.push(Piece::Line([half - rho, r_out]));
    }
    pieces.push(Piece::Arc {
        through: [half - rho + rho * c, cr + rho * s],
        to: [half, cr],
    });
    Section {
        start: [-half, cr],
        pieces,
    }
}

/// The section of a cylinder of `radius` along Z from 0 to `length`.
pub fn cylinder_section(radius: Real, length: Real) -> Section {
    Section {
        start: [0.0, radius],
        pieces: vec![Piece::Line([length, radius])],
    }
}

/// Checks a section: finite, on or above the axis, its ends off it, and
/// going from lower to higher z between its ends.
fn check(body: &str, s: &Section) -> Result<(), StepError> {
    let bad = |message: String| StepError::Section {
        body: body.to_owned(),
        message,
    };
    if s.pieces.is_empty() {
        return Err(bad("the section has no pieces".into()));
    }
    for p in s.points() {
        crate::math::all_finite("section point", &p)?;
        if p[1] < 0.0 {
            return Err(bad(format!(
                "the section's point (z {}, r {}) lies below the axis",
                p[0], p[1]
            )));
        }
    }
    let end = s.end();
    if !(s.start[1] > 0.0 && end[1] > 0.0) {
        return Err(bad(format!(
            "the end faces need a radius above zero: the section runs from r = {} (z {}) to r = {} (z {})",
            s.start[1], s.start[0], end[1], end[0]
        )));
    }
    if end[0] <= s.start[0] {
        return Err(bad(format!(
            "the section must end at a higher z than it starts: z {} to {}",
            s.start[0], end[0]
        )));
    }
    if !(s.volume() > 0.0) {
        return Err(bad("the section encloses no area".into()));
    }
    Ok(())
}

/// A point of the section in 3-D: `(z, r)` in the XZ plane.
fn point(p: [Real; 2]) -> Point3 {
    Point3::new(p[1], 0.0, p[0])
}

/// The section's edges from end face to end face: one per line or arc,
/// one per Bezier segment. (One B-spline face of many knots would do, but
/// OpenCASCADE integrates a surface of revolution's mass properties with a
/// fixed number of points per face: FreeCAD reported the mandrel's volume
/// 1.2 % high from one face of 80 segments.)
fn wire(s: &Section) -> Wire {
    let mut from = builder::vertex(point(s.start));
    let mut edges = Vec::with_capacity(s.pieces.len());
    for p in &s.pieces {
        match p {
            Piece::Line(to) => {
                let v = builder::vertex(point(*to));
                edges.push(builder::line(&from, &v));
                from = v;
            }
            Piece::Arc { through, to } => {
                let v = builder::vertex(point(*to));
                edges.push(builder::circle_arc(&from, &v, point(*through)));
                from = v;
            }
            Piece::Cubic(pts) => {
                for seg in pts.chunks_exact(3) {
                    let v = builder::vertex(point(seg[2]));
                    edges.push(builder::bezier(
                        &from,
                        &v,
                        vec![point(seg[0]), point(seg[1])],
                    ));
                    from = v;
                }
            }
        }
    }
    edges.into()
}

/// The STEP file of the solid `section` sweeps turning a full turn about
/// Z, placed by `pose` (a rigid motion), the product named `name`.
///
/// # Failures
/// A section that is not finite, dips below the axis, does not start and
/// end on it, runs backwards or encloses nothing; a pose that is not rigid.
pub fn revolution_step(name: &str, section: &Section, pose: &Mat4) -> Result<String, StepError> {
    check(name, section)?;
    rigid(name, pose)?;
    let mut shell = builder::rsweep(
        &wire(section),
        Point3::new(0.0, 0.0, 0.0),
        Vector3::unit_z(),
        Rad(std::f64::consts::TAU),
    );
    // The end faces: planes on the swept shell's two boundary circles, in
    // a fixed order (the lower end first, each circle starting at angle 0)
    // so that two runs write the same file.
    let mut ends = shell.extract_boundaries();
    let key = |w: &Wire| w.front_vertex().map_or(0.0, |v| v.point().z);
    ends.sort_by(|a, b| key(a).total_cmp(&key(b)));
    for end in ends {
        let mut end = end.inverse();
        let first = (0..end.len())
            .max_by(|&i, &j| {
                let (p, q) = (end[i].front().point(), end[j].front().point());
                p.x.total_cmp(&q.x).then(q.y.total_cmp(&p.y))
            })
            .unwrap_or(0);
        end.rotate_left(first);
        let face = builder::try_attach_plane(&[end]).map_err(|e| StepError::Section {
            body: name.to_owned(),
            message: format!("an end face cannot be made: {e}"),
        })?;
        shell.push(face);
    }
    let solid = truck_modeling::Solid::try_new(vec![shell]).map_err(|e| StepError::Section {
        body: name.to_owned(),
        message: format!("the swept faces do not close a solid: {e}"),
    })?;
    write(name, "a solid of revolution", &solid, pose)
}

/// Refuses a pose that is not a rigid motion.
fn rigid(name: &str, pose: &Mat4) -> Result<(), StepError> {
    let rot = pose.fixed_view::<3, 3>(0, 0);
    let rigid = (rot.transpose() * rot - nalgebra::Matrix3::identity()).amax()
        < crate::tolerance::SAME_RATIO
        && pose
            .row(3)
            .iter()
            .zip([0.0, 0.0, 0.0, 1.0])
            .all(|(a, b)| *a == b);
    if !rigid || !(rot.determinant() > 0.0) {
        return Err(StepError::Section {
            body: name.to_owned(),
            message: "the pose is not a rigid motion".into(),
        });
    }
    Ok(())
}

/// The STEP text of `solid` placed by `pose`, the product named `name`,
/// the file described as `what`.
fn write(
    name: &str,
    what: &str,
    solid: &truck_modeling::Solid,
    pose: &Mat4,
) -> Result<String, StepError> {
    let m = truck_modeling::Matrix4::from(std::array::from_fn::<[Real; 4], 4, _>(|c| {
        std::array::from_fn(|r| pose[(r, c)])
    }));
    let placed = builder::transformed(solid, m);
    let compressed = placed.compress();
    let body = truck_stepio::out::CompleteStepDisplay::new(
        truck_stepio::out::StepModel::from(&compressed),
        truck_stepio::out::StepHeaderDescriptor {
            time_stamp: String::new(),
            ..Default::default()
        },
    )
    .to_string();
    let data = body
        .find("DATA;")
        .map(|i| &body[i..])
        .ok_or_else(|| StepError::Section {
            body: name.to_owned(),
            message: "truck-stepio wrote no DATA section".into(),
        })?;
    let data = data.replacen(
        "PRODUCT('','','',",
        &format!("PRODUCT('{name}','{name}','',"),
        1,
    );
    Ok(format!(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('pilgrim: {name}, {what}'),'2;1');\n\
         FILE_NAME('{name}.step','',('pilgrim'),(''),'truck-stepio 0.3','pilgrim {}','');\n\
         FILE_SCHEMA(('{SCHEMA}'));\nENDSEC;\n{data}",
        crate::version::VERSION
    ))
}

/// The STEP file of a flat blade: the closed outline `section` (its
/// start, pieces back to the start) in the XZ plane (`(z, r)` as for a
/// section of revolution, r along X), `thickness` thick along Y about
/// y = 0, placed by `pose` (a rigid motion), the product named `name`. Its
/// volume is the outline's area times the thickness ([`Section::area`]).
///
/// # Failures
/// An outline that does not close, is not finite or encloses nothing; a
/// thickness not positive; a pose that is not rigid.
pub fn prism_step(
    name: &str,
    section: &Section,
    thickness: Real,
    pose: &Mat4,
) -> Result<String, StepError> {
    let bad = |message: String| StepError::Section {
        body: name.to_owned(),
        message,
    };
    crate::math::positive("blade thickness", thickness)?;
    for p in section.points() {
        crate::math::all_finite("outline point", &p)?;
    }
    let end = section.end();
    if end != section.start {
        return Err(bad(format!(
            "the outline does not close: it ends at (z {}, r {}), not at its start (z {}, r {})",
            end[0], end[1], section.start[0], section.start[1]
        )));
    }
    let area = section.area();
    if !(area.abs() > 0.0) {
        return Err(bad("the outline encloses no area".into()));
    }
    rigid(name, pose)?;
    let mut edges: Vec<truck_modeling::Edge> = wire(section).into_iter().collect();
    // The last edge ends where the first starts: one vertex, not two.
    if let (Some(first), Some(last)) = (edges.first().cloned(), edges.pop()) {
        let curve = last.oriented_curve();
        edges.push(truck_modeling::Edge::new(
            last.front(),
            first.front(),
            curve,
        ));
    }
    let face = builder::try_attach_plane(&[edges.into()])
        .map_err(|e| bad(format!("the outline is not a plane face: {e}")))?;
    let sign = if area > 0.0 { 1.0 } else { -1.0 };
    let face = builder::translated(&face, Vector3::new(0.0, -sign * thickness / 2.0, 0.0));
    let solid = builder::tsweep(&face, Vector3::new(0.0, sign * thickness, 0.0));
    write(name, "a flat blade", &solid, pose)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;
    use std::f64::consts::PI;

    /// A cylinder's and a cone's volumes from their sections.
    #[test]
    fn section_volumes() {
        assert_near!(cylinder_section(3.0, 10.0).volume(), PI * 90.0, 1e-9);
        let cone = Section {
            start: [0.0, 3.0],
            pieces: vec![Piece::Line([10.0, 0.0])],
        };
        assert_near!(cone.volume(), PI * 9.0 * 10.0 / 3.0, 1e-9);
        // A sphere of radius 2 as one arc.
        let sphere = Section {
            start: [-2.0, 0.0],
            pieces: vec![Piece::Arc {
                through: [0.0, 2.0],
                to: [2.0, 0.0],
            }],
        };
        assert_near!(sphere.volume(), 4.0 / 3.0 * PI * 8.0, 1e-9);
        // The cone r = z/2 on [0, 4] as a cubic Bezier (control points on
        // the line): pi z^3/12.
        let c = Section {
            start: [0.0, 0.0],
            pieces: vec![Piece::Cubic(vec![
                [4.0 / 3.0, 2.0 / 3.0],
                [8.0 / 3.0, 4.0 / 3.0],
                [4.0, 2.0],
            ])],
        };
        assert_near!(c.volume(), PI * 64.0 / 12.0, 1e-9);
    }

    /// A wheel with a flat: Pappus's theorem by hand (the rectangle less the
    /// two corners outside the rounding).
    #[test]
    fn wheel_volume_by_pappus() {
        let w = Wheel::new(400.0, 10.0, 50.0).unwrap();
        let (r, rho, b) = (200.0, 10.0, 50.0);
        let corner = rho * rho * (1.0 - PI / 4.0);
        let centroid = r - rho + 2.0 * rho / (3.0 * (4.0 - PI));
        let v = PI * r * r * b - 2.0 * 2.0 * PI * centroid * corner;
        assert_near!(wheel_section(&w).volume(), v, 1e-6);
    }

    /// The file: AP214's header with no clock, the product named, every
    /// entity referred to defined, two writes identical.
    #[test]
    fn file_is_complete_and_repeatable() {
        let w = Wheel::new(400.0, 25.0, 50.0).unwrap();
        let pose = Mat4::new_translation(&crate::math::Vec3::new(200.0, 0.0, 5.0));
        let a = revolution_step("wheel", &wheel_section(&w), &pose).unwrap();
        assert_eq!(
            a,
            revolution_step("wheel", &wheel_section(&w), &pose).unwrap()
        );
        assert!(a.starts_with("ISO-10303-21;\nHEADER;"));
        assert!(a.contains(&format!("FILE_SCHEMA(('{SCHEMA}'));")));
        assert!(a.contains("PRODUCT('wheel','wheel',''"));
        assert!(a.contains("SURFACE_OF_REVOLUTION"));
        assert!(a.trim_end().ends_with("END-ISO-10303-21;"));
        let mut defined = std::collections::BTreeSet::new();
        let mut used = std::collections::BTreeSet::new();
        for line in a.lines() {
            let line = line.trim_start();
            if let Some(rest) = line.strip_prefix('#') {
                if let Some((n, _)) = rest.split_once(" =") {
                    defined.insert(n.parse::<u64>().unwrap());
                }
            }
            for part in line.split('#').skip(1) {
                let n: String = part.chars().take_while(char::is_ascii_digit).collect();
                if !n.is_empty() {
                    used.insert(n.parse::<u64>().unwrap());
                }
            }
        }
        assert!(used.is_subset(&defined), "{:?}", used.difference(&defined));
    }

    /// A blade: its file names the product and describes it; an open
    /// outline is refused.
    #[test]
    fn a_blade_is_a_prism_of_its_outline() {
        let square = Section {
            start: [0.0, 0.0],
            pieces: vec![
                Piece::Line([2.0, 0.0]),
                Piece::Line([2.0, 3.0]),
                Piece::Line([0.0, 3.0]),
                Piece::Line([0.0, 0.0]),
            ],
        };
        assert_near!(square.area(), 6.0, 1e-12);
        let text = prism_step("cutter", &square, 4.0, &Mat4::identity()).unwrap();
        assert!(text.contains("PRODUCT('cutter','cutter',''") && text.contains("a flat blade"));
        let open = Section {
            start: [0.0, 0.0],
            pieces: vec![Piece::Line([2.0, 0.0]), Piece::Line([2.0, 3.0])],
        };
        let e = prism_step("cutter", &open, 4.0, &Mat4::identity()).unwrap_err();
        assert!(e.to_string().contains("does not close"), "{e}");
        // A half disc: straight diameter, arc back.
        let half = Section {
            start: [-1.0, 0.0],
            pieces: vec![
                Piece::Line([1.0, 0.0]),
                Piece::Arc {
                    through: [0.0, 1.0],
                    to: [-1.0, 0.0],
                },
            ],
        };
        assert_near!(half.area(), std::f64::consts::FRAC_PI_2, 1e-12);
    }

    /// Sections that cannot be solids are refused, naming the body.
    #[test]
    fn bad_sections_are_refused() {
        let pointed = Section {
            start: [0.0, 3.0],
            pieces: vec![Piece::Line([10.0, 0.0])],
        };
        let e = revolution_step("part", &pointed, &Mat4::identity()).unwrap_err();
        assert!(
            e.to_string().contains("part") && e.to_string().contains("z 10"),
            "{e}"
        );
        let below = Section {
            start: [0.0, 1.0],
            pieces: vec![Piece::Line([5.0, -1.0]), Piece::Line([10.0, 1.0])],
        };
        assert!(revolution_step("part", &below, &Mat4::identity())
            .unwrap_err()
            .to_string()
            .contains("below the axis"));
        let scaled = Mat4::new_scaling(2.0);
        assert!(
            revolution_step("part", &cylinder_section(1.0, 1.0), &scaled)
                .unwrap_err()
                .to_string()
                .contains("rigid")
        );
    }
}
