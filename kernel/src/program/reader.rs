//! The G-code reader: a program's text line by line, as its control reads
//! it, into moves. One reader serves the lint of every program pilgrim
//! writes ([`super::lint`]), `verify`'s reading of a program from a file
//! and anything that reads G-code later.
//!
//! It steps: a [`Reader`] holds what does not change over a text (the
//! dialect, the machine's axes, the axis program the text is held to),
//! and a [`Standing`] what the text has said so far (the modal state, the
//! move count, the last block number, the pass's comment). A caller that
//! keeps a [`Standing`] can read a changed line from it and go on, which
//! is how a mutation test reads millions of one-word edits of a program
//! without reading the program again for each: the reading after a line
//! depends only on the standing before it and the line.

use super::lint::{LintError, Linted};
use super::post::{Dialect, Style};
use super::{name_in, AxisProgram, ProgramSetup};
use crate::machine::{Axis, AxisKind};
use crate::math::Real;
use crate::toolpath::Motion;
use pilgrim_plugin_abi::types::Radial;

/// A move as the reader took it: each axis's value where the text has
/// given one so far.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadMove {
    /// Rapid, linear or thread (with the lead and start read).
    pub motion: Motion,
    /// Each axis's value (the axis program's axes, in its order), where
    /// the text has written one so far.
    pub values: Vec<Option<Real>>,
    /// The feed (mm/min; a thread's lead times the speed; 0 on a rapid).
    pub feed: Real,
    /// The spindle's speed where the text sets one for this move.
    pub spindle: Option<Real>,
    /// The last comment line since the move before: the pass it begins.
    pub comment: Option<String>,
    /// Its block number, where the text numbers blocks.
    pub number: Option<u32>,
    /// The line it stands on (from 0).
    pub line: usize,
}

/// Where a reading stands between two lines: the control's modal state
/// and what the text has said of itself so far. Two readings of one text
/// that stand equal before a line read the rest alike.
#[derive(Debug, Clone, PartialEq)]
pub struct Standing {
    st: State,
    /// The last block number read.
    last_n: Option<u32>,
    /// Moves read so far (the next move of the axis program).
    k: usize,
    /// The last comment line since the last move.
    pending: Option<String>,
    /// A speed set among the moves, for the next move.
    speed_next: Option<Real>,
    /// The name, number, tool and speed the text gives itself.
    name: Option<String>,
    number: Option<u32>,
    tool: Option<u32>,
    rpm: Option<Real>,
}

impl Standing {
    /// Moves read so far.
    pub fn moves(&self) -> usize {
        self.k
    }

    /// The program's name as its first line gives it, if it does.
    pub fn name(&self) -> Option<&str> {
        self.name.as_deref()
    }

    /// The program's number as its `O` line gives it, if it does.
    pub fn number(&self) -> Option<u32> {
        self.number
    }

    /// The tool the text calls, if it does.
    pub fn tool(&self) -> Option<u32> {
        self.tool
    }

    /// The spindle speed the text sets before its moves, if it does.
    pub fn rpm(&self) -> Option<Real> {
        self.rpm
    }
}

/// What stays the same over one text: the dialect, the program it is held
/// to (or the frame it is read into), the machine's axes, and what follows
/// from them.
pub struct Reader<'a> {
    d: &'a Dialect,
    program: &'a AxisProgram,
    axes: &'a [Axis],
    reading: bool,
    /// Lines of the text (its last line feed ends the last).
    lines: usize,
    framed: bool,
    decimals: usize,
    half: Real,
    lead_letter: char,
    start_letter: Option<char>,
    start_scale: f64,
    names: Vec<char>,
    program_number: String,
    header_name: Option<String>,
    radial: Option<(&'static str, &'static str)>,
    start: Option<&'static str>,
    spindle: Option<&'a Axis>,
    ticker: crate::budget::Ticker,
    /// The refusal of a code the dialect's table has not ([`not_read`]).
    not_read: String,
    /// The unit of an axis number without its decimal point, where it is
    /// not a millimetre (the machine's power-on state, else the dialect's).
    least_input: Option<Real>,
    /// The shop's offset table, where the caller gives one (read only).
    offsets: Option<&'a super::offsets::Offsets>,
}

/// Whether a G-code text is held to an axis program (the lint of a
/// program pilgrim wrote) or read as it stands ([`read`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Held to the axis program pilgrim wrote it from.
    Lint,
    /// Read as it stands.
    Read,
}

/// The modal state a G-code program has set so far.
#[derive(Debug, Clone, Default, PartialEq)]
struct State {
    motion: Option<u32>,
    feed: bool,
    /// The feed F as written, once written.
    f: Option<Real>,
    lead: Option<Real>,
    spindle_on: bool,
    /// The word and block that last started or stopped the spindle
    /// (`M5 at N70`), for a refusal to name.
    spindle_by: Option<String>,
    /// The spindle's speed as written (S), none before the first.
    speed: Option<Real>,
    coolant: bool,
    /// The word and block that last turned the coolant on or off.
    coolant_by: Option<String>,
    constant_speed: bool,
    /// Diameter (true) or radius programming, once set.
    radial: Option<bool>,
    feed_group: bool,
    start_deg: Real,
    values: Vec<Option<Real>>,
    ended: bool,
    /// The word and block that ended the program.
    ended_by: Option<String>,
    /// The setup's G codes stated so far (`Reading::setup_codes`).
    stated: Vec<u32>,
    /// The work offset selected (G54..) and the block that selected it,
    /// once selected.
    work_offset: Option<(u32, String)>,
    /// The plane selected (G17, G18, G19) and the block that selected it.
    plane: Option<(u32, String)>,
    /// Each axis's shift by the tool offset in force, where the offsets
    /// table gives another than the tool call's own (empty: none).
    tool_shift: Vec<Real>,
    /// Each axis's shift by the work offset in force, against the first
    /// (empty: none).
    work_shift: Vec<Real>,
}

/// A word of Sinumerik's own, outside the ISO words [`super::words`] reads.
#[derive(Debug, Clone, PartialEq)]
enum OwnWord {
    /// `DIAMON` (true) or `DIAMOF`.
    Radial(bool),
    /// `FGROUP(..)` with its list.
    FeedGroup(String),
    /// `SF=`, the thread's start angle (deg).
    StartAngle(Real),
}

