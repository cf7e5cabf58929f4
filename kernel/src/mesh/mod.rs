//! Triangle meshes of closed solids, scenes, and the files CAD systems read.
//!
//! Every tessellation takes a chordal tolerance (`tol`, mm; default
//! [`DEFAULT_TOLERANCE`]): no chord strays farther than `tol` from the
//! surface it approximates. Meshes are closed and consistently oriented
//! (normals outward): [`TriMesh::check_closed`] proves it for any mesh.
//!
//! - [`revolve`]: a closed section in the `(z, r)` half-plane turned about Z;
//!   [`body_of_revolution`] (a [`Profile`](crate::profile::Profile) with end caps),
//!   [`wheel`] (a disk with a torus periphery), [`cylinder`];
//! - [`sweep`]: a closed section carried along a path, its shape changing;
//! - [`Scene`]: named bodies with poses; STL ([`write_stl`]) and glTF
//!   ([`write_glb`], [`write_gltf`]) writers.

mod bodies;
mod gltf_writer;
mod revolve;
mod scene;
mod stl_writer;
mod sweep;

pub use bodies::body_mesh;
pub use gltf_writer::{write_glb, write_gltf};
pub use revolve::{body_of_revolution, cylinder, revolve, wheel};
pub use scene::{frame_from_pose, Motion, Node, Scene, Spin, MAX_SPIN_STEP};
pub use stl_writer::{read_stl, read_stl_bytes, write_stl, StlFormat};
pub use sweep::{sweep, sweep_hollow};

use crate::math::{Mat4, Real};
use std::collections::HashMap;

/// The most triangles a tessellation makes: 20 million (about 1 GB of
/// mesh); checked before the mesh is built.
pub const MAX_TRIANGLES: usize = 20_000_000;

/// An error unless `count` triangles are within [`MAX_TRIANGLES`].
pub(crate) fn check_triangles(count: usize, tol: Real) -> Result<(), MeshError> {
    if count > MAX_TRIANGLES {
        return Err(MeshError::Degenerate(format!(
            "the mesh would have {count} triangles at a chordal tolerance of {tol} mm, more than the ceiling {MAX_TRIANGLES}: give a coarser tolerance"
        )));
    }
    Ok(())
}

/// The default chordal tolerance of tessellations (mm).
pub const DEFAULT_TOLERANCE: Real = 0.01;

