//! Circular moves (G2 clockwise, G3 counter-clockwise) in the lathe's
//! plane G18, of Z (abscissa) and X (ordinate, on radius), as the
//! dialect's [`ArcReading`] says a program gives them: the centre by I
//! (along X) and K (along Z) from the arc's start, the radius (`CR=`,
//! negative for more than a half turn) or the opening angle (`AR=`, in
//! degrees). The other axes of the block move in proportion to the angle
//! swept, as a control moves them on a helix.
//!
//! A centre whose radius at the end differs from the radius at the start
//! is moved onto the chord's mid-perpendicular, keeping the start's
//! radius, as the 840D corrects it (its alarm 14040 beyond the limits its
//! machine data set); the verification accepts a difference of
//! [`END_MISMATCH`] only, what the rounding of a written number explains.
//!
//! The verification follows an arc by chords whose sagitta is at most
//! [`SAGITTA`] (a hundredth of a micron, far below what a replay reports),
//! each chord a move of the arc's block; an arc that would need more than
//! [`MAX_CHORDS`] is refused. Written here because the G-code crates the
//! project looked at interpolate in the XY plane only, with no control's
//! radius or angle words and no centre correction.
//!
//! [`ArcReading`]: crate::program::post::ArcReading

use super::{Block, ReadMove, Reader, Said, Standing};
use crate::math::Real;
use crate::program::lint::LintError;
use crate::toolpath::Motion;
use pilgrim_plugin_abi::types::Radial;
use std::f64::consts::{PI, TAU};

/// The largest sagitta of a chord an arc is followed by (mm).
pub const SAGITTA: Real = 1e-5;
/// The most chords one arc may take.
pub const MAX_CHORDS: usize = 100_000;
/// The largest difference of an arc's radius at its end from its radius
/// at its start the reader accepts (mm).
pub const END_MISMATCH: Real = 1e-3;

/// How an arc's block gives its circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Circle {
    /// The centre from the start, `[along Z, along X]` (K, I; mm, X on
    /// radius).
    Centre([Real; 2]),
    /// The radius: positive for at most a half turn, negative for more.
    Radius(Real),
    /// The opening angle (deg), in (0, 360).
    Angle(Real),
}

