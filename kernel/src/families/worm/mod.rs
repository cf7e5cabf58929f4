//! Worm threads cut in many passes on a CNC lathe (seed 004, docs/math.md §4, with
//! the corrections of issue 13).
//!
//! - [`WormSizes`] (the thread module's): the cylindrical worm, ZA, ZN or
//!   ZI, and its derived sizes (standard practice, not the seed's words);
//! - [`approach_length`], [`runout_length`] and their lead errors: the
//!   acceleration and deceleration lengths S1, S2 (Fanuc's exact form);
//! - [`ThreadCutter`]: the cutter's section, full-profile or universal;
//! - [`roughing_depths`], [`plan`]: the roughing law of decreasing infeed
//!   with its minimum depth, alternating flanks, finishing, the universal
//!   cutter's axial offset [`axial_offset`], every start;
//! - [`simulate`]: the program replayed in the axial section, pass by
//!   pass, with polygon booleans: chips, flank loads, the finished profile
//!   against the nominal;
//! - [`worm_solid`]: the finished worm as a closed mesh;
//! - [`worm_pass_workbook`]: the per-pass report as an Excel workbook.
//!
//! The part frame: Z along the worm's axis, the thread from z = 0 (the
//! face towards the tailstock) to z = -b1, cut towards the chuck (-Z); X
//! radial. The thread is right-handed.

mod outcome;
mod plan;
mod plots;
mod script;
mod servo;
mod simulate;
mod solid;
mod thread_script;
mod workbook;

pub use crate::blade::{cutter_outline, ThreadBlade, BLADE_RELIEF_DEG, BLADE_THICKNESS};
pub use crate::families::thread::{WormProfile, WormSizes};
pub use crate::tool::{ThreadCutter, ARC_TOLERANCE};
pub use outcome::{WormOutcome, KIND};
pub use plan::{
    axial_offset, plan, rational_passes, roughing_depths, Flank, FlankOrder, PassKind,
    PlanSettings, PlannedPass, MAX_PASSES,
};
pub use plots::{worm_pass_table, worm_passes_svg};
pub(crate) use script::SCRIPT_API;
pub use servo::{approach_error, approach_length, runout_error, runout_length};
pub use simulate::{
    simulate, SimulatedPass, StartProfile, WormCheck, WormRequest, WormStock, WormTolerances,
    LEAD_ERROR,
};
pub use solid::{worm_solid, WormSweep, MAX_AROUND};
pub(crate) use thread_script::SCRIPT_API as THREAD_SCRIPT_API;
pub use workbook::worm_pass_workbook;

/// The family, as the registry carries it.
pub const FAMILY: super::Family = super::Family {
    name: "worm",
    kind: Some(&KIND),
    script: &[&SCRIPT_API, &THREAD_SCRIPT_API],
};
