//! The thread cutter's blade as the 3-D models show it (`cutter.stl`,
//! `cutter.step`, the scene): its cutting profile in the plane through
//! the part's axis, and [`BLADE_THICKNESS`] of insert about it.
//!
//! A flat prism of the profile would cut into the thread it stands in:
//! away from the cutting plane the thread's flanks turn with the helix
//! (0.75 mm along the axis 3 mm off the plane at the root of the default
//! worm), so a real insert is tilted to the lead and relieved behind its
//! edges. The blade here follows the thread exactly instead: each section
//! parallel to the cutting plane, `y` off it, is the profile shifted along
//! the axis by the helix at its own radius (`lead atan2(y, rho) / 2 pi`,
//! right-handed for a positive lead) and shrunk towards the top of the
//! profile's centre line by a clearance that grows with `y^2` to
//! [`BLADE_RELIEF_DEG`] at the blade's faces: it touches the thread along
//! its cutting edges only, as the cut it makes.

use crate::math::{Mat4, Point3, Real};
use crate::mesh::{MeshError, TriMesh};
use crate::step::Section;
use crate::tool::ThreadCutter;

/// The blade's thickness across the cutting plane (mm): the cutting
/// profile is its edge; the thickness only shows it.
pub const BLADE_THICKNESS: Real = 6.0;

/// The clearance at the blade's faces: the angle, seen along the cut, by
/// which its tip stands back from the cutting plane's (deg).
pub const BLADE_RELIEF_DEG: Real = 3.0;

/// A thread cutter's blade standing in a thread: see the module docs
/// (`blade`).
#[derive(Debug, Clone)]
pub struct ThreadBlade {
    outline: Section,
    nose_radius: Real,
    top: Real,
    tip_radius: Real,
    lead: Real,
    pose: Mat4,
    /// +1 for a blade cutting from outside (its body away from the axis),
    /// -1 inside a bore (its body towards the axis).
    side: Real,
}

impl ThreadBlade {
    /// The blade of `cutter`, its tip `tip_radius` from the part's axis, in
    /// a thread of `lead` (0 where it stands in none: a flat blade),
    /// placed by `pose` in the part frame.
    pub fn new(cutter: &ThreadCutter, tip_radius: Real, lead: Real, pose: Mat4) -> Self {
        Self {
            outline: cutter_outline(cutter, cutter.height),
            nose_radius: cutter.nose_radius,
            top: cutter.height,
            tip_radius,
            lead,
            pose,
            side: if cutter.inside { -1.0 } else { 1.0 },
        }
    }

    /// How much a section `y` off the cutting plane is shrunk towards the
    /// top of the centre line: 1 at the plane, `1 - c` at the faces, `c`
    /// such that the tip stands back by the relief angle there.
    fn scale(&self, y: Real) -> Real {
        let half = BLADE_THICKNESS / 2.0;
        let c = half * BLADE_RELIEF_DEG.to_radians().tan() / self.top;
        1.0 - c * (y / half).powi(2)
    }

    /// Piece `k`'s point at `u` in the section `y` off the cutting plane, in
    /// the tool frame (x radial from the tip, y across, z along the axis;
    /// the body away from the axis, or towards it inside a bore).
    fn local(&self, k: usize, u: Real, y: Real) -> [Real; 3] {
        let [z, h] = self.outline.point_on(k, u);
        let s = self.scale(y);
        let h = self.top + s * (h - self.top);
        let rho = self.tip_radius + self.side * h;
        let shift = self.lead * y.atan2(rho) / std::f64::consts::TAU;
        [self.side * h, y, s * z + shift]
    }

    /// The blade's volume (mm^3): each section's area (the helix's shift
    /// along the axis keeps it) times the shrink squared, over the
    /// thickness, in closed form.
    pub fn volume(&self) -> Real {
        let half = BLADE_THICKNESS / 2.0;
        let c = half * BLADE_RELIEF_DEG.to_radians().tan() / self.top;
        // The integral of (1 - c t^2)^2 over t from -1 to 1, times half.
        self.outline.area().abs() * half * (2.0 - 4.0 * c / 3.0 + 2.0 * c * c / 5.0)
    }

