//! [`Error`]: any error of the kernel, one variant per stage, for callers
//! (the `pilgrim` program, a job) that do not care which stage failed. It
//! gathers the modules' own errors; no module below [`crate::job`] uses it,
//! so the modules' dependencies stay one-way.

use crate::catalog::CatalogError;
use crate::family::FamilyError;
use crate::input::InputError;
use crate::machine::MachineError;
use crate::mesh::MeshError;
use crate::mesh::SceneError;
use crate::params::ParamError;
use crate::plugin::PluginLoadError;
use crate::profile::{ProfileError, TableError};
use crate::program::{PostError, ProgramError};
use crate::replay::VerifyError;
use crate::transform::TransformError;

/// Any error of the kernel.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The run's time limit passed while this was being done.
    #[error(transparent)]
    OverTime(#[from] crate::budget::OverTime),
    /// A rejected input value.
    #[error(transparent)]
    Value(#[from] InputError),
    /// A transform chain or inverse kinematics failure.
    #[error(transparent)]
    Transform(#[from] TransformError),
    /// A machine description or limit failure.
    #[error(transparent)]
    Machine(#[from] MachineError),
    /// A machine that cannot be opened.
    #[error(transparent)]
    Catalog(#[from] CatalogError),
    /// A plugin that cannot be loaded.
    #[error(transparent)]
    Plugin(#[from] PluginLoadError),
    /// A profile, equidistant or envelope failure.
    #[error(transparent)]
    Profile(#[from] ProfileError),
    /// A table import failure.
    #[error(transparent)]
    Table(#[from] TableError),
    /// A measurement refused, or its correction.
    #[error(transparent)]
    Compensate(#[from] crate::compensate::CompensateError),
    /// A parameter that cannot be resolved.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// The part family's failure (a script's error, with its place).
    #[error(transparent)]
    Family(#[from] FamilyError),
    /// A toolpath that cannot become a program on the machine.
    #[error(transparent)]
    Program(#[from] ProgramError),
    /// A program that cannot be written.
    #[error(transparent)]
    Post(#[from] PostError),
    /// A written program that fails its lint (read back, it is not what
    /// the axis program says, or not what its dialect allows).
    #[error(transparent)]
    Lint(#[from] crate::program::lint::LintError),
    /// A machine whose control has no dialect.
    #[error("machine {machine}: unknown control '{control}'")]
    UnknownControl {
        /// The machine.
        machine: String,
        /// Its control.
        control: String,
    },
    /// The verification by replay.
    #[error(transparent)]
    Verify(#[from] VerifyError),
    /// A mesh.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// An exact solid (STEP).
    #[error(transparent)]
    Step(#[from] crate::step::StepError),
    /// The 3-D scene.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A part's body.
    #[error("{family}: {source}")]
    Part {
        /// The family.
        family: String,
        /// What failed.
        source: SceneError,
    },
    /// No machine was named, and the family names none.
    #[error(
        "{family}: no machine given: use --machine, or define fn default_machine() in the family"
    )]
    NoMachine {
        /// The family.
        family: String,
    },
    /// The collision check could not run (a chain or a program it cannot
    /// place the bodies by).
    #[error(transparent)]
    Collision(crate::collision::CollisionError),
    /// A block number of 0 given to an option that counts blocks from 1.
    #[error("{option} counts blocks from 1")]
    BlockFromOne {
        /// The option, by its flag.
        option: &'static str,
    },
    /// A finished run whose files cannot be used as the run left them.
    #[error(transparent)]
    Run(#[from] crate::output::RunError),
    /// A picture, a table or a report entry that cannot be drawn or
    /// written, named.
    #[error(transparent)]
    Draw(#[from] crate::family::DrawError),
    /// The run failed a check, a rule of the process or its verification:
    /// what it found, to write where the user looks (no program).
    #[error("{}", .0.report.verdict.message())]
    Failed(Box<crate::report::FailedRun>),
}

impl From<crate::output::OutputError> for Error {
    fn from(e: crate::output::OutputError) -> Self {
        Self::Run(e.into())
    }
}

impl From<crate::files::FileError> for Error {
    fn from(e: crate::files::FileError) -> Self {
        Self::Run(e.into())
    }
}

/// What the program says of a panic (a defect of pilgrim, never the user's
/// input): the panic's message quoted short with its control characters
/// escaped ([`crate::files::excerpt`]: a message may carry outside text),
/// where it happened, and what to do. The `pilgrim` program's panic hook
/// prints it instead of the default hook's raw text.
pub fn panic_text(
    payload: &(dyn std::any::Any + Send),
    location: Option<&std::panic::Location<'_>>,
) -> String {
    let message = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "no message".into());
    let at = location
        .map(|l| format!(" at {}:{}", l.file(), l.line()))
        .unwrap_or_default();
    format!(
        "internal error{at}: {} (a defect of pilgrim, not of your input: please report it with the command that gave it)",
        crate::files::excerpt(&message)
    )
}

#[cfg(test)]
mod tests {
    /// A panic's 800 KB message with escapes is quoted short and escaped.
    #[test]
    fn panics_are_quoted_short() {
        let text = format!("\u{1b}[31m{}", "x".repeat(800 << 10));
        let said = super::panic_text(&text, Some(std::panic::Location::caller()));
        assert!(said.len() < 400 && !said.contains('\u{1b}'), "{said}");
        assert!(
            said.contains("\\u{1b}[31mxxx") && said.contains("error.rs"),
            "{said}"
        );
    }
}
