//! Machines: named axes with travel and feed limits, the kinematic chain
//! from tool to part, and the chains of other moving bodies (a steady rest).
//!
//! A machine is described as data, a [`MachineInfo`] (the type the plugin
//! ABI carries): its axes, constants, the chains of the tool and of other
//! moving bodies, and its capabilities. It comes from a TOML file (see
//! [`Machine::from_toml_str`] for the format), the data built-in
//! ([`Machine::builtin`]), or a plugin's descriptor ([`Machine::from_info`]);
//! [`machine_file`] writes any description as a file. Units in files are millimetres and degrees
//! (`_deg` keys); inside, millimetres and radians.
//!
//! The runtime uses a machine through [`MachineKinematics`]: inverse and
//! forward kinematics in batches ([`ChainMachine`] for any data machine;
//! plugins implement it natively).
//!
//! ```
//! use pilgrim_kernel::machine::Machine;
//! let m = Machine::builtin("vertical-mill").unwrap();
//! assert_eq!(m.chain().axis_names(), ["X", "Y", "Z", "C"]);
//! ```

mod builtin;
mod file;
mod info;
mod kinematics;
mod write;

pub use builtin::{BUILTIN_MACHINES, BUILTIN_SOURCES};
pub use info::{
    bodies_of, body_offset, check_description, part_turn_factors, Body, BodyError, Solid,
    AXIS_LETTERS,
};
pub(crate) use kinematics::overridden as kinematics_overridden;
pub use kinematics::{batch_rows, ChainMachine, KinematicsError, MachineKinematics};
pub use pilgrim_plugin_abi::types::{
    Axis, AxisKind, BodyShape, BodySpec, FactorSpec, MachineInfo, Mount, Quantity, ToolSpec,
};
pub use write::machine_file;

use crate::math::Real;
use crate::transform::{Chain, IkOptions, IkSolution, Target, ToolFrame, TransformError};
use std::collections::BTreeMap;

/// Errors of machine files and machine limits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MachineError {
    /// A machine file that cannot be read or is wrong at a place.
    #[error("{file}:{line}:{column}: {message}")]
    File {
        /// The file (or built-in) name.
        file: String,
        /// Line (from 1).
        line: usize,
        /// Column (from 1).
        column: usize,
        /// What is wrong, naming the key.
        message: String,
    },
    /// A file that could not be opened.
    #[error("{file}: {message}")]
    Io {
        /// The file.
        file: String,
        /// The system's message.
        message: String,
    },
    /// No built-in machine of that name.
    #[error("no built-in machine '{name}' (built-ins: {known})")]
    UnknownMachine {
        /// The name asked for.
        name: String,
        /// The names there are.
        known: String,
    },
    /// An axis name the machine does not have.
    #[error("machine {machine} has no axis '{axis}' (axes: {known})")]
    UnknownAxis {
        /// The machine.
        machine: String,
        /// The name asked for.
        axis: String,
        /// The axes there are.
        known: String,
    },
    /// A point outside an axis's travel.
    #[error("point {point}: axis {axis} at {value:.4} {unit} is outside its travel [{min}, {max}] {unit}")]
    OutsideTravel {
        /// Index of the point (block).
        point: usize,
        /// The axis.
        axis: String,
        /// The value (mm or deg).
        value: Real,
        /// Lower limit (mm or deg).
        min: Real,
        /// Upper limit (mm or deg).
        max: Real,
        /// mm or deg.
        unit: &'static str,
    },
    /// A move faster than an axis can go.
    #[error("point {point}: axis {axis} would move at {speed:.1} {unit}, above its maximum {max} {unit}")]
    FeedExceeded {
        /// Index of the point (block) the move ends at.
        point: usize,
        /// The axis.
        axis: String,
        /// The speed needed (mm/min or deg/min).
        speed: Real,
        /// The axis's maximum.
        max: Real,
        /// mm/min or deg/min.
        unit: &'static str,
    },
    /// A bad feed, or a malformed batch of points.
    #[error("point {point}: {message}")]
    BadPoint {
        /// Index of the point.
        point: usize,
        /// What is wrong.
        message: String,
    },
    /// A kinematics failure (inverse kinematics, chain evaluation).
    #[error(transparent)]
    Transform(#[from] TransformError),
    /// A machine description (a plugin's descriptor) that is wrong.
    #[error("machine {machine}: {message}")]
    Description {
        /// The machine's name.
        machine: String,
        /// What is wrong, naming the axis, factor, body or constant.
        message: String,
    },
}

/// A machine tool: its description ([`MachineInfo`]: axes, constants,
/// capabilities, chains as data) and the chains compiled from it, the
/// tool's and every other body's.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    info: MachineInfo,
    chain: Chain,
    tool: ToolFrame,
    bodies: BTreeMap<String, Body>,
}

