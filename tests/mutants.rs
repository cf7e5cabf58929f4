//! A generated mutation test of the one G-code reader `verify` and the
//! lint share (`kernel/src/program/reader.rs`): pilgrim's default programs,
//! one word changed at a time, each change read as `pilgrim verify` reads
//! a program from a file.
//!
//! The programs: the mandrel and the caliber on Sinumerik, the worm and the
//! standard thread on Fanuc, and each posted for LinuxCNC (the worm with
//! one start: LinuxCNC's G33 has no start angle). The words: every word of
//! the setup blocks (before the first move), of the first and last block
//! of each pass (a pass begins at a comment line) and of 200 more blocks
//! drawn with a fixed seed. The changes, each word in turn: every G and M
//! code from 0 to 199, bare, with `.0` to `.9` and with a long decimal;
//! every letter as the word's address; the number with and without its
//! decimal point. Each mutant is refused naming the word, or read as the
//! dialect reads it ([`expected`]: the table of the dialect's rules); and
//! the harmless edits (a comment, spaces, leading and trailing zeros, a
//! renumbered block) read exactly as the program.
//!
//! Millions of mutants are read in seconds because the reader steps: the
//! standing before each line of the program is kept, a mutant's line is
//! read from it, and the reading goes on only until it stands where the
//! program's own reading stands (from there on the two read alike).

use crate::common::{default_run, pilgrim, s, scratch};
use pilgrim_kernel::machine::{Axis, MachineInfo};
use pilgrim_kernel::program::lint::LintError;
use pilgrim_kernel::program::post::{self, Dialect};
use pilgrim_kernel::program::reader::{Mode, ReadMove, Reader, Standing};
use pilgrim_kernel::program::{AxisProgram, PowerOn, Radial};
use pilgrim_kernel::toolpath::Motion;
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// A program under test: its lines, its dialect, the frame and axes its
/// machine gives the reader.
struct Subject {
    label: String,
    lines: Vec<String>,
    dialect: &'static Dialect,
    frame: AxisProgram,
    axes: Vec<Axis>,
    /// The control's power-on state as the machine states it (its
    /// parameters), where the program is in the machine's own dialect.
    power_on: PowerOn,
}

impl Subject {
    fn open(dir: &Path, file: &str, info: &MachineInfo) -> Self {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        let ext = file.rsplit('.').next().unwrap();
        let dialect = post::DIALECTS
            .iter()
            .copied()
            .find(|d| d.extension == ext)
            .unwrap();
        let mut lines: Vec<String> = text.split('\n').map(str::to_owned).collect();
        assert_eq!(
            lines.pop().as_deref(),
            Some(""),
            "{file} ends with a line feed"
        );
        Self {
            label: format!("{}/{file}", dir.file_name().unwrap().to_string_lossy()),
            lines,
            dialect,
            frame: pilgrim_kernel::program::frame(info),
            axes: info.axes.clone(),
            power_on: if info.control == dialect.name {
                info.setup.power_on.clone()
            } else {
                PowerOn::default()
            },
        }
    }

    fn reader(&self) -> Reader<'_> {
        let lines: Vec<&str> = self.lines.iter().map(String::as_str).collect();
        Reader::new(&lines, &self.frame, self.dialect, &self.axes, Mode::Read)
            .unwrap()
            .0
    }
}

/// The program's own reading: the standing before each line, the moves
/// each line makes.
struct Baseline {
    before: Vec<Standing>,
    moves: Vec<Vec<ReadMove>>,
}

fn baseline(subject: &Subject) -> Baseline {
    let lines: Vec<&str> = subject.lines.iter().map(String::as_str).collect();
    let (mut reader, mut at) = Reader::new(
        &lines,
        &subject.frame,
        subject.dialect,
        &subject.axes,
        Mode::Read,
    )
    .unwrap();
    let mut before = Vec::with_capacity(lines.len() + 1);
    let mut moves = Vec::with_capacity(lines.len());
    for (i, l) in lines.iter().enumerate() {
        before.push(at.clone());
        let mut here = Vec::new();
        reader
            .line(&mut at, i, l, &mut here)
            .unwrap_or_else(|e| panic!("{}: {e}", subject.label));
        moves.push(here);
    }
    reader.end(&at).unwrap();
    before.push(at);
    Baseline { before, moves }
}

/// How a mutant read.
enum Outcome {
    /// Refused.
    Refused(LintError),
    /// Read: the moves of lines `from..to`, after which the reading stands
    /// where the program's does, or (`lasting`) still differs at the
    /// reading's bound.
    Read {
        moves: Vec<ReadMove>,
        to: usize,
        lasting: bool,
    },
}

/// `text` in place of line `line`, read from the program's standing
/// before it, on until the reading stands where the program's does, or
/// `bound` lines on (an edit whose effect lasts: a lead or an axis the
/// program writes once changes every move after it).
fn read_mutant(
    reader: &mut Reader<'_>,
    subject: &Subject,
    base: &Baseline,
    line: usize,
    text: &str,
    bound: usize,
) -> Outcome {
    let mut at = base.before[line].clone();
    let mut moves = Vec::new();
    if let Err(e) = reader.line(&mut at, line, text, &mut moves) {
        return Outcome::Refused(e);
    }
    let mut i = line + 1;
    loop {
        if at == base.before[i] {
            return Outcome::Read {
                moves,
                to: i,
                lasting: false,
            };
        }
        if i - line > bound {
            return Outcome::Read {
                moves,
                to: i,
                lasting: true,
            };
        }
        if i == subject.lines.len() {
            return match reader.end(&at) {
                Ok(_) => Outcome::Read {
                    moves,
                    to: i,
                    lasting: false,
                },
                Err(e) => Outcome::Refused(e),
            };
        }
        if let Err(e) = reader.line(&mut at, i, &subject.lines[i], &mut moves) {
            return Outcome::Refused(e);
        }
        i += 1;
    }
}

/// A word of a line: its byte range and text.
#[derive(Clone)]
struct Token {
    start: usize,
    end: usize,
    text: String,
}

/// The words of a line's code (before its comment), as whitespace splits
/// them (Sinumerik's own words, `DIAMOF`, `FGROUP(A)`, `SF=90`, among them).
fn tokens(line: &str, d: &Dialect) -> Vec<Token> {
    let open = d.comment.0.trim_end();
    let code = match line.find(open) {
        Some(p) => &line[..p],
        None => line,
    };
    let mut out = Vec::new();
    let mut from = 0;
    for piece in code.split_whitespace() {
        let start = code[from..].find(piece).unwrap() + from;
        from = start + piece.len();
        out.push(Token {
            start,
            end: from,
            text: piece.to_owned(),
        });
    }
    out
}