/// Line `i` of a G-code program in `d` as its control reads it: the code
/// with its comments blanked in place (the same length, so the words'
/// spans index the line), after checking that every comment is one the
/// dialect's comment writer makes ([`super::post::comment_text`]): closed
/// on its line, nothing but names' characters, nothing LinuxCNC acts on;
/// and that the line holds no character pilgrim never writes (a control
/// character such as a lone carriage return, which ends a line on some
/// controls; anything beyond ASCII). With it, the text of the line's last
/// comment.
fn read_line(d: &Dialect, i: usize, line: &str) -> Result<(String, Option<String>), String> {
    if let Some(c) = line.chars().find(|c| c.is_control() || !c.is_ascii()) {
        return Err(format!(
            "the character U+{:04X}, which pilgrim never writes (a carriage return or another control character ends or changes a line on some controls)",
            u32::from(c)
        ));
    }
    let check = |comment: &str| -> Result<(), String> {
        // A header line with nothing filled in is the dialect's own at its
        // place (Sinumerik's `;$PATH=/_N_MPF_DIR`), whatever it holds.
        if d.header
            .get(i)
            .is_some_and(|h| !h.contains('{') && *h == line)
        {
            return Ok(());
        }
        let text = comment.strip_prefix(' ').unwrap_or(comment);
        if let Some(c) = text.chars().find(|c| !crate::names::is_name_char(*c)) {
            return Err(format!(
                "'{c}' in the comment '{}', which pilgrim's comments never hold",
                crate::files::excerpt(comment)
            ));
        }
        if d.upper_comments && text.chars().any(|c| c.is_ascii_lowercase()) {
            return Err(format!(
                "lower case in the comment '{}', which the control may refuse",
                crate::files::excerpt(comment)
            ));
        }
        if super::post::is_active_comment(d, text) {
            return Err(format!(
                "the comment '({})' makes LinuxCNC act (a message, a file, a script)",
                crate::files::excerpt(comment)
            ));
        }
        Ok(())
    };
    let mut code = String::with_capacity(line.len());
    let mut said = None;
    if d.comment.1.is_empty() {
        // A comment runs from its opening (`;`) to the line's end.
        let open = d.comment.0.trim_end();
        let (c, comment) = match line.find(open) {
            Some(p) => (&line[..p], Some(&line[p + open.len()..])),
            None => (line, None),
        };
        if let Some(comment) = comment {
            check(comment)?;
            said = Some(comment.strip_prefix(' ').unwrap_or(comment).to_owned());
        }
        code.push_str(c);
        code.push_str(&" ".repeat(line.len() - c.len()));
        return Ok((code, said));
    }
    // Parenthesised comments, closed on their line, none inside another.
    let mut rest = line;
    while let Some(p) = rest.find(['(', ')', ';']) {
        code.push_str(&rest[..p]);
        match rest.as_bytes()[p] {
            b'(' => {
                let inner = &rest[p + 1..];
                let Some(q) = inner.find(')') else {
                    return Err("a comment '(' that its line does not close".into());
                };
                let comment = &inner[..q];
                if comment.contains('(') {
                    return Err("a comment inside a comment".into());
                }
                check(comment)?;
                said = Some(comment.strip_prefix(' ').unwrap_or(comment).to_owned());
                code.push_str(&" ".repeat(q + 2));
                rest = &inner[q + 1..];
            }
            b')' => return Err("')' outside a comment".into()),
            _ => return Err("';', which pilgrim never writes in this dialect".into()),
        }
    }
    code.push_str(rest);
    Ok((code, said))
}

impl<'a> Reader<'a> {
    /// A reader of `lines` (the text split at its line feeds, the empty
    /// piece after the last taken off), a program in `d` held to
    /// `program` (`Mode::Lint`) or read into its frame (`Mode::Read`), for
    /// the machine whose axes are `axes`; and the standing before its
    /// first line.
    ///
    /// # Failures
    /// The framing (`%` first and last) where the dialect frames.
    pub fn new(
        lines: &[&str],
        program: &'a AxisProgram,
        d: &'a Dialect,
        axes: &'a [Axis],
        mode: Mode,
    ) -> Result<(Self, Standing), LintError> {
        let reading = mode == Mode::Read;
        let decimals = super::written_decimals(program.decimals, d.name);
        // A start angle by a one-letter address (Fanuc's Q, in 0.001 deg) is
        // an ISO word, read with the block's others.
        let (start_letter, start_scale) = match d.thread_start {
            Some(t) if t.address.len() == 1 => (t.address.chars().next(), t.scale),
            _ => (None, 1.0),
        };
        let names: Vec<char> = program
            .axes
            .iter()
            .filter_map(|a| a.name.chars().next())
            .collect();
        // A whole program is framed by `%` where its dialect frames one; a
        // program read as it stands says by its first line whether it is whole.
        let whole = if reading {
            lines.first() == Some(&"%")
        } else {
            program.number > 0
        };
        let framed = d.header.first().is_some_and(|h| *h == "%")
            || (d.header.first().is_some_and(|h| *h == "{WHOLE}%") && whole);
        let name_line = d.reading.name_line;
        let reader = Self {
            d,
            program,
            axes,
            reading,
            lines: lines.len(),
            framed,
            decimals,
            half: 0.5 * 10f64.powi(-(decimals as i32)) + crate::tolerance::SAME_LENGTH,
            lead_letter: d.lead.chars().next().unwrap_or('K'),
            start_letter,
            start_scale,
            program_number: format!("O{:04}", program.number % 10000),
            header_name: name_line
                .map(|(before, after)| format!("{before}{}{after}", program.name)),
            // The dialect's own words (no ISO words): radius and diameter
            // programming by name (DIAMOF/DIAMON, not G8/G7), a start angle
            // by an address of more than a letter (SF=).
            radial: d.radial_words.filter(|(r, _)| !is_g_code(r)),
            start: d.thread_start.map(|t| t.address).filter(|a| a.len() > 1),
            spindle: axes.iter().find(|a| a.kind == AxisKind::Spindle),
            ticker: crate::budget::Ticker::new("the program's lint", 1024),
            not_read: not_read(reading, d),
            least_input: match power_on_of(d, program).no_point {
                Some(1.0) => None,
                Some(unit) => Some(unit),
                None => d.reading.least_input,
            },
            offsets: None,
            names,
        };
        // The framing: % first and last where the dialect frames.
        if framed {
            if lines.first() != Some(&"%") {
                return Err(reader.fault(0, "the program must open with '%'".into()));
            }
            if lines.last() != Some(&"%") {
                return Err(reader.fault(
                    lines.len().saturating_sub(1),
                    "the program must close with '%'".into(),
                ));
            }
        }
        // What the control is in at power-on, as the machine states it: its
        // setup codes stated, constant rpm.
        let on = &power_on_of(d, program).g;
        let standing = Standing {
            st: State {
                values: vec![None; reader.names.len()],
                stated: (d.reading.setup_codes.iter())
                    .filter(|c| on.contains(c))
                    .copied()
                    .collect(),
                constant_speed: on.contains(&97),
                ..State::default()
            },
            last_n: None,
            k: 0,
            pending: None,
            speed_next: None,
            name: None,
            number: None,
            tool: None,
            rpm: None,
        };
        Ok((reader, standing))
    }

