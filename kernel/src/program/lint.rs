//! Every program pilgrim writes, read back and checked before it is
//! written (issue 14 §4): the text is parsed again (G-code with the
//! `gcode` crate; the APT CL file by its records) and held to the dialect
//! and to the axis program it came from.
//!
//! The checks: every block numbered in order where the dialect numbers
//! blocks; only the words the dialect allows (its G and M codes, the
//! program's axes, F, S, T, the lead's and the start angle's addresses);
//! modal state (a feed before the first G1, the spindle on before cutting,
//! constant speed G97 before a thread on the lathe dialects, a lead on a
//! thread block where the dialect wants one); every axis value within the
//! machine's travel; the end (M30, LinuxCNC's M2, the `%` framing); and
//! every move read back, the modal values carried, equal to the axis
//! program's block within half the output's last decimal. The parser's
//! numbers are `f32`: the values are read again from the text the parser
//! located (its spans), in `f64`.
//!
//! Sinumerik's own words (`DIAMON`, `DIAMOF`, `FGROUP(..)`, `SF=`) and the
//! `%_N_.._MPF` header are read here, not by the crate, which knows the
//! ISO words only.

use super::post::{Dialect, Style};
use super::{name_in, AxisProgram};
use crate::machine::Axis;
use crate::math::Real;
use crate::toolpath::Motion;
use gcode::{Code, Value};

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

/// The G and M codes each G-code dialect writes.
fn codes(d: &Dialect) -> (&'static [u32], &'static [u32]) {
    match d.name {
        "sinumerik" => (
            &[0, 1, 17, 18, 19, 33, 54, 55, 56, 57, 58, 59, 71, 90, 94],
            &[3, 5, 8, 9, 30],
        ),
        "fanuc" => (
            &[0, 1, 18, 17, 19, 21, 32, 40, 54, 55, 56, 57, 58, 59, 97, 98],
            &[3, 5, 8, 9, 30],
        ),
        _ => (
            &[
                0, 1, 7, 8, 17, 18, 19, 21, 33, 40, 54, 55, 56, 57, 58, 59, 90, 94, 97,
            ],
            &[2, 3, 5, 8, 9],
        ),
    }
}

/// The word ending a program in `d`.
fn end_code(d: &Dialect) -> u32 {
    if d.name == "linuxcnc" {
        2
    } else {
        30
    }
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
        Style::GCode => lint_gcode(text, program, d, axes),
    }
}

/// The modal state a G-code program has set so far.
#[derive(Default)]
struct State {
    motion: Option<u32>,
    feed: bool,
    lead: Option<Real>,
    spindle_on: bool,
    constant_speed: bool,
    start_deg: Real,
    values: Vec<Option<Real>>,
    ended: bool,
}

