//! The data the ABI carries as JSON: a machine's descriptor
//! ([`MachineInfo`]) and the programs posted ([`AxisProgram`], in a
//! [`PostRequest`]). Both sides use these types, so a plugin needs this
//! crate only, not the kernel.
//!
//! Units are the kernel's: millimetres and radians (degrees only in
//! programs, where [`ProgramAxis::unit`] says `deg`). Fields are only ever
//! appended, with defaults, so that a descriptor written by an older plugin
//! of the same major version still reads.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What an axis does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AxisKind {
    /// A slide (mm).
    Linear,
    /// A positioned rotary axis (rad inside, degrees in files and programs).
    Rotary,
    /// A spindle turning at a speed (rpm), not positioned.
    Spindle,
}

impl AxisKind {
    /// `linear`, `rotary` or `spindle`.
    pub fn word(self) -> &'static str {
        match self {
            Self::Linear => "linear",
            Self::Rotary => "rotary",
            Self::Spindle => "spindle",
        }
    }
}

/// One axis of a machine.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    /// The name, as the control's address letter (X, Z, U, A...).
    pub name: String,
    /// Linear, rotary or spindle.
    pub kind: AxisKind,
    /// Lower travel limit (mm or rad; 0 for a spindle).
    pub min: f64,
    /// Upper travel limit (mm or rad; the top speed in rpm for a spindle).
    pub max: f64,
    /// Top speed (mm/min or rad/min; rpm for a spindle).
    pub max_feed: f64,
    /// Whether blocks carry its position.
    pub programmed: bool,
    /// What it moves and which way is positive, in words.
    #[serde(default)]
    pub description: String,
    /// For linear axes: the tool's (or body's) displacement in the part frame
    /// per unit of the axis, at the home pose: the sign, stated and tested.
    #[serde(default)]
    pub moves: Option<[f64; 3]>,
    /// For rotary axes: the axis the tool (or body) turns about relative to
    /// the part for a positive value (right-handed), at the home pose.
    #[serde(default)]
    pub turns: Option<[f64; 3]>,
    /// The body it moves: `None` for the tool, else a body's name.
    #[serde(default)]
    pub body: Option<String>,
    /// Since 1.7: the most the axis accelerates (mm/s², rad/s² for a
    /// rotary axis), if the machine states it: the cycle time's model
    /// ramps every move's speed within it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_accel: Option<f64>,
    /// Since 1.8: the axis turns the part about the part's axis (Z) on the
    /// machine, the rest of the machine standing still: a spindle that
    /// carries the part (a lathe's, a grinder's work spindle; the
    /// program's S, M3 turning the part about +Z), or a rotary axis bound
    /// as the tool chain's leading factor, an Rz (a caliber grinder's roll
    /// turn). The page's player turns the part by it; the geometry is the
    /// chain's either way.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub turns_part: bool,
}

impl Axis {
    /// A programmed linear axis: travel `[min, max]` (mm), `max_feed`
    /// (mm/min), the tool's motion relative to the part for +1 mm
    /// (`moves`), and what it is.
    pub fn linear(
        name: &str,
        min: f64,
        max: f64,
        max_feed: f64,
        moves: [f64; 3],
        what: &str,
    ) -> Self {
        Self {
            name: name.into(),
            kind: AxisKind::Linear,
            min,
            max,
            max_feed,
            programmed: true,
            description: what.into(),
            moves: Some(moves),
            turns: None,
            body: None,
            max_accel: None,
            turns_part: false,
        }
    }

    /// A programmed rotary axis of travel `[-deg, deg]` and `feed_deg`
    /// deg/min (held in rad), turning the tool relative to the part about
    /// `turns` for +1 deg.
    pub fn rotary_deg(name: &str, deg: f64, feed_deg: f64, turns: [f64; 3], what: &str) -> Self {
        Self {
            name: name.into(),
            kind: AxisKind::Rotary,
            min: -deg.to_radians(),
            max: deg.to_radians(),
            max_feed: feed_deg.to_radians(),
            programmed: true,
            description: what.into(),
            moves: None,
            turns: Some(turns),
            body: None,
            max_accel: None,
            turns_part: false,
        }
    }