/// Whether a token is an ISO word: a letter and a number.
fn iso(t: &str) -> bool {
    let mut c = t.chars();
    c.next().is_some_and(|l| l.is_ascii_uppercase())
        && c.as_str()
            .trim_start_matches(['+', '-'])
            .chars()
            .all(|c| c.is_ascii_digit() || c == '.')
        && t.len() > 1
}

/// The lines whose words are changed: the setup blocks (before the first
/// move), the first and last block of each pass, 200 more drawn with a
/// fixed seed.
fn chosen_lines(subject: &Subject, base: &Baseline) -> Vec<usize> {
    let d = subject.dialect;
    let code: Vec<bool> = subject
        .lines
        .iter()
        .map(|l| !tokens(l, d).is_empty())
        .collect();
    let first_move = base.moves.iter().position(|m| !m.is_empty()).unwrap();
    let mut chosen: Vec<usize> = (0..first_move).filter(|&i| code[i]).collect();
    // A pass: the code lines after a comment line, to the next.
    let mut run: Vec<usize> = Vec::new();
    let close = |run: &mut Vec<usize>, chosen: &mut Vec<usize>| {
        if let (Some(a), Some(b)) = (run.first(), run.last()) {
            chosen.push(*a);
            chosen.push(*b);
        }
        run.clear();
    };
    for (i, l) in subject.lines.iter().enumerate() {
        if code[i] {
            run.push(i);
        } else if tokens(l, d).is_empty() && l.trim_start().starts_with(d.comment.0.trim_end()) {
            close(&mut run, &mut chosen);
        }
    }
    close(&mut run, &mut chosen);
    // 200 more, by a fixed xorshift.
    let rest: Vec<usize> = (0..subject.lines.len())
        .filter(|i| code[*i] && !chosen.contains(i))
        .collect();
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut drawn = Vec::new();
    while drawn.len() < 200.min(rest.len()) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let i = rest[(x % rest.len() as u64) as usize];
        if !drawn.contains(&i) {
            drawn.push(i);
        }
    }
    chosen.extend(drawn);
    chosen.sort_unstable();
    chosen.dedup();
    chosen
}

/// Every G and M code 0..199 bare, `.0`..`.9` and a long decimal: the
/// changes any word is put through, made once for all the words.
fn codes() -> &'static [String] {
    static CODES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    CODES.get_or_init(|| {
        let mut out = Vec::with_capacity(4800);
        for c in ['G', 'M'] {
            for n in 0..200 {
                out.push(format!("{c}{n}"));
                for d in 0..10 {
                    out.push(format!("{c}{n}.{d}"));
                }
                out.push(format!("{c}{n}.000010"));
            }
        }
        out
    })
}

/// The changes of a word: the [`codes`]; every letter as its address; its
/// number with and without a decimal point. The word itself is not among
/// them.
fn variants(word: &str) -> Vec<Cow<'static, str>> {
    let mut out: Vec<Cow<'static, str>> =
        codes().iter().map(|c| Cow::Borrowed(c.as_str())).collect();
    if iso(word) {
        let number = &word[1..];
        for l in 'A'..='Z' {
            out.push(format!("{l}{number}").into());
        }
        let letter = &word[..1];
        match number.split_once('.') {
            Some((a, b)) => out.push(format!("{letter}{a}{b}").into()),
            None => out.push(format!("{letter}{number}.").into()),
        }
    }
    out.retain(|v| v != word);
    out
}

/// What a code does, as the dialect's manual lists it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Effect {
    /// A motion of group 1, modal: rapid, linear, thread.
    Motion(Kind),
    /// The working plane (G17, G18, G19).
    Plane(u32),
    /// A settable work offset (G54..G59).
    Offset(u32),
    /// A mode the program's setup states (units, absolute distances, the
    /// feed's mode, no cutter compensation, constant rpm): restating it
    /// changes nothing, and the moves need it stated.
    Setup(u32),
    /// LinuxCNC's lathe diameter (G7) or radius (G8) mode.
    Radial(bool),
    /// Exact stop or exact path (Sinumerik's G9 and G60, LinuxCNC's
    /// G61): the path through every block's end point, which the replay
    /// models; it changes nothing read.
    Exact,
    /// The spindle on (M3) or stopped (M5).
    Spindle(bool),
    /// The coolant on (M8) or off (M9).
    Coolant(bool),
    /// The program's end (M30, LinuxCNC's M2).
    End,
    /// A dwell (G4), in a block of its own: its time by one of the rules'
    /// dwell addresses.
    Dwell,
    /// Constant surface speed on (G96: S in m/min) or off (G97: S in rpm,
    /// written with it after G96).
    Surface(bool),
    /// Fanuc's G50: with S alone, the spindle's clamp.
    Clamp,
}

/// How the spindle's clamp under G96 is written.
#[derive(Clone, Copy, Debug, PartialEq)]
enum ClampBy {
    /// `G50 S` (Fanuc).
    G50,
    /// `D` in the G96 block (LinuxCNC).
    D,
    /// `LIMS=` (Sinumerik).
    Lims,
}

/// The unit of a dwell's address.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Unit {
    /// Seconds.
    Seconds,
    /// Milliseconds, written without a point.
    Millis,
    /// Seconds with a point, milliseconds without.
    ByPoint,
    /// Turns of the spindle at the speed in force.
    Turns,
}

/// A move's kind.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Rapid,
    Linear,
    Thread,
}

/// A dialect's rules as its manual gives them: the expected reading of a
/// mutant. Each row cites the rule.
struct Rules {
    /// The G codes and what each does.
    g: &'static [(u32, Effect)],
    /// The M codes.
    m: &'static [(u32, Effect)],
    /// Whether a code is read to a tenth (LinuxCNC: `G1.0` is G1, and
    /// `G33.1` another code); elsewhere a code is a whole number.
    code_tenths: bool,
    /// The unit of an axis value written without a decimal point.
    least_input: Option<f64>,
    /// The lead's address.
    lead: char,
    /// Whether a thread block must write its lead.
    lead_every_block: bool,
    /// Whether the feed's F is also the lead (one modal F).
    one_f: bool,
    /// The start angle: its one-letter address and units per degree, held
    /// for its block only (Fanuc's Q); `None`: Sinumerik's modal `SF=` or
    /// none.
    start_q: Option<(char, f64)>,
    /// The codes a program states before its first move.
    stated: &'static [u32],
    /// A dwell's addresses and their units.
    dwell: &'static [(char, Unit)],
    /// How the clamp of G96 is written.
    clamp: ClampBy,
}

use Effect::*;
use Kind::*;

