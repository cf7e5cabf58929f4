//! Sinumerik's NC language, as the 840D reads it: `R` parameters and
//! `DEF REAL`/`INT`/`BOOL` variables set in a block (`R1=5 R2=R1*2`, with
//! the block's words after), labels (`MARK1:`) and jumps (`GOTOF`,
//! `GOTOB`, `GOTO`, `GOTOC` to a label or a block number, `IF cond
//! GOTOF ..`), `IF` .. `ELSE` .. `ENDIF`, `WHILE` .. `ENDWHILE`, `LOOP` ..
//! `ENDLOOP`, `FOR var = a TO b` .. `ENDFOR`, `REPEAT` .. `UNTIL cond`,
//! `REPEAT MARK (MARK2) P=n` (a section again), a subprogram called by its
//! name (`KONTUR`, `L10`, `KONTUR P3`), `RET` or `M17` its end, `MSG(..)`
//! a message and `STOPRE` a stop of the look-ahead (neither moves).

use super::expr::{self, Parser};
use super::scan::{self, Way};
use super::words::{self, target, tokens};
use super::{Call, Callee, Env, Flow, Kind, Language, State, Step, Target};

const LANG: Language = Language::Sinumerik;

/// Words that are never a subprogram's name: Sinumerik's own instructions
/// the block reader reads or refuses by name.
const INSTRUCTIONS: [&str; 14] = [
    "DIAMON", "DIAMOF", "DIAM90", "G0", "TRANS", "ATRANS", "ROT", "AROT", "SCALE", "MIRROR",
    "TRAFOOF", "TRACYL", "TRANSMIT", "SUPA",
];

/// Line `code`'s statements carried out (see [`super::step`]).
pub fn step(env: &Env<'_>, st: &mut State, code: &str) -> Result<Step, String> {
    if plain(code) {
        return Ok(Step::block(None));
    }
    let p = scan::parts(LANG, code);
    let rest = p.rest;
    if rest.is_empty() {
        // A label alone (or a number alone).
        return Ok(Step::done(Flow::Next));
    }
    let first = rest.split_whitespace().next().unwrap_or("");
    let upper = first.to_ascii_uppercase();
    if upper.starts_with("CYCLE") {
        let name: String = upper
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect();
        return Err(format!(
            "{name}: a Siemens cycle, which the verification does not expand (CYCLE97 and CYCLE99, the threading cycles: their arguments' meanings are not in any public source the project could hold them to); verify the cycle's moves written as blocks"
        ));
    }
    let after = rest[first.len()..].trim_start();
    match upper.as_str() {
        "DEF" => return define(st, after).map(|()| Step::done(Flow::Next)),
        "GOTOF" | "GOTOB" | "GOTO" | "GOTOC" => {
            return Ok(Step::done(jump(env, st, &upper, after)?));
        }
        "IF" => return conditional(env, st, after),
        "ELSE" => {
            // Reached from its IF's branch: on after ENDIF.
            let end = structure_end(env, env.line)?;
            return Ok(Step::done(Flow::Jump(end + 1)));
        }
        "ENDIF" | "LOOP" | "STOPRE" => return Ok(Step::done(Flow::Next)),
        "WHILE" => {
            if expr::truth(condition(st, after)?) {
                return Ok(Step::done(Flow::Next));
            }
            let end = env
                .index()?
                .close_of(env.line)
                .ok_or("WHILE without ENDWHILE")?;
            return Ok(Step::done(Flow::Jump(end + 1)));
        }
        "ENDWHILE" => {
            st.turn()?;
            let open = env
                .index()?
                .open_of(env.line)
                .ok_or("ENDWHILE without WHILE")?;
            return Ok(Step::done(Flow::Jump(open)));
        }
        "ENDLOOP" => {
            st.turn()?;
            let open = env
                .index()?
                .open_of(env.line)
                .ok_or("ENDLOOP without LOOP")?;
            return Ok(Step::done(Flow::Jump(open + 1)));
        }
        "FOR" => return for_loop(env, st, after, true),
        "ENDFOR" => {
            let open = env.index()?.open_of(env.line).ok_or("ENDFOR without FOR")?;
            let text = env.index()?.texts.get(&open).cloned().unwrap_or_default();
            let head = scan::parts(LANG, &text).rest;
            let head = head.get(3..).unwrap_or("").trim_start();
            return for_loop(env, st, head, false);
        }
        "REPEAT" if after.is_empty() => return Ok(Step::done(Flow::Next)),
        "REPEAT" | "REPEATB" => return repeat_section(env, after, &upper),
        "UNTIL" => {
            if expr::truth(condition(st, after)?) {
                return Ok(Step::done(Flow::Next));
            }
            st.turn()?;
            let open = env
                .index()?
                .open_of(env.line)
                .ok_or("UNTIL without REPEAT")?;
            return Ok(Step::done(Flow::Jump(open + 1)));
        }
        "RET" if after.is_empty() => return Ok(Step::done(Flow::Return(None))),
        _ => {}
    }
    if upper.starts_with("MSG(") || upper == "MSG" {
        return Ok(Step::done(Flow::Next));
    }
    if let Some(call) = subprogram(rest)? {
        return Ok(Step::done(Flow::Call(call)));
    }
    // Settings first, in order, then the block's words.
    let mut words_left: Vec<&str> = Vec::new();
    let mut set_any = false;
    for t in tokens(rest) {
        if let Some((name, e)) = setting(t) {
            let store = st.lookup(LANG);
            let v = expr::evaluate(LANG, e, &store).map_err(|m| format!("{t}: {m}"))?;
            let target = match expr::r_number(&name) {
                Some(n) => Target::R(n as u32),
                None => Target::Named(name),
            };
            st.set(LANG, &target, v)?;
            set_any = true;
        } else {
            words_left.push(t);
        }
    }
    let mut block = String::new();
    if let Some(n) = p.number {
        block.push_str(&format!("N{n}"));
    }
    for w in &words_left {
        if !block.is_empty() {
            block.push(' ');
        }
        block.push_str(w);
    }
    if words_left.is_empty() {
        return Ok(Step::done(Flow::Next));
    }
    if words_left.iter().any(|w| w.eq_ignore_ascii_case("M17")) && words_left.len() == 1 {
        return Ok(Step::done(Flow::Return(None)));
    }
    let evaluated = words::evaluate(env, st, &block)?.map(|e| e.code);
    let changed = set_any || p.label.is_some();
    Ok(Step::block(match evaluated {
        Some(c) => Some(c),
        None => changed.then_some(block),
    }))
}

