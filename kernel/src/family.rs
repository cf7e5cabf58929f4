//! Part families (docs/architecture.md, the extension points): parameters to part geometry, toolpath
//! and checks. [`PartFamily`] is the extension point; the Rhai host
//! implements it for scripts ([`crate::script::ScriptFamily`]) and a family
//! may be written in Rust as well. [`crate::job`] runs any of them on a
//! machine.

pub use crate::chart::DrawError;
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

/// What a family's finished part must be, for the job's replay: a
/// request of the family's own kind ([`Verifier`]), which replays a
/// program and says what it found. The run knows no kind by name.
#[derive(Debug)]
pub struct Verification(Box<dyn Verifier>);

impl Verification {
    /// The verification `request` asks for.
    pub fn new(request: impl Verifier + 'static) -> Self {
        Self(Box::new(request))
    }

    /// What a measurement of the finished part holds and its nominal
    /// ([`Verifier::nominal`]).
    pub fn nominal(&self) -> Option<crate::compensate::Nominal> {
        self.0.nominal()
    }

    /// The request, as its own type (`None` if it is of another kind).
    pub fn request<T: 'static>(&self) -> Option<&T> {
        self.0.as_any().downcast_ref()
    }

    /// The axial-section request, if this is one.
    pub fn into_profile(self) -> Option<VerifyRequest> {
        self.request::<VerifyRequest>().cloned()
    }

    /// The verifier.
    pub fn verifier(&self) -> &dyn Verifier {
        self.0.as_ref()
    }
}

/// What a verification replays: the program as its control reads it, on
/// the machine the run uses, with the family's tool, in its passes.
#[derive(Clone, Copy)]
pub struct ReplayContext<'a> {
    /// The family's name, for messages.
    pub family: &'a str,
    /// The program, read as written.
    pub program: &'a crate::program::AxisProgram,
    /// The machine (its constants as the run set them).
    pub machine: &'a dyn crate::machine::MachineKinematics,
    /// The family's tool.
    pub tool: &'a crate::tool::Tool,
    /// The program's passes.
    pub passes: &'a [crate::program::ProgramPass],
}

/// A family's request for a verification of its own kind: the replay it
/// makes of a program.
pub trait Verifier: AnyVerifier + std::fmt::Debug {
    /// Replays `ctx`'s program: the outcome, and the material as the replay
    /// left it (for the process's rules), where it knows it.
    ///
    /// # Failures
    /// The replay failing; a tool of the wrong kind
    /// ([`crate::replay::VerifyError::Replay`], naming what it needs).
    fn verify(&self, ctx: &ReplayContext<'_>) -> Result<Verified, crate::replay::VerifyError>;

    /// What a measurement of the finished part holds and its nominal, if
    /// the family's part can be measured and corrected (`pilgrim
    /// compensate`); `None` by default.
    fn nominal(&self) -> Option<crate::compensate::Nominal> {
        None
    }

    /// What the request itself warns of, before any program (a nominal
    /// that strays from what its source gives); none by default.
    fn warnings(&self) -> Vec<crate::verdict::Finding> {
        Vec::new()
    }
}

/// A request as [`std::any::Any`], for callers that know its type: every
/// [`Verifier`] has it.
pub trait AnyVerifier {
    /// The request as [`std::any::Any`].
    fn as_any(&self) -> &dyn std::any::Any;
}

impl<T: Verifier + 'static> AnyVerifier for T {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// What a verification found and the material it knows.
pub struct Verified {
    /// Its outcome.
    pub outcome: Box<dyn Outcome>,
    /// The material after each pass, for the process's rules.
    pub stock: Option<Box<dyn crate::process::Stock>>,
    /// The part the replay left, pass by pass, for a family's own
    /// judgement of it, where the verification gives it.
    pub part: Option<Replayed>,
}

/// The part a replay left, pass by pass, in whole columns: what a
/// family's own judgement reads (a script's `judge`, one call with every
/// array, not a call per point).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Replayed {
    /// What the columns are (`radius over angle at z = 0 mm`), for the
    /// report.
    pub what: String,
    /// The passes, in order.
    pub passes: Vec<ReplayedPass>,
    /// How far (mm) the replay's last refinement moved what it found.
    pub sampling_change: f64,
}

