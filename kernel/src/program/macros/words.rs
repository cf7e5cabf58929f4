//! A block's words whose values are expressions, evaluated as the control
//! evaluates them: Fanuc's `X#1`, `X-[#1+2.]`; rs274ngc's `X#1`,
//! `X[#1*2]`, `X ABS[#2]`, and its parameters set on the line
//! (`#1=5`, which take effect after the line is read); Sinumerik's
//! `X=R1*2`, `CR=(R2+1)`. Each value becomes the number a plain block
//! would hold, so that the block reader reads it as any block.
//!
//! A value from a variable carries its decimal point (Fanuc reads
//! `X#1` with #1 = 10 as 10 mm, never in the least input unit); Fanuc
//! rounds an axis's value to its least input increment; a word given
//! Fanuc's vacant value is dropped, as the control drops it.

use super::expr::{Parser, Value};
use super::{Env, Language, State, Target};
use crate::math::Real;

/// The addresses whose values are codes (whole numbers).
const CODE_LETTERS: &str = "GMTNDHOLP";

/// A block's code with its expressions evaluated, and rs274ngc's
/// parameters set on the line (in order, each value read before any is
/// set).
pub struct Evaluated {
    /// The code.
    pub code: String,
    /// rs274ngc's settings.
    pub sets: Vec<(Target, Value)>,
}

/// `text`, one block's code (its statements taken out), evaluated in
/// `env` with the variables of `st`; `None` where it holds no expression.
///
/// # Failures
/// An expression that cannot be evaluated, a code that is not a whole
/// number, a value not finite.
pub fn evaluate(env: &Env<'_>, st: &State, text: &str) -> Result<Option<Evaluated>, String> {
    match env.lang {
        Language::Sinumerik if text.contains('=') => sinumerik(env, st, text).map(Some),
        Language::Fanuc | Language::Rs274 if text.contains(['#', '[']) => {
            hashed(env, st, text).map(Some)
        }
        _ => Ok(None),
    }
}

/// The value `v` of address `letter` as a plain word's number: a code's
/// whole number, an axis's rounded where the control rounds it, else the
/// value with its point.
///
/// # Failures
/// A code that is not a whole number.
pub fn number(env: &Env<'_>, letter: char, v: Real) -> Result<String, String> {
    if !v.is_finite() {
        return Err(format!("{letter}: the value {v} is not a finite number"));
    }
    if CODE_LETTERS.contains(letter) && env.lang != Language::Rs274 {
        if v.fract() != 0.0 || v < 0.0 {
            return Err(format!(
                "{letter}{v}: a value that is not a whole number where {} takes one",
                env.lang.name()
            ));
        }
        return Ok(format!("{}", v as u64));
    }
    if let Some(unit) = env.round_axes.filter(|_| env.axes.contains(&letter)) {
        let decimals = (-unit.log10()).round().max(0.0) as usize;
        let steps = (v / unit).round();
        return Ok(format!("{:.*}", decimals, steps * unit));
    }
    let s = format!("{v}");
    Ok(if s.contains('.') { s } else { s + "." })
}

/// Fanuc's and rs274ngc's blocks: words whose values begin with `#` or
/// `[` (or, in rs274ngc, a function), and rs274ngc's settings.
fn hashed(env: &Env<'_>, st: &State, text: &str) -> Result<Evaluated, String> {
    let store = st.lookup(env.lang);
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len() + 8);
    let mut sets = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b' ' || c == b'\t' {
            i += 1;
            continue;
        }
        if c == b'#' {
            // A setting: `#1=..`, `#<name>=..`, `#[..]=..`.
            if env.lang != Language::Rs274 {
                return Err(
                    "a variable set in a block with other words: Fanuc sets a variable in a block of its own".into(),
                );
            }
            let mut p = Parser::new(env.lang, text, &store);
            p.at = i;
            let target = target(env.lang, &mut p)?;
            p.skip_spaces();
            if p.at >= b.len() || b[p.at] != b'=' {
                return Err(format!(
                    "'{}': a parameter where a word is wanted (a parameter is set by #n = value)",
                    crate::files::excerpt(&text[i..])
                ));
            }
            p.at += 1;
            let v = real_value(&mut p)?;
            sets.push((target, v));
            i = p.at;
            continue;
        }
        if !c.is_ascii_alphabetic() {
            // Not a word: the block reader names it.
            out.push_str(&text[i..]);
            break;
        }
        let letter = c as char;
        let mut j = i + 1;
        while j < b.len() && (b[j] == b' ' || b[j] == b'\t') {
            j += 1;
        }
        let value_at = j;
        let mut k = j;
        if k < b.len() && (b[k] == b'-' || b[k] == b'+') {
            k += 1;
            while k < b.len() && b[k] == b' ' {
                k += 1;
            }
        }
        // rs274ngc's value may be a function: letters, then its bracket.
        let function = env.lang == Language::Rs274 && {
            let n = b[k..]
                .iter()
                .take_while(|c| c.is_ascii_alphabetic())
                .count();
            n > 1 && b.get(k + n) == Some(&b'[')
        };
        let computed = k < b.len() && (b[k] == b'#' || b[k] == b'[' || function);
        if !computed {
            // A plain word (or what the block reader will refuse): copied.
            let end = (value_at..b.len())
                .find(|&m| !(b[m].is_ascii_digit() || matches!(b[m], b'.' | b'-' | b'+')))
                .unwrap_or(b.len());
            if !out.is_empty() {
                out.push(' ');
            }
            out.push(letter);
            out.push_str(&text[value_at..end]);
            i = end.max(i + 1);
            continue;
        }
        let mut p = Parser::new(env.lang, text, &store);
        p.at = value_at;
        let v = real_value(&mut p)?;
        i = p.at;
        // Fanuc drops a word whose value is vacant.
        let Some(v) = v else { continue };
        if !out.is_empty() {
            out.push(' ');
        }
        out.push(letter);
        out.push_str(&number(env, letter, v)?);
    }
    Ok(Evaluated { code: out, sets })
}

