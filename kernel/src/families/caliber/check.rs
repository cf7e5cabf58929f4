//! The caliber program replayed in 3-D: the torus swept along the moves
//! the machine makes, measured against the groove's surface over a grid of
//! `(theta, psi)` (the contact patch at one block is in `patch.rs`).
//!
//! The replay reads the program as written ([`crate::replay::as_written`]),
//! moves every solved axis in a straight line between blocks as the
//! control interpolates, and places the wheel by the machine's forward
//! kinematics at sub-steps of each move, as many as keep the sampling
//! error below a stated resolution: between two samples no point of the
//! wheel moves more than `s`, and a distance that is smallest between
//! samples is missed by at most `s^2 / (8 r_k)` (the distance to the
//! rounding curves at `1 / r_k` along the motion), reported as
//! [`GrooveCheck::sampling_resolution_mm`].
//!
//! At each grid point the figure is the signed distance from the nominal
//! groove to the nearest wheel surface over the samples of the passes
//! around it (positive: material left, the scallops between passes and
//! between blocks; negative: a gouge), the passes within
//! [`NEIGHBOUR_PASSES`] of it across the groove. Every block's wheel is
//! also measured across the whole section at its own theta, so that a
//! wheel cutting the groove away from its contact (across it) is seen.
//!
//! The grid covers the whole section, edge to edge (psi from -90 to 90
//! deg, where the groove meets the roll's periphery), whatever the passes
//! cover: beyond the outermost passes it runs on at the same spacing,
//! measured against them. Beside each edge the periphery is measured too,
//! a strip [`PERIPHERY_REACH`] rounding radii wide, for cuts only (it is
//! turned, not ground): a wheel whose side reaches past the edge cuts it.

use super::grid::Grid;
use super::groove::Groove;
use super::patch::ContactPatch;
use super::pose::TorusWheel;
use crate::budget::OverTime;
use crate::machine::MachineKinematics;
use crate::math::{Real, Vec3};
use crate::program::{axis_rows, AxisProgram, ProgramPass};
use crate::replay::{as_written, VerifyError};
use crate::tool::Wheel;
use crate::transform::ToolFrame;
use crate::verdict::{Figure, Finding};
use serde::{Deserialize, Serialize};

/// How many passes either side of a grid point (across the groove) its
/// distance is measured against along the whole groove.
pub const NEIGHBOUR_PASSES: usize = 2;

/// The sampling resolution is the tolerance over this: what the sampling
/// of the moves may miss is a tenth of what the groove may deviate.
pub const SAMPLING_SHARE: Real = 10.0;

/// The most grid points a verification may measure.
pub const MAX_GRID_POINTS: usize = 20_000_000;

/// The most wheel samples a replay may place.
pub const MAX_SAMPLES: usize = 20_000_000;

/// The coarsest step of the grid across the groove beyond the outermost
/// passes (rad): 1 deg, when there is one pass and no spacing to follow.
pub(super) const EDGE_GRID_STEP: Real = std::f64::consts::PI / 180.0;

/// How far the periphery strip beside each edge runs, in rounding radii:
/// the rounding, touching the edge, reaches no farther along the axis.
pub const PERIPHERY_REACH: Real = 1.0;

/// From how far from the groove's bottom (deg of psi, either side) a place
/// is by the edge, for the failure's explanation.
const BY_THE_EDGE_DEG: Real = 80.0;

/// What a caliber job asks the replay to hold.
#[derive(Debug, Clone, PartialEq)]
pub struct GrooveRequest {
    /// The nominal groove.
    pub groove: Groove,
    /// The pass angle psi (rad) of each cutting pass, in order.
    pub psi: Vec<Real>,
    /// The deviation the finished groove must hold (mm).
    pub tolerance: Real,
    /// The grid's step along theta (rad).
    pub grid_theta: Real,
    /// Grid points across the groove per pass step (>= 1).
    pub grid_per_step: usize,
    /// The distance from the wheel within which the groove is the contact
    /// patch (mm).
    pub patch_gap: Real,
    /// The groove's grinding allowance (mm): before it is ground, its
    /// surface stands this much into its open space everywhere. `None`:
    /// the family does not say, and the process's rules that need the
    /// material are not checked.
    pub stock: Option<Real>,
}

/// A place on the groove with the block whose wheel made the figure there.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GroovePlace {
    /// The figure (mm).
    pub mm: Real,
    /// Theta (deg).
    pub theta_deg: Real,
    /// Psi (deg).
    pub psi_deg: Real,
    /// The block, as the program names it.
    pub block: String,
    /// The block (from 1, the program's and `report.csv`'s count).
    #[serde(default)]
    pub block_index: usize,
    /// On the periphery beside the groove: how far beyond the edge at
    /// `psi_deg` (-90 or 90) along the roll's axis (mm); 0 on the groove.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub beyond_edge_mm: Real,
}

