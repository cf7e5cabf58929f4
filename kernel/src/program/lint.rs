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
//! The G-code is read by [`super::reader`] (the line and its comments,
//! Sinumerik's own words `DIAMON`, `DIAMOF`, `FGROUP(..)`, `SF=` and the
//! `%_N_.._MPF` header before the ISO words, the codes, the setup's words,
//! the threading cycle, the moves); the CL file by its records in `cl`.

use super::post::{Dialect, Style};
use super::reader::{Mode, ReadMove, Reader};
use super::AxisProgram;
use crate::machine::Axis;
use crate::math::Real;

mod cl;

use cl::lint_apt;

/// A program that fails its lint: which program, where, what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{what} of the {dialect} program: {place}: {message}")]
pub struct LintError {
    /// What read the program: "lint" (a program pilgrim wrote, read back)
    /// or "reading" (a program read as it stands).
    pub what: &'static str,
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
        Style::GCode => {
            lint_gcode(text, program, d, axes, Mode::Lint, Context::default()).map(|r| r.linted)
        }
    }
}

/// A program as a control reads its text: its blocks, and where each
/// stands in the text (the page's listing shows the block the player is
/// at).
#[derive(Debug, Clone, PartialEq)]
pub struct TextProgram {
    /// The program read.
    pub program: AxisProgram,
    /// The line (from 1) of each block's move in the program's own text,
    /// in the blocks' order (a subprogram's move: the line of its call).
    pub lines: Vec<usize>,
    /// Where each block's move was read: its file (0: the program's own,
    /// else `files[n - 1]`) and its line there (from 1).
    pub sources: Vec<(usize, usize)>,
    /// The subprograms' files the text called.
    pub files: Vec<String>,
    /// The runs of blocks a cycle, a loop or a call made.
    pub expansions: Vec<super::expansion::Expansion>,
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
    read_with(text, frame, d, axes, None, None, None)
}

/// [`read`] with the shop's offset table: a tool or work offset it gives
/// is followed, each later position shifted by it
/// ([`super::offsets`]), where [`read`] refuses it; and with `beside`,
/// where a subprogram the text calls is read by its file's name (the
/// program's folder).
///
/// # Failures
/// As [`read`].
pub fn read_with(
    text: &str,
    frame: &AxisProgram,
    d: &Dialect,
    axes: &[Axis],
    offsets: Option<&super::offsets::Offsets>,
    beside: Option<super::reader::Beside<'_>>,
    settings: Option<&std::collections::BTreeMap<String, Real>>,
) -> Result<TextProgram, LintError> {
    if d.style != Style::GCode {
        return Err(not_a_control_program(d));
    }
    let context = Context {
        offsets,
        beside,
        settings,
    };
    Ok(assemble(
        lint_gcode(text, frame, d, axes, Mode::Read, context)?,
        frame,
    ))
}

/// What a reading may follow besides the text: the shop's offset table,
/// where a called subprogram's file is read, the machine's constants (the
/// control's settings a cycle takes).
#[derive(Default)]
struct Context<'a> {
    offsets: Option<&'a super::offsets::Offsets>,
    beside: Option<super::reader::Beside<'a>>,
    settings: Option<&'a std::collections::BTreeMap<String, Real>>,
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
    let mut read = assemble(
        lint_gcode(text, program, d, axes, Mode::Lint, Context::default())?,
        program,
    );
    for (r, b) in read.program.blocks.iter_mut().zip(&program.blocks) {
        r.comment.clone_from(&b.comment);
    }
    Ok(read)
}

/// The refusal of a CL file where a control's program is wanted.
fn not_a_control_program(d: &Dialect) -> LintError {
    LintError {
        what: "lint",
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
    let lines = read
        .blocks
        .iter()
        .map(|b| b.via.unwrap_or(b.line) + 1)
        .collect();
    let sources = read.blocks.iter().map(|b| (b.file, b.line + 1)).collect();
    let origins: Vec<super::expansion::Origin> = (read.blocks.iter())
        .map(|b| super::expansion::Origin {
            file: b.file,
            line: b.line,
            via: b.via,
        })
        .collect();
    let expansions = super::expansion::expansions(&origins, &read.files);
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
                line: u32::try_from(b.via.unwrap_or(b.line) + 1).ok(),
                dwell_s: b.dwell_s,
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
        fanuc_cycles: Vec::new(),
    };
    TextProgram {
        program,
        lines,
        sources,
        files: read.files,
        expansions,
    }
}

/// What a G-code text read as: the lint's count, the moves and what the
/// text says of the program.
struct ReadText {
    linted: Linted,
    blocks: Vec<ReadMove>,
    name: Option<String>,
    number: Option<u32>,
    tool: Option<u32>,
    rpm: Option<Real>,
    /// The subprograms' files read.
    files: Vec<String>,
}

