//! What a script binding is made of, below every binding: the `Floats`
//! array type and its conversions, kernel errors as script errors, a tool's
//! checked number, where scripts may read files, and the group a binding
//! registers. The generic bindings (`crate::script`) and a family's own (in
//! its folder, listed in `crate::families`) both build on it; it names
//! neither.

pub(crate) mod floats;

pub use floats::Floats;

use crate::family::Verification;
use floats::{err, kernel};
use rhai::{Engine, EvalAltResult, Map};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Where scripts may read files.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Access {
    /// Directories scripts may read tables from (and below).
    pub input_dirs: Vec<PathBuf>,
    /// Tables given by the host, not read from a file: `(name, CSV
    /// text)`, found by `read_table(name)` before any directory (a
    /// correction `pilgrim compensate` made, written beside the run's
    /// files when the run succeeds).
    pub tables: Vec<(String, String)>,
    /// The files `read_table` read, for the run to keep beside its files
    /// ([`crate::job::Keep`]).
    pub read: ReadLog,
}

/// The files a script read its tables from, in the order read: a log
/// shared by the clones of an [`Access`] (equal whatever
/// it holds: it records, it does not configure).
#[derive(Debug, Clone, Default)]
pub struct ReadLog(Arc<Mutex<Vec<PathBuf>>>);

impl PartialEq for ReadLog {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Eq for ReadLog {}

impl ReadLog {
    /// Records `path` as read.
    pub fn record(&self, path: &Path) {
        if let Ok(mut v) = self.0.lock() {
            if !v.iter().any(|p| p == path) {
                v.push(path.to_owned());
            }
        }
    }

    /// The files read so far.
    pub fn paths(&self) -> Vec<PathBuf> {
        self.0.lock().map(|v| v.clone()).unwrap_or_default()
    }
}

/// A group of the script API: its heading, its types (by the names
/// scripts use) and its functions. A family with bindings of its own
/// keeps its group in its folder, listed in [`crate::families`].
pub(crate) struct ApiGroup {
    /// The reference's heading.
    pub title: &'static str,
    /// Registers the group's own types (none for most).
    pub types: fn(&mut Engine),
    /// Registers the group's functions.
    pub register: fn(&mut Engine, &Access),
    /// The family's verification, as its scripts ask for it.
    pub verify: Option<VerifyForm>,
}

/// How a family reads the map a script's `fn verify(p)` returns.
pub(crate) struct VerifyForm {
    /// The key that marks the family's map (`groove`, `worm`).
    pub key: &'static str,
    /// The map's form, for the message naming every form when a map fits
    /// none.
    pub form: &'static str,
    /// Every key the map may hold: another is refused, naming these.
    pub keys: &'static [&'static str],
    /// The request from the map: `Err(None)` for a map not of the form,
    /// `Err(Some(text))` saying what is wrong with one that is.
    pub read: fn(&Map) -> Result<Verification, Option<String>>,
}

/// A tool's number, its name checked first: the name reaches the program
/// ([`crate::names::check_name`]).
pub(crate) fn tool_number(name: &str, number: i64) -> Result<u32, Box<EvalAltResult>> {
    kernel(crate::names::check_name("tool name", name))?;
    u32::try_from(number).map_err(|_| format!("tool number {number} is out of range").into())
}

/// The wheel of a wheel tool.
pub(crate) fn wheel_of(tool: &crate::tool::Tool) -> Result<crate::tool::Wheel, Box<EvalAltResult>> {
    match tool.shape {
        crate::tool::ToolShape::Wheel(w) => Ok(w),
        _ => err(format!("tool '{}' is not a grinding wheel", tool.name)),
    }
}

// Earlier releases' forms (the script host's `compat` and a family's
// own) note their calls here; the run takes the warnings.
thread_local! {
    /// The old forms called since the last [`take_warnings`], each once.
    static CALLED: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

/// Notes that the old form `old` was called; `new` replaces it.
/// The date until which the script API's earlier forms are kept (each
/// listed in CHANGELOG.md with it).
pub const OLD_FORMS_UNTIL: &str = "2027-06-30";

pub(crate) fn deprecated(old: &str, new: &str) {
    let text = format!(
        "the script calls {old}, an earlier release's form: it still works, but use {new} (the old form is kept until {OLD_FORMS_UNTIL}; CHANGELOG.md)"
    );
    CALLED.with(|c| {
        let mut c = c.borrow_mut();
        if !c.contains(&text) {
            c.push(text);
        }
    });
}

/// The warnings for the old forms called since the last time, in the
/// order first called.
pub fn take_warnings() -> Vec<String> {
    CALLED.with(|c| std::mem::take(&mut *c.borrow_mut()))
}

/// An old form no longer callable: the error naming its replacement.
pub(crate) fn gone(old: &str, new: &str, why: &str) -> Box<EvalAltResult> {
    format!("{old} is an earlier release's form and no longer callable ({why}): use {new}").into()
}

/// The interpolation named `name` in a script, or the error naming the
/// accepted ones.
pub(crate) fn interpolation(
    name: &str,
) -> Result<crate::profile::Interpolation, Box<EvalAltResult>> {
    crate::profile::Interpolation::named(name).ok_or_else(|| {
        format!(
            "interpolation '{}' is none of {}",
            crate::files::excerpt(name),
            crate::profile::Interpolation::NAMES
        )
        .into()
    })
}
