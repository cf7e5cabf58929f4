//! A control's threading cycle as the passes it makes: LinuxCNC's G76
//! (`G76 P Z I J R K Q H`), expanded as LinuxCNC's interpreter expands it
//! (`convert_threading_cycle` in its `interp_convert.cc`), so that a run
//! that writes the cycle verifies the moves the control will make, and a
//! program read as it stands is simulated through its cycles. CI holds
//! the expansion to LinuxCNC's own: `rs274` reads every program the tests
//! leave and its moves must be the axis program's (`.ci/rs274_check.py`).
//!
//! The passes, from the drive line (where the tool stands when the cycle
//! starts, X there `x0`, Z `z0`), depths radial: the crest is `|I|` below
//! the drive line; pass `n` (from 1) cuts `|I| + J n^(1/R)` below it while
//! that is less than `|I| + K`, then `H + 1` passes at `|I| + K`. Each
//! pass starts at `z0 - zoff`, `zoff` its depth below the crest times
//! `tan Q` (Q negated when the cycle runs towards +Z), and ends at
//! `Z + K tan Q - zoff`: back (rapid to its depth's retract height at the
//! start), in (rapid to its depth), over (spindle-synchronised to the
//! end), out (rapid up by `|I| + K`). Last, a rapid to the block's X (the
//! drive line's where it writes none) at `Z`. On diameter (`G7`) the
//! words `I`, `J`, `K` are diameters, halved as X is. The tapered ends
//! (`E`, `L`) are not expanded: a reader refuses them.
//!
//! Written here, not taken from a crate: no Rust crate expands a control's
//! cycles; the rule is LinuxCNC's twenty lines.

use crate::math::Real;
use crate::toolpath::Motion;
pub use pilgrim_plugin_abi::types::{CycleSpan, ThreadCycle};

/// The most passes one cycle may make ((K / J)^R is refused above it).
pub const MAX_CYCLE_PASSES: usize = 10_000;

/// Decimals each word of a cycle is written with: `P` as a lead, `Z` as
/// an axis, `I`, `J`, `K`, `R`, `Q` to 0.0001.
pub const WORD_DECIMALS: usize = 4;

/// Decimals of the cycle's `Z`.
pub const Z_DECIMALS: usize = 3;

/// One move a cycle makes: how, and where it ends (program units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleMove {
    /// A rapid, or the spindle-synchronised cut.
    pub motion: Motion,
    /// X at the move's end.
    pub x: Real,
    /// Z at the move's end.
    pub z: Real,
}

/// `c` with each word rounded as it is written ([`WORD_DECIMALS`],
/// [`Z_DECIMALS`]): the cycle a control reads from the text.
pub fn as_written(c: &ThreadCycle) -> ThreadCycle {
    let r = |v: Real, d: usize| (v * 10f64.powi(d as i32)).round() / 10f64.powi(d as i32);
    ThreadCycle {
        pitch: r(c.pitch, WORD_DECIMALS),
        z: r(c.z, Z_DECIMALS),
        i: r(c.i, WORD_DECIMALS),
        j: r(c.j, WORD_DECIMALS),
        r: r(c.r, WORD_DECIMALS),
        k: r(c.k, WORD_DECIMALS),
        q: r(c.q, WORD_DECIMALS),
        h: c.h,
    }
}

/// The cycle's words as its block holds them after the cycle's own
/// (`P2.5000 Z-33.000 I-4.0000 ...`).
pub fn words(c: &ThreadCycle) -> String {
    let f = |v: Real| crate::math::fixed(v, WORD_DECIMALS);
    format!(
        "P{} Z{} I{} J{} R{} K{} Q{} H{}",
        f(c.pitch),
        crate::math::fixed(c.z, Z_DECIMALS),
        f(c.i),
        f(c.j),
        f(c.r),
        f(c.k),
        f(c.q),
        c.h
    )
}

