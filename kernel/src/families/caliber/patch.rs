//! The contact patch at one block (docs/math.md §3.6): the groove's points within
//! a small distance of the wheel, what the seed reads off the CAD model.

use super::check::{groove_middle, placed, wheel_distance, GrooveRequest};
use super::groove::{Groove, GrooveError};
use super::pose::TorusWheel;
use crate::machine::MachineKinematics;
use crate::math::{Real, Vec3};
use crate::mesh::TriMesh;
use crate::program::AxisProgram;
use crate::replay::VerifyError;
use crate::tool::Wheel;
use crate::transform::ToolFrame;
use serde::{Deserialize, Serialize};

/// The region of the groove within a small distance of the wheel at one
/// block (docs/math.md §3.6: what the seed reads off the CAD model).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactPatch {
    /// The block (from 1).
    pub block: usize,
    /// The distance that counts as contact (mm).
    pub gap_mm: Real,
    /// Its size along the groove (mm, on the surface).
    pub along_mm: Real,
    /// Its size across the groove (mm, on the section).
    pub across_mm: Real,
    /// Its middle: theta (deg).
    pub theta_deg: Real,
    /// Its middle: psi (deg).
    pub psi_deg: Real,
    /// The deepest the wheel reaches into the nominal there (mm, <= 0 if
    /// it does).
    pub least_distance_mm: Real,
    /// Grid points in the patch.
    pub points: usize,
}

/// The contact patch at block `block` (from 0) of `program` (as written):
/// the groove points within `req.patch_gap` of the wheel on a fine grid of
/// `(theta, psi)` round the contact (widened until the patch is inside
/// it), its sizes along and across the groove, its middle, and its cells
/// as a mesh (lifted 1 um off the groove along its normal, to show over
/// it).
///
/// # Failures
/// The block beyond the program; the replay failing. `None`: no groove
/// point within the gap (the wheel does not touch the groove there).
pub fn contact_patch(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    wheel: &Wheel,
    req: &GrooveRequest,
    block: usize,
) -> Result<Option<(ContactPatch, TriMesh)>, VerifyError> {
    crate::math::positive("contact patch gap", req.patch_gap)?;
    let pose = crate::replay::replay_blocks(program, machine, tool, block..block + 1)?;
    let wheel = placed(&pose, wheel);
    let g = &req.groove;
    let (lo, hi) = g.theta_range();
    let best = nearest(g, &wheel)?;
    let (mut w_theta, mut w_psi) = (2f64.to_radians(), 10f64.to_radians());
    let edge = std::f64::consts::FRAC_PI_2;
    loop {
        let win = Window::round(g, &wheel, best, [w_theta, w_psi], req.patch_gap)?;
        let Some([i0, i1, j0, j1]) = win.bounds else {
            return Ok(None); // the wheel does not touch the groove here
        };
        let (ts, ps) = (&win.ts, &win.ps);
        let theta_edge = (i0 == 0 || i1 == N) && ts[0] > lo && ts[N] < hi;
        let psi_edge = (j0 == 0 && ps[0] > -edge) || (j1 == N && ps[N] < edge);
        if (theta_edge || psi_edge) && w_theta < 30f64.to_radians() {
            if theta_edge {
                w_theta *= 2.0;
            }
            if psi_edge {
                w_psi = (w_psi * 2.0).min(edge);
            }
            continue;
        }
        let (tm, pm) = (0.5 * (ts[i0] + ts[i1]), 0.5 * (ps[j0] + ps[j1]));
        // Sizes on the surface: along theta at the middle psi, across psi
        // at the middle theta.
        let arc = |pts: Vec<Vec3>| pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<Real>();
        let along: Vec<Vec3> = ts[i0..=i1]
            .iter()
            .map(|&t| g.point(t, pm))
            .collect::<Result<_, _>>()?;
        let across: Vec<Vec3> = ps[j0..=j1]
            .iter()
            .map(|&p| g.point(tm, p))
            .collect::<Result<_, _>>()?;
        let patch = ContactPatch {
            block: block + 1,
            gap_mm: req.patch_gap,
            along_mm: arc(along),
            across_mm: arc(across),
            theta_deg: tm.to_degrees(),
            psi_deg: pm.to_degrees(),
            least_distance_mm: win.least,
            points: win.inside.iter().filter(|&&b| b).count(),
        };
        return Ok(Some((patch, win.mesh(g)?)));
    }
}

/// The cells of a window's grid along each direction.
const N: usize = 200;

