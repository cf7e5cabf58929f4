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
pub use pilgrim_plugin_abi::types::{CycleSpan, FanucCycleSpan, FanucThreadCycle, ThreadCycle};

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

/// How a control of Fanuc's kind moves where its manual leaves room: the
/// chamfer's pull-out angle (deg from the axis; 45 on the 0i).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FanucRules {
    /// The pull-out's angle.
    pub chamfer_deg: Real,
}

/// The rules pilgrim's own Fanuc cycles are expanded by: they write no
/// chamfer (the thread runs out over the toolpath's S2), so the control's
/// pull-out angle never enters.
pub const OWN_FANUC_RULES: FanucRules = FanucRules { chamfer_deg: 45.0 };

/// Decimals of a Fanuc cycle's lengths: its least input increment (IS-B,
/// 0.001 mm), in which its `P` and `Q` words are whole numbers.
pub const FANUC_DECIMALS: usize = 3;

/// `c` with each word rounded as its blocks write it ([`fanuc_blocks`]):
/// lengths to [`FANUC_DECIMALS`], the lead to [`WORD_DECIMALS`], the
/// angle to a whole degree.
pub fn fanuc_as_written(c: &FanucThreadCycle) -> FanucThreadCycle {
    let r = |v: Real, d: usize| (v * 10f64.powi(d as i32)).round() / 10f64.powi(d as i32);
    let mm = |v: Real| r(v, FANUC_DECIMALS);
    FanucThreadCycle {
        angle_deg: c.angle_deg.round(),
        min_cut: mm(c.min_cut),
        allowance: mm(c.allowance),
        x: mm(c.x),
        z: mm(c.z),
        taper: mm(c.taper),
        height: mm(c.height),
        first: mm(c.first),
        lead: r(c.lead, WORD_DECIMALS),
        ..*c
    }
}

/// The two blocks of Fanuc's `G76` for `c` (as written: [`fanuc_as_written`]):
/// `G76 P(m)(r)(a) Q(dd_min) R(d)` and `G76 X Z [R(i)] P(k) Q(dd) F(L)`,
/// `P` and `Q` whole numbers of the least input increment, `R` with its
/// point.
pub fn fanuc_blocks(c: &FanucThreadCycle) -> [String; 2] {
    let mm = |v: Real| crate::math::fixed(v, FANUC_DECIMALS);
    let units = |v: Real| format!("{:.0}", v * 10f64.powi(FANUC_DECIMALS as i32));
    let taper = if c.taper == 0.0 {
        String::new()
    } else {
        format!(" R{}", mm(c.taper))
    };
    [
        format!(
            "G76 P{:02}{:02}{:02} Q{} R{}",
            c.finishes,
            c.chamfer_tenths,
            c.angle_deg as u32,
            units(c.min_cut),
            mm(c.allowance)
        ),
        format!(
            "G76 X{} Z{}{taper} P{} Q{} F{}",
            mm(c.x),
            mm(c.z),
            units(c.height),
            units(c.first),
            crate::math::fixed(c.lead, WORD_DECIMALS)
        ),
    ]
}

/// The passes of Fanuc's two-block G76: each pass's depth below the crest
/// and its shift along Z towards the cycle's start (radius, mm).
/// `D_1 = dd`, `D_n = dd sqrt(n)`, raised to `D_(n-1) + dd_min` where the
/// step is smaller, capped at `k - d`, where roughing ends; then `m`
/// passes at `k`. Pass `n` is shifted towards the start by `(k - D_n)
/// tan(a/2)`: the tool's leading edge cuts, its trailing edge follows the
/// flank on the start's side; the finishing passes are not shifted
/// (docs/math.md, "Threading cycles").
///
/// # Failures
/// A word the control refuses (a height or first depth not above 0, the
/// allowance not below the height, an angle not of the list, no finishing
/// pass) or more than [`MAX_CYCLE_PASSES`] passes.
pub fn fanuc_passes(c: &FanucThreadCycle) -> Result<Vec<(Real, Real)>, super::ProgramFault> {
    fanuc_passes_text(c).map_err(super::ProgramFault::new)
}

