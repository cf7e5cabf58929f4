//! Toolpaths (CL data): passes of tool poses in the part frame.
//!
//! A [`Toolpath`] is what a part family makes: the tool, the spindle speed,
//! and passes of [`ClPoint`]s, each the tool's tracked point and axis in the
//! part frame, the motion that reaches it, the feed, and named auxiliary
//! values (the steady rest's `U` is one: an axis value the family computes
//! itself). It serialises to JSON (`toolpath.json`), one object per point:
//!
//! ```json
//! {"point":[30.0,0.0,12.5],"axis":[0.0,0.0,1.0],"motion":{"type":"linear"},"feed":2000.0,"aux":[41.2]}
//! ```

use crate::math::Real;
use crate::tool::Tool;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::ops::Range;

/// How a point is reached: rapid, linear at the point's feed, or a thread
/// at a lead (the plugin ABI's type, which programs carry too).
pub use pilgrim_plugin_abi::types::Motion;

/// One tool position.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClPoint {
    /// The tracked point in the part frame (mm).
    pub point: [Real; 3],
    /// The tool's axis in the part frame (unit).
    pub axis: [Real; 3],
    /// How the point is reached.
    pub motion: Motion,
    /// Feed (mm/min) of the move to this point: the tracked point's speed
    /// relative to the part (ignored for rapids). A program's F is the
    /// control's reading of it (the same unless a rotary axis moves).
    pub feed: Real,
    /// Auxiliary values, in the order of [`Toolpath::aux_names`].
    #[serde(default)]
    pub aux: Vec<Real>,
}

/// A pass: a run of points cut in one go.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pass {
    /// A name for the program's comments and reports.
    pub name: String,
    /// The points, in order.
    pub points: Vec<ClPoint>,
}

impl Pass {
    /// Whether the pass cuts: has a move other than a rapid that moves the
    /// tool (within the pass, or into its first point). A feed move that
    /// only moves another body (a steady rest coming onto the part) with
    /// the tool standing does not cut.
    pub fn cuts(&self) -> bool {
        self.points.iter().enumerate().any(|(i, p)| {
            p.motion != Motion::Rapid
                && (i == 0
                    || p.point != self.points[i - 1].point
                    || p.axis != self.points[i - 1].axis)
        })
    }
}

/// Each pass with the indices its points take over all passes: the blocks
/// (from 0) the pass becomes in a program.
pub fn pass_ranges(passes: &[Pass]) -> impl Iterator<Item = (&Pass, Range<usize>)> {
    passes.iter().scan(0, |start, p| {
        let r = *start..*start + p.points.len();
        *start = r.end;
        Some((p, r))
    })
}

/// The CL data of one job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Toolpath {
    /// The part's name (the program's name).
    pub part: String,
    /// The tool.
    pub tool: Tool,
    /// Spindle speed (rpm).
    pub spindle_rpm: Real,
    /// Names of the auxiliary values every point carries (e.g. `U`).
    pub aux_names: Vec<String>,
    /// The passes, in order.
    pub passes: Vec<Pass>,
    /// Figures the family reports about the toolpath (name to number).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub notes: BTreeMap<String, Real>,
    /// Tables the family reports (name to columns of equal length).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub tables: BTreeMap<String, BTreeMap<String, Vec<Real>>>,
    /// Charts the run draws from the tables.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plots: Vec<PlotSpec>,
    /// What the family warns of (the run goes on).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Runs of passes a control's threading cycle makes: a program writes
    /// each as its cycle where its dialect has it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cycles: Vec<PassCycle>,
    /// The part is held at its start alone (a short part in the chuck):
    /// the machine's bodies that stand at the part's end (a tailstock)
    /// are away.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub free_end: bool,
}

/// Passes `first_pass..first_pass + passes` of a toolpath: the moves a
/// threading cycle makes from where the pass before them ends (the
/// program holds each move as a block, and the program module
/// checks that they are the cycle's).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PassCycle {
    /// The first pass the cycle makes (from 0).
    pub first_pass: usize,
    /// How many passes.
    pub passes: usize,
    /// The cycle's words.
    pub cycle: CycleWords,
}

/// A threading cycle's words, in the form of the control whose cycle it
/// is: a program for that control writes the cycle, any other its moves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "form", rename_all = "snake_case")]
pub enum CycleWords {
    /// LinuxCNC's `G76 P Z I J R K Q H`.
    Linuxcnc(pilgrim_plugin_abi::types::ThreadCycle),
    /// Fanuc's two-block `G76`.
    FanucTwoBlock(pilgrim_plugin_abi::types::FanucThreadCycle),
}

/// A chart a run draws (`<file>.svg`) from one of the toolpath's tables:
/// the columns `y` against the column `x`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlotSpec {
    /// The file's name without `.svg` (a plain name).
    pub file: String,
    /// The chart's title.
    pub title: String,
    /// The table.
    pub table: String,
    /// The column along the horizontal axis.
    pub x: String,
    /// The columns drawn, each a line with its name in the legend.
    pub y: Vec<String>,
    /// The horizontal axis's label (with its unit).
    pub x_label: String,
    /// The vertical axis's label (with its unit).
    pub y_label: String,
}

/// The most points a toolpath may have (and so blocks a program): 2
/// million, checked before inverse kinematics.
pub const MAX_POINTS: usize = 2_000_000;

