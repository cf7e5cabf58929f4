//! Verifying a program by replaying it (ARCHITECTURE §1's VERIFY stage).
//!
//! A grinding program moves the wheel's rounding centre in straight lines
//! between blocks. [`SweptWheel`] is the surface the rounding leaves along
//! those moves, in the part's axial section: the envelope of the circle
//! placed along each move densely enough that the discretisation itself is
//! below a stated resolution. [`SweptWheel::deviation`] compares it with the
//! nominal profile and names the block whose move left the largest error.

use crate::math::{positive, Real};
use crate::offset::{CircleEnvelope, Side};
use crate::profile::{Profile, ProfileError};
use serde::{Deserialize, Serialize};

/// The surface left by a wheel's rounding moved in straight lines between
/// centres (mm, axial section).
#[derive(Debug, Clone)]
pub struct SweptWheel {
    envelope: CircleEnvelope,
    /// For each placed circle, the block whose move placed it.
    block_of: Vec<usize>,
    resolution: Real,
}

/// How far a surface strays from the nominal profile over a range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Deviation {
    /// The most material left above the profile (mm, >= 0 where any).
    pub max_above: Real,
    /// Where (z).
    pub above_z: Real,
    /// The deepest cut below the profile (mm, <= 0 where any: a gouge).
    pub max_below: Real,
    /// Where (z).
    pub below_z: Real,
    /// The largest of the two in size (mm).
    pub max_abs: Real,
    /// Where the largest is (z).
    pub at_z: Real,
    /// The block (index from 0) whose move forms the surface there.
    pub block: Option<usize>,
}

impl SweptWheel {
    /// The surface left when the rounding (radius `radius`) moves through
    /// the centres `(z[i], x[i])`, block `i` after block `i - 1`. Circles are
    /// placed along each move at most `sqrt(8 radius resolution)` apart, so
    /// the scallops between them stay below `resolution` (mm).
    ///
    /// # Failures
    /// Fewer than one centre, arrays of different lengths, non-finite
    /// values, a radius or resolution that is not positive, or more than 50
    /// million circles.
    pub fn new(
        z: &[Real],
        x: &[Real],
        radius: Real,
        resolution: Real,
    ) -> Result<Self, ProfileError> {
        positive("wheel rounding radius", radius)?;
        positive("verification resolution", resolution)?;
        crate::math::all_finite("wheel centre z", z)?;
        crate::math::all_finite("wheel centre x", x)?;
        if z.len() != x.len() || z.is_empty() {
            return Err(crate::error::InputError::LengthMismatch {
                what: "wheel centres z and x".into(),
                left: z.len(),
                right: x.len(),
            }
            .into());
        }
        let (cz, cx, block_of) = crate::offset::swept_circles(z, x, radius, resolution)?;
        Ok(Self {
            envelope: CircleEnvelope::new(&cz, &cx, radius, Side::Outside)?,
            block_of,
            resolution,
        })
    }

    /// The surface's x at `z` (infinite where the wheel never reached).
    pub fn eval(&self, z: Real) -> Real {
        self.envelope.eval(z)
    }

    /// The block whose move forms the surface at `z`.
    pub fn block_at(&self, z: Real) -> Option<usize> {
        self.envelope.source_at(z).map(|i| self.block_of[i])
    }

    /// The deviation from `nominal` over `[z_from, z_to]`, sampled at `step`
    /// (and at the nominal's nodes inside the range).
    ///
    /// # Tolerance
    /// The surface is exact to [`Self::new`]'s resolution; between samples a
    /// deviation can peak by at most the surface's and the profile's
    /// curvature times `step^2 / 8`.
    ///
    /// # Failures
    /// A range outside the nominal profile; a step that is not positive;
    /// a place in the range the wheel never reached.
    pub fn deviation(
        &self,
        nominal: &Profile,
        z_from: Real,
        z_to: Real,
        step: Real,
    ) -> Result<Deviation, ProfileError> {
        positive("verification step", step)?;
        let mut zs = crate::profile::uniform_grid(z_from, z_to, step)?;
        zs.extend(
            nominal
                .z()
                .iter()
                .copied()
                .filter(|z| (z_from..=z_to).contains(z)),
        );
        zs.sort_by(Real::total_cmp);
        zs.dedup();
        let surface = self.envelope.eval_many(&zs);
        let profile = nominal.eval_many(&zs)?;
        let mut d = Deviation {
            max_above: Real::NEG_INFINITY,
            above_z: z_from,
            max_below: Real::INFINITY,
            below_z: z_from,
            max_abs: 0.0,
            at_z: z_from,
            block: None,
        };
        for ((&z, &s), &p) in zs.iter().zip(&surface).zip(&profile) {
            if !s.is_finite() {
                return Err(ProfileError::OutsideProfile {
                    what: "the wheel never reached the profile".into(),
                    z,
                    z_min: z_from,
                    z_max: z_to,
                });
            }
            let e = s - p;
            if e > d.max_above {
                (d.max_above, d.above_z) = (e, z);
            }
            if e < d.max_below {
                (d.max_below, d.below_z) = (e, z);
            }
        }
        (d.max_abs, d.at_z) = if d.max_above >= -d.max_below {
            (d.max_above.abs(), d.above_z)
        } else {
            (d.max_below.abs(), d.below_z)
        };
        d.block = self.block_at(d.at_z);
        Ok(d)
    }

