//! The families the kernel carries, each its folder here exporting one
//! [`Family`], registered by one line in [`FAMILIES`]. The run, the
//! report, the page and the script host know no family by name: they read
//! the registry. A family written outside the kernel needs no line: its
//! verification's figures reach the report and the page's verdict through
//! [`crate::family::Outcome`] (`tests/ring/`).

pub mod caliber;
pub mod revolution;
pub mod thread;
pub mod worm;

use crate::binding::ApiGroup;
use crate::family::OutcomeKind;

/// What a family carries into the kernel, in one value, which its folder
/// exports (`FAMILY`): everything else of it (its geometry, passes,
/// replay, plots, bodies, the nominal it is measured against, the
/// material the process's rules read) reaches the run through the
/// `Verifier` and `Outcome` its verification returns.
pub struct Family {
    /// Its name: its folder under `families/`.
    pub name: &'static str,
    /// Its own verification's kind (its key in `report.json` and its
    /// section of the page), if it has one.
    pub kind: Option<&'static OutcomeKind>,
    /// Its script API: its types, its functions and the map its scripts'
    /// `fn verify(p)` returns, listed in the reference after the generic
    /// groups (numbers, profiles, paths, equidistants) and before the
    /// transforms, tools and toolpaths.
    pub(crate) script: &'static [&'static ApiGroup],
}

/// Every family the kernel carries, one line each.
pub const FAMILIES: [&Family; 4] = [
    &revolution::FAMILY,
    &caliber::FAMILY,
    &worm::FAMILY,
    &thread::FAMILY,
];

/// Every kind of verification the kernel carries: the families' own, and
/// a family's judgement of its replayed part ([`crate::judged`]).
pub fn kinds() -> impl Iterator<Item = &'static OutcomeKind> {
    FAMILIES
        .into_iter()
        .filter_map(|f| f.kind)
        .chain([&crate::judged::KIND])
}

/// The families' script API groups, in the registry's order.
pub(crate) fn script_api() -> impl Iterator<Item = &'static ApiGroup> {
    FAMILIES.into_iter().flat_map(|f| f.script.iter().copied())
}

/// The kind whose report key is `key`.
pub fn kind(key: &str) -> Option<&'static OutcomeKind> {
    kinds().find(|k| k.key == key)
}
