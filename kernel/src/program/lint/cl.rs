//! The APT CL file read back: each record one the writer makes, in the
//! form it makes it (the part's, machine's and tool's names and numbers,
//! text of names' characters in `PPRINT/`), no character pilgrim never
//! writes; the spindle turning (at a speed that is not 0) and the coolant
//! on where the setup says before a cutting `GOTO/`, `RAPID` before
//! exactly the rapid ones; one `GOTO/` a block with the axis program's
//! values, `FINI` last.

use super::{LintError, Linted};
use crate::math::Real;
use crate::program::post::Dialect;
use crate::program::AxisProgram;
use crate::toolpath::Motion;

/// What the CL file has said so far.
#[derive(Debug, Default)]
struct Said {
    /// `GOTO/` records read (the next block of the axis program).
    k: usize,
    /// `RAPID` read for the next `GOTO/`.
    rapid_next: bool,
    coolant: bool,
    /// The spindle's speed, while it turns.
    speed: Option<Real>,
}

/// Reads the CL file `text` back against `program` (see the module's docs).
///
/// # Failures
/// The first record or rule the file breaks, by line or block.
pub(super) fn lint_apt(
    text: &str,
    program: &AxisProgram,
    d: &Dialect,
) -> Result<Linted, LintError> {
    let fault = |place: String, message: String| LintError {
        what: "lint",
        dialect: d.name.to_owned(),
        place,
        message,
    };
    let Some(body) = text.strip_suffix('\n') else {
        return Err(fault(
            "the last line".into(),
            "the CL file's last line does not end with a line feed".into(),
        ));
    };
    let lines: Vec<&str> = body.split('\n').collect();
    let mut said = Said::default();
    let mut ticker = crate::budget::Ticker::new("the CL file's lint", 1024);
    for (l, line) in lines.iter().enumerate() {
        let at = || format!("line {}", l + 1);
        ticker.tick().map_err(|e| fault(at(), e.to_string()))?;
        record(line, program, d, &mut said).map_err(|m| fault(at(), m))?;
        if *line == "FINI" && l + 1 != lines.len() {
            return Err(fault(at(), "records after FINI".into()));
        }
        if let Some(values) = line.strip_prefix("GOTO/") {
            let Some(b) = program.blocks.get(said.k) else {
                return Err(fault(at(), "a GOTO beyond the axis program".into()));
            };
            // Named only when a fault is told: finding the pass of a block
            // walks back through the blocks before it.
            goto(values, b, program, d, &mut said)
                .map_err(|m| fault(crate::program::name_in(d.name, &program.blocks, said.k), m))?;
            said.k += 1;
        }
    }
    let last = format!("line {}", lines.len());
    if lines.last() != Some(&"FINI") {
        return Err(fault(last, "the CL file does not end with FINI".into()));
    }
    if said.k != program.blocks.len() {
        return Err(fault(
            last,
            format!(
                "{} GOTO records, the axis program has {} blocks",
                said.k,
                program.blocks.len()
            ),
        ));
    }
    Ok(Linted {
        moves: said.k,
        lines: lines.len(),
    })
}

/// One record `line`, one the writer makes in the form it makes it, taken
/// into what the file has `said`.
fn record(line: &str, program: &AxisProgram, d: &Dialect, said: &mut Said) -> Result<(), String> {
    if let Some(c) = line.chars().find(|c| c.is_control() || !c.is_ascii()) {
        return Err(format!(
            "the character U+{:04X}, which pilgrim never writes",
            u32::from(c)
        ));
    }
    let not_record = || {
        format!(
            "'{}' is not a CL record pilgrim writes",
            crate::files::excerpt(line)
        )
    };
    let (word, arg) = line.split_once('/').unwrap_or((line, ""));
    match (word, arg) {
        ("PARTNO", a) if a == program.name => {}
        ("MACHIN", a) if a == crate::program::post::comment_text(d, &program.machine) => {}
        ("UNITS", "MM") | ("FINI", "") => {}
        ("LOADTL", a) if a == program.tool_number.to_string() => {}
        ("PPRINT", a) => {
            let written_by = format!("written by pilgrim {}", crate::version::VERSION);
            if a != written_by && !a.chars().all(crate::names::is_name_char) {
                return Err(format!(
                    "PPRINT/{}: text no comment of pilgrim's holds",
                    crate::files::excerpt(a)
                ));
            }
        }
        ("COOLNT", "ON") => said.coolant = true,
        ("COOLNT", "OFF") => said.coolant = false,
        ("SPINDL", "OFF") => said.speed = None,
        ("SPINDL", a) => {
            let v: Real = a
                .strip_suffix(",RPM,CLW")
                .and_then(|v| v.parse().ok())
                .ok_or_else(not_record)?;
            if !(v >= 1.0) {
                return Err(format!(
                    "SPINDL/{v}: the spindle would stand while the program cuts"
                ));
            }
            said.speed = Some(v);
        }
        ("RAPID", "") => said.rapid_next = true,
        ("FEDRAT", a) if a.ends_with(",MMPM") || a.ends_with(",MMPR") => {}
        ("GOTO", _) => {}
        _ => return Err(not_record()),
    }
    Ok(())
}

/// A `GOTO/` record's `values` against the axis program's block `b`: a
/// rapid where it is one, the spindle and coolant on for a cut, each
/// axis's value within half the output's last decimal.
fn goto(
    values: &str,
    b: &crate::program::Block,
    program: &AxisProgram,
    d: &Dialect,
    said: &mut Said,
) -> Result<(), String> {
    let decimals = crate::program::written_decimals(program.decimals, d.name);
    let half = 0.5 * 10f64.powi(-(decimals as i32)) + crate::tolerance::SAME_LENGTH;
    let rapid = std::mem::take(&mut said.rapid_next);
    if rapid != (b.motion == Motion::Rapid) {
        return Err(format!(
            "{}, where the axis program has a {:?} move",
            if rapid { "RAPID" } else { "a feed move" },
            b.motion
        ));
    }
    if !rapid && said.speed.is_none() {
        return Err("a cutting move with the spindle off".into());
    }
    if !rapid && program.setup.coolant && !said.coolant {
        return Err("a cutting move with the coolant off (no COOLNT/ON), which the machine's setup turns on".into());
    }
    let read: Vec<Real> = values
        .split(',')
        .map(|v| v.parse())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{values}' are not numbers"))?;
    if read.len() != b.values.len() {
        return Err(format!("{} values for {} axes", read.len(), b.values.len()));
    }
    for (i, (r, w)) in read.iter().zip(&b.values).enumerate() {
        if !((r - w).abs() <= half) {
            return Err(format!(
                "{} = {r} read back, the axis program's {w}",
                program.axes[i].name
            ));
        }
    }
    Ok(())
}
