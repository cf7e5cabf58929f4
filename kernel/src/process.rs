//! The process checked as well as the geometry: the rules a machinist holds
//! every program to, whatever the family, each finding naming the block as
//! the program numbers it.
//!
//! A program verified to a tenth of a micron may still plunge the wheel at
//! the traverse feed or bring the steady rest onto the turning part at
//! rapid. So every program a run writes is replayed move by move against
//! the material as the family's replay knows it at that moment (the
//! [`Stock`] its verification gives: the blank cut by the passes before),
//! in sub-steps of each move as the control interpolates it:
//!
//! - **rapids through air only** ([`RAPID`]): a rapid that comes nearer
//!   the material than the machine's `rapid_clearance`, or into it, is an
//!   error (a rapid that leaves the part, a retract, may start on it);
//! - **into the stock at the infeed feed** ([`INFEED`]): a feed move that
//!   goes into the material more than along it (deeper by at least half
//!   its length inside, the depth taken as straight between its ends, and
//!   by more than [`PLUNGE_MIN`]) is an infeed, at most the machine's
//!   `infeed_feed`;
//! - **a body that rides the part meets it at its approach feed**
//!   ([`APPROACH`]): a block that brings a steady rest (a body with an
//!   `approach_feed`) from clear of the material (more than the rapid
//!   clearance off it) onto it is a feed move at most that fast, never a
//!   rapid;
//! - **a body that rides the part stays on it** ([`RIDING`]): while such a
//!   body is on the part (both ends of a move within the rapid clearance
//!   of it or into it, however deep), at every block and between blocks
//!   it stands off the highest surface any spindle phase leaves, or
//!   presses into it, by at most the machine's `rest_tolerance`; on every
//!   other move (onto the part, off it, fed or rapid) it presses into it
//!   by no more than that. Riding is where the body is along the program,
//!   not a window of distances: a rest 46 mm into the part rides it, and
//!   fails;
//! - **the spindle turns and the coolant flows before cutting**
//!   ([`SPINDLE`]): every cutting block runs at a speed the program writes
//!   as at least 1 rpm and the spindle's least, with the coolant on where
//!   the machine's setup has coolant;
//! - **a finishing pass takes no more than the finishing stock**
//!   ([`FINISH`]): each pass that leaves the part at its nominal removes at
//!   most the machine's `finish_stock` (a family may set it for its run);
//! - **a cutting move's feed within the family's limit** ([`FEED`]): a
//!   feed move into or through the material moves at most the feed per
//!   revolution its family allows there ([`Stock::feed_limit`]: a
//!   grinding family's finishing pass the feed whose ridge is the
//!   tolerance, any pass the wheel's width), wherever along the move the
//!   tool is in the material, named at the block that wrote the feed;
//! - **a ridge taller than the cut** ([`RIDGE`], a warning): a pass whose
//!   feed leaves ridges taller than its cut leaves the surface before it
//!   untouched at the crests.
//!
//! The machine states its limits as constants ([`ProcessLimits::of`]); a
//! machine that states none is held to [`ProcessLimits::DEFAULT`]. A family
//! whose verification gives no [`Stock`] is checked for the spindle and
//! coolant only, and the verdict says which rules were not checked.
//!
//! The rules are written here by hand: they read the kernel's own replays,
//! which no collision library knows; each is a few lines over them.

use crate::machine::{BodyShape, MachineInfo, MachineKinematics};
use crate::math::{Mat4, Real};
use crate::program::{block_name, AxisProgram};
use crate::toolpath::Motion;
use crate::transform::ToolFrame;
use crate::verdict::{Figure, Finding};

/// The rule of rapids through air only.
pub const RAPID: &str = "rapid through air only";
/// The rule of the infeed feed.
pub const INFEED: &str = "into the stock at the infeed feed";
/// The rule of a riding body's approach feed.
pub const APPROACH: &str = "the steady rest meets the part at its approach feed";
/// The rule of the spindle and coolant before cutting.
pub const SPINDLE: &str = "spindle at speed and coolant on before cutting";
/// The rule of a riding body's stand-off while it rides.
pub const RIDING: &str = "the steady rest rides the part within its tolerance";
/// The rule of the finishing stock.
pub const FINISH: &str = "a finishing pass takes no more than the finishing stock";
/// The rule of a cutting move's feed per revolution.
pub const FEED: &str = "a cutting move's feed per revolution within the family's limit";
/// The warning of a ridge taller than the cut.
pub const RIDGE: &str = "a pass's ridge taller than its cut";

