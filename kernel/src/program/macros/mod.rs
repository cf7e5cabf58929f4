//! The languages shops write their programs in by hand, read as the
//! control reads them: Fanuc's custom macro B (`#` variables, `IF [..]
//! GOTO n`, `WHILE [..] DO m`, `M98`/`M99` subprograms), Sinumerik's
//! (`R` parameters, `DEF` variables, labels with `GOTOF`/`GOTOB`, `IF`,
//! `WHILE`, `LOOP`, `FOR`, `REPEAT`, subprograms by name) and LinuxCNC's
//! rs274ngc (`#` parameters, `o`-word subroutines and loops).
//!
//! This is a layer of the one reader ([`super::reader`]), not a second
//! reader: a line's statements are carried out here (a variable set, a
//! jump, a loop's turn, a call), and what is left is a block whose
//! expressions are evaluated to numbers ([`words`]) and read by the
//! block reader as any block. Nothing is skipped: a statement, a function
//! or a variable this layer does not know is refused naming it.
//!
//! Every repetition is bounded: [`MAX_TURNS`] loop turns and repetitions
//! of a subprogram in all, calls [`MAX_CALL_DEPTH`] deep, [`MAX_FILES`]
//! subprogram files read; and the run's time limit holds on every line.

pub mod expr;
mod fanuc;
mod rs274;
pub mod scan;
mod sinumerik;
pub mod words;

pub use scan::{Index, Way};

use crate::math::Real;
use expr::{Lookup, Value};
use std::collections::BTreeMap;

pub use crate::program::post::MacroLanguage as Language;

/// Loop turns and repetitions of a subprogram in one reading, in all: a
/// program that turns more is refused (a loop that never ends would
/// otherwise read until the time limit, and a bound reached is a clear
/// refusal, not a hang).
pub const MAX_TURNS: u64 = 1_000_000;

/// Calls nested deeper than this are refused: Sinumerik nests 16 levels
/// (840D sl), Fanuc 0i-D/F 10 subprogram levels, rs274ngc 10; a
/// recursion is refused where it passes the bound.
pub const MAX_CALL_DEPTH: usize = 16;

/// Subprogram files one reading may open beside the program.
pub const MAX_FILES: usize = 64;

/// A Sinumerik local variable's type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `REAL`.
    Real,
    /// `INT`: a value assigned is rounded to a whole number.
    Int,
    /// `BOOL`: 0 or 1.
    Bool,
}

/// One call's own variables (a subprogram's locals and arguments).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Locals {
    /// Named locals: Sinumerik's `DEF`, rs274ngc's `#<name>`.
    named: BTreeMap<String, (Kind, Real)>,
    /// rs274ngc's `#1`..`#30` inside a call (its arguments).
    args: BTreeMap<u32, Real>,
    /// rs274ngc's `repeat` counters, by the line of their `repeat`.
    repeats: BTreeMap<usize, Real>,
}

impl Locals {
    /// rs274ngc's call arguments `args` as `#1`, `#2`, ...
    pub fn set_args(&mut self, args: &[Real]) {
        for (k, v) in args.iter().enumerate() {
            self.args.insert(k as u32 + 1, *v);
        }
    }
}

/// A call in progress: where it returns and what it repeats.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// The file the called lines are in (0: the program's own).
    pub file: usize,
    /// The called program's first line.
    pub entry: usize,
    /// The line the called lines end before, where a call is of a part of
    /// a file (Sinumerik's `REPEAT`): reaching it returns.
    pub end: Option<usize>,
    /// Where the call returns: its file and the line after the call.
    pub back: (usize, usize),
    /// Repetitions left after the one running.
    pub repeats: u64,
    /// Its own variables.
    pub locals: Locals,
}

/// What the text has set so far: its variables, the calls in progress,
/// the loops' turns. Part of the reader's standing ([`super::reader::Standing`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct State {
    /// Fanuc's `#1`..`#999` (a vacant one absent); rs274ngc's numbered
    /// parameters outside a call.
    numbered: BTreeMap<u32, Real>,
    /// Sinumerik's `R` parameters.
    r: BTreeMap<u32, Real>,
    /// rs274ngc's global named parameters (`#<_name>`).
    globals: BTreeMap<String, Real>,
    /// The main program's own named variables.
    main: Locals,
    /// The calls in progress, innermost last.
    pub frames: Vec<Frame>,
    /// Loop turns and repetitions so far.
    turns: u64,
}

