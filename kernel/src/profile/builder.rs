//! A whole part profile chained from lines, arcs and the mandrel law.

mod bands;
mod corners;

use super::{MandrelLaw, Profile, ProfileError};
use crate::input::InputError;
use crate::math::{finite, positive, Real};
use serde::{Deserialize, Serialize};

/// Which way an arc bulges.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Bulge {
    /// Toward +x: convex seen from outside (centre below the arc), like a
    /// rounded shoulder.
    Out,
    /// Toward the axis: concave seen from outside (centre above), like a fillet.
    In,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
enum Segment {
    Line {
        z: Real,
        x: Real,
    },
    Arc {
        z: Real,
        x: Real,
        radius: Real,
        bulge: Bulge,
    },
    Law(MandrelLaw),
    /// The corner between the line before and the line after, rounded by
    /// an arc of this radius tangent to both.
    Fillet {
        radius: Real,
    },
    /// An arc to this point tangent to the line before it, its radius
    /// what the two ends and that tangent make.
    TangentArc {
        z: Real,
        x: Real,
    },
    /// The corner between the line before and the line after, cut by a
    /// straight line from this far back along the one to this far along
    /// the other.
    Chamfer {
        length: Real,
    },
}

/// Chains segments into one profile, left to right along z: lines (a
/// thread's major diameter, a cylinder, a cone), arcs, and the mandrel law.
/// Each segment starts where the previous one ended.
///
/// ```
/// use pilgrim_kernel::{MandrelLaw, ProfileBuilder};
/// let law = MandrelLaw::new(40.0, 48.0, 300.0, 0.01, 2.5).unwrap();
/// let p = ProfileBuilder::start(-80.0, 18.0)
///     .cylinder(40.0)              // threaded tail, at the thread's major radius
///     .line_to(-30.0, 20.0)        // chamfer up to the transition
///     .cylinder(30.0)              // transition cylinder, d = 40
///     .law(law)                    // working part
///     .line_to(360.0, 20.0)        // cone
///     .build(0.001, 1.0)
///     .unwrap();
/// assert_eq!(p.z_range(), (-80.0, 360.0));
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileBuilder {
    start: (Real, Real),
    current: (Real, Real),
    segments: Vec<Segment>,
    /// The elements a drawing tolerances on their own: the segment's index
    /// and the tolerance on its diameter, as written.
    #[serde(default)]
    bands: Vec<(usize, String)>,
    /// The joints a drawing declares tangent: after the segment of each
    /// index.
    #[serde(default)]
    tangent: Vec<usize>,
    /// The arcs given by their centre: the segment's index and how far
    /// its start and its end lie from the centre, as drawn (mm).
    #[serde(default)]
    centred: Vec<(usize, Real, Real)>,
}

/// How far a drawing's arc given by its centre may have its ends at two
/// distances from it (mm): dimensions rounded to a tenth of a micrometre.
const CENTRED_RADII: Real = 1e-4;

/// How far a joint declared tangent may turn (rad): a drawing's
/// dimensions rounded to a micrometre over elements of a few millimetres
/// turn by less.
const TANGENT_TURN: Real = 1e-4;

/// Nodes of one segment with their analytic derivatives.
#[derive(Default)]
struct Nodes {
    z: Vec<Real>,
    x: Vec<Real>,
    d1: Vec<Real>,
    d2: Vec<Real>,
}

impl Nodes {
    fn push(&mut self, z: Real, x: Real, d1: Real, d2: Real) {
        self.z.push(z);
        self.x.push(x);
        self.d1.push(d1);
        self.d2.push(d2);
    }

    /// Appends `other`, merging the shared joint node (kinks get an
    /// infinite second derivative signed by the slope's jump).
    fn append(&mut self, other: Nodes) {
        if self.z.is_empty() {
            *self = other;
            return;
        }
        let last = self.z.len() - 1;
        let (l1, r1) = (self.d1[last], other.d1[0]);
        if (l1 - r1).abs() <= crate::tolerance::SAME_RATIO * (1.0 + l1.abs()) {
            let (l2, r2) = (self.d2[last], other.d2[0]);
            self.d2[last] = if r2.abs() > l2.abs() { r2 } else { l2 };
        } else {
            self.d1[last] = 0.5 * (l1 + r1);
            self.d2[last] = if r1 > l1 {
                Real::INFINITY
            } else {
                Real::NEG_INFINITY
            };
        }
        self.z.extend_from_slice(&other.z[1..]);
        self.x.extend_from_slice(&other.x[1..]);
        self.d1.extend_from_slice(&other.d1[1..]);
        self.d2.extend_from_slice(&other.d2[1..]);
    }
}