/// SINUMERIK 840D sl Programming Manual, Fundamentals: "List of G
/// functions/preparatory functions" (G0, G1, G33 group 1; G17..G19 group
/// 6; G54..G59 group 8; G71 group 13; G90 group 14; G94 group 15; a G
/// function is a whole number), "Thread cutting with constant lead (G33)"
/// (Z with the lead K, modal with G33; `SF=` the start offset, modal),
/// "Feedrate (G93, G94, G95, F...)" (F modal), "Exact stop (G60, G9)"
/// (group 10 and non-modal: the path through each end point), "Dwell time
/// (G4)" (in a block of its own: F in seconds, S in turns of the master
/// spindle), "Constant cutting rate (G96/G97, LIMS)" (S in m/min at the
/// transverse axis's diameter, LIMS= the upper limit), "M functions" (M3,
/// M5, M30; M8/M9 the coolant, the machine maker's).
const SINUMERIK: Rules = Rules {
    g: &[
        (0, Motion(Rapid)),
        (1, Motion(Linear)),
        (33, Motion(Thread)),
        (17, Plane(17)),
        (18, Plane(18)),
        (19, Plane(19)),
        (54, Offset(54)),
        (55, Offset(55)),
        (56, Offset(56)),
        (57, Offset(57)),
        (58, Offset(58)),
        (59, Offset(59)),
        (71, Setup(71)),
        (90, Setup(90)),
        (94, Setup(94)),
        (9, Exact),
        (60, Exact),
        (4, Dwell),
        (96, Surface(true)),
        (97, Surface(false)),
    ],
    m: &[
        (3, Spindle(true)),
        (5, Spindle(false)),
        (8, Coolant(true)),
        (9, Coolant(false)),
        (30, End),
    ],
    code_tenths: false,
    least_input: None,
    lead: 'K',
    lead_every_block: false,
    one_f: false,
    start_q: None,
    stated: &[90, 94, 71],
    dwell: &[('F', Unit::Seconds), ('S', Unit::Turns)],
    clamp: ClampBy::Lims,
};

/// FANUC Series 0i-TC Operator's Manual (B-64114EN), G code system A:
/// "G code list" (G00, G01, G32 group 01; G97 group 02; G98 group 05; G21
/// group 06; G40 group 07; G54..G59 group 14; G17..G19 group 16), "Decimal
/// point programming" (an axis value without a point in the least input
/// increment, 0.001 mm with decimal-point input off, the factory
/// setting), "Thread cutting (G32)" (the lead by F, the one modal F; Q the
/// start angle in 0.001 deg, no decimal point, on its block only), "Dwell
/// (G04)" (X or U in seconds with a point, in the least input increment
/// without; P in milliseconds, no point), "Constant surface speed control
/// (G96, G97)" (S in m/min at the X coordinate's diameter; "Spindle speed
/// clamp": G50 S), "M codes" (M03, M05, M08, M09, M30).
const FANUC: Rules = Rules {
    g: &[
        (0, Motion(Rapid)),
        (1, Motion(Linear)),
        (32, Motion(Thread)),
        (17, Plane(17)),
        (18, Plane(18)),
        (19, Plane(19)),
        (21, Setup(21)),
        (40, Setup(40)),
        (54, Offset(54)),
        (55, Offset(55)),
        (56, Offset(56)),
        (57, Offset(57)),
        (58, Offset(58)),
        (59, Offset(59)),
        (97, Surface(false)),
        (98, Setup(98)),
        (4, Dwell),
        (96, Surface(true)),
        (50, Clamp),
    ],
    m: &[
        (3, Spindle(true)),
        (5, Spindle(false)),
        (8, Coolant(true)),
        (9, Coolant(false)),
        (30, End),
    ],
    code_tenths: false,
    least_input: Some(0.001),
    lead: 'F',
    lead_every_block: false,
    one_f: true,
    start_q: Some(('Q', 1000.0)),
    stated: &[21, 40, 98],
    dwell: &[
        ('X', Unit::ByPoint),
        ('U', Unit::ByPoint),
        ('P', Unit::Millis),
    ],
    clamp: ClampBy::G50,
};

/// LinuxCNC G-code reference, "G Codes" (G0, G1, G33 with K each block;
/// G7 lathe diameter mode, G8 radius mode; G17..G19; G21; G40; G54..G59;
/// G90; G94; G61 exact path; G4 a dwell of P seconds; G96 D S constant
/// surface speed, S in its block, D its clamp, and G97 rpm), "M Codes" (M2 end, M3, M5,
/// M8, M9), "Numbers" (a code
/// is read to a tenth: `G1.0` is G1). The reference for a changed reading
/// is its own interpreter, rs274 (a sample left for CI).
const LINUXCNC: Rules = Rules {
    g: &[
        (0, Motion(Rapid)),
        (1, Motion(Linear)),
        (33, Motion(Thread)),
        (7, Radial(true)),
        (8, Radial(false)),
        (17, Plane(17)),
        (18, Plane(18)),
        (19, Plane(19)),
        (21, Setup(21)),
        (40, Setup(40)),
        (54, Offset(54)),
        (55, Offset(55)),
        (56, Offset(56)),
        (57, Offset(57)),
        (58, Offset(58)),
        (59, Offset(59)),
        (90, Setup(90)),
        (94, Setup(94)),
        (97, Surface(false)),
        (61, Exact),
        (4, Dwell),
        (96, Surface(true)),
    ],
    m: &[
        (2, End),
        (3, Spindle(true)),
        (5, Spindle(false)),
        (8, Coolant(true)),
        (9, Coolant(false)),
    ],
    code_tenths: true,
    least_input: None,
    lead: 'K',
    lead_every_block: true,
    one_f: false,
    start_q: None,
    stated: &[21, 40, 90, 94],
    dwell: &[('P', Unit::Seconds)],
    clamp: ClampBy::D,
};

fn rules(d: &Dialect) -> &'static Rules {
    match d.name {
        "sinumerik" => &SINUMERIK,
        "fanuc" => &FANUC,
        "linuxcnc" => &LINUXCNC,
        other => panic!("no rules for {other}"),
    }
}

/// The control's state as the rules follow it.
#[derive(Clone, Debug, PartialEq, Default)]
struct Expect {
    motion: Option<Kind>,
    values: Vec<Option<f64>>,
    f: Option<f64>,
    lead: Option<f64>,
    start: f64,
    speed: Option<f64>,
    speed_next: Option<f64>,
    spindle: bool,
    coolant: bool,
    plane: Option<u32>,
    offset: Option<u32>,
    radial: Option<bool>,
    stated: Vec<u32>,
    ended: bool,
    moved: bool,
    /// The seconds of the dwells since the last move.
    dwell: f64,
    /// G96 in force, its speed (m/min) once written, the clamp (rpm).
    surface: bool,
    vc: Option<f64>,
    clamp: Option<f64>,
}

/// A move as the rules read it.
#[derive(Debug, PartialEq)]
struct Move {
    kind: Kind,
    values: Vec<Option<f64>>,
    feed: f64,
    lead: f64,
    start: f64,
    spindle: Option<f64>,
    dwell: f64,
}

