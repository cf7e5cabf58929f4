//! The `MachineKinematics` trait, and its implementation for any machine
//! described as data (a chain with numerical inverse kinematics).

use super::{AxisProgram, PostError};
use crate::machine::{Axis, AxisKind, Machine};
use crate::math::{Point3, Real, Vec3};
use crate::transform::{IkOptions, Target, ToolFrame};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What a machine says of itself: the descriptor a plugin returns as JSON.
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
    pub constants: BTreeMap<String, Real>,
    /// Decimals of axis values in programs, if the machine states them.
    #[serde(default)]
    pub program_decimals: Option<usize>,
}

impl MachineInfo {
    /// The axis called `name`.
    pub fn axis(&self, name: &str) -> Option<&Axis> {
        self.axes.iter().find(|a| a.name == name)
    }

    /// The descriptor of a data machine.
    pub fn of(machine: &Machine) -> Self {
        Self {
            name: machine.name().to_owned(),
            description: machine.description().to_owned(),
            control: machine.control().unwrap_or("sinumerik").to_owned(),
            axes: machine.axes().to_vec(),
            solved_axes: machine.chain().axis_names().to_vec(),
            constants: machine.constants().clone(),
            program_decimals: machine.program_decimals(),
        }
    }
}

/// A kinematics failure; `index` is the pose (row) it happened at.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{message}", index.map(|i| format!("pose {i}: ")).unwrap_or_default())]
pub struct KinematicsError {
    /// The row of the batch, if the failure is at one.
    pub index: Option<usize>,
    /// What went wrong.
    pub message: String,
}

impl KinematicsError {
    /// A failure at row `index`.
    pub fn at(index: usize, message: impl Into<String>) -> Self {
        Self {
            index: Some(index),
            message: message.into(),
        }
    }

    /// A failure not tied to a row.
    pub fn whole(message: impl Into<String>) -> Self {
        Self {
            index: None,
            message: message.into(),
        }
    }
}

/// A machine as the runtime uses it: inverse and forward kinematics in
/// batches, and the post-processor. Implemented natively (compiled in, or
/// loaded from a shared library: [`crate::plugin`]) or by a chain from data
/// ([`ChainMachine`]).
///
/// Poses are rows of six numbers, the tracked point (mm) and the tool's unit
/// axis in the part frame; axis rows hold [`MachineInfo::solved_axes`] in
/// kernel units (mm, rad).
pub trait MachineKinematics {
    /// The machine's descriptor.
    fn info(&self) -> &MachineInfo;