    /// The reader with the shop's offset table `offsets`: a tool or work
    /// offset the table gives is followed (its shift added to every later
    /// position) where the reader would refuse it.
    pub fn with_offsets(mut self, offsets: Option<&'a super::offsets::Offsets>) -> Self {
        self.offsets = offsets;
        self
    }

    /// The shifts of tool word `word` by the offsets table, if it gives it.
    fn tool_shift(&self, word: &str) -> Option<Vec<Real>> {
        self.offsets?.tool_shift(word, &self.names)
    }

    /// The shifts of work offset `word` by the offsets table, if it gives it.
    fn work_shift(&self, word: &str) -> Option<Vec<Real>> {
        self.offsets?.work_shift(word, &self.names)
    }

    /// A fault at line `i` (from 0).
    fn fault(&self, i: usize, message: String) -> LintError {
        LintError {
            dialect: self.d.name.to_owned(),
            place: format!("line {}", i + 1),
            message,
        }
    }

    /// Reads line `i` (from 0), `text`, from `at`, the standing before it,
    /// which becomes the standing after it; its moves are pushed to `out`.
    /// After a failure `at` is not a standing of the text.
    ///
    /// # Failures
    /// The first word or rule of the line the reader cannot account for,
    /// named by the block's `N` or the line; the run's deadline.
    pub fn line(
        &mut self,
        at: &mut Standing,
        i: usize,
        text: &str,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let fault = |place: String, message: String| LintError {
            dialect: self.d.name.to_owned(),
            place,
            message,
        };
        let at_line = |l: usize| format!("line {}", l + 1);
        self.ticker
            .tick()
            .map_err(|e| fault(at_line(i), e.to_string()))?;
        let Self {
            d,
            program,
            axes,
            reading,
            decimals,
            half,
            lead_letter,
            start_letter,
            start_scale,
            ref names,
            ref program_number,
            ref header_name,
            radial,
            start,
            spindle,
            framed,
            lines: n_lines,
            ..
        } = *self;
        let (g_ok, m_ok) = (d.reading.g_codes, d.reading.m_codes);
        let name_line = d.reading.name_line;
        let line = i;
        // The line as its control reads it: comments out of the way of the
        // word reader (blanked in place) and checked, the header's own
        // lines recognised where they stand, Sinumerik's own words read.
        let mut own: Vec<OwnWord> = Vec::new();
        let (mut l, said) = read_line(d, i, text).map_err(|m| fault(at_line(i), m))?;
        if l.trim().is_empty() {
            if let Some(s) = &said {
                at.pending = Some(s.clone());
            }
        }
        // A program read as it stands names itself.
        let own_name = name_line
            .and_then(|(before, after)| text.strip_prefix(before)?.strip_suffix(after))
            .filter(|n| {
                reading && !n.is_empty() && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            });
        let own_number = first_code(&l)
            .and_then(|w| w.strip_prefix('O'))
            .filter(|n| reading && n.len() == 4)
            .and_then(|n| n.parse::<u32>().ok());
        if i == 0 && (header_name.as_deref() == Some(text) || own_name.is_some()) {
            at.name = own_name.map(str::to_owned);
            l = " ".repeat(text.len());
        } else if framed && text == "%" && (i == 0 || i + 1 == n_lines) {
            l = " ".into();
        } else if d.reading.number_line
            && framed
            && i == 1
            && (first_code(&l).is_some_and(|w| w == program_number) || own_number.is_some())
        {
            at.number = own_number;
            // Fanuc's program number, `O0001`, is not an ISO word.
            let n = l.find('O').unwrap_or(0);
            l.replace_range(n..n + 5, "     ");
        } else {
            let code_part = l.clone();
            for word in code_part.split_whitespace() {
                let w =
                    if let Some((_, diameter)) = radial.filter(|(r, dm)| word == *r || word == *dm)
                    {
                        OwnWord::Radial(word == diameter)
                    } else if let Some(list) = d
                        .feed_group
                        .and_then(|g| word.strip_prefix(g)?.strip_prefix('(')?.strip_suffix(')'))
                    {
                        OwnWord::FeedGroup(list.to_owned())
                    } else if let Some(v) = start.and_then(|a| word.strip_prefix(a)) {
                        OwnWord::StartAngle(v.parse().map_err(|_| {
                            fault(at_line(i), format!("'{word}' is not a start angle"))
                        })?)
                    } else {
                        continue;
                    };
                own.push(w);
                l = l.replacen(word, &" ".repeat(word.len()), 1);
            }
        }
        let has_code = !l.trim().is_empty() || !own.is_empty();
        let code_text = &l;
        let st = &mut at.st;
        let mut k = at.k;
        // The block's words, every character accounted for.
        let at_block = || {
            code_text
                .split_whitespace()
                .next()
                .filter(|w| {
                    w.len() > 1 && w.starts_with('N') && w[1..].bytes().all(|b| b.is_ascii_digit())
                })
                .map_or_else(|| at_line(line), str::to_owned)
        };
        let mut tokens =
            super::words::words(code_text).map_err(|m| fault(at_block(), m.message))?;
        let line_number = match tokens.first() {
            Some(w) if w.letter == 'N' => {
                let n = w.integer().ok_or_else(|| {
                    fault(
                        at_line(line),
                        format!("{}: a block number is a whole number", w.text()),
                    )
                })?;
                tokens.remove(0);
                Some(n)
            }
            _ => None,
        };
        if let Some(w) = tokens.iter().find(|w| w.letter == 'N') {
            return Err(fault(
                at_block(),
                format!("{}: a block number that does not open its block", w.text()),
            ));
        }
        let own_here = own;
        if tokens.is_empty() && line_number.is_none() && own_here.is_empty() {
            if has_code {
                return Err(fault(
                    at_line(line),
                    format!(
                        "'{}' is not a block the {} can account for",
                        crate::files::excerpt(text),
                        if reading { "reader" } else { "lint" }
                    ),
                ));
            }
            return Ok(());
        }
        let place = |k: usize| {
            if reading {
                line_number.map_or_else(|| at_line(line), |n| format!("N{n}"))
            } else if k < program.blocks.len() {
                name_in(d.name, &program.blocks, k)
            } else {
                at_line(line)
            }
        };
        if st.ended {
            return Err(fault(
                place(k),
                format!(
                    "a block after the program's end ({})",
                    st.ended_by.as_deref().unwrap_or("")
                ),
            ));
        }
        match (d.numbering, line_number) {
            (Some(_), None) => {
                return Err(fault(
                    at_line(line),
                    format!(
                        "a block without its number ('{}' opens it)",
                        code_text.split_whitespace().next().unwrap_or_default()
                    ),
                ))
            }
            (Some(_), Some(n)) => {
                if at.last_n.is_some_and(|m| n <= m) {
                    return Err(fault(
                        format!("N{n}"),
                        format!("numbered out of order, after N{}", at.last_n.unwrap_or(0)),
                    ));
                }
                at.last_n = Some(n);
            }
            (None, Some(n)) => {
                return Err(fault(
                    at_line(line),
                    format!("N{n}: the dialect numbers no blocks"),
                ))
            }
            (None, None) => {}
        }
        // The block's words: codes, the tool call, addresses with values.
        let mut radial_here: Vec<(bool, String)> = Vec::new();
        let mut feed_group_here: Vec<&str> = Vec::new();
        let mut sf_here = None;
        for w in &own_here {
            match w {
                OwnWord::Radial(diameter) => {
                    let (radius, on_diameter) = d.radial_words.unwrap_or_default();
                    radial_here.push((
                        *diameter,
                        if *diameter { on_diameter } else { radius }.into(),
                    ))
                }
                OwnWord::FeedGroup(list) => feed_group_here.push(list),
                OwnWord::StartAngle(v) => sf_here = Some(*v),
            }
        }
        let mut motion_here = None;
        let mut read = Vec::new();
        let mut letters_here: Vec<char> = Vec::new();
        let mut start_word: Option<String> = sf_here.map(|v| format!("SF={v}"));
        for w in &tokens {
            match w.letter {
                'G' | 'M' => {
                    let listed = if w.letter == 'G' { g_ok } else { m_ok };
                    // A code as the dialect reads it: to a tenth where it
                    // does (LinuxCNC's G1.0 is G1), else a whole number.
                    let code = if d.reading.code_tenths {
                        w.whole()
                    } else {
                        w.integer()
                    };
                    let Some(n) = code.filter(|n| listed.contains(n)) else {
                        // What the code means on this control, where the
                        // dialect's table says: never another dialect's.
                        let named = w
                            .code()
                            .map(|c| format!("{}{c}", w.letter))
                            .and_then(|c| d.reading.meanings.iter().find(|m| m.0 == c))
                            .map_or_else(String::new, |m| format!(" ({} on {})", m.1, d.name));
                        return Err(fault(
                            place(k),
                            format!("{}{named}{}", w.text(), self.not_read),
                        ));
                    };
                    let by = || Some(format!("{} at {}", w.text(), place(k)));
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
                        continue;
                    }
                    match n {
                        0 | 1 | 32 | 33 | 76 => {
                            if let Some(m) = motion_here {
                                return Err(fault(
                                    place(k),
                                    format!("G{m} and {} in one block: two motions", w.text()),
                                ));
                            }
                            motion_here = Some(n)
                        }
                        97 => st.constant_speed = true,
                        // LinuxCNC's diameter (G7) and radius (G8) modes.
                        7 | 8 => radial_here.push((n == 7, w.text())),
                        n if d.reading.work_offsets.contains(&n) => {
                            // The part zero is the work offset the program
                            // selects first (before its moves: the one in
                            // force at power-on, the first listed, if none).
                            let power_on = (k > 0).then(|| {
                                (
                                    power_on_code(d, program, d.reading.work_offsets)
                                        .unwrap_or(d.reading.work_offsets[0]),
                                    "power-on, before the moves".into(),
                                )
                            });
                            // A switch the offsets table gives: its shift
                            // (back to the first: none).
                            let first = st.work_offset.as_ref().map(|(c, _)| *c);
                            let table = first
                                .filter(|c| *c != n)
                                .and_then(|_| self.work_shift(&format!("G{n}")));
                            if first == Some(n) {
                                st.work_shift = Vec::new();
                                continue;
                            }
                            if let Some(shift) = table {
                                st.work_shift = shift;
                                continue;
                            }
                            keep_first(&mut st.work_offset, power_on, n, || place(k)).map_err(
                                |(c, at)| {
                                    fault(
                                        place(k),
                                        format!(
                                            "{}: a switch of the work offset from G{c} ({at}), the part zero the verification places the part at (another part zero moves every later block); verify a program that keeps one, or give the offset's shift in an --offsets file",
                                            w.text()
                                        ),
                                    )
                                },
                            )?;
                        }
                        17..=19 => {
                            // The plane the machine's setup states (the
                            // tool's length offsets and arcs follow it), or
                            // the first selected: another is refused.
                            let setup = match program.setup.plane {
                                Some(p) => {
                                    Some((super::post::plane_code(p), "the machine's setup".into()))
                                }
                                None => power_on_code(d, program, &[17, 18, 19])
                                    .map(|c| (c, "the machine's power-on state".into())),
                            };
                            keep_first(&mut st.plane, setup, n, || {
                                format!("{} at {}", w.text(), place(k))
                            })
                            .map_err(|(c, at)| {
                                fault(
                                    place(k),
                                    format!(
                                        "{}: another plane than G{c} ({at}); the tool's length offsets and arcs follow the plane, which the verification keeps",
                                        w.text()
                                    ),
                                )
                            })?;
                        }
                        _ => {}
                    }
                    // The setup's codes stated (a code restated, or one
                    // the setup does not need, changes nothing kept).
                    if d.reading.setup_codes.contains(&n) && !st.stated.contains(&n) {
                        st.stated.push(n);
                    }
                }
                'T' => {
                    if letters_here.contains(&'T') {
                        return Err(fault(
                            place(k),
                            format!("{}: T twice in one block", w.text()),
                        ));
                    }
                    letters_here.push('T');
                    if k > 0 {
                        return Err(fault(
                            place(k),
                            format!("a tool call {} among the moves", w.text()),
                        ));
                    }
                    let n = w.integer().ok_or_else(|| {
                        fault(
                            place(k),
                            format!("{}: a tool call is a whole number", w.text()),
                        )
                    })?;
                    // A lathe's T names the tool and its offset (`T0303`):
                    // the model's tool is the tool with its own offset.
                    at.tool = Some(if d.reading.tool_and_offset {
                        let (tool, offset) = (n / 100, n % 100);
                        let table = (n >= 100 && offset != tool)
                            .then(|| self.tool_shift(&format!("T{n:04}")))
                            .flatten();
                        if let Some(shift) = table {
                            st.tool_shift = shift;
                        } else if n < 100 || offset != tool {
                            return Err(fault(
                                place(k),
                                format!(
                                    "{}: tool {tool:02} with offset {offset:02}; the verification's tool is a tool with its own offset (T{tool:02}{tool:02}: 00 cancels the offset, another number is another tool's), or one an --offsets file gives",
                                    w.text()
                                ),
                            ));
                        }
                        tool
                    } else {
                        n
                    });
                    // Another tool has its own shape and offsets: the
                    // verification models the family's.
                    if at.tool != Some(program.tool_number) {
                        return Err(fault(
                            place(k),
                            format!(
                                "{}: another tool than T{}, the family's, whose shape the verification models",
                                w.text(),
                                program.tool_number
                            ),
                        ));
                    }
                }
                letter => {
                    if letters_here.contains(&letter) {
                        return Err(fault(
                            place(k),
                            format!("{}: {letter} twice in one block", w.text()),
                        ));
                    }
                    letters_here.push(letter);
                    if d.reading.point_needed.contains(letter) && !w.has_point() {
                        return Err(fault(
                            place(k),
                            format!(
                                "{}: a number without its decimal point, which {} reads by a parameter of the control; write {}.",
                                w.text(),
                                d.name,
                                w.text()
                            ),
                        ));
                    }
                    if d.reading.no_point.contains(letter) && w.has_point() {
                        return Err(fault(
                            place(k),
                            format!(
                                "{}: a decimal point in a word {} reads as a whole number",
                                w.text(),
                                d.name
                            ),
                        ));
                    }
                    // An axis value without a decimal point is in the
                    // control's least input unit where it says so.
                    let v = match self.least_input {
                        Some(unit) if !w.has_point() && names.contains(&letter) => w.value() * unit,
                        _ => w.value(),
                    };
                    if start_letter == Some(letter) {
                        start_word = Some(w.text());
                    }
                    if d.reading.offset_word == Some(letter) {
                        st.tool_shift = match w.integer() {
                            Some(1) => Vec::new(),
                            Some(n) => self.tool_shift(&format!("{letter}{n}")).ok_or_else(|| {
                                fault(
                                    place(k),
                                    format!(
                                        "{}: another tool offset than {letter}1, the tool call's, which is the verification's tool ({letter}0 cancels it, another number is another edge's); an --offsets file that gives {letter}{n} says where it moves the tool",
                                        w.text()
                                    ),
                                )
                            })?,
                            None => {
                                return Err(fault(
                                    place(k),
                                    format!(
                                        "{}: another tool offset than {letter}1, the tool call's, which is the verification's tool ({letter}0 cancels it, another number is another edge's)",
                                        w.text()
                                    ),
                                ))
                            }
                        };
                    }
                    read.push((letter, v, w.text()));
                }
            }
        }
        if let Some(s) = sf_here {
            read.push(('@', s, format!("SF={s}")));
        }
        let mut axis_here = vec![None; names.len()];
        // The machine's setup words, once, before the first move, and as
        // the setup says.
        for (diameter, word) in radial_here {
            let want = program.setup.radial.map(|r| r == Radial::Diameter);
            if k > 0 || st.radial.is_some() || want != Some(diameter) {
                return Err(fault(
                    place(k),
                    format!(
                        "{word}: {} where the machine's setup {}",
                        if diameter {
                            "diameter programming"
                        } else {
                            "radius programming"
                        },
                        match (want, k > 0 || st.radial.is_some()) {
                            (_, true) => "sets it once, before the moves".to_owned(),
                            (Some(true), _) => "programs the radial axis on diameter".to_owned(),
                            (Some(false), _) => "programs the radial axis on radius".to_owned(),
                            (None, _) => "says nothing of it".to_owned(),
                        }
                    ),
                ));
            }
            st.radial = Some(diameter);
        }
        for list in feed_group_here {
            if k > 0 || st.feed_group || list != program.setup.feed_group.join(",") {
                return Err(fault(
                    place(k),
                    format!(
                        "FGROUP({list}) where the machine's setup groups the feed over ({}), once, before the moves",
                        program.setup.feed_group.join(",")
                    ),
                ));
            }
            st.feed_group = true;
        }
        // A threading cycle (LinuxCNC's G76): the moves it makes, each
        // held and read as a block of its own.
        if motion_here == Some(76) {
            let values: Vec<(char, Real)> = read.iter().map(|(c, v, _)| (*c, *v)).collect();
            let (cycle, end_x) = cycle_words(&values, d).map_err(|m| fault(place(k), m))?;
            let what = "a threading cycle";
            let needs_g97 = (d.reading.thread_needs_constant_speed && !st.constant_speed)
                .then(|| format!("{what} before constant spindle speed (G97)"));
            if let Some(m) = cutting_fault(st, d, &program.setup, what)
                .or(needs_g97)
                .or_else(|| setup_fault(st, d, program, what))
            {
                return Err(fault(place(k), m));
            }
            let (Some(xi), Some(zi)) = (
                names.iter().position(|n| *n == 'X'),
                names.iter().position(|n| *n == 'Z'),
            ) else {
                return Err(fault(
                    place(k),
                    format!(
                        "a threading cycle on {}, which programs no X and Z",
                        program.machine
                    ),
                ));
            };
            let (Some(x0), Some(z0)) = (st.values[xi], st.values[zi]) else {
                return Err(fault(
                    place(k),
                    "a threading cycle before X and Z are written (the drive line it starts from)"
                        .into(),
                ));
            };
            let moves = super::cycle::expand(&cycle, [x0, z0], st.radial == Some(true), end_x)
                .map_err(|m| fault(place(k), m.message))?;
            let comment = at.pending.take();
            for (n, mv) in moves.iter().enumerate() {
                let b = if reading { None } else { program.blocks.get(k) };
                if !reading && b.is_none() {
                    return Err(fault(
                        at_line(line),
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
                if let Some(b) = b {
                    let off = (0..names.len())
                        .find(|&i| values[i].is_some_and(|v| !((v - b.values[i]).abs() <= half)));
                    if b.motion != mv.motion || off.is_some() {
                        return Err(fault(
                            place(k),
                            format!(
                                "the threading cycle's move {} is {:?} to X{} Z{}, the axis program's {:?} to X{} Z{}",
                                n + 1,
                                mv.motion,
                                crate::math::fixed(mv.x, decimals + 2),
                                crate::math::fixed(mv.z, decimals + 2),
                                b.motion,
                                crate::math::fixed(b.values[xi], decimals + 2),
                                crate::math::fixed(b.values[zi], decimals + 2)
                            ),
                        ));
                    }
                }
                for (i, v) in [(xi, mv.x), (zi, mv.z)] {
                    if let Some(a) = axes.iter().find(|a| a.name == program.axes[i].name) {
                        let (lo, hi) = (a.to_user(a.min), a.to_user(a.max));
                        if v < lo - half || v > hi + half {
                            return Err(fault(
                                place(k),
                                format!(
                                    "the threading cycle's move {} takes {} to {v}, outside the axis's travel [{lo}, {hi}]",
                                    n + 1,
                                    program.axes[i].name
                                ),
                            ));
                        }
                    }
                }
                st.values = values;
                out.push(ReadMove {
                    motion: mv.motion,
                    values: placed(st),
                    feed: match mv.motion {
                        Motion::Thread { lead, .. } => lead * st.speed.unwrap_or_default(),
                        _ => 0.0,
                    },
                    spindle: if n == 0 { at.speed_next.take() } else { None },
                    comment: if n == 0 { comment.clone() } else { None },
                    number: line_number,
                    line,
                });
                k += 1;
                at.k = k;
            }
            at.st.motion = Some(76);
            return Ok(());
        }
        let mut lead_here = None;
        // A lead by its own address (K), which only a thread block reads.
        let mut lead_word: Option<String> = None;
        let mut s_here = None;
        for (letter, v, text) in read {
            if let Some(i) = names.iter().position(|n| *n == letter) {
                axis_here[i] = Some(v);
                continue;
            }
            if letter == 'F' && !(v > 0.0) {
                return Err(fault(
                    place(k),
                    format!("{text}: a feed is a positive number"),
                ));
            }
            match letter {
                // One modal F where the lead's address is the feed's
                // (Fanuc): a feed written on a G01 is the next thread's
                // lead, and a lead the next G01's feed.
                'F' if lead_letter == 'F' => {
                    st.feed = true;
                    st.f = Some(v);
                    lead_here = Some(v);
                }
                'F' => {
                    st.feed = true;
                    st.f = Some(v);
                }
                'S' => s_here = Some(v),
                c if d.reading.offset_word == Some(c) => {}
                c if start_letter == Some(c) => st.start_deg = v / start_scale,
                '@' => st.start_deg = v,
                c if c == lead_letter => {
                    lead_here = Some(v);
                    lead_word = Some(text);
                }
                c if reading => {
                    // What the address means on this control, where its
                    // table says (Fanuc system A's U and W).
                    let named = (d.reading.meanings.iter())
                        .find(|m| m.0.len() == 1 && m.0.starts_with(c))
                        .map_or_else(String::new, |m| format!(" ({} on {})", m.1, d.name));
                    return Err(fault(
                        place(k),
                        format!(
                            "{text}{named}: a word the verification cannot simulate ({} on {} reads the axes {}, F, S, T{})",
                            d.name,
                            program.machine,
                            names.iter().collect::<String>(),
                            start_letter.map(|c| format!(", {c}")).unwrap_or_default()
                        ),
                    ));
                }
                _ => {
                    return Err(fault(
                        place(k),
                        format!("{text}: not a word of {} on {}", d.name, program.machine),
                    ))
                }
            }
        }
        if let Some(m) = motion_here {
            st.motion = Some(m);
        }
        if let Some(l) = lead_here {
            st.lead = Some(l);
        }
        let moves = axis_here.iter().any(Option::is_some);
        if let Some(v) = s_here {
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
            if !reading && want != Some(v) {
                return Err(fault(
                    place(k),
                    format!(
                        "S{v} read back, where the axis program sets {}",
                        want.map_or("no speed".to_owned(), |w| format!("S{w}"))
                    ),
                ));
            }
            if !(v >= 1.0) {
                return Err(fault(
                    place(k),
                    format!("S{v}: the spindle would stand while the program cuts"),
                ));
            }
            if let Some(a) = spindle.filter(|a| !(v >= a.min && v <= a.max)) {
                return Err(fault(
                    place(k),
                    format!(
                        "S{v} is outside spindle {}'s range [{}, {}] rpm",
                        a.name, a.min, a.max
                    ),
                ));
            }
            st.speed = Some(v);
        }
        let lead_outside = |w: &str| {
            format!(
                "{w}: a thread's lead outside a thread block ({} reads {lead_letter} as the lead of {} only)",
                d.name, d.thread
            )
        };
        if !moves {
            if motion_here.is_some() {
                return Err(fault(place(k), "a motion word with no axis".into()));
            }
            if let Some(w) = &lead_word {
                return Err(fault(place(k), lead_outside(w)));
            }
            if let Some(w) = &start_word {
                return Err(fault(place(k), outside_thread(w, d)));
            }
            return Ok(());
        }
        // A move: the modal values carried, held to the axis program.
        let b = if reading { None } else { program.blocks.get(k) };
        if !reading && b.is_none() {
            return Err(fault(
                at_line(line),
                format!(
                    "a move beyond the axis program's {} blocks",
                    program.blocks.len()
                ),
            ));
        };
        for (i, v) in axis_here.iter().enumerate() {
            if let Some(v) = v {
                st.values[i] = Some(*v);
            }
        }
        let Some(m) = st.motion else {
            return Err(fault(
                place(k),
                "a move before any motion word (G0, G1)".into(),
            ));
        };
        if m == 76 {
            return Err(fault(
                place(k),
                "a move under a threading cycle's modal G76 without its words: write G0 or G1 first".into(),
            ));
        }
        let is_thread = m == 32 || m == 33;
        if let Some(w) = lead_word.as_ref().filter(|_| !is_thread) {
            return Err(fault(place(k), lead_outside(w)));
        }
        if let Some(b) = b {
            let want = match b.motion {
                Motion::Rapid => m == 0,
                Motion::Linear => m == 1,
                Motion::Thread { .. } => is_thread,
            };
            if !want {
                return Err(fault(
                    place(k),
                    format!("G{m}, where the axis program has a {:?} move", b.motion),
                ));
            }
        }
        if m == 1 && !st.feed {
            return Err(fault(place(k), "G1 before any feed F".into()));
        }
        if let Some(m) = (m != 0)
            .then(|| cutting_fault(st, d, &program.setup, "a cutting move"))
            .flatten()
        {
            return Err(fault(place(k), m));
        }
        if let Some(w) = start_word.as_ref().filter(|_| !is_thread) {
            return Err(fault(place(k), outside_thread(w, d)));
        }
        if let Some(m) = setup_fault(st, d, program, "a move") {
            return Err(fault(place(k), m));
        }
        let read_lead = st.lead.unwrap_or(Real::NAN);
        let motion = match m {
            0 => Motion::Rapid,
            1 => Motion::Linear,
            _ => Motion::Thread {
                lead: read_lead,
                start_deg: st.start_deg,
            },
        };
        if is_thread {
            if d.lead_every_block && lead_here.is_none() {
                return Err(fault(
                    place(k),
                    format!("a thread block without its lead {}", d.lead),
                ));
            }
            if d.reading.thread_needs_constant_speed && !st.constant_speed {
                return Err(fault(
                    place(k),
                    "a thread before constant spindle speed (G97)".into(),
                ));
            }
            if !(read_lead > 0.0) {
                return Err(fault(place(k), "a thread block before any lead".into()));
            }
            if let Some(Motion::Thread { lead, start_deg }) = b.map(|b| b.motion) {
                if !((read_lead - lead).abs()
                    <= 0.5 * 10f64.powi(-(d.lead_decimals as i32)) + crate::tolerance::SAME_LENGTH)
                {
                    return Err(fault(
                        place(k),
                        format!("lead {read_lead}, the axis program's {lead}"),
                    ));
                }
                if (st.start_deg - start_deg).abs() > 1e-3 {
                    return Err(fault(
                        place(k),
                        format!(
                            "thread start {} deg, the axis program's {start_deg} deg",
                            st.start_deg
                        ),
                    ));
                }
            }
            if d.thread_start.is_some_and(|t| !t.modal) {
                st.start_deg = 0.0; // Fanuc's Q holds for its block only
            }
        }
        // Where each axis goes: its value with the offsets' shifts.
        let going = placed(st);
        for (i, name) in program.axes.iter().enumerate() {
            if b.is_some_and(|b| b.keep.contains(&name.name)) {
                continue;
            }
            let v = match (st.values[i], b) {
                (Some(v), _) => v,
                // Read: an axis not yet written stands where it stands.
                (None, None) => continue,
                (None, Some(_)) => {
                    return Err(fault(
                        place(k),
                        format!("axis {} has no value yet", name.name),
                    ))
                }
            };
            if let Some(b) = b.filter(|b| !((v - b.values[i]).abs() <= half)) {
                return Err(fault(
                    place(k),
                    format!(
                        "{}{v} read back, the axis program's {}",
                        name.name,
                        crate::math::fixed(b.values[i], decimals + 2)
                    ),
                ));
            }
            if let Some(a) = axes.iter().find(|a| a.name == name.name) {
                let (lo, hi) = (a.to_user(a.min), a.to_user(a.max));
                let shifted = going[i].unwrap_or(v);
                if shifted < lo - half || shifted > hi + half {
                    let by = if shifted == v {
                        String::new()
                    } else {
                        format!(" (at {shifted} with the offsets' shift)")
                    };
                    return Err(fault(
                        place(k),
                        format!(
                            "{}{v}{by} is outside the axis's travel [{lo}, {hi}]",
                            name.name
                        ),
                    ));
                }
            }
        }
        // The move as read (a lint reads it too: what a run verifies).
        {
            let comment = at.pending.take();
            out.push(ReadMove {
                motion,
                values: going,
                feed: match motion {
                    Motion::Rapid => 0.0,
                    Motion::Linear => st.f.unwrap_or_default(),
                    Motion::Thread { lead, .. } => lead * st.speed.unwrap_or_default(),
                },
                spindle: at.speed_next.take(),
                comment,
                number: line_number,
                line,
            });
        }
        k += 1;
        at.k = k;
        Ok(())
    }

    /// The checks at the text's end, from `at`, the standing after its
    /// last line: the program ended, every move of the axis program read
    /// (a lint), a move at all (a reading).
    ///
    /// # Failures
    /// What the end lacks, at the last line.
    pub fn end(&self, at: &Standing) -> Result<Linted, LintError> {
        let last = self.lines.saturating_sub(1);
        if !self.reading && at.k != self.program.blocks.len() {
            return Err(self.fault(
                last,
                format!(
                    "{} moves read back, the axis program has {}",
                    at.k,
                    self.program.blocks.len()
                ),
            ));
        }
        if !at.st.ended {
            return Err(self.fault(
                last,
                format!("the program does not end (M{})", self.d.reading.end_code),
            ));
        }
        if self.reading && at.k == 0 {
            return Err(self.fault(0, "no move: nothing to verify".into()));
        }
        Ok(Linted {
            moves: at.k,
            lines: self.lines,
        })
    }
}

/// Where the moves reach: each axis's value as written, shifted by the
/// tool and work offsets in force where an offsets table gives them.
fn placed(st: &State) -> Vec<Option<Real>> {
    let shift = |v: &Vec<Real>, i: usize| v.get(i).copied().unwrap_or(0.0);
    st.values
        .iter()
        .enumerate()
        .map(|(i, v)| v.map(|v| v + shift(&st.tool_shift, i) + shift(&st.work_shift, i)))
        .collect()
}

/// The control's power-on state as the machine states it, where the
/// program is in the machine's own dialect (a program posted for another
/// control, `--post linuxcnc` on a Sinumerik machine, assumes none).
fn power_on_of<'p>(d: &Dialect, program: &'p AxisProgram) -> &'p super::PowerOn {
    static NONE: super::PowerOn = super::PowerOn {
        g: Vec::new(),
        no_point: None,
        system: None,
    };
    if program.control == d.name {
        &program.setup.power_on
    } else {
        &NONE
    }
}