impl State {
    /// The file being read: the innermost call's, else the program's.
    pub fn file(&self) -> usize {
        self.frames.last().map_or(0, |f| f.file)
    }

    fn locals(&self) -> &Locals {
        self.frames.last().map_or(&self.main, |f| &f.locals)
    }

    fn locals_mut(&mut self) -> &mut Locals {
        match self.frames.last_mut() {
            Some(f) => &mut f.locals,
            None => &mut self.main,
        }
    }

    /// One more loop turn or repetition.
    ///
    /// # Failures
    /// Past [`MAX_TURNS`].
    pub fn turn(&mut self) -> Result<(), String> {
        self.turns += 1;
        if self.turns > MAX_TURNS {
            return Err(format!(
                "more than {MAX_TURNS} loop turns and repetitions: the verification reads at most {MAX_TURNS} (a loop that does not end, or a program too long to verify)"
            ));
        }
        Ok(())
    }

    /// A store to evaluate expressions against, in `lang`.
    pub fn lookup(&self, lang: Language) -> Store<'_> {
        Store { st: self, lang }
    }
}

/// The variables as an expression reads them, in a language.
pub struct Store<'s> {
    st: &'s State,
    lang: Language,
}

impl Lookup for Store<'_> {
    fn number(&self, n: Real) -> Result<Value, String> {
        let st = self.st;
        let k = n as u32;
        match self.lang {
            Language::Fanuc => match k {
                0 => Ok(None),
                1..=33 => Ok(st.numbered.get(&k).copied()),
                100..=199 | 500..=999 => st.numbered.get(&k).copied().map(Some).ok_or_else(|| {
                    format!(
                        "#{k} is read before the program sets it: the control keeps its common variables between programs (#100..#199 until power-off, #500..#999 for good), so its value is the machine's, which the verification does not know; set #{k} in the program first"
                    )
                }),
                _ => Err(fanuc_system(k)),
            },
            Language::Rs274 => {
                if (1..=30).contains(&k) && !st.frames.is_empty() {
                    return Ok(Some(st.locals().args.get(&k).copied().unwrap_or(0.0)));
                }
                match k {
                    1..=5000 => st.numbered.get(&k).copied().map(Some).ok_or_else(|| {
                        format!(
                            "#{k} is read before the program sets it: LinuxCNC keeps its numbered parameters while it runs, so its value is what an earlier program left, which the verification does not know; set #{k} in the program first"
                        )
                    }),
                    _ => Err(format!(
                        "#{k}: a parameter LinuxCNC sets itself (#5001 and above: positions, offsets, tool data), whose value the verification does not know"
                    )),
                }
            }
            Language::Sinumerik => Err(format!("#{k}: not a Sinumerik variable")),
        }
    }

    fn named(&self, name: &str) -> Result<Value, String> {
        let st = self.st;
        if self.lang == Language::Rs274 && name.starts_with('_') {
            return st.globals.get(name).copied().map(Some).ok_or_else(|| {
                format!(
                    "#<{name}> is read before the program sets it: a global named parameter the program does not set is LinuxCNC's own (a position, a mode), whose value the verification does not know"
                )
            });
        }
        match st.locals().named.get(name) {
            Some((_, v)) => Ok(Some(*v)),
            None => Err(match self.lang {
                Language::Rs274 => format!("#<{name}> is read before it is set (LinuxCNC stops there: 'named parameter not defined')"),
                _ => format!("{name}: not a variable the program defines (DEF REAL {name}), nor a word or instruction the verification reads"),
            }),
        }
    }

    fn r(&self, n: Real) -> Result<Value, String> {
        let k = n as u32;
        if k > 999 {
            return Err(format!("R{k}: beyond R999, the control's R parameters"));
        }
        self.st.r.get(&k).copied().map(Some).ok_or_else(|| {
            format!(
                "R{k} is read before the program sets it: the control keeps its R parameters between programs, so its value is what an earlier program left, which the verification does not know; set R{k} in the program first"
            )
        })
    }

    fn exists(&self, name: &str) -> bool {
        if name.starts_with('_') {
            self.st.globals.contains_key(name)
        } else {
            self.st.locals().named.contains_key(name)
        }
    }
}