/// Errors of tessellation and mesh files.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// The run's time limit passed while this was being done.
    #[error(transparent)]
    OverTime(#[from] crate::budget::OverTime),
    /// A rejected number.
    #[error(transparent)]
    Input(#[from] crate::input::InputError),
    /// A section that does not close on itself.
    #[error("the section is open: its last point ({:.6}, {:.6}) does not return to its first ({:.6}, {:.6})", last[0], last[1], first[0], first[1])]
    Open {
        /// First point (z, r).
        first: [Real; 2],
        /// Last point (z, r).
        last: [Real; 2],
    },
    /// A section whose edges cross, or that crosses or touches the axis.
    #[error("the section intersects itself: {0}")]
    SelfIntersecting(String),
    /// A degenerate or unusable shape.
    #[error("{0}")]
    Degenerate(String),
    /// A mesh that is not a closed, oriented surface.
    #[error("the mesh is not closed: {0}")]
    NotClosed(String),
    /// A file could not be written or read.
    #[error("{file}: {message}")]
    Io {
        /// The file.
        file: String,
        /// What went wrong.
        message: String,
    },
}

/// An indexed triangle mesh; `f64` inside. Vertices carry normals for
/// shading; where shading creases, a vertex is repeated at the same
/// coordinates (so closedness is judged by coordinates, as STL readers do).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions (mm).
    pub positions: Vec<[Real; 3]>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<[Real; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

pub(crate) fn sub(a: [Real; 3], b: [Real; 3]) -> [Real; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: [Real; 3], b: [Real; 3]) -> [Real; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: [Real; 3], b: [Real; 3]) -> Real {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn normalize(a: [Real; 3]) -> [Real; 3] {
    let n = dot(a, a).sqrt();
    if n > 0.0 {
        [a[0] / n, a[1] / n, a[2] / n]
    } else {
        [0.0, 0.0, 1.0]
    }
}

impl TriMesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Bytes of the mesh data (positions and normals as f64, indices as u32).
    pub fn byte_size(&self) -> usize {
        self.positions.len() * 48 + self.triangles.len() * 12
    }

    /// The three corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [[Real; 3]; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// The unit normal of triangle `t` from its corners' winding.
    pub fn face_normal(&self, t: usize) -> [Real; 3] {
        let [a, b, c] = self.corners(t);
        normalize(cross(sub(b, a), sub(c, a)))
    }

    /// The enclosed volume (mm^3), by the divergence theorem: positive for a
    /// closed mesh with outward normals.
    pub fn volume(&self) -> Real {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                dot(a, cross(b, c))
            })
            .sum::<Real>()
            / 6.0
    }

    /// Smallest and largest coordinates.
    pub fn bounds(&self) -> ([Real; 3], [Real; 3]) {
        let mut lo = [Real::INFINITY; 3];
        let mut hi = [Real::NEG_INFINITY; 3];
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// Appends another mesh.
    pub fn append(&mut self, other: &TriMesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }

    /// The mesh moved by a rigid motion (positions and normals).
    pub fn transformed(&self, m: &Mat4) -> TriMesh {
        let p = |v: [Real; 3]| {
            let r = m * nalgebra::Vector4::new(v[0], v[1], v[2], 1.0);
            [r.x, r.y, r.z]
        };
        let n = |v: [Real; 3]| {
            let r = m * nalgebra::Vector4::new(v[0], v[1], v[2], 0.0);
            normalize([r.x, r.y, r.z])
        };
        TriMesh {
            positions: self.positions.iter().map(|v| p(*v)).collect(),
            normals: self.normals.iter().map(|v| n(*v)).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Proves the mesh bounds a solid: vertices welded by coordinates, every
    /// edge is shared by exactly two triangles running it in opposite
    /// directions, no triangle is degenerate, and the enclosed volume is
    /// positive (normals outward).
    ///
    /// # Failures
    /// [`MeshError::NotClosed`] naming the triangle or edge.
    pub fn check_closed(&self) -> Result<(), MeshError> {
        let mut weld: HashMap<[u64; 3], u32> = HashMap::with_capacity(self.positions.len());
        let ids: Vec<u32> = self
            .positions
            .iter()
            .map(|p| {
                let key = [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()];
                let next = weld.len() as u32;
                *weld.entry(key).or_insert(next)
            })
            .collect();
        let mut edges: HashMap<(u32, u32), i32> = HashMap::with_capacity(self.triangles.len() * 3);
        for (t, tri) in self.triangles.iter().enumerate() {
            let v = [
                ids[tri[0] as usize],
                ids[tri[1] as usize],
                ids[tri[2] as usize],
            ];
            let [a, b, c] = self.corners(t);
            let area2 = dot(cross(sub(b, a), sub(c, a)), cross(sub(b, a), sub(c, a))).sqrt();
            let scale = dot(sub(b, a), sub(b, a)).max(dot(sub(c, a), sub(c, a)));
            if v[0] == v[1]
                || v[1] == v[2]
                || v[0] == v[2]
                || !(area2 > crate::tolerance::ROUNDING * scale)
            {
                return Err(MeshError::NotClosed(format!("triangle {t} is degenerate")));
            }
            for k in 0..3 {
                let (p, q) = (v[k], v[(k + 1) % 3]);
                // +1 for p->q, -1 for q->p, keyed by the unordered pair;
                // a second use in the same direction is a fault.
                let (key, dir) = if p < q { ((p, q), 1) } else { ((q, p), -1) };
                let e = edges.entry(key).or_insert(0);
                if *e == dir || *e == 2 {
                    return Err(MeshError::NotClosed(format!(
                        "edge {p}-{q} (triangle {t}) is used twice in one direction or by more than two triangles"
                    )));
                }
                *e = if *e == 0 { dir } else { 2 };
            }
        }
        if let Some(((p, q), _)) = edges.iter().find(|(_, v)| **v != 2) {
            return Err(MeshError::NotClosed(format!(
                "edge {p}-{q} has only one triangle (a hole)"
            )));
        }
        let v = self.volume();
        if !(v > 0.0) {
            return Err(MeshError::NotClosed(format!(
                "the enclosed volume is {v}: normals point inward"
            )));
        }
        Ok(())
    }
}

/// Checks a chordal tolerance.
pub(crate) fn check_tol(tol: Real) -> Result<Real, MeshError> {
    Ok(crate::math::positive("chordal tolerance", tol)?)
}

/// Segments of an arc of radius `r` and angle `angle` keeping chords within `tol`.
pub(crate) fn arc_segments(
    r: Real,
    angle: Real,
    tol: Real,
    min: usize,
) -> Result<usize, MeshError> {
    let step = if tol >= r {
        std::f64::consts::PI
    } else {
        2.0 * (1.0 - tol / r).acos()
    };
    let n = (angle.abs() / step).ceil();
    if !(n <= 2e6) {
        return Err(MeshError::Degenerate(format!(
            "a chordal tolerance of {tol} mm on a radius of {r} mm needs {n:e} segments"
        )));
    }
    Ok((n as usize).max(min))
}

/// Why the scene could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// A body's mesh failed.
    #[error("{body}: {source}")]
    Mesh {
        /// The body.
        body: String,
        /// The mesh's error.
        source: MeshError,
    },
    /// Placing a body failed (a block beyond the program, a chain).
    #[error("{0}")]
    Place(String),
}