/// Whether `code` is a plain block: ISO words (a letter and a number)
/// and the reader's own setup words only, no `=`, no label, no name.
fn plain(code: &str) -> bool {
    // `M17` returns, `L10` calls: statements, not plain words.
    let word = |t: &str| {
        let b = t.as_bytes();
        b.len() > 1
            && b[0].is_ascii_uppercase()
            && b[0] != b'L'
            && b[1..]
                .iter()
                .all(|c| c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'+'))
    };
    !code.contains(['=', ':', '"'])
        && !code.contains("M17")
        && code
            .split_whitespace()
            .all(|t| word(t) || matches!(t, "DIAMON" | "DIAMOF") || t.starts_with("FGROUP("))
}

/// A setting `R1=..` or `NAME=..` where `NAME` is not an address the
/// block reader reads (`X=..`, `CR=..`, `SF=..` are words).
fn setting(t: &str) -> Option<(String, &str)> {
    let (name, e) = t.split_once('=')?;
    if name.is_empty() || !name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
        return None;
    }
    let upper = name.to_ascii_uppercase();
    if expr::r_number(&upper).is_some() {
        return Some((upper, e));
    }
    // A word's address: one letter, or the reader's own (CR, AR, SF, ...).
    let address = upper.len() == 1 || matches!(upper.as_str(), "CR" | "AR" | "SF" | "LIMS");
    (!address).then_some((upper, e))
}

/// `DEF REAL A, B=2` / `DEF INT N` / `DEF BOOL F`.
fn define(st: &mut State, text: &str) -> Result<(), String> {
    let mut it = text.splitn(2, char::is_whitespace);
    let ty = it.next().unwrap_or("").to_ascii_uppercase();
    let kind = match ty.as_str() {
        "REAL" => Kind::Real,
        "INT" => Kind::Int,
        "BOOL" => Kind::Bool,
        other => {
            return Err(format!(
                "DEF {other}: a type the verification does not follow (it reads REAL, INT, BOOL)"
            ))
        }
    };
    let list = it.next().unwrap_or("").trim();
    if list.is_empty() {
        return Err(format!("DEF {ty} without a name"));
    }
    for item in list.split(',') {
        let (name, v) = match item.split_once('=') {
            Some((n, e)) => {
                let v = expr::evaluate(LANG, e, &st.lookup(LANG))?.unwrap_or(0.0);
                (n.trim().to_ascii_uppercase(), v)
            }
            None => (item.trim().to_ascii_uppercase(), 0.0),
        };
        if name.is_empty()
            || !name.as_bytes()[0].is_ascii_alphabetic()
            || !name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
        {
            return Err(format!("DEF {ty} {name}: not a name"));
        }
        if name.len() == 1 {
            return Err(format!("DEF {ty} {name}: a one-letter name is an address"));
        }
        st.define(&name, kind, v)?;
    }
    Ok(())
}