/// The groove point nearest the wheel near the wheel's turn, over the
/// whole section: (distance (mm), theta, psi (rad)), on a coarse grid
/// (0.2 deg along theta within 6 deg, 1 deg across).
fn nearest(g: &Groove, wheel: &TorusWheel) -> Result<(Real, Real, Real), GrooveError> {
    let (lo, hi) = g.theta_range();
    let mid = groove_middle(g);
    let turn = mid + crate::math::wrap_angle(wheel.centre.y.atan2(wheel.centre.x) - mid);
    let mut best = (Real::INFINITY, turn.clamp(lo, hi), 0.0);
    for i in 0..=60 {
        let t = (turn + (i as Real - 30.0) * 0.2f64.to_radians()).clamp(lo, hi);
        let section = g.section(t)?;
        for j in 0..=180 {
            let psi = (j as Real - 90.0).to_radians();
            let d = wheel_distance(wheel, &g.point_of(&section, t, psi));
            if d < best.0 {
                best = (d, t, psi);
            }
        }
    }
    Ok(best)
}

/// A window of the groove round a point, on an `N` x `N` grid, and the
/// grid points within the gap of the wheel.
struct Window {
    /// Theta of the grid's rows (rad).
    ts: Vec<Real>,
    /// Psi of the grid's columns (rad), within the section.
    ps: Vec<Real>,
    /// Whether each point, row by row, is within the gap.
    inside: Vec<bool>,
    /// The least distance from the wheel over the window (mm).
    least: Real,
    /// The rows and columns holding the points within the gap, `[first
    /// row, last row, first column, last column]`; `None` where there are
    /// none.
    bounds: Option<[usize; 4]>,
}

impl Window {
    /// The window `2 half[0]` along theta by `2 half[1]` across psi round
    /// `centre` (its distance, theta, psi), with the points within `gap`
    /// of `wheel`.
    fn round(
        g: &Groove,
        wheel: &TorusWheel,
        centre: (Real, Real, Real),
        half: [Real; 2],
        gap: Real,
    ) -> Result<Self, GrooveError> {
        let (lo, hi) = g.theta_range();
        let ts: Vec<Real> = (0..=N)
            .map(|i| (centre.1 - half[0] + 2.0 * half[0] * i as Real / N as Real).clamp(lo, hi))
            .collect();
        // Within the section: beyond psi = -+90 deg the ellipse runs on
        // out of the roll, where the wheel is.
        let edge = std::f64::consts::FRAC_PI_2;
        let ps: Vec<Real> = (0..=N)
            .map(|j| {
                (centre.2 - half[1] + 2.0 * half[1] * j as Real / N as Real).clamp(-edge, edge)
            })
            .collect();
        let mut inside = vec![false; (N + 1) * (N + 1)];
        let mut least = Real::INFINITY;
        let (mut i0, mut i1, mut j0, mut j1) = (N, 0, N, 0);
        for (i, &t) in ts.iter().enumerate() {
            let section = g.section(t)?;
            for (j, &p) in ps.iter().enumerate() {
                let d = wheel_distance(wheel, &g.point_of(&section, t, p));
                least = least.min(d);
                if d <= gap {
                    inside[i * (N + 1) + j] = true;
                    (i0, i1, j0, j1) = (i0.min(i), i1.max(i), j0.min(j), j1.max(j));
                }
            }
        }
        let bounds = (i0 <= i1).then_some([i0, i1, j0, j1]);
        Ok(Self {
            ts,
            ps,
            inside,
            least,
            bounds,
        })
    }

    /// The points within the gap as a mesh on the groove (its cells whose
    /// four corners are in), lifted a micron off the surface to be seen
    /// over it.
    fn mesh(&self, g: &Groove) -> Result<TriMesh, GrooveError> {
        let mut mesh = TriMesh::default();
        let Some([i0, i1, j0, j1]) = self.bounds else {
            return Ok(mesh);
        };
        let mut index = std::collections::BTreeMap::new();
        for i in i0..i1 {
            for j in j0..j1 {
                let cell = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                if !cell.iter().all(|&(a, b)| self.inside[a * (N + 1) + b]) {
                    continue;
                }
                let mut ids = [0u32; 4];
                for (c, &(a, b)) in cell.iter().enumerate() {
                    ids[c] = match index.get(&(a, b)) {
                        Some(&id) => id,
                        None => {
                            let n = g.normal(self.ts[a], self.ps[b])?;
                            let p = g.point(self.ts[a], self.ps[b])? + 0.001 * n;
                            mesh.positions.push([p.x, p.y, p.z]);
                            mesh.normals.push([n.x, n.y, n.z]);
                            let id = (mesh.positions.len() - 1) as u32;
                            index.insert((a, b), id);
                            id
                        }
                    };
                }
                mesh.triangles.push([ids[0], ids[2], ids[1]]);
                mesh.triangles.push([ids[0], ids[3], ids[2]]);
            }
        }
        Ok(mesh)
    }
}
