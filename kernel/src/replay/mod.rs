//! Replaying a program as its machine runs it: the generic machinery the
//! families' verifications share. [`as_written`] reads an axis program as
//! its control does (every value at the decimals written), [`replay`]
//! moves the tool through the machine's forward kinematics block by block,
//! [`passes_in`] finds the passes of a program read from its text; each
//! family's replay (in its folder under `families/`) builds on them and
//! reports through [`VerifyError`]; [`polar`] replays the radius over angle
//! of a part that is not round, for any family.

pub mod polar;

use crate::input::InputError;
use crate::machine::{KinematicsError, MachineKinematics};
use crate::math::Real;
use crate::profile::ProfileError;
use crate::program::{axis_rows, AxisProgram, ProgramPass};
use crate::transform::ToolFrame;

/// Why a program could not be verified, or failed verification.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VerifyError {
    /// The run's time limit passed while this was being done.
    #[error(transparent)]
    OverTime(#[from] crate::budget::OverTime),
    /// A rejected number (a tolerance that is not positive).
    #[error(transparent)]
    Input(#[from] InputError),
    /// A surface that cannot be built or compared.
    #[error(transparent)]
    Profile(#[from] ProfileError),
    /// A family's geometry cannot be evaluated where the replay measures
    /// it (the caliber's groove beyond its tables).
    #[error("{0}")]
    Geometry(String),
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
    /// The family's request does not fit what the run gives it (a
    /// replay of a wheel given a cutter): the family's contract, said.
    #[error("{0}")]
    Contract(String),
    /// Nothing cuts.
    #[error("the program has no cutting pass")]
    NoCuttingPass,
    /// The program verified, and the part it makes fails the family's
    /// check: the family's own words (where, by how much, the block, what
    /// to change).
    #[error("verification failed: {0}")]
    Failed(String),
    /// A tolerance finer than the program can carry.
    #[error("a verification tolerance of {tolerance} mm is finer than twice the program's resolution ({resolution} mm steps): the program cannot hold it")]
    Resolution {
        /// The tolerance asked.
        tolerance: Real,
        /// The program's smallest step.
        resolution: Real,
    },
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
    let rows = axis_rows(program, info, &info.solved_axes, blocks.clone())
        .map_err(|e| VerifyError::Replay(e.to_string()))?;
    forward_rows(machine, &rows, tool, blocks)
}

/// The tool's poses (rows of 6) at `rows` of the machine's solved axes,
/// values of the program's `blocks` (indices from 0, named in the error
/// as the program counts them, from 1) or between them.
///
/// # Failures
/// The machine's kinematics failing, naming the blocks.
pub fn forward_rows(
    machine: &dyn MachineKinematics,
    rows: &[Real],
    tool: &ToolFrame,
    blocks: std::ops::Range<usize>,
) -> Result<Vec<Real>, VerifyError> {
    let mut poses = Vec::new();
    machine
        .forward(rows, tool, &mut poses)
        .map_err(|source| VerifyError::Kinematics {
            first: blocks.start + 1,
            last: blocks.end,
            source,
        })?;
    Ok(poses)
}

/// The program as a control reads it: every axis value rounded to the
/// decimals the program is written with (its own, or its dialect's), and
/// where the dialect is known, every word as it writes it: the feeds and
/// leads at its decimals, a thread's start angle at its address's
/// resolution (Fanuc's Q counts 0.001 deg), the spindle's speeds in whole
/// rpm. The second value is the axis values' resolution.
pub fn as_written(program: &AxisProgram) -> (AxisProgram, Real) {
    let decimals = crate::program::written_decimals(program.decimals, &program.control);
    let dialect = crate::program::post::dialect(&program.control);
    let w = crate::program::written;
    let mut p = program.clone();
    for b in &mut p.blocks {
        for v in &mut b.values {
            *v = w(*v, decimals);
        }
        let Some(d) = dialect else { continue };
        b.spindle = b.spindle.map(Real::round);
        match &mut b.motion {
            crate::toolpath::Motion::Linear => b.feed = w(b.feed, d.feed_decimals),
            crate::toolpath::Motion::Thread { lead, start_deg } => {
                *lead = w(*lead, d.lead_decimals);
                if let Some(t) = d.thread_start {
                    *start_deg = w(*start_deg * t.scale, t.decimals) / t.scale;
                }
                b.feed = *lead * p.spindle_rpm.round();
            }
            crate::toolpath::Motion::Rapid => {}
        }
    }
    if dialect.is_some() {
        p.spindle_rpm = p.spindle_rpm.round();
    }
    (p, 10f64.powi(-(decimals as i32)))
}

/// The passes of a program read from its text: a pass begins at each block
/// with a comment (the line before it, as pilgrim writes a pass's name)
/// and runs to the next; blocks before the first comment are one pass,
/// `start`. A pass cuts ([`crate::toolpath::Pass::cuts`]) when one of its
/// moves other than a rapid moves the tool: its first block, or a block
/// that puts the tool (replayed on `machine` with `tool`) elsewhere than
/// the block before.
///
/// # Failures
/// The replay failing (a solved axis the program lacks); a program whose
/// blocks are all one pass that cuts (no comment between its blocks): the
/// surface each pass leaves, the rest rides and the finish's stock need
/// its passes, which a comment before each names.
pub fn passes_in(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
) -> Result<Vec<ProgramPass>, VerifyError> {
    let (written, _) = as_written(program);
    let poses = replay(&written, machine, tool)?;
    let mut out: Vec<ProgramPass> = Vec::new();
    for (k, b) in written.blocks.iter().enumerate() {
        match (&b.comment, out.last_mut()) {
            (None, Some(p)) => p.blocks.end = k + 1,
            (name, _) => out.push(ProgramPass {
                name: name.clone().unwrap_or_else(|| "start".into()),
                blocks: k..k + 1,
                cuts: false,
            }),
        }
        let moved = k == 0
            || out.last().is_some_and(|p| p.blocks.start == k)
            || poses[6 * k..6 * k + 6] != poses[6 * (k - 1)..6 * k];
        if b.motion != crate::toolpath::Motion::Rapid && moved {
            if let Some(p) = out.last_mut() {
                p.cuts = true;
            }
        }
    }
    if out.len() == 1 && out[0].cuts {
        return Err(VerifyError::Replay(format!(
            "the program's {} blocks are one pass: the verification reads a pass as the blocks after a comment line (as pilgrim writes `; pass 1` or `(PASS 1)`); put a comment before the first block of each pass",
            program.blocks.len()
        )));
    }
    Ok(out)
}