fn is_zero(x: &Real) -> bool {
    *x == 0.0
}

impl GroovePlace {
    /// Its block from 0 (the page's count), where it is at one.
    pub fn block_from_0(&self) -> Option<usize> {
        self.block_index.checked_sub(1)
    }
}

/// The replayed caliber program against the nominal groove.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GrooveCheck {
    /// The tolerance held (mm).
    pub tolerance: Real,
    /// The program's smallest step (mm), which the replay reads it at.
    pub resolution_mm: Real,
    /// The most the sampling of the moves may miss (mm).
    pub sampling_resolution_mm: Real,
    /// Wheel positions replayed (blocks and sub-steps).
    pub samples: usize,
    /// Grid points along theta.
    pub grid_theta: usize,
    /// Grid points across the groove.
    pub grid_psi: usize,
    /// The grid's step along theta (deg).
    pub grid_theta_step_deg: Real,
    /// The psi range measured (deg): the whole section, edge to edge.
    pub psi_range_deg: [Real; 2],
    /// The outermost passes' psi (deg).
    #[serde(default)]
    pub pass_range_deg: [Real; 2],
    /// The most material left (mm, >= 0) and where.
    pub max_left: GroovePlace,
    /// The deepest gouge (mm, <= 0; 0 if none) and where.
    pub max_gouge: GroovePlace,
    /// The larger of the two in size (mm).
    pub max_abs_mm: Real,
    /// The deepest cut into the roll's periphery beside the groove (mm,
    /// <= 0; 0 if none) and where.
    #[serde(default)]
    pub periphery_cut: GroovePlace,
    /// Why the worst place strays, where the check can tell, and what to
    /// change (empty if it cannot or nothing strays).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub why: String,
    /// The contact patch at the scene's block (set by the job).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patch: Option<ContactPatch>,
    /// The distances over the grid, in cells that keep their extremes
    /// (for the heat map; not in the report).
    #[serde(skip)]
    pub map: DeviationMap,
    /// The groove as cut at each theta of the grid, as a measurement takes
    /// it: `[theta (deg), depth, width]`, the depth's and the width's
    /// deviations from the nominal (mm): the depth less the material left
    /// at the bottom (psi 0, between its grid points), the width less the
    /// material left at both edges (psi -90 and 90 deg, where the section's
    /// normal runs along the roll's axis). Not in the report.
    #[serde(skip)]
    pub along_theta: Vec<[Real; 3]>,
}

/// The most cells a [`DeviationMap`] has along theta and across the groove.
pub const MAP_CELLS: (usize, usize) = (240, 60);

/// Distances from the groove to the swept wheel (mm, + material left, -
/// gouge) over a grid of theta and psi, each cell the grid points' value of
/// largest size.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DeviationMap {
    /// The cells' edges along theta (deg), one more than the cells.
    pub theta_deg: Vec<Real>,
    /// The cells' edges across the groove (deg), one more than the cells.
    pub psi_deg: Vec<Real>,
    /// The cells' values, row by row of theta.
    pub mm: Vec<Real>,
}

impl DeviationMap {
    /// The map of `values` (row by row of `thetas`, a value per `psis`)
    /// in at most [`MAP_CELLS`] cells.
    fn of(thetas: &[Real], psis: &[Real], values: &[Real]) -> Self {
        let cells = |n: usize, max: usize| n.clamp(1, max);
        let (nt, np) = (
            cells(thetas.len(), MAP_CELLS.0),
            cells(psis.len(), MAP_CELLS.1),
        );
        let bucket = |i: usize, n: usize, of: usize| (i * of / n.max(1)).min(of - 1);
        let mut mm: Vec<Real> = vec![0.0; nt * np];
        let mut seen = vec![false; nt * np];
        for (i, _) in thetas.iter().enumerate() {
            for (j, _) in psis.iter().enumerate() {
                let v = values[i * psis.len() + j];
                let c = bucket(i, thetas.len(), nt) * np + bucket(j, psis.len(), np);
                if !seen[c] || v.abs() > mm[c].abs() {
                    mm[c] = v;
                    seen[c] = true;
                }
            }
        }
        // Edges halfway between the grid points that start each cell.
        let edges = |xs: &[Real], n: usize| -> Vec<Real> {
            let first = |k: usize| (k * xs.len()).div_ceil(n).min(xs.len() - 1);
            let mut e = vec![xs[0]];
            for k in 1..n {
                let i = first(k);
                e.push(0.5 * (xs[i - 1] + xs[i]));
            }
            e.push(xs[xs.len() - 1]);
            e.iter().map(|r| r.to_degrees()).collect()
        };
        Self {
            theta_deg: edges(thetas, nt),
            psi_deg: edges(psis, np),
            mm,
        }
    }
}