/// The points an arc from `start` to `end` (each `[z, r]`, mm) passes,
/// clockwise in the (z, r) plane where `clockwise`, on `circle`: each
/// chord's end with the fraction of the sweep it stands at, the last
/// `end` itself.
///
/// # Failures
/// A circle that does not join the two points (an end off the centre's
/// circle, a radius shorter than half the chord, the same point by a
/// radius or an angle), a zero radius, an angle outside (0, 360), an arc
/// of more than [`MAX_CHORDS`] chords.
pub fn arc_points(
    start: [Real; 2],
    end: [Real; 2],
    clockwise: bool,
    circle: Circle,
) -> Result<Vec<(Real, [Real; 2])>, String> {
    let (dz, dr) = (end[0] - start[0], end[1] - start[1]);
    let chord = dz.hypot(dr);
    let mid = [0.5 * (start[0] + end[0]), 0.5 * (start[1] + end[1])];
    // The chord's left normal (the centre of a counter-clockwise arc of at
    // most a half turn lies on its left).
    let left = if chord > 0.0 {
        [-dr / chord, dz / chord]
    } else {
        [0.0, 0.0]
    };
    let side = if clockwise { -1.0 } else { 1.0 };
    let same = chord <= crate::tolerance::SAME_LENGTH;
    let centre = match circle {
        Circle::Centre([k, i]) => {
            let c = [start[0] + k, start[1] + i];
            let r0 = (start[0] - c[0]).hypot(start[1] - c[1]);
            let r1 = (end[0] - c[0]).hypot(end[1] - c[1]);
            if !(r0 > crate::tolerance::SAME_LENGTH) {
                return Err("the centre I, K is the arc's start: no circle".into());
            }
            if !((r1 - r0).abs() <= END_MISMATCH) {
                return Err(format!(
                    "the end is {:.4} mm from the centre I, K and the start {:.4} mm: the end is off the circle by {:.4} mm (the reader accepts {END_MISMATCH} mm, the rounding of a written number)",
                    r1,
                    r0,
                    (r1 - r0).abs()
                ));
            }
            if same {
                c
            } else {
                // Onto the mid-perpendicular, the start's radius kept, on
                // the side of the centre written.
                let h = (r0 * r0 - 0.25 * chord * chord).max(0.0).sqrt();
                let s = if (c[0] - mid[0]) * left[0] + (c[1] - mid[1]) * left[1] < 0.0 {
                    -1.0
                } else {
                    1.0
                };
                [mid[0] + s * h * left[0], mid[1] + s * h * left[1]]
            }
        }
        Circle::Radius(radius) => {
            if same {
                return Err(format!(
                    "an arc by its radius ({radius}) that ends where it starts: its circle is not determined"
                ));
            }
            if !(radius.abs() > crate::tolerance::SAME_LENGTH) || !radius.is_finite() {
                return Err(format!("an arc's radius {radius}: not a circle"));
            }
            if !(0.5 * chord <= radius.abs() + END_MISMATCH) {
                return Err(format!(
                    "an arc's radius {radius} is shorter than half the distance from its start to its end ({:.4} mm)",
                    0.5 * chord
                ));
            }
            let h = (radius * radius - 0.25 * chord * chord).max(0.0).sqrt();
            let s = side * radius.signum();
            [mid[0] + s * h * left[0], mid[1] + s * h * left[1]]
        }
        Circle::Angle(deg) => {
            if !(deg > 0.0 && deg < 360.0) {
                return Err(format!(
                    "an arc's opening angle {deg} deg: the control reads an angle between 0 and 360 deg"
                ));
            }
            if same {
                return Err(format!(
                    "an arc by its angle ({deg} deg) that ends where it starts: its circle is not determined"
                ));
            }
            let h = 0.5 * chord / (0.5 * deg.to_radians()).tan();
            [mid[0] + side * h * left[0], mid[1] + side * h * left[1]]
        }
    };
    let radius = (start[0] - centre[0]).hypot(start[1] - centre[1]);
    let a0 = (start[1] - centre[1]).atan2(start[0] - centre[0]);
    let a1 = (end[1] - centre[1]).atan2(end[0] - centre[0]);
    let mut sweep = a1 - a0;
    if same {
        sweep = side * TAU;
    } else if clockwise {
        while sweep >= 0.0 {
            sweep -= TAU;
        }
    } else {
        while sweep <= 0.0 {
            sweep += TAU;
        }
    }
    // The angle a chord of sagitta SAGITTA spans on this radius.
    let step = if SAGITTA >= radius {
        0.5 * PI
    } else {
        2.0 * (1.0 - SAGITTA / radius).acos()
    };
    let chords = (sweep.abs() / step).ceil().max(1.0);
    if !(chords <= MAX_CHORDS as Real) {
        return Err(format!(
            "an arc of radius {radius:.4} mm over {:.1} deg, which the verification would follow by more than {MAX_CHORDS} chords",
            sweep.abs().to_degrees()
        ));
    }
    let n = chords as usize;
    Ok((1..=n)
        .map(|j| {
            let t = j as Real / n as Real;
            if j == n {
                return (1.0, end);
            }
            let a = a0 + sweep * t;
            (
                t,
                [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()],
            )
        })
        .collect())
}

/// An arc's own words in a block, as the dialect names them: its radius
/// and its opening angle, each with the word as written.
#[derive(Debug, Default, Clone)]
pub(super) struct ArcWords {
    /// The radius's word (`CR=`).
    pub radius: Option<(Real, String)>,
    /// The opening angle's word (`AR=`).
    pub angle: Option<(Real, String)>,
}

