//! How long a program runs: at its programmed feeds, and as the machine's
//! axes can move it, each accelerating at most its `max_accel`.
//!
//! **At the programmed feeds** a feed move lasts its length
//! ([`feed_length`], the model the feed checks use) over its feed; a rapid
//! as long as its slowest axis at that axis's top speed.
//!
//! **With acceleration** every move is a straight line in the axes' space,
//! as the control interpolates it, its speed along it ramped
//! (a trapezoid: accelerate, cruise, decelerate) within the least of the
//! axes' accelerations scaled to the move (an axis that moves a share `u`
//! of the move's length holds the move to `a / u`). Between two moves the
//! control blends without stopping (continuous-path mode, G64) as far as
//! the change of each axis's speed at the corner fits in one interpolation
//! cycle of its acceleration (the machine's constant `ipo_cycle`, seconds;
//! [`IPO_CYCLE`] where it states none): so a straight run of short blocks
//! flows at its feed, and a corner slows to what its axes can turn. A
//! thread starts and ends at rest (its feed is tied to the spindle), and so
//! do the program's start and end; a thread waits at its start for the
//! spindle's one-revolution signal, half a turn on average at the speed it
//! runs at (chained threads wait once). The speeds at the corners come from a
//! backward and a forward pass over the blocks (each block's entry speed no
//! more than lets it stop in time), as a control's look-ahead plans them.
//!
//! The run times its program as its control reads it (the text read back:
//! feeds and positions as written), as its checks take it.
//!
//! An axis whose acceleration the machine does not state is taken as
//! reaching its speed at once; the report names such axes. Left out: jerk
//! limits, the control's smoothing of corners (which is faster than
//! stopping and slower than the blend here), the spindle's own run-up.
//!
//! Written here rather than taken from a library: the planner is a few
//! dozen lines over the kernel's own programs and machine data.

use crate::machine::{feed_length, Axis, AxisKind, MachineInfo};
use crate::math::Real;
use crate::program::{AxisProgram, ProgramPass};
use crate::toolpath::Motion;
use serde::{Deserialize, Serialize};

/// The interpolation cycle (s) where the machine states none: 4 ms, a
/// Sinumerik 840D's and a Fanuc 0i's usual.
pub const IPO_CYCLE: Real = 0.004;

/// The machine constant that states the interpolation cycle (s).
pub const IPO_CYCLE_CONSTANT: &str = "ipo_cycle";

/// One pass's times.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PassTime {
    /// The pass, as the program names it.
    pub pass: String,
    /// Its first block (from 0).
    pub first_block: usize,
    /// At the programmed feeds (min).
    pub programmed_min: Real,
    /// With the axes' acceleration (min).
    pub accelerated_min: Real,
}

/// A program's times (in `report.json` as `times`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Times {
    /// The whole program at its programmed feeds (min).
    pub programmed_min: Real,
    /// The whole program with the axes' acceleration (min).
    pub accelerated_min: Real,
    /// Each pass's.
    pub passes: Vec<PassTime>,
    /// The programmed axes whose acceleration the machine does not state.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unramped_axes: Vec<String>,
    /// The interpolation cycle the blends were planned with (s).
    pub ipo_cycle_s: Real,
    /// The seconds the threads wait in all for the spindle's
    /// one-revolution signal before they start (half a turn each on
    /// average), in [`Self::accelerated_min`].
    #[serde(default, skip_serializing_if = "is_zero")]
    pub thread_sync_s: Real,
    /// Each block's seconds with the axes' acceleration (the first, the
    /// start, 0): the scene's animation runs on them.
    #[serde(skip)]
    pub block_s: Vec<Real>,
}

/// One block's move, as the planner sees it.
#[derive(Debug, Clone, Copy, Default)]
struct Move {
    /// Length in the feed's measure (mm, or deg for a move that only turns).
    length: Real,
    /// Top speed (units/s): the feed, or the rapid's, within every axis's.
    speed: Real,
    /// Most acceleration along it (units/s²; infinite when no moving axis
    /// states one).
    accel: Real,
    /// At the programmed feed (s).
    programmed: Real,
    /// It starts and ends at rest (a thread).
    stops: bool,
}

