//! A machine's kinematics tried over its travel: what `pilgrim
//! plugin-check` reports, and what a run checks of a plugin library before
//! it trusts it with a program.
//!
//! [`SAMPLES`] rows of axis values are spread over each solved axis's
//! travel (a Halton sequence over the middle 80 % of it; a rotary axis kept
//! at least [`ROTARY_AWAY`] from zero, where a wrong sign or a swapped sine
//! would show nothing). The plugin's forward kinematics of them is compared
//! with the declared chain's (the descriptor's `chain`, as the kernel
//! evaluates it); its inverse kinematics of those poses, solved forward
//! again, with the poses (the two solutions against each other); and each
//! axis moved a little, by the plugin and by the chain (all axes' moves in
//! one batch each), to name an axis whose sign disagrees. A difference beyond [`POSITION_TOL`] or
//! [`ANGLE_TOL`], or a sign that disagrees, fails.

use crate::machine::{AxisKind, Machine, MachineKinematics};
use crate::transform::ToolFrame;

/// Rows of axis values tried.
pub const SAMPLES: usize = 64;
/// The largest difference of points allowed (mm): 0.1 um.
pub const POSITION_TOL: f64 = 1e-4;
/// The largest angle between tool axes allowed (rad).
pub const ANGLE_TOL: f64 = 1e-7;
/// The least distance of a rotary axis from zero in the samples (rad, 20 deg).
pub const ROTARY_AWAY: f64 = 0.35;

/// The worst difference of one comparison, and where.
#[derive(Debug, Clone, PartialEq)]
pub struct Worst {
    /// The distance between the points (mm).
    pub distance_mm: f64,
    /// The angle between the tool axes (rad).
    pub angle_rad: f64,
    /// The axis values (program units) of the row it was at.
    pub at: String,
}

/// What the exercise found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Exercise {
    /// Rows tried.
    pub samples: usize,
    /// The plugin's forward kinematics against the declared chain's.
    pub against_chain: Option<Worst>,
    /// The plugin's inverse, solved forward again, against the poses.
    pub round_trip: Option<Worst>,
    /// Solved axes whose sign disagrees with the chain's.
    pub signs: Vec<String>,
    /// What could not be tried, and why.
    pub notes: Vec<String>,
    /// A call that failed: what it was, and the plugin's message.
    pub failed: Option<String>,
}

impl Exercise {
    /// Whether everything tried agrees within the tolerances.
    pub fn passed(&self) -> bool {
        let within = |w: &Option<Worst>| {
            w.as_ref()
                .is_none_or(|w| w.distance_mm <= POSITION_TOL && w.angle_rad <= ANGLE_TOL)
        };
        self.failed.is_none()
            && within(&self.against_chain)
            && within(&self.round_trip)
            && self.signs.is_empty()
    }
}

impl std::fmt::Display for Exercise {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let worst = |w: &Worst| {
            format!(
                "worst {:.4} um and {:.2e} rad (at {})",
                1000.0 * w.distance_mm,
                w.angle_rad,
                w.at
            )
        };
        writeln!(
            f,
            "kinematics over the travel ({} rows of axis values; tolerance {} um, {:.0e} rad): {}",
            self.samples,
            1000.0 * POSITION_TOL,
            ANGLE_TOL,
            if self.passed() { "agree" } else { "DISAGREE" }
        )?;
        if let Some(w) = &self.against_chain {
            writeln!(f, "  forward against the declared chain: {}", worst(w))?;
        }
        if let Some(w) = &self.round_trip {
            writeln!(f, "  inverse then forward against the poses: {}", worst(w))?;
        }
        for a in &self.signs {
            writeln!(
                f,
                "  axis {a} moves the tool the other way than the declared chain says: its sign disagrees"
            )?;
        }
        if let Some(m) = &self.failed {
            writeln!(f, "  {m}")?;
        }
        for n in &self.notes {
            writeln!(f, "  {n}")?;
        }
        Ok(())
    }
}