/// One real value: a sign, then a number, a variable, a bracketed
/// expression or (rs274ngc) a function.
fn real_value(p: &mut Parser<'_, '_>) -> Result<Value, String> {
    p.skip_spaces();
    let neg = if p_peek(p) == Some(b'-') {
        p.at += 1;
        true
    } else {
        if p_peek(p) == Some(b'+') {
            p.at += 1;
        }
        false
    };
    let v = p.operand_value()?;
    Ok(if neg { v.map(|v| -v) } else { v })
}

fn p_peek(p: &mut Parser<'_, '_>) -> Option<u8> {
    p.skip_spaces();
    p.byte()
}

/// An assignment's target at the parser (`#1`, `#[#2]`, `#<name>`,
/// Sinumerik's `R1` or local name).
///
/// # Failures
/// No target there.
pub fn target(lang: Language, p: &mut Parser<'_, '_>) -> Result<Target, String> {
    p.skip_spaces();
    match (lang, p.byte()) {
        (Language::Fanuc | Language::Rs274, Some(b'#')) => {
            p.at += 1;
            p.skip_spaces();
            match p.byte() {
                Some(b'<') if lang == Language::Rs274 => Ok(Target::Named(p.angle_name()?)),
                Some(b'[') => {
                    p.at += 1;
                    let n = p.expression()?;
                    p.skip_spaces();
                    if p.byte() != Some(b']') {
                        return Err("#[ not closed by ']'".into());
                    }
                    p.at += 1;
                    whole_target(n)
                }
                Some(c) if c.is_ascii_digit() => whole_target(Some(p.number()?)),
                _ => Err("'#' without a variable's number".into()),
            }
        }
        (Language::Sinumerik, Some(c)) if c.is_ascii_alphabetic() => {
            let name = p.identifier();
            Ok(match super::expr::r_number(&name) {
                Some(n) => Target::R(n as u32),
                None => Target::Named(name),
            })
        }
        _ => Err("no variable where one is set".into()),
    }
}

fn whole_target(n: Value) -> Result<Target, String> {
    match n {
        Some(n) if n >= 0.0 && n.fract() == 0.0 && n < 1e9 => Ok(Target::Number(n as u32)),
        _ => Err(format!(
            "#{}: a variable's number is a whole number from 0",
            n.map_or("<vacant>".into(), |n| n.to_string())
        )),
    }
}

/// Sinumerik's words `ADDR=expr` (`X=R1*2`, `CR=R2`), each evaluated; a
/// one-letter address becomes its plain word (`X12.5`), a longer one
/// keeps its `=` (`CR=12.5`).
fn sinumerik(env: &Env<'_>, st: &State, text: &str) -> Result<Evaluated, String> {
    let store = st.lookup(env.lang);
    let mut out = String::with_capacity(text.len());
    for token in tokens(text) {
        if !out.is_empty() {
            out.push(' ');
        }
        let Some((addr, e)) = token.split_once('=') else {
            out.push_str(token);
            continue;
        };
        if addr.is_empty() || !addr.bytes().all(|b| b.is_ascii_alphanumeric()) {
            out.push_str(token);
            continue;
        }
        let v = super::expr::evaluate(env.lang, e, &store)
            .map_err(|m| format!("{addr}={e}: {m}"))?
            .unwrap_or(0.0);
        let mut letters = addr.chars();
        match (letters.next(), letters.next()) {
            (Some(l), None) => {
                out.push(l);
                out.push_str(&number(env, l, v)?);
            }
            _ => {
                out.push_str(addr);
                out.push('=');
                let s = format!("{v}");
                out.push_str(&s);
            }
        }
    }
    Ok(Evaluated {
        code: out,
        sets: Vec::new(),
    })
}

/// Sinumerik's block split at spaces outside brackets and strings.
pub fn tokens(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let b = text.as_bytes();
    let (mut depth, mut quoted, mut start) = (0i32, false, None);
    for (i, c) in b.iter().enumerate() {
        match c {
            b'"' => quoted = !quoted,
            b'(' | b'[' if !quoted => depth += 1,
            b')' | b']' if !quoted => depth -= 1,
            _ => {}
        }
        let space = (*c == b' ' || *c == b'\t') && depth <= 0 && !quoted;
        match (space, start) {
            (true, Some(s)) => {
                out.push(&text[s..i]);
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push(&text[s..]);
    }
    out
}
