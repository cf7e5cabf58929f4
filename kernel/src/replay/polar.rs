//! A part that is not round, replayed: its radius over the angle about the
//! part's axis, in one plane across that axis, as a program leaves it when
//! the part turns on a rotary axis and a tool whose axis is parallel to the
//! part's (the wheel of a cylindrical grinder, an end mill) cuts it: a cam,
//! a polygon, an eccentric. The families that grind such parts (in script
//! or in Rust) judge what this leaves; it knows none of them.
//!
//! The model, and why it is written here rather than taken from a library:
//! the tool's section in the plane is a disc (its radius from the tool's
//! true shape at that height: a wheel's flat or rounding, an end mill's
//! flutes), moved through every axis's values between blocks as the
//! control interpolates them (each axis linearly from block to block). The
//! part is the material along each ray from its axis up to the first point
//! any disc reached: a star-shaped section, which a cam's or a polygon's
//! is. Along a ray at angle `phi` a disc of centre `c` and radius `R`
//! covers `t` in `u.c -+ sqrt(R^2 - |c|^2 + (u.c)^2)`, so the replay is a
//! minimum over closed-form entries; a polygon library would cut the discs
//! out of the blank one by one and be asked for the same rays at the end.
//! The moves are sampled, and sampled again twice as densely until no
//! radius moves by [`SAMPLING_CHANGE`] (at most [`MAX_HALVINGS`] times):
//! the figures say how far the last doubling moved them.

use super::{as_written, forward_rows, VerifyError};
use crate::machine::AxisKind;
use crate::machine::MachineKinematics;
use crate::math::{Point3, Real};
use crate::program::{axis_rows, AxisProgram, ProgramPass};
use crate::tool::{Tool, ToolShape};
use crate::transform::ToolFrame;
use std::ops::Range;

/// How far (mm) the tool's centre moves in the part between two samples
/// of a move at first: a fifth of a millimetre, which on a 50 mm cam under
/// a 200 mm wheel leaves scallops of about 0.1 um between samples.
pub const FIRST_STEP: Real = 0.2;

/// The largest change (mm) of any radius from one sampling to the next
/// twice as dense at which the sampling is taken as converged: a tenth of
/// a micron, below what a program written to 0.001 mm can hold.
pub const SAMPLING_CHANGE: Real = 1e-4;

/// How many times the sampling is made twice as dense at most (the step
/// goes down to [`FIRST_STEP`] / 64, 3 um); the figures say the change
/// the last doubling made where it did not converge.
pub const MAX_HALVINGS: u32 = 6;

/// How far the tool's axis may lean from the part's (as the cosine's
/// shortfall from 1) and still be taken as parallel to it: 1e-9, a lean of
/// 45 urad, which moves a 40 mm wide wheel's edge 2 um.
pub const PARALLEL: Real = 1e-9;

/// Most angles round the part the replay reads (0.001 deg apart).
pub const MAX_ANGLES: usize = 360_000;

/// What the replay of radius over angle is asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarRequest {
    /// The plane across the part's axis where the section is read (z, mm).
    pub z: Real,
    /// How many angles round the part the radius is read at, equally
    /// spaced from 0 deg.
    pub angles: usize,
    /// The blank's radius (mm): the material before the first pass.
    pub blank: Real,
}

impl PolarRequest {
    /// The angles (deg) the radius is read at: `angles` equally spaced
    /// from 0, 360 not among them.
    pub fn angles_deg(&self) -> Vec<Real> {
        (0..self.angles)
            .map(|i| 360.0 * i as Real / self.angles as Real)
            .collect()
    }
}

/// The section one pass left.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarPass {
    /// The pass's name.
    pub name: String,
    /// Its blocks in the program (from 0).
    pub blocks: Range<usize>,
    /// Whether it cuts.
    pub cuts: bool,
    /// The radius (mm) at each angle after it.
    pub radius: Vec<Real>,
    /// The block (from 0) whose move last cut at each angle, if any did.
    pub block: Vec<Option<usize>>,
}

/// What the replay of radius over angle found.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarPart {
    /// The angles (deg, from 0) the radius is read at.
    pub angle_deg: Vec<Real>,
    /// The section after each pass, in order.
    pub passes: Vec<PolarPass>,
    /// How far (mm) the last doubling of the sampling moved any radius.
    pub sampling_change: Real,
    /// The program's resolution (mm): its axis values as written.
    pub resolution: Real,
}

/// The tool's section in a plane across its axis, `dz` mm along the axis
/// from its centre: the disc's radius, if the tool reaches the plane.
fn section_radius(shape: &ToolShape, dz: Real) -> Option<Real> {
    match *shape {
        ToolShape::Wheel(w) => {
            let half_flat = 0.5 * w.flat();
            let off = dz.abs() - half_flat;
            if off <= 0.0 {
                Some(0.5 * w.diameter)
            } else if off <= w.rounding_radius {
                let r = w.rounding_radius;
                Some(w.centre_radius() + (r * r - off * off).sqrt())
            } else {
                None
            }
        }
        ToolShape::EndMill { diameter, length } => {
            (0.0..=length).contains(&dz).then_some(0.5 * diameter)
        }
        _ => None,
    }
}

