//! Axis programs and post-processors.
//!
//! An [`AxisProgram`] is the toolpath in a machine's own terms: named axes
//! in program units (mm, degrees) and blocks (rapid, linear, thread); its
//! type is the plugin ABI's, since plugins post it. It is made from a
//! [`Toolpath`] by a [`MachineKinematics`] ([`build`]: inverse kinematics of
//! every point in one batch, then travel and feed checks naming the block
//! and axis), and written as text by a [`PostProcessor`]: the shared writer
//! in a control's dialect ([`post()`]), or a plugin's own.

pub mod cycle;
pub mod expansion;
pub mod lint;
pub(crate) mod macros;
pub mod offsets;
pub mod post;
pub mod reader;
pub mod words;

pub use pilgrim_plugin_abi::types::{
    AxisProgram, Block, Plane, PowerOn, ProgramAxis, ProgramSetup, Radial,
};
pub use post::{post, Dialect, PostError, PostProcessor, SharedPost};

use crate::machine::{Axis, AxisKind, MachineError, MachineInfo, MachineKinematics};
use crate::math::Real;
use crate::toolpath::{pass_ranges, CycleWords, Motion, Pass, Toolpath, ToolpathError};
use std::ops::Range;

/// How near (in the last written digit's units) a value may be to half a
/// step and still be rounded by arithmetic: nearer, it is a tie the
/// value's text decides (binary arithmetic cannot tell a tie from a value
/// a rounding off it).
const TIE: Real = 1e-6;

/// How far (mm, deg) a block read from a program may be from the move of
/// the cycle it stands for and still be that move: a nanometre, far below
/// the program's written step and far above the arithmetic that expands
/// the cycle.
const CYCLE_MATCH: Real = 1e-6;

/// The least feed of a cutting block on any machine (mm/min): below it a
/// move would take longer than a report can say.
pub const MIN_FEED: Real = 1e-3;

/// A program that is not one a machine runs, or that cannot be read as
/// asked (an axis it lacks, a block beyond it, words the control would not
/// read): the block where it is, if at one, and what is wrong (the message
/// names the block as the program numbers it).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct ProgramFault {
    /// The block (from 0) where it is, if at one.
    pub block: Option<usize>,
    /// What is wrong, and where.
    pub message: String,
}

impl ProgramFault {
    /// A fault at no block.
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            block: None,
            message: message.into(),
        }
    }

    /// A fault at block `block` (from 0).
    pub fn at(block: usize, message: impl Into<String>) -> Self {
        Self {
            block: Some(block),
            message: message.into(),
        }
    }
}

/// Errors making a program from a toolpath. Blocks are named as the
/// program names them ([`block_name`]: `N570 in "pass 1"`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProgramError {
    /// The toolpath itself is bad.
    #[error(transparent)]
    Toolpath(#[from] ToolpathError),
    /// Inverse kinematics failed at a block.
    #[error("{block}: {message}")]
    Kinematics {
        /// The block, as the program names it.
        block: String,
        /// What failed.
        message: String,
    },
    /// A toolpath's threading cycle whose passes are not the moves the
    /// cycle makes, or that the program cannot hold.
    #[error("{block}: {message}")]
    Cycle {
        /// The block, as the program names it.
        block: String,
        /// What is wrong.
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
    /// An axis the machine takes from the toolpath that the toolpath does
    /// not drive.
    #[error("machine {machine} takes axis {axis} from the toolpath, which does not drive it (its values: {given}): the family must give {axis} at every point")]
    NotDriven {
        /// The axis.
        axis: String,
        /// The machine.
        machine: String,
        /// The auxiliary values the toolpath gives.
        given: String,
    },
    /// A block outside an axis's travel.
    #[error(
        "{block}: axis {axis} at {value:.4} {unit} is outside its travel [{min}, {max}] {unit}"
    )]
    OutsideTravel {
        /// The block, as the program names it.
        block: String,
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
    #[error("{block}: feed {feed:e} mm/min is below the minimum feed of machine {machine}, {min} mm/min")]
    FeedTooLow {
        /// The block, as the program names it.
        block: String,
        /// The feed.
        feed: Real,
        /// The machine.
        machine: String,
        /// Its least feed.
        min: Real,
    },
    /// A block faster than an axis can go.
    #[error(
        "{block}: axis {axis} would move at {speed:.1} {unit}, above its maximum {max} {unit}"
    )]
    FeedExceeded {
        /// The block, as the program names it.
        block: String,
        /// The axis.
        axis: String,
        /// Speed needed.
        speed: Real,
        /// The axis's maximum.
        max: Real,
        /// mm/min or deg/min.
        unit: &'static str,
    },
    /// A thread block whose lead times the spindle's speed is beyond the
    /// feed of the axis that carries it.
    #[error("{block}: a thread of lead {lead:.4} mm at {rpm} rpm needs axis {axis} at {speed:.1} mm/min, above its maximum {max} mm/min: lower the spindle speed")]
    ThreadTooFast {
        /// The block, as the program names it.
        block: String,
        /// The lead (mm).
        lead: Real,
        /// The spindle speed (rpm).
        rpm: Real,
        /// The axis.
        axis: String,
        /// Speed needed (mm/min).
        speed: Real,
        /// The axis's maximum (mm/min).
        max: Real,
    },
    /// A spindle speed the program writes as `S0`: the spindle would stand
    /// while the program cuts.
    #[error("{block}: spindle speed {rpm} rpm is written S0: the part (or tool) would stand still while the program cuts; give a speed of at least 1 rpm")]
    SpindleStopped {
        /// The block, as the program names it.
        block: String,
        /// The speed (rpm).
        rpm: Real,
    },
    /// A spindle speed outside the machine's spindle range.
    #[error("{block}: spindle speed S{rpm} is outside the range of spindle {axis} of machine {machine}, [{min}, {max}] rpm")]
    Spindle {
        /// The block, as the program names it.
        block: String,
        /// The speed (rpm).
        rpm: Real,
        /// The spindle axis.
        axis: String,
        /// The machine.
        machine: String,
        /// Its least speed.
        min: Real,
        /// Its greatest speed.
        max: Real,
    },
}