impl Machine {
    /// The machine's description.
    pub fn info(&self) -> &MachineInfo {
        &self.info
    }

    /// The machine's name.
    pub fn name(&self) -> &str {
        &self.info.name
    }

    /// A description in words.
    pub fn description(&self) -> &str {
        &self.info.description
    }

    /// The control's dialect name (e.g. `sinumerik`, `fanuc`).
    pub fn control(&self) -> &str {
        &self.info.control
    }

    /// All axes, in the description's order.
    pub fn axes(&self) -> &[Axis] {
        &self.info.axes
    }

    /// The axis called `name`.
    pub fn axis(&self, name: &str) -> Option<&Axis> {
        self.info.axis(name)
    }

    fn axis_or_err(&self, name: &str) -> Result<&Axis, MachineError> {
        axis_or_err(&self.info, name)
    }

    /// The chain from the tool's frame to the part's: `r_part = A(q) r_tool`.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The tool's default reference point and axis in its own frame.
    pub fn tool_frame(&self) -> &ToolFrame {
        &self.tool
    }

    /// Another moving body (e.g. `rest`), with the chain placing it in the
    /// part frame.
    pub fn body(&self, name: &str) -> Option<&Body> {
        self.bodies.get(name)
    }

    /// The chain placing another body (e.g. `rest`) in the part frame.
    pub fn body_chain(&self, body: &str) -> Option<&Chain> {
        self.bodies.get(body).map(Body::chain)
    }

    /// The other bodies, by name.
    pub fn bodies(&self) -> impl Iterator<Item = &Body> {
        self.bodies.values()
    }

    /// Decimals of axis values in this machine's programs, if it states them
    /// (its resolution: 4 for 0.1 um); otherwise the dialect's.
    pub fn program_decimals(&self) -> Option<usize> {
        self.info.program_decimals
    }

    /// A named machine constant (mm or rad), e.g. the rest's offset `B`.
    pub fn constant(&self, name: &str) -> Option<Real> {
        self.info.constants.get(name).copied()
    }

    /// All named constants.
    pub fn constants(&self) -> &BTreeMap<String, Real> {
        &self.info.constants
    }

    /// The travel `(min, max)` of each of `chain`'s axes, in its order.
    pub fn travel_of(&self, chain: &Chain) -> Result<Vec<(Real, Real)>, MachineError> {
        chain
            .axis_names()
            .iter()
            .map(|n| self.axis_or_err(n).map(|a| (a.min, a.max)))
            .collect()
    }

    /// Inverse kinematics of the tool chain within travel. The seed defaults
    /// to the middle of each linear axis's travel and 0 (clamped into
    /// travel) for rotary axes.
    ///
    /// # Failures
    /// As [`Chain::inverse`].
    pub fn inverse(
        &self,
        target: &Target,
        tool: &ToolFrame,
        seed: Option<&[Real]>,
        opts: &IkOptions,
    ) -> Result<IkSolution, MachineError> {
        let travel = self.travel_of(&self.chain)?;
        let home = home_seed(&self.chain, &travel);
        Ok(self
            .chain
            .inverse(target, tool, seed.unwrap_or(&home), Some(&travel), opts)?)
    }

    /// Checks that every point lies within travel. `axes` names the columns
    /// of `rows` (row after row, kernel units: mm, rad).
    ///
    /// # Failures
    /// [`MachineError::OutsideTravel`] naming the first offending point and
    /// axis; an unknown axis; a ragged batch.
    pub fn check_travel(&self, axes: &[&str], rows: &[Real]) -> Result<(), MachineError> {
        check_travel(&self.columns(axes, rows)?, rows)
    }

    /// Checks that no axis moves faster than its maximum between points;
    /// see [`check_feed`].
    ///
    /// # Failures
    /// As [`check_feed`]; an unknown axis.
    pub fn check_feed(
        &self,
        axes: &[&str],
        rows: &[Real],
        feeds: &[Real],
    ) -> Result<(), MachineError> {
        check_feed(&self.columns(axes, rows)?, rows, feeds)
    }

    fn columns(&self, axes: &[&str], rows: &[Real]) -> Result<Vec<&Axis>, MachineError> {
        let cols = axes
            .iter()
            .map(|n| self.axis_or_err(n))
            .collect::<Result<Vec<_>, _>>()?;
        check_rows(&cols, rows)?;
        Ok(cols)
    }
}

/// The start of inverse kinematics when nothing better is known: the middle
/// of each linear axis's travel, 0 (clamped into travel) for rotary axes.
/// `travel` holds the chain's axes' `(min, max)` in its order.
pub fn home_seed(chain: &Chain, travel: &[(Real, Real)]) -> Vec<Real> {
    travel
        .iter()
        .enumerate()
        .map(|(i, &(lo, hi))| {
            if chain.is_rotary(i) {
                0.0_f64.clamp(lo, hi)
            } else {
                0.5 * (lo + hi)
            }
        })
        .collect()
}