/// The least a feed move must go deeper into the material to count as
/// going into it (mm): below it, the replay's own sampling of the surface.
pub const PLUNGE_MIN: Real = 2e-3;

/// How far the tool may reach into the material on a rapid that leaves it
/// (mm): the finished surface's ridges and the program's rounding.
pub const RAPID_SLACK: Real = 1e-3;

/// What the material is, as a family's replay knows it at every moment
/// of the program.
pub trait Stock {
    /// How deep the tool stands in the material at `pose` (a row of 6, the
    /// tracked point and the axis in the part frame, as the replay places
    /// them), the material as the program has left it when block `block`
    /// (from 0) begins (mm; negative: clear of it by that much, as far as
    /// the model can tell).
    fn tool_depth(&self, block: usize, pose: &[Real]) -> Real;

    /// How far a body of `shape` (its sizes resolved: radius and length
    /// of a roller) placed at `frame` in the part frame stands off the
    /// material at `along` (0 to 1) of the move into block `block` (from
    /// 0), as the tool has left it by then (mm; negative: pressed into
    /// it), or `None` where the model cannot say (the default: a part no
    /// body rides).
    fn body_gap(&self, block: usize, along: Real, shape: &Roller, frame: &Mat4) -> Option<Real> {
        let _ = (block, along, shape, frame);
        None
    }

    /// What each cutting pass removed.
    fn passes(&self) -> Vec<PassStock>;

    /// The largest feed per revolution a cutting move of block `block`
    /// (from 0) may have, with what sets it, or `None` where the family
    /// states none (the default).
    fn feed_limit(&self, block: usize) -> Option<FeedLimit> {
        let _ = block;
        None
    }
}

/// The largest feed per revolution a family allows a cutting move.
#[derive(Debug, Clone, PartialEq)]
pub struct FeedLimit {
    /// The limit (mm per revolution).
    pub per_rev: Real,
    /// What sets it, for the finding ("the finishing pass's ridge at most
    /// the tolerance 0.001 mm").
    pub why: String,
}

/// A roller body's sizes (mm): a cylinder along its frame's Y, centred on
/// its origin (a steady rest's support).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roller {
    /// Radius.
    pub radius: Real,
    /// Length.
    pub length: Real,
}

/// What one cutting pass removed.
#[derive(Debug, Clone, PartialEq)]
pub struct PassStock {
    /// The pass's name.
    pub name: String,
    /// Its first block (from 0).
    pub first_block: usize,
    /// The most material it removed under the tool's path (mm): its cut,
    /// the surface before it less the surface it left, at the valleys.
    pub cut: Real,
    /// The ridge its feed leaves on the surface (mm; 0 where none).
    pub ridge: Real,
    /// Whether it leaves the part at its nominal (within the tolerance):
    /// a finishing pass.
    pub finishes: bool,
}

/// The machine's process limits: constants the machine states, or the
/// kernel's defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessLimits {
    /// The fastest the tool may move into the stock (mm/min): the machine's
    /// constant `infeed_feed`.
    pub infeed_feed: Real,
    /// How far off the material a rapid stops as it approaches it (mm):
    /// `rapid_clearance`.
    pub rapid_clearance: Real,
    /// The most a finishing pass may take (mm): `finish_stock`.
    pub finish_stock: Real,
    /// How far a riding body may stand off the part or press into it
    /// (mm): `rest_tolerance`.
    pub rest_tolerance: Real,
}

impl ProcessLimits {
    /// The limits a machine is held to that states none: a grinder's
    /// infeed (5 mm/min), 0.5 mm of clearance, 0.05 mm of finishing stock,
    /// a steady rest within 5 um of the part.
    pub const DEFAULT: Self = Self {
        infeed_feed: 5.0,
        rapid_clearance: 0.5,
        finish_stock: 0.05,
        rest_tolerance: 0.005,
    };

