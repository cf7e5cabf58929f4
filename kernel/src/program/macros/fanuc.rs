//! Fanuc's custom macro B, as the 0i reads it: `#i = expr` on a block of
//! its own, `IF [cond] GOTO n`, `IF [cond] THEN #i = expr`, `GOTO n`,
//! `WHILE [cond] DO m` .. `END m` (m 1 to 3), `DO m` .. `END m` without
//! end; `M98 P.. (L..)` calls a program, `M99` returns (`M99 P n` to the
//! caller's `N n`).

use super::expr::{self, Parser};
use super::scan::{self, Way};
use super::words::{self, target};
use super::{Call, Callee, Env, Flow, Language, State, Step};

const LANG: Language = Language::Fanuc;

/// Line `code`'s statements carried out (see [`super::step`]).
pub fn step(env: &Env<'_>, st: &mut State, code: &str) -> Result<Step, String> {
    let p = scan::parts(LANG, code);
    let rest = p.rest;
    if rest.starts_with('#') {
        assign(st, rest)?;
        return Ok(Step::done(Flow::Next));
    }
    if let Some(after) = rest.strip_prefix("IF") {
        return conditional(env, st, after);
    }
    if let Some(after) = rest.strip_prefix("GOTO") {
        return Ok(Step::done(goto(env, st, after)?));
    }
    match scan::key(LANG, code) {
        scan::Key::While(m) => {
            check_do(m)?;
            let cond = bracketed(st, rest.strip_prefix("WHILE").unwrap_or(rest))?;
            if !expr::truth(cond.0) {
                let end = env
                    .index()?
                    .close_of(env.line)
                    .ok_or("WHILE without its END")?;
                return Ok(Step::done(Flow::Jump(end + 1)));
            }
            let after = scan::squeezed(cond.1);
            if !after.starts_with("DO") {
                return Err(format!("WHILE [..] followed by '{after}', not DO m"));
            }
            return Ok(Step::done(Flow::Next));
        }
        scan::Key::Do(m) => {
            check_do(m)?;
            return Ok(Step::done(Flow::Next));
        }
        scan::Key::End(m) => {
            check_do(m)?;
            let open = env
                .index()?
                .open_of(env.line)
                .ok_or("END without its WHILE")?;
            st.turn()?;
            // WHILE reads its condition again; DO m alone goes on after it.
            let is_while = env
                .index()?
                .texts
                .get(&open)
                .is_some_and(|t| scan::key(LANG, t) == scan::Key::While(m));
            return Ok(Step::done(Flow::Jump(if is_while {
                open
            } else {
                open + 1
            })));
        }
        scan::Key::Program(n) => {
            // The file's first program names itself; running into another
            // means the program before had no end.
            let first = env.index()?.programs.values().min() == Some(&env.line);
            if first && st.frames.is_empty() {
                return Ok(Step::done(Flow::Next));
            }
            return Err(format!(
                "O{n:04}: the program runs into program O{n:04} (it has no end, M30 or M99, before it)"
            ));
        }
        _ => {}
    }
    let evaluated = words::evaluate(env, st, code)?.map(|e| e.code);
    let text = evaluated.as_deref().unwrap_or(code);
    if text.contains("M9") {
        if let Some(flow) = call_or_return(env, st, text)? {
            return Ok(Step::done(flow));
        }
    }
    Ok(Step::block(evaluated))
}

fn check_do(m: u32) -> Result<(), String> {
    if (1..=3).contains(&m) {
        Ok(())
    } else {
        Err(format!("DO{m}/END{m}: the loop's number is 1, 2 or 3"))
    }
}

/// `#i = expr` (or `#[expr] = expr`) set in `st`.
fn assign(st: &mut State, text: &str) -> Result<(), String> {
    let store = st.lookup(LANG);
    let mut p = Parser::new(LANG, text, &store);
    let t = target(LANG, &mut p)?;
    p.skip_spaces();
    if p.byte() != Some(b'=') {
        return Err(format!(
            "'{}': a variable where a block is wanted (a variable is set by #i = value)",
            crate::files::excerpt(text)
        ));
    }
    let rhs = &text[p.at + 1..];
    if rhs.trim().is_empty() {
        return Err(format!(
            "{}: nothing after '='",
            crate::files::excerpt(text)
        ));
    }
    let v = expr::evaluate(LANG, rhs, &store)?;
    st.set(LANG, &t, v)
}

/// The value of `[cond]` at the start of `text`, and the text after it.
fn bracketed<'t>(st: &State, text: &'t str) -> Result<(expr::Value, &'t str), String> {
    let t = text.trim_start();
    if !t.starts_with('[') {
        return Err(format!(
            "'{}': a condition in brackets is wanted",
            crate::files::excerpt(t)
        ));
    }
    let mut depth = 0;
    let mut end = None;
    for (i, c) in t.bytes().enumerate() {
        match c {
            b'[' => depth += 1,
            b']' => {
                depth -= 1;
                if depth == 0 {
                    end = Some(i);
                    break;
                }
            }
            _ => {}
        }
    }
    let end = end.ok_or("a condition's '[' not closed by ']'")?;
    let v = expr::evaluate(LANG, &t[1..end], &st.lookup(LANG))?;
    Ok((v, &t[end + 1..]))
}

