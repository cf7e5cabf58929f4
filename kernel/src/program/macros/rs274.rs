//! LinuxCNC's rs274ngc, as its interpreter reads a program: `#` and
//! `#<name>` parameters set anywhere on a line (taking effect after the
//! line is read), and the o-words: `sub`/`endsub`/`return`/`call`
//! (`#1`..`#30` the call's arguments), `if`/`elseif`/`else`/`endif`,
//! `while`/`endwhile`, `do`/`while`, `repeat`/`endrepeat`, `break`,
//! `continue`. A subroutine is defined where it stands (reading passes
//! over its body) and called by its number or name; `o<name> call` finds
//! `name.ngc` beside the program where the file does not define it.

use super::expr::{self, Parser};
use super::scan::{self, Key};
use super::words;
use super::{Call, Callee, Env, Flow, Language, State, Step, Target};

const LANG: Language = Language::Rs274;

/// Line `code`'s statements carried out (see [`super::step`]).
pub fn step(env: &Env<'_>, st: &mut State, code: &str) -> Result<Step, String> {
    let original = code;
    let upper;
    let code = if code.bytes().any(|b| b.is_ascii_lowercase()) {
        upper = code.to_ascii_uppercase();
        upper.as_str()
    } else {
        code
    };
    if let Key::O(name, kw) = scan::key(LANG, code) {
        return o_word(env, st, code, &name, kw).map(Step::done);
    }
    let Some(ev) = words::evaluate(env, st, code)? else {
        // Upper-cased only: LinuxCNC reads letters in either case.
        return Ok(Step::block((code != original).then(|| code.to_owned())));
    };
    let setting = !ev.sets.is_empty();
    for (t, v) in ev.sets {
        st.set(LANG, &t, v)?;
    }
    if setting && scan::parts(LANG, &ev.code).rest.is_empty() {
        return Ok(Step::done(Flow::Next));
    }
    Ok(Step::block(Some(ev.code)))
}

/// What follows an o-word's keyword on its line (`o100 call [1]`: `[1]`).
fn after_keyword<'c>(code: &'c str, kw: &str) -> &'c str {
    let t = scan::parts(LANG, code).rest;
    let t = t.strip_prefix(['O', 'o']).unwrap_or(t).trim_start();
    let t = match t.strip_prefix('<') {
        Some(r) => r.find('>').map_or("", |e| &r[e + 1..]),
        None => t.trim_start_matches(|c: char| c.is_ascii_digit()),
    }
    .trim_start();
    match t.get(..kw.len()) {
        Some(k) if k.eq_ignore_ascii_case(kw) => t[kw.len()..].trim(),
        _ => "",
    }
}

/// The bracketed condition after an o-word's keyword.
fn condition(st: &State, code: &str, kw: &str) -> Result<bool, String> {
    let text = after_keyword(code, kw);
    if !text.starts_with('[') {
        return Err(format!(
            "{} without its condition in brackets",
            kw.to_lowercase()
        ));
    }
    expr::evaluate(LANG, text, &st.lookup(LANG)).map(expr::truth)
}

