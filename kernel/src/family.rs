//! Part families (ARCHITECTURE §4): parameters to part geometry, toolpath
//! and checks. [`PartFamily`] is the extension point; the Rhai host
//! implements it for scripts ([`crate::script::ScriptFamily`]) and a family
//! may be written in Rust as well. [`crate::job`] runs any of them on a
//! machine.

use crate::mesh::TriMesh;
use crate::params::{ParamSpec, Params};
use crate::profile::{Profile, ProfileError};
use crate::toolpath::{Toolpath, ToolpathError};
use serde::{Deserialize, Serialize};

/// The result of one of a family's checks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// What is checked.
    pub name: String,
    /// Whether it holds.
    pub ok: bool,
    /// Details (values, places).
    pub detail: String,
}

/// What a family's finished part must be, for a grinding job's replay: the
/// nominal profile in the axial section, held to `tolerance` over
/// `[from, to]`.
#[derive(Debug, Clone, PartialEq)]
pub struct VerifyRequest {
    /// The nominal profile.
    pub profile: Profile,
    /// Start of the range held to the tolerance (z, mm).
    pub from: f64,
    /// End of that range.
    pub to: f64,
    /// The tolerance (mm).
    pub tolerance: f64,
    /// The blank's profile, if the family gives it: the surface the first
    /// pass cuts into.
    pub blank: Option<Box<Profile>>,
}

/// What a family's finished part must be, for the job's replay.
#[derive(Debug, Clone, PartialEq)]
pub enum Verification {
    /// A body of revolution ground by a wheel: the axial section.
    Profile(VerifyRequest),
    /// A caliber's groove ground by a torus wheel, replayed in 3-D.
    Groove(Box<crate::caliber::GrooveRequest>),
    /// A worm's thread cut in passes, simulated in the axial section.
    Worm(Box<crate::worm::WormRequest>),
}

impl Verification {
    /// The axial-section request, if this is one.
    pub fn into_profile(self) -> Option<VerifyRequest> {
        match self {
            Self::Profile(v) => Some(v),
            Self::Groove(_) | Self::Worm(_) => None,
        }
    }
}

/// The geometry of one of a part's bodies.
#[derive(Debug, Clone, PartialEq)]
pub enum PartGeometry {
    /// A body of revolution about Z of this profile `x(z)`.
    Revolution(Profile),
    /// A body that is not of revolution: its closed mesh in the part frame
    /// and the exact body it was meshed from (for STEP).
    Swept(Box<Swept>),
}

/// A body swept through its sections, meshed and exact.
#[derive(Debug, Clone, PartialEq)]
pub struct Swept {
    /// Its closed mesh in the part frame (mm).
    pub mesh: TriMesh,
    /// The body itself.
    pub body: SweptBody,
}

/// The bodies swept through their sections that families make.
#[derive(Debug, Clone, PartialEq)]
pub enum SweptBody {
    /// The caliber's roll with its groove.
    Roll(Box<crate::caliber::Roll>),
    /// A finished worm.
    Worm(crate::worm::WormSweep),
}

impl SweptBody {
    /// Its sections, as the STEP writer fits them.
    pub fn sections(&self) -> &dyn crate::step::Sections {
        match self {
            Self::Roll(r) => r.as_ref(),
            Self::Worm(w) => w,
        }
    }

    /// How far (mm) its sections already stray from the body they stand
    /// for (a worm's outline simplified; 0 for the roll).
    pub fn simplified(&self) -> crate::math::Real {
        match self {
            Self::Roll(_) => 0.0,
            Self::Worm(w) => w.simplified(),
        }
    }
}

/// One named body of the part (`part`, `blank`, ...), for 3-D export.
#[derive(Debug, Clone, PartialEq)]
pub struct PartBody {
    /// Its name: a plain name (letters, digits, `_`, `-`), which becomes a
    /// file name.
    pub name: String,
    /// Its geometry.
    pub geometry: PartGeometry,
}

/// A family's failure, naming the family and the place.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FamilyError {
    /// The family's source could not be read.
    #[error("{file}: {message}")]
    Io {
        /// The file.
        file: String,
        /// The system's message.
        message: String,
    },
    /// An error at a place in the family's source (a script's line and
    /// column).
    #[error("{file}:{line}:{column}: {message}")]
    At {
        /// The source file.
        file: String,
        /// Line (from 1).
        line: usize,
        /// Column (from 1).
        column: usize,
        /// What went wrong.
        message: String,
    },
    /// A failure with no place in the source (a runaway script stopped, a
    /// native family's error).
    #[error("{family}: {message}")]
    Failed {
        /// The family (its file).
        family: String,
        /// What went wrong.
        message: String,
    },
    /// The family does not keep the contract (a function missing, a result
    /// of the wrong shape).
    #[error("{family}: {message}")]
    Contract {
        /// The family (its file).
        family: String,
        /// What is missing or wrong.
        message: String,
    },
    /// A native family's geometry failed.
    #[error("{family}: {source}")]
    Profile {
        /// The family.
        family: String,
        /// The kernel's error.
        source: ProfileError,
    },
    /// A native family's toolpath is bad.
    #[error("{family}: {source}")]
    Toolpath {
        /// The family.
        family: String,
        /// The kernel's error.
        source: ToolpathError,
    },
}

/// A part family: parameters to part geometry, toolpath and checks.
///
/// Only [`Self::name`], [`Self::params`] and [`Self::toolpath`] are
/// required; a family without [`Self::part`] has no 3-D models, one
/// without [`Self::verification`] is not replayed against a nominal.
pub trait PartFamily {
    /// The family's name in messages and reports (a script's file).
    fn name(&self) -> &str;

    /// Its parameters.
    fn params(&self) -> &[ParamSpec];

    /// The machine to use when none is named.
    ///
    /// # Failures
    /// The family's own.
    fn default_machine(&self) -> Result<Option<String>, FamilyError> {
        Ok(None)
    }

    /// Preconditions: a run stops, writing nothing, if one fails.
    ///
    /// # Failures
    /// The family's own.
    fn checks(&self, p: &Params) -> Result<Vec<Check>, FamilyError> {
        let _ = p;
        Ok(vec![])
    }

    /// The toolpath for the parameter values `p`.
    ///
    /// # Failures
    /// The family's own.
    fn toolpath(&self, p: &Params) -> Result<Toolpath, FamilyError>;

    /// The part's bodies for 3-D export; none (the default) if the family
    /// has no models, and then a run writes none.
    ///
    /// # Failures
    /// The family's own.
    fn part(&self, p: &Params) -> Result<Vec<PartBody>, FamilyError> {
        let _ = p;
        Ok(vec![])
    }

    /// What the finished part must be, if the job verifies it by replay.
    ///
    /// # Failures
    /// The family's own.
    fn verification(&self, p: &Params) -> Result<Option<Verification>, FamilyError> {
        let _ = p;
        Ok(None)
    }
}
