//! How the part turns on the machine along a program, for the scene's
//! player: by the axes that turn it ([`crate::machine::Axis::turns_part`]).
//!
//! - A rotary axis leading the tool chain (a caliber grinder's roll turn
//!   A): the part's turn is the inverse of those factors at the block's
//!   axis values ([`crate::collision::Placement::part_turn`]).
//! - A spindle carrying the part (a lathe's, a grinder's work spindle): it
//!   turns at the program's S (as the blocks set it), M3 about +Z, every
//!   post writing M3. In a
//!   thread block the lead ties the part's turn to the tool's travel, the
//!   part placed as the worm's simulation places each cut
//!   ([`thread_turn`]); the control's index pulse starts each thread at its
//!   start angle: the cycle time has the carriage wait half a turn for it
//!   on average ([`crate::timing`]), and the player shows the spindle
//!   reaching that angle over the stretch before the thread.
//!
//! The angles are sampled on keys of their own ([`spin_keys`]): a spindle
//! turns many times between two blocks' ends, and a player turns the short
//! way between keys.

use super::scene::SceneError;
use crate::machine::MachineKinematics;
use crate::mesh::MAX_SPIN_STEP;
use crate::program::AxisProgram;
use crate::tool::Tool;
use crate::toolpath::Motion;
use std::f64::consts::TAU;

/// The most keys the part's turn takes; a longer spin (more than a third
/// of this in turns) is left out of the player, the rotary axes' turn
/// kept.
pub const MAX_SPIN_KEYS: usize = 60_000;

/// How far the part has turned (rad, about the part's Z, the tool's turn
/// relative to the part) with the tool's point at `z`, in a thread block
/// that runs from `from_z` to `to_z` at `lead` (mm per turn) and starts at
/// `start_deg`: the thread's section at angle 0 lies a start angle's share
/// of the lead behind the block's start, and the part turns once a lead.
pub fn thread_turn(from_z: f64, to_z: f64, lead: f64, start_deg: f64, z: f64) -> f64 {
    let dir = (to_z - from_z).signum();
    let z_section = from_z - dir * lead * start_deg / 360.0;
    TAU * (z - z_section) / lead
}

/// The part's turn at the end of each block of `program` (rad, about +Z on
/// the machine, 0 at the program's start): `rotary` (each block's turn by
/// the rotary axes, [`crate::collision::Placement::part_turn`]) plus, when
/// a spindle carries the part (`spindle`), the spindle's turn at the
/// program's S over each block's seconds `block_s`, tied to the thread in
/// thread blocks.
///
/// # Failures
/// The replay of a program that threads failing.
pub fn part_turns(
    machine: &dyn MachineKinematics,
    program: &AxisProgram,
    tool: &Tool,
    rotary: &[f64],
    spindle: bool,
    block_s: &[f64],
) -> Result<Vec<f64>, SceneError> {
    let n = program.blocks.len();
    if !spindle {
        return Ok(rotary.to_vec());
    }
    // Where the tool's point stands along the axis at each block's end:
    // one batch through the machine's kinematics, where the program
    // threads at all.
    let threads = program
        .blocks
        .iter()
        .any(|b| matches!(b.motion, Motion::Thread { .. }));
    let poses = if threads {
        crate::replay::replay(program, machine, &tool.reference)
            .map_err(|e| SceneError::Place(e.to_string()))?
    } else {
        Vec::new()
    };
    let z_at = |k: usize| poses[6 * k + 2];
    let mut ends = Vec::with_capacity(n);
    let (mut theta, mut clock) = (0.0, 0.0);
    // The stretch since the last thread: its first block and start time.
    let (mut stretch, mut stretch_t0) = (0, 0.0);
    let speeds = crate::program::spindle_speeds(program);
    for (k, (b, rpm)) in program.blocks.iter().zip(speeds).enumerate() {
        let dt = block_s.get(k).copied().unwrap_or(0.0);
        match b.motion {
            Motion::Thread { lead, start_deg } if k > 0 => {
                let (from, to) = (z_at(k - 1), z_at(k));
                let turn = |z| thread_turn(from, to, lead, start_deg, z);
                // The part stands at minus the tool's turn relative to it.
                let (start, end) = (-turn(from), -turn(to));
                let span = clock - stretch_t0;
                if span > 0.0 {
                    // Reach the thread's start angle over the stretch.
                    let extra = (start - theta).rem_euclid(TAU);
                    let mut t = stretch_t0;
                    for (j, e) in ends.iter_mut().enumerate().skip(stretch) {
                        t += block_s.get(j).copied().unwrap_or(0.0);
                        *e += extra * (t - stretch_t0) / span;
                    }
                    theta += extra;
                }
                theta += end - start;
                stretch = k + 1;
                stretch_t0 = clock + dt;
            }
            _ => theta += rpm.max(0.0) * TAU / 60.0 * dt,
        }
        ends.push(theta);
        clock += dt;
    }
    Ok(ends
        .iter()
        .zip(rotary)
        .map(|(s, r)| s + r)
        .collect::<Vec<_>>())
}