    /// The same, accelerating at most `accel` (mm/s², or deg/s² for a
    /// rotary axis, held in rad/s²).
    pub fn accelerating(mut self, accel: f64) -> Self {
        self.max_accel = Some(if self.kind == AxisKind::Rotary {
            accel.to_radians()
        } else {
            accel
        });
        self
    }

    /// The same, turning the part ([`Self::turns_part`]).
    pub fn turning_part(mut self) -> Self {
        self.turns_part = true;
        self
    }

    /// A value in file/program units (mm, deg) from kernel units (mm, rad).
    pub fn to_user(&self, v: f64) -> f64 {
        if self.kind == AxisKind::Rotary {
            v.to_degrees()
        } else {
            v
        }
    }

    /// A value in kernel units (mm, rad) from file/program units (mm, deg):
    /// the inverse of [`Self::to_user`].
    pub fn from_user(&self, v: f64) -> f64 {
        if self.kind == AxisKind::Rotary {
            v.to_radians()
        } else {
            v
        }
    }

    /// The unit of [`Self::to_user`] values.
    pub fn unit(&self) -> &'static str {
        match self.kind {
            AxisKind::Linear => "mm",
            AxisKind::Rotary => "deg",
            AxisKind::Spindle => "rpm",
        }
    }

    /// The unit of feeds.
    pub fn feed_unit(&self) -> &'static str {
        match self.kind {
            AxisKind::Linear => "mm/min",
            AxisKind::Rotary => "deg/min",
            AxisKind::Spindle => "rpm",
        }
    }

    /// Whether blocks position it (programmed, and not a spindle).
    pub fn is_programmed(&self) -> bool {
        self.programmed && self.kind != AxisKind::Spindle
    }
}

/// One of the six elementary factors of a transform chain (docs/math.md §1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FactorKind {
    /// Translation along X (mm).
    Tx,
    /// Translation along Y (mm).
    Ty,
    /// Translation along Z (mm).
    Tz,
    /// Rotation about X (rad), right-handed.
    Rx,
    /// Rotation about Y (rad), right-handed.
    Ry,
    /// Rotation about Z (rad), right-handed.
    Rz,
}

impl FactorKind {
    /// Whether the factor is a rotation (its value in radians).
    pub fn is_rotation(self) -> bool {
        matches!(self, Self::Rx | Self::Ry | Self::Rz)
    }

    /// Index of the coordinate axis (0 = X, 1 = Y, 2 = Z) it moves along
    /// or about.
    pub fn direction_index(self) -> usize {
        match self {
            Self::Tx | Self::Rx => 0,
            Self::Ty | Self::Ry => 1,
            Self::Tz | Self::Rz => 2,
        }
    }
}

/// A number, or the name of a machine constant that gives it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Quantity {
    /// The number itself (mm or rad).
    Value(f64),
    /// The machine constant of this name (see [`MachineInfo::constants`]).
    Constant(String),
}

impl Quantity {
    /// The number: itself, or the constant's value.
    ///
    /// # Failures
    /// A constant the machine does not have: the message names it.
    pub fn resolve(&self, constants: &BTreeMap<String, f64>) -> Result<f64, String> {
        match self {
            Self::Value(v) => Ok(*v),
            Self::Constant(name) => constants
                .get(name)
                .copied()
                .ok_or_else(|| format!("no machine constant '{name}'")),
        }
    }
}

/// One factor of a chain as data: a constant (`value`), or bound to an
/// axis (`scale * axis + offset`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FactorSpec {
    /// Which elementary factor.
    pub factor: FactorKind,
    /// The axis it is bound to, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<String>,
    /// Multiplies the axis value (+1 or -1 for the sign, 0.5 for a
    /// diameter-programmed lathe X); since 1.7, also a constant's value
    /// (-0.5 to stand a body centred on its face).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub scale: f64,
    /// Added after scaling (mm or rad); for a constant factor, its value.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub offset: f64,
    /// A constant factor whose value is this machine constant, times
    /// `scale` (the offset is then unused).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constant: Option<String>,
}

fn one() -> f64 {
    1.0
}

