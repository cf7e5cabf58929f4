//! The families the kernel carries, registered once: each kind of
//! verification with its key in `report.json` and its section of the
//! report page. The run, the report and the page know no family by name;
//! a family with its own verification adds its line here (a family written
//! outside the kernel needs none: its verification's figures reach the
//! report and the page's verdict through [`crate::family::Outcome`]).

use crate::binding::ApiGroup;
use crate::family::OutcomeKind;

/// Every kind of verification the kernel carries.
pub const KINDS: [&OutcomeKind; 4] = [
    &crate::revolution::KIND,
    &crate::caliber::KIND,
    &crate::worm::KIND,
    &crate::judged::KIND,
];

/// The script API of the families that have their own, listed in the
/// reference after the generic groups (numbers, profiles, paths,
/// equidistants) and before the transforms, tools and toolpaths.
pub(crate) const SCRIPT_API: [&ApiGroup; 4] = [
    &crate::revolution::SCRIPT_API,
    &crate::caliber::SCRIPT_API,
    &crate::worm::SCRIPT_API,
    &crate::worm::THREAD_SCRIPT_API,
];

/// The kind whose report key is `key`.
pub fn kind(key: &str) -> Option<&'static OutcomeKind> {
    KINDS.into_iter().find(|k| k.key == key)
}