/// The signed distance from `q` to the wheel `w` (a torus with the disc
/// inside its centre circle: the wheel's body, rounded across its width).
#[inline]
pub fn wheel_distance(w: &TorusWheel, q: &Vec3) -> Real {
    let v = q - w.centre;
    let h = v.dot(&w.axis);
    let rho = (v - h * w.axis).norm();
    if rho <= w.major {
        h.abs() - w.minor
    } else {
        let r = rho - w.major;
        (r * r + h * h).sqrt() - w.minor
    }
}

/// The wheel (a full-radius wheel: a torus of its diameter and rounding)
/// at a replayed pose, a row of 6 (centre, axis).
pub(super) fn placed(pose: &[Real], wheel: &Wheel) -> TorusWheel {
    TorusWheel {
        centre: Vec3::new(pose[0], pose[1], pose[2]),
        axis: Vec3::new(pose[3], pose[4], pose[5]).normalize(),
        major: wheel.centre_radius(),
        minor: wheel.rounding_radius,
    }
}

/// The middle of the groove's range of theta (rad): angles about the
/// roll's axis are taken within half a turn of it.
pub(super) fn groove_middle(g: &Groove) -> Real {
    let (lo, hi) = g.theta_range();
    0.5 * (lo + hi)
}

/// One replayed wheel position.
#[derive(Debug, Clone, Copy)]
struct Sample {
    wheel: TorusWheel,
    /// The block (from 0) whose move it is on.
    block: usize,
    /// The wheel centre's angle about the roll's axis (rad).
    turn: Real,
}

/// The wheel at every sub-step of every move of the cutting passes,
/// grouped by pass and sorted by turn, with the sampling resolution.
fn samples(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    wheel: &Wheel,
    passes: &[ProgramPass],
    req: &GrooveRequest,
) -> Result<(Vec<Vec<Sample>>, Real, usize), VerifyError> {
    let info = machine.info();
    let n = program.blocks.len();
    let rows = axis_rows(program, info, &info.solved_axes, 0..n)
        .map_err(|e| VerifyError::Replay(e.to_string()))?;
    let poses = crate::replay::replay(program, machine, tool)?;
    // Between samples no point of the wheel moves more than `step`.
    let target = req.tolerance / SAMPLING_SHARE;
    let mut sub = Substeps {
        wheel,
        poses: &poses,
        rows: &rows,
        width: info.solved_axes.len(),
        step: (8.0 * wheel.rounding_radius * target).sqrt(),
        worst: 0.0,
        count: 0,
    };
    // A pass's samples are ordered on a second thread while this one
    // replays the next pass (the machine's kinematics stay on this one).
    let mid = groove_middle(&req.groove);
    let out = std::thread::scope(|s| {
        let (send, receive) = std::sync::mpsc::channel::<(Vec<Real>, Vec<usize>)>();
        let lists = s.spawn(move || {
            receive
                .into_iter()
                .map(|(p, o)| ordered(p, o, wheel, mid))
                .collect::<Vec<_>>()
        });
        let replayed = (|| {
            for blocks in passes.iter().filter(|p| p.cuts).map(|p| p.blocks.clone()) {
                crate::budget::check("the groove's replay")?;
                let (rows_sub, owner) = sub.of_pass(blocks.clone())?;
                let sub_poses =
                    crate::replay::forward_rows(machine, &rows_sub, tool, blocks.clone())?;
                // A send fails only where the second thread panicked, and
                // its join passes that on.
                let _ = send.send((sub_poses, owner));
            }
            Ok::<(), VerifyError>(())
        })();
        drop(send);
        let lists = lists
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        replayed.map(|()| lists)
    })?;
    let r_k = wheel.rounding_radius;
    Ok((out, sub.worst * sub.worst / (8.0 * r_k), sub.count))
}

/// The sub-steps of the cutting moves: each move cut so that no point of
/// the wheel moves more than `step` between two of them.
struct Substeps<'a> {
    wheel: &'a Wheel,
    /// The replayed poses, 6 per block.
    poses: &'a [Real],
    /// The solved axes' values, `width` per block.
    rows: &'a [Real],
    width: usize,
    step: Real,
    /// The largest motion of a wheel point between two sub-steps (mm).
    worst: Real,
    /// The sub-steps so far, bounded by [`MAX_SAMPLES`].
    count: usize,
}