fn is_one(v: &f64) -> bool {
    *v == 1.0
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl FactorSpec {
    /// A factor bound to `axis` (scale 1, offset 0).
    pub fn axis(factor: FactorKind, axis: &str) -> Self {
        Self {
            factor,
            axis: Some(axis.to_owned()),
            scale: 1.0,
            offset: 0.0,
            constant: None,
        }
    }

    /// A constant factor of `value` (mm or rad).
    pub fn value(factor: FactorKind, value: f64) -> Self {
        Self {
            factor,
            axis: None,
            scale: 1.0,
            offset: value,
            constant: None,
        }
    }

    /// A constant factor whose value is the machine constant `name`.
    pub fn constant(factor: FactorKind, name: &str) -> Self {
        Self {
            factor,
            axis: None,
            scale: 1.0,
            offset: 0.0,
            constant: Some(name.to_owned()),
        }
    }

    /// Since 1.7: a constant factor of `scale` times the machine constant
    /// `name`.
    pub fn scaled(factor: FactorKind, name: &str, scale: f64) -> Self {
        Self {
            scale,
            ..Self::constant(factor, name)
        }
    }
}

/// The solid of a moving body, in the body's own frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum BodyShape {
    /// A cylinder of `radius` and `length`, centred on the body's origin,
    /// its axis along the body frame's Y (across the part's axial section):
    /// a steady rest's roller.
    Roller {
        /// Radius (mm), or the constant that gives it.
        radius: Quantity,
        /// Length (mm), or the constant that gives it.
        length: Quantity,
    },
    /// Since 1.6: a cylinder of `radius` and `length`, its axis along the
    /// body frame's Z, centred on the body's origin: a chuck, a
    /// tailstock's quill, a spindle's nose, a roll's arbor.
    Cylinder {
        /// Radius (mm), or the constant that gives it.
        radius: Quantity,
        /// Length (mm), or the constant that gives it.
        length: Quantity,
    },
    /// Since 1.6: a box of `size` (along the body frame's X, Y and Z),
    /// centred on the body's origin: a wheelhead, a turret, a holder, a
    /// rest's arm. (`kind = "box"` in files.)
    #[serde(rename = "box")]
    Block {
        /// Its edges (mm), or the constants that give them.
        size: [Quantity; 3],
    },
    /// Since 1.9: the frustum of a cone along the body frame's Z, centred
    /// on the origin: `radius` at its -Z end, `end_radius` at its +Z end
    /// (a tailstock's centre, its point in the part's centre hole).
    Cone {
        /// Radius at the -Z end (mm), or the constant that gives it.
        radius: Quantity,
        /// Radius at the +Z end (mm), or the constant that gives it.
        end_radius: Quantity,
        /// Length (mm), or the constant that gives it.
        length: Quantity,
    },
    /// Since 1.6: a wheel's guard: a tube round the body frame's Z
    /// (`inner` and `outer` radius, `width` along Z, centred on the
    /// origin) over `cover_deg` of the turn, centred on the frame's +X;
    /// the open side faces -X (where the wheel meets the part).
    Guard {
        /// Inner radius (mm), or the constant that gives it.
        inner: Quantity,
        /// Outer radius (mm), or the constant that gives it.
        outer: Quantity,
        /// Width along Z (mm), or the constant that gives it.
        width: Quantity,
        /// The angle it covers (deg, above 0 and below 360).
        cover_deg: f64,
    },
}

impl BodyShape {
    /// Its sizes, numbers or constants' names.
    pub fn quantities(&self) -> Vec<&Quantity> {
        match self {
            Self::Roller { radius, length } | Self::Cylinder { radius, length } => {
                vec![radius, length]
            }
            Self::Block { size } => size.iter().collect(),
            Self::Cone {
                radius,
                end_radius,
                length,
            } => vec![radius, end_radius, length],
            Self::Guard {
                inner,
                outer,
                width,
                ..
            } => vec![inner, outer, width],
        }
    }
}

/// The machine constants a chain's factors take, each once, in order.
pub fn chain_constants(chain: &[FactorSpec]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for name in chain.iter().filter_map(|f| f.constant.as_ref()) {
        if !out.contains(name) {
            out.push(name.clone());
        }
    }
    out
}