/// Replays `program` on `machine` with `tool`, its passes `passes`: the
/// radius over angle each pass leaves in the plane `request.z`.
///
/// # Failures
/// A tool other than a wheel or an end mill; a tool whose axis is not the
/// part's at a block; no angle or too many; the replay failing (an axis the
/// program lacks, the machine's kinematics); the run's time limit.
pub fn replay_polar(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &Tool,
    passes: &[ProgramPass],
    request: &PolarRequest,
) -> Result<PolarPart, VerifyError> {
    if !matches!(tool.shape, ToolShape::Wheel(_) | ToolShape::EndMill { .. }) {
        return Err(VerifyError::Contract(format!(
            "the replay of radius over angle needs a wheel or an end mill (a disc in the section), not the tool '{}'",
            tool.name
        )));
    }
    if request.angles < 3 || request.angles > MAX_ANGLES {
        return Err(VerifyError::Contract(format!(
            "the replay of radius over angle reads 3 to {MAX_ANGLES} angles, not {}",
            request.angles
        )));
    }
    if !(request.blank.is_finite() && request.blank > 0.0 && request.z.is_finite()) {
        return Err(VerifyError::Contract(format!(
            "the replay of radius over angle needs a positive blank radius and a finite z, not blank {} at z {}",
            request.blank, request.z
        )));
    }
    let (written, resolution) = as_written(program);
    let info = machine.info();
    let n = written.blocks.len();
    let rows = axis_rows(&written, info, &info.solved_axes, 0..n)
        .map_err(|e| VerifyError::Replay(e.to_string()))?;
    let rotary: Vec<bool> = info
        .solved_axes
        .iter()
        .map(|a| info.axis(a).is_some_and(|x| x.kind == AxisKind::Rotary))
        .collect();
    let centre = ToolFrame {
        point: Point3::from(tool.spindle_centre()),
        axis: crate::math::Vec3::z(),
    };
    let at_blocks = forward_rows(machine, &rows, &centre, 0..n)?;
    let sweep = Sweep {
        machine,
        rows: &rows,
        dof: info.solved_axes.len(),
        rotary: &rotary,
        at_blocks: &at_blocks,
        centre: &centre,
        shape: &tool.shape,
        request,
        program,
    };
    let mut step = FIRST_STEP;
    let mut last = sweep.run(passes, step)?;
    let mut change = Real::INFINITY;
    for _ in 0..MAX_HALVINGS {
        step /= 2.0;
        let next = sweep.run(passes, step)?;
        change = largest_change(&last, &next);
        last = next;
        if change < SAMPLING_CHANGE {
            break;
        }
    }
    Ok(PolarPart {
        angle_deg: request.angles_deg(),
        passes: last,
        sampling_change: change,
        resolution,
    })
}

/// The largest change of any radius between two samplings.
fn largest_change(a: &[PolarPass], b: &[PolarPass]) -> Real {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| p.radius.iter().zip(&q.radius).map(|(x, y)| (x - y).abs()))
        .fold(0.0, Real::max)
}

/// One sampling of the program's moves.
struct Sweep<'a> {
    machine: &'a dyn MachineKinematics,
    rows: &'a [Real],
    dof: usize,
    rotary: &'a [bool],
    at_blocks: &'a [Real],
    centre: &'a ToolFrame,
    shape: &'a ToolShape,
    request: &'a PolarRequest,
    program: &'a AxisProgram,
}

impl Sweep<'_> {
    /// The section after each pass, the moves sampled `step` mm apart.
    fn run(&self, passes: &[ProgramPass], step: Real) -> Result<Vec<PolarPass>, VerifyError> {
        let m = self.request.angles;
        let mut radius = vec![self.request.blank; m];
        let mut block = vec![None; m];
        let mut out = Vec::with_capacity(passes.len());
        for p in passes {
            // The section's largest radius, which only falls, taken again
            // at each pass.
            let outer = radius.iter().copied().fold(0.0, Real::max);
            for k in p.blocks.clone() {
                crate::budget::check("the replay of radius over angle")?;
                self.cut_move(k, step, &outer, &mut radius, &mut block)?;
            }
            out.push(PolarPass {
                name: p.name.clone(),
                blocks: p.blocks.clone(),
                cuts: p.cuts,
                radius: radius.clone(),
                block: block.clone(),
            });
        }
        Ok(out)
    }

    /// The move into block `k` (from the block before it; block 0 where it
    /// stands), sampled `step` mm apart, cut into the section.
    fn cut_move(
        &self,
        k: usize,
        step: Real,
        outer: &Real,
        radius: &mut [Real],
        block: &mut [Option<usize>],
    ) -> Result<(), VerifyError> {
        let d = self.dof;
        let to = &self.rows[d * k..d * k + d];
        let from = if k == 0 {
            to
        } else {
            &self.rows[d * (k - 1)..d * k]
        };
        // The tool's centre's reach from the part's axis, at either end:
        // a rotary axis's turn moves it that far per radian.
        let reach = |i: usize| {
            let p = &self.at_blocks[6 * i..6 * i + 3];
            p[0].hypot(p[1])
        };
        let arm = if k == 0 {
            reach(0)
        } else {
            reach(k).max(reach(k - 1))
        };
        let travel = (0..d)
            .map(|a| {
                let delta = (to[a] - from[a]).abs();
                if self.rotary[a] {
                    delta * arm
                } else {
                    delta
                }
            })
            .fold(0.0, Real::max);
        let samples = ((travel / step).ceil() as usize).max(1);
        let mut rows = Vec::with_capacity(samples * d);
        for s in 1..=samples {
            let t = s as Real / samples as Real;
            rows.extend((0..d).map(|a| from[a] + t * (to[a] - from[a])));
        }
        let first = k.saturating_sub(1);
        let poses = forward_rows(self.machine, &rows, self.centre, first..k + 1)?;
        for pose in poses.chunks_exact(6) {
            let lean = 1.0 - pose[5].abs();
            if lean > PARALLEL {
                return Err(VerifyError::Replay(format!(
                    "{}: the tool's axis leans {:.4} deg from the part's; the replay of radius over angle needs them parallel",
                    crate::program::block_name(self.program, k),
                    pose[5].abs().min(1.0).acos().to_degrees()
                )));
            }
            let dz = (self.request.z - pose[2]) * pose[5].signum();
            if let Some(r) = section_radius(self.shape, dz) {
                cut_disc((pose[0], pose[1], r), *outer, k, radius, block);
            }
        }
        Ok(())
    }
}