/// The times of `program` on the machine `info`, in total and per pass.
pub fn times(program: &AxisProgram, info: &MachineInfo, passes: &[ProgramPass]) -> Times {
    let axes: Vec<Option<&Axis>> = program.axes.iter().map(|a| info.axis(&a.name)).collect();
    let known: Vec<&Axis> = axes.iter().flatten().copied().collect();
    let ipo = info
        .constants
        .get(IPO_CYCLE_CONSTANT)
        .copied()
        .filter(|v| v.is_finite() && *v > 0.0)
        .unwrap_or(IPO_CYCLE);
    // As the control reads the program: its values as written.
    let decimals = crate::program::written_decimals(program.decimals, &program.control);
    let w = |v: &Real| crate::program::written(*v, decimals);
    let n = program.blocks.len();
    let mut moves = vec![Move::default(); n];
    // Each block's unit direction in the axes' space (per length).
    let mut dirs: Vec<Vec<Real>> = vec![Vec::new(); n];
    for k in 1..n {
        let (a, b) = (&program.blocks[k - 1], &program.blocks[k]);
        let deltas: Vec<Real> = axes
            .iter()
            .zip(a.values.iter().zip(&b.values))
            .filter(|(ax, _)| ax.is_some())
            .map(|(_, (x, y))| w(y) - w(x))
            .collect();
        let rapid = b.motion == Motion::Rapid;
        let group: &[String] = if rapid { &[] } else { &info.setup.feed_group };
        let length = feed_length(&known, &deltas, group);
        if length <= 0.0 {
            continue;
        }
        let u: Vec<Real> = deltas.iter().map(|d| d / length).collect();
        // Every axis within its top speed and its acceleration.
        let (mut top, mut accel) = (Real::INFINITY, Real::INFINITY);
        for (ax, ui) in known.iter().zip(&u) {
            if ui.abs() < crate::tolerance::ROUNDING {
                continue;
            }
            top = top.min(ax.to_user(ax.max_feed) / 60.0 / ui.abs());
            if let Some(acc) = ax.max_accel {
                accel = accel.min(ax.to_user(acc) / ui.abs());
            }
        }
        let programmed = if rapid {
            known
                .iter()
                .zip(&deltas)
                .map(|(ax, d)| d.abs() / (ax.to_user(ax.max_feed) / 60.0))
                .fold(0.0, Real::max)
        } else if b.feed > 0.0 {
            length / (b.feed / 60.0)
        } else {
            0.0
        };
        let speed = if rapid {
            top
        } else if b.feed > 0.0 {
            (b.feed / 60.0).min(top)
        } else {
            continue;
        };
        moves[k] = Move {
            length,
            speed,
            accel,
            programmed,
            stops: matches!(b.motion, Motion::Thread { .. }),
        };
        dirs[k] = u;
    }
    // The most speed at the end of each block (the corner into the next).
    let mut corner = vec![0.0; n];
    for k in 1..n.saturating_sub(1) {
        let (m, next) = (&moves[k], &moves[k + 1]);
        // A dwell before the next move stops the axes at this one's end.
        let dwells = program.blocks[k + 1].dwell_s > 0.0;
        if m.length <= 0.0 || next.length <= 0.0 || m.stops || next.stops || dwells {
            continue;
        }
        let mut v = m.speed.min(next.speed);
        for ((ax, a), b) in known.iter().zip(&dirs[k]).zip(&dirs[k + 1]) {
            let jump = (b - a).abs();
            if jump > crate::tolerance::ROUNDING {
                if let Some(acc) = ax.max_accel {
                    v = v.min(ax.to_user(acc) * ipo / jump);
                }
            }
        }
        corner[k] = v;
    }
    // Look-ahead: no block enters faster than it can stop in; none leaves
    // faster than it can reach.
    let reach = |v: Real, m: &Move| (v * v + 2.0 * m.accel * m.length).sqrt();
    for k in (1..n.saturating_sub(1)).rev() {
        corner[k] = corner[k].min(reach(corner[k + 1], &moves[k + 1]));
    }
    for k in 1..n {
        let before = corner[k - 1];
        corner[k] = corner[k].min(reach(before, &moves[k]));
    }
    let block_time = |k: usize| -> Real {
        let m = &moves[k];
        if m.length <= 0.0 {
            return 0.0;
        }
        let (v0, v1) = (if k > 0 { corner[k - 1] } else { 0.0 }, corner[k]);
        trapezoid(v0, v1, m.speed, m.accel, m.length)
    };
    let mut accelerated: Vec<Real> = (0..n).map(block_time).collect();
    // A thread starts on the spindle's one-revolution signal (its feed is
    // tied to the turn): the carriage waits at the thread's start for it,
    // half a turn on average (where the spindle stands when the carriage
    // arrives is not known to a turn). A thread chained to a thread before
    // it runs on without a wait.
    let mut thread_sync_s = 0.0;
    for (k, rpm) in crate::program::spindle_speeds(program).enumerate() {
        let b = &program.blocks[k];
        let thread = |m: &Motion| matches!(m, Motion::Thread { .. });
        let chained = k > 0 && thread(&program.blocks[k - 1].motion);
        if thread(&b.motion) && !chained && rpm > 0.0 {
            let wait = 30.0 / rpm;
            accelerated[k.saturating_sub(1)] += wait;
            thread_sync_s += wait;
        }
    }
    // A block's dwell before its move: the axes stand, the clock runs.
    for (t, b) in accelerated.iter_mut().zip(&program.blocks) {
        *t += b.dwell_s;
    }
    let minutes = |t: &[Real]| t.iter().sum::<Real>() / 60.0;
    let programmed: Vec<Real> = (moves.iter().zip(&program.blocks))
        .map(|(m, b)| m.programmed + b.dwell_s)
        .collect();
    Times {
        programmed_min: minutes(&programmed),
        accelerated_min: minutes(&accelerated),
        passes: passes
            .iter()
            .map(|p| PassTime {
                pass: p.name.clone(),
                first_block: p.blocks.start,
                programmed_min: minutes(&programmed[p.blocks.clone()]),
                accelerated_min: minutes(&accelerated[p.blocks.clone()]),
            })
            .collect(),
        unramped_axes: known
            .iter()
            .filter(|a| a.kind != AxisKind::Spindle && a.max_accel.is_none())
            .map(|a| a.name.clone())
            .collect(),
        ipo_cycle_s: ipo,
        thread_sync_s,
        block_s: accelerated,
    }
}