impl Move {
    fn of(m: &ReadMove) -> Self {
        let (kind, lead, start) = match m.motion {
            Motion::Rapid => (Rapid, 0.0, 0.0),
            Motion::Linear => (Linear, 0.0, 0.0),
            Motion::Thread { lead, start_deg } => (Thread, lead, start_deg),
        };
        Self {
            kind,
            values: m.values.clone(),
            feed: m.feed,
            lead,
            start,
            spindle: m.spindle,
            dwell: m.dwell_s,
        }
    }
}

/// What the verification must refuse: the control would do what it does
/// not simulate.
type Refusal = String;

/// Line `text` as the rules read it from `at`; its moves pushed to `out`.
fn expect_line(
    subject: &Subject,
    at: &mut Expect,
    text: &str,
    out: &mut Vec<Move>,
) -> Result<(), Refusal> {
    let d = subject.dialect;
    let r = rules(d);
    let names: Vec<char> = subject
        .frame
        .axes
        .iter()
        .map(|a| a.name.chars().next().unwrap())
        .collect();
    let mut motion_here = None;
    let (mut surface_here, mut clamp_here, mut d_here) = (None, false, None);
    let mut axis = vec![None; names.len()];
    let mut letters: Vec<char> = Vec::new();
    let (mut lead_here, mut start_here, mut s_here) = (None, None, None);
    // A lead by its own address (K) is read on a thread block only
    // (LinuxCNC: "K word with no G2, G3, G33 ... to use it").
    let mut lead_word = false;
    // The tape's framing and Sinumerik's name line are no blocks.
    if text == "%" || text.starts_with("%_N_") {
        return Ok(());
    }
    let words = tokens(text, d);
    let g4 = |t: &Token| {
        let w = t.text.as_str();
        w.starts_with('G')
            && iso(w)
            && (w[1..].parse::<f64>().ok()).is_some_and(|v| code_number(r, w, &w[1..], v) == Ok(4))
    };
    if words.iter().any(g4) {
        return expect_dwell(r, at, &words);
    }
    for (n, t) in words.into_iter().enumerate() {
        let w = t.text.as_str();
        // Sinumerik's own words (the setup's; a start angle).
        if matches!(w, "DIAMOF" | "DIAMON") || w.starts_with("FGROUP(") {
            if at.moved {
                return Err(format!("{w} among the moves"));
            }
            continue;
        }
        if let Some(v) = w.strip_prefix("LIMS=").filter(|_| r.clamp == ClampBy::Lims) {
            let v: f64 = v.parse().map_err(|_| format!("{w}: not a clamp"))?;
            if !(v >= 1.0) {
                return Err(format!("{w}: a clamp below 1 rpm"));
            }
            at.clamp = Some(v);
            continue;
        }
        if let Some(v) = w.strip_prefix("SF=") {
            at.start = v.parse().map_err(|_| format!("{w}: not a start angle"))?;
            start_here = Some(at.start);
            continue;
        }
        if !iso(w) || w[1..].matches('.').count() > 1 {
            return Err(format!("{w}: not a word"));
        }
        let letter = w.chars().next().unwrap();
        let number = &w[1..];
        let value: f64 = number.parse().map_err(|_| format!("{w}: not a number"))?;
        match letter {
            'N' => {
                if n > 0 {
                    return Err(format!("{w}: a block number inside its block"));
                }
                continue;
            }
            'G' | 'M' => {
                let code = code_number(r, w, number, value)?;
                let table = if letter == 'G' { r.g } else { r.m };
                let Some((_, e)) = table.iter().find(|(c, _)| *c == code) else {
                    return Err(format!("{w}: not in the table"));
                };
                match *e {
                    Motion(k) => {
                        if motion_here.is_some() {
                            return Err(format!("{w}: two motions"));
                        }
                        motion_here = Some(k);
                    }
                    Plane(p) => {
                        if at.plane.is_some_and(|q| q != p) {
                            return Err(format!("{w}: a switch of the plane"));
                        }
                        at.plane = Some(p);
                    }
                    Offset(o) => {
                        // Before a selection, moves run in the power-on
                        // offset (the machine's, else G54).
                        let on = (subject.power_on.g.iter().copied())
                            .find(|c| *c == 500 || (54..=59).contains(c));
                        let now = at.offset.or(at.moved.then(|| on.unwrap_or(54)));
                        if now.is_some_and(|q| q != o) {
                            return Err(format!("{w}: a switch of the work offset"));
                        }
                        at.offset = Some(o);
                    }
                    Setup(c) => {
                        if r.stated.contains(&c) && !at.stated.contains(&c) {
                            at.stated.push(c);
                        }
                    }
                    Exact => {}
                    Radial(diameter) => {
                        if at.moved || at.radial.is_some() {
                            return Err(format!("{w}: diameter or radius among the moves"));
                        }
                        let want = subject.frame.setup.radial.map(|r| r == Radial::Diameter);
                        if want != Some(diameter) {
                            return Err(format!("{w}: not the setup's"));
                        }
                        at.radial = Some(diameter);
                    }
                    Spindle(on) => at.spindle = on,
                    Coolant(on) => at.coolant = on,
                    End => at.ended = true,
                    Dwell => unreachable!("a dwell's block is read apart"),
                    Surface(on) => surface_here = Some(on),
                    Clamp => clamp_here = true,
                }
                continue;
            }
            _ => {}
        }
        if letters.contains(&letter) {
            return Err(format!("{w}: {letter} twice"));
        }
        letters.push(letter);
        if let Some(i) = names.iter().position(|n| *n == letter) {
            // The machine's decimal-point parameter, else the dialect's.
            let unit = match subject.power_on.no_point {
                Some(1.0) => None,
                Some(u) => Some(u),
                None => r.least_input,
            };
            let v = match unit {
                Some(unit) if !number.contains('.') => value * unit,
                _ => value,
            };
            axis[i] = Some(v);
            continue;
        }
        match letter {
            'F' if !(value > 0.0) => return Err(format!("{w}: a feed not positive")),
            'F' if r.one_f => {
                if !number.contains('.') {
                    return Err(format!("{w}: F without its point"));
                }
                at.f = Some(value);
                lead_here = Some(value);
            }
            'F' => at.f = Some(value),
            'S' => s_here = Some(value),
            'D' if r.clamp == ClampBy::D => d_here = Some(value),
            c if c == r.lead => {
                lead_here = Some(value);
                lead_word = true;
            }
            c if r.start_q.is_some_and(|(q, _)| q == c) => {
                if number.contains('.') {
                    return Err(format!("{w}: Q with a point"));
                }
                start_here = Some(value / r.start_q.unwrap().1);
            }
            'T' => {
                if at.moved || value != 1.0 && value != 101.0 {
                    return Err(format!("{w}: another tool, or a tool call among the moves"));
                }
            }
            c if d.reading.offset_word == Some(c) => {
                if number != "1" {
                    return Err(format!("{w}: another offset"));
                }
            }
            _ => return Err(format!("{w}: an address the dialect does not read here")),
        }
    }
    if let Some(v) = d_here {
        if surface_here != Some(true) {
            return Err(format!("D{v}: an address the dialect does not read here"));
        }
        if !(v >= 1.0) {
            return Err(format!("D{v}: a clamp below 1 rpm"));
        }
        at.clamp = Some(v);
    }
    if clamp_here {
        if axis.iter().any(Option::is_some) {
            return Err("G50 with an axis".into());
        }
        let v = s_here.take().ok_or("G50 without S")?;
        if !(v >= 1.0) {
            return Err(format!("S{v}: a clamp below 1 rpm"));
        }
        at.clamp = Some(v);
    }
    if surface_here == Some(true) && r.clamp == ClampBy::D && s_here.is_none() {
        return Err("G96 without S in its block".into());
    }
    if let Some(on) = surface_here {
        if !on && at.vc.is_some() {
            if s_here.is_none() {
                return Err("G97 after G96 without S".into());
            }
            at.vc = None;
        }
        at.surface = on;
    }
    if at.surface {
        if let Some(v) = s_here.take() {
            if !(v > 0.0) {
                return Err(format!("S{v}: a surface speed not above 0"));
            }
            at.vc = Some(v);
        }
    }
    if let Some(v) = s_here {
        // A speed among the moves (or on a move) is the next move's.
        if at.moved || axis.iter().any(Option::is_some) {
            at.speed_next = Some(v);
        }
        at.speed = Some(v);
    }
    if at.ended && (motion_here.is_some() || axis.iter().any(Option::is_some)) {
        return Err("a move after the end".into());
    }
    if let Some(m) = motion_here {
        at.motion = Some(m);
    }
    if let Some(l) = lead_here {
        at.lead = Some(l);
    }
    if axis.iter().all(Option::is_none) {
        if lead_word && !r.one_f {
            return Err("a lead without a thread block".into());
        }
        if motion_here.is_some() {
            return Err("a motion without an axis".into());
        }
        if r.start_q.is_some() && start_here.is_some() {
            return Err("a start angle without a thread".into());
        }
        return Ok(());
    }
    // A move.
    let kind = at.motion.ok_or("a move before a motion")?;
    if at.surface {
        surface_speed(subject, at, kind, &axis)?;
    }
    if let Some(c) = r.stated.iter().find(|c| !at.stated.contains(c)) {
        return Err(format!("a move before G{c} is stated"));
    }
    if kind != Rapid {
        if !at.spindle || at.speed.is_none() {
            return Err("a cut with the spindle stopped".into());
        }
        if subject.frame.setup.coolant && !at.coolant {
            return Err("a cut with the coolant off".into());
        }
    }
    if kind == Linear && at.f.is_none() {
        return Err("a feed move before any F".into());
    }
    if kind != Thread && lead_word && !r.one_f {
        return Err("a lead without a thread block".into());
    }
    if kind == Thread && r.lead_every_block && lead_here.is_none() {
        return Err("a thread block without its lead".into());
    }
    if kind != Thread && r.start_q.is_some() && start_here.is_some() {
        return Err("a start angle without a thread".into());
    }
    for (i, v) in axis.iter().enumerate() {
        if let Some(v) = v {
            let name = &subject.frame.axes[i].name;
            let a = subject.axes.iter().find(|a| &a.name == name).unwrap();
            let (lo, hi) = (a.to_user(a.min), a.to_user(a.max));
            if *v < lo - 1e-3 || *v > hi + 1e-3 {
                return Err(format!("{name}{v} beyond the travel"));
            }
            at.values[i] = Some(*v);
        }
    }
    at.moved = true;
    let lead = at.lead.unwrap_or(0.0);
    let start = if r.start_q.is_some() {
        start_here.unwrap_or(0.0)
    } else {
        at.start
    };
    if kind == Thread && !(lead > 0.0) {
        return Err("a thread before any lead".into());
    }
    out.push(Move {
        kind,
        values: at.values.clone(),
        feed: match kind {
            Rapid => 0.0,
            Linear => at.f.unwrap_or(0.0),
            Thread => lead * at.speed.unwrap_or(0.0),
        },
        lead: if kind == Thread { lead } else { 0.0 },
        start: if kind == Thread { start } else { 0.0 },
        spindle: at.speed_next.take(),
        dwell: std::mem::take(&mut at.dwell),
    });
    Ok(())
}