/// The code of `group` in force at power-on, if the machine states one.
fn power_on_code(d: &Dialect, program: &AxisProgram, group: &[u32]) -> Option<u32> {
    power_on_of(d, program)
        .g
        .iter()
        .copied()
        .find(|c| group.contains(c))
}

/// Code `n` of a modal group that must stay what it first was (a work
/// offset, the plane): `kept` holds the code selected and where, `before`
/// the one in force before any selection (at power-on, by the machine's
/// setup). The first selection is kept, `set_at` naming it.
///
/// # Failures
/// A switch: the code in force and where it was set.
fn keep_first(
    kept: &mut Option<(u32, String)>,
    before: Option<(u32, String)>,
    n: u32,
    set_at: impl FnOnce() -> String,
) -> Result<(), (u32, String)> {
    match kept.clone().or(before) {
        Some((c, at)) if c != n => Err((c, at)),
        _ => {
            if kept.is_none() {
                *kept = Some((n, set_at()));
            }
            Ok(())
        }
    }
}

/// What the modal state `st` lacks for `what` (a cutting move, a cycle)
/// to cut: the spindle on, a speed written, the coolant on where the
/// machine's `setup` turns it on.
fn cutting_fault(st: &State, d: &Dialect, setup: &ProgramSetup, what: &str) -> Option<String> {
    if !st.spindle_on {
        Some(match &st.spindle_by {
            Some(by) => format!("{what} with the spindle stopped ({by})"),
            None => format!("{what} with the spindle stopped (no M3)"),
        })
    } else if !st.speed.is_some_and(|v| v >= 1.0) {
        Some(format!(
            "{what} with no spindle speed S written (the spindle turned on by {})",
            st.spindle_by.as_deref().unwrap_or("M3")
        ))
    } else if setup.coolant && !st.coolant {
        Some(match &st.coolant_by {
            Some(by) => {
                format!("{what} with the coolant off ({by}), which the machine's setup turns on")
            }
            None => format!(
                "{what} with the coolant off ({} not written), which the machine's setup turns on",
                d.coolant.0
            ),
        })
    } else {
        None
    }
}