/// The refusal of a Fanuc system variable (#1000 and above), or a number
/// no variable has.
fn fanuc_system(k: u32) -> String {
    let what = match k {
        34..=99 => "not a variable of the 0i's custom macro B",
        200..=499 => "a common variable the 0i has only as an option",
        1000..=1999 => "a system variable: the interface signals",
        2000..=2999 => "a system variable: the tool offsets",
        3000..=3999 => "a system variable: alarms, the clock, the part count, modes",
        4000..=4999 => "a system variable: the modal information",
        5000..=5999 => "a system variable: the positions and work offsets",
        _ => "a system variable",
    };
    format!("#{k}: {what}, whose value is the control's, which the verification does not know")
}

/// Where an assignment writes.
#[derive(Debug, Clone, PartialEq)]
pub enum Target {
    /// `#n`.
    Number(u32),
    /// `#<name>`, a Sinumerik local.
    Named(String),
    /// `Rn`.
    R(u32),
}

impl State {
    /// Sets `target` to `v` in `lang`.
    ///
    /// # Failures
    /// A variable the program may not set (a system variable, `#0`, an
    /// undefined Sinumerik name), or a vacant value where the language has
    /// none.
    pub fn set(&mut self, lang: Language, target: &Target, v: Value) -> Result<(), String> {
        match (lang, target) {
            (Language::Fanuc, Target::Number(k)) => match *k {
                0 => Err("#0 is always vacant: the control refuses to set it".into()),
                1..=33 | 100..=199 | 500..=999 => {
                    match v {
                        Some(v) => self.numbered.insert(*k, v),
                        None => self.numbered.remove(k),
                    };
                    Ok(())
                }
                k => Err(fanuc_system(k)),
            },
            (Language::Rs274, Target::Number(k)) => {
                let v = v.unwrap_or(0.0);
                if (1..=30).contains(k) && !self.frames.is_empty() {
                    self.locals_mut().args.insert(*k, v);
                    return Ok(());
                }
                if !(1..=5000).contains(k) {
                    return Err(format!(
                        "#{k}: a parameter LinuxCNC sets itself (#5001 and above), which the verification does not follow"
                    ));
                }
                self.numbered.insert(*k, v);
                Ok(())
            }
            (Language::Rs274, Target::Named(n)) => {
                let v = v.unwrap_or(0.0);
                if n.starts_with('_') {
                    self.globals.insert(n.clone(), v);
                } else {
                    self.locals_mut().named.insert(n.clone(), (Kind::Real, v));
                }
                Ok(())
            }
            (Language::Sinumerik, Target::R(k)) => {
                if *k > 999 {
                    return Err(format!("R{k}: beyond R999, the control's R parameters"));
                }
                self.r.insert(*k, v.unwrap_or(0.0));
                Ok(())
            }
            (Language::Sinumerik, Target::Named(n)) => {
                let v = v.unwrap_or(0.0);
                let Some((kind, slot)) = self.locals_mut().named.get_mut(n) else {
                    return Err(format!(
                        "{n} = ...: {n} is not a variable the program defines (DEF REAL {n})"
                    ));
                };
                *slot = match kind {
                    Kind::Real => v,
                    // Sinumerik rounds a REAL assigned to an INT.
                    Kind::Int => v.round(),
                    Kind::Bool => {
                        if v != 0.0 {
                            1.0
                        } else {
                            0.0
                        }
                    }
                };
                Ok(())
            }
            (lang, t) => Err(format!("{t:?} is not a variable of {}", lang.name())),
        }
    }

    /// Defines Sinumerik's local `name` of `kind`, at `v` (0 unless given).
    ///
    /// # Failures
    /// A name defined twice, or that is an R parameter's.
    pub fn define(&mut self, name: &str, kind: Kind, v: Real) -> Result<(), String> {
        if expr::r_number(name).is_some() {
            return Err(format!("DEF {name}: an R parameter's name"));
        }
        let locals = self.locals_mut();
        if locals.named.contains_key(name) {
            return Err(format!("DEF {name}: {name} is defined twice"));
        }
        locals.named.insert(name.to_owned(), (kind, 0.0));
        self.set(
            Language::Sinumerik,
            &Target::Named(name.to_owned()),
            Some(v),
        )
    }
}

