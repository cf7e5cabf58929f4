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

mod arcs;
mod codes;
mod cycles;
mod dwell;
mod fanuc_cycles;
mod flow;
mod line;
mod moves;
mod setup;
mod surface;

use flow::SourceFile;
pub use flow::{Beside, MAX_SUB_BYTES};

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
    /// The seconds the axes stand before it, by the dwells (`G4`) read
    /// since the move before.
    pub dwell_s: Real,
    /// The last comment line since the move before: the pass it begins.
    pub comment: Option<String>,
    /// Its block number, where the text numbers blocks.
    pub number: Option<u32>,
    /// The line it stands on (from 0), in its file.
    pub line: usize,
    /// Its file: 0 the program's own, else a subprogram's file
    /// ([`Reader::file_name`]).
    pub file: usize,
    /// The line of the program's own text (from 0) whose call made it,
    /// where a subprogram's line did.
    pub via: Option<usize>,
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
    /// The seconds of the dwells read since the last move, for the next,
    /// and where the first of them stands.
    dwell_next: Real,
    dwell_by: Option<String>,
    /// The name, number, tool and speed the text gives itself.
    name: Option<String>,
    number: Option<u32>,
    tool: Option<u32>,
    rpm: Option<Real>,
    /// What the text's statements have set: variables, calls, turns.
    mac: crate::program::macros::State,
    /// The next line to read in the file being read.
    next: usize,
    /// Whether the reading has ended before the text's last line (the
    /// program's end reached in a subprogram, or other programs after it).
    stopped: bool,
}

impl Standing {
    /// The seconds of the dwells read since the last move, for the move
    /// read now (none left for the next).
    fn take_dwell(&mut self) -> Real {
        self.dwell_by = None;
        std::mem::take(&mut self.dwell_next)
    }

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
    /// The dialect's macro language, where the text is read as it stands.
    macros: Option<super::post::MacroReading>,
    /// The files of the reading: the program's own text first.
    files: Vec<SourceFile<'a>>,
    /// Where a called subprogram's file is read, if anywhere.
    beside: Option<Beside<'a>>,
    /// The file the line being read is in.
    current: usize,
    /// The machine's constants, where the caller gives them: the settings
    /// of the control a cycle takes what its words leave out from.
    settings: Option<&'a std::collections::BTreeMap<String, Real>>,
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
    /// Constant surface speed (`G96`) in force, its speed S (m/min) once
    /// written, and the spindle's clamp (rpm) the program has set.
    surface: bool,
    surface_speed: Option<Real>,
    clamp: Option<Real>,
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
    /// Fanuc's first G76 block's words, once written: the control keeps
    /// them for the next cycle.
    fanuc_g76: Option<FanucFirst>,
    /// Where a run of cycle blocks (Fanuc's modal G92) started: each pass
    /// returns there.
    cycle_start: Option<[Real; 2]>,
    /// The last G92 pass's X and Z (a block may write one of them).
    g92_x: Option<Real>,
    g92_z: Option<Real>,
}

/// Fanuc's first G76 block: m, r, a, dd_min (mm), d (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
struct FanucFirst {
    finishes: u32,
    chamfer_tenths: u32,
    angle_deg: Real,
    min_cut: Real,
    allowance: Real,
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
    /// `CR=`, an arc's radius, with the word.
    ArcRadius(Real, String),
    /// `AR=`, an arc's opening angle (deg), with the word.
    ArcAngle(Real, String),
    /// `LIMS=`, the spindle's clamp under constant surface speed (rpm),
    /// with the word.
    SpeedLimit(Real, String),
}

/// One block being read: where it is and what it holds.
struct Block {
    /// Its line (from 0).
    line: usize,
    /// Its number N, where it has one.
    number: Option<u32>,
    /// Its code as the control reads it (comments blanked in place).
    code: String,
    /// Its ISO words after the number.
    tokens: Vec<super::words::Word>,
    /// Sinumerik's own words in it.
    own: Vec<OwnWord>,
}

/// What a block's words say before its move is read: its motion code,
/// its addresses with their values, the setup's words, a start angle.
#[derive(Debug, Default)]
struct Said {
    /// The motion code (G0, G1, G32, G33, G76), where it has one.
    motion: Option<u32>,
    /// Each address with its value and text (`@`: Sinumerik's `SF=`).
    read: Vec<(char, Real, String)>,
    /// Diameter (true) or radius programming, with the word that says it.
    radial: Vec<(bool, String)>,
    /// `FGROUP(..)`'s lists.
    feed_group: Vec<String>,
    /// The word giving a thread's start angle, where one does.
    start_word: Option<String>,
    /// An arc's own words (its radius, its angle).
    arc: arcs::ArcWords,
    /// `G96` (true) or `G97` (false) in the block, where it has one.
    surface: Option<bool>,
    /// Whether the block is Fanuc's `G50`: its S the spindle's clamp.
    clamp: bool,
}