impl Substeps<'_> {
    /// The axes' values at every sub-step of the moves of `blocks`, and
    /// the block (from 0) each is on.
    fn of_pass(
        &mut self,
        blocks: std::ops::Range<usize>,
    ) -> Result<(Vec<Real>, Vec<usize>), VerifyError> {
        let (w, at) = (self.width, |pose: &[Real]| placed(pose, self.wheel));
        let r_k0 = 0.5 * self.wheel.diameter;
        let mut rows_sub: Vec<Real> = Vec::new();
        let mut owner = Vec::new();
        for k in blocks.start.max(1)..blocks.end {
            let a = at(&self.poses[6 * (k - 1)..6 * k]);
            let b = at(&self.poses[6 * k..6 * k + 6]);
            let turned = a.axis.dot(&b.axis).clamp(-1.0, 1.0).acos();
            let moved = (b.centre - a.centre).norm() + r_k0 * turned;
            let subs = ((moved / self.step).ceil() as usize).max(1);
            self.worst = self.worst.max(moved / subs as Real);
            self.count += subs;
            if self.count > MAX_SAMPLES {
                return Err(VerifyError::Replay(format!(
                    "more than {MAX_SAMPLES} wheel positions to replay: a coarser tolerance or fewer blocks"
                )));
            }
            let (ra, rb) = (
                &self.rows[(k - 1) * w..k * w],
                &self.rows[k * w..(k + 1) * w],
            );
            for s in 1..=subs {
                let t = s as Real / subs as Real;
                rows_sub.extend(ra.iter().zip(rb).map(|(x, y)| x + (y - x) * t));
                owner.push(k);
            }
        }
        Ok((rows_sub, owner))
    }
}

/// A pass's wheel positions from its poses (6 per sub-step, `owner` the
/// block of each), their turns unwrapped from the first (taken within half
/// a turn of the groove's middle `mid`), then in order of turn.
fn ordered(sub_poses: Vec<Real>, owner: Vec<usize>, wheel: &Wheel, mid: Real) -> Vec<Sample> {
    let mut list: Vec<Sample> = sub_poses
        .chunks_exact(6)
        .zip(owner)
        .map(|(p, block)| Sample {
            wheel: placed(p, wheel),
            block,
            turn: p[1].atan2(p[0]),
        })
        .collect();
    let mut prev = list
        .first()
        .map_or(0.0, |s| mid + crate::math::wrap_angle(s.turn - mid));
    for s in &mut list {
        s.turn = prev + crate::math::wrap_angle(s.turn - prev);
        prev = s.turn;
    }
    list.sort_by(|a, b| a.turn.total_cmp(&b.turn));
    list
}

/// The least distance from `q` over `list` (sorted by turn), searched
/// from the sample nearest `theta` downhill: the distance along a pass is
/// smooth and has one minimum near the contact.
fn nearest(list: &[Sample], q: &Vec3, theta: Real) -> (Real, usize) {
    if list.is_empty() {
        return (Real::INFINITY, 0);
    }
    let mut i = list.partition_point(|s| s.turn < theta).min(list.len() - 1);
    let d = |i: usize| wheel_distance(&list[i].wheel, q);
    let mut best = d(i);
    for stride in [64usize, 8, 1] {
        loop {
            let mut moved = false;
            for j in [i.checked_sub(stride), Some(i + stride)]
                .into_iter()
                .flatten()
            {
                if j < list.len() {
                    let v = d(j);
                    if v < best {
                        (best, i, moved) = (v, j, true);
                        break;
                    }
                }
            }
            if !moved {
                break;
            }
        }
    }
    (best, list[i].block)
}