/// The value of a condition's text.
fn condition(st: &State, text: &str) -> Result<expr::Value, String> {
    if text.trim().is_empty() {
        return Err("a condition is wanted".into());
    }
    expr::evaluate(LANG, text, &st.lookup(LANG))
}

/// `GOTOF`, `GOTOB`, `GOTO`, `GOTOC` to `target` (a label or `N` number).
fn jump(env: &Env<'_>, st: &mut State, word: &str, target: &str) -> Result<Flow, String> {
    let target = target.trim();
    if target.is_empty() || target.contains(char::is_whitespace) {
        return Err(format!(
            "{word} '{target}': one label or block number is wanted"
        ));
    }
    let way = match word {
        "GOTOF" => Way::Forward,
        "GOTOB" => Way::Backward,
        _ => Way::Around,
    };
    let found = match target
        .strip_prefix(['N', 'n'])
        .filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
    {
        Some(d) => {
            let n: u32 = d
                .parse()
                .map_err(|_| format!("{target}: not a block number"))?;
            env.index()?.number(n, 0..env.index()?.lines, env.line, way)
        }
        None => env.index()?.label(target, env.line, way),
    };
    let line = match found {
        Ok(l) => l,
        // GOTOC goes on where its target is missing.
        Err(_) if word == "GOTOC" => return Ok(Flow::Next),
        Err(e) => return Err(format!("{word} {target}: {e}")),
    };
    if line <= env.line {
        st.turn()?;
    }
    Ok(Flow::Jump(line))
}

/// `IF cond GOTOF ..` (a jump), or `IF cond` opening a block.
fn conditional(env: &Env<'_>, st: &mut State, after: &str) -> Result<Step, String> {
    let toks = tokens(after);
    if let Some(k) = toks.iter().position(|t| {
        matches!(
            t.to_ascii_uppercase().as_str(),
            "GOTO" | "GOTOF" | "GOTOB" | "GOTOC"
        )
    }) {
        let cond = toks[..k].join(" ");
        if !expr::truth(condition(st, &cond)?) {
            return Ok(Step::done(Flow::Next));
        }
        let word = toks[k].to_ascii_uppercase();
        let target = toks[k + 1..].join(" ");
        return Ok(Step::done(jump(env, st, &word, &target)?));
    }
    if expr::truth(condition(st, after)?) {
        return Ok(Step::done(Flow::Next));
    }
    // False: on at the ELSE's next line, or after ENDIF.
    let next = env
        .index()?
        .next_branch(env.line)
        .ok_or("IF without its ENDIF")?;
    Ok(Step::done(Flow::Jump(next + 1)))
}

/// The `ENDIF` of the `IF` whose branch line `i` (an `ELSE`) is.
fn structure_end(env: &Env<'_>, i: usize) -> Result<usize, String> {
    env.index()?
        .next_branch(i)
        .ok_or_else(|| "ELSE without its ENDIF".to_owned())
}

/// `FOR var = a TO b`: on entry (`entering`) the variable set to `a`, on
/// `ENDFOR` raised by 1; the body runs while it is at most `b`.
fn for_loop(env: &Env<'_>, st: &mut State, head: &str, entering: bool) -> Result<Step, String> {
    let upper = head.to_ascii_uppercase();
    let to = upper
        .find(" TO ")
        .ok_or_else(|| format!("FOR {head}: 'var = start TO end' is wanted"))?;
    let (assign, end) = (&head[..to], &head[to + 4..]);
    let store = st.lookup(LANG);
    let mut p = Parser::new(LANG, assign, &store);
    let t = target(LANG, &mut p)?;
    let start = assign[p.at..]
        .trim_start()
        .strip_prefix('=')
        .ok_or_else(|| format!("FOR {head}: 'var = start TO end' is wanted"))?;
    let end_v = expr::evaluate(LANG, end, &store)?.unwrap_or(0.0);
    let v = if entering {
        expr::evaluate(LANG, start, &store)?.unwrap_or(0.0)
    } else {
        let now = match &t {
            Target::R(n) => store_r(st, *n)?,
            Target::Named(n) => expr::evaluate(LANG, n, &st.lookup(LANG))?.unwrap_or(0.0),
            Target::Number(_) => 0.0,
        };
        now + 1.0
    };
    st.set(LANG, &t, Some(v))?;
    let (open, close) = if entering {
        (
            env.line,
            env.index()?
                .close_of(env.line)
                .ok_or("FOR without ENDFOR")?,
        )
    } else {
        (
            env.index()?.open_of(env.line).ok_or("ENDFOR without FOR")?,
            env.line,
        )
    };
    if v <= end_v {
        if !entering {
            st.turn()?;
        }
        return Ok(Step::done(Flow::Jump(open + 1)));
    }
    Ok(Step::done(Flow::Jump(close + 1)))
}

