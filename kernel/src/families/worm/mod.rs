//! Worm threads cut in many passes on a CNC lathe (seed 004,
//! docs/math.md §4, with the corrections of issue 13): the cylindrical
//! worm's sizes in script (`Worm`: ZA, ZN or ZI, [`WormSizes`], the thread
//! module's, as a standard that gives a thread profile), the acceleration
//! and deceleration lengths S1 and S2, and its verification's map. A worm
//! is a thread: its plan, simulation, gauges, solid and workbook are the
//! thread family's ([`crate::families::thread`]).

mod script;

pub use crate::families::thread::{WormProfile, WormSizes};
pub(crate) use script::SCRIPT_API;

/// The family, as the registry carries it: its script API; its
/// verification is the thread's.
pub const FAMILY: super::Family = super::Family {
    name: "worm",
    kind: None,
    script: &[&SCRIPT_API],
};