/// The spindle's speed under G96 for a move of `kind` to `axis` (the
/// values it writes) from where `at` stands: `1000 v / (pi D)` at the
/// diameter a rapid ends at, the larger a cut passes (the X axis on the
/// setup's programming), within the clamp and the spindle's range.
fn surface_speed(
    subject: &Subject,
    at: &mut Expect,
    kind: Kind,
    axis: &[Option<f64>],
) -> Result<(), Refusal> {
    if kind == Thread {
        return Err("a thread under G96".into());
    }
    let vc = at.vc.ok_or("a move under G96 before its speed")?;
    let setup = &subject.frame.setup;
    let i = (subject.frame.axes.iter())
        .position(|a| a.name == setup.radial_axis)
        .ok_or("G96 with no radial axis")?;
    let per = match setup.radial.ok_or("G96 with no radial programming")? {
        Radial::Radius => 2.0,
        Radial::Diameter => 1.0,
    };
    let d = |v: Option<f64>| v.map_or(0.0, |v| v.abs() * per);
    let to = axis[i].or(at.values[i]);
    let dia = if kind == Rapid {
        d(to)
    } else {
        d(at.values[i]).max(d(to))
    };
    let spindle =
        (subject.axes.iter()).find(|a| a.kind == pilgrim_kernel::machine::AxisKind::Spindle);
    let top = match (at.clamp, spindle) {
        (Some(c), Some(s)) => c.min(s.max),
        (Some(c), None) => c,
        (None, Some(s)) => s.max,
        (None, None) => return Err("G96 with no clamp".into()),
    };
    let low = spindle.map_or(1.0, |s| s.min.max(1.0));
    let rpm = if dia > 0.0 {
        (1000.0 * vc / (std::f64::consts::PI * dia)).min(top)
    } else {
        top
    }
    .max(low);
    if at.speed != Some(rpm) {
        at.speed = Some(rpm);
        at.speed_next = Some(rpm);
    }
    Ok(())
}

