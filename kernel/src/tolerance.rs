//! The kernel's small tolerances, named by what they mean: each says why
//! its value. A comparison of computed reals uses one of these (or a
//! tolerance its caller passes in, which its docs bound); a bare literal
//! below 1e-3 outside a constant is refused by a test
//! (`tests/hygiene.rs`), so that the same meaning has one value and a
//! reader sees which meaning a comparison has.
//!
//! Lengths are in mm, angles in radians unless the name says degrees, as
//! everywhere in the kernel.

use crate::math::Real;

/// Two lengths (mm) within a picometre (1e-9 mm) are one length, and a
/// length below it is none (a vector that short has no direction): a
/// hundred-thousandth of the finest step a program is written in (0.1 um),
/// and far above the rounding of `f64` on any length the kernel meets
/// (2e-13 mm at 1 m).
pub const SAME_LENGTH: Real = 1e-9;

/// Two angles within 1e-9 (radians, or degrees where the values compared
/// are degrees: a table's stations) are one angle: 1e-9 rad moves a point
/// 1 m from the axis by a nanometre.
pub const SAME_ANGLE: Real = 1e-9;

/// Two dimensionless quantities (a ratio, a unit vector's component, a
/// length relative to the scale it is measured against) within 1e-9 are
/// one: a picometre per millimetre, [`SAME_LENGTH`] on the scale of 1.
pub const SAME_RATIO: Real = 1e-9;

/// A value compared with a limit exceeds it only beyond this share of the
/// limit: a value computed to be exactly at its limit (a feed from a
/// distance and a time, a spread against an uncertainty) carries the
/// rounding of its computation, which must not make it fail.
pub const LIMIT_SLACK: Real = 1e-9;

/// A quotient meant to be whole (a span over its step) is taken down by
/// this much before it is rounded up to a count: its rounding must not add
/// a step.
pub const COUNT_SLACK: Real = 1e-9;

/// The relative rounding of a computation of a few dozen `f64` operations
/// on quantities of order 1 (the precision of one is 2.2e-16): a change
/// or a difference below it is rounding, not a change.
pub const ROUNDING: Real = 1e-12;

/// An area (mm^2) below this is none: a sliver left between two polygons
/// by their vertices' rounding ([`ROUNDING`] on a section of a few mm).
pub const NO_AREA: Real = 1e-12;

/// A few units in the last place of `f64` near 1 (one is 2.2e-16): where a
/// value computed to be 1 (a cosine of two unit vectors), or an iteration
/// converged to its last bits, is told from one that is not.
pub const ULP: Real = 1e-15;

/// A floor for a divisor that may be zero: far below any quantity the
/// kernel divides by, far above the smallest normal `f64` (2.2e-308).
pub const TINY: Real = 1e-300;

/// The step of a central difference (in the unit of its variable, mm or
/// rad): its truncation error, of order the step squared (1e-12), and its
/// rounding, the precision over the step (1e-10), are both far below what
/// the derivative is checked against.
pub const DERIVATIVE_STEP: Real = 1e-6;
