//! Axis programs and post-processors.
//!
//! An [`AxisProgram`] is the toolpath in a machine's own terms: named axes
//! in program units (mm, degrees) and blocks (rapid, linear, thread); its
//! type is the plugin ABI's, since plugins post it. It is made from a
//! [`Toolpath`] by a [`MachineKinematics`] ([`build`]: inverse kinematics of
//! every point in one batch, then travel and feed checks naming the block
//! and axis), and written as text by a [`PostProcessor`]: the shared writer
//! in a control's dialect ([`post`]), or a plugin's own.

pub mod post;

pub use pilgrim_plugin_abi::types::{AxisProgram, Block, ProgramAxis};
pub use post::{post, Dialect, PostError, PostProcessor, SharedPost};

use crate::machine::{Axis, MachineError, MachineInfo, MachineKinematics};
use crate::math::Real;
use crate::toolpath::{Motion, Toolpath, ToolpathError};

/// The least feed of a cutting block on any machine (mm/min): below it a
/// move would take longer than a report can say.
pub const MIN_FEED: Real = 1e-3;

/// Errors making a program from a toolpath; blocks are numbered from 1.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProgramError {
    /// The toolpath itself is bad.
    #[error(transparent)]
    Toolpath(#[from] ToolpathError),
    /// Inverse kinematics failed at a block.
    #[error("block {block} (pass {pass}, point {point}): {message}")]
    Kinematics {
        /// Block number (from 1).
        block: usize,
        /// Pass (from 1).
        pass: usize,
        /// Point in the pass (from 1).
        point: usize,
        /// What failed.
        message: String,
    },
    /// The machine's kinematics failed as a whole.
    #[error("machine {machine}: {message}")]
    Machine {
        /// The machine.
        machine: String,
        /// What failed.
        message: String,
    },
    /// An auxiliary value that is no programmed axis of the machine.
    #[error(
        "auxiliary value '{name}' is not a programmed axis of machine {machine} (axes: {known})"
    )]
    UnknownAux {
        /// The name.
        name: String,
        /// The machine.
        machine: String,
        /// Its programmed axes.
        known: String,
    },
    /// A block outside an axis's travel.
    #[error("block {block}: axis {axis} at {value:.4} {unit} is outside its travel [{min}, {max}] {unit}")]
    OutsideTravel {
        /// Block number (from 1).
        block: usize,
        /// The axis.
        axis: String,
        /// Its value (mm or deg).
        value: Real,
        /// Lower limit.
        min: Real,
        /// Upper limit.
        max: Real,
        /// mm or deg.
        unit: &'static str,
    },
    /// A cutting block slower than the machine's controls accept.
    #[error("block {block}: feed {feed:e} mm/min is below the minimum feed of machine {machine}, {min} mm/min")]
    FeedTooLow {
        /// Block number (from 1).
        block: usize,
        /// The feed.
        feed: Real,
        /// The machine.
        machine: String,
        /// Its least feed.
        min: Real,
    },
    /// A block faster than an axis can go.
    #[error("block {block}: axis {axis} would move at {speed:.1} {unit}, above its maximum {max} {unit}")]
    FeedExceeded {
        /// Block number (from 1).
        block: usize,
        /// The axis.
        axis: String,
        /// Speed needed.
        speed: Real,
        /// The axis's maximum.
        max: Real,
        /// mm/min or deg/min.
        unit: &'static str,
    },
}

impl ProgramError {
    /// A machine limit error, its point index read as a block (from 0), on
    /// the machine called `machine`.
    fn from_limit(machine: &str, e: MachineError) -> Self {
        match e {
            MachineError::OutsideTravel {
                point,
                axis,
                value,
                min,
                max,
                unit,
            } => Self::OutsideTravel {
                block: point + 1,
                axis,
                value,
                min,
                max,
                unit,
            },
            MachineError::FeedExceeded {
                point,
                axis,
                speed,
                max,
                unit,
            } => Self::FeedExceeded {
                block: point + 1,
                axis,
                speed,
                max,
                unit,
            },
            other => Self::Machine {
                machine: machine.to_owned(),
                message: other.to_string(),
            },
        }
    }
}