/// "line N" for line `l` (from 0).
fn at_line(l: usize) -> String {
    format!("line {}", l + 1)
}

/// Where line `i` (from 0) whose code is `code` is, for a message: its
/// `N` where it opens with one, else its line.
fn code_place(code: &str, i: usize) -> String {
    (code.split_whitespace().next())
        .filter(|w| w.len() > 1 && w.starts_with('N') && w[1..].bytes().all(|b| b.is_ascii_digit()))
        .map_or_else(|| at_line(i), str::to_owned)
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
            macros: d.reading.macros.filter(|_| reading),
            files: vec![SourceFile::new(String::new(), lines, d)],
            beside: None,
            current: 0,
            settings: None,
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
                surface: on.contains(&96),
                ..State::default()
            },
            last_n: None,
            k: 0,
            pending: None,
            speed_next: None,
            dwell_next: 0.0,
            dwell_by: None,
            name: None,
            number: None,
            tool: None,
            rpm: None,
            mac: Default::default(),
            next: 0,
            stopped: false,
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

    /// The reader with the machine's constants `settings`, where a cycle
    /// takes what its words leave out from the control's settings.
    pub fn with_settings(
        mut self,
        settings: Option<&'a std::collections::BTreeMap<String, Real>>,
    ) -> Self {
        self.settings = settings;
        self
    }

    /// The machine's constant `name` as a machine file names it, where the
    /// caller gave the constants and it is a finite number (an angle's
    /// `_deg` constant is kept in radians under its name without the
    /// suffix, and given back in degrees).
    fn setting(&self, name: &str) -> Option<Real> {
        let m = self.settings?;
        match name.strip_suffix("_deg") {
            Some(base) => m.get(base).map(|r| r.to_degrees()),
            None => m.get(name).copied(),
        }
        .filter(|v| v.is_finite())
    }

    /// The reader with `beside`, where a called subprogram's file is read
    /// by its name (the program's folder).
    pub fn with_beside(mut self, beside: Option<Beside<'a>>) -> Self {
        self.beside = beside;
        self
    }

    /// The name of file `f` of the reading (empty: the program's own).
    pub fn file_name(&self, f: usize) -> &str {
        &self.files[f].name
    }

    /// The files the reading opened besides the program's own, in the
    /// order of their numbers from 1.
    pub fn called_files(&self) -> Vec<String> {
        self.files[1..].iter().map(|f| f.name.clone()).collect()
    }

    /// The shifts of tool word `word` by the offsets table, if it gives it.
    fn tool_shift(&self, word: &str) -> Option<Vec<Real>> {
        self.offsets?.tool_shift(word, &self.names)
    }

    /// The shifts of work offset `word` by the offsets table, if it gives it.
    fn work_shift(&self, word: &str) -> Option<Vec<Real>> {
        self.offsets?.work_shift(word, &self.names)
    }

    /// What reads the text, for a message: "reading" as it stands, else
    /// "lint".
    fn what(&self) -> &'static str {
        if self.reading {
            "reading"
        } else {
            "lint"
        }
    }

    /// A fault at line `i` (from 0) of the file being read.
    fn fault(&self, i: usize, message: String) -> LintError {
        LintError {
            what: self.what(),
            dialect: self.d.name.to_owned(),
            place: self.in_file(format!("line {}", i + 1)),
            message,
        }
    }

    /// `place` in the file being read: as it is in the program's own, with
    /// the file's name in a subprogram's.
    fn in_file(&self, place: String) -> String {
        match self.current {
            0 => place,
            f => format!("{place} of {}", self.files[f].name),
        }
    }

    /// Reads line `i` (from 0), `text`, from `at`, the standing before it,
    /// which becomes the standing after it; its moves are pushed to `out`.
    /// After a failure `at` is not a standing of the text.
    ///
    /// The line's code ([`line`]: comments, the header's lines, Sinumerik's
    /// own words), its block and number, its words ([`codes`]), the
    /// machine's setup words ([`setup`]), then a threading cycle's moves
    /// ([`cycles`]) or the block's move ([`moves`]).
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
        self.ticker
            .tick()
            .map_err(|e| self.fault(i, e.to_string()))?;
        self.current = at.mac.file();
        at.next = i + 1;
        let mut code = self.code_of(at, i, text)?;
        let mut evaluated = None;
        if let Some(m) = self.macros.filter(|_| !code.trim().is_empty()) {
            if at.st.ended && at.mac.frames.is_empty() {
                // After the program's end: only other programs (Fanuc's
                // O sections) follow, never read unless called.
                if crate::program::macros::scan::is_program_line(m.language, &code) {
                    at.stopped = true;
                    return Ok(());
                }
            } else {
                let env = crate::program::macros::Env {
                    lang: m.language,
                    file: &self.files[self.current],
                    line: i,
                    round_axes: self.least_input.or(self.d.reading.least_input),
                    axes: &self.names,
                    repeats_in_p: m.repeats_in_p,
                };
                let step = crate::program::macros::step(&env, &mut at.mac, &code)
                    .map_err(|e| self.err(self.in_file(code_place(&code, i)), e))?;
                self.follow(at, i, step.flow)
                    .map_err(|e| self.err(self.in_file(code_place(&code, i)), e))?;
                match step.left {
                    crate::program::macros::Left::Nothing => return Ok(()),
                    crate::program::macros::Left::Same => {}
                    crate::program::macros::Left::Code(c) => {
                        evaluated = Some(c.clone());
                        code = c;
                    }
                }
            }
        }
        let read = self.block_line(at, i, text, code, out);
        match (read, evaluated) {
            (Err(mut e), Some(c)) => {
                e.message = format!(
                    "{} (the block as the control evaluates it: {})",
                    e.message,
                    crate::files::excerpt(c.trim())
                );
                Err(e)
            }
            (r, _) => r,
        }
    }

    /// Line `i`'s block, `code` (its statements carried out), read: its
    /// own words, its number and ISO words, the setup's words, then a
    /// threading cycle's moves or the block's move.
    fn block_line(
        &mut self,
        at: &mut Standing,
        i: usize,
        text: &str,
        mut code: String,
        out: &mut Vec<ReadMove>,
    ) -> Result<(), LintError> {
        let own = self.own_words(&mut code, i)?;
        let Some(block) = self.block_of(at, i, text, code, own)? else {
            return Ok(());
        };
        if self.is_dwell(&block) {
            let s = self.dwell(at, &block)?;
            if at.dwell_next == 0.0 {
                at.dwell_by = Some(self.place(&block, at.k));
            }
            at.dwell_next += s;
            return Ok(());
        }
        let said = self.words_of(at, &block)?;
        self.setup_words(&mut at.st, &block, at.k, &said)?;
        if said.motion == Some(76) {
            return self.cycle(at, &block, &said, out);
        }
        // Fanuc's G92 is modal: a block of X (and Z) under it is a pass.
        let moves = said.read.iter().any(|(c, ..)| self.names.contains(c));
        if said.motion == Some(92) || (said.motion.is_none() && at.st.motion == Some(92) && moves) {
            return self.g92(at, &block, &said, out);
        }
        if said.motion.is_some() {
            at.st.cycle_start = None;
        }
        self.moves(at, &block, said, out)
    }

    /// A fault at `place` (`N20`, `line 3`).
    fn err(&self, place: String, message: String) -> LintError {
        LintError {
            what: self.what(),
            dialect: self.d.name.to_owned(),
            place,
            message,
        }
    }

    /// Where block `b` is, for a message, with `k` moves read before it: its
    /// number where the text is read as it stands, the axis program's
    /// block `k` where it is held to one, else its line.
    fn place(&self, b: &Block, k: usize) -> String {
        if self.reading {
            self.in_file(
                b.number
                    .map_or_else(|| at_line(b.line), |n| format!("N{n}")),
            )
        } else if k < self.program.blocks.len() {
            name_in(self.d.name, &self.program.blocks, k)
        } else {
            at_line(b.line)
        }
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
        if at.dwell_next > 0.0 {
            return Err(self.err(
                at.dwell_by.clone().unwrap_or_else(|| at_line(last)),
                format!(
                    "a dwell of {} s after the last move: the verification counts a dwell's time before the move that follows it, and none does",
                    at.dwell_next
                ),
            ));
        }
        Ok(Linted {
            moves: at.k,
            lines: self.lines,
        })
    }
}

impl Reader<'_> {
    /// Where a move read now comes from: the file being read, and the
    /// program's own line whose call made it (where a subprogram's did).
    fn origin(&self, at: &Standing) -> (usize, Option<usize>) {
        (
            self.current,
            at.mac.frames.first().map(|f| f.back.1.saturating_sub(1)),
        )
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
        let mut g = g.to_vec();
        g.extend(d.reading.read_g_codes);
        format!(
            ": a word the verification cannot simulate (it reads {} and {} in {} programs); verify a program without it",
            list('G', &g),
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
