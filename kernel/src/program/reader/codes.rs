//! A block's words as its control reads them: the G and M codes (the
//! spindle, the coolant, the end and the setup's codes taken into the
//! modal state at once; the work offset and the plane held to the first),
//! the tool call, and the addresses with their values.

use super::{keep_first, power_on_code, Block, OwnWord, Reader, Said, Standing, State};
use crate::program::lint::LintError;
use crate::program::words::Word;

impl Reader<'_> {
    /// What block `b`'s words say, the block the next move's, each word
    /// checked as its control reads it.
    pub(super) fn words_of(&self, at: &mut Standing, b: &Block) -> Result<Said, LintError> {
        let mut said = Said::default();
        let mut start_angle = None;
        for w in &b.own {
            match w {
                OwnWord::Radial(diameter) => {
                    let (radius, on_diameter) = self.d.radial_words.unwrap_or_default();
                    let word = if *diameter { on_diameter } else { radius };
                    said.radial.push((*diameter, word.into()));
                }
                OwnWord::FeedGroup(list) => said.feed_group.push(list.clone()),
                OwnWord::StartAngle(v) => {
                    start_angle = Some(*v);
                    said.start_word = Some(format!("SF={v}"));
                }
                OwnWord::ArcRadius(v, text) => said.arc.radius = Some((*v, text.clone())),
                OwnWord::ArcAngle(v, text) => said.arc.angle = Some((*v, text.clone())),
                OwnWord::SpeedLimit(v, text) => {
                    if !(v.is_finite() && *v >= 1.0) {
                        return Err(self.err(
                            self.place(b, at.k),
                            format!("{text}: a spindle's clamp is a speed of at least 1 rpm"),
                        ));
                    }
                    at.st.clamp = Some(*v);
                }
            }
        }
        let mut letters: Vec<char> = Vec::new();
        for w in &b.tokens {
            if w.letter != 'G' && w.letter != 'M' {
                if letters.contains(&w.letter) {
                    return Err(self.err(
                        self.place(b, at.k),
                        format!("{}: {} twice in one block", w.text(), w.letter),
                    ));
                }
                letters.push(w.letter);
            }
            match w.letter {
                'G' | 'M' => self.code_word(&mut at.st, b, at.k, w, &mut said)?,
                'T' => self.tool_call(at, b, w)?,
                _ => self.address(&mut at.st, b, at.k, w, &mut said)?,
            }
        }
        if let Some(s) = start_angle {
            said.read.push(('@', s, format!("SF={s}")));
        }
        Ok(said)
    }

    /// A G or M code `w` of block `b` (`k` moves before it): refused where
    /// the dialect's table has it not (named with what it means on this
    /// control, where the table says); the spindle, the coolant and the
    /// end taken into the modal state `st`, a motion kept for the block,
    /// the work offset and the plane held to the first, the setup's codes
    /// noted as stated.
    fn code_word(
        &self,
        st: &mut State,
        b: &Block,
        k: usize,
        w: &Word,
        said: &mut Said,
    ) -> Result<(), LintError> {
        let d = self.d;
        let listed = if w.letter == 'G' {
            d.reading.g_codes
        } else {
            d.reading.m_codes
        };
        let code = self.code_number(w);
        // A shop's program may hold what pilgrim never writes (its cycles).
        let read_too = if self.reading && w.letter == 'G' {
            d.reading.read_g_codes
        } else {
            &[]
        };
        let Some(n) = code.filter(|n| listed.contains(n) || read_too.contains(n)) else {
            // What the code means on this control, where the dialect's
            // table says: never another dialect's.
            let named = (w.code().map(|c| format!("{}{c}", w.letter)))
                .and_then(|c| d.reading.meanings.iter().find(|m| m.0 == c))
                .map_or_else(String::new, |m| format!(" ({} on {})", m.1, d.name));
            return Err(self.err(
                self.place(b, k),
                format!("{}{named}{}", w.text(), self.not_read),
            ));
        };
        let by = || Some(format!("{} at {}", w.text(), self.place(b, k)));
        if w.letter == 'M' {
            match n {
                3 | 5 if st.spindle_on != (n == 3) => {
                    st.spindle_on = n == 3;
                    st.spindle_by = by();
                }
                8 | 9 if st.coolant != (n == 8) => {
                    st.coolant = n == 8;
                    st.coolant_by = by();
                }
                n if n == d.reading.end_code => {
                    st.ended = true;
                    st.ended_by = by();
                }
                _ => {}
            }
            return Ok(());
        }
        match n {
            0 | 1 | 2 | 3 | 32 | 33 | 76 | 92 => {
                if let Some(m) = said.motion {
                    return Err(self.err(
                        self.place(b, k),
                        format!("G{m} and {} in one block: two motions", w.text()),
                    ));
                }
                said.motion = Some(n)
            }
            96 | 97 => {
                said.surface = Some(n == 96);
                st.constant_speed = n == 97;
                st.surface = n == 96;
            }
            50 => said.clamp = true,
            // LinuxCNC's diameter (G7) and radius (G8) modes.
            7 | 8 => said.radial.push((n == 7, w.text())),
            n if d.reading.work_offsets.contains(&n) => {
                // A switch the offsets table gives is no setup code stated.
                let shifted = self.work_offset(st, b, k, w, n)?;
                if shifted {
                    return Ok(());
                }
            }
            17..=19 => self.plane(st, b, k, w, n)?,
            _ => {}
        }
        // The setup's codes stated (a code restated, or one the setup does
        // not need, changes nothing kept).
        if d.reading.setup_codes.contains(&n) && !st.stated.contains(&n) {
            st.stated.push(n);
        }
        Ok(())
    }

    /// The number of code word `w` as the dialect reads it: to a tenth
    /// where it does (LinuxCNC's G1.0 is G1), else a whole number; `None`
    /// for a code it does not read so.
    pub(super) fn code_number(&self, w: &Word) -> Option<u32> {
        if self.d.reading.code_tenths {
            w.whole()
        } else {
            w.integer()
        }
    }

    /// Work offset `n` (the word `w`): the part zero is the work offset
    /// the program selects first (before its moves: the one in force at
    /// power-on, the first listed, if none); a switch the offsets table
    /// gives moves the axes by its shift (back to the first: none), any
    /// other is refused. True where a switch (or the first again) set the
    /// shift.
    fn work_offset(
        &self,
        st: &mut State,
        b: &Block,
        k: usize,
        w: &Word,
        n: u32,
    ) -> Result<bool, LintError> {
        let (d, program) = (self.d, self.program);
        let power_on = (k > 0).then(|| {
            (
                power_on_code(d, program, d.reading.work_offsets)
                    .unwrap_or(d.reading.work_offsets[0]),
                "power-on, before the moves".into(),
            )
        });
        let first = st.work_offset.as_ref().map(|(c, _)| *c);
        let table = (first.filter(|c| *c != n)).and_then(|_| self.work_shift(&format!("G{n}")));
        if first == Some(n) {
            st.work_shift = Vec::new();
            return Ok(true);
        }
        if let Some(shift) = table {
            st.work_shift = shift;
            return Ok(true);
        }
        keep_first(&mut st.work_offset, power_on, n, || self.place(b, k)).map_err(|(c, at)| {
            self.err(
                self.place(b, k),
                format!(
                    "{}: a switch of the work offset from G{c} ({at}), the part zero the verification places the part at (another part zero moves every later block); verify a program that keeps one, or give the offset's shift in an --offsets file",
                    w.text()
                ),
            )
        })?;
        Ok(false)
    }

    /// Plane `n` (G17, G18, G19; the word `w`): the plane the machine's
    /// setup states (the tool's length offsets and arcs follow it), or
    /// the first selected; another is refused.
    fn plane(
        &self,
        st: &mut State,
        b: &Block,
        k: usize,
        w: &Word,
        n: u32,
    ) -> Result<(), LintError> {
        let (d, program) = (self.d, self.program);
        let setup = match program.setup.plane {
            Some(p) => Some((
                crate::program::post::plane_code(p),
                "the machine's setup".into(),
            )),
            None => power_on_code(d, program, &[17, 18, 19])
                .map(|c| (c, "the machine's power-on state".into())),
        };
        keep_first(&mut st.plane, setup, n, || {
            format!("{} at {}", w.text(), self.place(b, k))
        })
        .map_err(|(c, at)| {
            self.err(
                self.place(b, k),
                format!(
                    "{}: another plane than G{c} ({at}); the tool's length offsets and arcs follow the plane, which the verification keeps",
                    w.text()
                ),
            )
        })
    }

    /// The tool call `w` of block `b`: before the moves, the family's tool
    /// with its own offset (a lathe's `T0303`: the model's tool is the tool
    /// with its own offset), or one the offsets table gives.
    fn tool_call(&self, at: &mut Standing, b: &Block, w: &Word) -> Result<(), LintError> {
        let fail = |m: String| self.err(self.place(b, at.k), m);
        if at.k > 0 {
            return Err(fail(format!("a tool call {} among the moves", w.text())));
        }
        let n = w
            .integer()
            .ok_or_else(|| fail(format!("{}: a tool call is a whole number", w.text())))?;
        let tool = if self.d.reading.tool_and_offset {
            let (tool, offset) = (n / 100, n % 100);
            let table = (n >= 100 && offset != tool)
                .then(|| self.tool_shift(&format!("T{n:04}")))
                .flatten();
            if let Some(shift) = table {
                at.st.tool_shift = shift;
            } else if n < 100 || offset != tool {
                return Err(fail(format!(
                    "{}: tool {tool:02} with offset {offset:02}; the verification's tool is a tool with its own offset (T{tool:02}{tool:02}: 00 cancels the offset, another number is another tool's), or one an --offsets file gives",
                    w.text()
                )));
            }
            tool
        } else {
            n
        };
        at.tool = Some(tool);
        // Another tool has its own shape and offsets: the verification
        // models the family's.
        if tool != self.program.tool_number {
            return Err(fail(format!(
                "{}: another tool than T{}, the family's, whose shape the verification models",
                w.text(),
                self.program.tool_number
            )));
        }
        Ok(())
    }

    /// An address with its value, `w` of block `b`: its decimal point as
    /// the dialect reads it, an axis value without one in the control's
    /// least input unit where it says so, a tool offset word held to the
    /// tool call's or the offsets table's.
    fn address(
        &self,
        st: &mut State,
        b: &Block,
        k: usize,
        w: &Word,
        said: &mut Said,
    ) -> Result<(), LintError> {
        let (d, letter) = (self.d, w.letter);
        let fail = |m: String| self.err(self.place(b, k), m);
        if d.reading.point_needed.contains(letter) && !w.has_point() {
            return Err(fail(format!(
                "{}: a number without its decimal point, which {} reads by a parameter of the control; write {}.",
                w.text(),
                d.name,
                w.text()
            )));
        }
        if d.reading.no_point.contains(letter) && w.has_point() {
            return Err(fail(format!(
                "{}: a decimal point in a word {} reads as a whole number",
                w.text(),
                d.name
            )));
        }
        let v = match self.least_input {
            Some(unit) if !w.has_point() && self.names.contains(&letter) => w.value() * unit,
            _ => w.value(),
        };
        if self.start_letter == Some(letter) {
            said.start_word = Some(w.text());
        }
        if d.reading.offset_word == Some(letter) {
            let other = format!(
                "{}: another tool offset than {letter}1, the tool call's, which is the verification's tool ({letter}0 cancels it, another number is another edge's)",
                w.text()
            );
            st.tool_shift = match w.integer() {
                Some(1) => Vec::new(),
                Some(n) => self.tool_shift(&format!("{letter}{n}")).ok_or_else(|| {
                    fail(format!(
                        "{other}; an --offsets file that gives {letter}{n} says where it moves the tool"
                    ))
                })?,
                None => return Err(fail(other)),
            };
        }
        said.read.push((letter, v, w.text()));
        Ok(())
    }
}