fn fanuc_passes_text(c: &FanucThreadCycle) -> Result<Vec<(Real, Real)>, String> {
    for (w, v) in [
        ("P(k)", c.height),
        ("Q(dd)", c.first),
        ("Q(dd_min)", c.min_cut),
        ("R(d)", c.allowance),
        ("R(i)", c.taper),
        ("F", c.lead),
        ("X", c.x),
        ("Z", c.z),
    ] {
        if !v.is_finite() {
            return Err(format!("G76 {w} {v} is not a finite number"));
        }
    }
    if !(c.height > 0.0) {
        return Err(format!(
            "G76 P(k) {}: the thread's height must be above 0",
            c.height
        ));
    }
    if !(c.first > 0.0) {
        return Err(format!(
            "G76 Q(dd) {}: the first depth must be above 0",
            c.first
        ));
    }
    if !(c.allowance >= 0.0 && c.allowance < c.height) {
        return Err(format!(
            "G76 R(d) {}: the finishing allowance must be from 0 to below the height {}",
            c.allowance, c.height
        ));
    }
    if !(c.min_cut >= 0.0) {
        return Err(format!("G76 Q(dd_min) {}: below 0", c.min_cut));
    }
    if !(0.0..=120.0).contains(&c.angle_deg) {
        return Err(format!(
            "G76: the tool's angle {} deg is not from 0 to 120",
            c.angle_deg
        ));
    }
    if c.finishes == 0 || c.finishes > 99 {
        return Err(format!(
            "G76 P{:02}....: the finishing passes must be 1 to 99",
            c.finishes
        ));
    }
    if !(c.lead > 0.0) {
        return Err(format!("G76 F{}: the lead must be above 0", c.lead));
    }
    let tan = (0.5 * c.angle_deg).to_radians().tan();
    let rough = c.height - c.allowance;
    let mut out = Vec::new();
    let mut last: Real = 0.0;
    let mut n: Real = 1.0;
    loop {
        let law = if c.constant_depth { n } else { n.sqrt() };
        let d = (c.first * law).max(last + c.min_cut).min(rough);
        out.push((d, (c.height - d) * tan));
        if out.len() > MAX_CYCLE_PASSES {
            return Err(format!(
                "G76 Q(dd) {} P(k) {}: more than {MAX_CYCLE_PASSES} passes",
                c.first, c.height
            ));
        }
        if d >= rough {
            break;
        }
        last = d;
        n += 1.0;
    }
    out.extend((0..c.finishes).map(|_| (c.height, 0.0)));
    Ok(out)
}

/// The moves Fanuc's two-block G76 `c` makes from its start `start` (`[X,
/// Z]` as the program writes them, X on diameter where `diameter`), by
/// `rules`: each pass a rapid to its depth and shift, the cut to Z (the
/// chamfer's pull-out over `0.1 r L` before it, at `rules`' angle, where r
/// is above 0), a rapid out to the start's X and one back to its Z.
///
/// # Failures
/// As [`fanuc_passes`].
pub fn expand_fanuc(
    c: &FanucThreadCycle,
    start: [Real; 2],
    diameter: bool,
    rules: &FanucRules,
) -> Result<Vec<CycleMove>, super::ProgramFault> {
    let passes = fanuc_passes(c)?;
    let s = if diameter { 0.5 } else { 1.0 };
    let (x0, z0) = (start[0] * s, start[1]);
    let root = c.x * s;
    // Outside (the thread's end below the start) the passes go inwards.
    let outside = root < x0;
    let inward = if outside { -1.0 } else { 1.0 };
    let crest = root - inward * c.height;
    // Towards the start along Z.
    let back = if z0 >= c.z { 1.0 } else { -1.0 };
    let chamfer = 0.1 * Real::from(c.chamfer_tenths) * c.lead;
    let rise = chamfer * rules.chamfer_deg.to_radians().tan();
    let thread = Motion::Thread {
        lead: c.lead,
        start_deg: 0.0,
    };
    let mut moves = Vec::with_capacity(5 * passes.len());
    let mut push = |motion, x: Real, z: Real| {
        moves.push(CycleMove {
            motion,
            x: x / s,
            z,
        })
    };
    for (depth, shift) in passes {
        let end = crest + inward * depth;
        let begin = end + c.taper;
        let dz = back * shift;
        push(Motion::Rapid, begin, z0 + dz);
        if chamfer > 0.0 {
            push(thread, end, c.z + dz + back * chamfer);
            // The pull-out rises away from the axis's side the cut is on,
            // no further than the start's X.
            let out = end - inward * rise;
            let out = if outside { out.min(x0) } else { out.max(x0) };
            push(thread, out, c.z + dz);
        } else {
            push(thread, end, c.z + dz);
        }
        push(Motion::Rapid, x0, c.z + dz);
        push(Motion::Rapid, x0, z0);
    }
    Ok(moves)
}