    /// The blade as a closed mesh in the tool frame, its sections' arcs
    /// within `tol`.
    ///
    /// # Failures
    /// A tolerance not positive; the mesh failing.
    pub fn mesh(&self, tol: Real) -> Result<TriMesh, MeshError> {
        crate::math::positive("mesh tolerance", tol)?;
        // Along each piece: lines at their ends; the nose arcs (a quarter
        // turn at most) in chords within tol of them.
        let pieces = self.outline.pieces.len();
        let r = self.nose_radius;
        let arc = if r > tol {
            ((std::f64::consts::FRAC_PI_2 / (2.0 * (1.0 - tol / r).acos())).ceil() as usize)
                .clamp(2, 256)
        } else {
            2
        };
        let arc_steps = |k: usize| match self.outline.pieces.get(k) {
            Some(crate::step::Piece::Line(_)) | None => 1,
            Some(_) => arc,
        };
        let half = BLADE_THICKNESS / 2.0;
        let rings: Vec<Vec<[Real; 3]>> = (0..=16)
            .map(|j| {
                let y = -half + BLADE_THICKNESS * j as Real / 16.0;
                (0..pieces)
                    .flat_map(|k| {
                        let n = arc_steps(k);
                        (0..n).map(move |i| (k, i as Real / n as Real))
                    })
                    .map(|(k, u)| self.local(k, u, y))
                    .collect()
            })
            .collect();
        crate::mesh::sweep(&rings)
    }
}

impl crate::step::Sections for ThreadBlade {
    fn pieces(&self) -> usize {
        // The outline closes itself (its top back to its start).
        self.outline.pieces.len()
    }

    fn straight(&self, _: usize) -> bool {
        // The helix's shift bends every line of the profile a little.
        false
    }

    fn point(&self, k: usize, u: Real, v: Real) -> [Real; 3] {
        let y = BLADE_THICKNESS * (v - 0.5);
        let p = self.local(k, u, y);
        let q = self.pose.transform_point(&Point3::new(p[0], p[1], p[2]));
        [q.x, q.y, q.z]
    }

    fn along(&self) -> usize {
        9
    }

    fn ends_along_z(&self) -> bool {
        // Its faces are parallel to the cutting plane, which holds the
        // part's axis.
        true
    }
}

/// The outline of `cutter`'s section ([`ThreadCutter::section`]) up to
/// `top`, closed along the top, in exact lines and arcs (the cutter's STEP
/// solid), counter-clockwise.
pub fn cutter_outline(cutter: &ThreadCutter, top: Real) -> Section {
    use crate::step::Piece;
    let (w, r) = (cutter.tip_width / 2.0, cutter.nose_radius);
    let (tl, tr) = (cutter.left_angle.tan(), cutter.right_angle.tan());
    // A form cutter's flank bends out by its bulge: lines in steps of
    // FORM_STEP along the height (a straight cutter's flank is one line).
    let bent = |p: [Real; 2]| [p[0] + p[0].signum() * cutter.bulge(p[1]), p[1]];
    let flank = |from: [Real; 2], to: [Real; 2], pieces: &mut Vec<Piece>| {
        let n = if cutter.ground.is_some() {
            ((to[1] - from[1]).abs() / crate::tool::FORM_STEP)
                .ceil()
                .max(1.0) as usize
        } else {
            1
        };
        for k in 1..n {
            let t = k as Real / n as Real;
            pieces.push(Piece::Line(bent([
                from[0] + t * (to[0] - from[0]),
                from[1] + t * (to[1] - from[1]),
            ])));
        }
        pieces.push(Piece::Line(bent(to)));
    };
    let start = [-w - top * tl, top];
    let mut pieces = Vec::new();
    if r > 0.0 {
        let at = |c: [Real; 2], a: Real| bent([c[0] + r * a.cos(), c[1] + r * a.sin()]);
        let half_pi = std::f64::consts::FRAC_PI_2;
        let cl = [-(w - cutter.inset(cutter.left_angle)), r];
        let cr = [w - cutter.inset(cutter.right_angle), r];
        let (l0, r1) = (
            -std::f64::consts::PI + cutter.left_angle,
            -cutter.right_angle,
        );
        let straight = |c: [Real; 2], a: Real| [c[0] + r * a.cos(), c[1] + r * a.sin()];
        flank(start, straight(cl, l0), &mut pieces);
        pieces.push(Piece::Arc {
            through: at(cl, 0.5 * (l0 - half_pi)),
            to: at(cl, -half_pi),
        });
        pieces.push(Piece::Line(at(cr, -half_pi)));
        pieces.push(Piece::Arc {
            through: at(cr, 0.5 * (r1 - half_pi)),
            to: at(cr, r1),
        });
        flank(straight(cr, r1), [w + top * tr, top], &mut pieces);
    } else {
        flank(start, [-w, 0.0], &mut pieces);
        pieces.push(Piece::Line([w, 0.0]));
        flank([w, 0.0], [w + top * tr, top], &mut pieces);
    }
    let start = bent(start);
    pieces.push(Piece::Line(start));
    Section { start, pieces }
}
