//! The `MachineKinematics` trait, and its implementation for any machine
//! described as data (a chain with numerical inverse kinematics).

use super::{Machine, MachineError, MachineInfo};
use crate::math::{Point3, Real, Vec3};
use crate::transform::{IkOptions, Target, ToolFrame, TransformError};
use std::f64::consts::FRAC_PI_4;

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

/// A machine as the runtime uses it: its descriptor, and inverse and
/// forward kinematics in batches. Implemented natively (a plugin, compiled
/// in or loaded from a shared library: [`crate::plugin`]) or by a chain from
/// data ([`ChainMachine`]). Posting is a step of its own
/// ([`crate::program::post::PostProcessor`]).
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

    /// The same machine with some of its named constants set otherwise
    /// (`name`, value in kernel units): everything the host derives from
    /// the description (bodies' chains and shapes) follows. Machines that
    /// cannot follow a constant in their own kinematics refuse it.
    ///
    /// # Failures
    /// A constant the machine does not have; one its kinematics cannot
    /// follow; a description that no longer holds.
    fn with_constants(
        &self,
        overrides: &[(String, Real)],
    ) -> Result<Box<dyn MachineKinematics>, MachineError> {
        let _ = overrides;
        Err(MachineError::Description {
            machine: self.info().name.clone(),
            message: "its constants cannot be changed".into(),
        })
    }
}

/// `info` with the constants `overrides` set, each checked to exist.
pub(crate) fn overridden(
    info: &MachineInfo,
    overrides: &[(String, Real)],
) -> Result<MachineInfo, MachineError> {
    let mut info = info.clone();
    for (name, v) in overrides {
        match info.constants.get_mut(name) {
            Some(c) => *c = *v,
            None => {
                return Err(MachineError::Description {
                    machine: info.name.clone(),
                    message: format!("no machine constant '{name}'"),
                })
            }
        }
    }
    Ok(info)
}

/// Any [`Machine`] as [`MachineKinematics`]: its chain, numerical inverse
/// kinematics within travel, each pose seeded by the previous solution.
#[derive(Debug, Clone)]
pub struct ChainMachine {
    machine: Machine,
    /// Tolerances of inverse kinematics.
    pub options: IkOptions,
}