fn is_zero(v: &Real) -> bool {
    *v == 0.0
}

/// The time (s) to run `length` entering at `v0`, leaving at `v1`, never
/// faster than `top`, accelerating at most `accel` (infinite: at `top`
/// throughout).
fn trapezoid(v0: Real, v1: Real, top: Real, accel: Real, length: Real) -> Real {
    if !accel.is_finite() {
        return length / top;
    }
    // The highest speed the length allows between the two ramps.
    let peak = ((2.0 * accel * length + v0 * v0 + v1 * v1) / 2.0).sqrt();
    if peak <= top {
        (2.0 * peak - v0 - v1).max(0.0) / accel
    } else {
        let ramps = (top * top - v0 * v0 + top * top - v1 * v1) / (2.0 * accel);
        (top - v0) / accel + (top - v1) / accel + (length - ramps).max(0.0) / top
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The trapezoid against its closed forms: 100 mm from rest to rest at
    /// 1000 mm/s² with a top of 50 mm/s cruises (0.05 s up and 0.05 s down
    /// over 1.25 mm each, 97.5 mm at 50 mm/s); 1 mm never reaches it (a triangle, 2 sqrt(1 /
    /// 1000) s); entering and leaving at the top is the length over it.
    #[test]
    fn a_move_ramps_up_cruises_and_ramps_down() {
        let t = trapezoid(0.0, 0.0, 50.0, 1000.0, 100.0);
        assert!((t - (0.1 + 97.5 / 50.0)).abs() < 1e-12, "{t}");
        let t = trapezoid(0.0, 0.0, 50.0, 1000.0, 1.0);
        assert!((t - 2.0 * (1.0_f64 / 1000.0).sqrt()).abs() < 1e-12, "{t}");
        let t = trapezoid(50.0, 50.0, 50.0, 1000.0, 10.0);
        assert!((t - 0.2).abs() < 1e-12, "{t}");
        assert_eq!(trapezoid(0.0, 0.0, 50.0, Real::INFINITY, 10.0), 0.2);
    }

    /// A thread waits at its start for the spindle's one-revolution
    /// signal, half a turn on average at the speed it runs at; the wait
    /// ends the block before it (the carriage stands at the thread's
    /// start); a thread chained to one before it does not wait again.
    #[test]
    fn a_thread_waits_half_a_turn_for_the_spindles_index() {
        let info = fanuc_0i_tc::describe();
        let mut p = crate::program::test_program();
        let t = times(&p, &info, &[]);
        let half = 30.0 / p.spindle_rpm;
        assert!(
            (t.thread_sync_s - half).abs() < 1e-12,
            "{}",
            t.thread_sync_s
        );
        // Block 4 (from 1) does not move: its time is the wait.
        assert!((t.block_s[3] - half).abs() < 1e-12, "{:?}", t.block_s);
        let sum: Real = t.block_s.iter().sum();
        assert!((sum / 60.0 - t.accelerated_min).abs() < 1e-12);
        let mut chained = p.blocks[4].clone();
        chained.values = vec![40.0, -70.0];
        p.blocks.insert(5, chained);
        assert!((times(&p, &info, &[]).thread_sync_s - half).abs() < 1e-12);
        p.blocks[1].spindle = Some(100.0);
        assert!((times(&p, &info, &[]).thread_sync_s - 0.3).abs() < 1e-12);
    }
}