/// Replays `program` on `machine` (the tool tracked at `tool`, a
/// full-radius `wheel`: the toolpath's own) and measures the groove of `req` against the swept wheel; `passes` are the
/// toolpath's, `req.psi` one per cutting pass. The check's `patch` is
/// left for the caller ([`crate::families::caliber::contact_patch`], at the block it shows).
///
/// # Failures
/// A tolerance finer than twice the program's resolution; the replay
/// failing; too large a grid. The finished groove straying more than the
/// tolerance is the check's own finding ([`GrooveCheck::failure`], naming
/// the block, theta and psi).
pub fn check_groove(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    wheel: &Wheel,
    passes: &[ProgramPass],
    req: &GrooveRequest,
) -> Result<GrooveCheck, VerifyError> {
    crate::math::positive("verification tolerance", req.tolerance)?;
    crate::math::positive("verification grid step along theta", req.grid_theta)?;
    let (written, resolution) = as_written(program);
    if req.tolerance < 2.0 * resolution {
        return Err(VerifyError::Resolution {
            tolerance: req.tolerance,
            resolution,
        });
    }
    let (lists, sampling, count) = samples(&written, machine, tool, wheel, passes, req)?;
    if lists.len() != req.psi.len() || lists.is_empty() {
        return Err(VerifyError::Replay(format!(
            "{} cutting passes for {} pass angles",
            lists.len(),
            req.psi.len()
        )));
    }
    let grid = Grid::new(req, wheel)?;
    let points = grid.points(&req.groove)?;
    let dist = measured(&grid, &points, &lists, req.grid_theta)?;
    let (max_left, max_gouge, periphery_cut) = extremes(&grid, &dist, program);
    let max_abs = max_left.mm.max(-max_gouge.mm);
    let worst = if max_left.mm >= -max_gouge.mm {
        &max_left
    } else {
        &max_gouge
    };
    let why = if max_abs > req.tolerance {
        explain(&req.groove, worst, grid.pass_range)?
    } else {
        String::new()
    };
    let (np, nc) = (grid.np(), grid.nc());
    Ok(GrooveCheck {
        along_theta: along_theta(&grid, &dist),
        tolerance: req.tolerance,
        resolution_mm: resolution,
        sampling_resolution_mm: sampling,
        samples: count,
        grid_theta: grid.thetas.len(),
        grid_psi: np,
        grid_theta_step_deg: req.grid_theta.to_degrees(),
        psi_range_deg: [grid.psi[0].0.to_degrees(), grid.psi[np - 1].0.to_degrees()],
        pass_range_deg: grid.pass_range.map(Real::to_degrees),
        max_left,
        max_gouge,
        max_abs_mm: max_abs,
        periphery_cut,
        why,
        patch: None,
        map: DeviationMap::of(
            &grid.thetas,
            &grid.psi.iter().map(|p| p.0).collect::<Vec<_>>(),
            &dist
                .chunks_exact(nc)
                .flat_map(|row| row[..np].iter().map(|d| d.0))
                .collect::<Vec<_>>(),
        ),
    })
}

/// The distance from each of the grid's `points` to the swept wheel, and
/// the block (from 0) whose wheel is nearest: against the passes around
/// the point, then every block's wheel across the whole section at its own
/// theta (`step` the grid's along theta); two threads share the rows.
fn measured(
    grid: &Grid,
    points: &[Vec3],
    lists: &[Vec<Sample>],
    step: Real,
) -> Result<Vec<(Real, usize)>, OverTime> {
    let n_theta = grid.thetas.len();
    let half = n_theta / 2;
    let near = |rows| near_passes(grid, points, lists, rows);
    let (a, b) = crate::budget::beside(|| near(0..half), || near(half..n_theta));
    let mut dist = a?;
    dist.extend(b?);
    let (first, second) = dist.split_at_mut(half * grid.nc());
    let across = |rows, dist: &mut [(Real, usize)]| across(grid, points, lists, step, rows, dist);
    let (a, b) = crate::budget::beside(|| across(0..half, first), || across(half..n_theta, second));
    a.and(b)?;
    Ok(dist)
}

/// The distance and block at the grid's points in `rows`, each against
/// the passes within [`NEIGHBOUR_PASSES`] of its own.
fn near_passes(
    grid: &Grid,
    points: &[Vec3],
    lists: &[Vec<Sample>],
    rows: std::ops::Range<usize>,
) -> Result<Vec<(Real, usize)>, OverTime> {
    let (nc, order) = (grid.nc(), &grid.order);
    let mut out = Vec::with_capacity(rows.len() * nc);
    for i in rows {
        crate::budget::check("the groove's measurement")?;
        for j in 0..nc {
            let k = grid.pass_of(j);
            let q = &points[i * nc + j];
            let from = k.saturating_sub(NEIGHBOUR_PASSES);
            let to = (k + NEIGHBOUR_PASSES + 1).min(order.len() - 1);
            let mut best = (Real::INFINITY, 0);
            for &pass in &order[from..=to] {
                let got = nearest(&lists[pass], q, grid.thetas[i]);
                if got.0 < best.0 {
                    best = got;
                }
            }
            out.push(best);
        }
    }
    Ok(out)
}

/// Each block's wheel (its last sample) across the whole section at its
/// own theta, for the rows in `rows` (`dist` holds those rows only).
fn across(
    grid: &Grid,
    points: &[Vec3],
    lists: &[Vec<Sample>],
    step: Real,
    rows: std::ops::Range<usize>,
    dist: &mut [(Real, usize)],
) -> Result<(), OverTime> {
    let (nc, lo) = (grid.nc(), grid.thetas[0]);
    for list in lists {
        crate::budget::check("the groove's measurement")?;
        for (idx, s) in list.iter().enumerate() {
            if idx + 1 < list.len() && list[idx + 1].block == s.block {
                continue; // one sample per block: its last, at the block
            }
            let i = ((s.turn - lo) / step).round();
            if !(i >= rows.start as Real && i < rows.end as Real) {
                continue;
            }
            let i = i as usize;
            for j in 0..nc {
                let d = wheel_distance(&s.wheel, &points[i * nc + j]);
                let at = &mut dist[(i - rows.start) * nc + j];
                if d < at.0 {
                    *at = (d, s.block);
                }
            }
        }
    }
    Ok(())
}