impl ProfileBuilder {
    /// Starts at the point `(z, x)`.
    pub fn start(z: Real, x: Real) -> Self {
        Self {
            start: (z, x),
            current: (z, x),
            segments: Vec::new(),
            bands: Vec::new(),
            tangent: Vec::new(),
            centred: Vec::new(),
        }
    }

    /// A straight segment to `(z, x)` (a cone, or a cylinder if x is unchanged).
    pub fn line_to(mut self, z: Real, x: Real) -> Self {
        self.segments.push(Segment::Line { z, x });
        self.current = (z, x);
        self
    }

    /// A cylinder of the given length at the current x.
    pub fn cylinder(self, length: Real) -> Self {
        let (z, x) = self.current;
        self.line_to(z + length, x)
    }

    /// A circular arc of `radius` to `(z, x)`, bulging as `bulge` says (the
    /// shorter of the two arcs). It must be a graph x(z): both ends on the
    /// same side of the centre, neither at a vertical tangent.
    pub fn arc_to(mut self, z: Real, x: Real, radius: Real, bulge: Bulge) -> Self {
        self.segments.push(Segment::Arc {
            z,
            x,
            radius,
            bulge,
        });
        self.current = (z, x);
        self
    }

    /// A circular arc to `(z, x)` about the centre `(cz, cx)`, as a drawing
    /// dimensions an arc by its centre: its radius the end's distance
    /// from the centre, bulging away from it. Refused at [`Self::build`],
    /// naming the segment and both distances, where the current point
    /// lies at another distance from the centre (over 1e-4 mm).
    pub fn arc_about(self, z: Real, x: Real, cz: Real, cx: Real) -> Self {
        let (z0, x0) = self.current;
        let (r0, r1) = ((z0 - cz).hypot(x0 - cx), (z - cz).hypot(x - cx));
        let bulge = if cx < 0.5 * (x0 + x) {
            Bulge::Out
        } else {
            Bulge::In
        };
        let index = self.segments.len();
        let mut b = self.arc_to(z, x, r1, bulge);
        b.centred.push((index, r0, r1));
        b
    }

    /// The mandrel law from the current z over its length L_r. The current x
    /// must be the law's start, `d_min / 2`.
    pub fn law(mut self, law: MandrelLaw) -> Self {
        self.segments.push(Segment::Law(law));
        self.current = (self.current.0 + law.l_r, law.x(law.l_r));
        self
    }

    /// Rounds the corner at the current point, between the line that ends
    /// here and the next segment (a line), by an arc of `radius` tangent to
    /// both, as a drawing's `R` at a corner: convex or concave as the
    /// corner turns. The lines must be long enough for the arc's tangent
    /// length `radius tan(delta / 2)` (`delta` the corner's turn), beside
    /// any other fillet or chamfer on them.
    pub fn fillet(mut self, radius: Real) -> Self {
        self.segments.push(Segment::Fillet { radius });
        self
    }

    /// An arc from the current point to `(z, x)` tangent to the line that
    /// ends here (a drawing's arc dimensioned by its end and "tangent"):
    /// its radius follows, `|chord|^2 / (2 |tangent x chord|)`. Refused,
    /// naming the segment, after anything but a line, or where the end
    /// lies on the line's own direction.
    pub fn tangent_arc_to(mut self, z: Real, x: Real) -> Self {
        self.segments.push(Segment::TangentArc { z, x });
        self.current = (z, x);
        self
    }

    /// Cuts the corner at the current point, between the line that ends
    /// here and the next segment (a line), by a straight line from
    /// `length` back along the first to `length` along the second (a
    /// drawing's chamfer `length x` the bisecting angle; `C1` at a 90
    /// degree shoulder is `chamfer(1.0)`).
    pub fn chamfer(mut self, length: Real) -> Self {
        self.segments.push(Segment::Chamfer { length });
        self
    }

