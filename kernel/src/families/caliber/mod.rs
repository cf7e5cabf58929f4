//! The caliber's geometry (seed 001, docs/math.md §3): the groove of a cold-pilger
//! roll as a surface in 3-D, the scallop between passes, and the wheel's
//! pose on the groove, by the seed's model and exactly.
//!
//! - [`Groove`]: the roll of radius `R_d` with its groove, half an ellipse
//!   in each section (`B(theta)/2` wide, `Hp(theta)` deep, from tables),
//!   its edges sharp, rounded or chamfered into the periphery
//!   ([`GrooveSection`], [`Edge`]), its points and normals in the roll's
//!   frame;
//! - [`scallop_height`] and [`step_for_scallop`]: the cusp two neighbouring
//!   passes leave, and its inverse (docs/math.md §3.3); [`step_for_scallop_convex`]
//!   on an edge's rounding;
//! - [`seed_pose`]: the seed's wheel centre and corrections (docs/math.md §3.4);
//!   [`TorusWheel`] and [`exact_pose`]: the torus touching the groove at a
//!   point with its normal, and the distance of any point from it;
//! - [`pass_poses`]: a pass's exact poses at a uniform step of the roll's
//!   turn, within what the machine reaches ([`SwivelPlane`]); the
//!   [`step_over`] between passes;
//! - [`check_groove`]: the program replayed in 3-D against the groove,
//!   edge to edge, and the periphery beside it; the [`contact_patch`] at a
//!   block; [`GrooveStock`], the turned groove for the process's rules;
//! - [`caliber_solid`]: the roll's sector with its groove as a closed mesh;
//!   [`Roll`]: the same exactly, for STEP.
//!
//! The roll's frame: Z along the roll's axis, the section at `theta = 0` in
//! the XZ plane, `theta` turning right-handed about +Z (docs/architecture.md, conventions).

mod check;
mod grid;
mod groove;
mod outcome;
mod pass;
mod patch;
mod plots;
mod pose;
mod scallop;
mod script;
mod section;
mod solid;
mod stock;

pub use check::{
    check_groove, wheel_distance, DeviationMap, GrooveCheck, GrooveFailure, GroovePlace,
    GrooveRequest, MAP_CELLS, NEIGHBOUR_PASSES,
};
pub use groove::{Groove, GrooveError};
pub use outcome::{GrooveOutcome, KIND};
pub use pass::{pass_poses, pose_at, step_over, PassPose, SwivelPlane, MAX_PASS_BLOCKS};
pub use patch::{contact_patch, ContactPatch};
pub use plots::{deviation_map_svg, section_svg};
pub use pose::{exact_pose, exact_pose_toward, seed_pose, SeedPose, TorusWheel};
pub use scallop::{scallop_height, step_for_scallop, step_for_scallop_convex};
pub(crate) use script::SCRIPT_API;
pub use section::{Edge, EdgeKind, GrooveSection};
pub use solid::{caliber_solid, Roll, SolidError};
pub use stock::GrooveStock;

/// The family, as the registry carries it.
pub const FAMILY: super::Family = super::Family {
    name: "caliber",
    kind: Some(&KIND),
    script: &[&SCRIPT_API],
};