/// Since 1.7: the frame a body's chain starts from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mount {
    /// The part frame: the chain places the body in it, its axes moving it
    /// (a steady rest).
    #[default]
    Part,
    /// The tool's spindle: the tool frame moved to the tool's centre (a
    /// wheel's centre on its axis, which the run knows from the wheel's
    /// size; the tool frame's origin for other tools), its axes the tool
    /// frame's. The body rides with the tool (a guard, a wheelhead, a
    /// holder, a turret).
    Tool,
    /// The part's end at its least z (the part frame turned by nothing,
    /// moved along Z to where the part's solids begin): a chuck, a
    /// headstock's centre, a roll's arbor on that side.
    PartStart,
    /// The part's end at its greatest z: a tailstock.
    PartEnd,
}

impl Mount {
    /// Whether this is the default, [`Mount::Part`].
    pub fn is_part(&self) -> bool {
        *self == Self::Part
    }

    /// `part`, `tool`, `part_start` or `part_end`.
    pub fn word(self) -> &'static str {
        match self {
            Self::Part => "part",
            Self::Tool => "tool",
            Self::PartStart => "part_start",
            Self::PartEnd => "part_end",
        }
    }
}

/// Since 1.10: which tools a body is there for. A lathe holds a tool that
/// cuts from outside the part in a holder, with the tailstock up; one
/// that cuts inside a bore on a boring bar, the tailstock away.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reach {
    /// Every tool.
    #[default]
    Any,
    /// Tools that cut from outside the part.
    Outside,
    /// Tools that cut inside a bore.
    Inside,
}

impl Reach {
    /// Whether this is the default, [`Reach::Any`].
    pub fn is_any(&self) -> bool {
        *self == Self::Any
    }

    /// `any`, `outside` or `inside`.
    pub fn word(self) -> &'static str {
        match self {
            Self::Any => "any",
            Self::Outside => "outside",
            Self::Inside => "inside",
        }
    }

    /// Whether the body is there for a tool that cuts inside a bore
    /// (`inside`) or from outside.
    pub fn holds(self, inside: bool) -> bool {
        match self {
            Self::Any => true,
            Self::Outside => !inside,
            Self::Inside => inside,
        }
    }
}

/// A body of the machine other than the tool: moving (a steady rest), on
/// the tool (a guard), or standing where the part is held (a chuck).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodySpec {
    /// Its name (a scene node and file name: letters, digits, `_`, `-`).
    pub name: String,
    /// What it is, in words.
    #[serde(default)]
    pub description: String,
    /// How reports and plots name the point its origin tracks (e.g.
    /// `steady rest: support centre`).
    #[serde(default)]
    pub label: String,
    /// The chain placing the body's frame in its mount's frame (the part
    /// frame unless [`Self::mount`] says otherwise), left to right. A body
    /// not mounted on the part takes constants only: its mount moves it.
    pub chain: Vec<FactorSpec>,
    /// Since 1.7: what the body is mounted on.
    #[serde(default, skip_serializing_if = "Mount::is_part")]
    pub mount: Mount,
    /// Its solid, if it is drawn.
    #[serde(default)]
    pub shape: Option<BodyShape>,
    /// Since 1.5: for a body that rides the part (a steady rest), the
    /// largest speed at which it may come onto it (mm/min), or the
    /// constant that gives it; `None` for a body that never touches it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub approach_feed: Option<Quantity>,
    /// Since 1.10: which tools it is there for.
    #[serde(default, skip_serializing_if = "Reach::is_any")]
    pub reach: Reach,
}

impl BodySpec {
    /// The machine constants that place it (its chain's) and size it
    /// (its shape's), each once, in the order they appear: what a
    /// collision of the body can be resolved by.
    pub fn constants(&self) -> Vec<String> {
        let mut out = chain_constants(&self.chain);
        for q in self.shape.iter().flat_map(BodyShape::quantities) {
            if let Quantity::Constant(name) = q {
                if !out.contains(name) {
                    out.push(name.clone());
                }
            }
        }
        out
    }

    /// A body of `shape` on `mount`, placed there by `chain`, described as
    /// `description`; no label, riding nothing.
    pub fn mounted(
        name: &str,
        description: &str,
        mount: Mount,
        chain: Vec<FactorSpec>,
        shape: BodyShape,
    ) -> Self {
        Self {
            name: name.into(),
            description: description.into(),
            label: String::new(),
            chain,
            shape: Some(shape),
            approach_feed: None,
            mount,
            reach: Reach::Any,
        }
    }

    /// The same body, there only for the tools `reach` says.
    pub fn for_tools(self, reach: Reach) -> Self {
        Self { reach, ..self }
    }
}

