//! The cut simulated pass by pass (issue 13 §2): the axis program, as
//! written, replayed in the worm's axial section. Every thread block cuts
//! the section at one place: the cutter's tip at the block's X, at the Z
//! where the helix it cuts crosses the section at part angle 0 (its start
//! Z shifted by the start angle's share of the lead). The cutter's section
//! (nose radii included) is subtracted from the blank's with a polygon
//! boolean crate (`geo`, whose `BooleanOps` is the `i_overlay` engine), not
//! hand-written clipping. From the simulation alone: each pass's chip
//! area and its share on each flank, any cut beyond the nominal space
//! (named by block), and the finished profile against the nominal ZA
//! axial profile: flank angles and form, thickness at the pitch line,
//! root and tip diameters, each start's position.
//!
//! An internal thread is cut as its external twin in rho = -r
//! ([`ThreadRequest::mirrored`]): its space opens towards the axis, so in
//! rho it opens outwards as an external thread's, and the results are
//! turned back (diameters positive, the measurement over wires one between
//! balls).
//!
//! The section is periodic along the axis with the lead: one lead is
//! simulated, from the middle of the thread before start 0's space, the
//! cutter placed with its copies one lead either side. What the model
//! leaves out: the servo's lag (the same on every pass at one spindle
//! speed, so it shifts the whole thread, not one pass), the approach and
//! run-out (checked to cover the thread's length), the cutter's clearance
//! angles and the lead angle's effect on the section (a ZA worm is cut with
//! the cutter in the axial plane), deflection and wear.

mod check;
mod cut;
mod gauge;
mod request;
mod section;
mod stock;
#[cfg(test)]
mod tests;

use crate::math::Real;
pub use check::{SimulatedPass, StartProfile, ThreadCheck};
pub use cut::simulate;
use gauge::{diameter, flank_radii, measure, mirrored_limits, nominal_flanks_deg};
pub use request::{ThreadRequest, ThreadTolerances, LEAD_ERROR};
use section::{
    edges, extreme_top, flipped, no_section, nominal_spaces, segment_distance, space_edges,
    thread_middle, vertical_top,
};
pub(super) use section::{poly, rect};
pub use stock::ThreadStock;

/// How far (mm) inside its ends a radial band is read, where the flanks
/// are defined on both sides: a nanometre.
const INSIDE: Real = 1e-6;
