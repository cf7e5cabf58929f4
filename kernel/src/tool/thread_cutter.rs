//! The thread cutter: a lathe tool whose section in the worm's axial
//! plane is a trapezoid, its tip `tip_width` wide with both corners
//! rounded by the nose radius, its flanks at their own angles from the
//! radial direction. A full-profile cutter has the worm's half-angle on
//! both flanks and the root's space as its tip; a narrower "universal"
//! one reaches the flanks by the axial offset `a_1z` (docs/math.md §4.4). A form
//! cutter ground to a ZN or ZI worm's curved flanks ([`GroundFlanks`]) is
//! the full-profile trapezoid whose flanks bend out on the curve of the
//! space it was ground for.

use crate::input::InputError;
use crate::math::{positive, Real};
use crate::profile::FlankForm;
use serde::{Deserialize, Serialize};

/// How far a nose arc's chords may stray from it (mm) in the section.
pub const ARC_TOLERANCE: Real = 2e-4;

/// The longest step along the height of a form cutter's curved flank in
/// its section (mm): a ZI flank's curve (module 5) strays at most 0.35 um
/// from its chords, at the root where it bends most; finer steps cost the
/// simulation's booleans and the solid's faces more than they gain.
pub const FORM_STEP: Real = 0.5;

/// A thread cutter's section. Its tracked point is the middle of its tip,
/// its `z` along the worm's axis and `r` radial, away from the axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ThreadCutter {
    /// Width of the tip between the flanks' lines (mm).
    pub tip_width: Real,
    /// Radius of the two tip corners (mm).
    pub nose_radius: Real,
    /// Angle of the left flank (towards -z) from the radial direction (rad).
    pub left_angle: Real,
    /// Angle of the right flank (rad).
    pub right_angle: Real,
    /// Height of the cutting profile above the tip (mm).
    pub height: Real,
    /// It cuts inside a bore, on a boring bar: its tip looks away from the
    /// axis (`r` above then means towards the axis), and the machine's
    /// bodies for tools inside a bore hold it.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub inside: bool,
    /// A form cutter's curved flanks (`None`: straight).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ground: Option<GroundFlanks>,
}

/// The flanks a form cutter is ground to: a worm's space of `form` with
/// the cutter's tip at its root, `root` from the axis. Its flanks there
/// follow the space's; above the tip they stand [`ThreadCutter::bulge`]
/// outside the straight lines at the root's angles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GroundFlanks {
    /// The worm's flank form (curved: ZN or ZI).
    pub form: FlankForm,
    /// The radius of the root it is ground for (mm).
    pub root: Real,
}

impl ThreadCutter {
    /// A cutter from its sizes.
    ///
    /// # Failures
    /// A size not positive and finite (the nose radius may be 0); a flank
    /// angle beyond 45 degrees; nose radii that do not fit on the tip.
    pub fn new(
        tip_width: Real,
        nose_radius: Real,
        left_angle: Real,
        right_angle: Real,
        height: Real,
    ) -> Result<Self, InputError> {
        positive("cutter tip width", tip_width)?;
        crate::math::finite("cutter nose radius", nose_radius)?;
        if nose_radius < 0.0 {
            return Err(InputError::out_of_range(
                "cutter nose radius",
                nose_radius,
                "0 or more",
            ));
        }
        for (what, a) in [
            ("cutter left flank angle", left_angle),
            ("cutter right flank angle", right_angle),
        ] {
            crate::math::finite(what, a)?;
            if !(0.0..=std::f64::consts::FRAC_PI_4).contains(&a) {
                return Err(InputError::out_of_range(
                    format!("{what} (deg)"),
                    a.to_degrees(),
                    "from 0 to 45",
                ));
            }
        }
        positive("cutter height", height)?;
        let c = Self {
            tip_width,
            nose_radius,
            left_angle,
            right_angle,
            height,
            inside: false,
            ground: None,
        };
        let need = c.inset(left_angle) + c.inset(right_angle);
        if need > tip_width {
            return Err(InputError::out_of_range(
                "cutter nose radius",
                nose_radius,
                format!(
                    "small enough that both corners fit on the {tip_width} mm tip (they need {need:.4} mm)"
                ),
            ));
        }
        Ok(c)
    }