    /// The limits `info` states in its constants, the defaults for those
    /// it does not.
    pub fn of(info: &MachineInfo) -> Self {
        let c = |name: &str, default: Real| {
            info.constants
                .get(name)
                .copied()
                .filter(|v| v.is_finite() && *v > 0.0)
                .unwrap_or(default)
        };
        let d = Self::DEFAULT;
        Self {
            infeed_feed: c("infeed_feed", d.infeed_feed),
            rapid_clearance: c("rapid_clearance", d.rapid_clearance),
            finish_stock: c("finish_stock", d.finish_stock),
            rest_tolerance: c("rest_tolerance", d.rest_tolerance),
        }
    }
}

/// What the process check found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ProcessFindings {
    /// Errors: each fails the run.
    pub errors: Vec<Finding>,
    /// Warnings: the report and the page show them.
    pub warnings: Vec<Finding>,
    /// Figures against their limits (the finishing stock).
    pub figures: Vec<Figure>,
}

/// How many sub-steps a move is checked in: enough that the tool moves at
/// most `step` mm between two, at most [`MAX_SUBSTEPS`].
fn substeps(length: Real, step: Real) -> usize {
    ((length / step).ceil() as usize).clamp(1, MAX_SUBSTEPS)
}

/// The shortest sub-step of a move the rules sample (mm), where the
/// rapid clearance is shorter.
pub const LEAST_SUBSTEP: Real = 0.05;

/// The most sub-steps of one move.
pub const MAX_SUBSTEPS: usize = 200;

/// Checks `program` (run on `machine`, the tool tracked at `tool`) against
/// the rules of the [module docs](self), the material `stock` (if the
/// family's verification gives one), the machine's `limits` (the finishing
/// stock as the run sets it).
///
/// # Failures
/// The machine's forward kinematics failing (the replay has already run
/// it on the same program, so only a plugin that changed its mind).
pub fn check(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    stock: Option<&dyn Stock>,
    limits: &ProcessLimits,
) -> Result<ProcessFindings, crate::replay::VerifyError> {
    match stock {
        Some(stock) => check_on(program, &Moves::new(program, machine, tool)?, stock, limits),
        None => {
            let mut out = ProcessFindings::default();
            spindle_and_coolant(program, machine.info(), &mut out);
            Ok(out)
        }
    }
}