    /// Axis values for each pose; `out` is cleared and filled row by row.
    /// Each row may be seeded by the previous one (poses along a path).
    fn inverse(
        &self,
        poses: &[Real],
        tool: &ToolFrame,
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError>;

    /// As [`Self::inverse`], with some solved axes driven by the caller:
    /// `held` lists solved-axis indices, `values` one row of their values
    /// (kernel units) per pose. Machines that cannot hold axes refuse.
    fn inverse_held(
        &self,
        poses: &[Real],
        tool: &ToolFrame,
        held: &[usize],
        values: &[Real],
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError> {
        if held.is_empty() {
            return self.inverse(poses, tool, out);
        }
        let _ = values;
        Err(KinematicsError::whole(format!(
            "machine {} cannot have axes driven by the toolpath",
            self.info().name
        )))
    }

    /// The pose of each row of axis values; `out` is cleared and filled.
    fn forward(
        &self,
        axes: &[Real],
        tool: &ToolFrame,
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError>;

    /// The program as text in `dialect` (`sinumerik`, `fanuc`, `cld`). The
    /// default is the kernel's shared writer.
    fn post(&self, program: &AxisProgram, dialect: &str) -> Result<String, PostError> {
        super::post::post_by_name(program, dialect)
    }
}

/// Any [`Machine`] as [`MachineKinematics`]: its chain, numerical inverse
/// kinematics within travel, each pose seeded by the previous solution.
#[derive(Debug, Clone)]
pub struct ChainMachine {
    machine: Machine,
    info: MachineInfo,
    /// Tolerances of inverse kinematics.
    pub options: IkOptions,
}

impl ChainMachine {
    /// Wraps a machine.
    pub fn new(machine: Machine) -> Self {
        let info = MachineInfo::of(&machine);
        Self {
            machine,
            info,
            options: IkOptions::default(),
        }
    }

    /// The machine.
    pub fn machine(&self) -> &Machine {
        &self.machine
    }
}

impl ChainMachine {
    /// An inverse-kinematics error in program units (mm, degrees).
    fn explain(&self, e: crate::machine::MachineError) -> String {
        use crate::machine::MachineError;
        use crate::transform::TransformError;
        match e {
            MachineError::Transform(TransformError::OutsideTravel {
                axis,
                value,
                min,
                max,
            }) => match self.machine.axis(&axis) {
                Some(a) => format!(
                    "axis {axis} would need {} {unit}, outside its travel [{}, {}] {unit}",
                    crate::math::fixed(a.to_user(value), 4),
                    a.to_user(min),
                    a.to_user(max),
                    unit = a.unit()
                ),
                None => {
                    format!("axis {axis} would need {value}, outside its travel [{min}, {max}]")
                }
            },
            other => other.to_string(),
        }
    }
}

/// The number of rows of `width` values in a batch; a ragged end (or a
/// zero width) is an error naming `what` the values are.
pub fn batch_rows(values: &[Real], width: usize, what: &str) -> Result<usize, KinematicsError> {
    if width == 0 || !values.len().is_multiple_of(width) {
        return Err(KinematicsError::whole(format!(
            "{} {what} values do not fill rows of {width}",
            values.len()
        )));
    }
    Ok(values.len() / width)
}

impl MachineKinematics for ChainMachine {
    fn info(&self) -> &MachineInfo {
        &self.info
    }

    fn inverse(
        &self,
        poses: &[Real],
        tool: &ToolFrame,
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError> {
        batch_rows(poses, 6, "pose")?;
        out.clear();
        let chain = self.machine.chain();
        let rotary = (0..chain.dof()).any(|i| chain.is_rotary(i));
        let mut seed: Option<Vec<Real>> = None;
        for (i, p) in poses.chunks_exact(6).enumerate() {
            let point = Point3::new(p[0], p[1], p[2]);
            let axis = Vec3::new(p[3], p[4], p[5]);
            // Without rotary axes the tool's axis is fixed: check it, solve the point.
            let target = if rotary {
                Target::pose(point, axis)
            } else {
                Target::point(point)
            };
            let sol = self
                .machine
                .inverse(&target, tool, seed.as_deref(), &self.options)
                .map_err(|e| KinematicsError::at(i, self.explain(e)))?;
            if !rotary {
                let reached = chain
                    .pose(&sol.q, tool)
                    .map_err(|e| KinematicsError::at(i, e.to_string()))?;
                if (reached.axis - axis.normalize()).norm() > self.options.tol_dir.max(1e-9) {
                    return Err(KinematicsError::at(
                        i,
                        format!(
                            "tool axis ({:.6}, {:.6}, {:.6}) cannot be reached: the machine holds it at ({:.6}, {:.6}, {:.6})",
                            axis.x, axis.y, axis.z, reached.axis.x, reached.axis.y, reached.axis.z
                        ),
                    ));
                }
            }
            out.extend_from_slice(&sol.q);
            seed = Some(sol.q);
        }
        Ok(())
    }

    fn inverse_held(
        &self,
        poses: &[Real],
        tool: &ToolFrame,
        held: &[usize],
        values: &[Real],
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError> {
        if held.is_empty() {
            return self.inverse(poses, tool, out);
        }
        let n = batch_rows(poses, 6, "pose")?;
        if values.len() != n * held.len() {
            return Err(KinematicsError::whole(format!(
                "{} held values for {n} poses of {} held axes",
                values.len(),
                held.len()
            )));
        }
        let chain = self.machine.chain();
        let dof = chain.dof();
        let travel = self
            .machine
            .travel_of(chain)
            .map_err(|e| KinematicsError::whole(e.to_string()))?;
        let free: Vec<usize> = (0..dof).filter(|i| !held.contains(i)).collect();
        let free_travel: Vec<(Real, Real)> = free.iter().map(|&i| travel[i]).collect();
        out.clear();
        let home = crate::machine::home_seed(chain, &travel);
        let mut seed: Vec<Real> = free.iter().map(|&i| home[i]).collect();
        for (k, p) in poses.chunks_exact(6).enumerate() {
            let mut fixed = vec![None; dof];
            for (j, &h) in held.iter().enumerate() {
                fixed[h] = Some(values[k * held.len() + j]);
            }
            let reduced = chain
                .with_fixed(&fixed)
                .map_err(|e| KinematicsError::at(k, e.to_string()))?;
            let rotary = (0..reduced.dof()).any(|i| reduced.is_rotary(i))
                || held.iter().any(|&h| chain.is_rotary(h));
            let point = Point3::new(p[0], p[1], p[2]);
            let target = if rotary {
                Target::pose(point, Vec3::new(p[3], p[4], p[5]))
            } else {
                Target::point(point)
            };
            let q = if free.is_empty() {
                vec![]
            } else {
                reduced
                    .inverse(&target, tool, &seed, Some(&free_travel), &self.options)
                    .map_err(|e| KinematicsError::at(k, self.explain(e.into())))?
                    .q
            };
            let mut row = vec![0.0; dof];
            for (j, &i) in free.iter().enumerate() {
                row[i] = q[j];
            }
            for (j, &h) in held.iter().enumerate() {
                row[h] = values[k * held.len() + j];
            }
            let reached = chain
                .pose(&row, tool)
                .map_err(|e| KinematicsError::at(k, e.to_string()))?;
            if (reached.point - point).norm() > 10.0 * self.options.tol_pos
                || (reached.axis - Vec3::new(p[3], p[4], p[5]).normalize()).norm() > 1e-6
            {
                return Err(KinematicsError::at(
                    k,
                    "the pose cannot be reached with the driven axes' values",
                ));
            }
            out.extend_from_slice(&row);
            if !q.is_empty() {
                seed = q;
            }
        }
        Ok(())
    }

    fn forward(
        &self,
        axes: &[Real],
        tool: &ToolFrame,
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError> {
        let chain = self.machine.chain();
        batch_rows(axes, chain.dof(), "axis")?;
        let poses = chain
            .poses(axes, tool)
            .map_err(|e| KinematicsError::whole(e.to_string()))?;
        out.clear();
        for p in poses {
            out.extend_from_slice(&[
                p.point.x, p.point.y, p.point.z, p.axis.x, p.axis.y, p.axis.z,
            ]);
        }
        Ok(())
    }
}

/// Whether an axis is positioned by blocks (not a spindle, and programmed).
pub(crate) fn is_programmed(a: &Axis) -> bool {
    a.programmed && a.kind != AxisKind::Spindle
}