/// What a line's statements do to the reading's course.
#[derive(Debug, Clone, PartialEq)]
pub enum Flow {
    /// On to the next line.
    Next,
    /// To line `n` of the file being read.
    Jump(usize),
    /// A call of a subprogram.
    Call(Call),
    /// Back from a subprogram (Fanuc's `M99 P n`: to block `N n` of the
    /// caller instead of the line after the call).
    Return(Option<u32>),
}

/// A subprogram called.
#[derive(Debug, Clone, PartialEq)]
pub struct Call {
    /// Which: a program by number or name, or a part of this file.
    pub what: Callee,
    /// How many times it runs (1: once).
    pub times: u64,
    /// rs274ngc's arguments, `#1`.. in the call.
    pub args: Vec<Real>,
}

/// What a call calls.
#[derive(Debug, Clone, PartialEq)]
pub enum Callee {
    /// Fanuc's `O` number (`M98 P1234`).
    Number(u32),
    /// A program by name: Sinumerik's `KONTUR`, `L10`; rs274ngc's
    /// `o<name>` (a file of that name beside the program).
    Name(String),
    /// rs274ngc's `oN sub` in the file being read, at its line.
    Sub(usize),
    /// Lines of the file being read, from the first up to before the
    /// second (Sinumerik's `REPEAT`).
    Section(usize, usize),
}

/// What is left of a line after its statements.
#[derive(Debug, Clone, PartialEq)]
pub enum Left {
    /// Nothing: the line was a statement (or a label) alone.
    Nothing,
    /// The line's own code, a plain block.
    Same,
    /// A block whose code is not the line's own (its expressions
    /// evaluated, its statements taken out).
    Code(String),
}

/// What a line's statements did: what is left for the block reader, and
/// where the reading goes on.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The block left.
    pub left: Left,
    /// Where the reading goes on.
    pub flow: Flow,
}

impl Step {
    /// A line done with (a statement alone).
    pub fn done(flow: Flow) -> Self {
        Self {
            left: Left::Nothing,
            flow,
        }
    }

    /// A block, evaluated where `evaluated` says, the reading going on.
    pub fn block(evaluated: Option<String>) -> Self {
        Self {
            left: evaluated.map_or(Left::Same, Left::Code),
            flow: Flow::Next,
        }
    }
}

/// What a line's statements need of the reading: the language, the index
/// of the file being read, the line's number in it.
pub struct Env<'x> {
    /// The language.
    pub lang: Language,
    /// The file being read.
    pub file: &'x dyn Landmarks,
    /// The line (from 0).
    pub line: usize,
    /// The unit of an axis value from a variable, where the control rounds
    /// it (Fanuc: its least input increment); `None`: not rounded.
    pub round_axes: Option<Real>,
    /// The axis letters (for the rounding).
    pub axes: &'x [char],
    /// Whether a call's repetitions stand in P before the program's
    /// number ([`crate::program::post::MacroReading::repeats_in_p`]).
    pub repeats_in_p: bool,
}

/// A file whose landmarks are found when first asked for (a plain
/// program never needs them).
pub trait Landmarks {
    /// The file's landmarks.
    ///
    /// # Failures
    /// Its structure broken (see [`Index::build`]), as a message naming
    /// the line.
    fn index(&self) -> Result<&Index, String>;
}

impl Env<'_> {
    /// The landmarks of the file being read.
    ///
    /// # Failures
    /// As [`Landmarks::index`].
    pub fn index(&self) -> Result<&Index, String> {
        self.file.index()
    }
}

/// Carries out line `code`'s statements (its comments blanked), from
/// `st`, in `env`: a variable set, a jump, a loop, a call; and gives the
/// block left, its expressions evaluated.
///
/// # Failures
/// A statement the language has not, or one the verification does not
/// carry out, named; a variable it cannot know; a bound passed.
pub fn step(env: &Env<'_>, st: &mut State, code: &str) -> Result<Step, String> {
    match env.lang {
        Language::Fanuc => fanuc::step(env, st, code),
        Language::Rs274 => rs274::step(env, st, code),
        Language::Sinumerik => sinumerik::step(env, st, code),
    }
}