/// [`check`] on `program`'s `moves` (made once for a run: the passes'
/// [`Contact`] reads the same) against `stock`.
///
/// # Failures
/// As [`check`].
pub fn check_on(
    program: &AxisProgram,
    moves: &Moves<'_>,
    stock: &dyn Stock,
    limits: &ProcessLimits,
) -> Result<ProcessFindings, crate::replay::VerifyError> {
    let mut out = ProcessFindings::default();
    let machine = moves.machine;
    spindle_and_coolant(program, machine.info(), &mut out);
    let written = &moves.written;
    let name = |k: usize| block_name(program, k);
    let n = written.blocks.len();
    let poses_along = |k: usize, steps: usize| moves.along(k, steps);
    let ends = &moves.ends;
    let speeds: Vec<Real> = crate::program::spindle_speeds(program).collect();
    // The block that last broke the feed rule, and its feed: the blocks
    // right after it at the same modal feed are the same fault, not told.
    let mut fast: Option<(usize, Real)> = None;
    let mut ticker = crate::budget::Ticker::new("the process's rules", 64);
    for k in 1..n {
        ticker.tick()?;
        let b = &written.blocks[k];
        let (p0, p1) = (&ends[6 * (k - 1)..6 * k], &ends[6 * k..6 * k + 6]);
        let length = moves.length(k);
        match b.motion {
            Motion::Rapid => {
                let steps = substeps(length, limits.rapid_clearance.max(LEAST_SUBSTEP));
                let d0 = stock.tool_depth(k, p0);
                // The deepest the move takes the tool where it comes nearer
                // the material than it started.
                let mut worst: Option<(Real, Real)> = None;
                let along = poses_along(k, steps)?;
                for i in 1..=steps {
                    let t = i as Real / steps as Real;
                    let d = if i == steps {
                        stock.tool_depth(k, p1)
                    } else {
                        stock.tool_depth(k, &along[6 * (i - 1)..6 * i])
                    };
                    let nearer = d > d0 + RAPID_SLACK;
                    let bad = nearer && (d > RAPID_SLACK || d > -0.99 * limits.rapid_clearance);
                    if bad && worst.is_none_or(|w| d > w.0) {
                        worst = Some((d, t));
                    }
                }
                if let Some((d, t)) = worst {
                    out.errors.push(
                        Finding::new(
                            RAPID,
                            format!(
                                "{}: a rapid {} ({} mm {} the material {} of the way through the move; rapids stop {} mm off it, the rest at feed)",
                                name(k),
                                if d > 0.0 { "into the material" } else { "onto the part" },
                                crate::math::fixed(d.abs(), 3),
                                if d > 0.0 { "into" } else { "off" },
                                crate::math::fixed(t, 2),
                                limits.rapid_clearance
                            ),
                        )
                        .at(k, name(k)),
                    );
                }
            }
            Motion::Linear => {
                // How much deeper the move takes the tool, over how much of
                // its length inside the material (the depth taken as
                // straight along the move: a feed move is short, and the
                // material smooth on its scale).
                let (d0, d1) = (stock.tool_depth(k, p0), stock.tool_depth(k, p1));
                // Too fast for the family's limit, and in the material
                // anywhere along the move (its ends may both be clear).
                if let Some((per_rev, limit)) = over_feed_limit(stock, k, b.feed, speeds[k]) {
                    let steps = substeps(length, limits.rapid_clearance.max(LEAST_SUBSTEP));
                    let cuts = d0 > 0.0
                        || d1 > 0.0
                        || (poses_along(k, steps)?)
                            .chunks(6)
                            .any(|pose| stock.tool_depth(k, pose) > 0.0);
                    if cuts {
                        let told = fast.is_some_and(|(j, f)| j + 1 == k && f == b.feed);
                        fast = Some((k, b.feed));
                        if !told {
                            out.errors
                                .push(too_fast(program, k, b.feed, speeds[k], per_rev, &limit));
                        }
                    }
                }
                let deeper = d1 - d0.max(0.0);
                let inside = if d0 >= 0.0 {
                    length
                } else if d1 > 0.0 {
                    length * d1 / (d1 - d0)
                } else {
                    0.0
                };
                if deeper > PLUNGE_MIN
                    && deeper >= 0.5 * inside
                    && b.feed > limits.infeed_feed * (1.0 + crate::tolerance::LIMIT_SLACK)
                {
                    out.errors.push(
                        Finding::new(
                            INFEED,
                            format!(
                                "{}: the tool goes {} mm into the stock at F{} mm/min; the machine's infeed feed is at most {} mm/min (give the move into the material its own block at that feed)",
                                name(k),
                                crate::math::fixed(deeper, 4),
                                crate::math::fixed(b.feed, 1),
                                limits.infeed_feed
                            ),
                        )
                        .at(k, name(k)),
                    );
                }
            }
            Motion::Thread { .. } => {}
        }
    }
    bodies(program, written, machine, stock, limits, &mut out)?;
    finishing(program, stock, limits, &mut out);
    Ok(out)
}

/// A program's moves as the control interpolates them, made once for a
/// run: the program as written (its values rounded as the control reads
/// them) and its resolution, its axes' rows, the tool's poses at the
/// moves' ends, and the poses between on request.
pub struct Moves<'a> {
    /// The program as written.
    written: AxisProgram,
    /// Its resolution (mm): the last decimal it writes.
    resolution: Real,
    /// The solved axes' values, a row per block.
    rows: Vec<Real>,
    /// The length of a row.
    width: usize,
    /// The tool at each block's end, rows of 6 in the part frame.
    ends: Vec<Real>,
    machine: &'a dyn MachineKinematics,
    tool: &'a ToolFrame,
}

impl<'a> Moves<'a> {
    /// The moves of `program` as written, on `machine`, the tool tracked
    /// at `tool`.
    ///
    /// # Failures
    /// The machine's kinematics failing on the program.
    pub fn new(
        program: &AxisProgram,
        machine: &'a dyn MachineKinematics,
        tool: &'a ToolFrame,
    ) -> Result<Self, crate::replay::VerifyError> {
        let (written, resolution) = crate::replay::as_written(program);
        let info = machine.info();
        let n = written.blocks.len();
        let rows = crate::program::axis_rows(&written, info, &info.solved_axes, 0..n)
            .map_err(|e| crate::replay::VerifyError::Replay(e.to_string()))?;
        Ok(Self {
            rows,
            width: info.solved_axes.len(),
            ends: crate::replay::replay(&written, machine, tool)?,
            written,
            resolution,
            machine,
            tool,
        })
    }

