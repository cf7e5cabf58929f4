//! A drawing's fillets and chamfers resolved into the lines and arcs they
//! leave: the corner between two lines, rounded by a tangent arc or cut by
//! a line, as the drawing dimensions it (a radius, a chamfer's length).

use super::{Bulge, Segment};
use crate::input::InputError;
use crate::math::{positive, Real};
use crate::profile::ProfileError;

/// The segments from `start` with every fillet and chamfer replaced by
/// what it leaves, each tagged with the index of the segment it came
/// from (for messages): only lines, arcs and laws remain.
///
/// # Failures
/// A fillet or chamfer not between two lines, at no corner (the lines in
/// line), or longer than a line beside it has left: each names its
/// segment and the corner's z.
pub(super) fn resolved(
    start: (Real, Real),
    segments: &[Segment],
) -> Result<Vec<(usize, Segment)>, ProfileError> {
    let mut out: Vec<(usize, Segment)> = Vec::with_capacity(segments.len());
    // Where the last segment pushed starts.
    let mut from = start;
    let mut at = start;
    for (i, seg) in segments.iter().enumerate() {
        match *seg {
            Segment::Fillet { radius } => {
                positive(&format!("segment {i} fillet radius"), radius)?;
                let c = Corner::between(i, from, at, out.last(), segments.get(i + 1))?;
                let t = radius * (0.5 * c.turn.abs()).tan();
                let (t1, t2) = c.cut(i, t, "fillet")?;
                c.trim(&mut out, t1);
                let bulge = if c.turn < 0.0 { Bulge::Out } else { Bulge::In };
                out.push((i, arc(t2, radius, bulge)));
                (from, at) = (t2, t2);
            }
            Segment::Chamfer { length } => {
                positive(&format!("segment {i} chamfer length"), length)?;
                let c = Corner::between(i, from, at, out.last(), segments.get(i + 1))?;
                let (t1, t2) = c.cut(i, length, "chamfer")?;
                c.trim(&mut out, t1);
                out.push((i, Segment::Line { z: t2.0, x: t2.1 }));
                (from, at) = (t2, t2);
            }
            Segment::TangentArc { z, x } => {
                let what =
                    format!("segment {i} (an arc tangent to the line before it, to z = {z})");
                let Some((_, Segment::Line { .. })) = out.last() else {
                    return Err(InputError::out_of_range(what, z, "an arc after a line").into());
                };
                let (dz, dx) = (at.0 - from.0, at.1 - from.1);
                let len = dz.hypot(dx);
                let (cz, cx) = (z - at.0, x - at.1);
                let cross = (dz * cx - dx * cz) / len;
                let chord2 = cz * cz + cx * cx;
                if cross.abs() <= crate::tolerance::SAME_RATIO * chord2.sqrt() {
                    return Err(InputError::out_of_range(
                        what,
                        z,
                        "an end off the line's direction (on it, the arc is the line)",
                    )
                    .into());
                }
                // The centre on the line's normal at `at`, on the side the
                // end turns to: above (concave) where it turns to +x.
                let radius = chord2 / (2.0 * cross.abs());
                let bulge = if cross > 0.0 { Bulge::In } else { Bulge::Out };
                // The shorter arc: the end within half a turn of the tangent.
                if (dz * cz + dx * cx) / len < 0.0 {
                    return Err(InputError::out_of_range(
                        what,
                        z,
                        "an end ahead of the tangent (the arc would turn more than half a turn)",
                    )
                    .into());
                }
                out.push((i, arc((z, x), radius, bulge)));
                (from, at) = ((z, x), (z, x));
            }
            other => {
                from = at;
                at = end_of(&other, at);
                out.push((i, other));
            }
        }
    }
    Ok(out)
}

fn arc(to: (Real, Real), radius: Real, bulge: Bulge) -> Segment {
    Segment::Arc {
        z: to.0,
        x: to.1,
        radius,
        bulge,
    }
}

/// Where a segment starting at `at` ends.
fn end_of(seg: &Segment, at: (Real, Real)) -> (Real, Real) {
    match *seg {
        Segment::Line { z, x } | Segment::Arc { z, x, .. } => (z, x),
        Segment::Law(law) => (at.0 + law.l_r, law.x(law.l_r)),
        Segment::Fillet { .. } | Segment::Chamfer { .. } | Segment::TangentArc { .. } => at,
    }
}

/// A point `(z, x)` of the section (mm).
type Point = (Real, Real);

/// The corner at `at` between the line from `from` and the next line.
struct Corner {
    from: (Real, Real),
    at: (Real, Real),
    to: (Real, Real),
    /// The turn from the first line's direction to the second's (rad;
    /// negative where the slope falls: a convex corner seen from +x).
    turn: Real,
}

impl Corner {
    fn between(
        i: usize,
        from: (Real, Real),
        at: (Real, Real),
        before: Option<&(usize, Segment)>,
        after: Option<&Segment>,
    ) -> Result<Self, ProfileError> {
        let not_lines = || {
            ProfileError::from(InputError::out_of_range(
                format!("segment {i} (a fillet or chamfer at z = {})", at.0),
                at.0,
                "a corner between a line before it and a line after it",
            ))
        };
        let Some((_, Segment::Line { .. })) = before else {
            return Err(not_lines());
        };
        let Some(&Segment::Line { z, x }) = after else {
            return Err(not_lines());
        };
        // The next line must advance; its own check names it otherwise.
        let to = (z, x);
        let a = (at.1 - from.1).atan2(at.0 - from.0);
        let b = (to.1 - at.1).atan2(to.0 - at.0);
        let turn = b - a;
        if turn.abs() <= crate::tolerance::SAME_RATIO {
            return Err(InputError::out_of_range(
                format!("segment {i} (a fillet or chamfer at z = {})", at.0),
                turn,
                "a corner: the lines before and after it are in line",
            )
            .into());
        }
        Ok(Self { from, at, to, turn })
    }

    /// The points `t` back along the first line and `t` along the second.
    fn cut(&self, i: usize, t: Real, what: &str) -> Result<(Point, Point), ProfileError> {
        let (za, xa) = (self.at.0 - self.from.0, self.at.1 - self.from.1);
        let (zb, xb) = (self.to.0 - self.at.0, self.to.1 - self.at.1);
        let (la, lb) = (za.hypot(xa), zb.hypot(xb));
        let room = la.min(lb);
        if t > room || !t.is_finite() {
            return Err(InputError::out_of_range(
                format!(
                    "segment {i}: the {what} at the corner z = {}, x = {} (a turn of {:.4} deg) needs {t:.4} mm along each line",
                    self.at.0,
                    self.at.1,
                    self.turn.abs().to_degrees()
                ),
                t,
                format!("at most {room:.4} mm (the shorter line beside it left)"),
            )
            .into());
        }
        let t1 = (self.at.0 - za / la * t, self.at.1 - xa / la * t);
        let t2 = (self.at.0 + zb / lb * t, self.at.1 + xb / lb * t);
        Ok((t1, t2))
    }

    /// Ends the line before the corner at `t1` (drops it where it is
    /// used up whole).
    fn trim(&self, out: &mut Vec<(usize, Segment)>, t1: (Real, Real)) {
        let used_up =
            (t1.0 - self.from.0).abs() <= crate::tolerance::SAME_RATIO * (1.0 + t1.0.abs());
        if used_up {
            out.pop();
        } else if let Some((_, seg)) = out.last_mut() {
            *seg = Segment::Line { z: t1.0, x: t1.1 };
        }
    }
}
