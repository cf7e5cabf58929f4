//! A threading cycle (LinuxCNC's G76) as its control runs it: its words
//! read, the moves it makes expanded ([`crate::program::cycle`]), each
//! held and read as a block of its own.

use super::{
    at_line, cutting_fault, placed, setup_fault, Block, ReadMove, Reader, Said, Standing, State,
};
use crate::math::Real;
use crate::program::cycle::CycleMove;
use crate::program::lint::LintError;
use crate::program::post::Dialect;
use crate::toolpath::Motion;

impl Reader<'_> {
    /// The threading cycle block `b` holds (`said`): its moves pushed to
    /// `out`, each the next of the axis program's where the text is held
    /// to one.
    ///
    /// # Failures
    /// Its words (one missing, one it has not, the tapered ends), the
    /// modal state it needs (the spindle, constant speed, X and Z
    /// written), a move off the axis program's or outside an axis's
    /// travel.
    pub(super) fn cycle(
        &self,
        at: &mut Standing,
        b: &Block,
        said: &Said,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let d = self.d;
        let fail = |m: String| self.err(self.place(b, at.k), m);
        match d.reading.g76 {
            Some(crate::program::post::G76Form::FanucTwoBlock(rules)) => {
                return self.fanuc_g76(at, b, said, &rules, out);
            }
            Some(crate::program::post::G76Form::OneBlock) => {
                return self.one_block_g76(at, b, said, out);
            }
            _ => {}
        }
        let values: Vec<(char, Real)> = said.read.iter().map(|(c, v, _)| (*c, *v)).collect();
        let (cycle, end_x) = cycle_words(&values, d).map_err(fail)?;
        let ([x0, z0], xz) = self.cycle_ready(at, b, 76)?;
        let moves =
            crate::program::cycle::expand(&cycle, [x0, z0], at.st.radial == Some(true), end_x)
                .map_err(|m| fail(m.message))?;
        self.cycle_moves(at, b, &moves, xz, out)?;
        at.st.motion = Some(76);
        Ok(())
    }

    /// What a threading cycle at block `b` needs of the modal state: the
    /// spindle, constant speed where the dialect wants it, the setup, X
    /// and Z written (`code` the cycle's G code, for a message); where it starts (`[X, Z]` as written) and the two
    /// axes' places among the program's.
    pub(super) fn cycle_ready(
        &self,
        at: &Standing,
        b: &Block,
        code: u32,
    ) -> Result<([Real; 2], [usize; 2]), LintError> {
        let (d, program) = (self.d, self.program);
        let fail = |m: String| self.err(self.place(b, at.k), m);
        let st = &at.st;
        let what = &format!("a threading cycle (G{code})");
        let needs_g97 = (d.reading.thread_needs_constant_speed && !st.constant_speed)
            .then(|| format!("{what} before constant spindle speed (G97)"));
        if let Some(m) = cutting_fault(st, d, &program.setup, what)
            .or(needs_g97)
            .or_else(|| setup_fault(st, d, program, what))
        {
            return Err(fail(m));
        }
        let (Some(xi), Some(zi)) = (
            self.names.iter().position(|n| *n == 'X'),
            self.names.iter().position(|n| *n == 'Z'),
        ) else {
            return Err(fail(format!(
                "a threading cycle on {}, which programs no X and Z",
                program.machine
            )));
        };
        let (Some(x0), Some(z0)) = (st.values[xi], st.values[zi]) else {
            return Err(fail(
                "a threading cycle before X and Z are written (the drive line it starts from)"
                    .into(),
            ));
        };
        Ok(([x0, z0], [xi, zi]))
    }

    /// The moves a cycle at block `b` makes, each held and pushed to `out`
    /// as a block of its own.
    pub(super) fn cycle_moves(
        &self,
        at: &mut Standing,
        b: &Block,
        moves: &[CycleMove],
        xz: [usize; 2],
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let comment = at.pending.take();
        let (file, via) = self.origin(at);
        for (n, mv) in moves.iter().enumerate() {
            at.st.values = self.cycle_move(&at.st, b, at.k, n, mv, xz)?;
            out.push(ReadMove {
                motion: mv.motion,
                values: placed(&at.st),
                feed: match mv.motion {
                    Motion::Thread { lead, .. } => lead * at.st.speed.unwrap_or_default(),
                    _ => 0.0,
                },
                spindle: if n == 0 { at.speed_next.take() } else { None },
                dwell_s: at.take_dwell(),
                comment: if n == 0 { comment.clone() } else { None },
                number: b.number,
                line: b.line,
                file,
                via,
            });
            at.k += 1;
        }
        Ok(())
    }

    /// The axes' values after the cycle's move `n`, `mv`, from the state
    /// `st` (the cycle's first move the axis program's `k`-th; X and Z the
    /// axes `xz`): held to the axis program's move where the text is held
    /// to one, and to the axes' travel.
    fn cycle_move(
        &self,
        st: &State,
        b: &Block,
        k: usize,
        n: usize,
        mv: &CycleMove,
        [xi, zi]: [usize; 2],
    ) -> Result<Vec<Option<Real>>, LintError> {
        let (program, half, decimals) = (self.program, self.half, self.decimals);
        let fail = |m: String| self.err(self.place(b, k), m);
        let block = if self.reading {
            None
        } else {
            program.blocks.get(k)
        };
        if !self.reading && block.is_none() {
            return Err(self.err(
                at_line(b.line),
                format!(
                    "the threading cycle's move {} is beyond the axis program's {} blocks",
                    n + 1,
                    program.blocks.len()
                ),
            ));
        }
        let mut values = st.values.clone();
        values[xi] = Some(mv.x);
        values[zi] = Some(mv.z);
        if let Some(bl) = block {
            let off = (0..self.names.len())
                .find(|&i| values[i].is_some_and(|v| !((v - bl.values[i]).abs() <= half)));
            if bl.motion != mv.motion || off.is_some() {
                let at = |x: Real| crate::math::fixed(x, decimals + 2);
                return Err(fail(format!(
                    "the threading cycle's move {} is {} to X{} Z{}, the axis program's {} to X{} Z{}",
                    n + 1,
                    mv.motion,
                    at(mv.x),
                    at(mv.z),
                    bl.motion,
                    at(bl.values[xi]),
                    at(bl.values[zi])
                )));
            }
        }
        for (i, v) in [(xi, mv.x), (zi, mv.z)] {
            if let Some(a) = self.axes.iter().find(|a| a.name == program.axes[i].name) {
                let (lo, hi) = (a.to_user(a.min), a.to_user(a.max));
                if v < lo - half || v > hi + half {
                    return Err(fail(format!(
                        "the threading cycle's move {} takes {} to {v}, outside the axis's travel [{lo}, {hi}]",
                        n + 1,
                        program.axes[i].name
                    )));
                }
            }
        }
        Ok(values)
    }
}

