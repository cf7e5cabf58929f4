//! Every program pilgrim writes, read back and checked before it is
//! written, and every program `verify` reads: one reader, as strict as the
//! control. The text is read word by word (G-code by [`super::words`],
//! every character accounted for; the APT CL file by its records) and
//! held to the dialect and, for a program pilgrim wrote, to the axis
//! program it came from.
//!
//! The checks: every block numbered in order where the dialect numbers
//! blocks; only the words the dialect's table lists (its G and M codes
//! with their decimals exactly as written: `G33.1` is not G33, `G91.000010`
//! not a G code the table has; the program's axes, F, S, T, the lead's and
//! the start angle's addresses; no address twice in a block, no two
//! motions); the control's number rules (Fanuc: an axis value without a
//! decimal point in its least input unit, F with its point, Q without);
//! modal state (the setup's units, distance and feed mode stated before
//! the first move, never the power-on state assumed; one work offset, the
//! first selected; the tool with its own offset, `D1` or `T0101`; a feed
//! before the first G1, one modal F where the lead's address is F; the
//! spindle on before cutting, constant speed G97 before a thread on the
//! lathe dialects, a lead on a thread block where the dialect wants one, a
//! start angle on a thread block only); every axis value within the
//! machine's travel; the end (M30, LinuxCNC's M2, the `%` framing); and
//! every move read back, the modal values carried, equal to the axis
//! program's block within half the output's last decimal.
//!
//! Sinumerik's own words (`DIAMON`, `DIAMOF`, `FGROUP(..)`, `SF=`) and the
//! `%_N_.._MPF` header are read here, before the ISO words.

use super::post::{Dialect, Style};
use super::{name_in, AxisProgram, ProgramSetup};
use crate::machine::{Axis, AxisKind};
use crate::math::Real;
use crate::toolpath::Motion;
use pilgrim_plugin_abi::types::Radial;

/// A program that fails its lint: which program, where, what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("lint of the {dialect} program: {place}: {message}")]
pub struct LintError {
    /// The dialect.
    pub dialect: String,
    /// The block as the program numbers it (`N570`, `block 57 in "pass
    /// 3"`), or the line (`line 4`) outside the moves.
    pub place: String,
    /// What is wrong.
    pub message: String,
}

/// What a lint read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Linted {
    /// Moves read back and matched to the axis program's blocks.
    pub moves: usize,
    /// Lines read.
    pub lines: usize,
}

/// Lints `text`, the program `program` written in `d`, against the
/// machine's `axes` (their travel in program units).
///
/// # Failures
/// The first fault found, named by block or line.
pub fn lint(
    text: &str,
    program: &AxisProgram,
    d: &Dialect,
    axes: &[Axis],
) -> Result<Linted, LintError> {
    match d.style {
        Style::Apt => lint_apt(text, program, d),
        Style::GCode => lint_gcode(text, program, d, axes, Mode::Lint).map(|r| r.linted),
    }
}

/// A program as a control reads its text: its blocks, and where each
/// stands in the text (the page's listing shows the block the player is
/// at).
#[derive(Debug, Clone, PartialEq)]
pub struct TextProgram {
    /// The program read.
    pub program: AxisProgram,
    /// The line (from 1) of each block's move, in the blocks' order.
    pub lines: Vec<usize>,
}

/// Reads `text`, a program in `d` for the machine whose axes (their
/// travel) are `axes`, as its control reads it: the lint's reader and
/// rules, the moves taken as they are written instead of held to an axis
/// program. `frame` is the program the text is for, without blocks: its
/// axes (the machine's programmed axes), its setup and decimals; the name,
/// number, tool number and spindle speed are the text's where it writes
/// them. Axes the text never writes are left out; an axis not yet written
/// is kept where it stands until its first value ([`super::Block::keep`],
/// as the writer's start does). Each block carries its `N` and, as its
/// comment, the last comment line before it since the move before: the
/// pass it begins.
///
/// # Failures
/// The first word or block the reader cannot account for, named by its
/// `N` or its line: a word outside the dialect's (an arc, a cycle, a
/// variable), a modal rule broken, a value beyond travel; a CL file (a
/// control reads G-code).
pub fn read(
    text: &str,
    frame: &AxisProgram,
    d: &Dialect,
    axes: &[Axis],
) -> Result<TextProgram, LintError> {
    if d.style != Style::GCode {
        return Err(LintError {
            dialect: d.name.to_owned(),
            place: "line 1".into(),
            message: "a CL file is not a program a control runs: read the control's program".into(),
        });
    }
    Ok(assemble(
        lint_gcode(text, frame, d, axes, Mode::Read)?,
        frame,
    ))
}

/// Lints `text`, the program `program` written in `d`, as [`lint`] does,
/// and returns the program as the control reads it: its values as the
/// text writes them, each pass named as `program` names it (the text
/// carries the names as its dialect's comments allow: Fanuc's in capitals).
/// What a run verifies is this, read in the same pass as its lint.
///
/// # Failures
/// As [`lint`]; a CL file, which no control runs.
pub fn lint_read(
    text: &str,
    program: &AxisProgram,
    d: &Dialect,
    axes: &[Axis],
) -> Result<TextProgram, LintError> {
    if d.style != Style::GCode {
        return Err(not_a_control_program(d));
    }
    let mut read = assemble(lint_gcode(text, program, d, axes, Mode::Lint)?, program);
    for (r, b) in read.program.blocks.iter_mut().zip(&program.blocks) {
        r.comment.clone_from(&b.comment);
    }
    Ok(read)
}

/// The refusal of a CL file where a control's program is wanted.
fn not_a_control_program(d: &Dialect) -> LintError {
    LintError {
        dialect: d.name.to_owned(),
        place: "line 1".into(),
        message: "a CL file is not a program a control runs: read the control's program".into(),
    }
}

