//! Verifying a program by replaying it (ARCHITECTURE §1's VERIFY stage).
//!
//! A grinding program moves the wheel's rounding centre in straight lines
//! between blocks. [`SweptWheel`] is the surface the rounding leaves along
//! those moves, in the part's axial section: the envelope of the circle
//! placed along each move densely enough that the discretisation itself is
//! below a stated resolution. [`SweptWheel::deviation`] compares it with the
//! nominal profile and names the block whose move left the largest error.

use crate::input::InputError;
use crate::machine::{KinematicsError, MachineKinematics};
use crate::math::{positive, Real};
use crate::offset::{CircleEnvelope, Side};
use crate::profile::{Profile, ProfileError};
use crate::program::{axis_rows, AxisProgram};
use crate::toolpath::{pass_ranges, Pass};
use crate::transform::ToolFrame;
use serde::{Deserialize, Serialize};

/// Why a program could not be verified, or failed verification.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VerifyError {
    /// A rejected number (a tolerance that is not positive).
    #[error(transparent)]
    Input(#[from] InputError),
    /// A surface that cannot be built or compared.
    #[error(transparent)]
    Profile(#[from] ProfileError),
    /// The program cannot be replayed on the machine: a block beyond it,
    /// an axis it lacks.
    #[error("{0}")]
    Replay(String),
    /// The machine's forward kinematics failed over blocks `first..=last`
    /// (from 1).
    #[error("blocks {first} to {last}: {source}")]
    Kinematics {
        /// First block (from 1).
        first: usize,
        /// Last block.
        last: usize,
        /// The machine's message.
        source: KinematicsError,
    },
    /// A pass whose surface does not cover the range held to the tolerance.
    #[error("{pass}: {source}")]
    Pass {
        /// The pass's name.
        pass: String,
        /// What went wrong.
        source: ProfileError,
    },
    /// Nothing cuts.
    #[error("the program has no cutting pass")]
    NoCuttingPass,
    /// The finished surface strays from the nominal beyond the tolerance.
    #[error(
        "verification failed: the finished surface strays {} mm from the nominal profile at z = {}, \
         where block {} cuts it (tolerance {tolerance} mm)",
        crate::math::fixed(*deviation, 5),
        crate::math::fixed(*z, 3),
        block.map_or("?".into(), |b| b.to_string())
    )]
    Deviation {
        /// The signed deviation (mm; negative: a gouge).
        deviation: Real,
        /// Where (z, mm).
        z: Real,
        /// The block (from 1) whose move formed the surface there.
        block: Option<usize>,
        /// The tolerance (mm).
        tolerance: Real,
    },
}

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
    #[serde(default, skip_serializing_if = "Option::is_none")]
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
            return Err(crate::input::InputError::LengthMismatch {
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
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
) -> Result<Vec<Real>, VerifyError> {
    replay_blocks(program, machine, tool, 0..program.blocks.len())
}

/// [`replay`] of the blocks in `blocks` (indices from 0).
///
/// # Failures
/// A block beyond the program; a solved axis the program lacks; the
/// machine's kinematics failing.
pub fn replay_blocks(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    blocks: std::ops::Range<usize>,
) -> Result<Vec<Real>, VerifyError> {
    let info = machine.info();
    let rows =
        axis_rows(program, info, &info.solved_axes, blocks.clone()).map_err(VerifyError::Replay)?;
    let mut poses = Vec::new();
    machine
        .forward(&rows, tool, &mut poses)
        .map_err(|source| VerifyError::Kinematics {
            first: blocks.start + 1,
            last: blocks.end,
            source,
        })?;
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
/// z), and compares it with `nominal` over `[from, to]`. `passes` are the
/// toolpath's, whose points became the program's blocks.
///
/// # Failures
/// The replay failing; a pass that does not cover the range; the finishing
/// pass straying more than `tolerance` from the nominal
/// ([`VerifyError::Deviation`], naming the deviation, its z and the block,
/// from 1, whose move formed it).
#[allow(clippy::too_many_arguments)]
pub fn check_grinding(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    rounding_radius: Real,
    passes: &[Pass],
    nominal: &Profile,
    range: (Real, Real),
    tolerance: Real,
) -> Result<GrindingCheck, VerifyError> {
    positive("verification tolerance", tolerance)?;
    let poses = replay(program, machine, tool)?;
    let mut out = GrindingCheck {
        tolerance,
        passes: Vec::new(),
    };
    for (pass, blocks) in pass_ranges(passes) {
        if !pass.cuts() {
            continue;
        }
        let z: Vec<Real> = blocks.clone().map(|b| poses[6 * b + 2]).collect();
        let x: Vec<Real> = blocks
            .clone()
            .map(|b| poses[6 * b].hypot(poses[6 * b + 1]))
            .collect();
        let swept = SweptWheel::new(&z, &x, rounding_radius, tolerance / 20.0)?;
        let step = (tolerance * 20.0).clamp(0.005, 0.05);
        let mut d = swept
            .deviation(nominal, range.0, range.1, step)
            .map_err(|source| VerifyError::Pass {
                pass: pass.name.clone(),
                source,
            })?;
        d.block = d.block.map(|k| blocks.start + k + 1);
        out.passes.push(PassCheck {
            name: pass.name.clone(),
            first_block: blocks.start + 1,
            deviation: d,
        });
    }
    let finish = out.passes.last().ok_or(VerifyError::NoCuttingPass)?;
    let d = finish.deviation;
    if d.max_abs > tolerance {
        return Err(VerifyError::Deviation {
            deviation: if d.max_above.abs() >= d.max_below.abs() {
                d.max_above
            } else {
                d.max_below
            },
            z: d.at_z,
            block: d.block,
            tolerance,
        });
    }
    Ok(out)
}