/// A bad toolpath, named by pass and point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ToolpathError {
    /// A value at a point is wrong.
    #[error("pass {pass} ({name}), point {point}: {message}")]
    Point {
        /// Pass index (from 1).
        pass: usize,
        /// Pass name.
        name: String,
        /// Point index in the pass (from 1).
        point: usize,
        /// What is wrong.
        message: String,
    },
    /// Something about the whole toolpath.
    #[error("toolpath: {0}")]
    Whole(String),
}

impl Toolpath {
    /// Checks the names and texts of [`Self::validate`].
    fn check_texts(&self) -> Result<(), ToolpathError> {
        use crate::names::{check_name, check_text};
        let whole = |e: crate::input::InputError| ToolpathError::Whole(e.to_string());
        check_name("tool name", &self.tool.name).map_err(whole)?;
        check_name("part name", &self.part).map_err(whole)?;
        for (i, p) in self.passes.iter().enumerate() {
            check_name("pass name", &p.name)
                .map_err(|e| ToolpathError::Whole(format!("pass {}: {e}", i + 1)))?;
        }
        for k in self.notes.keys() {
            check_name("note name", k).map_err(whole)?;
        }
        for (name, columns) in &self.tables {
            check_name("table name", name).map_err(whole)?;
            for c in columns.keys() {
                check_name("column name", c).map_err(whole)?;
            }
        }
        for w in &self.warnings {
            check_text("warning", w).map_err(whole)?;
        }
        for p in &self.plots {
            for t in [&p.title, &p.x_label, &p.y_label] {
                check_text("plot label", t).map_err(whole)?;
            }
        }
        Ok(())
    }

    /// An empty toolpath.
    pub fn new(part: &str, tool: Tool, spindle_rpm: Real, aux_names: Vec<String>) -> Self {
        Self {
            part: part.to_owned(),
            tool,
            spindle_rpm,
            aux_names,
            passes: Vec::new(),
            notes: BTreeMap::new(),
            tables: BTreeMap::new(),
            plots: Vec::new(),
            warnings: Vec::new(),
            cycles: Vec::new(),
            free_end: false,
        }
    }

    /// Number of points over all passes.
    pub fn point_count(&self) -> usize {
        self.passes.iter().map(|p| p.points.len()).sum()
    }

    /// Each pass with its blocks' indices (from 0); see [`pass_ranges`].
    pub fn pass_ranges(&self) -> impl Iterator<Item = (&Pass, Range<usize>)> {
        pass_ranges(&self.passes)
    }

    /// The points of all passes in order, with (pass index, point index).
    pub fn points(&self) -> impl Iterator<Item = (usize, usize, &ClPoint)> {
        self.passes
            .iter()
            .enumerate()
            .flat_map(|(i, p)| p.points.iter().enumerate().map(move |(j, c)| (i, j, c)))
    }

    /// Checks every value: its names and texts ([`crate::names`]: the
    /// tool's, the part's, each pass's, each note's and table's are names,
    /// which programs and file names may carry; warnings and plot labels
    /// are texts), finite coordinates, unit axes, positive feeds on
    /// cutting moves, positive leads, the right number of auxiliary values,
    /// a positive spindle speed, at least one point and at most
    /// [`MAX_POINTS`].
    ///
    /// # Failures
    /// [`ToolpathError`] naming the pass and point.
    pub fn validate(&self) -> Result<(), ToolpathError> {
        self.check_texts()?;
        if !(self.spindle_rpm.is_finite() && self.spindle_rpm > 0.0) {
            return Err(ToolpathError::Whole(format!(
                "spindle speed {} rpm is not positive",
                self.spindle_rpm
            )));
        }
        if self.point_count() == 0 {
            return Err(ToolpathError::Whole("no points".into()));
        }
        if self.point_count() > MAX_POINTS {
            return Err(ToolpathError::Whole(format!(
                "{} points, more than the ceiling of {MAX_POINTS}",
                self.point_count()
            )));
        }
        for (i, j, c) in self.points() {
            let err = |message: String| ToolpathError::Point {
                pass: i + 1,
                name: self.passes[i].name.clone(),
                point: j + 1,
                message,
            };
            if let Some(v) = c
                .point
                .iter()
                .chain(&c.axis)
                .chain(&c.aux)
                .find(|v| !v.is_finite())
            {
                return Err(err(format!("value {v} is not a finite number")));
            }
            let n = c.axis.iter().map(|a| a * a).sum::<Real>().sqrt();
            if (n - 1.0).abs() > crate::tolerance::SAME_RATIO {
                return Err(err(format!("tool axis has length {n}, not 1")));
            }
            let feed_ok = c.feed.is_finite() && c.feed > 0.0;
            if c.motion != Motion::Rapid && !feed_ok {
                return Err(err(format!("feed {} mm/min is not positive", c.feed)));
            }
            if let Motion::Thread { lead, start_deg } = c.motion {
                if !(lead.is_finite() && lead > 0.0) {
                    return Err(err(format!("thread lead {lead} is not positive")));
                }
                if !(0.0..360.0).contains(&start_deg) {
                    return Err(err(format!(
                        "thread start angle {start_deg} deg is not in [0, 360)"
                    )));
                }
            }
            if c.aux.len() != self.aux_names.len() {
                return Err(err(format!(
                    "{} auxiliary values for {} names ({})",
                    c.aux.len(),
                    self.aux_names.len(),
                    self.aux_names.join(", ")
                )));
            }
        }
        Ok(())
    }
}
