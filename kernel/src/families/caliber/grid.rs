//! The grid a caliber's groove is measured on: theta along the groove's
//! tables, psi across its section (the passes' angles, each step divided,
//! run on beyond the outermost passes to the edges at -90 and 90 deg), and
//! beside each edge a strip of the roll's periphery.

use super::check::{GroovePlace, GrooveRequest, EDGE_GRID_STEP, MAX_GRID_POINTS, PERIPHERY_REACH};
use super::groove::Groove;
use crate::math::{Real, Vec3};
use crate::program::{block_name, AxisProgram};
use crate::replay::VerifyError;
use crate::tool::Wheel;

/// The grid's points: `thetas` in rows, each row the section's points
/// (`psi`) then the periphery's (`rim`).
pub(super) struct Grid {
    /// Theta of each row (rad), from the groove's first angle.
    pub thetas: Vec<Real>,
    /// Across the section: (psi (rad), the pass it is measured against,
    /// as an index into `order`).
    pub psi: Vec<(Real, usize)>,
    /// Beside the edges: (side -1 or 1, distance beyond the edge (mm),
    /// the pass, as an index into `order`).
    pub rim: Vec<(Real, Real, usize)>,
    /// The cutting passes in order of psi.
    pub order: Vec<usize>,
    /// The psi of the outermost passes (rad).
    pub pass_range: [Real; 2],
}

impl Grid {
    /// The grid of `req` (the periphery's strip as wide as the rounding
    /// of `wheel` reaches), refused over [`MAX_GRID_POINTS`].
    pub fn new(req: &GrooveRequest, wheel: &Wheel) -> Result<Self, VerifyError> {
        let (lo, hi) = req.groove.theta_range();
        let n_theta = ((hi - lo) / req.grid_theta).ceil() as usize + 1;
        let mut order: Vec<usize> = (0..req.psi.len()).collect();
        order.sort_by(|&a, &b| req.psi[a].total_cmp(&req.psi[b]));
        let (psi, pass_range) = across(req, &order);
        let last = order.len() - 1;
        let rim = rim(req.tolerance, PERIPHERY_REACH * wheel.rounding_radius, last);
        let nc = psi.len() + rim.len();
        if n_theta.saturating_mul(nc) > MAX_GRID_POINTS {
            return Err(VerifyError::Replay(format!(
                "a grid of {n_theta} x {nc} points is more than {MAX_GRID_POINTS}: a coarser grid"
            )));
        }
        let thetas = (0..n_theta)
            .map(|i| (lo + req.grid_theta * i as Real).min(hi))
            .collect();
        Ok(Self {
            thetas,
            psi,
            rim,
            order,
            pass_range,
        })
    }

    /// The points across the section in a row.
    pub fn np(&self) -> usize {
        self.psi.len()
    }

    /// The points in a row, the section's and the periphery's.
    pub fn nc(&self) -> usize {
        self.psi.len() + self.rim.len()
    }

    /// The pass (an index into `order`) the `j`-th point of a row is
    /// measured against.
    pub fn pass_of(&self, j: usize) -> usize {
        match j.checked_sub(self.np()) {
            None => self.psi[j].1,
            Some(r) => self.rim[r].2,
        }
    }

    /// The points of the grid on `groove`, row by row of theta: the
    /// groove's, then the periphery's.
    pub fn points(&self, groove: &Groove) -> Result<Vec<Vec3>, VerifyError> {
        let r_d = groove.roll_radius();
        let mut points = Vec::with_capacity(self.thetas.len() * self.nc());
        for &t in &self.thetas {
            let section = groove.section(t)?;
            for &(psi, _) in &self.psi {
                points.push(groove.point_of(&section, t, psi));
            }
            let half = section.edge_x();
            for &(side, d, _) in &self.rim {
                points.push(Vec3::new(r_d * t.cos(), r_d * t.sin(), side * (half + d)));
            }
        }
        Ok(points)
    }

    /// The place of the grid's `idx`-th point, with its figure and block
    /// from `dist` (the distance and the block, from 0, at each point).
    pub fn place(&self, idx: usize, dist: &[(Real, usize)], program: &AxisProgram) -> GroovePlace {
        let (i, j) = (idx / self.nc(), idx % self.nc());
        let (psi, beyond) = match j.checked_sub(self.np()) {
            None => (self.psi[j].0, 0.0),
            Some(r) => (self.rim[r].0 * std::f64::consts::FRAC_PI_2, self.rim[r].1),
        };
        GroovePlace {
            mm: dist[idx].0,
            theta_deg: self.thetas[i].to_degrees(),
            psi_deg: psi.to_degrees(),
            block: block_name(program, dist[idx].1),
            block_index: dist[idx].1 + 1,
            beyond_edge_mm: beyond,
        }
    }
}

/// Psi across the section: the passes' angles (in `order`), each step
/// divided in `grid_per_step`, then on to the edges beyond the outermost
/// passes, no coarser than between them, against the outermost passes;
/// with the outermost passes' psi.
fn across(req: &GrooveRequest, order: &[usize]) -> (Vec<(Real, usize)>, [Real; 2]) {
    let per = req.grid_per_step.max(1);
    let mut between: Vec<(Real, usize)> = Vec::new();
    for (k, w) in order.windows(2).enumerate() {
        let (a, b) = (req.psi[w[0]], req.psi[w[1]]);
        for s in 0..per {
            between.push((a + (b - a) * s as Real / per as Real, k));
        }
    }
    let last = order.len() - 1;
    between.push((req.psi[order[last]], last));
    let range = [between[0].0, between[between.len() - 1].0];
    let h = between
        .windows(2)
        .map(|w| w[1].0 - w[0].0)
        .fold(EDGE_GRID_STEP, Real::min);
    let edge = std::f64::consts::FRAC_PI_2;
    let spans = |from: Real, to: Real| {
        ((to - from) / h - crate::tolerance::COUNT_SLACK)
            .ceil()
            .max(0.0) as usize
    };
    let (below, above) = (spans(-edge, range[0]), spans(range[1], edge));
    let mut grid: Vec<(Real, usize)> = (0..below)
        .map(|i| (-edge + (range[0] + edge) * i as Real / below as Real, 0))
        .collect();
    grid.extend(between);
    grid.extend((1..=above).map(|i| {
        let psi = range[1] + (edge - range[1]) * i as Real / above as Real;
        (psi, last)
    }));
    (grid, range)
}

/// The periphery beside each edge: (side, distance beyond the edge, the
/// pass), from the tolerance out, doubling, to `reach`; the first pass
/// (in order of psi) beside the lower edge, the `last` beside the upper.
fn rim(tolerance: Real, reach: Real, last: usize) -> Vec<(Real, Real, usize)> {
    let mut offsets = Vec::new();
    let mut d = tolerance;
    while d < reach {
        offsets.push(d);
        d *= 2.0;
    }
    offsets.push(reach);
    [(-1.0, 0), (1.0, last)]
        .into_iter()
        .flat_map(|(side, k)| offsets.iter().map(move |&d| (side, d, k)))
        .collect()
}