/// The `i`-th element (from 1) of the Halton sequence in base `b`.
fn halton(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

const PRIMES: [usize; 9] = [2, 3, 5, 7, 11, 13, 17, 19, 23];

/// Rows of axis values spread over the travel of `machine`'s solved axes.
fn samples(machine: &dyn MachineKinematics) -> Vec<f64> {
    let info = machine.info();
    let mut rows = Vec::new();
    for i in 1..=SAMPLES {
        for (j, name) in info.solved_axes.iter().enumerate() {
            let Some(a) = info.axis(name) else {
                rows.push(0.0);
                continue;
            };
            let (mut lo, mut hi) = (a.min, a.max);
            if a.kind == AxisKind::Rotary {
                lo = lo.max(-std::f64::consts::TAU);
                hi = hi.min(std::f64::consts::TAU);
            }
            let t = 0.1 + 0.8 * halton(i, PRIMES[j % PRIMES.len()]);
            let mut v = lo + t * (hi - lo);
            if a.kind == AxisKind::Rotary && v.abs() < ROTARY_AWAY {
                let up = ROTARY_AWAY.copysign(if v == 0.0 { 1.0 } else { v });
                if (lo..=hi).contains(&up) {
                    v = up;
                } else if (lo..=hi).contains(&-up) {
                    v = -up;
                }
            }
            rows.push(v);
        }
    }
    rows
}

/// A row of axis values as program units: `X=12.3 C=45.0`.
fn row_text(machine: &dyn MachineKinematics, row: &[f64]) -> String {
    let info = machine.info();
    info.solved_axes
        .iter()
        .zip(row)
        .map(|(n, v)| match info.axis(n) {
            Some(a) => format!("{n}={:.4}", a.to_user(*v)),
            None => format!("{n}={v:.4}"),
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The worst difference between two batches of poses, at rows of `axes`.
fn worst(machine: &dyn MachineKinematics, a: &[f64], b: &[f64], axes: &[f64]) -> Worst {
    let width = machine.info().solved_axes.len().max(1);
    let mut w = Worst {
        distance_mm: 0.0,
        angle_rad: 0.0,
        at: String::new(),
    };
    let mut worst_score = -1.0;
    for (k, (p, q)) in a.chunks_exact(6).zip(b.chunks_exact(6)).enumerate() {
        let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
        let dot = (p[3] * q[3] + p[4] * q[4] + p[5] * q[5]).clamp(-1.0, 1.0);
        let cross = ((p[4] * q[5] - p[5] * q[4]).powi(2)
            + (p[5] * q[3] - p[3] * q[5]).powi(2)
            + (p[3] * q[4] - p[4] * q[3]).powi(2))
        .sqrt();
        let angle = cross.atan2(dot);
        let (d, angle) = if d.is_finite() && angle.is_finite() {
            (d, angle)
        } else {
            (f64::INFINITY, f64::INFINITY)
        };
        let score = d / POSITION_TOL + angle / ANGLE_TOL;
        if score > worst_score {
            worst_score = score;
            w = Worst {
                distance_mm: d,
                angle_rad: angle,
                at: axes
                    .get(k * width..(k + 1) * width)
                    .map(|r| row_text(machine, r))
                    .unwrap_or_default(),
            };
        }
    }
    w
}

/// Tries `plugin`'s kinematics over its travel. See the [module docs](self).
pub fn exercise(plugin: &super::PluginMachine) -> Exercise {
    use pilgrim_plugin_abi::{CAP_FORWARD, CAP_INVERSE};
    let info = plugin.info();
    let offers = |cap: u32| plugin.capabilities() & cap != 0;
    let tool = ToolFrame::default();
    let width = info.solved_axes.len();
    let mut out = Exercise {
        samples: SAMPLES,
        ..Exercise::default()
    };
    if width == 0 {
        out.notes
            .push("the machine solves no axes: nothing to try".into());
        return out;
    }
    let chain = if info.chain.is_empty() {
        out.notes
            .push("the descriptor declares no chain: only inverse against forward is tried".into());
        None
    } else {
        match Machine::from_info(info.clone()) {
            Ok(m) => Some(crate::machine::ChainMachine::new(m)),
            Err(e) => {
                out.notes
                    .push(format!("the declared chain cannot be evaluated: {e}"));
                None
            }
        }
    };
    let axes = samples(plugin);
    let chain_poses = chain.as_ref().and_then(|c| {
        let mut p = Vec::new();
        c.forward(&axes, &tool, &mut p).ok().map(|_| p)
    });
    let mut poses = Vec::new();
    let has_forward = offers(CAP_FORWARD);
    if !has_forward {
        out.notes
            .push("the plugin offers no forward kinematics: poses come from the chain".into());
    } else if let Err(e) = plugin.forward(&axes, &tool, &mut poses) {
        out.failed = Some(format!("forward kinematics failed: {e}"));
        return out;
    }
    if has_forward {
        if let Some(c) = &chain_poses {
            out.against_chain = Some(worst(plugin, &poses, c, &axes));
        }
    } else if let Some(c) = &chain_poses {
        poses = c.clone();
    } else {
        out.notes
            .push("no forward kinematics and no chain: nothing to try".into());
        return out;
    }
    // Inverse, then forward again (the plugin's, else the chain's).
    let mut solved = Vec::new();
    let inverse = if offers(CAP_INVERSE) {
        Some(plugin.inverse(&poses, &tool, &mut solved))
    } else {
        None
    };
    match inverse {
        Some(Ok(())) => {
            let mut again = Vec::new();
            let forward = if has_forward {
                plugin.forward(&solved, &tool, &mut again)
            } else {
                chain
                    .as_ref()
                    .map_or(Ok(()), |c| c.forward(&solved, &tool, &mut again))
            };
            match forward {
                Ok(()) => out.round_trip = Some(worst(plugin, &again, &poses, &axes)),
                Err(e) => out.failed = Some(format!("forward kinematics failed: {e}")),
            }
        }
        None => out
            .notes
            .push("the plugin offers no inverse kinematics".into()),
        Some(Err(e)) => {
            let at = e
                .index
                .and_then(|i| axes.get(i * width..(i + 1) * width))
                .map(|r| format!(" (at the pose of {})", row_text(plugin, r)))
                .unwrap_or_default();
            out.failed = Some(format!(
                "inverse kinematics failed on a pose its own forward kinematics gave{at}: {}",
                e.message
            ));
        }
    }
    // Each axis moved a little, by the plugin and by the chain: the rows
    // of every axis's move in one batch for each.
    if let (true, Some(c), Some(base_chain)) = (has_forward, &chain, &chain_poses) {
        let mut moved = Vec::with_capacity(width * axes.len());
        for (j, name) in info.solved_axes.iter().enumerate() {
            let span = info.axis(name).map_or(1.0, |a| {
                let s = (a.max - a.min).abs();
                if s.is_finite() && s > 0.0 {
                    s.min(100.0)
                } else {
                    1.0
                }
            });
            for row in axes.chunks_exact(width) {
                moved.extend_from_slice(row);
                let last = moved.len() - width;
                moved[last + j] += 1e-3 * span;
            }
        }
        let (mut p, mut q) = (Vec::new(), Vec::new());
        if plugin.forward(&moved, &tool, &mut p).is_ok() && c.forward(&moved, &tool, &mut q).is_ok()
        {
            let per_axis = poses.len();
            for (j, name) in info.solved_axes.iter().enumerate() {
                let block = j * per_axis..(j + 1) * per_axis;
                let agree: f64 = p[block.clone()]
                    .iter()
                    .zip(&q[block])
                    .zip(poses.iter().zip(base_chain))
                    .map(|((p, q), (p0, q0))| (p - p0) * (q - q0))
                    .sum();
                if agree < 0.0 {
                    out.signs.push(name.clone());
                }
            }
        }
    }
    out
}