fn lint_gcode(
    text: &str,
    program: &AxisProgram,
    d: &Dialect,
    axes: &[Axis],
) -> Result<Linted, LintError> {
    let fault = |place: String, message: String| LintError {
        dialect: d.name.to_owned(),
        place,
        message,
    };
    let at_line = |l: usize| format!("line {}", l + 1);
    let decimals = super::written_decimals(program.decimals, d.name);
    let half = 0.5 * 10f64.powi(-(decimals as i32)) + 1e-9;
    let (g_ok, m_ok) = codes(d);
    let lead_letter = d.lead.chars().next().unwrap_or('K');
    let names: Vec<char> = program
        .axes
        .iter()
        .filter_map(|a| a.name.chars().next())
        .collect();
    let lines: Vec<&str> = text.lines().collect();
    // Sinumerik's own words out of the way of the ISO parser (kept at
    // their places: spans stay valid), the start angle read.
    let mut iso = String::with_capacity(text.len());
    let mut sf: Vec<Option<Real>> = vec![None; lines.len()];
    for (i, line) in lines.iter().enumerate() {
        let mut l = (*line).to_owned();
        let first = i == 0;
        let _ = first;
        if d.name == "sinumerik" {
            if first && l.starts_with("%_N_") && l.ends_with("_MPF") {
                l = " ".repeat(l.len());
            }
            let code_part = l.split(';').next().unwrap_or("").to_owned();
            let mut cleaned = code_part.clone();
            for word in code_part.split_whitespace() {
                let keyword = matches!(word, "DIAMON" | "DIAMOF")
                    || (word.starts_with("FGROUP(") && word.ends_with(')'));
                if let Some(v) = word.strip_prefix("SF=") {
                    let v: Real = v
                        .parse()
                        .map_err(|_| fault(at_line(i), format!("'{word}' is not a start angle")))?;
                    sf[i] = Some(v);
                } else if !keyword {
                    continue;
                }
                cleaned = cleaned.replacen(word, &" ".repeat(word.len()), 1);
            }
            l = cleaned + &l[code_part.len()..];
        } else if l == "%" {
            l = " ".into();
        } else if d.name == "fanuc" && first_code(&l).is_some_and(is_program_number) {
            // Fanuc's program number, `O0001`, is not an ISO word.
            let n = l.find('O').unwrap_or(0);
            l.replace_range(n..n + 5, "     ");
        }
        iso.push_str(&l);
        iso.push('\n');
    }
    // The framing: % first and last where the dialect frames.
    let framed = d.header.first().is_some_and(|h| *h == "%")
        || (d.header.first().is_some_and(|h| *h == "{WHOLE}%") && program.number > 0);
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
    let parsed = gcode::parse(&iso).map_err(|diags| {
        let first = diags.iter().next();
        let line = first.map(|x| x.span.line).unwrap_or(0);
        fault(
            at_line(line),
            format!(
                "not G-code the control reads: {:?} in '{}'",
                first.map(|x| &x.kind),
                lines.get(line).unwrap_or(&"")
            ),
        )
    })?;
    let mut st = State {
        values: vec![None; names.len()],
        ..State::default()
    };
    let mut last_n: Option<u32> = None;
    let mut k = 0; // the next move of the axis program
    for block in &parsed.blocks {
        let line = block.span.line;
        if block.codes.is_empty() && block.word_addresses.is_empty() && block.line_number.is_none()
        {
            continue;
        }
        let place = |k: usize| {
            if k < program.blocks.len() {
                name_in(d.name, &program.blocks, k)
            } else {
                at_line(line)
            }
        };
        if st.ended {
            return Err(fault(place(k), "a block after the program's end".into()));
        }
        match (d.numbering, block.line_number) {
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
        // The block's words: codes and their arguments, bare addresses.
        let mut words: Vec<(char, &gcode::Argument)> = Vec::new();
        let mut bare: Vec<&gcode::WordAddress> = Vec::new();
        let mut motion_here = None;
        for c in &block.codes {
            match c {
                Code::General(g) => {
                    let n = number(&g.number.to_string());
                    if !g_ok.contains(&n) {
                        return Err(fault(
                            place(k),
                            format!("G{} is not a word of {}", g.number, d.name),
                        ));
                    }
                    match n {
                        0 | 1 | 32 | 33 => motion_here = Some(n),
                        97 => st.constant_speed = true,
                        _ => {}
                    }
                    words.extend(g.args.iter().map(|a| (a.letter, a)));
                }
                Code::Miscellaneous(m) => {
                    let n = number(&m.number.to_string());
                    if !m_ok.contains(&n) {
                        return Err(fault(
                            place(k),
                            format!("M{} is not a word of {}", m.number, d.name),
                        ));
                    }
                    match n {
                        3 => st.spindle_on = true,
                        5 => st.spindle_on = false,
                        n if n == end_code(d) => st.ended = true,
                        _ => {}
                    }
                    words.extend(m.args.iter().map(|a| (a.letter, a)));
                }
                Code::ToolChange(t) => {
                    if k > 0 {
                        return Err(fault(
                            place(k),
                            format!("a tool call T{} among the moves", t.number),
                        ));
                    }
                    words.extend(t.args.iter().map(|a| (a.letter, a)));
                }
                _ => return Err(fault(place(k), "a code the lint does not know".into())),
            }
        }
        bare.extend(block.word_addresses.iter());
        // Values from the text at the parser's spans (f64, as written).
        let value_at = |span: gcode::core::Span, letter: char| -> Result<Real, LintError> {
            let t = iso.get(span.start..span.start + span.length).unwrap_or("");
            let digits = t.trim_start_matches(|c: char| c.is_ascii_alphabetic());
            digits
                .parse()
                .map_err(|_| fault(place(k), format!("{letter}: '{t}' is not a number")))
        };
        let mut axis_here = vec![None; names.len()];
        let mut read = Vec::new();
        for (letter, v, span) in words
            .iter()
            .map(|(l, a)| (*l, &a.value, a.span))
            .chain(bare.iter().map(|w| (w.letter, &w.value, w.span)))
        {
            if let Value::Variable(_) = v {
                return Err(fault(
                    place(k),
                    format!("{letter}: a variable, which pilgrim never writes"),
                ));
            }
            read.push((letter, value_at(span, letter)?));
        }
        if let Some(s) = sf[line] {
            read.push(('@', s));
        }
        let mut lead_here = None;
        for (letter, v) in read {
            if let Some(i) = names.iter().position(|n| *n == letter) {
                axis_here[i] = Some(v);
                continue;
            }
            match letter {
                'F' if motion_here.or(st.motion).is_some_and(|m| m == 32) => lead_here = Some(v),
                'F' => st.feed = true,
                'S' => {}
                'D' if d.name == "sinumerik" => {}
                'Q' if d.name == "fanuc" => st.start_deg = v / 1000.0,
                '@' => st.start_deg = v,
                c if c == lead_letter => lead_here = Some(v),
                c => {
                    return Err(fault(
                        place(k),
                        format!("{c}{v}: not a word of {} on {}", d.name, program.machine),
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
        if !moves {
            if motion_here.is_some() {
                return Err(fault(place(k), "a motion word with no axis".into()));
            }
            continue;
        }
        // A move: the modal values carried, held to the axis program.
        let Some(b) = program.blocks.get(k) else {
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
        let is_thread = m == 32 || m == 33;
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
        if m == 1 && !st.feed {
            return Err(fault(place(k), "G1 before any feed F".into()));
        }
        if m != 0 && !st.spindle_on {
            return Err(fault(
                place(k),
                "a cutting move with the spindle stopped (no M3)".into(),
            ));
        }
        if let Motion::Thread { lead, start_deg } = b.motion {
            if d.lead_every_block && lead_here.is_none() {
                return Err(fault(
                    place(k),
                    format!("a thread block without its lead {}", d.lead),
                ));
            }
            if d.name != "sinumerik" && !st.constant_speed {
                return Err(fault(
                    place(k),
                    "a thread before constant spindle speed (G97)".into(),
                ));
            }
            let read_lead = st.lead.unwrap_or(Real::NAN);
            if !((read_lead - lead).abs() <= 0.5 * 10f64.powi(-(d.lead_decimals as i32)) + 1e-9) {
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
            if d.name == "fanuc" {
                st.start_deg = 0.0; // Q holds for its block only
            }
        }
        for (i, name) in program.axes.iter().enumerate() {
            if b.keep.contains(&name.name) {
                continue;
            }
            let Some(v) = st.values[i] else {
                return Err(fault(
                    place(k),
                    format!("axis {} has no value yet", name.name),
                ));
            };
            if !((v - b.values[i]).abs() <= half) {
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
        k += 1;
    }
    if k != program.blocks.len() {
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
            format!("the program does not end (M{})", end_code(d)),
        ));
    }
    Ok(Linted {
        moves: k,
        lines: lines.len(),
    })
}

/// The first word of a line (before a comment).
fn first_code(line: &str) -> Option<&str> {
    line.split('(').next()?.split_whitespace().next()
}

/// Whether `word` is a Fanuc program number, `O` and four digits.
fn is_program_number(word: &str) -> bool {
    word.len() == 5 && word.starts_with('O') && word[1..].bytes().all(|b| b.is_ascii_digit())
}

/// The integer part of a G or M number as the crate prints it (`1`, `33`).
fn number(text: &str) -> u32 {
    text.split('.')
        .next()
        .and_then(|t| t.parse().ok())
        .unwrap_or(u32::MAX)
}

/// The APT CL file: known records only, one `GOTO/` a block with the
/// axis program's values, `FINI` last.
fn lint_apt(text: &str, program: &AxisProgram, d: &Dialect) -> Result<Linted, LintError> {
    const RECORDS: [&str; 11] = [
        "PARTNO/", "MACHIN/", "PPRINT/", "UNITS/", "LOADTL/", "SPINDL/", "COOLNT/", "RAPID",
        "FEDRAT/", "GOTO/", "FINI",
    ];
    let fault = |place: String, message: String| LintError {
        dialect: d.name.to_owned(),
        place,
        message,
    };
    let decimals = super::written_decimals(program.decimals, d.name);
    let half = 0.5 * 10f64.powi(-(decimals as i32)) + 1e-9;
    let lines: Vec<&str> = text.lines().collect();
    let mut k = 0;
    for (l, line) in lines.iter().enumerate() {
        if !RECORDS.iter().any(|r| line.starts_with(r)) {
            return Err(fault(
                format!("line {}", l + 1),
                format!("'{line}' is not a CL record"),
            ));
        }
        if *line == "FINI" && l + 1 != lines.len() {
            return Err(fault(
                format!("line {}", l + 1),
                "records after FINI".into(),
            ));
        }
        let Some(values) = line.strip_prefix("GOTO/") else {
            continue;
        };
        let place = name_in(d.name, &program.blocks, k);
        let Some(b) = program.blocks.get(k) else {
            return Err(fault(
                format!("line {}", l + 1),
                "a GOTO beyond the axis program".into(),
            ));
        };
        let read: Vec<Real> = values
            .split(',')
            .map(|v| v.parse())
            .collect::<Result<_, _>>()
            .map_err(|_| fault(place.clone(), format!("'{values}' are not numbers")))?;
        if read.len() != b.values.len() {
            return Err(fault(
                place,
                format!("{} values for {} axes", read.len(), b.values.len()),
            ));
        }
        for (i, (r, w)) in read.iter().zip(&b.values).enumerate() {
            if !((r - w).abs() <= half) {
                return Err(fault(
                    place,
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

    fn program() -> AxisProgram {
        crate::program::test_program()
    }

    fn axes() -> Vec<Axis> {
        vec![
            Axis::linear("X", -10.0, 400.0, 1e4, [0.5, 0.0, 0.0], ""),
            Axis::linear("Z", -700.0, 10.0, 1e4, [0.0, 0.0, 1.0], ""),
        ]
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
            &["block 1", "Y3: not a word of fanuc"],
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
}