/// The tool's tracked point and axis in the tool's own frame, as the
/// machine's chain defines that frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToolSpec {
    /// The point (mm).
    pub point: [f64; 3],
    /// The unit axis.
    pub axis: [f64; 3],
}

impl Default for ToolSpec {
    /// The origin and +Z.
    fn default() -> Self {
        Self {
            point: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
        }
    }
}

/// What a machine says of itself: the descriptor a plugin returns. Besides
/// its axes it declares its capabilities, as LinuxCNC's kinematics modules
/// declare theirs: the axes its inverse kinematics solves
/// ([`Self::solved_axes`]), the axes it takes from the toolpath instead
/// ([`Self::driven_axes`]) and its other moving bodies ([`Self::bodies`]).
/// Whether it posts its own programs is the entry table's capability
/// (`CAP_POST`); without it the host's writer posts them in the dialect of
/// [`Self::control`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MachineInfo {
    /// The machine's name.
    pub name: String,
    /// A description in words.
    #[serde(default)]
    pub description: String,
    /// The control's dialect: `sinumerik`, `fanuc`.
    pub control: String,
    /// All axes (kernel units: mm, rad).
    pub axes: Vec<Axis>,
    /// The axes inverse kinematics solves for, in the order of its output rows.
    pub solved_axes: Vec<String>,
    /// Named machine constants (mm, rad).
    #[serde(default)]
    pub constants: BTreeMap<String, f64>,
    /// Decimals of axis values in programs, if the machine states them.
    #[serde(default)]
    pub program_decimals: Option<usize>,
    /// Programmed axes the machine does not solve but takes from the
    /// toolpath, which must drive them (a steady rest's U).
    #[serde(default)]
    pub driven_axes: Vec<String>,
    /// Moving bodies other than the tool, placed by their own chains.
    #[serde(default)]
    pub bodies: Vec<BodySpec>,
    /// The tool's chain, tool frame to part frame, when the machine states
    /// it (the host checks the axes' stated signs against it). Empty if not.
    #[serde(default)]
    pub chain: Vec<FactorSpec>,
    /// The tool frame the chain places.
    #[serde(default)]
    pub tool: ToolSpec,
    /// The least feed the machine's controls accept on a cutting move
    /// (mm/min, or deg/min for a move that only turns), if stated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_feed: Option<f64>,
    /// Since 1.2: how every program on the machine starts and ends.
    #[serde(default)]
    pub setup: ProgramSetup,
}

/// A working plane (G17, G18, G19).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Plane {
    /// X-Y (G17).
    Xy,
    /// Z-X (G18), the plane of a lathe or a cylindrical grinder.
    Zx,
    /// Y-Z (G19).
    Yz,
}

/// How a radial axis is programmed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Radial {
    /// The value is the distance from the part's axis (Sinumerik `DIAMOF`).
    Radius,
    /// The value is twice it (Sinumerik `DIAMON`; a Fanuc lathe's parameter).
    Diameter,
}

/// How every program on a machine starts and ends (since 1.2): settings of
/// the machine that the writer turns into its dialect's words, and the safe
/// order of the first and last moves, which the host turns into blocks.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProgramSetup {
    /// The work offset: 1 is G54, ... 6 is G59. `None`: none written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub work_offset: Option<u8>,
    /// The working plane. `None`: none written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<Plane>,
    /// The radial axis (the one named in `radial_axis`) and how it is
    /// programmed; the host checks it against the axis's stated motion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial: Option<Radial>,
    /// The name of the radial axis (`X` if empty).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub radial_axis: String,
    /// Coolant on after the spindle starts and off at the end (M8, M9).
    #[serde(default)]
    pub coolant: bool,
    /// Clear positions of axes (program units): where the start and the
    /// end take them out of the way.
    #[serde(default)]
    pub clear: BTreeMap<String, f64>,
    /// The start's first move: these axes to their clear positions,
    /// together, from wherever they stand.
    #[serde(default)]
    pub start_clear: Vec<String>,
    /// Then these groups of axes, one group after the other, to the first
    /// block's position; the first block brings the remaining axes.
    #[serde(default)]
    pub approach: Vec<Vec<String>>,
    /// After the last block, these groups of axes, one after the other, to
    /// their clear positions.
    #[serde(default)]
    pub retract: Vec<Vec<String>>,
    /// The axes whose path the feed F is (Sinumerik `FGROUP`; ABI 1.3):
    /// empty, the linear axes (a move that only turns: its rotary axes,
    /// F in deg/min). A caliber grinder's is the roll's turn `A`, the
    /// leading coordinate: F in deg/min of the roll, the other axes
    /// following; a block that does not turn it reads F as the linear
    /// axes' path feed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub feed_group: Vec<String>,
    /// Since 1.12: the control's state at power-on and reset, as the
    /// machine's parameters set it, where the machine states it. A program
    /// that relies on it gets it; where the machine states none, a program
    /// must state its setup codes itself.
    #[serde(default, skip_serializing_if = "PowerOn::is_unstated")]
    pub power_on: PowerOn,
}