fn store_r(st: &State, n: u32) -> Result<f64, String> {
    use super::expr::Lookup;
    Ok(st.lookup(LANG).r(n.into())?.unwrap_or(0.0))
}

/// `REPEAT MARK (MARK2) (P=n)`: the lines from label `MARK` (to `MARK2`,
/// or to the line before the `REPEAT`) run again, `n` times (1 if not
/// given); `REPEATB MARK P=n` the block of the label alone.
fn repeat_section(env: &Env<'_>, after: &str, word: &str) -> Result<Step, String> {
    let toks: Vec<&str> = after.split_whitespace().collect();
    let mut times = 1u64;
    let mut labels = Vec::new();
    for t in &toks {
        let u = t.to_ascii_uppercase();
        if let Some(n) = u.strip_prefix("P=").or_else(|| {
            u.strip_prefix('P')
                .filter(|d| d.bytes().all(|b| b.is_ascii_digit()) && !d.is_empty())
        }) {
            times = n
                .parse()
                .map_err(|_| format!("{word} {t}: P is a whole number of repetitions"))?;
        } else {
            labels.push(*t);
        }
    }
    if times == 0 || times > 9999 || labels.is_empty() || labels.len() > 2 {
        return Err(format!(
            "{word} {after}: a label (and an end label) and P=1..9999 are wanted"
        ));
    }
    let from = env.index()?.label(labels[0], env.line, Way::Backward)?;
    let to = match (word, labels.get(1)) {
        ("REPEATB", _) => from + 1,
        (_, Some(end)) => env.index()?.label(end, env.line, Way::Backward)? + 1,
        (_, None) => env.line,
    };
    if to <= from {
        return Err(format!(
            "{word} {after}: the end label stands before the start"
        ));
    }
    Ok(Step::done(Flow::Call(Call {
        what: Callee::Section(from, to),
        times,
        args: Vec::new(),
    })))
}

/// A subprogram's call: a name alone, or with its repetitions (`KONTUR`,
/// `L10`, `KONTUR P3`, `P3 KONTUR`, `CALL "KONTUR"`).
fn subprogram(rest: &str) -> Result<Option<Call>, String> {
    let toks: Vec<&str> = rest.split_whitespace().collect();
    let mut name = None;
    let mut times = 1u64;
    if let [c, quoted] = toks.as_slice() {
        if c.eq_ignore_ascii_case("CALL") {
            let n = quoted.trim_matches('"');
            return Ok(Some(Call {
                what: Callee::Name(n.to_ascii_uppercase()),
                times: 1,
                args: Vec::new(),
            }));
        }
    }
    for t in &toks {
        let u = t.to_ascii_uppercase();
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        if let Some(n) = u
            .strip_prefix("P=")
            .or_else(|| u.strip_prefix('P').filter(|d| digits(d)))
        {
            times = match n.parse() {
                Ok(v) => v,
                Err(_) => return Ok(None),
            };
        } else if u.len() >= 2
            && u.as_bytes()[0].is_ascii_alphabetic()
            && u.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
            && name.is_none()
        {
            name = Some(u);
        } else {
            return Ok(None);
        }
    }
    let Some(name) = name else { return Ok(None) };
    // `L10` is a call; a word of one letter and a number is an address.
    let word_like = name.as_bytes()[1].is_ascii_digit() && !name.starts_with('L');
    let keyword = INSTRUCTIONS.contains(&name.as_str())
        || scan::SINUMERIK_BLOCKS.contains(&name.as_str())
        || matches!(name.as_str(), "RET" | "M17" | "M30" | "M2" | "MSG")
        || expr::r_number(&name).is_some();
    if word_like || keyword {
        return Ok(None);
    }
    if times == 0 || times > 9999 {
        return Err(format!("{name} P{times}: repetitions are 1 to 9999"));
    }
    Ok(Some(Call {
        what: Callee::Name(name),
        times,
        args: Vec::new(),
    }))
}
