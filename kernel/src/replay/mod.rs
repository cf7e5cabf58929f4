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
use nalgebra::Vector3;

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

/// The passes of a program read from its text, as its motion makes them
/// (never its comments, which only name them): the tool's moves replayed
/// on `machine` with `tool`, in the part's frame (Z its axis). A cutting
/// pass is a run of cutting moves (a move other than a rapid that moves
/// the tool); it ends where a rapid takes the tool away, or where the feed
/// reverses along the part: the moves' travel along the part's surface
/// (along Z and round it: the radial part left out) turns back by more
/// than [`REVERSAL_COS`] against the pass's travel. Moves that are mostly
/// radial (an infeed) or that step across the travel (a caliber's step to
/// its next section) between two runs begin the later pass; so do the
/// rapids between two passes. A thread's pass is its spindle-synchronised
/// move (rapids part the passes). Blocks before the first cut are the
/// pass `start`, after the last `end`, neither cutting; a pass is named by
/// the first comment among its blocks (as pilgrim writes `; pass 1`), else
/// by its order among the cutting passes (`pass 3`).
///
/// # Failures
/// The replay failing (a solved axis the program lacks).
pub fn passes_in(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
) -> Result<Vec<ProgramPass>, VerifyError> {
    let (written, _) = as_written(program);
    let poses = replay(&written, machine, tool)?;
    let n = written.blocks.len();
    let at = |k: usize| Vector3::new(poses[6 * k], poses[6 * k + 1], poses[6 * k + 2]);
    // (start, cuts) of each run; the first is the start.
    let mut runs: Vec<(usize, bool)> = vec![(0, false)];
    // The travel along the surface of the pass so far, and where a run of
    // infeeds and steps since its last travel began.
    let mut travel: Option<Vector3<Real>> = None;
    let mut stepping: Option<usize> = None;
    for k in 1..n {
        let (p, q) = (at(k - 1), at(k));
        let d = q - p;
        if d.norm() <= crate::tolerance::SAME_LENGTH {
            continue;
        }
        let rapid = written.blocks[k].motion == crate::toolpath::Motion::Rapid;
        let last = runs.len() - 1;
        if rapid {
            travel = None;
            stepping = None;
            // Rapids after a cut begin the next pass (its approach).
            if runs[last].1 {
                runs.push((k, false));
            }
            continue;
        }
        if !runs[last].1 {
            if last == 0 {
                runs.push((k, true));
            } else {
                runs[last].1 = true;
            }
            travel = along_surface(p, q);
            stepping = None;
            if travel.is_none() {
                stepping = Some(k);
            }
            continue;
        }
        let Some(v) = along_surface(p, q) else {
            // A plunge straight into the part after the pass's travel (a
            // cam's next turn, a mandrel's next pass) begins the next.
            if travel.is_some() && is_plunge(p, q) {
                runs.push((k, true));
                travel = None;
                stepping = None;
            } else {
                stepping.get_or_insert(k);
            }
            continue;
        };
        let Some(t) = travel else {
            travel = Some(v);
            continue;
        };
        let cos = v.dot(&t) / (v.norm() * t.norm());
        if cos < REVERSAL_COS {
            let from = stepping.unwrap_or(k);
            if from > runs[runs.len() - 1].0 {
                runs.push((from, true));
            }
            travel = Some(v);
            stepping = None;
        } else if cos > -REVERSAL_COS {
            travel = Some(v);
            stepping = None;
        } else if v.norm() > t.norm() {
            // Across a shorter first move (an infeed along the axis): this
            // is the pass's travel.
            travel = Some(v);
        } else {
            // A step across the travel: the pass's travel stays.
            stepping.get_or_insert(k);
        }
    }
    Ok(named(&written, &runs))
}