    /// Gives the element that ends here (a line or an arc) its own
    /// tolerance on its diameter (`"h6"`, `"±0.01"`, `"+0.02/-0.01"`; as
    /// [`crate::fits::limits`], the size its larger diameter): both its
    /// ends are moved to the band's middle (the elements beside it meet
    /// them there) and the profile carries the band ([`super::Band`]).
    /// Refused at [`Self::build`], naming the element, after anything but
    /// a line or an arc, after the mandrel law's end, or where two
    /// neighbours would move their shared point to two middles.
    pub fn toleranced(mut self, tolerance: &str) -> Self {
        let last = self.segments.len().checked_sub(1).unwrap_or(usize::MAX);
        self.bands.push((last, tolerance.to_owned()));
        self
    }

    /// Declares the joint at the current point tangent, as a drawing says
    /// an arc meets a line: [`Self::build`] refuses it, naming the joint
    /// and its turn, where the elements meet at an angle (over 1e-4 rad).
    pub fn tangent(mut self) -> Self {
        let last = self.segments.len().checked_sub(1).unwrap_or(usize::MAX);
        self.tangent.push(last);
        self
    }

    /// The end point so far.
    pub fn current(&self) -> (Real, Real) {
        self.current
    }

    /// Samples every segment and joins them.
    ///
    /// `tol` is the chordal tolerance (mm): arcs and the law are sampled so
    /// that the chord between two nodes strays at most `tol` from the curve;
    /// `max_step` caps the distance in z between nodes on every segment.
    ///
    /// # Failures
    /// A non-positive `tol` or `max_step`; a segment that does not advance
    /// in z; an arc that cannot join its ends as a graph; the law not
    /// starting at the current x. Each names the segment's index.
    pub fn build(&self, tol: Real, max_step: Real) -> Result<Profile, ProfileError> {
        positive("profile chordal tolerance", tol)?;
        positive("profile max step", max_step)?;
        finite("profile start z", self.start.0)?;
        finite("profile start x", self.start.1)?;
        if self.segments.is_empty() {
            return Err(InputError::TooFew {
                what: "profile segments".into(),
                got: 0,
                min: 1,
            }
            .into());
        }
        if let Some(&(i, r0, r1)) =
            (self.centred.iter()).find(|c| (c.1 - c.2).abs() > CENTRED_RADII)
        {
            return Err(InputError::out_of_range(
                format!("segment {i}: an arc about its centre ends at a distance (mm) from it"),
                r1,
                format!("the distance its start lies at, {r0} mm (within {CENTRED_RADII} mm): the drawing's centre or one of its ends is off"),
            )
            .into());
        }
        let (start, segments, bands) = bands::aimed(self.start, &self.segments, &self.bands)?;
        let mut all = Nodes::default();
        let mut at = start;
        let mut last = None;
        let mut sources: Vec<super::Source> = Vec::new();
        for (i, seg) in corners::resolved(start, &segments)? {
            let nodes = match seg {
                Segment::Line { z, x } => line(i, at, (z, x), max_step)?,
                Segment::Arc {
                    z,
                    x,
                    radius,
                    bulge,
                } => arc(i, at, (z, x), radius, bulge, tol, max_step)?,
                Segment::Law(law) => {
                    let x0 = law.x(0.0);
                    if (x0 - at.1).abs() > crate::tolerance::SAME_RATIO * (1.0 + x0.abs()) {
                        return Err(ProfileError::Discontinuous {
                            segment: i,
                            z: at.0,
                            x_end: at.1,
                            x_start: x0,
                        });
                    }
                    law_nodes(&law, at.0, tol, max_step)?
                }
                Segment::Fillet { .. } | Segment::Chamfer { .. } | Segment::TangentArc { .. } => {
                    unreachable!("corners and tangent arcs are resolved into lines and arcs")
                }
            };
            if let Some(k) = last.filter(|&k| k != i && self.tangent.contains(&k)) {
                tangent_joint(k, &all, &nodes)?;
            }
            last = Some(i);
            at = (*nodes.z.last().unwrap(), *nodes.x.last().unwrap());
            match sources.last_mut() {
                Some(s) if s.index == i => s.to = at.0,
                _ => sources.push(super::Source {
                    from: nodes.z[0],
                    to: at.0,
                    index: i,
                    label: described(i, &self.segments[i]),
                }),
            }
            all.append(nodes);
        }
        if let Some(&k) =
            (self.tangent.iter()).find(|&&k| k == usize::MAX || k + 1 >= self.segments.len())
        {
            return Err(InputError::out_of_range(
                "a joint declared tangent",
                k.min(self.segments.len()) as Real,
                "after an element and before the next",
            )
            .into());
        }
        Ok(Profile::with_derivatives(all.z, all.x, all.d1, all.d2)?
            .with_bands(bands)
            .with_sources(sources))
    }
}