/// `IF [cond] GOTO n` or `IF [cond] THEN #i = expr`.
fn conditional(env: &Env<'_>, st: &mut State, after: &str) -> Result<Step, String> {
    let (cond, rest) = bracketed(st, after)?;
    let rest = rest.trim_start();
    if let Some(n) = rest.strip_prefix("GOTO") {
        if !expr::truth(cond) {
            return Ok(Step::done(Flow::Next));
        }
        return Ok(Step::done(goto(env, st, n)?));
    }
    if let Some(a) = rest.strip_prefix("THEN") {
        if expr::truth(cond) {
            assign(st, a.trim_start())?;
        }
        return Ok(Step::done(Flow::Next));
    }
    Err(format!(
        "IF [..] followed by '{}': GOTO n or THEN #i = value is wanted",
        crate::files::excerpt(rest)
    ))
}

/// `GOTO n` (n an expression): to block `N n` of the program.
fn goto(env: &Env<'_>, st: &mut State, n: &str) -> Result<Flow, String> {
    let v = expr::evaluate(LANG, n, &st.lookup(LANG))?.ok_or("GOTO to a vacant block number")?;
    if !((1.0..=99_999.0).contains(&v) && v.fract() == 0.0) {
        return Err(format!("GOTO {v}: a block number is 1 to 99999"));
    }
    let within = env.index()?.program_at(env.line);
    let target = env
        .index()?
        .number(v as u32, within, env.line, Way::Around)?;
    if target <= env.line {
        st.turn()?;
    }
    Ok(Flow::Jump(target))
}

/// `M98 P.. (L..)` or `M99 (P..)` in the evaluated block `code`, where it
/// holds one.
///
/// # Failures
/// Another word with them, the called program's number or repetitions
/// out of range, `M99` in the main program (it would repeat it without
/// end).
fn call_or_return(env: &Env<'_>, st: &State, code: &str) -> Result<Option<Flow>, String> {
    let w = crate::program::words::words(code).map_err(|e| e.message)?;
    let is = |n: u32| w.iter().any(|w| w.letter == 'M' && w.integer() == Some(n));
    let (call, ret) = (is(98), is(99));
    if !call && !ret {
        return Ok(None);
    }
    let word = if call { "M98" } else { "M99" };
    if let Some(o) = w.iter().find(|x| {
        !matches!(x.letter, 'N' | 'P' | 'L' | 'M')
            || (x.letter == 'M' && x.integer() != Some(if call { 98 } else { 99 }))
    }) {
        return Err(format!(
            "{}: a word beside {word}, which the verification reads on a block of its own (N, {word}, P{})",
            o.text(),
            if call { ", L" } else { "" }
        ));
    }
    let p = w.iter().find(|x| x.letter == 'P');
    if ret {
        if st.frames.is_empty() {
            return Err(
                "M99 in the main program: the control runs the program again from its start, without end"
                    .into(),
            );
        }
        if w.iter().any(|x| x.letter == 'L') {
            return Err("M99 with L: not a word of M99".into());
        }
        let to = match p {
            Some(p) => Some(p.integer().ok_or_else(|| {
                format!("{}: M99's P is a block number, a whole number", p.text())
            })?),
            None => None,
        };
        return Ok(Some(Flow::Return(to)));
    }
    let p = p.ok_or("M98 without P, the program it calls")?;
    if p.has_point() {
        return Err(format!("{}: M98's P is a whole number", p.text()));
    }
    let digits = p.number.trim_start_matches('+');
    let all: u64 = digits
        .parse()
        .map_err(|_| format!("{}: M98's P is a whole number", p.text()))?;
    // 0i: P holds the repetitions before the program's four digits
    // (P0041234: O1234 four times); L, where given, counts them instead.
    let (mut times, number) = if env.repeats_in_p && digits.len() > 4 {
        (all / 10_000, (all % 10_000) as u32)
    } else {
        (1, all as u32)
    };
    if let Some(l) = w.iter().find(|x| x.letter == 'L') {
        if env.repeats_in_p && digits.len() > 4 {
            return Err(format!(
                "{}: repetitions given twice, in P{} and in L",
                l.text(),
                p.number
            ));
        }
        times = l
            .integer()
            .ok_or_else(|| format!("{}: L is a whole number of repetitions", l.text()))?
            .into();
    }
    if times == 0 || times > 9999 {
        return Err(format!(
            "M98 P{}: {times} repetitions, not 1 to 9999",
            p.number
        ));
    }
    Ok(Some(Flow::Call(Call {
        what: Callee::Number(number),
        times,
        args: Vec::new(),
    })))
}
