//! Fanuc's threading cycles in a shop's program (system A): the two-block
//! `G76` (its first block's words kept by the control for the next
//! cycle), the one-block `G76` of the Fanuc 10/11/15-T and Haas (the
//! control's settings for what its words leave out, as the machine states
//! them) and the modal `G92`, each expanded as the control runs it
//! ([`crate::program::cycle::expand_fanuc`], [`crate::program::cycle::fanuc_g92`])
//! and its moves read as blocks of their own.

use super::{Block, FanucFirst, ReadMove, Reader, Said, Standing};
use crate::math::Real;
use crate::program::cycle::{FanucRules, FanucThreadCycle};
use crate::program::lint::LintError;

/// The refusal of the first word of `said` that `cycle` (its name in the
/// message) has not among its words `allowed`, if there is one.
fn foreign_word(said: &Said, allowed: &[char], cycle: &str) -> Option<String> {
    let (c, _, t) = said.read.iter().find(|(c, ..)| !allowed.contains(c))?;
    let words: Vec<String> = allowed.iter().map(char::to_string).collect();
    Some(format!(
        "{t}: not a word of {cycle} ({}); {c} is {}",
        words.join(" "),
        if *c == 'U' || *c == 'W' {
            "incremental, which the verification does not read"
        } else {
            "another word"
        }
    ))
}

/// Where a Fanuc-kind G76 starts (`[X, Z]` as written, and the two axes'
/// places) and ends (X, Z), with its lead.
struct G76End {
    start: [Real; 2],
    xz: [usize; 2],
    x: Real,
    z: Real,
    lead: Real,
}