/// A threading cycle's words as read (`read`, its block's letters and
/// values): the cycle and the block's X, where it writes one (where the
/// cycle leaves the tool). LinuxCNC's defaults: `R` 1, `Q` not given
/// (-1, no compound), `H` 0.
///
/// # Failures
/// A word missing (the block's reader refuses one given twice), `H` not a whole number, the tapered
/// ends (`E`, `L`), which are not simulated, or a word the cycle has not.
fn cycle_words(
    read: &[(char, Real)],
    d: &Dialect,
) -> Result<(crate::program::cycle::ThreadCycle, Option<Real>), String> {
    let mut seen: Vec<char> = Vec::new();
    // The block's reader refuses an address given twice: the first is it.
    let mut get = |c: char| -> Option<Real> {
        seen.push(c);
        read.iter().find(|(l, _)| *l == c).map(|(_, v)| *v)
    };
    let need = |c: char, v: Option<Real>| v.ok_or_else(|| format!("G76 without its {c} word"));
    let pitch = need('P', get('P'))?;
    let z = need('Z', get('Z'))?;
    let i = need('I', get('I'))?;
    let j = need('J', get('J'))?;
    let k = need('K', get('K'))?;
    let r = get('R').unwrap_or(1.0);
    let q = get('Q').unwrap_or(-1.0);
    let h = get('H').unwrap_or(0.0);
    let end_x = get('X');
    if !(h >= 0.0 && h.fract() == 0.0 && h <= 1000.0) {
        return Err(format!(
            "G76 H{h}: the spring passes must be a whole number from 0 to 1000"
        ));
    }
    if let Some((c, v)) = read.iter().find(|(l, _)| !seen.contains(l)) {
        return Err(match c {
            'E' | 'L' => format!(
                "G76 {c}{v}: the cycle's tapered ends, which the verification does not simulate; verify a program without them"
            ),
            _ => format!("G76 {c}{v}: not a word of {}'s threading cycle", d.name),
        });
    }
    Ok((
        crate::program::cycle::ThreadCycle {
            pitch,
            z,
            i,
            j,
            r,
            k,
            q,
            h: h as u32,
        },
        end_x,
    ))
}