/// The program for `toolpath` on `machine`: inverse kinematics of every
/// point (one batch), auxiliary values mapped to the machine's axes of
/// the same names (an auxiliary value named like an axis inverse
/// kinematics solves drives that axis, and the others are solved around
/// it), values in program units, then travel and feed checks.
/// Every pass's first block carries the pass's name as a comment.
///
/// # Failures
/// A bad toolpath (named by pass and point); an auxiliary name that is
/// no programmed axis; inverse kinematics failing at a point; a block
/// outside travel or too fast for an axis (named by block and axis).
pub fn build(
    toolpath: &Toolpath,
    machine: &dyn MachineKinematics,
    name: &str,
) -> Result<AxisProgram, ProgramError> {
    toolpath.validate()?;
    let info = machine.info();
    let machine_err = |message: String| ProgramError::Machine {
        machine: info.name.clone(),
        message,
    };
    let mut poses = Vec::with_capacity(toolpath.point_count() * 6);
    for (_, _, c) in toolpath.points() {
        poses.extend_from_slice(&c.point);
        poses.extend_from_slice(&c.axis);
    }
    // Auxiliary values named like solved axes drive those axes.
    let held: Vec<(usize, usize)> = info
        .solved_axes
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            toolpath
                .aux_names
                .iter()
                .position(|a| a == s)
                .map(|j| (i, j))
        })
        .collect();
    let held_axes: Vec<usize> = held.iter().map(|h| h.0).collect();
    let held_values: Vec<Real> = toolpath
        .points()
        .flat_map(|(_, _, c)| {
            held.iter()
                .map(|&(_, j)| aux_internal(info, &toolpath.aux_names[j], c.aux[j]))
                .collect::<Vec<_>>()
        })
        .collect();
    let mut solved = Vec::new();
    machine
        .inverse_held(
            &poses,
            &toolpath.tool.reference,
            &held_axes,
            &held_values,
            &mut solved,
        )
        .map_err(|e| {
            match e
                .index
                .and_then(|i| toolpath.points().nth(i).map(|(p, q, _)| (i, p, q)))
            {
                Some((i, p, q)) => ProgramError::Kinematics {
                    block: i + 1,
                    pass: p + 1,
                    point: q + 1,
                    message: e.message,
                },
                None => machine_err(e.message),
            }
        })?;
    let n_solved = info.solved_axes.len();
    if solved.len() != toolpath.point_count() * n_solved {
        return Err(machine_err(format!(
            "inverse kinematics returned {} values for {} poses of {} axes",
            solved.len(),
            toolpath.point_count(),
            n_solved
        )));
    }
    // Program columns, in the machine's axis order: solved axes and
    // auxiliary values, each a programmed axis.
    let programmed: Vec<&Axis> = info.axes.iter().filter(|a| a.is_programmed()).collect();
    for aux in &toolpath.aux_names {
        if !programmed.iter().any(|a| &a.name == aux) {
            return Err(ProgramError::UnknownAux {
                name: aux.clone(),
                machine: info.name.clone(),
                known: programmed
                    .iter()
                    .map(|a| a.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
    }
    enum Source {
        Solved(usize),
        Aux(usize),
    }
    let mut columns: Vec<(&Axis, Source)> = Vec::new();
    for a in &programmed {
        // Solved first: a driven solved axis is in the solved rows too.
        if let Some(i) = info.solved_axes.iter().position(|s| s == &a.name) {
            columns.push((a, Source::Solved(i)));
        } else if let Some(i) = toolpath.aux_names.iter().position(|s| s == &a.name) {
            columns.push((a, Source::Aux(i)));
        }
    }
    let mut blocks = Vec::with_capacity(toolpath.point_count());
    let mut rows_internal = Vec::with_capacity(toolpath.point_count() * columns.len());
    for (k, (p, j, c)) in toolpath.points().enumerate() {
        let row = &solved[k * n_solved..(k + 1) * n_solved];
        let internal: Vec<Real> = columns
            .iter()
            .map(|(_, s)| match s {
                Source::Solved(i) => row[*i],
                Source::Aux(i) => aux_internal(info, &toolpath.aux_names[*i], c.aux[*i]),
            })
            .collect();
        let values = columns
            .iter()
            .zip(&internal)
            .map(|((a, _), v)| a.to_user(*v))
            .collect();
        rows_internal.extend_from_slice(&internal);
        blocks.push(Block {
            motion: c.motion,
            values,
            feed: match c.motion {
                Motion::Rapid => 0.0,
                Motion::Linear => c.feed,
                Motion::Thread { lead } => lead * toolpath.spindle_rpm,
            },
            spindle: (k == 0).then_some(toolpath.spindle_rpm),
            comment: (j == 0).then(|| toolpath.passes[p].name.clone()),
        });
    }
    let min = info.min_feed.unwrap_or(MIN_FEED).max(MIN_FEED);
    if let Some((i, b)) = blocks
        .iter()
        .enumerate()
        .find(|(_, b)| b.motion != Motion::Rapid && !(b.feed >= min))
    {
        return Err(ProgramError::FeedTooLow {
            block: i + 1,
            feed: b.feed,
            machine: info.name.clone(),
            min,
        });
    }
    let axes_refs: Vec<&Axis> = columns.iter().map(|(a, _)| *a).collect();
    crate::machine::check_travel(&axes_refs, &rows_internal)
        .map_err(|e| ProgramError::from_limit(&info.name, e))?;
    // Feed: rapid blocks move at the machine's rapid rate, not checked.
    let feeds: Vec<Real> = blocks
        .iter()
        .map(|b| {
            if b.motion == Motion::Rapid {
                Real::INFINITY
            } else {
                b.feed
            }
        })
        .collect();
    crate::machine::check_feed(&axes_refs, &rows_internal, &feeds)
        .map_err(|e| ProgramError::from_limit(&info.name, e))?;
    Ok(AxisProgram {
        name: program_name(name),
        number: 1,
        machine: info.name.clone(),
        control: info.control.clone(),
        tool_number: toolpath.tool.number,
        tool_name: toolpath.tool.name.clone(),
        spindle_rpm: toolpath.spindle_rpm,
        decimals: info.program_decimals,
        axes: columns
            .iter()
            .map(|(a, _)| ProgramAxis {
                name: a.name.clone(),
                unit: a.unit().to_owned(),
            })
            .collect(),
        blocks,
    })
}

/// An auxiliary value in kernel units: toolpaths give rotary aux values in
/// degrees (as the family's user thinks of them) and linear in mm.
fn aux_internal(info: &MachineInfo, name: &str, v: Real) -> Real {
    info.axis(name).map_or(v, |a| a.from_user(v))
}

/// The values of the axes `names` at the blocks `blocks` (indices from 0),
/// row after row, in kernel units (mm, rad): what forward kinematics of the
/// program takes.
///
/// # Failures
/// A block beyond the program; an axis the program or the machine lacks
/// (the message names it).
pub fn axis_rows(
    program: &AxisProgram,
    info: &MachineInfo,
    names: &[String],
    blocks: std::ops::Range<usize>,
) -> Result<Vec<Real>, String> {
    if blocks.end > program.blocks.len() {
        return Err(format!(
            "block {} is beyond the program's {} blocks",
            blocks.end,
            program.blocks.len()
        ));
    }
    let cols = names
        .iter()
        .map(|name| {
            let c = program
                .axes
                .iter()
                .position(|a| &a.name == name)
                .ok_or(format!("the program has no axis {name}"))?;
            let axis = info
                .axis(name)
                .ok_or(format!("machine {} has no axis {name}", info.name))?;
            Ok((c, axis))
        })
        .collect::<Result<Vec<(usize, &Axis)>, String>>()?;
    Ok(program.blocks[blocks]
        .iter()
        .flat_map(|b| cols.iter().map(|&(c, a)| a.from_user(b.values[c])))
        .collect())
}

/// A name a control accepts: upper case letters, digits and `_`, starting
/// with a letter (`PILGRIM` if nothing is left).
pub fn program_name(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    if !s.starts_with(|c: char| c.is_ascii_alphabetic()) {
        s.insert_str(0, "P_");
    }
    s.truncate(24);
    s
}