/// The control's state at power-on and reset (since 1.12), as the
/// machine's parameters set it.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowerOn {
    /// The G codes in force, one for each modal group the machine states
    /// (`21`: millimetres, `90`: absolute, `94` or Fanuc's `98`: feed per
    /// minute, `99`: per revolution, `40`: no cutter compensation, `97`:
    /// constant rpm, `18`: the plane, `54`: the work offset). A group not
    /// listed is not stated.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub g: Vec<u32>,
    /// The value in millimetres of an axis number written without a
    /// decimal point, where the control has a parameter for it (Fanuc:
    /// `0.001`, the least input increment, with decimal-point input off;
    /// `1` with calculator-type input). `None`: the dialect's default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_point: Option<f64>,
    /// The control's G-code system where it has several (a Fanuc lathe's
    /// `A`, `B` or `C`), if stated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub system: Option<String>,
}

impl PowerOn {
    /// Whether the machine states nothing of its power-on state.
    pub fn is_unstated(&self) -> bool {
        *self == Self::default()
    }
}

impl MachineInfo {
    /// The axis called `name`.
    pub fn axis(&self, name: &str) -> Option<&Axis> {
        self.axes.iter().find(|a| a.name == name)
    }

    /// The body called `name`.
    pub fn body(&self, name: &str) -> Option<&BodySpec> {
        self.bodies.iter().find(|b| b.name == name)
    }
}

/// How a block moves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Motion {
    /// At the machine's rapid traverse.
    Rapid,
    /// A straight cut at the block's feed.
    Linear,
    /// A thread cut synchronised with the spindle at `lead` mm per turn.
    Thread {
        /// Lead (mm per spindle turn).
        lead: f64,
        /// Since 1.4: the spindle's angle (deg) at which the cut starts,
        /// after the spindle's one-turn mark (Fanuc `Q`, Sinumerik `SF`):
        /// a multi-start thread's starts differ by `360 / z1`. 0 when
        /// absent.
        #[serde(default, skip_serializing_if = "is_zero")]
        start_deg: f64,
    },
}

impl std::fmt::Display for Motion {
    /// The motion as a message names it: `a rapid`, `a straight cut`, `a
    /// thread cut of lead 2.5 mm` (and its start angle where it has one).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Rapid => write!(f, "a rapid"),
            Self::Linear => write!(f, "a straight cut"),
            Self::Thread { lead, start_deg } if *start_deg != 0.0 => {
                write!(f, "a thread cut of lead {lead} mm from {start_deg} deg")
            }
            Self::Thread { lead, .. } => write!(f, "a thread cut of lead {lead} mm"),
        }
    }
}

/// An axis of a program.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProgramAxis {
    /// The address letter.
    pub name: String,
    /// `mm` or `deg`.
    pub unit: String,
}