/// A code word's number (`number` after its letter, `value` its value)
/// as the rules read it.
fn code_number(r: &Rules, w: &str, number: &str, value: f64) -> Result<u32, Refusal> {
    if r.code_tenths {
        let tenths = value * 10.0;
        if number.starts_with(['+', '-']) || (tenths - tenths.round()).abs() > 1e-9 {
            return Err(format!("{w}: not a code"));
        }
        if tenths.round() % 10.0 != 0.0 {
            return Err(format!("{w}: a code with tenths the table has not"));
        }
        Ok((tenths.round() / 10.0) as u32)
    } else {
        if !number.chars().all(|c| c.is_ascii_digit()) {
            return Err(format!("{w}: a code is a whole number"));
        }
        Ok(value as u32)
    }
}

/// A dwell's block (`words`, a G4 among them) as the rules read it: its
/// number, G4 and one time, nothing else; the seconds kept for the next
/// move.
fn expect_dwell(r: &Rules, at: &mut Expect, words: &[Token]) -> Result<(), Refusal> {
    let mut time = None;
    for (n, t) in words.iter().enumerate() {
        let w = t.text.as_str();
        if !iso(w) || w[1..].matches('.').count() > 1 {
            return Err(format!("{w}: not a word in a dwell's block"));
        }
        let (letter, number) = (w.chars().next().unwrap(), &w[1..]);
        let value: f64 = number.parse().map_err(|_| format!("{w}: not a number"))?;
        if letter == 'N' && n == 0 {
            continue;
        }
        if letter == 'G' && code_number(r, w, number, value) == Ok(4) {
            continue;
        }
        let Some((_, unit)) = r.dwell.iter().find(|(c, _)| *c == letter) else {
            return Err(format!("{w}: another word in a dwell's block"));
        };
        if time.is_some() {
            return Err(format!("{w}: a second time"));
        }
        if value < 0.0 {
            return Err(format!("{w}: a time below 0"));
        }
        let point = number.contains('.');
        time = Some(match unit {
            Unit::Seconds => value,
            Unit::Millis if point => return Err(format!("{w}: milliseconds with a point")),
            Unit::Millis => value / 1000.0,
            Unit::ByPoint if point => value,
            Unit::ByPoint => value / 1000.0,
            Unit::Turns => match at.speed {
                Some(s) if at.spindle && s > 0.0 => value * 60.0 / s,
                _ => return Err(format!("{w}: turns of a spindle that stands")),
            },
        });
    }
    at.dwell += time.ok_or("a dwell without its time")?;
    Ok(())
}

/// The rules' state before each line of the program, and its moves.
fn expect_program(subject: &Subject) -> (Vec<Expect>, Vec<Move>) {
    // The setup codes the control is in at power-on, by the machine.
    let stated = rules(subject.dialect).stated.iter().copied();
    let mut at = Expect {
        values: vec![None; subject.frame.axes.len()],
        stated: stated.filter(|c| subject.power_on.g.contains(c)).collect(),
        surface: subject.power_on.g.contains(&96),
        ..Expect::default()
    };
    let mut before = Vec::new();
    let mut moves = Vec::new();
    for l in &subject.lines {
        before.push(at.clone());
        expect_line(subject, &mut at, l, &mut moves)
            .unwrap_or_else(|e| panic!("{}: the rules refuse '{l}': {e}", subject.label));
    }
    before.push(at);
    (before, moves)
}

/// The harmless edits of line `line` of `subject` (each the whole line):
/// a comment after the words, spaces doubled and one after the last word,
/// the block renumbered within the gap to the next, a leading zero on
/// every number, a trailing zero on every number with a point.
fn harmless(subject: &Subject, line: usize) -> Vec<String> {
    let text = &subject.lines[line];
    let d = subject.dialect;
    // The tape's framing and Sinumerik's name line are no blocks.
    if text.starts_with('%') {
        return Vec::new();
    }
    let mut out = vec![
        commented(text, d),
        spaced(text),
        zeros(text, d, true),
        zeros(text, d, false),
    ];
    // The block renumbered where the numbering leaves room.
    let number = |l: &str| -> Option<u32> { l.strip_prefix('N')?.split(' ').next()?.parse().ok() };
    if let Some(n) = number(text) {
        let next = subject.lines[line + 1..].iter().find_map(|l| number(l));
        if next.is_none_or(|m| m > n + 1) {
            out.push(text.replacen(&format!("N{n}"), &format!("N{}", n + 1), 1));
        }
    }
    out.retain(|v| v != text);
    out
}

/// A block with a comment after its words.
fn commented(text: &str, d: &Dialect) -> String {
    format!("{text} {}NOTE{}", d.comment.0, d.comment.1)
}

/// A block with its spaces doubled and one after its last word.
fn spaced(text: &str) -> String {
    format!("{} ", text.replace(' ', "  "))
}

/// A block with a leading zero on every number (`leading`), or a trailing
/// zero on every number with a point.
fn zeros(text: &str, d: &Dialect, leading: bool) -> String {
    let mut t = text.to_owned();
    for w in tokens(text, d).iter().rev().filter(|w| iso(&w.text)) {
        let (l, n) = w.text.split_at(1);
        let v = if leading {
            match n.strip_prefix('-') {
                Some(n) => format!("{l}-0{n}"),
                None => format!("{l}0{n}"),
            }
        } else if n.contains('.') {
            format!("{}0", w.text)
        } else {
            continue;
        };
        t.replace_range(w.start..w.end, &v);
    }
    t
}

/// Every block of `text` (a program in `d`) with every harmless edit but
/// the renumbering (which renames the blocks a report names).
fn all_harmless(text: &str, d: &Dialect) -> String {
    text.lines()
        .map(|l| {
            if l.starts_with('%') || tokens(l, d).is_empty() {
                l.to_owned()
            } else {
                commented(&spaced(&zeros(&zeros(l, d, true), d, false)), d)
            }
        })
        .map(|l| l + "\n")
        .collect()
}