/// The program `read` holds, for the machine's `frame` (its axes, setup,
/// decimals; its name, number, tool and speed where the text writes none).
/// Axes the text never writes are left out; an axis not yet written is
/// kept where it stands until its first value.
fn assemble(read: ReadText, frame: &AxisProgram) -> TextProgram {
    let lines = read.blocks.iter().map(|b| b.line + 1).collect();
    let written: Vec<usize> = (0..frame.axes.len())
        .filter(|&i| read.blocks.iter().any(|b| b.values[i].is_some()))
        .collect();
    // Each axis's first value, for the blocks before it moves.
    let first: Vec<Real> = written
        .iter()
        .map(|&i| {
            read.blocks
                .iter()
                .find_map(|b| b.values[i])
                .unwrap_or_default()
        })
        .collect();
    let blocks = read
        .blocks
        .into_iter()
        .map(|b| {
            let keep = written
                .iter()
                .filter(|&&i| b.values[i].is_none())
                .map(|&i| frame.axes[i].name.clone())
                .collect();
            super::Block {
                motion: b.motion,
                values: written
                    .iter()
                    .zip(&first)
                    .map(|(&i, f)| b.values[i].unwrap_or(*f))
                    .collect(),
                feed: b.feed,
                spindle: b.spindle,
                comment: b.comment,
                keep,
                number: b.number,
            }
        })
        .collect();
    let program = AxisProgram {
        name: read.name.unwrap_or_else(|| frame.name.clone()),
        number: read.number.unwrap_or(frame.number),
        machine: frame.machine.clone(),
        control: frame.control.clone(),
        tool_number: read.tool.unwrap_or(frame.tool_number),
        tool_name: frame.tool_name.clone(),
        spindle_rpm: read.rpm.unwrap_or(frame.spindle_rpm),
        decimals: frame.decimals,
        axes: written.iter().map(|&i| frame.axes[i].clone()).collect(),
        blocks,
        setup: frame.setup.clone(),
        cycles: Vec::new(),
    };
    TextProgram { program, lines }
}

/// Whether a G-code text is held to an axis program (the lint of a
/// program pilgrim wrote) or read as it stands ([`read`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Lint,
    Read,
}

/// A move as the reader took it: each axis's value where the text has
/// given one so far.
struct ReadBlock {
    motion: Motion,
    values: Vec<Option<Real>>,
    feed: Real,
    spindle: Option<Real>,
    comment: Option<String>,
    number: Option<u32>,
    /// The line it stands on (from 0).
    line: usize,
}

/// What a G-code text read as: the lint's count, the moves and what the
/// text says of the program.
struct ReadText {
    linted: Linted,
    blocks: Vec<ReadBlock>,
    name: Option<String>,
    number: Option<u32>,
    tool: Option<u32>,
    rpm: Option<Real>,
}

/// The modal state a G-code program has set so far.
#[derive(Default)]
struct State {
    motion: Option<u32>,
    feed: bool,
    /// The feed F as written, once written.
    f: Option<Real>,
    lead: Option<Real>,
    spindle_on: bool,
    /// The spindle's speed as written (S), none before the first.
    speed: Option<Real>,
    coolant: bool,
    constant_speed: bool,
    /// Diameter (true) or radius programming, once set.
    radial: Option<bool>,
    feed_group: bool,
    start_deg: Real,
    values: Vec<Option<Real>>,
    ended: bool,
    /// The G codes stated so far (the setup's modal states among them).
    stated: Vec<u32>,
    /// The work offset selected (G54..), once selected.
    work_offset: Option<u32>,
}

/// A word of Sinumerik's own, outside the ISO words the parser reads.
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
/// with its comments blanked in place (the same length, so the parser's
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

