//! The course of a reading through its files: the program's own lines in
//! order, a jump, a loop's turn, a call into a subprogram (in the same
//! file, or a file beside the program the caller hands over), its return
//! and its repetitions. Each file's landmarks ([`macros::Index`]) are
//! found when a statement first needs them.

use super::{Reader, Standing};
use crate::program::lint::LintError;
use crate::program::macros::{self, Call, Callee, Flow, Frame, Index, Landmarks};
use crate::program::post::Dialect;
use std::cell::OnceCell;

/// Reads a file beside the program by its name: its text, `None` where
/// there is no such file (a path is never given: names only, so nothing
/// outside the program's folder is read).
pub type Beside<'a> = &'a dyn Fn(&str) -> Result<Option<String>, crate::files::FileError>;

/// The largest subprogram file read (bytes), as a program file.
pub const MAX_SUB_BYTES: usize = crate::files::MAX_TEXT_BYTES as usize;

/// One file of the reading: its name, its text by lines, its landmarks.
pub(crate) struct SourceFile<'a> {
    /// Its name (the program's own: empty).
    pub name: String,
    text: String,
    /// Where each line starts in `text`.
    starts: Vec<usize>,
    d: &'a Dialect,
    lang: Option<macros::Language>,
    index: OnceCell<Result<Index, String>>,
}

impl<'a> SourceFile<'a> {
    /// The file `name` of `lines` (a text split at its line feeds, the
    /// piece after the last taken off), in dialect `d`.
    pub fn new(name: String, lines: &[&str], d: &'a Dialect) -> Self {
        let mut text = String::with_capacity(lines.iter().map(|l| l.len() + 1).sum());
        let mut starts = Vec::with_capacity(lines.len() + 1);
        for l in lines {
            starts.push(text.len());
            text.push_str(l);
            text.push('\n');
        }
        starts.push(text.len());
        Self {
            name,
            text,
            starts,
            d,
            lang: d.reading.macros.map(|m| m.language),
            index: OnceCell::new(),
        }
    }

    /// Lines in the file.
    pub fn lines(&self) -> usize {
        self.starts.len() - 1
    }

    /// Line `i` (from 0).
    pub fn line(&self, i: usize) -> &str {
        &self.text[self.starts[i]..self.starts[i + 1] - 1]
    }
}

impl Landmarks for SourceFile<'_> {
    fn index(&self) -> Result<&Index, String> {
        let built = self.index.get_or_init(|| {
            let Some(lang) = self.lang else {
                return Err("the dialect has no statements".into());
            };
            let codes: Vec<String> = (0..self.lines())
                .map(|i| {
                    super::line::read_line(self.d, i, self.line(i), true)
                        .map(|(c, _)| c)
                        .unwrap_or_default()
                })
                .collect();
            Index::build(lang, codes.iter().map(String::as_str)).map_err(|(l, m)| {
                let file = if self.name.is_empty() {
                    String::new()
                } else {
                    format!(" of {}", self.name)
                };
                format!("the structure of the program{file} (line {}): {m}", l + 1)
            })
        });
        built.as_ref().map_err(Clone::clone)
    }
}

impl<'a> Reader<'a> {
    /// Where the reading goes on after line `i` by `flow`.
    ///
    /// # Failures
    /// A call nested past [`macros::MAX_CALL_DEPTH`], a subprogram not
    /// found, a return without a call, a bound passed.
    pub(super) fn follow(&mut self, at: &mut Standing, i: usize, flow: Flow) -> Result<(), String> {
        match flow {
            Flow::Next => at.next = i + 1,
            Flow::Jump(l) => at.next = l,
            Flow::Call(call) => self.call(at, i, call)?,
            Flow::Return(to) => self.back(at, to)?,
        }
        Ok(())
    }

    fn call(&mut self, at: &mut Standing, i: usize, call: Call) -> Result<(), String> {
        if at.mac.frames.len() >= macros::MAX_CALL_DEPTH {
            return Err(format!(
                "calls nested deeper than {} levels (a recursion without end?)",
                macros::MAX_CALL_DEPTH
            ));
        }
        let here = at.mac.file();
        let (file, entry, end) = match &call.what {
            Callee::Sub(line) => (here, line + 1, None),
            Callee::Section(from, to) => (here, *from, Some(*to)),
            Callee::Number(n) => self.program(here, *n)?,
            Callee::Name(name) => {
                let f = self.open(name, None)?;
                (f, 0, None)
            }
        };
        let mut locals = macros::Locals::default();
        locals.set_args(&call.args);
        at.mac.frames.push(Frame {
            file,
            entry,
            end,
            back: (here, i + 1),
            repeats: call.times - 1,
            locals,
        });
        at.next = entry;
        Ok(())
    }