/// A disc of centre `(cx, cy)` and radius `r` cut into the section, whose
/// largest radius is `outer`: every ray it crosses ends where it enters
/// (the material beyond it from the axis is gone); `k` is the block that
/// cut.
fn cut_disc(
    (cx, cy, r): (Real, Real, Real),
    outer: Real,
    k: usize,
    radius: &mut [Real],
    block: &mut [Option<usize>],
) {
    let m = radius.len();
    let d = cx.hypot(cy);
    let angle = std::f64::consts::TAU / m as Real;
    // The rays where the disc can reach material: within the angle at the
    // axis of the points where its circle meets the circle of the section's
    // largest radius (none where it stays outside that circle; all where
    // it covers the axis).
    if d - r >= outer {
        return;
    }
    let (lo, hi) = if d > r {
        let mid = cy.atan2(cx);
        let cos = (d * d + outer * outer - r * r) / (2.0 * d * outer);
        let half = if cos <= -1.0 {
            std::f64::consts::PI
        } else {
            cos.min(1.0).acos()
        };
        (
            ((mid - half) / angle).floor() as i64,
            ((mid + half) / angle).ceil() as i64,
        )
    } else {
        (0, m as i64 - 1)
    };
    let (lo, hi) = if hi - lo >= m as i64 {
        (0, m as i64 - 1)
    } else {
        (lo, hi)
    };
    for j in lo..=hi {
        let i = j.rem_euclid(m as i64) as usize;
        let phi = i as Real * angle;
        let (s, c) = phi.sin_cos();
        let along = c * cx + s * cy;
        let across2 = d * d - along * along;
        let gap = r * r - across2;
        if gap < 0.0 {
            continue;
        }
        let root = gap.sqrt();
        if along + root <= 0.0 {
            continue;
        }
        let entry = (along - root).max(0.0);
        if entry < radius[i] {
            radius[i] = entry;
            block[i] = Some(k);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tool::Wheel;

    #[test]
    fn a_wheels_section_is_its_flat_then_its_rounding() {
        let w = ToolShape::Wheel(Wheel::new(400.0, 2.0, 40.0).unwrap());
        assert_eq!(section_radius(&w, 0.0), Some(200.0));
        assert_eq!(section_radius(&w, 18.0), Some(200.0));
        let r = section_radius(&w, 19.0).unwrap();
        assert!((r - (198.0 + 3.0_f64.sqrt())).abs() < 1e-12, "{r}");
        assert_eq!(section_radius(&w, 20.5), None);
    }

    #[test]
    fn a_disc_beside_the_axis_leaves_the_circle_of_its_near_side() {
        // A disc of radius 100 centred 150 mm out on +x: the ray along +x
        // ends at 50; a ray at angle phi ends where the circle meets it.
        let m = 3600;
        let mut radius = vec![80.0; m];
        let mut block = vec![None; m];
        cut_disc((150.0, 0.0, 100.0), 80.0, 7, &mut radius, &mut block);
        assert!((radius[0] - 50.0).abs() < 1e-12);
        assert_eq!(block[0], Some(7));
        for (i, r) in radius.iter().enumerate() {
            let phi = (i as Real * 0.1).to_radians();
            let along = 150.0 * phi.cos();
            let gap = 100.0f64.powi(2) - (150.0f64.powi(2) - along * along);
            let expect = if gap >= 0.0 && along + gap.sqrt() > 0.0 {
                (along - gap.sqrt()).clamp(0.0, 80.0)
            } else {
                80.0
            };
            assert!((r - expect).abs() < 1e-9, "{i}: {r} vs {expect}");
        }
    }
}