/// The most material left and the deepest gouge on the groove, and the
/// deepest cut into the periphery (0 where none), with their places.
fn extremes(
    grid: &Grid,
    dist: &[(Real, usize)],
    program: &AxisProgram,
) -> (GroovePlace, GroovePlace, GroovePlace) {
    let (np, nc) = (grid.np(), grid.nc());
    let (mut left, mut gouge, mut cut) = (0, 0, np);
    for (idx, d) in dist.iter().enumerate() {
        if idx % nc >= np {
            if d.0 < dist[cut].0 {
                cut = idx;
            }
            continue;
        }
        if d.0 > dist[left].0 {
            left = idx;
        }
        if d.0 < dist[gouge].0 {
            gouge = idx;
        }
    }
    let mut max_gouge = grid.place(gouge, dist, program);
    max_gouge.mm = max_gouge.mm.min(0.0);
    let mut periphery_cut = grid.place(cut, dist, program);
    periphery_cut.mm = periphery_cut.mm.min(0.0);
    (grid.place(left, dist, program), max_gouge, periphery_cut)
}

/// Along theta: `[theta (deg), depth, width]`, as
/// [`GrooveCheck::along_theta`] says.
fn along_theta(grid: &Grid, dist: &[(Real, usize)]) -> Vec<[Real; 3]> {
    let (np, nc) = (grid.np(), grid.nc());
    let bottom = grid.psi.partition_point(|p| p.0 < 0.0).clamp(1, np - 1);
    let (a, b) = (grid.psi[bottom - 1].0, grid.psi[bottom].0);
    let s = if b > a {
        (-a / (b - a)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist.chunks_exact(nc)
        .zip(&grid.thetas)
        .map(|(row, t)| {
            let at_bottom = row[bottom - 1].0 + s * (row[bottom].0 - row[bottom - 1].0);
            [t.to_degrees(), -at_bottom, -(row[0].0 + row[np - 1].0)]
        })
        .collect()
}

/// Why `worst` strays, where the geometry tells: material left beyond
/// the outermost passes (at `pass_range`, rad) is short passes; a gouge by
/// the edge where the groove's width bends toward the wheel (`B'' < 0`) is
/// the wheel's flat side, which reaches along the groove far beyond the
/// contact, meeting the wall where the edge curves in. Empty otherwise.
fn explain(g: &Groove, worst: &GroovePlace, pass_range: [Real; 2]) -> Result<String, VerifyError> {
    let (psi, theta) = (worst.psi_deg, worst.theta_deg.to_radians());
    let [a, b] = pass_range.map(Real::to_degrees);
    if worst.mm > 0.0
        && (psi < a - crate::tolerance::SAME_ANGLE || psi > b + crate::tolerance::SAME_ANGLE)
    {
        return Ok(format!(
            ": the outermost passes are at psi {} and {} deg, short of the groove's edges at -90 and 90 deg; \
             place the outermost passes at the edges",
            crate::math::fixed(a, 2),
            crate::math::fixed(b, 2)
        ));
    }
    if worst.mm < 0.0 && psi.abs() >= BY_THE_EDGE_DEG {
        // B'' by the second difference over half a degree each side
        // (inside the tables at their ends).
        let (lo, hi) = g.theta_range();
        let step = 0.5f64.to_radians();
        let t = theta.clamp(lo + step, hi - step);
        let width = |t: Real| g.section(t).map(|s| 2.0 * s.half_width());
        let bend = (width(t + step)? - 2.0 * width(t)? + width(t - step)?) / 0.25;
        if bend < 0.0 {
            return Ok(format!(
                ": by the edge the groove's width bends toward the wheel (B'' = {} mm/deg^2 at theta {} deg), \
                 and the wheel's flat side, reaching along the groove far beyond its contact, cuts the wall where the edge curves in; \
                 give the groove a width that bends away by its edges (B'' >= 0 there: a relief widening ever faster toward the groove's end), \
                 or use a smaller wheel, whose side reaches less far",
                crate::math::fixed(bend, 5),
                crate::math::fixed(t.to_degrees(), 2)
            ));
        }
    }
    Ok(String::new())
}

/// The groove's failure (with `verification failed: ` before it, the
/// check's [`VerifyError::Failed`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GrooveFailure {
    /// The finished groove strays from the nominal beyond the tolerance.
    #[error(
        "the finished groove strays {} mm from the nominal at theta = {} deg, psi = {} deg, \
         where {block} leaves it (tolerance {tolerance} mm; positive: material left, negative: a gouge){why}",
        crate::math::fixed(*deviation, 5),
        crate::math::fixed(*theta_deg, 3),
        crate::math::fixed(*psi_deg, 3)
    )]
    Groove {
        /// The signed deviation (mm).
        deviation: Real,
        /// Where: theta (deg).
        theta_deg: Real,
        /// Where: psi (deg).
        psi_deg: Real,
        /// The block whose wheel is nearest there, as the program names it.
        block: String,
        /// The tolerance (mm).
        tolerance: Real,
        /// Why, where the check can tell, and what to change (from `: `;
        /// empty if it cannot).
        why: String,
    },
    /// The wheel cuts the roll's periphery beside the groove, which is not
    /// to be ground.
    #[error(
        "the wheel cuts the roll's periphery {} mm deep at theta = {} deg, {} mm beyond the groove's edge at psi = {} deg, \
         where {block} reaches it (tolerance {tolerance} mm): the periphery beside the groove is not ground",
        crate::math::fixed(*deviation, 5),
        crate::math::fixed(*theta_deg, 3),
        crate::math::fixed(*beyond_mm, 3),
        crate::math::fixed(*psi_deg, 0)
    )]
    Periphery {
        /// The cut (mm, negative).
        deviation: Real,
        /// Where: theta (deg).
        theta_deg: Real,
        /// The edge's side: psi (deg), -90 or 90.
        psi_deg: Real,
        /// How far beyond the edge along the roll's axis (mm).
        beyond_mm: Real,
        /// The block whose wheel cuts it, as the program names it.
        block: String,
        /// The tolerance (mm).
        tolerance: Real,
    },
}

