//! A block's addresses taken into the modal state (the axes, the feed,
//! the lead, the spindle's speed, a thread's start) and its move, if it
//! has one: the motion in force, the thread's lead and start, every axis's
//! value held to the axis program's and to the axis's travel.

use super::{
    at_line, cutting_fault, outside_thread, placed, setup_fault, Block, ReadMove, Reader, Said,
    Standing, State,
};
use crate::math::Real;
use crate::program::lint::LintError;
use crate::toolpath::Motion;

/// What a block's addresses give, besides what the modal state keeps.
struct Given {
    /// Each axis's value where the block writes it.
    axes: Vec<Option<Real>>,
    /// The thread's lead, where the block gives one.
    lead: Option<Real>,
    /// The lead by its own address (K), which only a thread block reads.
    lead_word: Option<String>,
    /// The spindle's speed S, where the block writes it.
    speed: Option<Real>,
    /// An arc's centre from its start, I (along X) and K (along Z), where
    /// the block is an arc's and gives them.
    centre: [Option<Real>; 2],
}

impl Reader<'_> {
    /// Block `b`'s addresses (`said`) into the modal state and, where it
    /// moves an axis, its move pushed to `out`.
    ///
    /// # Failures
    /// An address the verification cannot simulate, a speed or feed out
    /// of range, a lead or start angle outside a thread block, a move the
    /// modal state or the axis program does not allow.
    pub(super) fn moves(
        &self,
        at: &mut Standing,
        b: &Block,
        mut said: Said,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let k = at.k;
        let fail = |m: String| self.err(self.place(b, k), m);
        let arc = match said.motion.or(at.st.motion) {
            Some(2) => Some(true),
            Some(3) => Some(false),
            _ => None,
        };
        if let Some((_, w)) =
            (said.arc.radius.as_ref().or(said.arc.angle.as_ref())).filter(|_| arc.is_none())
        {
            return Err(fail(format!(
                "{w}: an arc's word outside an arc block (G2, G3)"
            )));
        }
        self.clamp_word(at, b, &mut said)?;
        let read = std::mem::take(&mut said.read);
        let given = self.addresses(&mut at.st, b, k, read, arc.is_some())?;
        if let Some(m) = said.motion {
            at.st.motion = Some(m);
        }
        if let Some(l) = given.lead {
            at.st.lead = Some(l);
        }
        let moves = given.axes.iter().any(Option::is_some);
        if let Some(v) = self.surface_words(at, b, &said, given.speed, moves)? {
            self.speed(at, b, v, moves)?;
        }
        if !moves {
            if said.motion.is_some() {
                return Err(fail("a motion word with no axis".into()));
            }
            if let Some(w) = &given.lead_word {
                return Err(fail(self.lead_outside(w)));
            }
            if let Some(w) = &said.start_word {
                return Err(fail(outside_thread(w, self.d)));
            }
            return Ok(());
        }
        // A move: the modal values carried, held to the axis program.
        let block = if self.reading {
            None
        } else {
            self.program.blocks.get(k)
        };
        if !self.reading && block.is_none() {
            return Err(self.err(
                at_line(b.line),
                format!(
                    "a move beyond the axis program's {} blocks",
                    self.program.blocks.len()
                ),
            ));
        };
        let before = arc.map(|_| placed(&at.st));
        let from = (at.st.surface)
            .then(|| self.radial_index().and_then(|i| placed(&at.st)[i]))
            .flatten();
        for (i, v) in given.axes.iter().enumerate() {
            if let Some(v) = v {
                at.st.values[i] = Some(*v);
            }
        }
        if at.st.surface {
            let rapid = said.motion.or(at.st.motion) == Some(0);
            self.surface_move(at, b, from, rapid, arc.is_some())?;
        }
        let motion = self.motion(&mut at.st, b, k, &given, &said.start_word, block)?;
        let going = self.going(&at.st, b, k, block)?;
        if let (Some(clockwise), Some(before)) = (arc, before) {
            return self.arc(at, b, clockwise, &said, given.centre, &before, going, out);
        }
        // The move as read (a lint reads it too: what a run verifies).
        let (file, via) = self.origin(at);
        let st = &at.st;
        out.push(ReadMove {
            motion,
            values: going,
            feed: match motion {
                Motion::Rapid => 0.0,
                Motion::Linear => st.f.unwrap_or_default(),
                Motion::Thread { lead, .. } => lead * st.speed.unwrap_or_default(),
            },
            spindle: at.speed_next.take(),
            dwell_s: at.take_dwell(),
            comment: at.pending.take(),
            number: b.number,
            line: b.line,
            file,
            via,
        });
        at.k += 1;
        Ok(())
    }

    /// The refusal of a lead word `w` outside a thread block.
    fn lead_outside(&self, w: &str) -> String {
        format!(
            "{w}: a thread's lead outside a thread block ({} reads {} as the lead of {} only)",
            self.d.name, self.lead_letter, self.d.thread
        )
    }

    /// Block `b`'s addresses (`read`; `k` moves read before it): the
    /// feed and a thread's start into the modal state `st`, the rest
    /// given back.
    fn addresses(
        &self,
        st: &mut State,
        b: &Block,
        k: usize,
        read: Vec<(char, Real, String)>,
        arc: bool,
    ) -> Result<Given, LintError> {
        let (d, program) = (self.d, self.program);
        let fail = |m: String| self.err(self.place(b, k), m);
        let mut given = Given {
            axes: vec![None; self.names.len()],
            lead: None,
            lead_word: None,
            speed: None,
            centre: [None, None],
        };
        for (letter, v, text) in read {
            if let Some(i) = self.names.iter().position(|n| *n == letter) {
                given.axes[i] = Some(v * self.radial_scale(st, letter));
                continue;
            }
            match letter {
                'I' if arc => {
                    given.centre[0] = Some(v);
                    continue;
                }
                'K' if arc => {
                    given.centre[1] = Some(v);
                    continue;
                }
                _ => {}
            }
            if letter == 'F' && !(v > 0.0) {
                return Err(fail(format!("{text}: a feed is a positive number")));
            }
            match letter {
                // One modal F where the lead's address is the feed's
                // (Fanuc): a feed written on a G01 is the next thread's
                // lead, and a lead the next G01's feed.
                'F' if self.lead_letter == 'F' => {
                    st.feed = true;
                    st.f = Some(v);
                    given.lead = Some(v);
                }
                'F' => {
                    st.feed = true;
                    st.f = Some(v);
                }
                'S' => given.speed = Some(v),
                c if d.reading.offset_word == Some(c) => {}
                c if self.start_letter == Some(c) => st.start_deg = v / self.start_scale,
                '@' => st.start_deg = v,
                c if c == self.lead_letter => {
                    given.lead = Some(v);
                    given.lead_word = Some(text);
                }
                c if self.reading => {
                    // What the address means on this control, where its
                    // table says (Fanuc system A's U and W).
                    let named = (d.reading.meanings.iter())
                        .find(|m| m.0.len() == 1 && m.0.starts_with(c))
                        .map_or_else(String::new, |m| format!(" ({} on {})", m.1, d.name));
                    return Err(fail(format!(
                        "{text}{named}: a word the verification cannot simulate ({} on {} reads the axes {}, F, S, T{})",
                        d.name,
                        program.machine,
                        self.names.iter().collect::<String>(),
                        self.start_letter.map(|c| format!(", {c}")).unwrap_or_default()
                    )));
                }
                _ => {
                    return Err(fail(format!(
                        "{text}: not a word of {} on {}",
                        d.name, program.machine
                    )))
                }
            }
        }
        Ok(given)
    }

    /// The spindle's speed `v` block `b` writes (`moves`: with a move of
    /// its own): the axis program's where the text is held to one, within
    /// the spindle's range, the program's or the next move's.
    fn speed(&self, at: &mut Standing, b: &Block, v: Real, moves: bool) -> Result<(), LintError> {
        let (k, program) = (at.k, self.program);
        let fail = |m: String| self.err(self.place(b, k), m);
        // The speed the axis program sets here: a move's own where it
        // changes, the program's before the moves.
        let want = if moves {
            program.blocks.get(k).and_then(|b| b.spindle)
        } else {
            Some(program.spindle_rpm)
        }
        .map(Real::round);
        if k == 0 && !moves {
            at.rpm = Some(v);
        } else {
            at.speed_next = Some(v);
        }
        if !self.reading && want != Some(v) {
            return Err(fail(format!(
                "S{v} read back, where the axis program sets {}",
                want.map_or("no speed".to_owned(), |w| format!("S{w}"))
            )));
        }
        if !(v >= 1.0) {
            return Err(fail(format!(
                "S{v}: the spindle would stand while the program cuts"
            )));
        }
        if let Some(a) = self.spindle.filter(|a| !(v >= a.min && v <= a.max)) {
            return Err(fail(format!(
                "S{v} is outside spindle {}'s range [{}, {}] rpm",
                a.name, a.min, a.max
            )));
        }
        at.st.speed = Some(v);
        Ok(())
    }

    /// The motion of block `b`'s move (`k` moves before it) in the modal
    /// state `st`: a motion word in force, the axis program's `block`'s
    /// kind, a feed, the spindle and the setup for a cut; a thread's lead
    /// and start as the axis program's.
    fn motion(
        &self,
        st: &mut State,
        b: &Block,
        k: usize,
        given: &Given,
        start_word: &Option<String>,
        block: Option<&crate::program::Block>,
    ) -> Result<Motion, LintError> {
        let (d, program) = (self.d, self.program);
        let fail = |m: String| self.err(self.place(b, k), m);
        let Some(m) = st.motion else {
            return Err(fail("a move before any motion word (G0, G1)".into()));
        };
        if m == 76 {
            return Err(fail(
                "a move under a threading cycle's modal G76 without its words: write G0 or G1 first"
                    .into(),
            ));
        }
        let is_thread = m == 32 || m == 33;
        if let Some(w) = given.lead_word.as_ref().filter(|_| !is_thread) {
            return Err(fail(self.lead_outside(w)));
        }
        if let Some(bl) = block {
            let want = match bl.motion {
                Motion::Rapid => m == 0,
                Motion::Linear => m == 1,
                Motion::Thread { .. } => is_thread,
            };
            if !want {
                return Err(fail(format!(
                    "G{m}, where the axis program has a {:?} move",
                    bl.motion
                )));
            }
        }
        if matches!(m, 1..=3) && !st.feed {
            return Err(fail(format!("G{m} before any feed F")));
        }
        if let Some(m) = (m != 0)
            .then(|| cutting_fault(st, d, &program.setup, "a cutting move"))
            .flatten()
        {
            return Err(fail(m));
        }
        if let Some(w) = start_word.as_ref().filter(|_| !is_thread) {
            return Err(fail(outside_thread(w, d)));
        }
        if let Some(m) = setup_fault(st, d, program, "a move") {
            return Err(fail(m));
        }
        let read_lead = st.lead.unwrap_or(Real::NAN);
        let motion = match m {
            0 => Motion::Rapid,
            // An arc is followed by chords (`arcs`).
            1..=3 => Motion::Linear,
            _ => Motion::Thread {
                lead: read_lead,
                start_deg: st.start_deg,
            },
        };
        if is_thread {
            self.thread(st, b, k, given.lead, block)?;
        }
        Ok(motion)
    }

    /// A thread block's lead (`lead` the block's own, where it gives one)
    /// and start in the modal state `st`, as the dialect needs them and as
    /// the axis program's `block` has them.
    fn thread(
        &self,
        st: &mut State,
        b: &Block,
        k: usize,
        lead: Option<Real>,
        block: Option<&crate::program::Block>,
    ) -> Result<(), LintError> {
        let d = self.d;
        let fail = |m: String| self.err(self.place(b, k), m);
        let read_lead = st.lead.unwrap_or(Real::NAN);
        if st.surface {
            return Err(fail(
                "a thread under constant surface speed (G96): its lead is tied to the spindle's turn, whose speed G96 changes with the diameter; write G97 S(rpm) before it".into(),
            ));
        }
        if d.lead_every_block && lead.is_none() {
            return Err(fail(format!("a thread block without its lead {}", d.lead)));
        }
        if d.reading.thread_needs_constant_speed && !st.constant_speed {
            return Err(fail("a thread before constant spindle speed (G97)".into()));
        }
        if !(read_lead > 0.0) {
            return Err(fail("a thread block before any lead".into()));
        }
        if let Some(Motion::Thread { lead, start_deg }) = block.map(|b| b.motion) {
            if !((read_lead - lead).abs()
                <= 0.5 * 10f64.powi(-(d.lead_decimals as i32)) + crate::tolerance::SAME_LENGTH)
            {
                return Err(fail(format!("lead {read_lead}, the axis program's {lead}")));
            }
            if (st.start_deg - start_deg).abs() > 1e-3 {
                return Err(fail(format!(
                    "thread start {} deg, the axis program's {start_deg} deg",
                    st.start_deg
                )));
            }
        }
        if d.thread_start.is_some_and(|t| !t.modal) {
            st.start_deg = 0.0; // Fanuc's Q holds for its block only
        }
        Ok(())
    }

    /// Where each axis goes on block `b`'s move (`k` moves before it):
    /// its value in the modal state `st` with the offsets' shifts, held to
    /// the axis program's `block` and to the axis's travel.
    fn going(
        &self,
        st: &State,
        b: &Block,
        k: usize,
        block: Option<&crate::program::Block>,
    ) -> Result<Vec<Option<Real>>, LintError> {
        let (program, half) = (self.program, self.half);
        let fail = |m: String| self.err(self.place(b, k), m);
        let going = placed(st);
        for (i, name) in program.axes.iter().enumerate() {
            if block.is_some_and(|b| b.keep.contains(&name.name)) {
                continue;
            }
            let v = match (st.values[i], block) {
                (Some(v), _) => v,
                // Read: an axis not yet written stands where it stands.
                (None, None) => continue,
                (None, Some(_)) => {
                    return Err(fail(format!("axis {} has no value yet", name.name)))
                }
            };
            if let Some(bl) = block.filter(|bl| !((v - bl.values[i]).abs() <= half)) {
                return Err(fail(format!(
                    "{}{v} read back, the axis program's {}",
                    name.name,
                    crate::math::fixed(bl.values[i], self.decimals + 2)
                )));
            }
            self.within_travel(b, k, i, v, going[i].unwrap_or(v))?;
        }
        Ok(going)
    }

    /// Axis `i`'s value `v` (`shifted` with the offsets' shifts) on block
    /// `b`'s move (`k` moves before it) held to the axis's travel.
    pub(super) fn within_travel(
        &self,
        b: &Block,
        k: usize,
        i: usize,
        v: Real,
        shifted: Real,
    ) -> Result<(), LintError> {
        let (name, half) = (&self.program.axes[i].name, self.half);
        if let Some(a) = self.axes.iter().find(|a| a.name == *name) {
            let (lo, hi) = (a.to_user(a.min), a.to_user(a.max));
            if shifted < lo - half || shifted > hi + half {
                let by = if shifted == v {
                    String::new()
                } else {
                    format!(" (at {shifted} with the offsets' shift)")
                };
                return Err(self.err(
                    self.place(b, k),
                    format!("{name}{v}{by} is outside the axis's travel [{lo}, {hi}]"),
                ));
            }
        }
        Ok(())
    }

    /// What an axis value of `letter` is multiplied by to be in the
    /// machine's setup's programming: 1, but for the radial axis of a
    /// program read as it stands that switched to the other programming
    /// by the dialect's own word (Sinumerik's `DIAMON` on a machine
    /// programmed on radius: a half).
    fn radial_scale(&self, st: &State, letter: char) -> Real {
        let setup = &self.program.setup;
        let radial = setup.radial_axis.chars().next().unwrap_or('X');
        let (Some(now), Some(want)) = (st.radial, setup.radial) else {
            return 1.0;
        };
        if !self.reading || self.radial.is_none() || letter != radial {
            return 1.0;
        }
        match (now, want == pilgrim_plugin_abi::types::Radial::Diameter) {
            (true, false) => 0.5,
            (false, true) => 2.0,
            _ => 1.0,
        }
    }
}