impl ProgramError {
    /// A machine limit error, its point index read as block `index`, named
    /// by `name`, on the machine called `machine`.
    fn from_limit(machine: &str, e: MachineError, name: impl Fn(usize) -> String) -> Self {
        match e {
            MachineError::OutsideTravel {
                point,
                axis,
                value,
                min,
                max,
                unit,
            } => Self::OutsideTravel {
                block: name(point),
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
                block: name(point),
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

/// How many blocks a machine's setup puts before the toolpath's first: the
/// start's clearing move and each approach group.
pub fn start_blocks(setup: &ProgramSetup) -> usize {
    usize::from(!setup.start_clear.is_empty()) + setup.approach.len()
}

/// A pass as a program holds it: its name, the blocks (indices from 0) it
/// is, and whether it cuts ([`Pass::cuts`]: a move other than a rapid
/// that moves the tool). The replays take passes in this form, whether
/// they come from the toolpath a program was built from
/// ([`pass_blocks`]) or from a program's text (its comments).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProgramPass {
    /// Its name (the comment before its first block).
    pub name: String,
    /// Its blocks in the program.
    pub blocks: Range<usize>,
    /// Whether it cuts.
    pub cuts: bool,
}

/// Each of `passes` with the blocks (indices from 0) it became in
/// `program`, which was built from them ([`build`]): after the setup's
/// start blocks.
pub fn pass_blocks(program: &AxisProgram, passes: &[Pass]) -> Vec<ProgramPass> {
    let lead = start_blocks(&program.setup);
    pass_ranges(passes)
        .map(|(p, r)| ProgramPass {
            name: p.name.clone(),
            blocks: r.start + lead..r.end + lead,
            cuts: p.cuts(),
        })
        .collect()
}

/// Checks a program read back from a file (a run's `program.json`, which
/// anyone may have edited) before anything is done with it: every block
/// holds one finite value per axis, feeds and spindle speeds are finite
/// and not negative, the axes and the axes a block keeps are the
/// program's, and the blocks are at most [`crate::toolpath::MAX_POINTS`]
/// and a few more for the setup's moves.
///
/// # Failures
/// The first fault, naming the block as the program numbers it.
pub fn check_shape(program: &AxisProgram) -> Result<(), ProgramFault> {
    let width = program.axes.len();
    let letters = crate::machine::AXIS_LETTERS;
    if width == 0 || width > letters.len() {
        return Err(ProgramFault::new(format!(
            "{width} axes (a program has 1 to {})",
            letters.len()
        )));
    }
    for (i, a) in program.axes.iter().enumerate() {
        if !(a.name.len() == 1 && letters.contains(a.name.as_str()))
            || program.axes[..i].iter().any(|b| b.name == a.name)
        {
            return Err(ProgramFault::new(format!(
                "axis {} is not one of the letters {letters}, once each",
                crate::names::quoted(&a.name)
            )));
        }
    }
    let most = crate::toolpath::MAX_POINTS + 64;
    if program.blocks.len() > most {
        return Err(ProgramFault::new(format!(
            "{} blocks, more than the {most} a run writes",
            program.blocks.len()
        )));
    }
    for (i, b) in program.blocks.iter().enumerate() {
        let at = || block_label(&program.control, i);
        if b.values.len() != width {
            return Err(ProgramFault::new(format!(
                "{}: {} values for the program's {width} axes",
                at(),
                b.values.len()
            )));
        }
        if let Some(v) = b.values.iter().find(|v| !v.is_finite()) {
            return Err(ProgramFault::new(format!(
                "{}: the value {v} is not a finite number",
                at()
            )));
        }
        if !(b.feed.is_finite() && b.feed >= 0.0)
            || b.spindle.is_some_and(|s| !(s.is_finite() && s >= 0.0))
            || !(b.dwell_s.is_finite() && b.dwell_s >= 0.0)
        {
            return Err(ProgramFault::new(format!(
                "{}: a feed, spindle speed or dwell that is not a finite number of at least 0",
                at()
            )));
        }
        if let Some(k) = b
            .keep
            .iter()
            .find(|k| !program.axes.iter().any(|a| &a.name == *k))
        {
            return Err(ProgramFault::new(format!(
                "{}: it keeps axis {}, which is not the program's",
                at(),
                crate::names::quoted(k)
            )));
        }
    }
    Ok(())
}

/// The number a program in the dialect `control` gives its block `index`
/// (from 0): `N570` where the dialect numbers blocks (the shared writer's
/// numbering, [`post::Dialect::numbering`]), else `block 57`.
pub fn block_label(control: &str, index: usize) -> String {
    match post::dialect(control).and_then(|d| d.numbering) {
        Some((first, step)) => format!("N{}", first + step * index as u64),
        None => format!("block {}", index + 1),
    }
}

/// The label block `index` (from 0) of `blocks` has in a program in the
/// dialect `control`: where it was read from a file, the `N` its text
/// gives it ([`Block::number`]), else its line (`line 15`,
/// [`Block::line`]); else the writer's ([`block_label`]).
pub fn label_in(control: &str, blocks: &[Block], index: usize) -> String {
    let b = blocks.get(index);
    match (b.and_then(|b| b.number), b.and_then(|b| b.line)) {
        (Some(n), _) => format!("N{n}"),
        (None, Some(l)) => format!("line {l}"),
        (None, None) => block_label(control, index),
    }
}

/// Block `index` (from 0) of `program` as the program names it: its label
/// ([`block_label`]) and the pass it is in (the last comment at or before
/// it): `N570 in "pass 1, stock 225.0 um"`.
pub fn block_name(program: &AxisProgram, index: usize) -> String {
    name_in(&program.control, &program.blocks, index)
}

pub(crate) fn name_in(control: &str, blocks: &[Block], index: usize) -> String {
    let label = label_in(control, blocks, index);
    let pass = blocks
        .get(..=index.min(blocks.len().saturating_sub(1)))
        .and_then(|b| b.iter().rev().find_map(|b| b.comment.as_deref()));
    match pass {
        Some(p) => format!("{label} in \"{}\"", crate::files::excerpt(p)),
        None => label,
    }
}

/// The spindle speed (rpm) in force at each block of `program`: the
/// program's, then each block's `spindle` from that block on.
pub fn spindle_speeds(program: &AxisProgram) -> impl Iterator<Item = Real> + '_ {
    program.blocks.iter().scan(program.spindle_rpm, |rpm, b| {
        *rpm = b.spindle.unwrap_or(*rpm);
        Some(*rpm)
    })
}

/// The decimals a program writes its axis values with: its own
/// (`decimals`, the machine's), else its dialect's (`control`), else 3.
pub fn written_decimals(decimals: Option<usize>, control: &str) -> usize {
    decimals
        .or_else(|| post::dialect(control).map(|d| d.decimals))
        .unwrap_or(3)
}

/// `v` as a program with `decimals` writes it and a control reads it back:
/// the one rounding every reader of a program's values uses (replays,
/// feed checks, cycle times, feeds over rotary moves).
///
/// The same number as formatting and parsing (`fixed`), faster: away from
/// a tie, `round(v 10^d) / 10^d` is the nearest double to the decimal the
/// file holds (an exact integer over an exact power of ten, divided once);
/// within 1e-6 of a tie, or beyond 2^52, the text decides.
pub fn written(v: Real, decimals: usize) -> Real {
    let scale = 10f64.powi(decimals.min(22) as i32);
    let t = v * scale;
    if t.abs() < 4.5e15 && (t.fract().abs() - 0.5).abs() > TIE {
        t.round() / scale + 0.0
    } else {
        crate::math::fixed(v, decimals).parse().unwrap_or(v)
    }
}

/// Where a cutting block turns a rotary axis, its feed becomes the
/// control's: the toolpath's feed is the tracked point's speed relative to
/// the part, while a control (Sinumerik, Fanuc, G94) reads F as the path
/// feed of the linear axes, in deg/min on a move that only turns, or of
/// the machine's feed group ([`crate::machine::feed_length`]), over the
/// values as written. The block's F is set so that the
/// move takes the time the tracked point needs at the toolpath's feed over
/// the chord between the two points; blocks that turn nothing keep their
/// feed. `blocks` are the toolpath's, one per point, in order.
fn rotary_feeds(blocks: &mut [Block], axes: &[&Axis], toolpath: &Toolpath, info: &MachineInfo) {
    let decimals = written_decimals(info.program_decimals, &info.control);
    let points: Vec<&crate::toolpath::ClPoint> = toolpath.points().map(|(_, _, c)| c).collect();
    for k in 1..blocks.len().min(points.len()) {
        if blocks[k].motion != Motion::Linear {
            continue;
        }
        let deltas: Vec<Real> = blocks[k]
            .values
            .iter()
            .zip(&blocks[k - 1].values)
            .map(|(b, a)| written(*b, decimals) - written(*a, decimals))
            .collect();
        let turns = axes
            .iter()
            .zip(&deltas)
            .any(|(a, d)| a.kind == AxisKind::Rotary && d.abs() > crate::tolerance::ROUNDING);
        let (p, q) = (points[k - 1].point, points[k].point);
        let chord = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt();
        if !turns || !(chord > 0.0) {
            continue;
        }
        let minutes = chord / blocks[k].feed;
        let length = crate::machine::feed_length(axes, &deltas, &info.setup.feed_group);
        if length > 0.0 {
            blocks[k].feed = length / minutes;
        }
    }
}

/// The program for `toolpath` on `machine`: inverse kinematics of every
/// point (one batch), auxiliary values mapped to the machine's axes of
/// the same names (an auxiliary value named like an axis inverse
/// kinematics solves drives that axis, and the others are solved around
/// it), values in program units; the machine's start before the first
/// point (its axes cleared, then brought in, group by group, as its setup
/// says: [`ProgramSetup`]) and its end after the last; then every word
/// checked against the machine: travel, feeds (`rotary_feeds` where a
/// rotary axis moves) (each axis's and the
/// least), the spindle's speed. Every pass's first block carries the
/// pass's name as a comment; the start's and the end's blocks carry
/// `start` and `end`.
///
/// # Failures
/// A bad toolpath (named by pass and point); an auxiliary name that is no
/// programmed axis; an axis the machine takes from the toolpath
/// ([`MachineInfo::driven_axes`]) that it does not give; inverse kinematics
/// failing at a point; a block outside travel, too fast for an axis, too
/// slow for the control, or a spindle speed beyond the spindle's range
/// (named by block, as the program numbers it, and axis).
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
    for axis in &info.driven_axes {
        if !toolpath.aux_names.contains(axis) {
            return Err(ProgramError::NotDriven {
                axis: axis.clone(),
                machine: info.name.clone(),
                given: if toolpath.aux_names.is_empty() {
                    "none".into()
                } else {
                    toolpath.aux_names.join(", ")
                },
            });
        }
    }
    let lead = start_blocks(&info.setup);
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
                .and_then(|i| toolpath.points().nth(i).map(|(p, _, _)| (i, p)))
            {
                Some((i, p)) => ProgramError::Kinematics {
                    block: format!(
                        "{} in \"{}\"",
                        block_label(&info.control, lead + i),
                        toolpath.passes[p].name
                    ),
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
    let mut blocks = Vec::with_capacity(toolpath.point_count() + lead + 4);
    for (k, (p, j, c)) in toolpath.points().enumerate() {
        let row = &solved[k * n_solved..(k + 1) * n_solved];
        let values = columns
            .iter()
            .map(|(a, s)| {
                a.to_user(match s {
                    Source::Solved(i) => row[*i],
                    Source::Aux(i) => aux_internal(info, &toolpath.aux_names[*i], c.aux[*i]),
                })
            })
            .collect();
        blocks.push(Block {
            motion: c.motion,
            values,
            feed: match c.motion {
                Motion::Rapid => 0.0,
                Motion::Linear => c.feed,
                Motion::Thread { lead, .. } => lead * toolpath.spindle_rpm,
            },
            spindle: (k == 0).then_some(toolpath.spindle_rpm),
            comment: (j == 0).then(|| toolpath.passes[p].name.clone()),
            keep: Vec::new(),
            number: None,
            line: None,
            dwell_s: 0.0,
        });
    }
    let col_axes: Vec<&Axis> = columns.iter().map(|(a, _)| *a).collect();
    rotary_feeds(&mut blocks, &col_axes, toolpath, info);
    let names: Vec<&str> = columns.iter().map(|(a, _)| a.name.as_str()).collect();
    let blocks = with_start_and_end(blocks, &names, &info.setup);
    let name_of = |i: usize| name_in(&info.control, &blocks, i);
    let (cycles, fanuc_cycles) = cycle_spans(
        toolpath,
        &blocks,
        start_blocks(&info.setup),
        &names,
        info,
        &name_of,
    )?;
    check_spindle(info, &blocks, toolpath.spindle_rpm, &name_of)?;
    let min = info.min_feed.unwrap_or(MIN_FEED).max(MIN_FEED);
    if let Some((i, b)) = blocks
        .iter()
        .enumerate()
        .find(|(_, b)| b.motion != Motion::Rapid && !(b.feed >= min))
    {
        return Err(ProgramError::FeedTooLow {
            block: name_of(i),
            feed: b.feed,
            machine: info.name.clone(),
            min,
        });
    }
    let axes_refs: Vec<&Axis> = columns.iter().map(|(a, _)| *a).collect();
    // Rows in kernel units, each value first mapped by `f`.
    let rows = |f: &dyn Fn(Real) -> Real| -> Vec<Real> {
        blocks
            .iter()
            .flat_map(|b| {
                axes_refs
                    .iter()
                    .zip(&b.values)
                    .map(|(a, v)| a.from_user(f(*v)))
            })
            .collect()
    };
    let rows_internal = rows(&|v| v);
    crate::machine::check_travel(&axes_refs, &rows_internal)
        .map_err(|e| ProgramError::from_limit(&info.name, e, name_of))?;
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
    // Speeds as the control runs the program: its values as written.
    let decimals = written_decimals(info.program_decimals, &info.control);
    let rows_written = rows(&|v| written(v, decimals));
    crate::machine::check_feed_grouped(&axes_refs, &rows_written, &feeds, &info.setup.feed_group)
        .map_err(|e| {
        // A thread's feed is the lead times the spindle's speed.
        if let MachineError::FeedExceeded {
            point,
            axis,
            speed,
            max,
            ..
        } = &e
        {
            if let Some(Motion::Thread { lead, .. }) = blocks.get(*point).map(|b| b.motion) {
                return ProgramError::ThreadTooFast {
                    block: name_of(*point),
                    lead,
                    rpm: toolpath.spindle_rpm,
                    axis: axis.clone(),
                    speed: *speed,
                    max: *max,
                };
            }
        }
        ProgramError::from_limit(&info.name, e, name_of)
    })?;
    Ok(AxisProgram {
        name: program_name(name),
        // A block to paste after the tool call until the caller numbers it.
        number: 0,
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
        setup: info.setup.clone(),
        cycles,
        fanuc_cycles,
    })
}

/// The toolpath's threading cycles as runs of the program's `blocks`
/// (the toolpath's own start `offset` blocks after the program's start),
/// LinuxCNC's and Fanuc's apart, each checked to be the moves its cycle
/// makes from the block before it: X and Z as the cycle puts them (X on
/// diameter where the machine's setup programs it so), every other axis
/// standing, within 1 um.
fn cycle_spans(
    toolpath: &Toolpath,
    blocks: &[Block],
    offset: usize,
    names: &[&str],
    info: &MachineInfo,
    name_of: &dyn Fn(usize) -> String,
) -> Result<(Vec<cycle::CycleSpan>, Vec<cycle::FanucCycleSpan>), ProgramError> {
    let ranges: Vec<std::ops::Range<usize>> = toolpath.pass_ranges().map(|(_, r)| r).collect();
    let diameter = info.setup.radial == Some(pilgrim_plugin_abi::types::Radial::Diameter);
    let (Some(x), Some(z)) = (
        names.iter().position(|n| *n == "X"),
        names.iter().position(|n| *n == "Z"),
    ) else {
        return match toolpath.cycles.first() {
            None => Ok((Vec::new(), Vec::new())),
            Some(_) => Err(ProgramError::Machine {
                machine: info.name.clone(),
                message:
                    "a threading cycle needs the axes X and Z, which the machine does not program"
                        .into(),
            }),
        };
    };
    let mut linuxcnc: Vec<cycle::CycleSpan> = Vec::new();
    let mut fanuc: Vec<cycle::FanucCycleSpan> = Vec::new();
    let mut last_end = 0;
    for c in &toolpath.cycles {
        let (first, last) = (c.first_pass, c.first_pass + c.passes);
        let bad = |block: usize, message: String| ProgramError::Cycle {
            block: name_of(block),
            message,
        };
        if c.passes == 0 || last > ranges.len() {
            return Err(bad(
                offset,
                format!(
                    "a threading cycle over passes {} to {last}, of the toolpath's {}",
                    first + 1,
                    ranges.len()
                ),
            ));
        }
        let span = offset + ranges[first].start..offset + ranges[last - 1].end;
        if span.start == 0 || last_end > span.start - 1 {
            return Err(bad(
                span.start,
                "a threading cycle with no move of its own before it (the drive line it starts from)".into(),
            ));
        }
        let before = &blocks[span.start - 1];
        let start = [before.values[x], before.values[z]];
        let (moves, rounded) = match &c.cycle {
            CycleWords::Linuxcnc(w) => (
                cycle::expand(w, start, diameter, None),
                (cycle::as_written(w) != *w).then(|| cycle::words(w)),
            ),
            CycleWords::FanucTwoBlock(w) => (
                cycle::expand_fanuc(w, start, diameter, &cycle::OWN_FANUC_RULES),
                (cycle::fanuc_as_written(w) != *w).then(|| cycle::fanuc_blocks(w).join(" ")),
            ),
        };
        if let Some(words) = rounded {
            return Err(bad(
                span.start,
                format!(
                    "the threading cycle's words are not as a program writes them ({words}): round them with the cycle's own rounding"
                ),
            ));
        }
        let moves = moves.map_err(|m| bad(span.start, m.message))?;
        if moves.len() != span.len() {
            return Err(bad(
                span.start,
                format!(
                    "the threading cycle makes {} moves, its passes hold {}",
                    moves.len(),
                    span.len()
                ),
            ));
        }
        for (i, m) in span.clone().zip(&moves) {
            let b = &blocks[i];
            let stands = (0..names.len())
                .filter(|&k| k != x && k != z)
                .all(|k| (b.values[k] - before.values[k]).abs() <= CYCLE_MATCH);
            if b.motion != m.motion
                || (b.values[x] - m.x).abs() > CYCLE_MATCH
                || (b.values[z] - m.z).abs() > CYCLE_MATCH
                || !stands
            {
                return Err(bad(
                    i,
                    format!(
                        "{} to X{} Z{}, where the threading cycle makes {} to X{} Z{}",
                        b.motion, b.values[x], b.values[z], m.motion, m.x, m.z
                    ),
                ));
            }
        }
        last_end = span.end;
        match &c.cycle {
            CycleWords::Linuxcnc(w) => linuxcnc.push(cycle::CycleSpan {
                first: span.start,
                count: span.len(),
                cycle: w.clone(),
            }),
            CycleWords::FanucTwoBlock(w) => fanuc.push(cycle::FanucCycleSpan {
                first: span.start,
                count: span.len(),
                cycle: *w,
            }),
        }
    }
    Ok((linuxcnc, fanuc))
}

/// `blocks` (the toolpath's) with the setup's start before them and its end
/// after them (`axes`: the program's columns). The start: the axes of
/// `start_clear` to their clear positions, every other axis kept where it
/// stands; then each approach group to the first block's values, the axes
/// not yet moved kept. The end: each retract group to its clear positions.
/// Axes the setup names that the program lacks are left out.
fn with_start_and_end(blocks: Vec<Block>, axes: &[&str], setup: &ProgramSetup) -> Vec<Block> {
    let (Some(first), Some(last)) = (blocks.first(), blocks.last()) else {
        return blocks;
    };
    let col = |name: &str| axes.iter().position(|a| *a == name);
    let rapid = |values: Vec<Real>, keep: Vec<String>| Block {
        motion: Motion::Rapid,
        values,
        feed: 0.0,
        spindle: None,
        comment: None,
        keep,
        number: None,
        line: None,
        dwell_s: 0.0,
    };
    let mut out = Vec::with_capacity(blocks.len() + start_blocks(setup) + setup.retract.len());
    let mut moved: Vec<bool> = vec![false; axes.len()];
    let mut values = first.values.clone();
    let kept = |moved: &[bool]| -> Vec<String> {
        axes.iter()
            .zip(moved)
            .filter(|(_, m)| !**m)
            .map(|(a, _)| (*a).to_owned())
            .collect()
    };
    if !setup.start_clear.is_empty() {
        for a in &setup.start_clear {
            if let (Some(c), Some(v)) = (col(a), setup.clear.get(a)) {
                values[c] = *v;
                moved[c] = true;
            }
        }
        out.push(rapid(values.clone(), kept(&moved)));
    }
    for group in &setup.approach {
        for a in group {
            if let Some(c) = col(a) {
                values[c] = first.values[c];
                moved[c] = true;
            }
        }
        out.push(rapid(values.clone(), kept(&moved)));
    }
    if let Some(b) = out.first_mut() {
        b.comment = Some("start".into());
        // The start's blocks must not pass a later spindle speed by.
        b.spindle = first.spindle;
    }
    let mut values = last.values.clone();
    let mut end = Vec::with_capacity(setup.retract.len());
    for group in &setup.retract {
        for a in group {
            if let (Some(c), Some(v)) = (col(a), setup.clear.get(a)) {
                values[c] = *v;
            }
        }
        end.push(rapid(values.clone(), Vec::new()));
    }
    if let Some(b) = end.first_mut() {
        b.comment = Some("end".into());
    }
    out.extend(blocks);
    out.extend(end);
    out
}

/// Every spindle speed the program sets: none written as `S0` (programs
/// write whole rpm), each within the machine's spindle (its first spindle
/// axis), if it has one.
fn check_spindle(
    info: &MachineInfo,
    blocks: &[Block],
    rpm: Real,
    name_of: &impl Fn(usize) -> String,
) -> Result<(), ProgramError> {
    let speeds = std::iter::once((0, rpm)).chain(
        blocks
            .iter()
            .enumerate()
            .filter_map(|(i, b)| b.spindle.map(|v| (i, v))),
    );
    let spindle = info.axes.iter().find(|a| a.kind == AxisKind::Spindle);
    for (i, v) in speeds {
        if !(v.round() >= 1.0) {
            return Err(ProgramError::SpindleStopped {
                block: name_of(i),
                rpm: v,
            });
        }
        let Some(s) = spindle else { continue };
        if !(v >= s.min && v <= s.max) {
            return Err(ProgramError::Spindle {
                block: name_of(i),
                rpm: v,
                axis: s.name.clone(),
                machine: info.name.clone(),
                min: s.min,
                max: s.max,
            });
        }
    }
    Ok(())
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
) -> Result<Vec<Real>, ProgramFault> {
    if blocks.end > program.blocks.len() {
        return Err(ProgramFault::new(format!(
            "block {} is beyond the program's {} blocks",
            blocks.end,
            program.blocks.len()
        )));
    }
    let cols = names
        .iter()
        .map(|name| {
            let c = program
                .axes
                .iter()
                .position(|a| &a.name == name)
                .ok_or(ProgramFault::new(format!("the program has no axis {name}")))?;
            let axis = info.axis(name).ok_or(ProgramFault::new(format!(
                "machine {} has no axis {name}",
                info.name
            )))?;
            Ok((c, axis))
        })
        .collect::<Result<Vec<(usize, &Axis)>, ProgramFault>>()?;
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

/// The program `info`'s machine runs, without blocks: what a program read
/// from a file ([`lint::read`]) is read into. Its axes are the machine's
/// programmed axes; its name, number, tool and speed are placeholders the
/// text's own words replace.
pub fn frame(info: &MachineInfo) -> AxisProgram {
    AxisProgram {
        name: "PROGRAM".into(),
        number: 0,
        machine: info.name.clone(),
        control: info.control.clone(),
        tool_number: 1,
        tool_name: String::new(),
        spindle_rpm: 0.0,
        decimals: info.program_decimals,
        axes: info
            .axes
            .iter()
            .filter(|a| a.is_programmed())
            .map(|a| ProgramAxis {
                name: a.name.clone(),
                unit: a.unit().to_owned(),
            })
            .collect(),
        blocks: Vec::new(),
        setup: info.setup.clone(),
        cycles: Vec::new(),
        fanuc_cycles: Vec::new(),
    }
}

/// Checks a machine's power-on state ([`PowerOn`]) against its control's
/// dialect (the catalog does, for every machine it opens): each code
/// in one of the dialect's modal groups, one per group; a number's value
/// without its point only where the dialect has the parameter, positive
/// and at most 1 mm; a G-code system the reader follows.
///
/// # Failures
/// The first of these that does not hold, naming the key and the value.
pub fn check_power_on(info: &MachineInfo) -> Result<(), ProgramFault> {
    let p = &info.setup.power_on;
    if p.is_unstated() {
        return Ok(());
    }
    let Some(d) = post::dialect(&info.control) else {
        return Err(ProgramFault::new(format!(
            "setup: power_on is stated for the control '{}', whose modal groups pilgrim does not know",
            crate::files::excerpt(&info.control)
        )));
    };
    let mut seen: Vec<(usize, u32)> = Vec::new();
    for &c in &p.g {
        let Some(group) = d.reading.modal_groups.iter().position(|g| g.contains(&c)) else {
            return Err(ProgramFault::new(format!(
                "setup: power_on.g lists G{c}, which is in no modal group of {} pilgrim knows (groups: {})",
                d.name,
                groups_text(d.reading.modal_groups)
            )));
        };
        if let Some((_, other)) = seen.iter().find(|(g, _)| *g == group) {
            return Err(ProgramFault::new(format!(
                "setup: power_on.g lists G{other} and G{c}, two codes of one modal group"
            )));
        }
        seen.push((group, c));
    }
    if let Some(v) = p.no_point {
        if d.reading.least_input.is_none() {
            return Err(ProgramFault::new(format!(
                "setup: power_on.no_point = {v}: a number without its decimal point is millimetres on {}, which has no such parameter",
                d.name
            )));
        }
        if !(v > 0.0 && v <= 1.0) {
            return Err(ProgramFault::new(format!(
                "setup: power_on.no_point = {v} must be above 0 and at most 1 (mm)"
            )));
        }
    }
    if let Some(sys) = &p.system {
        if !d.reading.systems.contains(&sys.as_str()) {
            return Err(ProgramFault::new(if d.reading.systems.is_empty() {
                format!(
                    "setup: power_on.system = \"{}\": {} has no G-code systems",
                    crate::files::excerpt(sys),
                    d.name
                )
            } else {
                format!(
                    "setup: power_on.system = \"{}\": pilgrim reads and writes {} programs in G-code system {} only (another system gives G90..G99 other meanings); set the control to it",
                    crate::files::excerpt(sys),
                    d.name,
                    d.reading.systems.join(", ")
                )
            }));
        }
    }
    Ok(())
}

/// The modal groups as a reader would list them (`G17/G18/G19, ...`).
fn groups_text(groups: &[&[u32]]) -> String {
    groups
        .iter()
        .map(|g| {
            g.iter()
                .map(|c| format!("G{c}"))
                .collect::<Vec<_>>()
                .join("/")
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// A small lathe program of every motion (the post-processor's and the
/// lint's tests).
#[cfg(test)]
pub(crate) fn test_program() -> AxisProgram {
    let axis = |n: &str| ProgramAxis {
        name: n.into(),
        unit: "mm".into(),
    };
    let block = |motion, v: [f64; 2], feed, comment: Option<&str>| Block {
        motion,
        values: v.to_vec(),
        feed,
        spindle: None,
        comment: comment.map(str::to_owned),
        keep: Vec::new(),
        number: None,
        line: None,
        dwell_s: 0.0,
    };
    AxisProgram {
        name: "DEMO".into(),
        number: 7,
        machine: "test-lathe".into(),
        control: "fanuc".into(),
        tool_number: 3,
        tool_name: "thread insert 60".into(),
        spindle_rpm: 399.4,
        decimals: None,
        axes: vec![axis("X"), axis("Z")],
        blocks: vec![
            block(Motion::Rapid, [50.0, 5.0], 0.0, Some("pass 1")),
            block(Motion::Linear, [40.0, 5.0], 100.0, None),
            block(Motion::Linear, [40.0, -0.0001], 100.0, None),
            block(Motion::Linear, [40.0, -0.0001], 100.0, None),
            block(
                Motion::Thread {
                    lead: 6.35,
                    start_deg: 0.0,
                },
                [40.0, -60.0],
                0.0,
                None,
            ),
            block(Motion::Rapid, [50.0, -60.0], 0.0, None),
        ],
        setup: ProgramSetup::default(),
        cycles: Vec::new(),
        fanuc_cycles: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The caliber grinders' F: the roll's turn in deg/min where the turn
    /// is written, the linear path's where it is not. A turn of 0.0003 deg
    /// the program writes as none, with 1.3 mm of X: the feed check reads
    /// the program as written (it had read the unwritten turn and found X
    /// at 3.4 m/min); a whole degree: F is the turn's, at the chord's time.
    #[test]
    fn rotary_feeds_follow_the_program_as_written() {
        use crate::machine::{ChainMachine, Machine};
        use crate::toolpath::{ClPoint, Pass};
        let lz = ChainMachine::new(Machine::from_info(lz_250::describe()).unwrap());
        let wheel = crate::tool::Wheel::new(250.0, 8.0, 16.0).unwrap();
        let at = |deg: Real, z: Real| {
            let t = deg.to_radians();
            ClPoint {
                point: [250.0 * t.cos(), 250.0 * t.sin(), z],
                axis: [0.0, 0.0, 1.0],
                motion: Motion::Linear,
                feed: 1500.0,
                aux: vec![],
            }
        };
        let mut tp = Toolpath::new(
            "t",
            crate::tool::Tool::wheel_at_centre("w", 1, wheel),
            2000.0,
            vec![],
        );
        tp.passes.push(Pass {
            name: "p".into(),
            points: vec![at(10.0, 0.0), at(10.0003, 1.3), at(11.0003, 1.3)],
        });
        let p = build(&tp, &lz, "t").unwrap();
        let n = p.blocks.len();
        let (unwritten, turn) = (&p.blocks[n - 3], &p.blocks[n - 2]);
        assert_eq!(
            unwritten.feed, 1500.0,
            "no turn as written: the linear path's feed"
        );
        // 1 deg at 250 mm: 4.363 mm at 1500 mm/min, so 1 deg in 0.00291 min.
        let chord = 2.0 * 250.0 * 0.5f64.to_radians().sin();
        assert!((turn.feed - 1500.0 / chord).abs() < 1e-6, "{}", turn.feed);
    }

    /// A toolpath's threading cycle becomes a run of the program's
    /// blocks, each the move the cycle makes (X on the lathe's diameter);
    /// passes that are not the cycle's moves, or words not as a program
    /// writes them, are refused, naming the block.
    #[test]
    fn a_cycles_passes_must_be_its_moves() {
        use crate::machine::{ChainMachine, Machine};
        use crate::toolpath::{ClPoint, Pass, PassCycle};
        let lathe = ChainMachine::new(Machine::from_info(fanuc_0i_tc::describe()).unwrap());
        let cutter =
            crate::tool::ThreadCutter::new(0.3, 0.1, 30f64.to_radians(), 30f64.to_radians(), 3.0)
                .unwrap();
        let c = cycle::m20();
        let point = |motion: Motion, x: Real, z: Real| ClPoint {
            point: [x / 2.0, 0.0, z],
            axis: [0.0, 0.0, 1.0],
            motion,
            feed: if motion == Motion::Rapid {
                0.0
            } else {
                2.5 * 300.0
            },
            aux: vec![],
        };
        let moves = cycle::expand(&c, [24.0, 5.0], true, None).unwrap();
        let toolpath = |c: &cycle::ThreadCycle, nudge: Real| {
            let mut tp = Toolpath::new(
                "t",
                crate::tool::Tool::thread_cutter("c", 1, cutter),
                300.0,
                vec![],
            );
            tp.passes.push(Pass {
                name: "drive line".into(),
                points: vec![point(Motion::Rapid, 24.0, 5.0)],
            });
            for (n, four) in moves.chunks(4).enumerate() {
                tp.passes.push(Pass {
                    name: format!("cycle {n}"),
                    points: four
                        .iter()
                        .map(|m| point(m.motion, m.x, m.z + if n == 3 { nudge } else { 0.0 }))
                        .collect(),
                });
            }
            tp.cycles.push(PassCycle {
                first_pass: 1,
                passes: tp.passes.len() - 1,
                cycle: crate::toolpath::CycleWords::Linuxcnc(c.clone()),
            });
            tp
        };
        let p = build(&toolpath(&c, 0.0), &lathe, "t").unwrap();
        let span = &p.cycles[0];
        assert_eq!(span.count, moves.len());
        let x = p.axes.iter().position(|a| a.name == "X").unwrap();
        let first = &p.blocks[span.first];
        assert!((first.values[x] - moves[0].x).abs() < 1e-9, "{first:?}");
        let e = build(&toolpath(&c, 0.01), &lathe, "t")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("where the threading cycle makes")
                && e.contains("a rapid")
                && !e.contains('{'),
            "{e}"
        );
        let loose = cycle::ThreadCycle { q: 29.51234, ..c };
        let e = build(&toolpath(&loose, 0.0), &lathe, "t")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not as a program writes them"), "{e}");
    }

    /// The fast rounding is the text's, near-ties and negative zeros
    /// included.
    #[test]
    fn written_values_are_the_files() {
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        for i in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = match i % 4 {
                0 => (x as f64 / u64::MAX as f64 - 0.5) * 2000.0,
                1 => (x % 2_000_000) as f64 / 2000.0 - 500.0,
                2 => -((x % 1000) as f64) * 1e-7,
                _ => (x % 100_000) as f64 * 0.001 + 0.0005,
            };
            for d in [1, 3, 4] {
                let text: Real = crate::math::fixed(v, d).parse().unwrap();
                assert_eq!(
                    written(v, d).to_bits(),
                    text.to_bits(),
                    "{v} at {d} decimals"
                );
            }
        }
    }
}