impl Reader<'_> {
    /// The arc block `b` moves (`clockwise` G2, else G3; `said` its words,
    /// `centre` its I and K where it gives them) from `before` to `going`
    /// (each axis's value where it stands, with the offsets' shifts),
    /// followed by chords each pushed to `out` as a move of the block.
    ///
    /// # Failures
    /// An arc outside the plane G18 of Z and X, before both are written,
    /// given twice over or not at all, with I under diameter programming,
    /// a circle that does not join its ends ([`arc_points`]), a chord's
    /// end outside an axis's travel.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn arc(
        &self,
        at: &mut Standing,
        b: &Block,
        clockwise: bool,
        said: &Said,
        centre: [Option<Real>; 2],
        before: &[Option<Real>],
        going: Vec<Option<Real>>,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let (k, program) = (at.k, self.program);
        let fail = |m: String| self.err(self.place(b, k), m);
        let code = if clockwise { "G2" } else { "G3" };
        let plane = at
            .st
            .plane
            .as_ref()
            .map(|p| p.0)
            .or(program.setup.plane.map(crate::program::post::plane_code));
        if plane.is_some_and(|p| p != 18) {
            return Err(fail(format!(
                "{code} in the plane G{}: the verification follows arcs in G18 (Z and X), the lathe's",
                plane.unwrap_or_default()
            )));
        }
        let radial = if program.setup.radial_axis.is_empty() {
            'X'
        } else {
            program.setup.radial_axis.chars().next().unwrap_or('X')
        };
        let (Some(xi), Some(zi)) = (
            self.names.iter().position(|n| *n == radial),
            self.names.iter().position(|n| *n == 'Z'),
        ) else {
            return Err(fail(format!(
                "{code} on {}, which programs no {radial} and Z",
                program.machine
            )));
        };
        let (Some(x0), Some(z0), Some(x1), Some(z1)) =
            (before[xi], before[zi], going[xi], going[zi])
        else {
            return Err(fail(format!(
                "{code} before {radial} and Z are written (where the arc starts)"
            )));
        };
        // The plane's ordinate on radius.
        let per = if program.setup.radial == Some(Radial::Diameter) {
            0.5
        } else {
            1.0
        };
        let on_diameter = at.st.radial.unwrap_or(per == 0.5);
        let circle = match (centre, &said.arc.radius, &said.arc.angle) {
            ([None, None], Some((r, _)), None) => Circle::Radius(*r),
            ([None, None], None, Some((a, _))) => Circle::Angle(*a),
            ([i, k], None, None) if i.is_some() || k.is_some() => {
                if on_diameter && i.is_some() {
                    return Err(fail(format!(
                        "{code} with I under diameter programming, whose unit for I the control's machine data set; write the arc by its radius (CR=) or under radius programming"
                    )));
                }
                Circle::Centre([k.unwrap_or(0.0), i.unwrap_or(0.0)])
            }
            ([None, None], None, None) => {
                return Err(fail(format!(
                    "{code} without its circle: a centre (I, K), a radius or an opening angle"
                )))
            }
            _ => {
                return Err(fail(format!(
                "{code} with its circle given twice (a centre, a radius and an angle: one of them)"
            )))
            }
        };
        let points = arc_points([z0, x0 * per], [z1, x1 * per], clockwise, circle)
            .map_err(|m| fail(format!("{code}: {m}")))?;
        let (file, via) = self.origin(at);
        let mut first = true;
        for (t, [z, r]) in points {
            let values: Vec<Option<Real>> = (0..going.len())
                .map(|i| match i {
                    _ if i == xi => Some(r / per),
                    _ if i == zi => Some(z),
                    _ => match (before[i], going[i]) {
                        (Some(a), Some(g)) => Some(a + (g - a) * t),
                        (_, g) => g,
                    },
                })
                .collect();
            for (i, v) in values.iter().enumerate() {
                if let Some(v) = v {
                    self.within_travel(b, k, i, *v, *v)?;
                }
            }
            out.push(ReadMove {
                motion: Motion::Linear,
                values,
                feed: at.st.f.unwrap_or_default(),
                spindle: if first { at.speed_next.take() } else { None },
                dwell_s: at.take_dwell(),
                comment: if first { at.pending.take() } else { None },
                number: b.number,
                line: b.line,
                file,
                via,
            });
            first = false;
            at.k += 1;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every chord's end on the circle, each chord's sagitta within
    /// SAGITTA, the sweep's sense as asked.
    fn on_circle(points: &[(Real, [Real; 2])], start: [Real; 2], c: [Real; 2], r: Real, cw: bool) {
        let mut prev = start;
        let mut turned = 0.0;
        for (_, p) in points {
            assert!(((p[0] - c[0]).hypot(p[1] - c[1]) - r).abs() < 1e-9, "{p:?}");
            let chord = (p[0] - prev[0]).hypot(p[1] - prev[1]);
            let sagitta = r - (r * r - 0.25 * chord * chord).sqrt();
            assert!(sagitta <= SAGITTA * (1.0 + 1e-9), "{sagitta}");
            let (a, b) = ([prev[0] - c[0], prev[1] - c[1]], [p[0] - c[0], p[1] - c[1]]);
            turned += (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
            prev = *p;
        }
        assert!(if cw { turned < 0.0 } else { turned > 0.0 }, "{turned}");
    }

    #[test]
    fn a_quarter_by_centre_radius_and_angle_is_one_arc() {
        // From (z 0, r 10) to (z 10, r 0) about (0, 0), clockwise: a
        // quarter turn.
        let (s, e) = ([0.0, 10.0], [10.0, 0.0]);
        let by_centre = arc_points(s, e, true, Circle::Centre([0.0, -10.0])).unwrap();
        let by_radius = arc_points(s, e, true, Circle::Radius(10.0)).unwrap();
        let by_angle = arc_points(s, e, true, Circle::Angle(90.0)).unwrap();
        on_circle(&by_centre, s, [0.0, 0.0], 10.0, true);
        assert_eq!(by_centre.len(), by_radius.len());
        assert_eq!(by_centre.len(), by_angle.len());
        for ((a, b), c) in by_centre.iter().zip(&by_radius).zip(&by_angle) {
            for j in 0..2 {
                assert!((a.1[j] - b.1[j]).abs() < 1e-9 && (a.1[j] - c.1[j]).abs() < 1e-9);
            }
        }
        assert_eq!(by_centre.last().unwrap().1, e);
    }

    #[test]
    fn a_negative_radius_takes_the_long_way() {
        let (s, e) = ([0.0, 10.0], [10.0, 0.0]);
        // Three quarters clockwise about (10, 10).
        let long = arc_points(s, e, true, Circle::Radius(-10.0)).unwrap();
        on_circle(&long, s, [10.0, 10.0], 10.0, true);
        let three_quarters = arc_points(s, e, true, Circle::Angle(270.0)).unwrap();
        assert_eq!(long.len(), three_quarters.len());
        // Counter-clockwise the short way is about (10, 10) too.
        let ccw = arc_points(s, e, false, Circle::Radius(10.0)).unwrap();
        on_circle(&ccw, s, [10.0, 10.0], 10.0, false);
        assert!(long.len() > 2 * ccw.len());
    }

    #[test]
    fn a_full_circle_by_its_centre() {
        let s = [5.0, 20.0];
        let full = arc_points(s, s, false, Circle::Centre([0.0, -5.0])).unwrap();
        on_circle(&full, s, [5.0, 15.0], 5.0, false);
        assert_eq!(full.last().unwrap().1, s);
    }

    #[test]
    fn a_centre_off_by_rounding_is_corrected_and_more_refused() {
        let (s, e) = ([0.0, 10.0], [10.0, 0.0]);
        // The centre written 0.0004 mm off: moved onto the mid-perpendicular.
        let p = arc_points(s, e, true, Circle::Centre([0.0004, -10.0])).unwrap();
        assert_eq!(p.last().unwrap().1, e);
        let m = arc_points(s, e, true, Circle::Centre([0.5, -10.0])).unwrap_err();
        assert!(m.contains("off the circle by"), "{m}");
        for (circle, says) in [
            (Circle::Radius(4.0), "shorter than half the distance"),
            (Circle::Angle(360.0), "between 0 and 360"),
            (Circle::Radius(0.0), "not a circle"),
        ] {
            let m = arc_points(s, e, false, circle).unwrap_err();
            assert!(m.contains(says), "{m}");
        }
        let m = arc_points(s, s, false, Circle::Radius(3.0)).unwrap_err();
        assert!(m.contains("not determined"), "{m}");
        // A radius of 100 m over a half turn needs too many chords.
        let m = arc_points([0.0, 0.0], [0.0, 2e5], false, Circle::Radius(1e5)).unwrap_err();
        assert!(m.contains("chords"), "{m}");
    }
}