impl GrooveCheck {
    /// The larger of the most material left and the deepest gouge.
    fn worst(&self) -> &GroovePlace {
        if self.max_left.mm >= -self.max_gouge.mm {
            &self.max_left
        } else {
            &self.max_gouge
        }
    }

    /// The place the check fails at: the groove's worst, then the cut into
    /// the periphery.
    fn failed_place(&self) -> Option<&GroovePlace> {
        if self.max_abs_mm > self.tolerance {
            Some(self.worst())
        } else {
            (-self.periphery_cut.mm > self.tolerance).then_some(&self.periphery_cut)
        }
    }

    /// The groove's failure, if it strays more than the tolerance from the
    /// nominal ([`GrooveFailure::Groove`]), or the wheel cuts the periphery
    /// beside it more than that ([`GrooveFailure::Periphery`]).
    pub fn failure(&self) -> Option<GrooveFailure> {
        let place = self.failed_place()?;
        Some(if place.beyond_edge_mm > 0.0 {
            GrooveFailure::Periphery {
                deviation: place.mm,
                theta_deg: place.theta_deg,
                psi_deg: place.psi_deg,
                beyond_mm: place.beyond_edge_mm,
                block: place.block.clone(),
                tolerance: self.tolerance,
            }
        } else {
            GrooveFailure::Groove {
                deviation: place.mm,
                theta_deg: place.theta_deg,
                psi_deg: place.psi_deg,
                block: place.block.clone(),
                tolerance: self.tolerance,
                why: self.why.clone(),
            }
        })
    }

    /// The check, or its failure as an error.
    ///
    /// # Failures
    /// [`Self::failure`].
    pub fn verified(self) -> Result<Self, VerifyError> {
        match self.failure() {
            Some(e) => Err(VerifyError::Failed(e.to_string())),
            None => Ok(self),
        }
    }

    /// The most material left and the deepest gouge against the
    /// tolerance, and the failure.
    pub fn findings(&self) -> (Vec<Figure>, Vec<Finding>) {
        let place = |p: &GroovePlace| {
            format!(
                "theta {} deg, psi {} deg, {}",
                crate::math::fixed(p.theta_deg, 2),
                crate::math::fixed(p.psi_deg, 2),
                p.block
            )
        };
        let at = |f: Figure, p: &GroovePlace| match p.block_from_0() {
            Some(b) => f.at_block(b),
            None => f,
        };
        let figures = vec![
            at(
                Figure::new(
                    "the groove: most material left",
                    self.max_left.mm,
                    self.tolerance,
                    "mm",
                    place(&self.max_left),
                ),
                &self.max_left,
            ),
            at(
                Figure::new(
                    "the groove: deepest gouge",
                    self.max_gouge.mm,
                    self.tolerance,
                    "mm",
                    place(&self.max_gouge),
                ),
                &self.max_gouge,
            ),
            at(
                Figure::new(
                    "the roll's periphery beside the groove: deepest cut",
                    self.periphery_cut.mm,
                    self.tolerance,
                    "mm",
                    format!(
                        "{}, {} mm beyond the edge",
                        place(&self.periphery_cut),
                        crate::math::fixed(self.periphery_cut.beyond_edge_mm, 3)
                    ),
                ),
                &self.periphery_cut,
            ),
        ];
        let failures = self
            .failure()
            .zip(self.failed_place())
            .map(|(e, at)| {
                Finding::new(
                    "verification",
                    VerifyError::Failed(e.to_string()).to_string(),
                )
                .at(at.block_index.saturating_sub(1), at.block.clone())
            })
            .into_iter()
            .collect();
        (figures, failures)
    }
}

