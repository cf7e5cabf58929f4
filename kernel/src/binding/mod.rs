//! What a script binding is made of, below every binding: the `Floats`
//! array type and its conversions, kernel errors as script errors, a tool's
//! checked number, where scripts may read files, and the group a binding
//! registers. The generic bindings (`crate::script`) and a family's own (in
//! its folder, listed in `crate::families`) both build on it; it names
//! neither.

pub(crate) mod floats;

pub use floats::Floats;

use crate::family::Verification;
use floats::kernel;
use rhai::{Engine, EvalAltResult, Map};
use std::path::PathBuf;

/// Where scripts may read files.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Access {
    /// Directories scripts may read tables from (and below).
    pub input_dirs: Vec<PathBuf>,
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