    /// The resolution the surface was built to (mm).
    pub fn resolution(&self) -> Real {
        self.resolution
    }
}

/// The tool's pose at every block of a program, by the machine's forward
/// kinematics of the block's values: rows of 6 (tracked point, axis).
///
/// # Failures
/// As [`replay_blocks`].
pub fn replay(
    program: &crate::AxisProgram,
    machine: &dyn crate::MachineKinematics,
    tool: &crate::ToolFrame,
) -> Result<Vec<Real>, String> {
    replay_blocks(program, machine, tool, 0..program.blocks.len())
}

/// [`replay`] of the blocks in `blocks` (indices from 0).
///
/// # Failures
/// A block beyond the program; a solved axis the program lacks; the
/// machine's kinematics failing.
pub fn replay_blocks(
    program: &crate::AxisProgram,
    machine: &dyn crate::MachineKinematics,
    tool: &crate::ToolFrame,
    blocks: std::ops::Range<usize>,
) -> Result<Vec<Real>, String> {
    if blocks.end > program.blocks.len() {
        return Err(format!(
            "block {} is beyond the program's {} blocks",
            blocks.end,
            program.blocks.len()
        ));
    }
    let info = machine.info();
    let cols = info
        .solved_axes
        .iter()
        .map(|name| {
            let c = program
                .axes
                .iter()
                .position(|a| &a.name == name)
                .ok_or(format!("the program has no axis {name}"))?;
            let rotary = info
                .axis(name)
                .is_some_and(|a| a.kind == crate::AxisKind::Rotary);
            Ok((c, rotary))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let rows: Vec<Real> = program.blocks[blocks.clone()]
        .iter()
        .flat_map(|b| {
            cols.iter()
                .map(|&(c, rot)| {
                    if rot {
                        b.values[c].to_radians()
                    } else {
                        b.values[c]
                    }
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let mut poses = Vec::new();
    machine
        .forward(&rows, tool, &mut poses)
        .map_err(|e| format!("blocks {} to {}: {e}", blocks.start + 1, blocks.end))?;
    Ok(poses)
}

/// One cutting pass's surface against the nominal profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PassCheck {
    /// The pass's name.
    pub name: String,
    /// Its first block (from 1).
    pub first_block: usize,
    /// Its surface against the nominal (blocks from 1).
    pub deviation: Deviation,
}

/// A grinding program replayed: each cutting pass's swept surface against
/// the nominal profile; the last one must hold the tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GrindingCheck {
    /// The tolerance held (mm).
    pub tolerance: Real,
    /// Each cutting pass (the last is the finish).
    pub passes: Vec<PassCheck>,
}

/// Replays a grinding program (a wheel of rounding `rounding_radius` whose
/// tracked point is its rounding's centre) through the machine, builds each
/// cutting pass's swept surface in the axial section (radius from the axis,
/// z), and compares it with `nominal` over `[from, to]`.
///
/// # Failures
/// The replay failing; a pass that does not cover the range; the finishing
/// pass straying more than `tolerance` from the nominal: the message names
/// the deviation, its z and the block (from 1) whose move formed it.
#[allow(clippy::too_many_arguments)]
pub fn check_grinding(
    program: &crate::AxisProgram,
    machine: &dyn crate::MachineKinematics,
    tool: &crate::ToolFrame,
    rounding_radius: Real,
    passes: &[(String, usize)],
    nominal: &Profile,
    range: (Real, Real),
    tolerance: Real,
) -> Result<GrindingCheck, String> {
    positive("verification tolerance", tolerance).map_err(|e| e.to_string())?;
    let poses = replay(program, machine, tool)?;
    let mut out = GrindingCheck {
        tolerance,
        passes: Vec::new(),
    };
    let mut first = 0;
    for (name, len) in passes {
        let blocks = first..first + len;
        first += len;
        let cutting = blocks
            .clone()
            .any(|b| program.blocks[b].motion != crate::Motion::Rapid);
        if !cutting || *len == 0 {
            continue;
        }
        let z: Vec<Real> = blocks.clone().map(|b| poses[6 * b + 2]).collect();
        let x: Vec<Real> = blocks
            .clone()
            .map(|b| poses[6 * b].hypot(poses[6 * b + 1]))
            .collect();
        let swept = SweptWheel::new(&z, &x, rounding_radius, tolerance / 20.0)
            .map_err(|e| e.to_string())?;
        let step = (tolerance * 20.0).clamp(0.005, 0.05);
        let mut d = swept
            .deviation(nominal, range.0, range.1, step)
            .map_err(|e| format!("{name}: {e}"))?;
        d.block = d.block.map(|k| blocks.start + k + 1);
        out.passes.push(PassCheck {
            name: name.clone(),
            first_block: blocks.start + 1,
            deviation: d,
        });
    }
    let finish = out.passes.last().ok_or("the program has no cutting pass")?;
    let d = finish.deviation;
    if d.max_abs > tolerance {
        return Err(format!(
            "verification failed: the finished surface strays {} mm from the nominal profile at z = {}, \
             where block {} cuts it (tolerance {} mm)",
            crate::math::fixed(if d.max_above.abs() >= d.max_below.abs() { d.max_above } else { d.max_below }, 5),
            crate::math::fixed(d.at_z, 3),
            d.block.map_or("?".into(), |b| b.to_string()),
            tolerance
        ));
    }
    Ok(out)
}