/// Segment `i` as a message names it (its values as given).
fn described(i: usize, segment: &Segment) -> String {
    let what = match *segment {
        Segment::Line { z, x } => format!("the line to z = {z} mm, x = {x} mm"),
        Segment::Arc { z, x, radius, .. } => {
            format!("the arc of radius {radius} mm to z = {z} mm, x = {x} mm")
        }
        Segment::TangentArc { z, x } => format!("the tangent arc to z = {z} mm, x = {x} mm"),
        Segment::Law(_) => "the mandrel law".to_owned(),
        Segment::Fillet { radius } => format!("the fillet of radius {radius} mm"),
        Segment::Chamfer { length } => format!("the chamfer of {length} mm"),
    };
    format!("segment {i} ({what})")
}

/// The joint after segment `k` between the nodes so far and the next
/// segment's, declared tangent: refused where it turns by more than
/// [`TANGENT_TURN`], naming it, where it is and by how much.
fn tangent_joint(k: usize, before: &Nodes, after: &Nodes) -> Result<(), ProfileError> {
    let (Some(l), Some(r)) = (before.d1.last(), after.d1.first()) else {
        return Ok(());
    };
    let turn = (r.atan() - l.atan()).abs();
    if turn <= TANGENT_TURN {
        return Ok(());
    }
    let z = after.z[0];
    Err(InputError::out_of_range(
        format!("the joint after segment {k} at z = {z} mm, declared tangent, turns by (deg)"),
        turn.to_degrees(),
        format!(
            "at most {} deg: the elements beside it meet at an angle; correct the drawing's element (its radius, centre or end) or drop the tangency",
            TANGENT_TURN.to_degrees()
        ),
    )
    .into())
}

fn advance(segment: usize, from: Real, to: Real) -> Result<(), ProfileError> {
    finite(&format!("segment {segment} end z"), to)?;
    if to <= from {
        return Err(InputError::NotIncreasing {
            what: format!("profile segment {segment} end z"),
            index: segment + 1,
            prev: from,
            value: to,
        }
        .into());
    }
    Ok(())
}