/// The axis called `name` of the machine `info`, or an error listing its axes.
fn axis_or_err<'a>(info: &'a MachineInfo, name: &str) -> Result<&'a Axis, MachineError> {
    info.axis(name).ok_or_else(|| MachineError::UnknownAxis {
        machine: info.name.clone(),
        axis: name.to_owned(),
        known: info
            .axes
            .iter()
            .map(|a| a.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
    })
}

fn check_rows(axes: &[&Axis], rows: &[Real]) -> Result<usize, MachineError> {
    if axes.is_empty() || !rows.len().is_multiple_of(axes.len()) {
        return Err(MachineError::BadPoint {
            point: rows.len() / axes.len().max(1),
            message: format!(
                "{} values do not fill rows of {} axes",
                rows.len(),
                axes.len()
            ),
        });
    }
    Ok(rows.len() / axes.len())
}

/// Checks that every row of `rows` (one value per axis of `axes`, kernel
/// units) lies within travel; spindles are not checked.
///
/// # Failures
/// [`MachineError::OutsideTravel`] naming the first offending point (row,
/// from 0) and axis, with values in mm or degrees; a ragged batch.
pub fn check_travel(axes: &[&Axis], rows: &[Real]) -> Result<(), MachineError> {
    check_rows(axes, rows)?;
    for (p, row) in rows.chunks_exact(axes.len()).enumerate() {
        for (a, &v) in axes.iter().zip(row) {
            if a.kind == AxisKind::Spindle {
                continue;
            }
            if !v.is_finite() || v < a.min || v > a.max {
                return Err(MachineError::OutsideTravel {
                    point: p,
                    axis: a.name.clone(),
                    value: a.to_user(v),
                    min: a.to_user(a.min),
                    max: a.to_user(a.max),
                    unit: a.unit(),
                });
            }
        }
    }
    Ok(())
}

/// Linear motion shorter than this (mm) counts as none: a move that only
/// turns reads its feed in degrees per minute (feed checks, cycle times).
pub const LINEAR_RESOLUTION: Real = 1e-4;

/// The length of a move, which its feed divides to give its time: the
/// linear axes' path (mm), or for a move that only turns (linear motion
/// under [`LINEAR_RESOLUTION`]) the rotary axes' (degrees, the feed then in
/// deg/min). `deltas` are the axes' changes in program units (mm, deg), one
/// per axis of `axes`.
pub fn move_length(axes: &[&Axis], deltas: &[Real]) -> Real {
    feed_length(axes, deltas, &[])
}

/// [`move_length`] on a control whose feed is the path of the axes
/// `group` (Sinumerik `FGROUP`, [`pilgrim_plugin_abi::types::ProgramSetup::feed_group`]): their path
/// (mm and degrees summed alike, as the control does without `FGREF`)
/// where one of them moves, else [`move_length`]'s.
pub fn feed_length(axes: &[&Axis], deltas: &[Real], group: &[String]) -> Real {
    if !group.is_empty() {
        let g = axes
            .iter()
            .zip(deltas)
            .filter(|(a, _)| group.contains(&a.name))
            .map(|(_, d)| d * d)
            .sum::<Real>()
            .sqrt();
        if g > crate::tolerance::SAME_LENGTH {
            return g;
        }
    }
    let length_of = |kind: AxisKind| -> Real {
        axes.iter()
            .zip(deltas)
            .filter(|(a, _)| a.kind == kind)
            .map(|(_, d)| d * d)
            .sum::<Real>()
            .sqrt()
    };
    let linear = length_of(AxisKind::Linear);
    if linear > LINEAR_RESOLUTION {
        linear
    } else {
        length_of(AxisKind::Rotary)
    }
}

/// Checks that no axis moves faster than its maximum between rows.
/// `feeds[i]` is the programmed feed (mm/min) of the move ending at row `i`
/// (`feeds[0]` is unused; `+inf` marks a rapid, not checked); the move lasts
/// its linear axes' path length over the feed (or, for a rotary-only move,
/// one whose linear motion is under 0.0001 mm, its angle in degrees over the
/// feed in deg/min).
///
/// # Failures
/// [`MachineError::FeedExceeded`] naming the first offending point and axis;
/// a feed that is not positive; a ragged batch.
pub fn check_feed(axes: &[&Axis], rows: &[Real], feeds: &[Real]) -> Result<(), MachineError> {
    check_feed_grouped(axes, rows, feeds, &[])
}

