//! The 3K152VF20 mandrel grinder (seed 000, MATH §2.3) as a pilgrim machine
//! plugin: table Z, wheelhead X, CNC steady rest U, work spindle; a
//! Sinumerik 840D control.
//!
//! The kinematics are closed-form: the wheel moves in the part's axial
//! section with its axis parallel to the part's, so `X = x - r_x` and
//! `Z = z - r_z` for a tracked point `(x, 0, z)` and the tool's reference
//! `r`. The axes, travel and signs are those of the kernel's built-in
//! machine file `3k152vf20.toml`. The steady rest's U comes with the
//! toolpath (an auxiliary value the part family computes on the current
//! surface).
//!
//! Built as an rlib it is compiled into the `pilgrim` program; built as a
//! cdylib it is `libgrinder_3k152vf20.so`, exporting
//! `pilgrim_plugin_grinder_3k152vf20`.

use pilgrim_kernel::program::{batch_rows, KinematicsError, MachineInfo, MachineKinematics};
use pilgrim_kernel::{AxisProgram, Machine, ToolFrame};
use pilgrim_plugin_abi::{export_plugin, Plugin, PluginError};

/// How far off the axial section (y) or off the part's axis direction a
/// pose may be and still be the grinder's.
const POSE_TOL: f64 = 1e-9;

/// The 3K152VF20.
#[derive(Debug, Clone)]
pub struct Grinder {
    info: MachineInfo,
}

impl Default for Grinder {
    fn default() -> Self {
        let machine =
            Machine::builtin("3K152VF20").expect("the built-in 3K152VF20 machine file is valid");
        Self {
            info: MachineInfo::of(&machine),
        }
    }
}

impl Grinder {
    /// The grinder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Inverse kinematics into `out` (two values per pose), the one code
    /// path of the compiled-in machine and of the shared library.
    fn solve_into(
        &self,
        poses: &[f64],
        tool: &ToolFrame,
        out: &mut [f64],
    ) -> Result<(), KinematicsError> {
        let (r, w) = (tool.point, tool.axis);
        for (i, (p, q)) in poses
            .chunks_exact(6)
            .zip(out.chunks_exact_mut(2))
            .enumerate()
        {
            if (p[1] - r.y).abs() > POSE_TOL {
                return Err(KinematicsError::at(
                    i,
                    format!(
                        "the point is {:.6} mm off the wheel's plane (y must be {})",
                        p[1] - r.y,
                        r.y
                    ),
                ));
            }
            let tilt = ((p[3] - w.x).powi(2) + (p[4] - w.y).powi(2) + (p[5] - w.z).powi(2)).sqrt();
            if tilt > POSE_TOL {
                return Err(KinematicsError::at(
                    i,
                    format!(
                        "the wheel's axis ({:.6}, {:.6}, {:.6}) must stay parallel to the part's ({}, {}, {})",
                        p[3], p[4], p[5], w.x, w.y, w.z
                    ),
                ));
            }
            q[0] = p[2] - r.z;
            q[1] = p[0] - r.x;
        }
        Ok(())
    }
}

impl MachineKinematics for Grinder {
    fn info(&self) -> &MachineInfo {
        &self.info
    }

    /// Rows of `[Z, X]` (the solved axes' order).
    fn inverse(
        &self,
        poses: &[f64],
        tool: &ToolFrame,
        out: &mut Vec<f64>,
    ) -> Result<(), KinematicsError> {
        batch_rows(poses, 6, "pose")?;
        out.clear();
        out.resize(poses.len() / 3, 0.0);
        self.solve_into(poses, tool, out)
    }

    fn forward(
        &self,
        axes: &[f64],
        tool: &ToolFrame,
        out: &mut Vec<f64>,
    ) -> Result<(), KinematicsError> {
        batch_rows(axes, 2, "axis")?;
        out.clear();
        let (r, w) = (tool.point, tool.axis);
        for q in axes.chunks_exact(2) {
            out.extend_from_slice(&[q[1] + r.x, r.y, q[0] + r.z, w.x, w.y, w.z]);
        }
        Ok(())
    }
}

fn tool_frame(t: &[f64; 6]) -> ToolFrame {
    ToolFrame {
        point: pilgrim_kernel::Point3::new(t[0], t[1], t[2]),
        axis: pilgrim_kernel::Vec3::new(t[3], t[4], t[5]),
    }
}

fn from_kinematics(e: KinematicsError) -> PluginError {
    PluginError {
        row: e.index,
        message: e.message,
    }
}

/// A post request: `{"dialect": "...", "program": {...}}`.
#[derive(serde::Deserialize)]
struct PostRequest {
    dialect: String,
    program: AxisProgram,
}

impl Plugin for Grinder {
    fn describe(&self) -> String {
        serde_json::to_string(&self.info).unwrap_or_default()
    }

    fn solved_axis_count(&self) -> usize {
        self.info.solved_axes.len()
    }

    fn inverse(&self, poses: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        self.solve_into(poses, &tool_frame(tool), out)
            .map_err(from_kinematics)
    }

    fn forward(&self, axes: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        let mut v = Vec::with_capacity(out.len());
        MachineKinematics::forward(self, axes, &tool_frame(tool), &mut v)
            .map_err(from_kinematics)?;
        out.copy_from_slice(&v);
        Ok(())
    }

    fn post(&self, request: &str) -> Result<String, PluginError> {
        let req: PostRequest = serde_json::from_str(request)
            .map_err(|e| PluginError::new(format!("bad post request: {e}")))?;
        MachineKinematics::post(self, &req.program, &req.dialect)
            .map_err(|e| PluginError::new(e.to_string()))
    }
}

export_plugin!(pilgrim_plugin_grinder_3k152vf20, Grinder);

#[cfg(test)]
mod tests {
    use super::*;
    use pilgrim_kernel::{ChainMachine, Point3, Vec3};

    /// The closed form agrees with the machine file's chain solved numerically.
    #[test]
    fn closed_form_matches_the_chain() {
        let g = Grinder::new();
        let chain = ChainMachine::new(Machine::builtin("3K152VF20").unwrap());
        let tool = ToolFrame {
            point: Point3::new(20.0, 0.0, 3.0),
            axis: Vec3::z(),
        };
        let poses: Vec<f64> = (0..50)
            .flat_map(|i| [25.0 + 0.1 * i as f64, 0.0, 10.0 * i as f64, 0.0, 0.0, 1.0])
            .collect();
        let (mut a, mut b) = (vec![], vec![]);
        MachineKinematics::inverse(&g, &poses, &tool, &mut a).unwrap();
        chain.inverse(&poses, &tool, &mut b).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-7, "{x} vs {y}");
        }
        let mut back = vec![];
        MachineKinematics::forward(&g, &a, &tool, &mut back).unwrap();
        for (x, y) in back.iter().zip(&poses) {
            assert!((x - y).abs() < 1e-12);
        }
        let mut bad = poses.clone();
        bad[6 * 7 + 1] = 0.5;
        let e = MachineKinematics::inverse(&g, &bad, &tool, &mut a).unwrap_err();
        assert_eq!(e.index, Some(7));
        assert!(e.message.contains("off the wheel's plane"), "{e}");
    }
}