/// An o-word statement `kw` of subroutine or structure `name`.
fn o_word(
    env: &Env<'_>,
    st: &mut State,
    code: &str,
    name: &str,
    kw: &'static str,
) -> Result<Flow, String> {
    let ix = env.index()?;
    let i = env.line;
    let close = || {
        ix.close_of(i)
            .ok_or_else(|| format!("o{name} {}: its end is missing", kw.to_lowercase()))
    };
    let open = || {
        ix.open_of(i)
            .ok_or_else(|| format!("o{name} {}: its opening is missing", kw.to_lowercase()))
    };
    match kw {
        // A definition passed over: its body runs when it is called.
        "SUB" => Ok(Flow::Jump(close()? + 1)),
        "ENDSUB" | "RETURN" => {
            if st.frames.is_empty() {
                return Err(format!(
                    "o{name} {} outside a call of o{name}",
                    kw.to_lowercase()
                ));
            }
            let value = after_keyword(code, kw);
            if value.starts_with('[') {
                let v = expr::evaluate(LANG, value, &st.lookup(LANG))?;
                // The caller reads it as #<_value>.
                st.set(LANG, &Target::Named("_value".into()), v)?;
            }
            Ok(Flow::Return(None))
        }
        "CALL" => {
            let args = arguments(st, after_keyword(code, "CALL"))?;
            let what = match ix.subs.get(name) {
                Some((line, _)) => Callee::Sub(*line),
                None if name.starts_with('<') => {
                    Callee::Name(name.trim_matches(['<', '>']).to_ascii_lowercase())
                }
                None => {
                    return Err(format!(
                        "o{name} call: no o{name} sub in the program before the call"
                    ))
                }
            };
            Ok(Flow::Call(Call {
                what,
                times: 1,
                args,
            }))
        }
        "IF" => {
            if condition(st, code, "IF")? {
                return Ok(Flow::Next);
            }
            branch_after(env, st, i)
        }
        "ELSEIF" | "ELSE" => {
            // The branch before it ran: on after the ENDIF.
            let mut at = i;
            while let Some(n) = ix.next_branch(at) {
                at = n;
            }
            Ok(Flow::Jump(at + 1))
        }
        "ENDIF" | "DO" => Ok(Flow::Next),
        "WHILE" => {
            if let Ok(o) = open() {
                // `do .. while`: again while the condition holds.
                if condition(st, code, "WHILE")? {
                    st.turn()?;
                    return Ok(Flow::Jump(o + 1));
                }
                return Ok(Flow::Next);
            }
            if condition(st, code, "WHILE")? {
                Ok(Flow::Next)
            } else {
                Ok(Flow::Jump(close()? + 1))
            }
        }
        "ENDWHILE" => {
            st.turn()?;
            Ok(Flow::Jump(open()?))
        }
        "REPEAT" => {
            let n = expr::evaluate(LANG, after_keyword(code, "REPEAT"), &st.lookup(LANG))?
                .unwrap_or(0.0)
                .floor();
            if n <= 0.0 {
                return Ok(Flow::Jump(close()? + 1));
            }
            st.set_repeats(i, n);
            Ok(Flow::Next)
        }
        "ENDREPEAT" => {
            let o = open()?;
            let left = st.repeats(o) - 1.0;
            if left > 0.0 {
                st.turn()?;
                st.set_repeats(o, left);
                Ok(Flow::Jump(o + 1))
            } else {
                st.clear_repeats(o);
                Ok(Flow::Next)
            }
        }
        "BREAK" | "CONTINUE" => {
            let l = ix
                .loop_of(i)
                .ok_or_else(|| format!("o{name} {}: outside its loop", kw.to_lowercase()))?;
            let end = ix.close_of(l).ok_or("a loop without its end")?;
            if kw == "BREAK" {
                st.clear_repeats(l);
                return Ok(Flow::Jump(end + 1));
            }
            // Continue: the loop's end decides (a while's condition, a
            // repeat's count).
            Ok(Flow::Jump(end))
        }
        other => Err(format!("o{name} {}: not read", other.to_lowercase())),
    }
}

/// The false `if` (or `elseif`) on line `i`: on at the first branch
/// whose condition holds, an `else`, or after the `endif`.
fn branch_after(env: &Env<'_>, st: &State, i: usize) -> Result<Flow, String> {
    let ix = env.index()?;
    let mut at = i;
    loop {
        let next = ix.next_branch(at).ok_or("an if without its endif")?;
        let text = ix.texts.get(&next).cloned().unwrap_or_default();
        let upper = text.to_ascii_uppercase();
        match scan::key(LANG, &upper) {
            Key::O(_, "ELSEIF") => {
                if condition(st, &upper, "ELSEIF")? {
                    return Ok(Flow::Jump(next + 1));
                }
                at = next;
            }
            _ => return Ok(Flow::Jump(next + 1)),
        }
    }
}

/// A call's arguments: each bracketed expression after `call`.
fn arguments(st: &State, text: &str) -> Result<Vec<f64>, String> {
    let store = st.lookup(LANG);
    let mut p = Parser::new(LANG, text, &store);
    let mut out = Vec::new();
    loop {
        p.skip_spaces();
        match p.byte() {
            None => return Ok(out),
            Some(b'[') => {
                let v = p.operand_value()?.unwrap_or(0.0);
                out.push(v);
                if out.len() > 30 {
                    return Err("more than 30 arguments: a call passes #1..#30".into());
                }
            }
            Some(_) => {
                return Err(format!(
                    "'{}' after call: each argument is a bracketed expression",
                    crate::files::excerpt(&text[p.at..])
                ))
            }
        }
    }
}

impl State {
    fn set_repeats(&mut self, line: usize, n: f64) {
        self.locals_mut().repeats.insert(line, n);
    }

    fn repeats(&self, line: usize) -> f64 {
        self.locals().repeats.get(&line).copied().unwrap_or(0.0)
    }

    fn clear_repeats(&mut self, line: usize) {
        self.locals_mut().repeats.remove(&line);
    }
}