/// The moves the cycle `c` makes from the drive line `start` (`[X, Z]`,
/// program units), X on diameter where `diameter`, ending at `end_x`
/// (the block's X; `None`: the drive line's).
///
/// # Failures
/// A word the control refuses (`I` 0, `J` not above 0, `K` not above
/// `J`, `P` not above 0), a value not finite, or more than
/// [`MAX_CYCLE_PASSES`] passes; each named by its word.
pub fn expand(
    c: &ThreadCycle,
    start: [Real; 2],
    diameter: bool,
    end_x: Option<Real>,
) -> Result<Vec<CycleMove>, super::ProgramFault> {
    expand_text(c, start, diameter, end_x).map_err(super::ProgramFault::new)
}

/// [`expand`], its failure as text.
fn expand_text(
    c: &ThreadCycle,
    start: [Real; 2],
    diameter: bool,
    end_x: Option<Real>,
) -> Result<Vec<CycleMove>, String> {
    for (w, v) in [
        ('P', c.pitch),
        ('Z', c.z),
        ('I', c.i),
        ('J', c.j),
        ('R', c.r),
        ('K', c.k),
        ('Q', c.q),
        ('X', start[0]),
        ('Z', start[1]),
    ] {
        if !v.is_finite() {
            return Err(format!("G76 {w}{v} is not a finite number"));
        }
    }
    if !(c.pitch > 0.0) {
        return Err(format!("G76 P{}: the lead must be above 0", c.pitch));
    }
    if c.i == 0.0 {
        return Err("G76 I0: I must not be 0 (the crest's offset from the drive line)".into());
    }
    if !(c.j > 0.0) {
        return Err(format!("G76 J{}: J must be greater than 0", c.j));
    }
    if !(c.k > c.j) {
        return Err(format!("G76 K{} must be greater than J{}", c.k, c.j));
    }
    // Radial: LinuxCNC halves I, J, K and X on diameter.
    let s = if diameter { 0.5 } else { 1.0 };
    let (i, j, k) = (c.i * s, c.j * s, c.k * s);
    let safe_x = start[0] * s;
    let start_z = start[1];
    let boring = i > 0.0;
    let full_dia_depth = i.abs();
    let end_depth = k.abs() + i.abs();
    let degression = if c.r < 1.0 { 1.0 } else { c.r };
    // Q -1 is LinuxCNC's "not given".
    let mut q = if c.q == -1.0 { 0.0 } else { c.q }.to_radians();
    if c.z > start_z {
        q = -q;
    }
    let passes = (k / j).abs().powf(degression);
    if !(passes < MAX_CYCLE_PASSES as Real) {
        return Err(format!(
            "G76 J{} K{} R{}: about {passes:.0} passes, more than {MAX_CYCLE_PASSES}",
            c.j, c.k, c.r
        ));
    }
    let target_z = c.z + k.abs() * q.tan();
    let x_at = |depth: Real| {
        if boring {
            safe_x + depth
        } else {
            safe_x - depth
        }
    };
    let thread = Motion::Thread {
        lead: c.pitch,
        start_deg: 0.0,
    };
    let mut moves = Vec::new();
    let mut pass = |depth: Real| {
        let zoff = (depth - full_dia_depth) * q.tan();
        let up = x_at(depth - end_depth);
        for (motion, x, z) in [
            (Motion::Rapid, up, start_z - zoff),
            (Motion::Rapid, x_at(depth), start_z - zoff),
            (thread, x_at(depth), target_z - zoff),
            (Motion::Rapid, up, target_z - zoff),
        ] {
            moves.push(CycleMove {
                motion,
                x: x / s,
                z,
            });
        }
    };
    let mut n: i32 = 1;
    let mut depth = full_dia_depth + j.abs();
    while depth < end_depth {
        pass(depth);
        n += 1;
        depth = full_dia_depth + j.abs() * Real::from(n).powf(1.0 / degression);
    }
    for _ in 0..=c.h {
        pass(end_depth);
    }
    moves.push(CycleMove {
        motion: Motion::Rapid,
        x: end_x.unwrap_or(start[0]),
        z: c.z,
    });
    Ok(moves)
}