fn line(
    segment: usize,
    a: (Real, Real),
    b: (Real, Real),
    max_step: Real,
) -> Result<Nodes, ProfileError> {
    advance(segment, a.0, b.0)?;
    finite(&format!("segment {segment} end x"), b.1)?;
    let slope = (b.1 - a.1) / (b.0 - a.0);
    let n = super::check_node_count(
        &format!("segment {segment} max step"),
        ((b.0 - a.0) / max_step).ceil().max(1.0),
        max_step,
    )?;
    let mut nodes = Nodes::default();
    for k in 0..=n {
        let t = k as Real / n as Real;
        let (z, x) = if k == n {
            b
        } else {
            (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
        };
        nodes.push(z, x, slope, 0.0);
    }
    Ok(nodes)
}

fn arc(
    segment: usize,
    a: (Real, Real),
    b: (Real, Real),
    r: Real,
    bulge: Bulge,
    tol: Real,
    max_step: Real,
) -> Result<Nodes, ProfileError> {
    advance(segment, a.0, b.0)?;
    finite(&format!("segment {segment} end x"), b.1)?;
    positive(&format!("segment {segment} arc radius"), r)?;
    let (dz, dx) = (b.0 - a.0, b.1 - a.1);
    let chord = dz.hypot(dx);
    let bad = || ProfileError::BadArc {
        segment,
        radius: r,
        chord,
    };
    if 2.0 * r < chord {
        return Err(bad());
    }
    // Centre on the chord's bisector, on the side away from the bulge.
    let h = (r * r - 0.25 * chord * chord).max(0.0).sqrt();
    let (nz, nx) = (-dx / chord, dz / chord); // unit normal toward +x side
    let sign = match bulge {
        Bulge::Out => -1.0,
        Bulge::In => 1.0,
    };
    let (cz, cx) = (
        a.0 + 0.5 * dz + sign * h * nz,
        a.1 + 0.5 * dx + sign * h * nx,
    );
    // Upper half of the circle for Out, lower half for In; ends strictly inside.
    let side = -sign;
    let margin = crate::tolerance::SAME_RATIO * r;
    if (a.1 - cx) * side <= margin || (b.1 - cx) * side <= margin {
        return Err(bad());
    }
    let ang = |p: (Real, Real)| (p.1 - cx).atan2(p.0 - cz);
    let (t0, t1) = (ang(a), ang(b));
    let max_angle = (2.0 * (1.0 - tol / r).clamp(-1.0, 1.0).acos()).min(max_step / r);
    let n = super::check_node_count(
        &format!("segment {segment} chordal tolerance"),
        ((t1 - t0).abs() / max_angle).ceil().max(1.0),
        tol,
    )?;
    let mut nodes = Nodes::default();
    for k in 0..=n {
        let (z, x) = if k == 0 {
            a
        } else if k == n {
            b
        } else {
            let t = t0 + (t1 - t0) * k as Real / n as Real;
            (cz + r * t.cos(), cx + r * t.sin())
        };
        let u = x - cx;
        nodes.push(z, x, -(z - cz) / u, -r * r / (u * u * u));
    }
    Ok(nodes)
}

fn law_nodes(law: &MandrelLaw, z0: Real, tol: Real, max_step: Real) -> Result<Nodes, ProfileError> {
    // Chordal step sqrt(8 tol / max|x''|), the curvature taken away from z = 0
    // where it may be infinite.
    let k = (1..=1000)
        .map(|i| law.d2x(law.l_r * i as Real / 1000.0).abs())
        .fold(0.0, Real::max);
    let step = if k > 0.0 {
        (8.0 * tol / k).sqrt().min(max_step)
    } else {
        max_step
    };
    Ok(law.profile(step, z0)?.into())
}

impl From<Profile> for Nodes {
    fn from(p: Profile) -> Self {
        Self {
            d1: p.slopes().into_owned(),
            d2: p.second_derivatives().into_owned(),
            z: p.z,
            x: p.x,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    #[test]
    fn arcs_are_circles_with_exact_derivatives() {
        let p = ProfileBuilder::start(0.0, 10.0)
            .arc_to(10.0, 10.0, 8.0, Bulge::Out)
            .build(1e-4, 1.0)
            .unwrap();
        // Centre at (5, 10 - sqrt(64 - 25)).
        let cx = 10.0 - 39.0_f64.sqrt();
        for (z, x) in p.z().iter().zip(p.x()) {
            assert_near!((z - 5.0).hypot(x - cx), 8.0, 1e-12);
        }
        for k in p.curvature() {
            assert_near!(k, -1.0 / 8.0, 1e-12);
        }
        let e = ProfileBuilder::start(0.0, 10.0)
            .arc_to(10.0, 10.0, 4.0, Bulge::Out)
            .build(1e-4, 1.0);
        assert!(matches!(e, Err(ProfileError::BadArc { segment: 0, .. })));
    }

    #[test]
    fn kinks_are_marked_and_law_must_meet() {
        let p = ProfileBuilder::start(0.0, 5.0)
            .cylinder(10.0)
            .line_to(20.0, 8.0)
            .build(0.01, 2.0)
            .unwrap();
        let i = p.z().iter().position(|&z| z == 10.0).unwrap();
        assert_eq!(p.second_derivatives()[i], Real::INFINITY); // concave corner
        assert_eq!(p.curvature_radius()[i], 0.0);
        let law = MandrelLaw::new(40.0, 48.0, 300.0, 0.01, 2.5).unwrap();
        let e = ProfileBuilder::start(0.0, 19.0)
            .law(law)
            .build(0.01, 1.0)
            .unwrap_err();
        assert!(
            matches!(e, ProfileError::Discontinuous { segment: 0, .. }),
            "{e}"
        );
        let e = ProfileBuilder::start(0.0, 19.0)
            .line_to(-1.0, 2.0)
            .build(0.01, 1.0)
            .unwrap_err();
        assert!(e.to_string().contains("segment 0"), "{e}");
    }

    #[test]
    fn whole_mandrel_follows_the_law() {
        let law = MandrelLaw::new(40.0, 48.0, 300.0, 0.01, 2.5).unwrap();
        let p = ProfileBuilder::start(-80.0, 18.0)
            .cylinder(40.0)
            .line_to(-30.0, 20.0)
            .cylinder(30.0)
            .law(law)
            .line_to(360.0, 20.0)
            .build(1e-4, 0.5)
            .unwrap();
        for (z, x) in p.z().iter().zip(p.x()) {
            if (0.0..=300.0).contains(z) {
                assert_near!(*x, law.x(*z), 1e-12);
            }
        }
        assert!(p.len() > 600);
    }

    /// A fillet is tangent to both lines it joins (no kink left), at its
    /// radius from one centre; a chamfer leaves two kinks on its line; a
    /// fillet too large for its lines is refused naming the corner.
    #[test]
    fn fillets_and_chamfers_round_and_cut_corners() {
        // A cylinder at x = 10, then a cone falling 30 degrees (convex),
        // then a cylinder at x = 10 - 10 tan 30 (concave).
        let x2 = 10.0 - 10.0 * (30.0_f64).to_radians().tan();
        let p = ProfileBuilder::start(0.0, 10.0)
            .line_to(10.0, 10.0)
            .fillet(3.0)
            .line_to(20.0, x2)
            .fillet(5.0)
            .line_to(30.0, x2)
            .build(1e-5, 1.0)
            .unwrap();
        assert!(p.second_derivatives().iter().all(|d| d.is_finite()));
        let t = 3.0 * (15.0_f64).to_radians().tan();
        // The convex arc's centre lies 3 mm below the first line, above
        // its tangent point.
        let (cz, cx) = (10.0 - t, 7.0);
        let on_arc: Vec<usize> = (0..p.len())
            .filter(|&i| p.z()[i] > 10.0 - t && p.z()[i] < 10.0 + t * 0.8)
            .collect();
        assert!(on_arc.len() > 3);
        for &i in &on_arc {
            assert_near!((p.z()[i] - cz).hypot(p.x()[i] - cx), 3.0, 1e-9);
        }
        assert_near!(p.eval(5.0).unwrap(), 10.0, 1e-12);
        assert_near!(p.eval(25.0).unwrap(), x2, 1e-12);
        // The concave one: curvature +1/5 on its nodes.
        let k = p.curvature();
        let i = p.z().iter().position(|&z| (z - 20.0).abs() < 0.3).unwrap();
        assert_near!(k[i], 0.2, 1e-9);

        let c = ProfileBuilder::start(0.0, 10.0)
            .line_to(10.0, 10.0)
            .chamfer(1.0)
            .line_to(10.5, 5.0)
            .build(1e-5, 1.0)
            .unwrap();
        let kinks = c
            .second_derivatives()
            .iter()
            .filter(|d| d.is_infinite())
            .count();
        assert_eq!(kinks, 2);
        assert_near!(c.eval(9.0).unwrap(), 10.0, 1e-12);

        let e = ProfileBuilder::start(0.0, 10.0)
            .line_to(10.0, 10.0)
            .fillet(40.0)
            .line_to(20.0, x2)
            .build(1e-5, 1.0)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("segment 1: the fillet at the corner z = 10"),
            "{e}"
        );
        assert!(e.contains("30.0000 deg"), "{e}");
        let e = ProfileBuilder::start(0.0, 10.0)
            .line_to(10.0, 10.0)
            .fillet(1.0)
            .line_to(20.0, 10.0)
            .build(1e-5, 1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("in line"), "{e}");
    }

    /// An arc given by its end and "tangent" leaves the line before it
    /// with no kink, at the radius its ends make; an end on the line's
    /// own direction is refused.
    #[test]
    fn a_tangent_arc_leaves_its_line_smoothly() {
        let p = ProfileBuilder::start(0.0, 10.0)
            .line_to(10.0, 10.0)
            .tangent_arc_to(14.0, 8.0)
            .build(1e-6, 1.0)
            .unwrap();
        assert!(p.second_derivatives().iter().all(|d| d.is_finite()));
        // Chord (4, -2): radius 20 / 4 = 5, centre 5 below (10, 10).
        for (z, x) in p.z().iter().zip(p.x()).filter(|(z, _)| **z > 10.0) {
            assert_near!((z - 10.0).hypot(x - 5.0), 5.0, 1e-9);
        }
        let e = ProfileBuilder::start(0.0, 10.0)
            .line_to(10.0, 10.0)
            .tangent_arc_to(14.0, 10.0)
            .build(1e-6, 1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("segment 1 (an arc tangent"), "{e}");
    }
}