/// One block of a program.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Block {
    /// How the block moves.
    pub motion: Motion,
    /// Axis values in program units, in the order of [`AxisProgram::axes`].
    pub values: Vec<f64>,
    /// Feed (mm/min) for linear blocks; the lead for thread blocks is in
    /// the motion; 0 for rapids.
    pub feed: f64,
    /// A spindle speed (rpm) set from this block on; `None` keeps the last.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle: Option<f64>,
    /// A comment to print before the block (a pass's name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub comment: Option<String>,
    /// Since 1.2: axes this block leaves where they stand (not written):
    /// at the start, an axis not yet moved, whose place nobody knows. Its
    /// value here is the one it takes next.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub keep: Vec<String>,
    /// Since 1.5: the number the block carries in a program's text (`N`),
    /// for a program read from a file; `None` for a program the host
    /// builds, whose writer numbers it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub number: Option<u32>,
    /// Since 1.13: the line (from 1) of a program read from a file on
    /// which the block's move stands (a subprogram's move: the line of its
    /// call), naming the block where it carries no `N`; `None` for a
    /// program the host builds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line: Option<u32>,
    /// Since 1.14: the seconds the axes stand before the block's move (a
    /// program read from a file: its dwells, `G4`, since the move before),
    /// the spindle turning; 0 for a program the host builds, whose posts
    /// write no dwell.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub dwell_s: f64,
}

/// A program for one machine: named axes in program units (mm, degrees)
/// and blocks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisProgram {
    /// The program's name (letters, digits, `_`).
    pub name: String,
    /// The program number (Fanuc `O` word).
    pub number: u32,
    /// The machine's name.
    pub machine: String,
    /// The control's dialect.
    pub control: String,
    /// The tool's number.
    pub tool_number: u32,
    /// The tool's name.
    pub tool_name: String,
    /// Spindle speed (rpm).
    pub spindle_rpm: f64,
    /// Decimals of axis values, if the machine states them (else the
    /// dialect's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decimals: Option<usize>,
    /// The programmed axes.
    pub axes: Vec<ProgramAxis>,
    /// The blocks.
    pub blocks: Vec<Block>,
    /// Since 1.2: the machine's start and end settings (work offset,
    /// plane, radial programming, coolant); its safe first and last moves
    /// are blocks already.
    #[serde(default)]
    pub setup: ProgramSetup,
    /// Since 1.11: runs of blocks a control's threading cycle makes, each
    /// written as its cycle where the dialect has it (LinuxCNC's G76),
    /// as its blocks elsewhere. The blocks are the cycle's passes as the
    /// control makes them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cycles: Vec<CycleSpan>,
    /// Since 1.13: runs of blocks Fanuc's two-block threading cycle makes,
    /// written as its two `G76` blocks on a control of Fanuc's kind, as
    /// their blocks elsewhere.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fanuc_cycles: Vec<FanucCycleSpan>,
}

/// Since 1.13: the blocks `first..first + count` of a program, which one
/// Fanuc two-block threading cycle makes from where the block before them
/// leaves the tool.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FanucCycleSpan {
    /// The first block the cycle makes (from 0).
    pub first: usize,
    /// How many blocks it makes.
    pub count: usize,
    /// The cycle.
    pub cycle: FanucThreadCycle,
}

/// Since 1.13: Fanuc's two-block threading cycle (`G76 P(m)(r)(a)
/// Q(dd_min) R(d)`, then `G76 X Z R(i) P(k) Q(dd) F(L)`) as its words give
/// it, every length a radius in mm (the words' least input units
/// converted) but `x`, the thread's end as the program writes X. The
/// passes: `D_1 = dd`, `D_n = dd sqrt(n)` (or `n dd` at a constant
/// depth), at least `dd_min` more than the last, capped at `k - d`; then
/// `m` passes at `k`; pass `n` shifted towards the start by `(k - D_n)
/// tan(a/2)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FanucThreadCycle {
    /// m: the finishing passes at the full height.
    pub finishes: u32,
    /// r: the chamfer at the end, in tenths of the lead (0 to 99).
    pub chamfer_tenths: u32,
    /// a: the tool's angle (deg): 80, 60, 55, 30, 29 or 0.
    pub angle_deg: f64,
    /// dd_min: the least depth a roughing pass adds.
    pub min_cut: f64,
    /// d: the finishing allowance.
    pub allowance: f64,
    /// X: the thread's end at its full height (as the program writes X).
    pub x: f64,
    /// Z: the thread's end.
    pub z: f64,
    /// i: the taper, the radius at the start minus at the end.
    pub taper: f64,
    /// k: the thread's height.
    pub height: f64,
    /// dd: the first pass's depth.
    pub first: f64,
    /// L: the lead.
    pub lead: f64,
    /// Whether the roughing passes cut a constant depth (`D_n = n dd`,
    /// the one-block form's P3) rather than a constant area (`D_n = dd
    /// sqrt(n)`, the two-block form and P1).
    #[serde(default)]
    pub constant_depth: bool,
}