/// An external M20's cycle on diameter (the tests' example): P2.5,
/// from the drive line 4 mm over the crest, J0.6, R2, K3, Q29.5, H1, to
/// Z-35.
#[cfg(test)]
pub(crate) fn m20() -> ThreadCycle {
    ThreadCycle {
        pitch: 2.5,
        z: -35.0,
        i: -4.0,
        j: 0.6,
        r: 2.0,
        k: 3.0,
        q: 29.5,
        h: 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An external M20 on diameter from X24 Z5: the passes' depths are
    /// J sqrt(n) (radially half of it) below the crest at X20, until the
    /// full K; H + 1 at the full depth; each pass's start moved towards
    /// -Z by its depth times tan Q; every cut ends where its start's shift
    /// puts it, the last at Z; each retract returns above the drive line
    /// by what is left of the depth.
    #[test]
    fn linuxcnc_g76_passes() {
        let moves = expand(&m20(), [24.0, 5.0], true, None).unwrap();
        let cuts: Vec<&CycleMove> = moves
            .iter()
            .filter(|m| matches!(m.motion, Motion::Thread { .. }))
            .collect();
        // n = 1..25 below 3.0 = 0.6 sqrt(n): n < 25, 24 passes, then 2.
        assert_eq!(cuts.len(), 24 + 2);
        assert_eq!(moves.len(), 4 * 26 + 1);
        let tan = 29.5f64.to_radians().tan();
        for (n, c) in cuts.iter().enumerate().take(24) {
            let depth = 0.3 * ((n + 1) as Real).sqrt();
            assert!((c.x - (20.0 - 2.0 * depth)).abs() < 1e-12, "{n}: {}", c.x);
            let start = &moves[4 * n + 1];
            assert!((start.z - (5.0 - depth * tan)).abs() < 1e-12);
            assert!((c.z - (-35.0 + (1.5 - depth) * tan)).abs() < 1e-12);
            let up = &moves[4 * n + 3];
            assert!((up.x - (24.0 + 2.0 * (1.5 - depth))).abs() < 1e-12);
        }
        for c in &cuts[24..] {
            assert!((c.x - 17.0).abs() < 1e-12 && (c.z + 35.0).abs() < 1e-12);
        }
        let last = moves.last().unwrap();
        assert_eq!((last.motion, last.x, last.z), (Motion::Rapid, 24.0, -35.0));
    }

    /// Inside a bore (I above 0) the passes go outwards; towards +Z the
    /// shift runs the other way.
    #[test]
    fn boring_and_towards_plus_z() {
        let c = ThreadCycle {
            i: 2.0,
            z: 5.0,
            ..m20()
        };
        let moves = expand(&c, [26.0, -35.0], true, None).unwrap();
        let first = moves[2];
        assert!((first.x - 28.6).abs() < 1e-12, "{}", first.x);
        assert!(moves[1].z > -35.0);
    }

    #[test]
    fn bad_words_are_refused() {
        let e = |c: ThreadCycle| expand(&c, [24.0, 5.0], true, None).unwrap_err().message;
        assert!(e(ThreadCycle { i: 0.0, ..m20() }).contains("I must not be 0"));
        assert!(e(ThreadCycle { j: 0.0, ..m20() }).contains("J must be greater than 0"));
        assert!(e(ThreadCycle { k: 0.5, ..m20() }).contains("K0.5 must be greater than J0.6"));
        assert!(e(ThreadCycle {
            j: 1e-6,
            r: 3.0,
            ..m20()
        })
        .contains("passes, more than"));
        assert!(e(ThreadCycle {
            pitch: Real::NAN,
            ..m20()
        })
        .contains("P"));
        assert_eq!(
            words(&m20()),
            "P2.5000 Z-35.000 I-4.0000 J0.6000 R2.0000 K3.0000 Q29.5000 H1"
        );
    }
}