/// A G-code text read line by line by the [`Reader`], held to `program`
/// or read as it stands (`mode`), following its statements through the
/// files `beside` gives (a program read as it stands).
fn lint_gcode(
    text: &str,
    program: &AxisProgram,
    d: &Dialect,
    axes: &[Axis],
    mode: Mode,
    context: Context<'_>,
) -> Result<ReadText, LintError> {
    let mut lines: Vec<&str> = text.split('\n').collect();
    if lines.last() != Some(&"") {
        return Err(LintError {
            what: if mode == Mode::Read {
                "reading"
            } else {
                "lint"
            },
            dialect: d.name.to_owned(),
            place: format!("line {}", lines.len()),
            message: "the program's last line does not end with a line feed".into(),
        });
    }
    lines.pop();
    if mode == Mode::Read {
        // A line ended by a carriage return and a line feed (a file kept on
        // Windows) is a line.
        for l in &mut lines {
            *l = l.strip_suffix('\r').unwrap_or(l);
        }
    }
    let (reader, mut at) = Reader::new(&lines, program, d, axes, mode)?;
    let mut reader = reader
        .with_offsets(context.offsets)
        .with_beside(context.beside)
        .with_settings(context.settings);
    let mut blocks = Vec::new();
    let mut line = String::new();
    while let Some((f, i)) = reader.next_line(&mut at)? {
        line.clear();
        line.push_str(reader.text(f, i));
        reader.line(&mut at, i, &line, &mut blocks)?;
    }
    Ok(ReadText {
        linted: reader.end(&at)?,
        blocks,
        name: at.name().map(str::to_owned),
        number: at.number(),
        tool: at.tool(),
        rpm: at.rpm(),
        files: reader.called_files(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::post::{post, CLD, FANUC, LINUXCNC, SINUMERIK};
    use crate::program::{ProgramSetup, Radial};
    use crate::toolpath::Motion;

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

    /// Fanuc's text of the test program with `before_end` before its M30
    /// and `after` (other programs) after it.
    fn fanuc_with(before_end: &str, after: &str) -> String {
        let text = post(&program(), &FANUC).unwrap();
        let at = text.find("M30").unwrap();
        let line = text[..at].rfind('\n').unwrap() + 1;
        let end = text.rfind("%\n").unwrap();
        format!(
            "{}{before_end}{}{after}%\n",
            &text[..line],
            &text[line..end]
        )
    }

    /// The bounds of a reading are exact: a loop of MAX_TURNS turns is
    /// read, one turn more is refused; calls MAX_CALL_DEPTH deep are
    /// followed, one deeper is refused; MAX_FILES files beside the program
    /// are read, one more is refused.
    #[test]
    fn the_reading_bounds_are_exact() {
        use crate::program::macros::{MAX_CALL_DEPTH, MAX_TURNS};
        let mut frame = program();
        frame.blocks.clear();
        let turns = |n: u64| {
            let text = fanuc_with(&format!("#1=0\nWHILE[#1LT{n}]DO1\n#1=#1+1\nEND1\n"), "");
            read(&text, &frame, &FANUC, &axes())
        };
        let moves = read(&fanuc_with("", ""), &frame, &FANUC, &axes())
            .unwrap()
            .program
            .blocks;
        assert_eq!(turns(MAX_TURNS).unwrap().program.blocks, moves);
        let e = turns(MAX_TURNS + 1).unwrap_err().to_string();
        assert!(
            e.contains(&format!("more than {MAX_TURNS} loop turns")),
            "{e}"
        );
        let nested = |depth: usize| {
            // O1001 calls O1002, ... to O(1000 + depth), which returns.
            let subs: String = (1..=depth)
                .map(|k| {
                    let call = if k < depth {
                        format!("M98 P{}\n", 1001 + k)
                    } else {
                        String::new()
                    };
                    format!("O{}\n{call}M99\n", 1000 + k)
                })
                .collect();
            read(&fanuc_with("M98 P1001\n", &subs), &frame, &FANUC, &axes())
        };
        assert_eq!(nested(MAX_CALL_DEPTH).unwrap().program.blocks, moves);
        let e = nested(MAX_CALL_DEPTH + 1).unwrap_err().to_string();
        assert!(
            e.contains(&format!("calls nested deeper than {MAX_CALL_DEPTH}")),
            "{e}"
        );
        // Each call of another file beside the program: MAX_FILES of them
        // are read, one more is refused.
        use crate::program::macros::MAX_FILES;
        let beside = |name: &str| -> Result<Option<String>, crate::files::FileError> {
            Ok(name
                .strip_prefix('O')
                .filter(|n| n.len() == 4 && !name.contains('.'))
                .map(|n| format!("%\nO{n}\nM99\n%\n")))
        };
        let files = |n: usize| {
            let calls: String = (1..=n).map(|k| format!("M98 P{}\n", 2000 + k)).collect();
            read_with(
                &fanuc_with(&calls, ""),
                &frame,
                &FANUC,
                &axes(),
                None,
                Some(&beside),
                None,
            )
        };
        let read = files(MAX_FILES).unwrap();
        assert_eq!((read.program.blocks, read.files.len()), (moves, MAX_FILES));
        let e = files(MAX_FILES + 1).unwrap_err().to_string();
        assert!(
            e.contains(&format!("more than {MAX_FILES} subprogram files")),
            "{e}"
        );
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
            ("G1 X40.000", "G41 G1 X40.000", "G41"),
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
            &[
                "N20",
                "G2 (circular interpolation clockwise on sinumerik) is not a word of sinumerik",
            ],
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
                line: None,
                dwell_s: 0.0,
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
                "a threading cycle (G76) with the spindle stopped (no M3)",
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