impl Reader<'_> {
    /// The unit of a cycle's whole-number words (P, Q; R without its
    /// point): the control's least input increment.
    fn increment(&self) -> Real {
        self.d.reading.least_input.unwrap_or(0.001)
    }

    /// Word `c` of block `b`'s words `said`: its value and whether it is
    /// written with a decimal point.
    fn cycle_word(said: &Said, c: char) -> Option<(Real, bool)> {
        said.read
            .iter()
            .find(|(l, ..)| *l == c)
            .map(|(_, v, t)| (*v, t.contains('.')))
    }

    /// A length word `c` of a cycle: in mm with its point, else in the
    /// least input increment.
    fn cycle_length(&self, said: &Said, c: char) -> Option<Real> {
        Self::cycle_word(said, c).map(|(v, point)| if point { v } else { v * self.increment() })
    }

    /// Fanuc's `G76` at block `b`: the first block's words kept, or the
    /// second block's cycle expanded from where the tool stands.
    ///
    /// # Failures
    /// A word the cycle has not, one written with a point where the
    /// control takes a whole number, the second block before any first
    /// (its values would be the control's parameters, which the machine
    /// does not state), a cycle the control refuses.
    pub(super) fn fanuc_g76(
        &self,
        at: &mut Standing,
        b: &Block,
        said: &Said,
        rules: &FanucRules,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let fail = |m: String| self.err(self.place(b, at.k), m);
        let second = said.read.iter().any(|(c, ..)| *c == 'X' || *c == 'Z');
        let allowed: &[char] = if second {
            &['X', 'Z', 'R', 'P', 'Q', 'F']
        } else {
            &['P', 'Q', 'R']
        };
        let cycle = if second {
            "G76's second block"
        } else {
            "G76's first block"
        };
        if let Some(m) = foreign_word(said, allowed, cycle) {
            return Err(fail(m));
        }
        let whole = |c: char| -> Result<Option<Real>, LintError> {
            match Self::cycle_word(said, c) {
                Some((_, true)) => Err(fail(format!(
                    "G76 {c} with a decimal point: the control takes {c} as a whole number in its least input increment"
                ))),
                Some((v, false)) => Ok(Some(v)),
                None => Ok(None),
            }
        };
        if !second {
            let p = whole('P')?.ok_or_else(|| fail("G76 without P(m)(r)(a)".into()))?;
            let p = p as u64;
            if ![80, 60, 55, 30, 29, 0].contains(&(p % 100)) {
                return Err(fail(format!(
                    "G76 P..{:02}: the tool's angle must be 80, 60, 55, 30, 29 or 00",
                    p % 100
                )));
            }
            let first = FanucFirst {
                finishes: (p / 10_000) as u32,
                chamfer_tenths: ((p / 100) % 100) as u32,
                angle_deg: (p % 100) as Real,
                min_cut: whole('Q')?.map_or(0.0, |q| q * self.increment()),
                allowance: self.cycle_length(said, 'R').unwrap_or(0.0),
            };
            if whole('Q')?.is_none() || said.read.iter().all(|(c, ..)| *c != 'R') {
                return Err(fail(
                    "G76's first block without Q(dd_min) or R(d): the control would take them from its parameters, which the machine does not state; write both".into(),
                ));
            }
            at.st.fanuc_g76 = Some(first);
            return Ok(());
        }
        let Some(f) = at.st.fanuc_g76 else {
            return Err(fail(
                "G76's second block before its first (G76 P(m)(r)(a) Q(dd_min) R(d)): the control would take m, r, a, dd_min and d from its parameters, which the machine does not state".into(),
            ));
        };
        let need = |c: char, what: &str| fail(format!("G76 without {c}, {what}"));
        let end = self.g76_end(at, b, said)?;
        let (x, z, lead) = (end.x, end.z, end.lead);
        let cycle = FanucThreadCycle {
            finishes: f.finishes,
            chamfer_tenths: f.chamfer_tenths,
            angle_deg: f.angle_deg,
            min_cut: f.min_cut,
            allowance: f.allowance,
            x,
            z,
            taper: self.cycle_length(said, 'R').unwrap_or(0.0),
            height: whole('P')?.ok_or_else(|| need('P', "the thread's height"))? * self.increment(),
            first: whole('Q')?.ok_or_else(|| need('Q', "the first cut's depth"))?
                * self.increment(),
            lead,
            constant_depth: false,
        };
        self.g76_moves(at, b, &cycle, rules, &end, out)
    }

    /// The one-block `G76 X Z I K D A P F` at block `b` (I the taper, K
    /// the height, D the first cut's depth, A the tool's angle, P the
    /// infeed: P1 one edge at a constant area, P3 one edge at a constant
    /// depth), expanded from where the tool stands with the least cut, the
    /// finishing allowance (one finishing pass takes it) and the chamfer
    /// the machine's constants give ([`ONE_BLOCK_SETTINGS`]).
    ///
    /// # Failures
    /// A word the cycle has not, a setting the machine does not state,
    /// P2 or P4 (alternating edges, whose shifts no public source gives),
    /// a cycle the control refuses.
    ///
    /// [`ONE_BLOCK_SETTINGS`]: crate::program::post::ONE_BLOCK_SETTINGS
    pub(super) fn one_block_g76(
        &self,
        at: &mut Standing,
        b: &Block,
        said: &Said,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let fail = |m: String| self.err(self.place(b, at.k), m);
        let allowed = ['X', 'Z', 'I', 'K', 'D', 'A', 'P', 'F'];
        if let Some(m) = foreign_word(said, &allowed, "the one-block G76") {
            return Err(fail(m));
        }
        let settings = crate::program::post::ONE_BLOCK_SETTINGS;
        let missing: Vec<String> = (settings.iter())
            .filter(|(name, _)| self.setting(name).is_none())
            .map(|(name, what)| format!("{name} ({what})"))
            .collect();
        if !missing.is_empty() {
            return Err(fail(format!(
                "the one-block G76 takes its least cut, finishing allowance and chamfer from the control's settings (Haas's 99, 86, 95, 96), which machine {} does not state: give {} among its constants",
                self.program.machine,
                missing.join(", ")
            )));
        }
        let setting = |name: &str| self.setting(name).unwrap_or_default();
        let need = |c: char, what: &str| fail(format!("G76 without {c}, {what}"));
        let method = Self::cycle_word(said, 'P').map_or(1.0, |(v, _)| v);
        let whole =
            (method.fract() == 0.0 && (1.0..=4.0).contains(&method)).then_some(method as u8);
        let constant_depth = match whole {
            Some(1) => false,
            Some(3) => true,
            Some(_) => {
                return Err(fail(format!(
                    "G76 P{method}: alternating edges, whose shifts from pass to pass no public source gives as a law; verify P1 or P3, or the passes written as blocks"
                )))
            }
            None => {
                return Err(fail(format!(
                    "G76 P{method}: the infeed is P1 to P4 (one edge or alternating, a constant area or depth)"
                )))
            }
        };
        let leads = setting("thread_chamfer_leads");
        let tenths = (leads * 10.0).round();
        if !((0.0..=99.0).contains(&tenths)
            && (tenths - leads * 10.0).abs() < crate::tolerance::COUNT_SLACK)
        {
            return Err(fail(format!(
                "the machine's thread_chamfer_leads {leads}: the verification follows a chamfer of 0 to 9.9 leads, in tenths"
            )));
        }
        let end = self.g76_end(at, b, said)?;
        let (x, z, lead) = (end.x, end.z, end.lead);
        let cycle = FanucThreadCycle {
            finishes: 1,
            chamfer_tenths: tenths as u32,
            angle_deg: Self::cycle_word(said, 'A').map_or(0.0, |(v, _)| v),
            min_cut: setting("thread_min_cut"),
            allowance: setting("thread_finish_allowance"),
            x,
            z,
            taper: self.cycle_length(said, 'I').unwrap_or(0.0),
            height: self
                .cycle_length(said, 'K')
                .ok_or_else(|| need('K', "the thread's height"))?,
            first: self
                .cycle_length(said, 'D')
                .ok_or_else(|| need('D', "the first cut's depth"))?,
            lead,
            constant_depth,
        };
        let rules = FanucRules {
            chamfer_deg: setting("thread_chamfer_deg"),
        };
        self.g76_moves(at, b, &cycle, &rules, &end, out)
    }

    /// Where a Fanuc-kind G76 at block `b` (its words `said`) starts and
    /// ends: the drive line's point and axes, the thread's end (X where
    /// the cycle writes it, else the start's), the lead (F, else the
    /// modal one).
    fn g76_end(&self, at: &Standing, b: &Block, said: &Said) -> Result<G76End, LintError> {
        let need =
            |c: char, what: &str| self.err(self.place(b, at.k), format!("G76 without {c}, {what}"));
        let (start, xz) = self.cycle_ready(at, b, 76)?;
        let x = Self::cycle_word(said, 'X').map_or(start[0], |(v, _)| v);
        let z = Self::cycle_word(said, 'Z')
            .map(|(v, _)| v)
            .ok_or_else(|| need('Z', "the thread's end"))?;
        let lead = match Self::cycle_word(said, 'F') {
            Some((v, _)) => v,
            None => at.st.lead.ok_or_else(|| need('F', "the lead"))?,
        };
        Ok(G76End {
            start,
            xz,
            x,
            z,
            lead,
        })
    }

    /// A Fanuc-kind G76 `cycle` at block `b` from `end`'s start expanded
    /// by `rules`, its lead modal after it, its moves pushed to `out`.
    fn g76_moves(
        &self,
        at: &mut Standing,
        b: &Block,
        cycle: &FanucThreadCycle,
        rules: &FanucRules,
        end: &G76End,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let diameter = self.program.setup.radial == Some(super::Radial::Diameter);
        let moves = crate::program::cycle::expand_fanuc(cycle, end.start, diameter, rules)
            .map_err(|e| self.err(self.place(b, at.k), e.message))?;
        at.st.f = Some(end.lead);
        at.st.lead = Some(end.lead);
        self.cycle_moves(at, b, &moves, end.xz, out)
    }

    /// Fanuc's modal `G92` at block `b`: one pass from where the run of
    /// G92 blocks started, to the block's X (its Z, F and R, or the last
    /// block's).
    ///
    /// # Failures
    /// A word the cycle has not, no lead, the modal state a cut needs.
    pub(super) fn g92(
        &self,
        at: &mut Standing,
        b: &Block,
        said: &Said,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let fail = |m: String| self.err(self.place(b, at.k), m);
        if !self.d.reading.g92_thread {
            return Err(fail("G92: not a threading cycle of this dialect".into()));
        }
        if let Some(m) = foreign_word(said, &['X', 'Z', 'F', 'R'], "G92") {
            return Err(fail(m));
        }
        let (here, xz) = self.cycle_ready(at, b, 92)?;
        let start = *at.st.cycle_start.get_or_insert(here);
        if let Some(f) = Self::cycle_word(said, 'F').map(|(v, _)| v) {
            at.st.f = Some(f);
            at.st.lead = Some(f);
        }
        let lead = at
            .st
            .lead
            .ok_or_else(|| fail("G92 before any lead F".into()))?;
        let x = Self::cycle_word(said, 'X')
            .map(|(v, _)| v)
            .or(at.st.g92_x)
            .ok_or_else(|| fail("G92 without X".into()))?;
        let z = Self::cycle_word(said, 'Z')
            .map(|(v, _)| v)
            .or(at.st.g92_z)
            .ok_or_else(|| fail("G92 without Z".into()))?;
        let taper = self.cycle_length(said, 'R').unwrap_or(0.0);
        at.st.g92_x = Some(x);
        at.st.g92_z = Some(z);
        let diameter = self.program.setup.radial == Some(super::Radial::Diameter);
        let moves = crate::program::cycle::fanuc_g92(start, x, z, taper, lead, diameter);
        at.st.motion = Some(92);
        self.cycle_moves(at, b, &moves, xz, out)
    }
}