/// [`check_feed`] on a control whose feed is the path of `group`
/// ([`feed_length`]).
///
/// # Failures
/// As [`check_feed`].
pub fn check_feed_grouped(
    axes: &[&Axis],
    rows: &[Real],
    feeds: &[Real],
    group: &[String],
) -> Result<(), MachineError> {
    let n = check_rows(axes, rows)?;
    let w = axes.len();
    if feeds.len() != n {
        return Err(MachineError::BadPoint {
            point: feeds.len().min(n),
            message: format!("{} feeds for {n} points", feeds.len()),
        });
    }
    for p in 1..n {
        let (a0, a1) = (&rows[(p - 1) * w..p * w], &rows[p * w..(p + 1) * w]);
        let f = feeds[p];
        if f == Real::INFINITY {
            continue;
        }
        if !(f.is_finite() && f > 0.0) {
            return Err(MachineError::BadPoint {
                point: p,
                message: format!("feed {f} mm/min is not positive"),
            });
        }
        let user_delta = |i: usize| axes[i].to_user(a1[i]) - axes[i].to_user(a0[i]);
        let deltas: Vec<Real> = (0..w).map(user_delta).collect();
        let path = feed_length(axes, &deltas, group);
        if path == 0.0 {
            continue;
        }
        let minutes = path / f;
        for (i, a) in axes.iter().enumerate() {
            if a.kind == AxisKind::Spindle {
                continue;
            }
            let speed = deltas[i].abs() / minutes;
            let max = a.to_user(a.max_feed);
            if speed > max * (1.0 + crate::tolerance::LIMIT_SLACK) {
                return Err(MachineError::FeedExceeded {
                    point: p,
                    axis: a.name.clone(),
                    speed,
                    max,
                    unit: a.feed_unit(),
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The feed's length: the linear path, the turn of a move that only
    /// turns, and with a feed group (FGROUP(A)) the group's motion where
    /// it moves, the linear path where it does not.
    #[test]
    fn feed_lengths_follow_the_control() {
        let m = Machine::from_info(lz_250::describe()).unwrap();
        let axes: Vec<&Axis> = ["X", "Z", "A", "B"]
            .iter()
            .map(|n| m.info().axis(n).unwrap())
            .collect();
        assert_eq!(move_length(&axes, &[3.0, 4.0, 10.0, 1.0]), 5.0);
        assert_eq!(move_length(&axes, &[0.0, 0.0, 3.0, 4.0]), 5.0);
        let group = vec!["A".to_owned()];
        assert_eq!(feed_length(&axes, &[3.0, 4.0, 2.0, 1.0], &group), 2.0);
        assert_eq!(feed_length(&axes, &[3.0, 4.0, 0.0, 1.0], &group), 5.0);
        assert_eq!(
            m.info().setup.feed_group,
            group,
            "the caliber grinders' F is the roll's turn"
        );
    }

    #[test]
    fn travel_and_feed_errors_name_point_and_axis() {
        let m = Machine::from_info(fanuc_0i_tc::describe()).unwrap();
        let rows = [10.0, 0.0, 20.0, -5.0, 30.0, -900.0];
        let e = m.check_travel(&["X", "Z"], &rows).unwrap_err();
        assert!(
            matches!(&e, MachineError::OutsideTravel { point: 2, axis, .. } if axis == "Z"),
            "{e}"
        );
        assert!(
            e.to_string().starts_with("point 2: axis Z at -900.0000 mm"),
            "{e}"
        );
        // 100 mm of Z in a move at 50000 mm/min is over the axis's maximum.
        let rows = [10.0, 0.0, 10.0, -100.0];
        let e = m
            .check_feed(&["X", "Z"], &rows, &[0.0, 50000.0])
            .unwrap_err();
        assert!(
            matches!(&e, MachineError::FeedExceeded { point: 1, axis, .. } if axis == "Z"),
            "{e}"
        );
        assert!(m.check_feed(&["X", "Z"], &rows, &[0.0, 100.0]).is_ok());
        let e = m.check_feed(&["X", "Z"], &rows, &[0.0, -1.0]).unwrap_err();
        assert!(e.to_string().contains("point 1: feed -1"), "{e}");
        let e = m.check_travel(&["Q"], &[1.0]).unwrap_err();
        assert!(e.to_string().contains("no axis 'Q'"), "{e}");
    }

    #[test]
    fn rotary_limits_are_reported_in_degrees() {
        let m = Machine::from_info(lz_250::describe()).unwrap();
        let b = m.axis("B").unwrap();
        let too_far = b.max + 0.1;
        let e = m.check_travel(&["B"], &[too_far]).unwrap_err();
        let MachineError::OutsideTravel {
            value, max, unit, ..
        } = e
        else {
            panic!("{e}")
        };
        assert_eq!(unit, "deg");
        assert!(
            (value - too_far.to_degrees()).abs() < 1e-9 && (max - b.max.to_degrees()).abs() < 1e-9
        );
    }
}