    /// The full-profile form cutter for a worm's space of curved `form`
    /// (ZN, ZI) whose root is `root` from the axis: its tip the space's
    /// width there, its flanks the space's, curved, at `nose_radius` and
    /// `height` above the tip.
    ///
    /// # Failures
    /// A straight form (cut with [`Self::new`]'s cutter); those of
    /// [`Self::new`].
    pub fn ground_to(
        form: FlankForm,
        root: Real,
        nose_radius: Real,
        height: Real,
    ) -> Result<Self, InputError> {
        let (Some(half), Some(angle)) = (form.half_space(root), form.axial_angle(root)) else {
            return Err(InputError::out_of_range(
                "form cutter's flanks",
                0.0,
                "curved (ZN or ZI): a straight flank takes the straight cutter",
            ));
        };
        let mut c = Self::new(2.0 * half, nose_radius, angle, angle, height)?;
        c.ground = Some(GroundFlanks { form, root });
        Ok(c)
    }

    /// How far each flank stands outside its straight line (at the tip's
    /// angle) at `h` above the tip: 0 for straight flanks; a form cutter's
    /// curve less its tangent at the tip.
    pub fn bulge(&self, h: Real) -> Real {
        let Some(g) = self.ground else {
            return 0.0;
        };
        match (g.form.half_space(g.root + h), g.form.half_space(g.root)) {
            (Some(a), Some(b)) => a - b - h * self.left_angle.tan(),
            _ => 0.0,
        }
    }

    /// How far a corner's arc starts inside the tip's end: `r (1 - sin a) / cos a`.
    pub(crate) fn inset(&self, angle: Real) -> Real {
        self.nose_radius * (1.0 - angle.sin()) / angle.cos()
    }

    /// The width between the flanks' lines (or curves) at `r` above the
    /// tip.
    pub fn width_at(&self, r: Real) -> Real {
        self.tip_width + r * (self.left_angle.tan() + self.right_angle.tan()) + 2.0 * self.bulge(r)
    }

    /// How far the section reaches from the tip's centre at `h` above the
    /// tip, to the left (-z) and to the right: where its cutting edges
    /// stand at that height (on a flank's line, or on a nose's arc below
    /// the point where the flank touches it; 0 and 0 below the tip).
    pub fn extent_at(&self, h: Real) -> [Real; 2] {
        let r = self.nose_radius;
        let side = |a: Real| {
            if !(h > 0.0) {
                0.0
            } else if h >= r * (1.0 - a.sin()) {
                self.tip_width / 2.0 + h * a.tan() + self.bulge(h)
            } else {
                let centre = self.tip_width / 2.0 - self.inset(a);
                centre + (r * r - (r - h) * (r - h)).max(0.0).sqrt() + self.bulge(h)
            }
        };
        [side(self.left_angle), side(self.right_angle)]
    }

    /// The section as a closed polygon `(z, r)` about the tracked point,
    /// counter-clockwise, up to `top` above the tip (the profile's straight
    /// flanks carried on past `height` if `top` is higher): down the left
    /// flank, round the left corner, along the tip, round the right
    /// corner, up the right flank. Arcs within [`ARC_TOLERANCE`].
    pub fn section(&self, top: Real) -> Vec<[Real; 2]> {
        let w = self.tip_width / 2.0;
        let r = self.nose_radius;
        let mut pts = vec![[w + top * self.right_angle.tan(), top]];
        let arc = |centre: [Real; 2], from: Real, to: Real, pts: &mut Vec<[Real; 2]>| {
            let step = if r > ARC_TOLERANCE {
                2.0 * (1.0 - ARC_TOLERANCE / r).acos()
            } else {
                Real::INFINITY
            };
            let n = (((from - to).abs() / step).ceil() as usize).clamp(1, 256);
            for k in 0..=n {
                let t = from + (to - from) * k as Real / n as Real;
                pts.push([centre[0] + r * t.cos(), centre[1] + r * t.sin()]);
            }
        };
        let half_pi = std::f64::consts::FRAC_PI_2;
        if r > 0.0 {
            arc(
                [w - self.inset(self.right_angle), r],
                -self.right_angle,
                -half_pi,
                &mut pts,
            );
            arc(
                [-(w - self.inset(self.left_angle)), r],
                -half_pi,
                -std::f64::consts::PI + self.left_angle,
                &mut pts,
            );
        } else {
            pts.push([w, 0.0]);
            pts.push([-w, 0.0]);
        }
        pts.push([-w - top * self.left_angle.tan(), top]);
        // Built clockwise (down the right flank): turned round.
        pts.reverse();
        if self.ground.is_some() {
            pts = self.bent(&pts);
        }
        pts
    }