/// `passes` of `program` (as [`passes_in`] found them) with those whose
/// blocks `touch` finds clear of the material no longer cutting passes: a
/// move at feed away from the part and back above it (a retract and a
/// return at feed, where a shop writes no rapid) cuts nothing. Each such
/// pass's blocks join the pass after it, as its approach (or the start
/// before the first cut, the end after the last); the passes named by
/// their order are numbered again. `None` where every cutting pass
/// touches the material.
///
/// # Failures
/// `touch` failing.
pub fn regrouped<E>(
    program: &AxisProgram,
    passes: &[ProgramPass],
    mut touch: impl FnMut(std::ops::Range<usize>) -> Result<bool, E>,
) -> Result<Option<Vec<ProgramPass>>, E> {
    let mut clear = false;
    let mut runs: Vec<(usize, bool)> = Vec::with_capacity(passes.len());
    for p in passes {
        let cuts = p.cuts && touch(p.blocks.clone())?;
        clear |= p.cuts && !cuts;
        runs.push((p.blocks.start, cuts));
    }
    if !clear {
        return Ok(None);
    }
    let mut merged: Vec<(usize, bool)> = Vec::with_capacity(runs.len());
    let mut pending: Option<usize> = None;
    for (i, &(start, cuts)) in runs.iter().enumerate() {
        let before_any_cut = merged.iter().all(|r| !r.1);
        if i == 0 || (!cuts && before_any_cut) {
            // The start, and what joins it before the first cut.
            if merged.is_empty() {
                merged.push((start, cuts));
            }
            continue;
        }
        let start = pending.take().unwrap_or(start);
        match cuts {
            true => merged.push((start, true)),
            false => pending = Some(start),
        }
    }
    if let Some(start) = pending {
        merged.push((start, false));
    }
    Ok(Some(named(program, &merged)))
}

/// The passes of `written` that `runs` (each run's first block and
/// whether it cuts, in order) make: each to the next run's first block,
/// named by the first comment among its blocks, else by its order among
/// the cutting passes (`pass 3`), `start` before the first cut and `end`
/// after the last.
fn named(written: &AxisProgram, runs: &[(usize, bool)]) -> Vec<ProgramPass> {
    let n = written.blocks.len();
    // The trailing rapids after the last cut are the end.
    let mut out: Vec<ProgramPass> = Vec::with_capacity(runs.len());
    let mut cutting = 0;
    for (i, &(start, cuts)) in runs.iter().enumerate() {
        let end = runs.get(i + 1).map_or(n, |r| r.0);
        if start >= end {
            continue;
        }
        let named = written.blocks[start..end]
            .iter()
            .find_map(|b| b.comment.clone());
        let name = match (named, cuts) {
            (Some(c), _) => c,
            (None, true) => format!("pass {}", cutting + 1),
            (None, false) if i == 0 => "start".into(),
            (None, false) => "end".into(),
        };
        cutting += usize::from(cuts);
        out.push(ProgramPass {
            name,
            blocks: start..end,
            cuts,
        });
    }
    if n > 0 && out.is_empty() {
        out.push(ProgramPass {
            name: "start".into(),
            blocks: 0..n,
            cuts: false,
        });
    }
    out
}

/// How far a cutting move may turn back against its pass's travel before
/// it begins another pass (the cosine of the angle between them, 120
/// degrees): a feed that reverses turns by 180 degrees; one that follows
/// a profile or goes round a part turns by a few; a step across the
/// travel by 90.
pub const REVERSAL_COS: Real = -0.5;

/// Whether the move from `p` to `q` plunges straight into the part (or
/// out of it): its travel along the surface a tenth of its radial part
/// at most.
fn is_plunge(p: Vector3<Real>, q: Vector3<Real>) -> bool {
    let dr = (q.xy().norm() - p.xy().norm()).abs();
    let travel = along_any(p, q).norm();
    dr > crate::tolerance::SAME_LENGTH && travel <= 0.1 * dr
}

/// The travel of a move from `p` to `q` along the surface (see
/// [`along_surface`]), whatever its radial part.
fn along_any(p: Vector3<Real>, q: Vector3<Real>) -> Vector3<Real> {
    let (rp, rq) = (p.xy().norm(), q.xy().norm());
    let turn = if rp > crate::tolerance::SAME_LENGTH && rq > crate::tolerance::SAME_LENGTH {
        let a = q.y.atan2(q.x) - p.y.atan2(p.x);
        // The shorter way round.
        (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    } else {
        0.0
    };
    Vector3::new(q.z - p.z, 0.5 * (rp + rq) * turn, 0.0)
}

/// The travel of a move from `p` to `q` (part frame, Z the part's axis)
/// along the part's surface: along Z and round it (the arc at the mean
/// radius), the radial part left out; `None` where the move is an infeed:
/// its radial part more than half its travel (steeper than 27 degrees
/// to the surface), or no travel.
fn along_surface(p: Vector3<Real>, q: Vector3<Real>) -> Option<Vector3<Real>> {
    let v = along_any(p, q);
    let travel = v.norm();
    let dr = (q.xy().norm() - p.xy().norm()).abs();
    (travel > crate::tolerance::SAME_LENGTH && dr <= 0.5 * travel).then_some(v)
}