/// The program of each default job verified as a whole with every
/// harmless edit on every block (a comment, spaces, leading and trailing
/// zeros): the verification's figures are the program's own.
#[test]
fn a_program_with_every_harmless_edit_verifies_with_identical_figures() {
    let mandrel = default_run("mutants", "mandrel", "harmless-mandrel");
    let thread = posted("thread", "harmless-thread", &[]);
    // The lathe with a LinuxCNC control, for the program posted for it.
    let lathe = pilgrim_kernel::machine::machine_file(&fanuc_0i_tc::describe(), "its crate");
    assert!(lathe.contains("control = \"fanuc\""));
    let linuxcnc_lathe = thread.parent().unwrap().join("linuxcnc-lathe.toml");
    std::fs::write(
        &linuxcnc_lathe,
        crate::common::with_control(&lathe, "linuxcnc"),
    )
    .unwrap();
    for (dir, file, machine, family) in [
        (&mandrel, "program.mpf", "3K152VF20", "scripts/mandrel.rhai"),
        (&thread, "program.nc", "fanuc-0i-tc", "scripts/thread.rhai"),
        (
            &thread,
            "program.ngc",
            s(&linuxcnc_lathe),
            "scripts/thread.rhai",
        ),
    ] {
        let d = post::DIALECTS
            .iter()
            .find(|d| file.ends_with(d.extension))
            .unwrap();
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        let edited = all_harmless(&text, d);
        assert_ne!(edited, text);
        let verified = |name: &str, text: &str| {
            let path = dir.parent().unwrap().join(name);
            std::fs::write(&path, text).unwrap();
            let (code, _, err) = pilgrim(&[
                "verify",
                s(&path),
                "--machine",
                machine,
                "--family",
                family,
                "-q",
            ]);
            assert_eq!(code, 0, "{name}: {err}");
            let report = path
                .with_file_name(format!("{name}.verify"))
                .join("report.json");
            let report: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
            // The family's verification, and the verdict's figures.
            let key = ["verification", "groove_verification", "thread_verification"]
                .into_iter()
                .find(|k| report.get(k).is_some())
                .unwrap_or_else(|| panic!("{name}: no verification in its report"));
            (report[key].clone(), report["verdict"].clone())
        };
        let ext = file.rsplit('.').next().unwrap();
        let own = verified(&format!("OWN.{ext}"), &text);
        assert!(own.0.is_object() && own.1["status"] == "passed", "{own:?}");
        assert_eq!(
            verified(&format!("EDITED.{ext}"), &edited),
            own,
            "{file} with every harmless edit"
        );
    }
}

/// The statistics of a subject's mutants.
#[derive(Default, Debug)]
struct Tally {
    mutants: usize,
    refused: usize,
    same: usize,
    changed: usize,
    /// Read edits whose effect lasts past the reading's bound.
    lasting: usize,
    /// Harmless edits, each read as the program.
    harmless: usize,
}

/// How far past its line a mutant is read and compared line by line
/// while its reading differs from the program's (every 64th to the end).
const BOUND: usize = 400;

/// Whether the refusal `e` names the edit: the word `word` (as written,
/// or as a code without its leading zeros: `M03` is named `M3`), or the
/// block `block` it stands in (its `N`, or its line where the program
/// numbers no blocks), where the refusal is of what the edit took away.
fn names_edit(e: &LintError, word: &str, block: &str) -> bool {
    let said = &e.message;
    // The block by its whole name: N4 is not N40.
    let whole_name = said
        .match_indices(block)
        .any(|(i, _)| !said[i + block.len()..].starts_with(|c: char| c.is_ascii_digit()));
    if e.place == block || whole_name {
        return true;
    }
    if said.contains(word) {
        return true;
    }
    // A code as its dialect compares it: `M03` is M3, LinuxCNC's `G8.0` G8.
    iso(word) && {
        let (l, n) = word.split_at(1);
        let n = n.trim_start_matches('0');
        let n = match n.split_once('.') {
            Some((i, f)) if f.chars().all(|c| c == '0') => i,
            _ => n,
        };
        // `N00` is block N0.
        let n = if n.is_empty() && !word[1..].is_empty() {
            "0"
        } else {
            n
        };
        !n.is_empty() && said.contains(&format!("{l}{n}"))
    }
}