    /// Fanuc's program `O n`: in the file being read, in the program's own,
    /// else a file beside it; its first line after its `O` line.
    fn program(&mut self, here: usize, n: u32) -> Result<(usize, usize, Option<usize>), String> {
        for f in [here, 0] {
            let ix = self.files[f].index()?;
            if let Some(l) = ix.programs.get(&n) {
                return Ok((f, l + 1, None));
            }
        }
        let f = self.open(&format!("{n}"), Some(n))?;
        let entry = (self.files[f].index()?.programs.get(&n)).map_or(0, |l| l + 1);
        Ok((f, entry, None))
    }

    /// The file a call names (`name`, or the program number `number`),
    /// opened beside the program by the dialect's file names; its index
    /// among the reading's files.
    fn open(&mut self, name: &str, number: Option<u32>) -> Result<usize, String> {
        let Some(m) = self.macros else {
            return Err("the dialect calls no subprograms".into());
        };
        let mut names: Vec<String> = Vec::new();
        for file in (m.files.iter()).map(|p| {
            let o = number.map_or(String::new(), |n| format!("{n:04}"));
            p.replace("{O}", &o)
                .replace("{N}", name)
                .replace("{NAME}", &name.to_ascii_uppercase())
                .replace("{name}", &name.to_ascii_lowercase())
        }) {
            if !names.contains(&file) {
                names.push(file);
            }
        }
        if let Some(k) = self.files.iter().position(|f| names.contains(&f.name)) {
            return Ok(k);
        }
        let shown = || names.join(", ");
        let Some(beside) = self.beside else {
            return Err(format!(
                "a call of {name}, whose file ({}) the verification was not given (a program's folder is read when the program is a file)",
                shown()
            ));
        };
        for file in &names {
            if let Some(text) = beside(file).map_err(|e| e.to_string())? {
                if self.files.len() > macros::MAX_FILES {
                    return Err(format!(
                        "more than {} subprogram files called",
                        macros::MAX_FILES
                    ));
                }
                if text.len() > MAX_SUB_BYTES {
                    return Err(format!(
                        "{file}: larger than {MAX_SUB_BYTES} bytes, the most a program file may be"
                    ));
                }
                let mut lines: Vec<&str> = text.split('\n').collect();
                if lines.last() == Some(&"") {
                    lines.pop();
                }
                let lines: Vec<&str> = lines
                    .iter()
                    .map(|l| l.strip_suffix('\r').unwrap_or(l))
                    .collect();
                self.files
                    .push(SourceFile::new(file.clone(), &lines, self.d));
                return Ok(self.files.len() - 1);
            }
        }
        Err(format!(
            "a call of {name}: no file {} beside the program",
            shown()
        ))
    }

    /// Back from the innermost call (to block `N to` of the caller, where
    /// given), or its next repetition.
    fn back(&mut self, at: &mut Standing, to: Option<u32>) -> Result<(), String> {
        let Some(top) = at.mac.frames.last_mut() else {
            return Err("a return without a call".into());
        };
        if top.repeats > 0 {
            top.repeats -= 1;
            top.locals = macros::Locals::default();
            let entry = top.entry;
            at.mac.turn()?;
            at.next = entry;
            return Ok(());
        }
        let Some(frame) = at.mac.frames.pop() else {
            return Err("a return without a call".into());
        };
        let (file, mut line) = frame.back;
        if let Some(n) = to {
            let ix = self.files[file].index()?;
            let within = ix.program_at(line.saturating_sub(1));
            line = ix.number(n, within, line, macros::Way::Around)?;
        }
        at.next = line;
        Ok(())
    }

    /// The next line to read, as `(file, line)`: `None` at the program's
    /// end. A section's call (Sinumerik's `REPEAT`) returns where its end
    /// is reached.
    ///
    /// # Failures
    /// A subprogram's file ending before its return.
    pub fn next_line(&mut self, at: &mut Standing) -> Result<Option<(usize, usize)>, LintError> {
        loop {
            if at.stopped {
                return Ok(None);
            }
            let file = at.mac.file();
            if let Some(end) = at.mac.frames.last().and_then(|f| f.end) {
                if at.next == end {
                    self.back(at, None).map_err(|m| self.fault(at.next, m))?;
                    continue;
                }
            }
            if at.next < self.files[file].lines() {
                return Ok(Some((file, at.next)));
            }
            if file == 0 && at.mac.frames.is_empty() {
                return Ok(None);
            }
            let name = &self.files[file].name;
            return Err(self.fault(
                self.files[file].lines().saturating_sub(1),
                format!(
                    "{} ends before its subprogram returns (M99, M17, RET or endsub)",
                    if name.is_empty() { "the program" } else { name }
                ),
            ));
        }
    }

    /// Line `i` of file `f`.
    pub fn text(&self, f: usize, i: usize) -> &str {
        self.files[f].line(i)
    }
}