#[cfg(test)]
mod map_tests {
    use super::*;

    /// A grid larger than the map's cells keeps each cell's value of
    /// largest size, so the extremes survive; the edges span the grid.
    #[test]
    fn the_map_keeps_the_extremes() {
        let thetas: Vec<Real> = (0..1000).map(|i| (i as Real * 0.2).to_radians()).collect();
        let psis: Vec<Real> = (0..101)
            .map(|j| ((j as Real - 50.0) * 1.6).to_radians())
            .collect();
        let mut values: Vec<Real> = (0..thetas.len() * psis.len())
            .map(|k| 1e-3 * ((k % 7) as Real - 3.0) / 10.0)
            .collect();
        values[123 * 101 + 17] = 0.0042;
        values[777 * 101 + 99] = -0.0031;
        let m = DeviationMap::of(&thetas, &psis, &values);
        assert_eq!(m.theta_deg.len(), MAP_CELLS.0 + 1);
        assert_eq!(m.psi_deg.len(), MAP_CELLS.1 + 1);
        assert_eq!(m.mm.len(), MAP_CELLS.0 * MAP_CELLS.1);
        let max = m.mm.iter().copied().fold(Real::MIN, Real::max);
        let min = m.mm.iter().copied().fold(Real::MAX, Real::min);
        assert_eq!((max, min), (0.0042, -0.0031));
        assert!(
            (m.theta_deg[0] - 0.0).abs() < 1e-12 && (m.theta_deg[MAP_CELLS.0] - 199.8).abs() < 1e-9
        );
        assert!((m.psi_deg[0] + 80.0).abs() < 1e-9 && (m.psi_deg[MAP_CELLS.1] - 80.0).abs() < 1e-9);
        assert!(m.theta_deg.windows(2).all(|w| w[1] > w[0]));
        // The 0.0042 at theta 24.6 deg, psi -52.8 deg lies in the cell
        // whose edges hold it.
        let i = m
            .theta_deg
            .windows(2)
            .position(|w| w[0] <= 24.6 && 24.6 <= w[1])
            .unwrap();
        let j = m
            .psi_deg
            .windows(2)
            .position(|w| w[0] <= -52.8 && -52.8 <= w[1])
            .unwrap();
        assert_eq!(m.mm[i * MAP_CELLS.1 + j], 0.0042);
    }
}

#[cfg(test)]
mod failure_tests {
    use super::*;

    fn check(groove_mm: Real, periphery_mm: Real) -> GrooveCheck {
        let at = |mm: Real, psi: Real, beyond: Real, block: usize| GroovePlace {
            mm,
            theta_deg: 40.0,
            psi_deg: psi,
            block: format!("N{}", 10 * block),
            block_index: block,
            beyond_edge_mm: beyond,
        };
        GrooveCheck {
            tolerance: 0.01,
            resolution_mm: 1e-4,
            sampling_resolution_mm: 1e-4,
            samples: 1,
            grid_theta: 1,
            grid_psi: 1,
            grid_theta_step_deg: 1.0,
            psi_range_deg: [-90.0, 90.0],
            pass_range_deg: [-90.0, 90.0],
            max_left: at(groove_mm, 3.0, 0.0, 7),
            max_gouge: at(0.0, 3.0, 0.0, 7),
            max_abs_mm: groove_mm,
            periphery_cut: at(periphery_mm, 90.0, 1.25, 9),
            why: String::new(),
            patch: None,
            map: DeviationMap::default(),
            along_theta: Vec::new(),
        }
    }

    /// A wheel that cuts only the periphery fails the run there, naming
    /// the block, the edge's side and how far beyond it; a groove that
    /// strays too is named first.
    #[test]
    fn a_cut_periphery_fails_at_its_block() {
        assert!(check(0.005, -0.005).failure().is_none());
        let c = check(0.005, -0.03);
        let e = c.failure().expect("the periphery is cut 30 um");
        assert!(matches!(e, GrooveFailure::Periphery { .. }), "{e}");
        let text = e.to_string();
        assert!(
            text.contains("periphery") && text.contains("N90") && text.contains("1.250 mm beyond"),
            "{text}"
        );
        let (_, failures) = c.findings();
        assert_eq!(failures.len(), 1);
        assert_eq!(failures[0].block_index, Some(9));
        let both = check(0.02, -0.03).failure().unwrap();
        assert!(matches!(both, GrooveFailure::Groove { .. }), "{both}");
    }
}