    /// A form cutter's section from its straight one: the flanks in steps
    /// of at most [`FORM_STEP`] along the height, every point moved out by
    /// the bulge at its height (the tip's points, at height 0, stay).
    fn bent(&self, straight: &[[Real; 2]]) -> Vec<[Real; 2]> {
        let mut pts = Vec::with_capacity(straight.len() + 128);
        for (i, &p) in straight.iter().enumerate() {
            if let Some(&q) = straight.get(i + 1) {
                let n = ((q[1] - p[1]).abs() / FORM_STEP).ceil().max(1.0) as usize;
                pts.extend((0..n).map(|k| {
                    let t = k as Real / n as Real;
                    [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
                }));
            } else {
                pts.push(p);
            }
        }
        for p in &mut pts {
            p[0] += p[0].signum() * self.bulge(p[1]);
        }
        pts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The section's corners are tangent to the tip and the flanks, its
    /// area that of the trapezoid less the corners'.
    #[test]
    fn the_section_is_the_rounded_trapezoid() {
        let a = 20f64.to_radians();
        let c = ThreadCutter::new(3.0, 0.5, a, a, 12.0).unwrap();
        let s = c.section(10.0);
        let area: f64 = (0..s.len())
            .map(|i| {
                let (p, q) = (s[i], s[(i + 1) % s.len()]);
                p[0] * q[1] - q[0] * p[1]
            })
            .sum::<f64>()
            / 2.0;
        let trapezoid = 0.5 * (3.0 + c.width_at(10.0)) * 10.0;
        // A corner of interior angle 90 + a rounded by r loses
        // r^2 (tan(phi/2) - phi/2), phi = 90 - a its turning angle.
        let phi = std::f64::consts::FRAC_PI_2 - a;
        let corner = 0.25 * ((phi / 2.0).tan() - phi / 2.0);
        assert!(area > 0.0, "counter-clockwise");
        assert!((area - (trapezoid - 2.0 * corner)).abs() < 5e-4, "{area}");
        // The lowest points are on the tip line, the flank points on their lines.
        assert!(s.iter().all(|p| p[1] >= -1e-12));
        for p in &s {
            if p[1] > 0.5 {
                assert!((p[0].abs() - (1.5 + p[1] * a.tan())).abs() < 1e-9, "{p:?}");
            }
        }
        // The exact outline encloses the same area, less the chords'.
        let exact = crate::blade::cutter_outline(&c, 10.0).area();
        assert!(
            exact >= area && (exact - (trapezoid - 2.0 * corner)).abs() < 1e-9,
            "{exact}"
        );
        // A nose radius that does not fit is refused.
        assert!(ThreadCutter::new(0.5, 0.5, a, a, 5.0).is_err());
    }

    /// The edges' reach at a height is where a horizontal line there
    /// leaves the section, on the nose arcs and on the flanks, each side
    /// at its own angle.
    #[test]
    fn the_edges_reach_is_the_sections() {
        let c = ThreadCutter::new(3.0, 0.5, 20f64.to_radians(), 10f64.to_radians(), 12.0).unwrap();
        let s = c.section(12.0);
        for h in [0.01, 0.05, 0.1, 0.2, 0.4, 1.0, 5.0, 11.0] {
            // The section's crossings of the line r = h, from its edges.
            let mut xs: Vec<f64> = (0..s.len())
                .filter_map(|i| {
                    let (p, q) = (s[i], s[(i + 1) % s.len()]);
                    ((p[1] - h) * (q[1] - h) < 0.0)
                        .then(|| p[0] + (h - p[1]) / (q[1] - p[1]) * (q[0] - p[0]))
                })
                .collect();
            xs.sort_by(f64::total_cmp);
            let [l, r] = c.extent_at(h);
            // The polygon's chords lie within ARC_TOLERANCE inside the arcs.
            let tol = 2.0 * (2.0 * ARC_TOLERANCE * 0.5).sqrt();
            assert!((-xs[0] - l).abs() < tol, "{h}: {} vs {l}", -xs[0]);
            assert!((xs[xs.len() - 1] - r).abs() < tol, "{h}: {} vs {r}", xs[1]);
        }
        assert_eq!(c.extent_at(0.0), [0.0, 0.0]);
    }
}