fn lint_gcode(
    text: &str,
    program: &AxisProgram,
    d: &Dialect,
    axes: &[Axis],
    mode: Mode,
) -> Result<ReadText, LintError> {
    let reading = mode == Mode::Read;
    let mut out = ReadText {
        linted: Linted { moves: 0, lines: 0 },
        blocks: Vec::new(),
        name: None,
        number: None,
        tool: None,
        rpm: None,
    };
    let fault = |place: String, message: String| LintError {
        dialect: d.name.to_owned(),
        place,
        message,
    };
    let at_line = |l: usize| format!("line {}", l + 1);
    let decimals = super::written_decimals(program.decimals, d.name);
    let half = 0.5 * 10f64.powi(-(decimals as i32)) + 1e-9;
    let (g_ok, m_ok) = (d.reading.g_codes, d.reading.m_codes);
    let lead_letter = d.lead.chars().next().unwrap_or('K');
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
    let lines: Vec<&str> = text.split('\n').collect();
    if lines.last() != Some(&"") {
        return Err(fault(
            at_line(lines.len() - 1),
            "the program's last line does not end with a line feed".into(),
        ));
    }
    let lines = &lines[..lines.len() - 1];
    // Each line as its control reads it: comments out of the way of the ISO
    // parser (blanked in place, so spans stay valid) and checked, the
    // header's own lines recognised where they stand, Sinumerik's own
    // words read.
    let mut code_lines: Vec<String> = Vec::with_capacity(lines.len());
    let mut own: Vec<Vec<OwnWord>> = vec![Vec::new(); lines.len()];
    // The comment of each line that holds nothing else.
    let mut comments: Vec<Option<String>> = vec![None; lines.len()];
    let mut has_code = vec![false; lines.len()];
    // A whole program is framed by `%` where its dialect frames one; a
    // program read as it stands says by its first line whether it is whole.
    let whole = if reading {
        lines.first() == Some(&"%")
    } else {
        program.number > 0
    };
    let framed = d.header.first().is_some_and(|h| *h == "%")
        || (d.header.first().is_some_and(|h| *h == "{WHOLE}%") && whole);
    // What the header's lines hold, and the dialect's own words (no ISO
    // words): radius and diameter programming by name (DIAMOF/DIAMON, not
    // G8/G7), the feed's group (FGROUP(..)), a start angle by an address
    // of more than a letter (SF=).
    let program_number = format!("O{:04}", program.number % 10000);
    let name_line = d.reading.name_line;
    let header_name = name_line.map(|(before, after)| format!("{before}{}{after}", program.name));
    let radial = d.radial_words.filter(|(r, _)| !is_g_code(r));
    let start = d.thread_start.map(|t| t.address).filter(|a| a.len() > 1);
    let mut ticker = crate::budget::Ticker::new("the program's lint", 1024);
    for (i, line) in lines.iter().enumerate() {
        ticker
            .tick()
            .map_err(|e| fault(at_line(i), e.to_string()))?;
        let (mut l, said) = read_line(d, i, line).map_err(|m| fault(at_line(i), m))?;
        if l.trim().is_empty() {
            comments[i] = said;
        }
        // A program read as it stands names itself.
        let own_name = name_line
            .and_then(|(before, after)| line.strip_prefix(before)?.strip_suffix(after))
            .filter(|n| {
                reading && !n.is_empty() && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            });
        let own_number = first_code(&l)
            .and_then(|w| w.strip_prefix('O'))
            .filter(|n| reading && n.len() == 4)
            .and_then(|n| n.parse::<u32>().ok());
        if i == 0 && (header_name.as_deref() == Some(*line) || own_name.is_some()) {
            out.name = own_name.map(str::to_owned);
            l = " ".repeat(line.len());
        } else if framed && *line == "%" && (i == 0 || i + 1 == lines.len()) {
            l = " ".into();
        } else if d.reading.number_line
            && framed
            && i == 1
            && (first_code(&l).is_some_and(|w| w == program_number) || own_number.is_some())
        {
            out.number = own_number;
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
                own[i].push(w);
                l = l.replacen(word, &" ".repeat(word.len()), 1);
            }
        }
        has_code[i] = !l.trim().is_empty() || !own[i].is_empty();
        code_lines.push(l);
    }
    let mut consumed = vec![false; lines.len()];
    let spindle = axes.iter().find(|a| a.kind == AxisKind::Spindle);
    // The framing: % first and last where the dialect frames.
    if framed {
        if lines.first() != Some(&"%") {
            return Err(fault(at_line(0), "the program must open with '%'".into()));
        }
        if lines.last() != Some(&"%") {
            return Err(fault(
                at_line(lines.len().saturating_sub(1)),
                "the program must close with '%'".into(),
            ));
        }
    }
    let mut st = State {
        values: vec![None; names.len()],
        ..State::default()
    };
    let mut last_n: Option<u32> = None;
    let mut k = 0; // the next move of the axis program
                   // Read: the first line not yet searched for a move's comment, and a
                   // speed set among the moves for the next move.
    let (mut comment_from, mut speed_next) = (0, None);
    for (line, code_text) in code_lines.iter().enumerate() {
        ticker
            .tick()
            .map_err(|e| fault(at_line(line), e.to_string()))?;
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
        let mut tokens = super::words::words(code_text).map_err(|m| fault(at_block(), m))?;
        let line_number = match tokens.first() {
            Some(w) if w.letter == 'N' => {
                let n = w
                    .whole()
                    .filter(|_| !w.number.starts_with('+'))
                    .ok_or_else(|| {
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
        let own_here = own.get_mut(line).map(std::mem::take).unwrap_or_default();
        if tokens.is_empty() && line_number.is_none() && own_here.is_empty() {
            continue;
        }
        if let Some(c) = consumed.get_mut(line) {
            *c = true;
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
            return Err(fault(place(k), "a block after the program's end".into()));
        }
        match (d.numbering, line_number) {
            (Some(_), None) => {
                return Err(fault(at_line(line), "a block without its number".into()))
            }
            (Some(_), Some(n)) => {
                if last_n.is_some_and(|m| n <= m) {
                    return Err(fault(
                        format!("N{n}"),
                        format!("numbered out of order, after N{}", last_n.unwrap_or(0)),
                    ));
                }
                last_n = Some(n);
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
        let mut radial_here: Vec<bool> = Vec::new();
        let mut feed_group_here: Vec<&str> = Vec::new();
        let mut sf_here = None;
        for w in &own_here {
            match w {
                OwnWord::Radial(diameter) => radial_here.push(*diameter),
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
                    let Some(n) = w.whole().filter(|n| listed.contains(n)) else {
                        return Err(fault(place(k), not_read(reading, d, w.letter, &w.number)));
                    };
                    if w.letter == 'M' {
                        match n {
                            3 => st.spindle_on = true,
                            5 => st.spindle_on = false,
                            8 => st.coolant = true,
                            9 => st.coolant = false,
                            n if n == d.reading.end_code => st.ended = true,
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
                        7 | 8 => radial_here.push(n == 7),
                        n if d.reading.work_offsets.contains(&n) => {
                            // The part zero is the work offset the program
                            // selects first (before its moves: the one in
                            // force at power-on, the first listed, if none).
                            let current = st
                                .work_offset
                                .or((k > 0).then(|| d.reading.work_offsets[0]));
                            match current {
                                Some(c) if c != n => {
                                    return Err(fault(
                                        place(k),
                                        format!(
                                            "{}: a switch of the work offset from G{c}, the part zero the verification places the part at (another part zero moves every later block); verify a program that keeps one",
                                            w.text()
                                        ),
                                    ))
                                }
                                _ => st.work_offset = Some(n),
                            }
                        }
                        _ => {}
                    }
                    if !st.stated.contains(&n) {
                        st.stated.push(n);
                    }
                }
                'T' => {
                    if k > 0 {
                        return Err(fault(
                            place(k),
                            format!("a tool call {} among the moves", w.text()),
                        ));
                    }
                    let n = w.whole().ok_or_else(|| {
                        fault(
                            place(k),
                            format!("{}: a tool call is a whole number", w.text()),
                        )
                    })?;
                    // A lathe's T names the tool and its offset (`T0303`):
                    // the model's tool is the tool with its own offset.
                    out.tool = Some(if d.reading.tool_and_offset {
                        let (tool, offset) = (n / 100, n % 100);
                        if n < 100 || offset != tool {
                            return Err(fault(
                                place(k),
                                format!(
                                    "{}: tool {tool:02} with offset {offset:02}; the verification's tool is a tool with its own offset (T{tool:02}{tool:02}: 00 cancels the offset, another number is another tool's)",
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
                    if out.tool != Some(program.tool_number) {
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
                    let v = match d.reading.least_input {
                        Some(unit) if !w.has_point() && names.contains(&letter) => w.value() * unit,
                        _ => w.value(),
                    };
                    if start_letter == Some(letter) {
                        start_word = Some(w.text());
                    }
                    if d.reading.offset_word == Some(letter) && w.whole() != Some(1) {
                        return Err(fault(
                            place(k),
                            format!(
                                "{}: another tool offset than {letter}1, the tool call's, which is the verification's tool ({letter}0 cancels it, another number is another edge's)",
                                w.text()
                            ),
                        ));
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
        for diameter in radial_here {
            let want = program.setup.radial.map(|r| r == Radial::Diameter);
            if k > 0 || st.radial.is_some() || want != Some(diameter) {
                return Err(fault(
                    place(k),
                    format!(
                        "{} where the machine's setup {}",
                        if diameter {
                            "diameter programming"
                        } else {
                            "radius programming"
                        },
                        match (want, k > 0 || st.radial.is_some()) {
                            (_, true) => "set it before the moves, once".to_owned(),
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
            if let Some(m) = cutting_fault(&st, d, &program.setup, what)
                .or(needs_g97)
                .or_else(|| setup_fault(&st, d, &program.setup, what))
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
                .map_err(|m| fault(place(k), m))?;
            let comment = comment_before(&comments, &mut comment_from, line);
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
                out.blocks.push(ReadBlock {
                    motion: mv.motion,
                    values: st.values.clone(),
                    feed: match mv.motion {
                        Motion::Thread { lead, .. } => lead * st.speed.unwrap_or_default(),
                        _ => 0.0,
                    },
                    spindle: if n == 0 { speed_next.take() } else { None },
                    comment: if n == 0 { comment.clone() } else { None },
                    number: line_number,
                    line,
                });
                k += 1;
            }
            st.motion = Some(76);
            continue;
        }
        let mut lead_here = None;
        let mut s_here = None;
        for (letter, v, text) in read {
            if let Some(i) = names.iter().position(|n| *n == letter) {
                axis_here[i] = Some(v);
                continue;
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
                c if c == lead_letter => lead_here = Some(v),
                _ if reading => {
                    return Err(fault(
                        place(k),
                        format!(
                            "{text}: a word the verification cannot simulate ({} on {} reads the axes {}, F, S, T{})",
                            d.name,
                            program.machine,
                            names.iter().collect::<String>(),
                            start_letter.map(|c| format!(", {c}")).unwrap_or_default()
                        ),
                    ))
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
                out.rpm = Some(v);
            } else {
                speed_next = Some(v);
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
        if !moves {
            if motion_here.is_some() {
                return Err(fault(place(k), "a motion word with no axis".into()));
            }
            if let Some(w) = &start_word {
                return Err(fault(place(k), outside_thread(w, d)));
            }
            continue;
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
            .then(|| cutting_fault(&st, d, &program.setup, "a cutting move"))
            .flatten()
        {
            return Err(fault(place(k), m));
        }
        if let Some(w) = start_word.as_ref().filter(|_| !is_thread) {
            return Err(fault(place(k), outside_thread(w, d)));
        }
        if let Some(m) = setup_fault(&st, d, &program.setup, "a move") {
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
                if !((read_lead - lead).abs() <= 0.5 * 10f64.powi(-(d.lead_decimals as i32)) + 1e-9)
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
                if v < lo - half || v > hi + half {
                    return Err(fault(
                        place(k),
                        format!("{}{v} is outside the axis's travel [{lo}, {hi}]", name.name),
                    ));
                }
            }
        }
        // The move as read (a lint reads it too: what a run verifies).
        {
            let comment = comment_before(&comments, &mut comment_from, line);
            out.blocks.push(ReadBlock {
                motion,
                values: st.values.clone(),
                feed: match motion {
                    Motion::Rapid => 0.0,
                    Motion::Linear => st.f.unwrap_or_default(),
                    Motion::Thread { lead, .. } => lead * st.speed.unwrap_or_default(),
                },
                spindle: speed_next.take(),
                comment,
                number: line_number,
                line,
            });
        }
        k += 1;
    }
    if let Some(i) = (0..lines.len()).find(|&i| has_code[i] && !consumed[i]) {
        return Err(fault(
            at_line(i),
            format!(
                "'{}' is not a block the {} can account for",
                crate::files::excerpt(lines[i]),
                if reading { "reader" } else { "lint" }
            ),
        ));
    }
    if !reading && k != program.blocks.len() {
        return Err(fault(
            at_line(lines.len().saturating_sub(1)),
            format!(
                "{k} moves read back, the axis program has {}",
                program.blocks.len()
            ),
        ));
    }
    if !st.ended {
        return Err(fault(
            at_line(lines.len().saturating_sub(1)),
            format!("the program does not end (M{})", d.reading.end_code),
        ));
    }
    if reading && k == 0 {
        return Err(fault(at_line(0), "no move: nothing to verify".into()));
    }
    out.linted = Linted {
        moves: k,
        lines: lines.len(),
    };
    Ok(out)
}

/// What the modal state `st` lacks for `what` (a cutting move, a cycle)
/// to cut: the spindle on, a speed written, the coolant on where the
/// machine's `setup` turns it on.
fn cutting_fault(st: &State, d: &Dialect, setup: &ProgramSetup, what: &str) -> Option<String> {
    if !st.spindle_on {
        Some(format!("{what} with the spindle stopped (no M3)"))
    } else if !st.speed.is_some_and(|v| v >= 1.0) {
        Some(format!("{what} with no spindle speed S written"))
    } else if setup.coolant && !st.coolant {
        Some(format!(
            "{what} with the coolant off ({} not written), which the machine's setup turns on",
            d.coolant.0
        ))
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
fn setup_fault(st: &State, d: &Dialect, setup: &ProgramSetup, what: &str) -> Option<String> {
    let radial_word = d.radial_words.is_some() && d.style == Style::GCode;
    if let Some(c) = d
        .reading
        .setup_codes
        .iter()
        .find(|c| !st.stated.contains(c))
    {
        Some(format!(
            "{what} before G{c} is stated: the program leaves it to the control's power-on state, which the verification does not assume; write G{c} before the moves"
        ))
    } else if radial_word && setup.radial.is_some() && st.radial.is_none() {
        Some(format!(
            "{what} before the radial axis's programming (radius or diameter) is set, which the machine's setup states"
        ))
    } else if d.feed_group.is_some() && !setup.feed_group.is_empty() && !st.feed_group {
        Some(format!(
            "{what} before the feed group the machine's setup states"
        ))
    } else {
        None
    }
}

/// The last comment line among `comments[from..line]` (the pass a move at
/// `line` begins), the search starting after `line` for the next move.
fn comment_before(comments: &[Option<String>], from: &mut usize, line: usize) -> Option<String> {
    let found = comments[(*from).min(line)..line]
        .iter()
        .rev()
        .find_map(Clone::clone);
    *from = line + 1;
    found
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

/// Why the reader refuses the word `letter number` in `d`: in a program
/// pilgrim wrote, a word its dialect does not write; in a program read as
/// it stands, a word the verification cannot simulate.
fn not_read(reading: bool, d: &Dialect, letter: char, number: &dyn std::fmt::Display) -> String {
    let (g, m) = (d.reading.g_codes, d.reading.m_codes);
    if reading {
        let list = |l: char, c: &[u32]| {
            c.iter()
                .map(|n| format!("{l}{n}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        format!(
            "{letter}{number}: a word the verification cannot simulate (it reads {} and {} in {} programs); verify a program without it",
            list('G', g),
            list('M', m),
            d.name
        )
    } else {
        format!("{letter}{number} is not a word of {}", d.name)
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

/// The APT CL file: each record one the writer makes, in the form it
/// makes it (the part's, machine's and tool's names and numbers, text of
/// names' characters in `PPRINT/`), no character pilgrim never writes;
/// the spindle turning (at a speed that is not 0) and the coolant on where
/// the setup says before a cutting `GOTO/`, `RAPID` before exactly the
/// rapid ones; one `GOTO/` a block with the axis program's values,
/// `FINI` last.
fn lint_apt(text: &str, program: &AxisProgram, d: &Dialect) -> Result<Linted, LintError> {
    let fault = |place: String, message: String| LintError {
        dialect: d.name.to_owned(),
        place,
        message,
    };
    let decimals = super::written_decimals(program.decimals, d.name);
    let half = 0.5 * 10f64.powi(-(decimals as i32)) + 1e-9;
    let Some(body) = text.strip_suffix('\n') else {
        return Err(fault(
            "the last line".into(),
            "the CL file's last line does not end with a line feed".into(),
        ));
    };
    let lines: Vec<&str> = body.split('\n').collect();
    let mut k = 0;
    let (mut rapid_next, mut coolant) = (false, false);
    let mut speed: Option<Real> = None;
    let written_by = format!("written by pilgrim {}", crate::VERSION);
    let mut ticker = crate::budget::Ticker::new("the CL file's lint", 1024);
    for (l, line) in lines.iter().enumerate() {
        let at = || format!("line {}", l + 1);
        ticker.tick().map_err(|e| fault(at(), e.to_string()))?;
        if let Some(c) = line.chars().find(|c| c.is_control() || !c.is_ascii()) {
            return Err(fault(
                at(),
                format!(
                    "the character U+{:04X}, which pilgrim never writes",
                    u32::from(c)
                ),
            ));
        }
        let not_record = || {
            fault(
                at(),
                format!(
                    "'{}' is not a CL record pilgrim writes",
                    crate::files::excerpt(line)
                ),
            )
        };
        let (word, arg) = line.split_once('/').unwrap_or((line, ""));
        match (word, arg) {
            ("PARTNO", a) if a == program.name => {}
            ("MACHIN", a) if a == super::post::comment_text(d, &program.machine) => {}
            ("UNITS", "MM") | ("FINI", "") => {}
            ("LOADTL", a) if a == program.tool_number.to_string() => {}
            ("PPRINT", a) => {
                if a != written_by && !a.chars().all(crate::names::is_name_char) {
                    return Err(fault(
                        at(),
                        format!(
                            "PPRINT/{}: text no comment of pilgrim's holds",
                            crate::files::excerpt(a)
                        ),
                    ));
                }
            }
            ("COOLNT", "ON") => coolant = true,
            ("COOLNT", "OFF") => coolant = false,
            ("SPINDL", "OFF") => speed = None,
            ("SPINDL", a) => {
                let v: Real = a
                    .strip_suffix(",RPM,CLW")
                    .and_then(|v| v.parse().ok())
                    .ok_or_else(not_record)?;
                if !(v >= 1.0) {
                    return Err(fault(
                        at(),
                        format!("SPINDL/{v}: the spindle would stand while the program cuts"),
                    ));
                }
                speed = Some(v);
            }
            ("RAPID", "") => rapid_next = true,
            ("FEDRAT", a) if a.ends_with(",MMPM") || a.ends_with(",MMPR") => {}
            ("GOTO", _) => {}
            _ => return Err(not_record()),
        }
        if *line == "FINI" && l + 1 != lines.len() {
            return Err(fault(at(), "records after FINI".into()));
        }
        let Some(values) = line.strip_prefix("GOTO/") else {
            continue;
        };
        // Named only when a fault is told: finding the pass of a block
        // walks back through the blocks before it.
        let place = || name_in(d.name, &program.blocks, k);
        let Some(b) = program.blocks.get(k) else {
            return Err(fault(at(), "a GOTO beyond the axis program".into()));
        };
        let rapid = std::mem::take(&mut rapid_next);
        if rapid != (b.motion == Motion::Rapid) {
            return Err(fault(
                place(),
                format!(
                    "{}, where the axis program has a {:?} move",
                    if rapid { "RAPID" } else { "a feed move" },
                    b.motion
                ),
            ));
        }
        if !rapid && speed.is_none() {
            return Err(fault(place(), "a cutting move with the spindle off".into()));
        }
        if !rapid && program.setup.coolant && !coolant {
            return Err(fault(
                place(),
                "a cutting move with the coolant off (no COOLNT/ON), which the machine's setup turns on".into(),
            ));
        }
        let read: Vec<Real> = values
            .split(',')
            .map(|v| v.parse())
            .collect::<Result<_, _>>()
            .map_err(|_| fault(place(), format!("'{values}' are not numbers")))?;
        if read.len() != b.values.len() {
            return Err(fault(
                place(),
                format!("{} values for {} axes", read.len(), b.values.len()),
            ));
        }
        for (i, (r, w)) in read.iter().zip(&b.values).enumerate() {
            if !((r - w).abs() <= half) {
                return Err(fault(
                    place(),
                    format!(
                        "{} = {r} read back, the axis program's {w}",
                        program.axes[i].name
                    ),
                ));
            }
        }
        k += 1;
    }
    if lines.last() != Some(&"FINI") {
        return Err(fault(
            format!("line {}", lines.len()),
            "the CL file does not end with FINI".into(),
        ));
    }
    if k != program.blocks.len() {
        return Err(fault(
            format!("line {}", lines.len()),
            format!(
                "{k} GOTO records, the axis program has {} blocks",
                program.blocks.len()
            ),
        ));
    }
    Ok(Linted {
        moves: k,
        lines: lines.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::post::{post, CLD, FANUC, LINUXCNC, SINUMERIK};
    use crate::program::ProgramSetup;

    fn program() -> AxisProgram {
        crate::program::test_program()
    }

    fn axes() -> Vec<Axis> {
        vec![
            Axis::linear("X", -10.0, 400.0, 1e4, [0.5, 0.0, 0.0], ""),
            Axis::linear("Z", -700.0, 10.0, 1e4, [0.0, 0.0, 1.0], ""),
        ]
    }

    /// The lint knows no control by name: each dialect's quirks are its
    /// `Dialect` value's data. The same values under another name write,
    /// lint and read the same program.
    #[test]
    fn a_dialect_is_its_data_not_its_name() {
        let p = program();
        let mut frame = p.clone();
        frame.blocks.clear();
        for d in [&SINUMERIK, &FANUC, &LINUXCNC] {
            let acme = Dialect { name: "acme", ..*d };
            let text = post(&p, d).unwrap();
            assert_eq!(post(&p, &acme).unwrap(), text, "{}", d.name);
            assert_eq!(
                lint(&text, &p, &acme, &axes()).unwrap(),
                lint(&text, &p, d, &axes()).unwrap(),
                "{}",
                d.name
            );
            let (ours, theirs) = (
                read(&text, &frame, &acme, &axes()).unwrap().program,
                read(&text, &frame, d, &axes()).unwrap().program,
            );
            assert_eq!(
                (ours.name, ours.number, ours.tool_number),
                (theirs.name, theirs.number, theirs.tool_number),
                "{}",
                d.name
            );
            assert_eq!(ours.blocks, theirs.blocks, "{}", d.name);
        }
    }

    /// The reader takes a program's text as the control reads it: what
    /// the writer wrote comes back as the program, its values as written,
    /// its comments on the blocks they stand before, its N on each block.
    #[test]
    fn the_reader_reads_what_the_writer_wrote() {
        let p = program();
        let mut frame = p.clone();
        frame.blocks.clear();
        (frame.name, frame.number, frame.spindle_rpm) = ("X".into(), 0, 1.0);
        for d in [&SINUMERIK, &FANUC, &LINUXCNC] {
            let text = post(&p, d).unwrap();
            let read = read(&text, &frame, d, &axes()).unwrap_or_else(|e| panic!("{e}\n{text}"));
            // Each block's line holds its move: its N where the dialect
            // numbers blocks, and no other block's.
            let lines: Vec<&str> = text.lines().collect();
            assert_eq!(read.lines.len(), read.program.blocks.len(), "{}", d.name);
            assert!(read.lines.windows(2).all(|w| w[0] < w[1]), "{}", d.name);
            for (b, &l) in read.program.blocks.iter().zip(&read.lines) {
                if let Some(n) = b.number {
                    assert!(lines[l - 1].starts_with(&format!("N{n} ")), "{}", d.name);
                }
            }
            let r = read.program;
            // Sinumerik names the program in its header; Fanuc numbers it.
            let number = if d.name == "fanuc" { 7 } else { 0 };
            let name = if d.name == "sinumerik" { "DEMO" } else { "X" };
            assert_eq!((r.name.as_str(), r.number), (name, number), "{}", d.name);
            assert_eq!((r.spindle_rpm, r.tool_number), (399.0, 3), "{}", d.name);
            assert_eq!(r.blocks.len(), p.blocks.len(), "{}", d.name);
            let (written, _) = crate::replay::as_written(&p);
            for (k, (a, b)) in r.blocks.iter().zip(&written.blocks).enumerate() {
                let what = format!("{} block {k}", d.name);
                assert_eq!(a.values, b.values, "{what}");
                assert_eq!(a.motion, b.motion, "{what}");
                assert_eq!(
                    a.comment,
                    b.comment
                        .as_ref()
                        .map(|c| super::super::post::comment_text(d, c)),
                    "{what}"
                );
                if b.motion == Motion::Linear {
                    assert_eq!(a.feed, b.feed, "{what}");
                }
                let n = d
                    .numbering
                    .map(|(first, step)| (first + step * k as u64) as u32);
                assert_eq!(a.number, n, "{what}");
            }
            assert!(r.blocks[4].motion == written.blocks[4].motion);
            // A lint reads the same program, its passes named as the axis
            // program names them.
            let l = lint_read(&text, &p, d, &axes()).unwrap().program;
            for (k, (a, b)) in l.blocks.iter().zip(&written.blocks).enumerate() {
                assert_eq!(
                    (&a.values, a.motion),
                    (&b.values, b.motion),
                    "{} {k}",
                    d.name
                );
                assert_eq!(a.comment, b.comment, "{} {k}", d.name);
            }
        }
        // A CL file is no control's program.
        let cld = post(&p, &CLD).unwrap();
        assert!(read(&cld, &frame, &CLD, &axes())
            .unwrap_err()
            .message
            .contains("CL file"));
    }

    /// A word the verification cannot simulate is refused, naming it and
    /// the block; a program read as it stands may carry its own name.
    #[test]
    fn the_reader_refuses_what_it_cannot_simulate() {
        let p = program();
        let mut frame = p.clone();
        frame.blocks.clear();
        let text = post(&p, &SINUMERIK).unwrap();
        for (from, to, word) in [
            ("G1 X40.000", "G2 X40.000 I5.0", "G2"),
            ("G1 X40.000", "G1 X40.000 R5", "R5"),
            ("M3", "M98", "M98"),
        ] {
            let edited = text.replacen(from, to, 1);
            assert_ne!(edited, text, "{from}");
            let e = read(&edited, &frame, &SINUMERIK, &axes()).unwrap_err();
            assert!(
                e.message.starts_with(word) && e.message.contains("cannot simulate"),
                "{e}"
            );
            assert!(e.place.starts_with('N'), "{e}");
        }
        let renamed = text.replacen("%_N_DEMO_MPF", "%_N_OTHER_MPF", 1);
        assert_eq!(
            read(&renamed, &frame, &SINUMERIK, &axes())
                .unwrap()
                .program
                .name,
            "OTHER"
        );
    }

    /// What the writer writes, the lint reads back: every dialect.
    #[test]
    fn every_dialect_reads_back() {
        let p = program();
        for d in [&SINUMERIK, &FANUC, &LINUXCNC, &CLD] {
            let text = post(&p, d).unwrap();
            let l = lint(&text, &p, d, &axes()).unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert_eq!(l.moves, 6, "{}", d.name);
        }
        let mut block = p.clone();
        block.number = 0;
        lint(&post(&block, &FANUC).unwrap(), &block, &FANUC, &axes()).unwrap();
    }

    /// A corrupted program: the lint names the block and says what.
    #[test]
    fn corruptions_are_named() {
        let p = program();
        let case = |d: &Dialect, from: &str, to: &str, says: &[&str]| {
            let text = post(&p, d).unwrap();
            assert!(text.contains(from), "{}: {from} not in\n{text}", d.name);
            let bad = text.replacen(from, to, 1);
            let e = lint(&bad, &p, d, &axes()).unwrap_err().to_string();
            for s in says {
                assert!(e.contains(s), "{}: '{s}' not in: {e}", d.name);
            }
        };
        // A value changed.
        case(
            &SINUMERIK,
            "N30 Z0.000",
            "N30 Z0.002",
            &["N30", "Z0.002 read back", "-0.00010"],
        );
        case(
            &FANUC,
            "G32 Z-60.000",
            "G32 Z-60.100",
            &["block 5", "Z-60.1 read back"],
        );
        case(
            &CLD,
            "GOTO/40.000,-60.000",
            "GOTO/40.000,-60.010",
            &["block 5", "Z = -60.01"],
        );
        // Numbering out of order, a block without its number.
        case(&SINUMERIK, "N50 G33", "N25 G33", &["N25", "out of order"]);
        case(&LINUXCNC, "N50 G33", "G33", &["line", "without its number"]);
        // A word the dialect does not have.
        case(
            &FANUC,
            "G00 X50.000 Z5.000",
            "G00 X50.000 Z5.000 Y3.000",
            &["block 1", "Y3.000: not a word of fanuc"],
        );
        case(
            &SINUMERIK,
            "N20 G1 X40.000",
            "N20 G2 X40.000",
            &["N20", "G2 is not a word of sinumerik"],
        );
        // Modal state: no feed before G1, no spindle, no lead, no G97.
        case(&SINUMERIK, " F100.0", "", &["N20", "G1 before any feed"]);
        case(
            &SINUMERIK,
            "N3 S399 M3\n",
            "N3 S399\n",
            &["N20", "spindle stopped"],
        );
        case(&LINUXCNC, " K6.3500", "", &["N50", "without its lead K"]);
        case(
            &LINUXCNC,
            "G21 G40 G90 G94 G97",
            "G21 G40 G90 G94",
            &["N50", "G97"],
        );
        // Travel, and the end.
        case(
            &FANUC,
            "G00 X50.000 Z5.000",
            "G00 X500.000 Z5.000",
            &["block 1"],
        );
        case(&FANUC, "M30\n", "", &["does not end (M30)"]);
        case(&LINUXCNC, "M2\n%\n", "M2\n", &["close with '%'"]);
        case(&CLD, "FINI\n", "", &["FINI"]);
        // A move lost.
        case(
            &CLD,
            "GOTO/50.000,-60.000\n",
            "",
            &["5 GOTO records", "6 blocks"],
        );
    }

    /// Text that would break a comment or a block, put straight into an
    /// axis program (past the checks where names enter): every dialect's
    /// writer keeps it inside its comments, each comment stays one line, and
    /// the lint reads the result back.
    #[test]
    fn no_text_breaks_a_comment_of_the_writer() {
        let mut p = program();
        p.tool_name = "T1)\nG00 X0 Z0 (".into();
        p.machine = "lathe\rG00 X0; SF=90 %".into();
        p.blocks[1].comment = Some("MSG, PROBEOPEN /tmp/x".into());
        p.blocks[2].comment = Some("a;b(c)\r\nG01 Z-99 $x".into());
        let clean = {
            let mut c = program();
            c.blocks[1].comment = Some("x".into());
            c.blocks[2].comment = Some("y".into());
            c
        };
        for d in [&SINUMERIK, &FANUC, &LINUXCNC, &CLD] {
            let text = post(&p, d).unwrap();
            assert_eq!(
                text.lines().count(),
                post(&clean, d).unwrap().lines().count(),
                "{}: a line was added\n{text}",
                d.name
            );
            lint(&text, &p, d, &axes()).unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert!(
                !text.contains('\r') && !text.contains("G00 X0 Z0 ("),
                "{text}"
            );
        }
        let l = post(&p, &LINUXCNC).unwrap();
        assert!(l.contains("(_MSG, PROBEOPEN /tmp/x)"), "{l}");
    }

    /// What a hostile text or a hand edit puts into a program, as each
    /// control would read it: the lint refuses it, naming the line or the
    /// block. The `gcode` crate reads a `(` comment across lines; Sinumerik's
    /// own words were blanked and a line left empty by it skipped.
    #[test]
    fn injected_lines_and_words_are_refused() {
        let mut p = program();
        p.setup = ProgramSetup {
            radial: Some(Radial::Diameter),
            radial_axis: "X".into(),
            coolant: true,
            ..ProgramSetup::default()
        };
        let case = |d: &Dialect, from: &str, to: &str, says: &[&str]| {
            let text = post(&p, d).unwrap();
            lint(&text, &p, d, &axes()).unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert!(text.contains(from), "{}: {from:?} not in\n{text}", d.name);
            let bad = text.replacen(from, to, 1);
            let e = lint(&bad, &p, d, &axes())
                .map(|_| format!("passed:\n{bad}"))
                .unwrap_or_else(|e| e.to_string());
            for s in says {
                assert!(
                    e.contains(s),
                    "{}: {from:?} -> {to:?}: '{s}' not in: {e}",
                    d.name
                );
            }
        };
        // A comment opened and closed on another line: the rapid between.
        case(
            &FANUC,
            "(TOOL T03: THREAD INSERT 60)\n",
            "(TOOL T03: T1\nG00 X0 Z0 )\n",
            &["line 4", "does not close"],
        );
        case(
            &FANUC,
            "(PASS 1)",
            "(PASS (1))",
            &["comment inside a comment"],
        );
        case(&FANUC, "(PASS 1)", "(pass 1)", &["lower case"]);
        case(
            &FANUC,
            "G21 G40 G97 G98\n",
            "G21 G40 G97 G98 ; x\n",
            &["';'"],
        );
        // A lone carriage return passed all four lints.
        case(&FANUC, "(PASS 1)", "(PASS 1\rG00 X0)", &["U+000D"]);
        case(&SINUMERIK, "; pass 1", "; pass 1\rN15 G0 X0", &["U+000D"]);
        case(&LINUXCNC, "(pass 1)", "(pass 1\r)", &["U+000D"]);
        case(
            &CLD,
            "PPRINT/pass 1",
            "PPRINT/pass 1\rGOTO/0,0",
            &["U+000D"],
        );
        // Sinumerik's own words only where the writer puts them.
        case(
            &SINUMERIK,
            "N1 G90 G94 G71\n",
            "N1 G90 G94 G71\nSF=90\n",
            &["line 6"],
        );
        case(
            &SINUMERIK,
            "N1 G90 G94 G71\n",
            "N1 G90 G94 G71 SF=90\n",
            &["SF=90: a thread's start angle outside a thread block"],
        );
        case(
            &SINUMERIK,
            "; tool T3: thread insert 60\n",
            "; tool T3: thread insert 60\nDIAMOF\n",
            &["line 5"],
        );
        case(
            &SINUMERIK,
            "N2 DIAMON",
            "N2 DIAMOF",
            &["radius programming", "on diameter"],
        );
        case(&SINUMERIK, "N2 DIAMON", "N2", &["N10", "radial axis"]);
        case(
            &SINUMERIK,
            "N20 G1 X40.000",
            "N20 G1 DIAMOF X40.000",
            &["N20", "before the moves"],
        );
        case(
            &SINUMERIK,
            "N2 DIAMON",
            "N2 DIAMON FGROUP(A)",
            &["FGROUP(A)"],
        );
        case(
            &SINUMERIK,
            "; pass 1",
            "; pass 1 (x)",
            &["'(' in the comment"],
        );
        // LinuxCNC's comments that act; its ';' comments, never written.
        case(
            &LINUXCNC,
            "(pass 1)",
            "(MSG, hello)",
            &["makes LinuxCNC act"],
        );
        case(
            &LINUXCNC,
            "(pass 1)",
            "(probeopen /tmp/x)",
            &["makes LinuxCNC act"],
        );
        case(&LINUXCNC, "N10 G0", "N10 G0 ;x", &["';'"]);
        // The spindle's speed and the coolant, as modal state.
        case(&SINUMERIK, "N4 S399 M3", "N4 S0 M3", &["S0 read back"]);
        case(&FANUC, "S399 M03", "S400 M03", &["S400 read back", "S399"]);
        case(&FANUC, "S399 M03", "M03", &["no spindle speed"]);
        case(&SINUMERIK, "N5 M8\n", "N5 M9\n", &["N20", "coolant off"]);
        case(&CLD, "COOLNT/ON\n", "", &["block 2", "coolant off"]);
        case(
            &CLD,
            "SPINDL/399,RPM,CLW",
            "SPINDL/0,RPM,CLW",
            &["would stand"],
        );
        case(
            &CLD,
            "MACHIN/test-lathe",
            "MACHIN/other",
            &["not a CL record"],
        );
        case(
            &CLD,
            "RAPID\nGOTO/50.000,-60.000",
            "GOTO/50.000,-60.000",
            &["block 6", "a feed move"],
        );
    }
    /// A threading cycle: LinuxCNC writes the run of blocks it makes as
    /// one G76 block, which the lint expands and holds move by move to
    /// the axis program, and a reader takes as those moves; Fanuc writes
    /// the same moves as blocks. A word changed in the text, a tapered
    /// end, a word given twice, a bare move under G76's modal motion, a
    /// cycle with the spindle stopped are refused, named.
    #[test]
    fn a_threading_cycle_is_written_read_and_held() {
        use crate::program::cycle::{expand, m20, CycleSpan};
        let c = m20();
        let mut p = program();
        let block =
            |motion: Motion, x: Real, z: Real, comment: Option<&str>| crate::program::Block {
                motion,
                values: vec![x, z],
                feed: if motion == Motion::Rapid {
                    0.0
                } else {
                    2.5 * 399.4
                },
                spindle: None,
                comment: comment.map(str::to_owned),
                keep: Vec::new(),
                number: None,
            };
        let moves = expand(&c, [24.0, 5.0], false, None).unwrap();
        p.blocks = std::iter::once(block(Motion::Rapid, 24.0, 5.0, Some("drive line")))
            .chain(moves.iter().map(|m| block(m.motion, m.x, m.z, None)))
            .chain([block(Motion::Rapid, 50.0, -35.0, Some("away"))])
            .collect();
        p.cycles = vec![CycleSpan {
            first: 1,
            count: moves.len(),
            cycle: c.clone(),
        }];
        let text = post(&p, &LINUXCNC).unwrap();
        assert!(
            text.contains(
                "N20 G76 P2.5000 Z-35.000 I-4.0000 J0.6000 R2.0000 K3.0000 Q29.5000 H1\n"
            ) && !text.contains("G33"),
            "{text}"
        );
        let n_after = 10 + 10 * (1 + moves.len());
        assert!(text.contains(&format!("N{n_after} G0 X50.000\n")), "{text}");
        let linted = lint(&text, &p, &LINUXCNC, &axes()).unwrap();
        assert_eq!(linted.moves, p.blocks.len());
        let mut frame = p.clone();
        frame.blocks.clear();
        frame.cycles.clear();
        let got = read(&text, &frame, &LINUXCNC, &axes()).unwrap().program;
        assert_eq!(got.blocks.len(), p.blocks.len());
        for (g, want) in got.blocks.iter().zip(&p.blocks) {
            assert_eq!(g.motion, want.motion);
            for (a, b) in g.values.iter().zip(&want.values) {
                assert!((a - b).abs() < 1e-9, "{a} {b}");
            }
        }
        // Fanuc has no such cycle: the moves as blocks, linted as ever.
        let f = post(&p, &FANUC).unwrap();
        assert!(!f.contains("G76") && f.matches("G32").count() == 26, "{f}");
        lint(&f, &p, &FANUC, &axes()).unwrap();
        for (from, to, says) in [
            ("J0.6000", "J0.6100", "the threading cycle's move"),
            (" H1\n", " H1 E1.0\n", "tapered ends"),
            (" H1\n", " H1 J0.7\n", "J twice in one block"),
            (" I-4.0000", "", "G76 without its I word"),
            (
                "G0 X50.000",
                "X50.000",
                "under a threading cycle's modal G76",
            ),
            (
                "S399 M3",
                "S399 M5",
                "a threading cycle with the spindle stopped (no M3)",
            ),
        ] {
            let bad = text.replacen(from, to, 1);
            let e = lint(&bad, &p, &LINUXCNC, &axes()).unwrap_err().to_string();
            assert!(e.contains(says), "{to}: {e}");
            let e = read(&bad, &frame, &LINUXCNC, &axes());
            if from != "J0.6000" {
                assert!(e.is_err_and(|e| e.to_string().contains(says)), "{to}");
            }
        }
    }
}