/// Since 1.11: the blocks `first..first + count` of a program, which one
/// threading cycle makes from where the block before them leaves the
/// tool.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CycleSpan {
    /// The first block the cycle makes (from 0).
    pub first: usize,
    /// How many blocks it makes.
    pub count: usize,
    /// The cycle.
    pub cycle: ThreadCycle,
}

/// Since 1.11: a multi-pass threading cycle by its words, in program
/// units (X's words on diameter where the program is): LinuxCNC's G76
/// (`G76 P Z I J R K Q H`), the passes
/// `depth = |I| + J n^(1/R)` from the drive line (where the tool stands
/// before it) while below `|I| + K`, then `H + 1` at the full depth, each
/// pass's start moved along Z by its depth below the crest times
/// `tan Q`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThreadCycle {
    /// `P`: the lead (mm per turn).
    pub pitch: f64,
    /// `Z`: where the passes end along Z, the cycle's last place.
    pub z: f64,
    /// `I`: the crest's offset from the drive line, negative outside a
    /// part, positive inside a bore.
    pub i: f64,
    /// `J`: the first pass's depth below the crest.
    pub j: f64,
    /// `R`: the depth's degression (1: constant depth, 2: constant area).
    pub r: f64,
    /// `K`: the thread's full depth below the crest.
    pub k: f64,
    /// `Q`: the compound angle (deg).
    pub q: f64,
    /// `H`: spring passes at the full depth after the first.
    pub h: u32,
}

impl AxisProgram {
    /// The values of axis `name` over all blocks, in program units.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let i = self.axes.iter().position(|a| a.name == name)?;
        Some(self.blocks.iter().map(|b| b.values[i]).collect())
    }
}

/// What the host sends a plugin's `post`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PostRequest {
    /// The dialect (`sinumerik`, `fanuc`, `cld`).
    pub dialect: String,
    /// The program.
    pub program: AxisProgram,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A descriptor of ABI 1.0 (without the fields 1.1 appended) still reads.
    #[test]
    fn a_1_0_descriptor_reads_with_defaults() {
        let text = r#"{"name":"lathe","control":"fanuc","axes":[
            {"name":"X","kind":"linear","min":-10.0,"max":400.0,"max_feed":8000.0,"programmed":true,
             "description":"","moves":[0.5,0.0,0.0],"turns":null,"body":null}],
            "solved_axes":["X"]}"#;
        let info: MachineInfo = serde_json::from_str(text).unwrap();
        assert!(info.bodies.is_empty() && info.chain.is_empty());
        assert_eq!(info.tool, ToolSpec::default());
        assert_eq!(info.axis("X").unwrap().moves, Some([0.5, 0.0, 0.0]));
    }

    #[test]
    fn quantities_and_factors_read_as_numbers_or_names() {
        let q: Vec<Quantity> = serde_json::from_str(r#"[25.0, "rest_radius"]"#).unwrap();
        let constants = BTreeMap::from([("rest_radius".to_owned(), 30.0)]);
        assert_eq!(q[0].resolve(&constants), Ok(25.0));
        assert_eq!(q[1].resolve(&constants), Ok(30.0));
        assert!(Quantity::Constant("b".into())
            .resolve(&constants)
            .unwrap_err()
            .contains("'b'"));
        let f = FactorSpec::constant(FactorKind::Tz, "rest_offset_b");
        let text = serde_json::to_string(&f).unwrap();
        assert_eq!(text, r#"{"factor":"tz","constant":"rest_offset_b"}"#);
        assert_eq!(serde_json::from_str::<FactorSpec>(&text).unwrap(), f);
    }

    #[test]
    fn units_round_trip() {
        let a = Axis {
            name: "A".into(),
            kind: AxisKind::Rotary,
            min: -1.0,
            max: 1.0,
            max_feed: 1.0,
            programmed: true,
            description: String::new(),
            moves: None,
            turns: Some([0.0, 0.0, 1.0]),
            body: None,
            max_accel: None,
            turns_part: false,
        };
        assert!((a.from_user(a.to_user(0.3)) - 0.3).abs() < 1e-15);
        assert_eq!(a.unit(), "deg");
    }
}