    /// The tool at `i / steps` of the way through block `k`'s move, for i
    /// in 1..steps: rows of 6, in one call of the machine's kinematics (a
    /// plugin's is a call to another process).
    fn along(&self, k: usize, steps: usize) -> Result<Vec<Real>, crate::replay::VerifyError> {
        let w = self.width;
        let b = &self.rows[k * w..(k + 1) * w];
        let a = if k > 0 {
            &self.rows[(k - 1) * w..k * w]
        } else {
            b
        };
        let q: Vec<Real> = (1..steps)
            .flat_map(|i| {
                let t = i as Real / steps as Real;
                a.iter().zip(b).map(move |(a, b)| a + (b - a) * t)
            })
            .collect();
        if q.is_empty() {
            return Ok(Vec::new());
        }
        crate::replay::forward_rows(self.machine, &q, self.tool, k..k + 1)
    }

    /// The length of block `k`'s move (mm, in the part frame).
    fn length(&self, k: usize) -> Real {
        let e = &self.ends;
        let (p0, p1) = (&e[6 * (k - 1)..6 * k], &e[6 * k..6 * k + 6]);
        ((p1[0] - p0[0]).powi(2) + (p1[1] - p0[1]).powi(2) + (p1[2] - p0[2]).powi(2)).sqrt()
    }
}

/// Where the tool meets the material on a program's feed moves: what a
/// pass found from the motion needs to cut at all.
pub struct Contact<'a> {
    moves: &'a Moves<'a>,
    stock: &'a dyn Stock,
    /// The sub-steps' length (mm).
    step: Real,
}

impl<'a> Contact<'a> {
    /// The feed moves of `moves` against `stock`, sampled every `step` mm
    /// (at most [`MAX_SUBSTEPS`] a move).
    pub fn new(moves: &'a Moves<'a>, stock: &'a dyn Stock, step: Real) -> Self {
        Self { moves, stock, step }
    }

