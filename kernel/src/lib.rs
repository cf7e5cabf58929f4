//! # pilgrim-kernel
//!
//! The geometry kernel of pilgrim, a CAM system for special grinders and
//! lathes: cold-pilger mandrels and calibers, worm threads.
//!
//! - [`transform`]: elementary factors, the [`Chain`] of a machine, the
//!   universal 15-factor preset of seed 003, forward and inverse kinematics.
//! - [`machine`]: [`Machine`]s with axes, limits and chains, read from TOML;
//!   the machines of the seeds built in.
//! - [`profile`]: the [`Profile`] ("digital array"), its derivatives,
//!   curvature, smoothing and resampling; generators (the mandrel law,
//!   chained segments, the ellipse section); CSV and spreadsheet tables.
//! - [`offset`]: equidistants with the curvature check, the exact drop of a
//!   circle, the envelope of a swept circle, the steady-rest models.
//!
//! Conventions (ARCHITECTURE §3): right-handed frames, millimetres and
//! radians inside (degrees only in files, named `_deg`), the part frame's Z
//! along the part's axis and X radial. Every approximate operation takes its
//! tolerance as an argument. Every error names the value and its place.
//!
//! ```
//! use pilgrim_kernel::{equidistant, CircleEnvelope, MandrelLaw, Side};
//! // The wheel's rounding (R_s = 20 mm) rolled along a mandrel's working part
//! // leaves the profile back, up to the scallop between positions.
//! let law = MandrelLaw::new(40.0, 48.0, 300.0, 0.01, 2.5).unwrap();
//! let profile = law.profile(0.1, 0.0).unwrap();
//! let centres = equidistant(&profile, 20.0, Side::Outside).unwrap();
//! let env = CircleEnvelope::new(&centres.z, &centres.x, 20.0, Side::Outside).unwrap();
//! let dev = env.eval(150.05) - law.x(150.05);
//! assert!(dev >= -1e-9 && dev < 0.1 * 0.1 / (8.0 * 20.0) + 1e-5);
//! ```

pub mod error;
pub mod machine;
pub mod math;
pub mod mesh;
pub mod offset;
pub mod plugin;
pub mod profile;
pub mod program;
pub mod script;
pub mod tool;
pub mod toolpath;
pub mod transform;
pub mod verify;

pub use error::{Error, InputError};
pub use machine::{Axis, AxisKind, Machine, MachineError};
pub use math::{Mat3, Mat4, Point3, Real, Vec3};
pub use offset::{
    curvature_violations, drop_circle, equidistant, rest, CircleEnvelope, Drop, Equidistant, Side,
};
pub use profile::{
    read_table, read_table_str, uniform_grid, Bulge, CurvatureViolation, EllipseSection,
    MandrelLaw, Profile, ProfileBuilder, ProfileError, Smoothing, Table, TableError,
};
pub use program::{AxisProgram, Block, ChainMachine, MachineInfo, MachineKinematics, ProgramError};
pub use tool::{Tool, ToolShape, Wheel};
pub use toolpath::{ClPoint, Motion, Pass, Toolpath, ToolpathError};
pub use transform::{
    Chain, ChainBuilder, Factor, FactorKind, FactorValue, Frame, IkOptions, IkSolution, Pose,
    Target, ToolFrame, TransformError, UNIVERSAL_PARAMETERS,
};

/// The README's examples, compiled and run as doc tests.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;

/// The kernel's version, as in its `Cargo.toml`.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