impl ChainMachine {
    /// Wraps a machine.
    pub fn new(machine: Machine) -> Self {
        Self {
            machine,
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
    fn explain(&self, e: MachineError) -> String {
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

impl ChainMachine {
    /// Inverse kinematics of every pose, the solved axes listed in `held`
    /// set to `values` (one row per pose) and the others solved around them,
    /// each pose seeded by the previous solution (the first by the home
    /// seed). Every solution is checked by forward kinematics: the point
    /// within 10 times the position tolerance, the tool's axis within the
    /// direction tolerance.
    fn solve(
        &self,
        poses: &[Real],
        tool: &ToolFrame,
        held: &[usize],
        values: &[Real],
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError> {
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
        if let Some(&h) = held.iter().find(|&&h| h >= dof) {
            return Err(KinematicsError::whole(format!(
                "held axis {h} is beyond the chain's {dof} axes"
            )));
        }
        let travel = self
            .machine
            .travel_of(chain)
            .map_err(|e| KinematicsError::whole(e.to_string()))?;
        let free: Vec<usize> = (0..dof).filter(|i| !held.contains(i)).collect();
        let free_travel: Vec<(Real, Real)> = free.iter().map(|&i| travel[i]).collect();
        let home = super::home_seed(chain, &travel);
        let home: Vec<Real> = free.iter().map(|&i| home[i]).collect();
        // The last two solutions with their poses (the latest first): each
        // pose is seeded by the last, or by extrapolating both where it
        // continues their step.
        let mut solved: [Option<(Vec<Real>, &[Real])>; 2] = [None, None];
        let tol_dir = self.options.tol_dir.max(crate::tolerance::SAME_RATIO);
        out.clear();
        let mut ticker = crate::budget::Ticker::new("inverse kinematics", 64);
        for (k, p) in poses.chunks_exact(6).enumerate() {
            ticker
                .tick()
                .map_err(|e| KinematicsError::at(k, e.to_string()))?;
            let row_held = &values[k * held.len()..(k + 1) * held.len()];
            let reduced;
            let solving = if held.is_empty() {
                chain
            } else {
                let mut fixed = vec![None; dof];
                for (&h, &v) in held.iter().zip(row_held) {
                    fixed[h] = Some(v);
                }
                reduced = chain
                    .with_fixed(&fixed)
                    .map_err(|e| KinematicsError::at(k, e.to_string()))?;
                &reduced
            };
            // Without a rotary axis to solve or hold, the tool's axis is
            // fixed: solve the point, then check the axis.
            let rotary = (0..solving.dof()).any(|i| solving.is_rotary(i))
                || held.iter().any(|&h| chain.is_rotary(h));
            let point = Point3::new(p[0], p[1], p[2]);
            let axis = Vec3::new(p[3], p[4], p[5]);
            let target = if rotary {
                Target::pose(point, axis)
            } else {
                Target::point(point)
            };
            let seed = match &solved {
                [Some(last), Some(before)] => continued(p, last, before, |i| solving.is_rotary(i))
                    .unwrap_or_else(|| last.0.clone()),
                [Some(last), None] => last.0.clone(),
                _ => home.clone(),
            };
            let q = if free.is_empty() {
                vec![]
            } else {
                solving
                    .inverse(&target, tool, &seed, Some(&free_travel), &self.options)
                    .map_err(|e| KinematicsError::at(k, self.explain(e.into())))?
                    .q
            };
            let mut row = vec![0.0; dof];
            for (&i, &v) in free.iter().zip(&q) {
                row[i] = v;
            }
            for (&h, &v) in held.iter().zip(row_held) {
                row[h] = v;
            }
            let reached = chain
                .pose(&row, tool)
                .map_err(|e| KinematicsError::at(k, e.to_string()))?;
            if (reached.axis - axis.normalize()).norm() > tol_dir {
                return Err(KinematicsError::at(
                    k,
                    format!(
                        "tool axis ({:.6}, {:.6}, {:.6}) cannot be reached: the machine holds it at ({:.6}, {:.6}, {:.6})",
                        axis.x, axis.y, axis.z, reached.axis.x, reached.axis.y, reached.axis.z
                    ),
                ));
            }
            if (reached.point - point).norm() > 10.0 * self.options.tol_pos {
                return Err(KinematicsError::at(
                    k,
                    "the pose cannot be reached with the driven axes' values",
                ));
            }
            out.extend_from_slice(&row);
            if !q.is_empty() {
                solved = [Some((q, p)), solved[0].take()];
            }
        }
        Ok(())
    }
}

/// The seed of a pose `p` that continues the step between the last two
/// solved, `last` and `before` (each its solution and pose): the two
/// solutions extrapolated. `None` when the pose does not continue the step
/// (its step differs from the last by more than a fifth of it: a new pass,
/// a rapid) or a rotary turned more than a quarter turn. Where the target does not fix an axis (a singular
/// pose: a swivel at zero leaves the roll's turn free) the solver keeps
/// the seed's value there, so the machine moves on as it moved, rather
/// than standing still on one axis while another makes up for it.
fn continued(
    p: &[Real],
    (q1, p1): &(Vec<Real>, &[Real]),
    (q0, p0): &(Vec<Real>, &[Real]),
    rotary: impl Fn(usize) -> bool,
) -> Option<Vec<Real>> {
    fn length(v: impl Iterator<Item = Real>) -> Real {
        v.map(|x| x * x).sum::<Real>().sqrt()
    }
    let step = length((0..p.len()).map(|i| p1[i] - p0[i]));
    let change = length((0..p.len()).map(|i| p[i] - 2.0 * p1[i] + p0[i]));
    let turned = (0..q1.len()).any(|i| rotary(i) && (q1[i] - q0[i]).abs() > FRAC_PI_4);
    (step > 0.0 && change <= 0.2 * step && !turned)
        .then(|| (0..q1.len()).map(|i| 2.0 * q1[i] - q0[i]).collect())
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
        self.machine.info()
    }

    /// The machine rebuilt from its description with the constants set:
    /// its chains follow.
    fn with_constants(
        &self,
        overrides: &[(String, Real)],
    ) -> Result<Box<dyn MachineKinematics>, MachineError> {
        let info = overridden(self.machine.info(), overrides)?;
        Ok(Box::new(ChainMachine {
            machine: Machine::from_info(info)?,
            options: self.options,
        }))
    }

    fn inverse(
        &self,
        poses: &[Real],
        tool: &ToolFrame,
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError> {
        self.solve(poses, tool, &[], &[], out)
    }

    fn inverse_held(
        &self,
        poses: &[Real],
        tool: &ToolFrame,
        held: &[usize],
        values: &[Real],
        out: &mut Vec<Real>,
    ) -> Result<(), KinematicsError> {
        self.solve(poses, tool, held, values, out)
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