/// The moves of one pass of Fanuc's simple threading cycle (`G92 X Z F
/// R`, system A) from its start `start` (`[X, Z]` as written): a rapid to
/// X (with the taper `taper`, radius, at the start), the cut to `[x, z]`,
/// a rapid out to the start's X and one back to its Z.
pub fn fanuc_g92(
    start: [Real; 2],
    x: Real,
    z: Real,
    taper: Real,
    lead: Real,
    diameter: bool,
) -> Vec<CycleMove> {
    let s = if diameter { 0.5 } else { 1.0 };
    let thread = Motion::Thread {
        lead,
        start_deg: 0.0,
    };
    vec![
        CycleMove {
            motion: Motion::Rapid,
            x: (x * s + taper) / s,
            z: start[1],
        },
        CycleMove {
            motion: thread,
            x,
            z,
        },
        CycleMove {
            motion: Motion::Rapid,
            x: start[0],
            z,
        },
        CycleMove {
            motion: Motion::Rapid,
            x: start[0],
            z: start[1],
        },
    ]
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

    /// The two worked examples of docs/math.md ("Threading cycles"): the
    /// depths, the shifts towards the start, the clamp and the chamfer.
    #[test]
    fn fanuc_g76_worked_examples() {
        let first = FanucThreadCycle {
            finishes: 2,
            chamfer_tenths: 0,
            angle_deg: 60.0,
            min_cut: 0.050,
            allowance: 0.020,
            x: 18.052,
            z: -30.0,
            taper: 0.0,
            height: 0.974,
            first: 0.400,
            lead: 1.5,
            constant_depth: false,
        };
        let round = |v: Real| (v * 1000.0).round() / 1000.0;
        // Each pass's depth and shift to 0.001 mm, as the manuals print them.
        let rounded = |c: &FanucThreadCycle| -> Vec<(Real, Real)> {
            fanuc_passes(c)
                .unwrap()
                .into_iter()
                .map(|(d, s)| (round(d), round(s)))
                .collect()
        };
        let got = rounded(&first);
        let want = [
            (0.400, 0.331),
            (0.566, 0.236),
            (0.693, 0.162),
            (0.800, 0.100),
            (0.894, 0.046),
            (0.954, 0.012),
            (0.974, 0.0),
            (0.974, 0.0),
        ];
        assert_eq!(got, want);
        let clamped = FanucThreadCycle {
            min_cut: 0.100,
            chamfer_tenths: 10,
            ..first
        };
        let got = rounded(&clamped);
        let want = [
            (0.400, 0.331),
            (0.566, 0.236),
            (0.693, 0.162),
            (0.800, 0.100),
            (0.900, 0.043),
            (0.954, 0.012),
            (0.974, 0.0),
            (0.974, 0.0),
        ];
        assert_eq!(got, want);
        // From X24 Z5 on diameter: the crest at 18.052 / 2 + 0.974; each
        // pass pulls out over L = 1.5 before Z at 45 degrees.
        let rules = FanucRules { chamfer_deg: 45.0 };
        let moves = expand_fanuc(&clamped, [24.0, 5.0], true, &rules).unwrap();
        assert_eq!(moves.len(), 5 * 8);
        let crest = 9.026 + 0.974;
        let (cut, pull) = (moves[1], moves[2]);
        assert!((moves[0].z - (5.0 + (0.974 - 0.4) * 30f64.to_radians().tan())).abs() < 1e-12);
        assert!((cut.x / 2.0 - (crest - 0.4)).abs() < 1e-12, "{}", cut.x);
        assert!((cut.z - (-30.0 + moves[0].z - 5.0 + 1.5)).abs() < 1e-12);
        assert!(
            (pull.x / 2.0 - (crest - 0.4 + 1.5)).abs() < 1e-12,
            "{}",
            pull.x
        );
        assert!((pull.z - (moves[0].z - 5.0 - 30.0)).abs() < 1e-12);
        assert_eq!((moves[3].x, moves[4].x, moves[4].z), (24.0, 24.0, 5.0));
        let last = &moves[35..40];
        assert!((last[1].x - 18.052).abs() < 1e-12 && (last[2].z + 30.0).abs() < 1e-12);
        // The one-block form's P3: a constant depth, D_n = n dd, capped at
        // k - d, one finishing pass.
        let depth = FanucThreadCycle {
            constant_depth: true,
            finishes: 1,
            first: 0.2,
            ..first
        };
        let got: Vec<Real> = rounded(&depth).into_iter().map(|(d, _)| d).collect();
        assert_eq!(got, [0.2, 0.4, 0.6, 0.8, 0.954, 0.974]);
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
