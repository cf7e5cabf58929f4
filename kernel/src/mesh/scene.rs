//! Scenes: named bodies, each a mesh and a pose.

use super::TriMesh;
use crate::math::{Mat3, Mat4, Point3, Vec3};
use crate::transform::ToolFrame;

/// One body of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// Its name (a glTF node and mesh name, a file name).
    pub name: String,
    /// Its mesh in its own frame (mm).
    pub mesh: TriMesh,
    /// Where its frame stands in the part frame.
    pub pose: Mat4,
    /// Its colour (linear RGBA).
    pub color: [f32; 4],
}

/// How a scene's bodies move: each named body's pose at key times, played
/// as one glTF animation (linear between keys).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Motion {
    /// The animation's name.
    pub name: String,
    /// The key times (s from the start), increasing.
    pub times: Vec<f32>,
    /// What each key stands for, for people (the program's block, from
    /// 0, whose end it is).
    pub keys: Vec<usize>,
    /// For each moving body (by its node's name), its pose at each key.
    pub tracks: Vec<(String, Vec<Mat4>)>,
    /// The part's turn about its axis, on its own keys.
    pub spin: Option<Spin>,
}

/// Bodies turning together about the part's axis (Z) on keys of their own
/// (a spindle turns many times between the motion's keys): played as one
/// group node of the scene, turned right-handed by the angle.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Spin {
    /// The bodies that turn (by their nodes' names): the part and what is
    /// fixed to it.
    pub members: Vec<String>,
    /// The key times (s from the start), increasing.
    pub times: Vec<f32>,
    /// The angle at each key (rad), each within [`MAX_SPIN_STEP`] of the
    /// one before, so that the player turns the way the part turns.
    pub angles: Vec<f64>,
}

/// The most a spin turns between two keys (a third of a turn): well below
/// the half turn at which a player's interpolation would turn it the other
/// way.
pub const MAX_SPIN_STEP: f64 = std::f64::consts::TAU / 3.0;

/// Named bodies with poses, in the part frame (mm, Z up), and how they
/// move, if they do.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    /// The bodies, in order.
    pub nodes: Vec<Node>,
    /// Their motion along the program.
    pub motion: Option<Motion>,
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a body.
    pub fn add(&mut self, name: &str, mesh: TriMesh, pose: Mat4, color: [f32; 4]) -> &mut Self {
        self.nodes.push(Node {
            name: name.to_owned(),
            mesh,
            pose,
            color,
        });
        self
    }

    /// Total triangles.
    pub fn triangle_count(&self) -> usize {
        self.nodes.iter().map(|n| n.mesh.triangle_count()).sum()
    }
}

/// The rigid motion placing a tool that is symmetric about its axis (a
/// wheel, an end mill) at a pose: its reference point on `point`, its axis
/// along `axis` (the smallest turn from the tool frame's axis). For such a
/// tool the turn about its own axis does not change the solid, so a pose
/// (point and axis) fixes the placement.
pub fn frame_from_pose(tool: &ToolFrame, point: Point3, axis: Vec3) -> Mat4 {
    let a = tool.axis.normalize();
    let b = axis.normalize();
    let c = a.dot(&b);
    let rot: Mat3 = if c > 1.0 - crate::tolerance::ULP {
        Mat3::identity()
    } else if c < -1.0 + crate::tolerance::ULP {
        // Half a turn about any axis perpendicular to a.
        let p = if a.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        let u = a.cross(&p).normalize();
        Mat3::identity() * -1.0 + u * u.transpose() * 2.0
    } else {
        let v = a.cross(&b);
        let k = v.cross_matrix();
        Mat3::identity() + k + k * k * (1.0 / (1.0 + c))
    };
    let t = point.coords - rot * tool.point.coords;
    let mut m = Mat4::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&rot);
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&t);
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_places_reference_point_and_axis() {
        let tool = ToolFrame {
            point: Point3::new(20.0, 0.0, 1.0),
            axis: Vec3::z(),
        };
        for axis in [Vec3::z(), -Vec3::z(), Vec3::new(0.3, -0.2, 0.9), Vec3::x()] {
            let m = frame_from_pose(&tool, Point3::new(5.0, 6.0, 7.0), axis);
            let p = m * tool.point.to_homogeneous();
            assert!((p.xyz() - Vec3::new(5.0, 6.0, 7.0)).norm() < 1e-12);
            let w = m * tool.axis.to_homogeneous();
            assert!((w.xyz() - axis.normalize()).norm() < 1e-12);
            let r = m.fixed_view::<3, 3>(0, 0).into_owned();
            assert!((r.transpose() * r - Mat3::identity()).norm() < 1e-12);
            assert!((r.determinant() - 1.0).abs() < 1e-12);
        }
    }
}