/// One pass of a [`Replayed`] part.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReplayedPass {
    /// The pass's name.
    pub name: String,
    /// Its blocks in the program (from 0).
    pub blocks: std::ops::Range<usize>,
    /// Whether it cuts.
    pub cuts: bool,
    /// Its columns (name with unit, `radius_mm`, to values; every
    /// column of a pass is as long as the others; a block column holds
    /// indices from 0, -1 where no block cut).
    pub columns: std::collections::BTreeMap<String, Vec<f64>>,
}

/// The extra files of a verification: what it draws.
pub struct FilesContext<'a> {
    /// The replay's context.
    pub replay: ReplayContext<'a>,
    /// The part's bodies (of revolution, for the profile's picture).
    pub parts: &'a [PartBody],
    /// The correction's generation of a corrected run (`pilgrim
    /// compensate`), which its charts' titles say; `None` for a run of its
    /// own.
    pub corrected: Option<u32>,
}

impl FilesContext<'_> {
    /// A chart's title as this run's charts show it: `base`, and for a
    /// corrected run which correction drew it.
    pub fn title(&self, base: &str) -> String {
        crate::chart::titled(base, self.corrected)
    }
}

/// A verification's files (name, bytes: plots and tables, in order) and
/// the marks over its plots (by the plot's file name).
#[derive(Debug, Clone, Default)]
pub struct Drawn {
    /// The files.
    pub files: Vec<(String, Vec<u8>)>,
    /// The page's marks over its plots.
    pub marks: std::collections::BTreeMap<String, crate::chart::Marks>,
}

impl From<Vec<(String, Vec<u8>)>> for Drawn {
    fn from(files: Vec<(String, Vec<u8>)>) -> Self {
        Self {
            files,
            marks: Default::default(),
        }
    }
}

/// What a verification found, as the run uses it: figures and failures
/// for the verdict, its entry in the report, and its own files, bodies and
/// overlays.
pub trait Outcome: AnyOutcome + std::fmt::Debug + Send + Sync {
    /// Its key in `report.json` (one per kind: `verification`,
    /// `groove_verification`, ...): a plain name ending in `verification`,
    /// which no field of the report's own is.
    fn key(&self) -> &'static str;
    /// Its entry in `report.json`.
    ///
    /// # Failures
    /// The outcome not serialisable.
    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error>;
    /// The verdict's figures, and what failed, over `program` (as read).
    fn findings(
        &self,
        program: &crate::program::AxisProgram,
    ) -> (Vec<crate::verdict::Figure>, Vec<crate::verdict::Finding>);
    /// What the run's one-line summary says of it (from `, `).
    fn summary(&self) -> String;
    /// The outcome as [`std::any::Any`], for callers that know its type.
    /// A mesh to show at block `block` (from 0) in the scene, recording
    /// what it shows in the outcome (the caliber's contact patch).
    ///
    /// # Failures
    /// The replay failing at the block.
    fn at_pose(
        &mut self,
        _ctx: &ReplayContext<'_>,
        _block: usize,
    ) -> Result<Option<crate::mesh::TriMesh>, crate::replay::VerifyError> {
        Ok(None)
    }
    /// Bodies the verification made (the worm's finished solid), meshed
    /// within `mesh_tolerance`, their exact sections within
    /// `step_tolerance`.
    ///
    /// # Failures
    /// A body whose mesh fails.
    fn bodies(
        &self,
        _mesh_tolerance: f64,
        _step_tolerance: f64,
    ) -> Result<Vec<PartBody>, crate::mesh::SceneError> {
        Ok(Vec::new())
    }
    /// Whether its files come before the family's own charts (the worm's
    /// pass table and picture lead its page), else after them.
    fn leads_charts(&self) -> bool {
        false
    }
    /// Adds what the replay found to the family's tables (name to columns).
    fn extend_tables(
        &self,
        _tables: &mut std::collections::BTreeMap<
            String,
            std::collections::BTreeMap<String, Vec<f64>>,
        >,
    ) {
    }
    /// Its files (name, bytes): plots and tables, in order, and the
    /// page's marks over its plots.
    ///
    /// # Failures
    /// A file that cannot be drawn or written, said.
    fn files(
        &self,
        _ctx: &FilesContext<'_>,
        _tables: &std::collections::BTreeMap<String, std::collections::BTreeMap<String, Vec<f64>>>,
    ) -> Result<Drawn, DrawError> {
        Ok(Drawn::default())
    }
}

