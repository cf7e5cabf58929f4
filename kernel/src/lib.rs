//! # pilgrim-kernel
//!
//! The geometry kernel of pilgrim, a CAM system for special grinders and
//! lathes: cold-pilger mandrels and calibers, worm threads.
//!
//! The modules, in the order data flows through them (docs/architecture.md, the flow;
//! `docs/architecture.md` says where each stage lives):
//!
//! - [`math`], [`InputError`], [`files`], [`names`]: the numbers, the one
//!   validation error, reading outside files (regular files only,
//!   bounded), and the names and texts that come from outside;
//! - [`transform`]: elementary factors, the [`Chain`] of a machine, the
//!   universal 15-factor preset of seed 003, forward and inverse kinematics;
//! - [`machine`]: a machine's description ([`MachineInfo`], the plugin ABI's
//!   type), [`Machine`]s compiled from it or read from TOML, the
//!   [`MachineKinematics`] trait;
//! - [`profile`], [`offset`], [`tool`]: profiles ("digital arrays"),
//!   equidistants, envelopes, wheels and cutters;
//! - [`params`], [`family`]: a part family's parameters and the
//!   [`PartFamily`] trait;
//! - [`toolpath`] (CL data), [`program`] (the axis program and its
//!   post-processors), [`replay`] (the replays' machinery), [`mesh`] (3-D models),
//!   [`step`] (exact solids for CAD);
//! - the families, each in its folder with its geometry, verification,
//!   plots and script bindings: [`revolution`] (mandrels and other bodies
//!   of revolution ground with a wheel and a steady rest), [`caliber`],
//!   [`worm`];
//! - [`script`] (part families in Rhai), [`plugin`] (machine plugins),
//!   [`catalog`] (machines by name);
//! - [`job`]: a run as one call; [`Error`]: any stage's error.
//!
//! What only the run itself uses is private: the charts the plots share,
//! the report page's HTML, the report's tables and rows (their types are
//! public through [`job`]), the families' registry and the input checks
//! behind [`InputError`].
//!
//! Conventions (docs/architecture.md, conventions): right-handed frames, millimetres and
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

mod binding;
pub mod blade;
pub mod budget;
pub mod catalog;
mod chart;
pub mod collision;
pub mod compensate;
pub mod error;
pub mod families;
pub mod family;
pub mod files;
pub mod fits;
mod html;
mod input;
pub mod job;
pub mod judged;
pub mod machine;
pub mod math;
pub mod mesh;
pub mod names;
pub mod offset;
pub mod output;
pub mod params;
pub mod plugin;
pub mod process;
pub mod profile;
pub mod program;
pub mod render;
pub mod replay;
mod report;
pub mod script;
pub mod step;
pub mod timing;
pub mod tolerance;
pub mod tool;
pub mod toolpath;
pub mod transform;
pub mod verdict;
pub mod version;

pub use catalog::{Catalog, OpenMachine};
pub use error::Error;
pub use family::{Check, PartBody, PartFamily, PartGeometry, Verification, VerifyRequest};
pub use input::InputError;
pub use machine::{
    Axis, AxisKind, ChainMachine, Machine, MachineError, MachineInfo, MachineKinematics,
};
pub use math::{Mat3, Mat4, Point3, Real, Vec3};
pub use offset::{
    curvature_violations, drop_circle, equidistant, CircleEnvelope, Drop, Equidistant, Side,
};
pub use params::{ParamSource, ParamSpec, ParamValue, Params};
pub use profile::{
    read_table, read_table_str, uniform_grid, Bulge, CurvatureViolation, EllipseSection,
    Interpolation, MandrelLaw, Profile, ProfileBuilder, ProfileError, Smoothing, Table, TableError,
};
pub use program::{AxisProgram, Block, ProgramError};
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

pub use version::VERSION;