/// Every mutant of `subject`: the tally, and what failed (each failure
/// once per kind, with how many mutants it stands for).
fn mutate(subject: &Subject) -> (Tally, Vec<String>) {
    let base = baseline(subject);
    let (rules_before, rules_moves) = expect_program(subject);
    let read: Vec<Move> = base.moves.iter().flatten().map(Move::of).collect();
    assert_eq!(read.len(), rules_moves.len(), "{}", subject.label);
    for (n, (a, b)) in read.iter().zip(&rules_moves).enumerate() {
        assert_eq!(
            a,
            b,
            "{}: move {}: the reader and the rules",
            subject.label,
            n + 1
        );
    }
    let mut reader = subject.reader();
    let mut tally = Tally::default();
    // The first changed reading of each kind of edit, for LinuxCNC's own
    // interpreter.
    let mut sampled: Vec<(String, usize, String)> = Vec::new();
    let mut failures: std::collections::BTreeMap<String, (usize, String)> = Default::default();
    let mut fail = |key: String, what: String| {
        failures.entry(key).or_insert((0, what)).0 += 1;
    };
    // One buffer for every mutant's text.
    let mut mutant = String::new();
    for line in chosen_lines(subject, &base) {
        let text = &subject.lines[line];
        // The block as a refusal names it.
        let line_name = format!("line {}", line + 1);
        let block = match text.split_whitespace().next() {
            Some(n) if n.starts_with('N') && n.len() > 1 => n.to_owned(),
            _ => format!("line {}", line + 1),
        };
        // The harmless edits read as the program.
        for edit in harmless(subject, line) {
            tally.harmless += 1;
            let same = match read_mutant(&mut reader, subject, &base, line, &edit, usize::MAX) {
                Outcome::Refused(e) => Err(e.to_string()),
                Outcome::Read { moves, to, .. } => {
                    let got: Vec<Move> = moves.iter().map(Move::of).collect();
                    let want: Vec<Move> = base.moves[line..to]
                        .iter()
                        .flatten()
                        .map(Move::of)
                        .collect();
                    if got == want {
                        Ok(())
                    } else {
                        Err(format!("read as {got:?}, the program as {want:?}"))
                    }
                }
            };
            if let Err(why) = same {
                fail(
                    format!("harmless {}", edit.len() as isize - text.len() as isize),
                    format!(
                        "'{edit}' for '{text}': a harmless edit not read as the program: {why}"
                    ),
                );
            }
        }
        for t in tokens(text, subject.dialect) {
            for v in variants(&t.text) {
                mutant.clear();
                mutant.push_str(&text[..t.start]);
                mutant.push_str(&v);
                mutant.push_str(&text[t.end..]);
                tally.mutants += 1;
                // Named only where an edit fails or is sampled.
                let class = || {
                    format!(
                        "{}->{}",
                        t.text.chars().next().unwrap(),
                        v.chars().next().unwrap()
                    )
                };
                // Every 64th edit whose effect lasts is read to the end.
                let mut outcome = read_mutant(&mut reader, subject, &base, line, &mutant, BOUND);
                if let Outcome::Read { lasting: true, .. } = outcome {
                    tally.lasting += 1;
                    if tally.lasting % 64 == 0 {
                        outcome =
                            read_mutant(&mut reader, subject, &base, line, &mutant, usize::MAX);
                    }
                }
                match outcome {
                    Outcome::Refused(e) => {
                        tally.refused += 1;
                        if let Some(rust) = crate::common::rust_text(&e.message)
                            .or_else(|| crate::common::rust_text(&e.place))
                        {
                            fail(
                                format!("rust text {rust}"),
                                format!("'{mutant}': Rust's text {rust} in the refusal: {e}"),
                            );
                        }
                        // A block whose N the edit took away is named by
                        // its line (a program read as it stands numbers its
                        // blocks as it likes).
                        let named = |w: &str| {
                            names_edit(&e, w, &block)
                                || (t.text.starts_with('N') && e.place == line_name)
                        };
                        if !named(&v) && !named(&t.text) {
                            fail(
                                format!(
                                    "unnamed {} {}",
                                    class(),
                                    e.message.split(':').next().unwrap_or("")
                                ),
                                format!(
                                    "'{mutant}' ({} for {v}): refused naming neither: {e}",
                                    t.text
                                ),
                            );
                        }
                    }
                    Outcome::Read { moves, to, lasting } => {
                        let got: Vec<Move> = moves.iter().map(Move::of).collect();
                        let mut at = rules_before[line].clone();
                        let mut want = Vec::new();
                        let ruled = (line..to).try_for_each(|i| {
                            let l = if i == line {
                                &mutant
                            } else {
                                &subject.lines[i]
                            };
                            expect_line(subject, &mut at, l, &mut want)
                        });
                        if let Err(why) = ruled {
                            fail(
                                format!(
                                    "accepted {} {}",
                                    class(),
                                    why.split(':').next_back().unwrap_or("")
                                ),
                                format!(
                                    "'{mutant}' ({} for {v}): read, where the control would {why}",
                                    t.text
                                ),
                            );
                        } else if got != want {
                            fail(
                                format!("misread {}", class()),
                                format!("'{mutant}' ({} for {v}): read as {got:?}, the rules read {want:?}", t.text),
                            );
                        } else if !lasting && to < subject.lines.len() && at != rules_before[to] {
                            fail(
                                format!("unfollowed {}", class()),
                                format!("'{mutant}' ({} for {v}): the reader stands as the program does after line {to}, the control does not: {at:?}", t.text),
                            );
                        } else if got.iter().eq(base.moves[line..to]
                            .iter()
                            .flatten()
                            .map(Move::of)
                            .collect::<Vec<_>>()
                            .iter())
                        {
                            tally.same += 1;
                        } else {
                            tally.changed += 1;
                            if sampled.len() < 40 {
                                let class = class();
                                if !sampled.iter().any(|(c, _, _)| *c == class) {
                                    sampled.push((class, line, mutant.clone()));
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    if subject.dialect.name == "linuxcnc" {
        leave_for_rs274(subject, &sampled);
    }
    let failures = failures
        .into_iter()
        .map(|(k, (n, what))| format!("{} x{n} [{k}]: {what}", subject.label))
        .collect();
    (tally, failures)
}

/// Each mutant of `sampled` (its line and text) as a whole program with
/// the reader's reading of it, for CI's `rs274` check
/// (`.ci/rs274_check.py`: LinuxCNC's interpreter must make the moves the
/// reader read), where rs274's standalone axes (X Y Z A B C) hold the
/// program's: an axis it lacks (the rest's U) is read there as a rotary
/// letter the program leaves free.
fn leave_for_rs274(subject: &Subject, sampled: &[(String, usize, String)]) {
    let names: Vec<&str> = subject.frame.axes.iter().map(|a| a.name.as_str()).collect();
    let lacking = names.iter().filter(|n| !"XYZABC".contains(**n)).count();
    let free = ["A", "B", "C"]
        .iter()
        .filter(|c| !names.contains(c))
        .count();
    if lacking > free {
        return;
    }
    let exe = std::env::current_exe().unwrap();
    let root = exe.ancestors().nth(3).unwrap().join("linuxcnc-check");
    let tag = subject.label.replace(['/', '.'], "-");
    for (n, (_, line, mutant)) in sampled.iter().enumerate() {
        let mut lines = subject.lines.clone();
        lines[*line] = mutant.clone();
        let text = lines.join("\n") + "\n";
        let read = pilgrim_kernel::program::lint::read(
            &text,
            &subject.frame,
            subject.dialect,
            &subject.axes,
        )
        .unwrap_or_else(|e| {
            panic!(
                "{}: '{mutant}' read line by line, not whole: {e}",
                subject.label
            )
        });
        let dir = root.join(format!("mutant-{tag}-{n:02}"));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("program.ngc"), &text).unwrap();
        std::fs::write(
            dir.join("program.json"),
            serde_json::to_string(&read.program).unwrap(),
        )
        .unwrap();
    }
}

/// A run of `scripts/<job>.rhai` with `sets`, posted for LinuxCNC too.
fn posted(job: &str, name: &str, sets: &[&str]) -> PathBuf {
    let out = scratch("mutants", name).join(job);
    let script = format!("scripts/{job}.rhai");
    let mut args = vec!["run", &script, "--out", s(&out), "-q", "--post", "linuxcnc"];
    for set in sets {
        args.extend(["--set", set]);
    }
    let (code, _, err) = pilgrim(&args);
    assert_eq!(code, 0, "{job} {sets:?}: {err}");
    out
}

#[test]
fn every_one_word_edit_of_the_default_programs_is_refused_by_name_or_read_as_the_control_reads_it()
{
    let grinder = grinder_3k152vf20::describe();
    let mannesmann = mannesmann::describe();
    let lathe = fanuc_0i_tc::describe();
    let mandrel = posted("mandrel", "mandrel", &[]);
    let caliber = posted("caliber", "caliber", &[]);
    let worm = default_run("mutants", "worm", "worm");
    let worm1 = posted("worm", "worm-one-start", &["z1=1"]);
    let thread = posted("thread", "thread", &[]);
    let filter = std::env::var("PILGRIM_MUTANTS").unwrap_or_default();
    let mut failures = Vec::new();
    let subjects = [
        (&mandrel, "program.mpf", &grinder),
        (&mandrel, "program.ngc", &grinder),
        (&caliber, "program.mpf", &mannesmann),
        (&caliber, "program.ngc", &mannesmann),
        (&worm, "program.nc", &lathe),
        (&worm1, "program.ngc", &lathe),
        (&thread, "program.nc", &lathe),
        (&thread, "program.ngc", &lathe),
    ];
    // The subjects side by side: each reads its own program.
    std::thread::scope(|scope| {
        let running: Vec<_> = subjects
            .iter()
            .map(|(dir, file, info)| Subject::open(dir, file, info))
            .filter(|subject| subject.label.contains(&filter))
            .map(|subject| {
                scope.spawn(move || {
                    let (tally, failed) = mutate(&subject);
                    eprintln!("{}: {tally:?}", subject.label);
                    failed
                })
            })
            .collect();
        for r in running {
            failures.extend(r.join().unwrap());
        }
    });
    assert!(
        failures.is_empty(),
        "{} kinds of mutant failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