/// An outcome as [`std::any::Any`] (for [`crate::job::JobOutput::check`])
/// and boxed copies: every [`Outcome`] that is `Clone` has them.
pub trait AnyOutcome {
    /// The outcome as [`std::any::Any`], for callers that know its type.
    fn as_any(&self) -> &dyn std::any::Any;
    /// A copy.
    fn clone_box(&self) -> Box<dyn Outcome>;
}

impl<T: Outcome + Clone + 'static> AnyOutcome for T {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn clone_box(&self) -> Box<dyn Outcome> {
        Box::new(self.clone())
    }
}

impl Clone for Box<dyn Outcome> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

/// A kind's section of the report page: the HTML of its `report.json`
/// entry, given each block's label (from its index from 0).
pub type SectionFn = fn(&serde_json::Value, &dyn Fn(usize) -> String) -> Result<String, DrawError>;

/// A kind of verification as the report page shows it: its key in
/// `report.json` and the page's section drawn from that entry.
pub struct OutcomeKind {
    /// The key.
    pub key: &'static str,
    /// The section's HTML from the entry (`label`: a block's label, from
    /// its index from 0, as the program numbers it).
    pub section: SectionFn,
}

/// The geometry of one of a part's bodies.
#[derive(Debug, Clone)]
pub enum PartGeometry {
    /// A body of revolution about Z of this profile `x(z)`.
    Revolution(Profile),
    /// A body that is not of revolution: its closed mesh in the part frame
    /// and the exact body it was meshed from (for STEP).
    Swept(Box<Swept>),
}

/// A body swept through its sections, meshed and exact.
#[derive(Debug, Clone)]
pub struct Swept {
    /// Its closed mesh in the part frame (mm).
    pub mesh: TriMesh,
    /// The body itself.
    pub body: SweptBody,
}

/// A body swept through its sections, as the STEP writer fits it: what a
/// family's body that is not of revolution gives (the caliber's roll, a
/// finished worm).
pub trait SweptSolid: CloneSwept + std::fmt::Debug + Send + Sync {
    /// Its sections, as the STEP writer fits them.
    fn sections(&self) -> &dyn crate::step::Sections;
    /// How far (mm) its sections already stray from the body they stand
    /// for (a worm's outline simplified; 0 where they are exact).
    fn simplified(&self) -> crate::math::Real {
        0.0
    }
}

/// Boxed copies of a swept solid: every [`SweptSolid`] that is `Clone`
/// has them.
pub trait CloneSwept {
    /// A copy.
    fn clone_box(&self) -> Box<dyn SweptSolid>;
}

impl<T: SweptSolid + Clone + 'static> CloneSwept for T {
    fn clone_box(&self) -> Box<dyn SweptSolid> {
        Box::new(self.clone())
    }
}

/// A family's body swept through its sections.
#[derive(Debug)]
pub struct SweptBody(Box<dyn SweptSolid>);

impl SweptBody {
    /// The body `solid`.
    pub fn new(solid: impl SweptSolid + 'static) -> Self {
        Self(Box::new(solid))
    }

    /// Its sections, as the STEP writer fits them.
    pub fn sections(&self) -> &dyn crate::step::Sections {
        self.0.sections()
    }

    /// How far (mm) its sections already stray from the body they stand
    /// for.
    pub fn simplified(&self) -> crate::math::Real {
        self.0.simplified()
    }
}

impl Clone for SweptBody {
    fn clone(&self) -> Self {
        Self(self.0.clone_box())
    }
}

/// One named body of the part (`part`, `blank`, ...), for 3-D export.
#[derive(Debug, Clone)]
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