/// Keys of the part's turn: each block's end turned `turns` (rad) at the
/// end of `block_s`' seconds, kept where the motion has a key (`keyed`)
/// and where the turn would otherwise go more than [`MAX_SPIN_STEP`]
/// between keys (a block that turns more is cut into equal parts, the
/// turn linear in time within it). Times as the motion's (f32 seconds),
/// increasing; `None` when the turn needs more than [`MAX_SPIN_KEYS`], or
/// when blocks of no time turn it further than a key's step.
pub fn spin_keys(
    turns: &[f64],
    block_s: &[f64],
    keyed: impl Fn(usize) -> bool,
) -> Option<(Vec<f32>, Vec<f64>)> {
    let n = turns.len();
    // The keys (s, rad), their times increasing as f32 holds them.
    let mut keys: Vec<(f32, f64)> = Vec::new();
    let emit = |keys: &mut Vec<(f32, f64)>, t: f64, a: f64| {
        let t = t as f32;
        if keys.last().is_none_or(|last| t > last.0) {
            keys.push((t, a));
        }
    };
    let last = |keys: &[(f32, f64)]| keys.last().map_or(0.0, |k| k.1);
    let mut clock = 0.0;
    for k in 0..n {
        let (t0, a0) = (clock, if k == 0 { 0.0 } else { turns[k - 1] });
        clock += block_s.get(k).copied().unwrap_or(0.0);
        let a1 = turns[k];
        if (a1 - last(&keys)).abs() > MAX_SPIN_STEP {
            emit(&mut keys, t0, a0);
            let m = ((a1 - a0).abs() / (0.9 * MAX_SPIN_STEP)).ceil();
            for j in 1..m as usize {
                let f = j as f64 / m;
                emit(&mut keys, t0 + f * (clock - t0), a0 + f * (a1 - a0));
            }
        }
        let far_next = turns
            .get(k + 1)
            .is_some_and(|next| (next - last(&keys)).abs() > 0.9 * MAX_SPIN_STEP);
        if keyed(k) || k + 1 == n || far_next {
            emit(&mut keys, clock, a1);
        }
        if keys.len() > MAX_SPIN_KEYS {
            return None;
        }
    }
    let (times, angles): (Vec<f32>, Vec<f64>) = keys.into_iter().unzip();
    // Blocks of no time can leave a step a player would show turning back.
    let even = angles
        .windows(2)
        .all(|w| (w[1] - w[0]).abs() <= MAX_SPIN_STEP);
    even.then_some((times, angles))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A spin at 10 turns a second over blocks of 1 s reads back as keys a
    /// quarter turn or less apart, at every block's end the motion keys,
    /// the angle linear in time within a block.
    #[test]
    fn a_fast_spin_gets_keys_within_a_third_of_a_turn() {
        let turns: Vec<f64> = (1..=5).map(|k| TAU * 10.0 * k as f64).collect();
        let (times, angles) = spin_keys(&turns, &[1.0; 5], |k| k % 2 == 0).unwrap();
        assert!(angles
            .windows(2)
            .all(|w| (w[1] - w[0]).abs() <= MAX_SPIN_STEP));
        for (t, a) in times.iter().zip(&angles) {
            assert!(
                (a - TAU * 10.0 * *t as f64).abs() < 1e-3 * a.max(1.0),
                "{t} {a}"
            );
        }
        for k in [0usize, 2, 4] {
            assert!(times.contains(&((k + 1) as f32)), "{k}");
        }
        // A still part keeps only the motion's keys and the last.
        let (times, _) = spin_keys(&[0.0; 5], &[1.0; 5], |k| k == 1).unwrap();
        assert_eq!(times, vec![2.0, 5.0]);
    }

    /// A thread's turn: the tool at the block's start stands at the start
    /// angle, and one lead further along at one more turn.
    #[test]
    fn a_thread_turns_once_a_lead_from_its_start_angle() {
        let (lead, start) = (6.0, 90.0);
        let at = |z| thread_turn(10.0, -20.0, lead, start, z);
        assert!((at(10.0) + 0.25 * TAU).abs() < 1e-12);
        assert!((at(10.0 - lead) - at(10.0) + TAU).abs() < 1e-12);
    }
}
