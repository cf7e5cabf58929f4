//! Threads of any profile cut in many passes on a CNC lathe (seed 004,
//! docs/math.md §4): the profile as data ([`ThreadProfile`]: the axial
//! section with its limits) and the standards that give it ([`standards`]:
//! ISO metric, trapezoidal, ACME, buttress, straight pipe; [`WormSizes`]:
//! cylindrical worms, ZA, ZN and ZI), read from a drawing's designation
//! ([`designated`]); and the process every thread shares:
//!
//! - [`approach_length`], [`runout_length`] and their lead errors: the
//!   acceleration and deceleration lengths S1, S2 (Fanuc's exact form);
//! - [`ThreadCutter`]: the cutter's section, full-profile or universal;
//! - [`roughing_depths`], [`plan`]: the roughing law of decreasing infeed
//!   with its minimum depth, alternating flanks, finishing, the universal
//!   cutter's axial offset [`axial_offset`], every start;
//! - [`simulate`]: the program replayed in the axial section, pass by
//!   pass, with polygon booleans: chips, flank loads, the finished profile
//!   against the nominal, the gauges (pitch diameter, over wires);
//! - [`thread_solid`]: the finished thread as a closed mesh;
//! - [`pass_workbook`]: the per-pass report as an Excel workbook.
//!
//! The part frame: Z along the thread's axis, the thread from z = 0 (the
//! face towards the tailstock) to z = -b1, cut towards the chuck (-Z); X
//! radial.

mod designation;
pub mod iso965;
mod outcome;
mod plan;
mod plots;
mod profile;
pub(crate) mod script;
mod servo;
mod simulate;
mod solid;
pub mod standards;
pub mod tools;
pub mod wires;
mod workbook;
mod worm_sizes;

pub use crate::blade::{cutter_outline, ThreadBlade, BLADE_RELIEF_DEG, BLADE_THICKNESS};
pub use crate::tool::{ThreadCutter, ARC_TOLERANCE};
pub use designation::{designated, Drawing};
pub use outcome::{ThreadOutcome, KIND};
pub use plan::{
    axial_offset, plan, rational_passes, roughing_depths, Flank, FlankOrder, PassKind,
    PlanSettings, PlannedPass, MAX_PASSES,
};
pub use plots::{pass_table, passes_svg};
pub use profile::{Hand, Limits, ThreadLimits, ThreadProfile, ThreadSection};
pub(crate) use script::SCRIPT_API;
pub use servo::{approach_error, approach_length, runout_error, runout_length};
pub use simulate::{
    simulate, SimulatedPass, StartProfile, ThreadCheck, ThreadRequest, ThreadStock,
    ThreadTolerances, LEAD_ERROR,
};
pub use solid::{thread_solid, ThreadSweep, MAX_AROUND};
pub use workbook::pass_workbook;
pub use worm_sizes::{WormProfile, WormSizes};

/// The family, as the registry carries it: its verification (the key
/// `worm_verification`, as reports have carried it since the worm came
/// first) and its script API.
pub const FAMILY: super::Family = super::Family {
    name: "thread",
    kind: Some(&KIND),
    script: &[&SCRIPT_API],
};