/// The refusal of a thread's start angle `word` on a block that cuts no
/// thread: Fanuc's Q holds for its own thread block only, and a start
/// angle elsewhere would be verified as a start the control never cuts.
fn outside_thread(word: &str, d: &Dialect) -> String {
    format!(
        "{word}: a thread's start angle outside a thread block ({} reads it on the thread block it stands on); write it on the {} block",
        d.name, d.thread
    )
}

/// What the modal state `st` lacks for `what` (any move) of the machine's
/// `setup`, where the dialect has words for it: radius or diameter
/// programming, the feed's group, each set before the first move.
fn setup_fault(st: &State, d: &Dialect, program: &AxisProgram, what: &str) -> Option<String> {
    let setup = &program.setup;
    let radial_word = d.radial_words.is_some() && d.style == Style::GCode;
    if let Some(c) = d
        .reading
        .setup_codes
        .iter()
        .find(|c| !st.stated.contains(c))
    {
        let group = d.reading.modal_groups.iter().find(|g| g.contains(c));
        Some(match group.and_then(|g| power_on_code(d, program, g)) {
            Some(on) => format!(
                "{what} before G{c} is stated: the machine's control is in G{on} at power-on, which the verification does not model; write G{c} before the moves"
            ),
            None => format!(
                "{what} before G{c} is stated: the program leaves it to the control's power-on state, which the machine does not state; write G{c} before the moves, or state the power-on state in the machine's setup"
            ),
        })
    } else if let Some(r) = setup.radial.filter(|_| radial_word && st.radial.is_none()) {
        let (radius, diameter) = d.radial_words.unwrap_or_default();
        Some(format!(
            "{what} before {} sets the radial axis's programming ({}), which the machine's setup states",
            if r == Radial::Diameter { diameter } else { radius },
            if r == Radial::Diameter { "diameter" } else { "radius" }
        ))
    } else if d.feed_group.is_some() && !setup.feed_group.is_empty() && !st.feed_group {
        Some(format!(
            "{what} before {}({}), the feed group the machine's setup states",
            d.feed_group.unwrap_or_default(),
            setup.feed_group.join(",")
        ))
    } else {
        None
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
) -> Result<(super::cycle::ThreadCycle, Option<Real>), String> {
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
        super::cycle::ThreadCycle {
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

/// Why the reader refuses a code: in a program pilgrim wrote, a word its
/// dialect does not write; in a program read as it stands, a word the
/// verification cannot simulate. The text after the word, made once per
/// reader (a mutation test refuses millions of codes).
fn not_read(reading: bool, d: &Dialect) -> String {
    let (g, m) = (d.reading.g_codes, d.reading.m_codes);
    if reading {
        let list = |l: char, c: &[u32]| {
            c.iter()
                .map(|n| format!("{l}{n}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        format!(
            ": a word the verification cannot simulate (it reads {} and {} in {} programs); verify a program without it",
            list('G', g),
            list('M', m),
            d.name
        )
    } else {
        format!(" is not a word of {}", d.name)
    }
}

/// Whether `word` is an ISO G code (`G8`), not a dialect's own word.
fn is_g_code(word: &str) -> bool {
    word.strip_prefix('G')
        .is_some_and(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()))
}

/// The first word of a line (before a comment).
fn first_code(line: &str) -> Option<&str> {
    line.split('(').next()?.split_whitespace().next()
}