    /// Whether a feed move of `blocks` (a rapid's or a thread's aside)
    /// brings the tool onto the material (within the program's resolution
    /// of it, or into it) anywhere past the move's start: a move that
    /// starts on the surface it has just cut and leaves it does not; a
    /// spark-out along the surface does. A thread's move cuts by what it
    /// is.
    ///
    /// # Failures
    /// The machine's kinematics failing between the moves' ends.
    pub fn touches(
        &self,
        blocks: std::ops::Range<usize>,
    ) -> Result<bool, crate::replay::VerifyError> {
        let written = &self.moves.written;
        // On the material: within the program's resolution of it.
        let near = self.moves.resolution;
        let on = |k: usize, pose: &[Real]| self.stock.tool_depth(k, pose) > -near;
        let feed: Vec<usize> = blocks
            .filter(|&k| k > 0 && k < written.blocks.len())
            .filter(|&k| written.blocks[k].motion != Motion::Rapid)
            .collect();
        let mut ticker = crate::budget::Ticker::new("the passes' contact with the material", 64);
        for &k in &feed {
            ticker.tick()?;
            if matches!(written.blocks[k].motion, Motion::Thread { .. })
                || on(k, &self.moves.ends[6 * k..6 * k + 6])
            {
                return Ok(true);
            }
        }
        for &k in &feed {
            ticker.tick()?;
            let steps = substeps(self.moves.length(k), self.step);
            if self
                .moves
                .along(k, steps)?
                .chunks(6)
                .any(|pose| on(k, pose))
            {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// The feed per revolution of block `k` at `feed` (mm/min) and `rpm`,
/// with the limit `stock`'s family sets there, where it is over it.
fn over_feed_limit(
    stock: &dyn Stock,
    k: usize,
    feed: Real,
    rpm: Real,
) -> Option<(Real, FeedLimit)> {
    let limit = stock.feed_limit(k).filter(|_| rpm > 0.0)?;
    let per_rev = feed / rpm;
    (per_rev > limit.per_rev * (1.0 + crate::tolerance::LIMIT_SLACK)).then_some((per_rev, limit))
}

/// The finding of block `k`'s cut at `feed` and `rpm`, `per_rev` over
/// `limit`.
fn too_fast(
    program: &AxisProgram,
    k: usize,
    feed: Real,
    rpm: Real,
    per_rev: Real,
    limit: &FeedLimit,
) -> Finding {
    let name = block_name(program, k);
    Finding::new(
        FEED,
        format!(
            "{name}: F{} at S{} is {} mm per revolution, more than {} mm: {} (at most F{} at this speed)",
            crate::math::fixed(feed, 1),
            crate::math::fixed(rpm, 0),
            crate::math::fixed(per_rev, 4),
            crate::math::fixed(limit.per_rev, 4),
            limit.why,
            crate::math::fixed((limit.per_rev * rpm * 10.0).floor() / 10.0, 1),
        ),
    )
    .at(k, name)
}

/// The spindle and coolant before every cutting block (as written: a
/// speed rounded to whole rpm).
fn spindle_and_coolant(program: &AxisProgram, info: &MachineInfo, out: &mut ProcessFindings) {
    let least = info
        .axes
        .iter()
        .find(|a| a.kind == crate::machine::AxisKind::Spindle)
        .map_or(0.0, |a| a.min)
        .max(1.0);
    let speeds = crate::program::spindle_speeds(program).map(Real::round);
    for (k, (b, rpm)) in program.blocks.iter().zip(speeds).enumerate() {
        if b.motion == Motion::Rapid {
            continue;
        }
        let wrong = if !(rpm >= least) {
            format!("the spindle at S{rpm}, below its least speed {least} rpm")
        } else if info.setup.coolant && !program.setup.coolant {
            "the coolant off, which the machine's setup turns on".to_owned()
        } else {
            continue;
        };
        let name = block_name(program, k);
        out.errors.push(
            Finding::new(SPINDLE, format!("{name}: the program cuts with {wrong}")).at(k, name),
        );
        return;
    }
}

/// The bodies that ride the part come onto it at their approach feed.
fn bodies(
    program: &AxisProgram,
    written: &AxisProgram,
    machine: &dyn MachineKinematics,
    stock: &dyn Stock,
    limits: &ProcessLimits,
    out: &mut ProcessFindings,
) -> Result<(), crate::replay::VerifyError> {
    let info = machine.info();
    let Ok(bodies) = crate::machine::bodies_of(info) else {
        return Ok(());
    };
    let axes: Vec<Option<&crate::machine::Axis>> =
        written.axes.iter().map(|a| info.axis(&a.name)).collect();
    let known: Vec<&crate::machine::Axis> = axes.iter().flatten().copied().collect();
    for body in bodies {
        let spec = body.spec();
        let (Some(feed), Some(BodyShape::Roller { radius, length })) =
            (&spec.approach_feed, &spec.shape)
        else {
            continue;
        };
        let (Ok(feed), Ok(radius), Ok(length)) = (
            feed.resolve(&info.constants),
            radius.resolve(&info.constants),
            length.resolve(&info.constants),
        ) else {
            continue;
        };
        let roller = Roller { radius, length };
        let Ok(rows) = crate::program::axis_rows(
            written,
            info,
            body.chain().axis_names(),
            0..written.blocks.len(),
        ) else {
            continue; // the program does not drive the body
        };
        let width = body.chain().axis_names().len();
        let frame = |k: usize| body.chain().matrix(&rows[k * width..(k + 1) * width]).ok();
        // A body stands clear of the part when it is more than the rapid
        // clearance off it; as it rides, it stands within the difference
        // between the replay's surface and the one the family rode it on.
        let clear = limits.rapid_clearance;
        // The frame at `along` of the move into block k: the axes move in
        // straight lines between blocks.
        let between = |k: usize, along: Real| {
            let (a, b) = (
                &rows[(k - 1) * width..k * width],
                &rows[k * width..(k + 1) * width],
            );
            let v: Vec<Real> = a.iter().zip(b).map(|(p, q)| p + along * (q - p)).collect();
            body.chain().matrix(&v).ok()
        };
        // While it rides: its worst stand-off (+) or press (-), where; and
        // the deepest it presses into the part on any other move.
        let mut worst: Option<(Real, usize)> = None;
        let mut deepest: Option<(Real, usize)> = None;
        let mut gap_before = frame(0).and_then(|f| stock.body_gap(0, 1.0, &roller, &f));
        if let Some(g) = gap_before.filter(|g| *g < 0.0) {
            deepest = Some((g, 0));
        }
        let mut ticker = crate::budget::Ticker::new("the steady rest's ride", 16);
        for k in 1..written.blocks.len() {
            ticker.tick()?;
            let gap = frame(k).and_then(|f| stock.body_gap(k, 1.0, &roller, &f));
            // The body at the block and at the quarters before it: the
            // whole move, whatever the depth, fed or rapid.
            let inside = (1..RIDING_CHECKS).filter_map(|i| {
                let along = i as Real / RIDING_CHECKS as Real;
                between(k, along).and_then(|f| stock.body_gap(k, along, &roller, &f))
            });
            let gaps: Vec<Real> = gap.into_iter().chain(inside).collect();
            // It rides from the block where it comes within the clearance
            // (or into the part, however deep) to the one that takes it
            // clear again.
            let rides =
                gap_before.is_some_and(|g0| g0 <= clear) && gap.is_some_and(|g1| g1 <= clear);
            for &g in &gaps {
                if rides {
                    if worst.is_none_or(|w| g.abs() > w.0.abs()) {
                        worst = Some((g, k));
                    }
                } else if deepest.is_none_or(|w| g < w.0) {
                    deepest = Some((g, k));
                }
            }
            if let (Some(g0), Some(g1)) = (gap_before, gap) {
                if g0 > clear && g1 <= clear {
                    // It comes onto the part in this block: how fast.
                    let b = &written.blocks[k];
                    let moved = frame(k - 1).zip(frame(k)).map_or(0.0, |(a, b)| {
                        let (a, b) = (a.column(3), b.column(3));
                        ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2))
                            .sqrt()
                    });
                    let speed = if b.motion == Motion::Rapid {
                        Real::INFINITY
                    } else {
                        let deltas: Vec<Real> = b
                            .values
                            .iter()
                            .zip(&written.blocks[k - 1].values)
                            .zip(&axes)
                            .filter(|(_, a)| a.is_some())
                            .map(|((q, p), _)| q - p)
                            .collect();
                        let path =
                            crate::machine::feed_length(&known, &deltas, &info.setup.feed_group);
                        if path > 0.0 {
                            moved * b.feed / path
                        } else {
                            0.0
                        }
                    };
                    if speed > feed * (1.0 + crate::tolerance::LIMIT_SLACK) {
                        let name = block_name(program, k);
                        out.errors.push(
                            Finding::new(
                                APPROACH,
                                format!(
                                    "{name}: {} comes onto the part {}; it may meet it at most at {feed} mm/min (bring it to its clearance at rapid, then onto the part at feed)",
                                    spec.name,
                                    if speed.is_infinite() {
                                        "at rapid".to_owned()
                                    } else {
                                        format!("at {} mm/min", crate::math::fixed(speed, 1))
                                    }
                                ),
                            )
                            .at(k, name.clone()),
                        );
                    }
                }
            }
            gap_before = gap;
        }
        if let Some((g, k)) = worst {
            let name = block_name(program, k);
            let tol = limits.rest_tolerance;
            out.figures.push(
                Figure::new(
                    &format!(
                        "{}: off the part while it rides (+ stand-off, - press)",
                        spec.name
                    ),
                    g,
                    tol,
                    "mm",
                    name.clone(),
                )
                .at_block(k),
            );
            if g.abs() > tol * (1.0 + crate::tolerance::LIMIT_SLACK) {
                out.errors.push(
                    Finding::new(
                        RIDING,
                        format!(
                            "{name}: {} {} mm {} the highest surface the part can have there (the machine's rest_tolerance is {tol} mm)",
                            spec.name,
                            crate::math::fixed(g.abs(), 4),
                            if g > 0.0 { "off" } else { "into" }
                        ),
                    )
                    .at(k, name),
                );
            }
        }
        // Pressed into the part on a move on which it does not ride: onto
        // the part from clear of it, or off it.
        if let Some((g, k)) = deepest
            .filter(|(g, _)| *g < -limits.rest_tolerance * (1.0 + crate::tolerance::LIMIT_SLACK))
        {
            let name = block_name(program, k);
            out.errors.push(
                Finding::new(
                    RIDING,
                    format!(
                        "{name}: {} {} mm into the highest surface the part can have there, on its way onto or off the part (it may press at most the machine's rest_tolerance, {} mm)",
                        spec.name,
                        crate::math::fixed(-g, 4),
                        limits.rest_tolerance
                    ),
                )
                .at(k, name),
            );
        }
    }
    Ok(())
}

/// The places a riding body is checked at along each move (its ends
/// included): every quarter.
pub const RIDING_CHECKS: usize = 4;

/// The finishing passes' stock, and the ridges taller than their cuts.
fn finishing(
    program: &AxisProgram,
    stock: &dyn Stock,
    limits: &ProcessLimits,
    out: &mut ProcessFindings,
) {
    let passes = stock.passes();
    let mut worst: Option<&PassStock> = None;
    for p in &passes {
        let name = block_name(program, p.first_block);
        if p.finishes {
            if worst.is_none_or(|w| p.cut > w.cut) {
                worst = Some(p);
            }
            if p.cut > limits.finish_stock * (1.0 + crate::tolerance::LIMIT_SLACK) {
                out.errors.push(
                    Finding::new(
                        FINISH,
                        format!(
                            "{name}: the finishing pass \"{}\" takes {} mm, more than the finishing stock {} mm (leave it less: a lighter cut before it)",
                            p.name,
                            crate::math::fixed(p.cut, 4),
                            limits.finish_stock
                        ),
                    )
                    .at(p.first_block, name.clone()),
                );
            }
        } else if p.ridge > p.cut && p.cut > 0.0 {
            out.warnings.push(
                Finding::new(
                    RIDGE,
                    format!(
                        "{name}: pass \"{}\" leaves ridges {} mm high on a cut of {} mm: at the crests it leaves the surface before it untouched (a lower feed, or a deeper cut)",
                        p.name,
                        crate::math::fixed(p.ridge, 4),
                        crate::math::fixed(p.cut, 4)
                    ),
                )
                .at(p.first_block, name),
            );
        }
    }
    if let Some(w) = worst {
        out.figures.push(
            Figure::new(
                "the finishing stock",
                w.cut,
                limits.finish_stock,
                "mm",
                block_name(program, w.first_block),
            )
            .at_block(w.first_block),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Machine;
    use crate::program::{frame, Block};

    /// Material only within 1 mm of x = 0, every move's feed limited to
    /// 1 mm a revolution.
    struct Ridge;

    impl Stock for Ridge {
        fn tool_depth(&self, _block: usize, pose: &[Real]) -> Real {
            1.0 - pose[0].abs()
        }
        fn passes(&self) -> Vec<PassStock> {
            Vec::new()
        }
        fn feed_limit(&self, _block: usize) -> Option<FeedLimit> {
            Some(FeedLimit {
                per_rev: 1.0,
                why: "the test's limit".into(),
            })
        }
    }

    /// A feed move whose ends are both clear of the material but which
    /// passes through it is held to the feed rule: the rule looks along
    /// the whole move, not at its ends only.
    #[test]
    fn a_move_through_the_material_is_held_to_its_feed() {
        let mill = crate::machine::ChainMachine::new(Machine::builtin("vertical-mill").unwrap());
        let mut p = frame(MachineKinematics::info(&mill));
        p.spindle_rpm = 100.0;
        let block = |motion, x: Real, feed| Block {
            motion,
            values: vec![x, 0.0, 0.0, 0.0],
            feed,
            spindle: None,
            comment: None,
            keep: Vec::new(),
            number: None,
            line: None,
            dwell_s: 0.0,
        };
        p.blocks = vec![
            block(Motion::Rapid, -10.0, 0.0),
            block(Motion::Linear, 10.0, 6000.0),
        ];
        let found = check(
            &p,
            &mill,
            &ToolFrame::default(),
            Some(&Ridge),
            &ProcessLimits::DEFAULT,
        )
        .unwrap();
        let fast: Vec<&Finding> = found.errors.iter().filter(|f| f.rule == FEED).collect();
        assert_eq!(fast.len(), 1, "{:?}", found.errors);
        assert!(
            fast[0].message.contains("60.0000 mm per revolution"),
            "{}",
            fast[0].message
        );
    }
}
