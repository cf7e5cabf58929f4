//! A run, as one kernel call (docs/architecture.md, the flow): a part family on a machine
//! with parameters, to every output.
//!
//! [`run`] resolves the parameters (the family's defaults, the machine's
//! constants, the caller's sources), runs the family's checks, builds the
//! toolpath, the axis program (inverse kinematics, travel and feed checks),
//! replays it against the family's nominal when the family asks, posts it
//! in the control's dialect and as a CL file, builds the 3-D scene and the
//! report, and returns them typed, with the bytes of every file
//! ([`JobOutput::files`]). It writes nothing: the caller decides where
//! (the `pilgrim` program writes them atomically). [`export`] places a
//! finished run's tool at another block.

mod compensate;
mod export;
pub mod kept;
mod page;
mod scene;
mod solids;
mod spin;

pub use crate::report::{axis_ranges, block_table, FailedRun, Report, ReportParam};
pub use compensate::{
    compensate, run_correction, CompensateOptions, Compensation, Place, ProgramChange, CORRECTION,
    CORRECTION_FILE,
};
pub use export::{export, run_machine, Exported};
pub use kept::{Keep, KeptInput};
pub use scene::{default_pose_block, BodyFile, Formats, PosePlace, SceneError};
pub use solids::SolidFile;

use crate::catalog::OpenMachine;
use crate::error::Error;
use crate::family::{FilesContext, Outcome, PartFamily, ReplayContext};
use crate::params::{ParamSource, ParamValue, Params};
use crate::program::post::{dialect, CLD};
use crate::program::{build, AxisProgram};
use crate::toolpath::Toolpath;
use crate::verdict::{Finding, Verdict};
use serde::Serialize;

/// How a run makes its outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct JobOptions {
    /// The program's name (letters, digits, `_`; others become `_`).
    pub program_name: String,
    /// The block (from 1) to place the tool at in the 3-D models; `None`:
    /// the middle of the last cutting pass.
    pub pose_block: Option<usize>,
    /// Chordal tolerance of the 3-D models (mm).
    pub mesh_tolerance: f64,
    /// Which 3-D files to write.
    pub formats: Formats,
    /// Largest deviation of a STEP solid's B-spline from the family's
    /// profile (mm).
    pub step_tolerance: f64,
    /// Dialects to write the program in besides the control's and the CL
    /// file (`linuxcnc`: `program.ngc`).
    pub also_post: Vec<String>,
    /// The program's number (Fanuc `O`): `Some` writes a whole program;
    /// `None` the block to paste after the tool call, where the dialect
    /// tells them apart (Fanuc).
    pub program_number: Option<u32>,
    /// The file the program [`verify`] reads came from, as messages show
    /// it: named in the report and on the page.
    pub program_file: Option<String>,
    /// Tables and charts the caller adds to the family's (a compensated
    /// run's measured error, its fit and the correction): in the report,
    /// drawn and shown on the page as the family's own.
    pub annex: Annex,
    /// What the run keeps of its inputs beside its files, if it keeps them
    /// (`pilgrim run` and `compensate` do; [`kept`]).
    pub keep: Option<Keep>,
    /// The shop's offset table a verified program's tool and work offsets
    /// are read by (`--offsets`), if given.
    pub offsets: Option<crate::program::offsets::Offsets>,
}

/// Tables and charts a run's caller adds ([`JobOptions::annex`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Annex {
    /// Tables by name (columns of equal length).
    pub tables: std::collections::BTreeMap<String, std::collections::BTreeMap<String, Vec<f64>>>,
    /// Charts of them.
    pub plots: Vec<crate::toolpath::PlotSpec>,
    /// Called with the run's tables once its verification has added to
    /// them, before anything is drawn: the caller's tables finished from
    /// what the run found (a compensated run's part after, from its own
    /// prediction; how far its program moved), and charts of them.
    pub finish: Option<TablesHook>,
}

/// The tables a run keeps by name, each its columns by name.
pub type Tables = std::collections::BTreeMap<String, std::collections::BTreeMap<String, Vec<f64>>>;

/// A caller's function over a run's tables, given its program and its
/// passes' blocks ([`Annex::finish`]): it may add to the tables and
/// returns charts of them to draw besides. Copies share it, and are equal
/// only to themselves.
#[derive(Clone)]
#[allow(clippy::type_complexity)]
pub struct TablesHook(
    pub  std::sync::Arc<
        dyn Fn(
                &mut Tables,
                &AxisProgram,
                &[crate::program::ProgramPass],
            ) -> Vec<crate::toolpath::PlotSpec>
            + Send
            + Sync,
    >,
);

impl std::fmt::Debug for TablesHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("TablesHook")
    }
}

impl PartialEq for TablesHook {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

impl Default for JobOptions {
    fn default() -> Self {
        Self {
            program_name: "pilgrim".into(),
            pose_block: None,
            mesh_tolerance: crate::mesh::DEFAULT_TOLERANCE,
            formats: Formats::default(),
            step_tolerance: crate::step::DEFAULT_TOLERANCE,
            also_post: Vec::new(),
            program_number: None,
            program_file: None,
            annex: Annex::default(),
            keep: None,
            offsets: None,
        }
    }
}

/// The stages of a run, in order, as [`run`] reports them.
pub const STAGES: [&str; 5] = [
    "checking",
    "computing the toolpath",
    "inverse kinematics and limits",
    "post-processing",
    "3-D models",
];

/// Everything a run made.
#[derive(Debug, Clone)]
pub struct JobOutput {
    /// The parameter values used.
    pub params: Params,
    /// The CL data.
    pub toolpath: Toolpath,
    /// The axis program.
    pub program: AxisProgram,
    /// What the family's verification found, if it asked for one (its
    /// own type: [`JobOutput::check`]).
    pub outcome: Option<Box<dyn Outcome>>,
    /// The report.
    pub report: Report,
    /// Every file's name and bytes, in the order they were made.
    pub files: Vec<(String, Vec<u8>)>,
}

/// What a run of a family that declares no verification says of its
/// program: nothing says it makes the part.
pub const NOT_VERIFIED: &str =
    "not verified: the family declares no verification (fn verify), so nothing says the program makes the part";

impl JobOutput {
    /// The verification's outcome as its own type (`None` if the family
    /// asked for none, or for one of another kind): e.g.
    /// `out.check::<GrindingOutcome>()` (the outcome type of the family's verification).
    pub fn check<T: 'static>(&self) -> Option<&T> {
        self.outcome.as_ref()?.as_any().downcast_ref()
    }

    /// One line saying what the run made: passes, blocks, machine, cycle
    /// time and the verified finish.
    pub fn summary(&self) -> String {
        let r = &self.report;
        let verified = self
            .outcome
            .as_ref()
            .map(|o| o.summary())
            .unwrap_or_default();
        let unverified = if r.verdict.status == crate::verdict::Status::NotVerified {
            format!("; {NOT_VERIFIED}")
        } else {
            String::new()
        };
        format!(
            "{}: {} cutting passes ({} in all), {} blocks for {} ({}), about {:.1} min{verified}{unverified}",
            r.script, r.cutting_passes, r.passes, r.blocks, r.machine, r.control, r.cycle_time_min,
        )
    }
}

fn json<T: Serialize>(v: &T) -> Result<Vec<u8>, Error> {
    serde_json::to_string_pretty(v)
        .map(|s| (s + "\n").into_bytes())
        .map_err(|e| Error::Output(e.to_string()))
}

/// The first place in `v` holding null: where JSON has put a number that
/// is not finite (NaN or infinite).
fn null_at(v: &serde_json::Value, path: &str) -> Option<String> {
    use serde_json::Value;
    match v {
        Value::Null => Some(path.to_owned()),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| null_at(x, &format!("{path}[{i}]"))),
        Value::Object(m) => m
            .iter()
            .find_map(|(k, x)| null_at(x, &format!("{path}.{k}"))),
        _ => None,
    }
}

/// The report as JSON, refused if any of its numbers is not finite.
fn report_json(report: &Report) -> Result<Vec<u8>, Error> {
    let value = serde_json::to_value(report).map_err(|e| Error::Output(e.to_string()))?;
    if let Some(at) = null_at(&value, "report") {
        return Err(Error::Output(format!(
            "{at} is not a finite number: the run's figures are out of range"
        )));
    }
    json(report)
}

/// Posts `program` in the control's dialect, as a CL file and in the
/// dialects `also` names, and lints each ([`crate::program::lint`]):
/// nothing is kept that does not read back as the axis program. The
/// programs as files (name, bytes) in that order, and the control's
/// program as its lint read it: what the run verifies.
fn post_all(
    machine: &OpenMachine,
    info: &crate::machine::MachineInfo,
    program: &AxisProgram,
    also: &[String],
) -> Result<(scene::Files, crate::program::lint::TextProgram), Error> {
    let control = dialect(&info.control).ok_or_else(|| Error::UnknownControl {
        machine: info.name.clone(),
        control: info.control.clone(),
    })?;
    let control_text = machine.post.post(program, control.name)?;
    // The control's text read back on a second thread while the CL file
    // is written and linted (the machine's post stays on this one).
    let (cld_text, read) = crate::budget::beside(
        || {
            let text = machine.post.post(program, CLD.name)?;
            crate::program::lint::lint(&text, program, &CLD, &info.axes)?;
            Ok::<_, Error>(text)
        },
        || crate::program::lint::lint_read(&control_text, program, control, &info.axes),
    );
    let (read, cld_text) = (read?, cld_text?);
    let mut files = vec![
        (
            format!("program.{}", control.extension),
            control_text.into_bytes(),
        ),
        ("program.cld".into(), cld_text.into_bytes()),
    ];
    for name in also {
        let d = dialect(name).ok_or_else(|| {
            Error::Post(crate::program::PostError::UnknownDialect { name: name.clone() })
        })?;
        if d.name == control.name || d.name == CLD.name {
            continue;
        }
        let text = machine.post.post(program, d.name)?;
        crate::program::lint::lint(&text, program, d, &info.axes)?;
        files.push((format!("program.{}", d.extension), text.into_bytes()));
    }
    Ok((files, read))
}

/// Enters the run's stage `name`, told to `stage`, once the run's deadline
/// allows: every stage starts within its time limit, so a run ends at most
/// one stage past it (the loops inside a stage check it too).
fn enter(stage: &mut dyn FnMut(&str), name: &'static str) -> Result<(), Error> {
    crate::budget::check(name)?;
    stage(name);
    Ok(())
}

/// The failed run of `report` with the `files` made so far: the page and
/// `report.json` added.
fn failed_run(
    mut report: Report,
    mut files: Vec<(String, Vec<u8>)>,
    part_box: Option<([f64; 3], [f64; 3])>,
) -> Error {
    report.files = files
        .iter()
        .map(|f| f.0.clone())
        .chain(["report.html".to_owned(), "report.json".to_owned()])
        .collect();
    let html = page::page_of(&report, &files, None, part_box);
    files.push(("report.html".into(), html.into_bytes()));
    match report_json(&report) {
        Ok(json) => files.push(("report.json".into(), json)),
        Err(e) => return e,
    }
    Error::Failed(Box::new(FailedRun { report, files }))
}

/// The collision check of `program` on `machine`, its bodies placed by
/// `placement`: the tool's solid at the mesh tolerance `tol` in its own
/// frame, the part at its largest (the body of `parts` of the greatest
/// volume).
///
/// # Failures
/// The tool's mesh failing; the check's own ([`crate::collision::check`]).
fn collisions(
    program: &AxisProgram,
    machine: &crate::machine::MachineInfo,
    placement: &crate::collision::Placement,
    tool: &crate::tool::Tool,
    parts: &[(String, crate::mesh::TriMesh)],
    tol: f64,
) -> Result<crate::collision::Collisions, Error> {
    let (written, _) = crate::replay::as_written(program);
    let unplaced = scene::ToolAt {
        pose: crate::math::Mat4::identity(),
        lead: 0.0,
        turn: 0.0,
    };
    let tool_mesh = scene::tool_mesh(tool, &unplaced, tol)?;
    let part = crate::collision::part_at_largest(parts);
    crate::collision::check(
        &written,
        machine,
        placement,
        crate::collision::Solids {
            tool: tool_mesh.as_ref().map(|(m, n)| (*n, tool, Some(m))),
            part,
            tolerance: tol,
        },
    )
    .map_err(|e| match e {
        crate::collision::CollisionError::OverTime(o) => Error::OverTime(o),
        e => Error::Collision(e.to_string()),
    })
}

/// The run's data files, made of the toolpath and the program alone:
/// `toolpath.json`, `program.json` and the block table `report.csv`.
fn data_files(toolpath: &Toolpath, program: &AxisProgram) -> Result<[Vec<u8>; 3], Error> {
    Ok([
        json(toolpath)?,
        json(program)?,
        block_table(program)?.into_bytes(),
    ])
}

/// Runs `family` on `machine` with the parameter `sources`; `stage` is
/// called as each stage begins (for progress).
///
/// # Failures
/// Any stage's error ([`Error`]): a parameter, a failed check (naming
/// them), the family's script, a block beyond travel, the verification, a
/// mesh.
pub fn run(
    family: &dyn PartFamily,
    machine: &OpenMachine,
    sources: &[ParamSource],
    options: &JobOptions,
    stage: &mut dyn FnMut(&str),
) -> Result<JobOutput, Error> {
    run_on(family, machine, sources, options, stage, None)
}

/// Verifies `text`, a program in the control's dialect of `machine`,
/// against `family` with the parameter `sources`: the text read as the
/// control reads it ([`crate::program::lint::read`]: a word it cannot
/// simulate is refused, naming it and its block), its passes as its
/// comments group its blocks, then the run's own verification, process
/// rules, plots, scene and report over it, as [`run`] verifies the program
/// it writes (the same call). The family gives the nominal and the tool;
/// the program is the text's. The files: the report and page, the plots,
/// the scene, `program.json` (the program as read) and `report.csv`; no
/// program.
///
/// # Failures
/// As [`run`]: a failed verification is [`Error::Failed`] with its report
/// naming the block as the text numbers it; a text the reader cannot
/// account for is [`Error::Lint`].
pub fn verify(
    family: &dyn PartFamily,
    machine: &OpenMachine,
    sources: &[ParamSource],
    text: &str,
    options: &JobOptions,
    stage: &mut dyn FnMut(&str),
) -> Result<JobOutput, Error> {
    run_on(family, machine, sources, options, stage, Some(text))
}

/// The parameter values of `sources` for `family` on `machine`, as a run
/// takes them. Parameters tied to machine constants default to this
/// machine's; set otherwise, they set the machine's for the whole run (its
/// chains, its bodies, the scene), so that the family and the machine
/// cannot differ. A parameter that restates where a machine body stands
/// takes its default from the machine's chain when no constant states it.
///
/// # Failures
/// A value refused ([`resolve`]); a body's place the machine cannot give.
pub fn params_on(
    family: &dyn PartFamily,
    machine: &OpenMachine,
    sources: &[ParamSource],
) -> Result<Params, Error> {
    params_traced(family, machine, sources).map(|(values, _)| values)
}

/// [`params_on`], and where each value came from
/// ([`crate::params::resolve_traced`]).
///
/// # Failures
/// As [`params_on`].
pub fn params_traced(
    family: &dyn PartFamily,
    machine: &OpenMachine,
    sources: &[ParamSource],
) -> Result<(Params, std::collections::BTreeMap<String, String>), Error> {
    let mut constants = machine.kinematics.info().constants.clone();
    for s in family.params() {
        if let (Some((body, along)), Some(c)) = (s.body_place(), &s.machine) {
            if !constants.contains_key(c) {
                if let Some(v) =
                    crate::machine::body_offset(machine.kinematics.info(), body, along)?
                {
                    constants.insert(c.clone(), v);
                }
            }
        }
    }
    Ok(crate::params::resolve_traced(
        family.params(),
        &constants,
        sources,
    )?)
}

/// [`run`] of the program the run builds (`text` `None`), or [`verify`] of
/// `text`.
fn run_on(
    family: &dyn PartFamily,
    machine: &OpenMachine,
    sources: &[ParamSource],
    options: &JobOptions,
    stage: &mut dyn FnMut(&str),
    text: Option<&str>,
) -> Result<JobOutput, Error> {
    let (values, origins) = params_traced(family, machine, sources)?;
    match run_with(family, machine, (&values, &origins), options, stage, text) {
        // A run stopped by its time limit after its inputs were read
        // leaves its report, FAILED, saying where it stopped.
        // (A caller's cancel asked for nothing more: no report.)
        Err(Error::OverTime(o)) if !o.cancelled => {
            let info = machine.kinematics.info();
            let mut report = Report::of_run(family, machine, info, (&values, &origins), Vec::new());
            report.program_file = text.and(options.program_file.clone());
            let message = format!("{o}; nothing was verified (give it more time: --run-seconds)");
            report.verdict = Verdict::of(
                true,
                vec![Finding::new("the run's time limit", message)],
                Vec::new(),
                Vec::new(),
            );
            Err(failed_run(report, Vec::new(), None))
        }
        other => other,
    }
}

/// [`run_on`] with the parameters' `values` and where each came from.
fn run_with(
    family: &dyn PartFamily,
    machine: &OpenMachine,
    (values, origins): (&Params, &std::collections::BTreeMap<String, String>),
    options: &JobOptions,
    stage: &mut dyn FnMut(&str),
    text: Option<&str>,
) -> Result<JobOutput, Error> {
    let overrides: Vec<(String, f64)> = family
        .params()
        .iter()
        .filter_map(|s| {
            let c = s.machine.as_ref()?;
            let have = *machine.kinematics.info().constants.get(c)?;
            let want = match &values[&s.name] {
                ParamValue::Bool(b) => f64::from(u8::from(*b)),
                v => v.as_number()?,
            };
            (want != have).then(|| (c.clone(), want))
        })
        .collect();
    let changed;
    let kin: &dyn crate::machine::MachineKinematics = if overrides.is_empty() {
        machine.kinematics.as_ref()
    } else {
        changed = machine.kinematics.with_constants(&overrides)?;
        changed.as_ref()
    };
    let info = kin.info();
    body_places_agree(family, machine.kinematics.info(), info, values)?;
    needed_axes_present(family, info, values)?;
    enter(stage, STAGES[0])?;
    let checks = family.checks(values)?;
    for c in &checks {
        for (what, t) in [("a check's name", &c.name), ("a check's detail", &c.detail)] {
            crate::names::check_text(what, t).map_err(|e| {
                Error::Family(crate::family::FamilyError::Contract {
                    family: family.name().to_owned(),
                    message: format!("fn checks(p): {e}"),
                })
            })?;
        }
    }
    let failed: Vec<Finding> = checks
        .iter()
        .filter(|c| !c.ok)
        .map(|c| {
            Finding::new(
                "the family's checks",
                format!("{}: check failed: {} ({})", family.name(), c.name, c.detail),
            )
        })
        .collect();
    if !failed.is_empty() {
        // Nothing to replay or draw: the report says which checks failed,
        // with every parameter.
        let mut report = Report::of_run(family, machine, info, (values, origins), checks);
        report.program_file = text.and(options.program_file.clone());
        report.verdict = Verdict::of(false, failed, Vec::new(), Vec::new());
        return Err(failed_run(report, Vec::new(), None));
    }
    enter(stage, STAGES[1])?;
    let mut toolpath = family.toolpath(values)?;
    toolpath.tables.extend(options.annex.tables.clone());
    toolpath.plots.extend(options.annex.plots.iter().cloned());
    enter(stage, STAGES[2])?;
    let control = dialect(&info.control).ok_or_else(|| Error::UnknownControl {
        machine: info.name.clone(),
        control: info.control.clone(),
    })?;
    // The program; the program the verification replays, where it is
    // not the program itself (the text a control reads, as the lint read
    // it back); its passes; the posted programs (or why none); the data
    // files.
    let (program, read_back, passes, posted, data, lines) = match text {
        None => {
            let mut program = build(&toolpath, kin, &options.program_name)?;
            program.number = options.program_number.unwrap_or(0);
            let passes = crate::program::pass_blocks(&program, &toolpath.passes);
            enter(stage, STAGES[3])?;
            // The data files need only the toolpath and the program: a
            // second thread writes them while this one posts and lints.
            let (posted, data) = crate::budget::beside(
                || post_all(machine, info, &program, &options.also_post),
                || data_files(&toolpath, &program),
            );
            let [toolpath_json, program_json, csv] = data?;
            let data = vec![
                ("toolpath.json".into(), toolpath_json),
                ("program.json".into(), program_json),
                ("report.csv".into(), csv),
            ];
            let (posted, read_back, lines) = match posted {
                Ok((files, read)) => (Ok(files), Some(read.program), read.lines),
                Err(e) => (Err(e), None, Vec::new()),
            };
            (program, read_back, passes, posted, data, lines)
        }
        Some(text) => {
            // A text the verification cannot take leaves its report: what
            // was refused and where, every parameter; nothing verified.
            let refused = |message: String| {
                let mut report =
                    Report::of_run(family, machine, info, (values, origins), checks.clone());
                report.program_file.clone_from(&options.program_file);
                report.verdict = Verdict::of(
                    true,
                    vec![Finding::new("the program's text", message)],
                    Vec::new(),
                    Vec::new(),
                );
                failed_run(report, Vec::new(), None)
            };
            let frame = crate::program::frame(info);
            let crate::program::lint::TextProgram {
                program: read,
                lines,
            } = crate::program::lint::read_with(
                text,
                &frame,
                control,
                &info.axes,
                options.offsets.as_ref(),
            )
            .map_err(|e| refused(e.to_string()))?;
            // No more blocks than a run writes: the replays' work is bounded.
            crate::program::check_shape(&read).map_err(|m| refused(format!("the program: {m}")))?;
            let passes = crate::replay::passes_in(&read, kin, &toolpath.tool.reference)
                .map_err(|e| refused(e.to_string()))?;
            enter(stage, STAGES[3])?;
            let data = vec![
                ("program.json".into(), json(&read)?),
                ("report.csv".into(), block_table(&read)?.into_bytes()),
            ];
            (read, None, passes, Ok(Vec::new()), data, lines)
        }
    };
    let verified = read_back.as_ref().unwrap_or(&program);
    let requested = family.verification(values)?;
    let requested_any = requested.is_some();
    if options.pose_block == Some(0) {
        return Err(Error::Options("--pose-block counts blocks from 1".into()));
    }
    let replay_ctx = ReplayContext {
        family: family.name(),
        program: verified,
        machine: kin,
        tool: &toolpath.tool,
        passes: &passes,
    };
    // The family's verification, of whatever kind: the replay of the
    // program as written, and the material as it left it.
    let contract = |e: crate::replay::VerifyError| match e {
        crate::replay::VerifyError::Contract(message) => {
            Error::Family(crate::family::FamilyError::Contract {
                family: family.name().to_owned(),
                message,
            })
        }
        e => e.into(),
    };
    let (mut outcome, stock) = match &requested {
        None => (None, None),
        Some(r) => {
            let v = r.verifier().verify(&replay_ctx).map_err(contract)?;
            (Some(v.outcome), v.stock)
        }
    };
    // What the verification found: its figures, and what failed.
    let mut figures = Vec::new();
    let mut failures = Vec::new();
    if let Some(o) = &outcome {
        let (f, x) = o.findings(verified);
        figures.extend(f);
        failures.extend(x);
    }
    let mut warnings: Vec<Finding> = toolpath
        .warnings
        .iter()
        .map(|w| Finding::new("the family", w.clone()))
        .collect();
    let mut parts = family.part(values)?;
    if let Some(b) = parts.iter().find(|b| !crate::files::is_plain_name(&b.name)) {
        return Err(Error::Family(crate::family::FamilyError::Contract {
            family: family.name().to_owned(),
            message: format!(
                "fn part(p): the body name '{}' is not a plain name (letters, digits, _ or -, at most 64): it becomes a file name",
                crate::files::excerpt(&b.name)
            ),
        }));
    }
    let tol = options.mesh_tolerance;
    // Bodies the verification made (the finished worm).
    if let Some(o) = &outcome {
        parts.extend(o.bodies(tol, options.step_tolerance)?);
    }
    let meshes = scene::part_meshes(&parts, tol).map_err(|source| Error::Part {
        family: family.name().to_owned(),
        source,
    })?;
    // One placement of the machine's bodies for the check and the scene.
    let placement = scene::placement(kin, &program, &toolpath.tool, &meshes)?;
    // The process, checked as well as the geometry; and, on a second
    // thread, the machine's bodies, the tool and the part clear of each
    // other along the whole program (neither reads the other).
    let (process, collisions) = crate::budget::beside(
        || {
            crate::process::check(
                verified,
                kin,
                &toolpath.tool.reference,
                stock.as_deref(),
                &crate::process::ProcessLimits::of(info),
            )
        },
        || collisions(verified, info, &placement, &toolpath.tool, &meshes, tol),
    );
    let (process, collisions) = (process?, collisions?);
    failures.extend(process.errors);
    warnings.extend(process.warnings);
    figures.extend(process.figures);
    if stock.is_none() {
        warnings.push(Finding::new(
            "the process",
            "the rules that need the material (rapids through air only, into the stock at the infeed feed, the steady rest's approach, the finishing stock) were not checked: the family's verification gives no blank",
        ));
    }
    failures.extend(collisions.findings.iter().cloned());
    // The scene shows the tool where asked; a failed run's, where it
    // failed; else the middle of the last cutting pass.
    let pose_place = match (
        options.pose_block,
        failures.iter().find_map(|f| f.block_index),
    ) {
        (Some(n), _) => scene::PosePlace::at_end(n - 1),
        (None, Some(b)) => scene::PosePlace::at_end(b - 1),
        (None, None) => default_pose_block(verified, &passes),
    };
    let pose_index = pose_place.block;
    // What the verification shows at the scene's block (the caliber's
    // contact patch: in the report, and its mesh in the scene).
    let overlay = match &mut outcome {
        Some(o) => o.at_pose(&replay_ctx, pose_index).map_err(contract)?,
        None => None,
    };
    // A run that failed writes no program a control could load.
    let programs = match posted {
        Ok(_) if !failures.is_empty() => Vec::new(),
        Ok(p) => p,
        // A program that does not read back as the axis program (a
        // plugin's own post, a block its dialect cannot write): no
        // program, the report says why.
        Err(e @ (Error::Lint(_) | Error::Post(_))) => {
            failures.push(Finding::new("the program's text", e.to_string()));
            Vec::new()
        }
        Err(e) => return Err(e),
    };
    // The data files in the order a run lists them: the programs after
    // the JSON files, the block table after the programs.
    let (table, mut files): (Vec<_>, Vec<_>) = data.into_iter().partition(|f| f.0 == "report.csv");
    files.extend(programs);
    files.extend(table);
    enter(stage, STAGES[4])?;
    // The times of the program as its control reads it (feeds and
    // positions as written), as every other check takes it.
    let times = crate::timing::times(verified, info, &passes);
    // The verification's own tables, then the caller's hook over them, on
    // a second thread while this one stages the scene and its solids
    // (neither reads the other).
    let mut tables = toolpath.tables.clone();
    if let Some(o) = &outcome {
        o.extend_tables(&mut tables);
    }
    let mut playback = Vec::new();
    let (scene, (tables, finishing_plots)) = crate::budget::beside(
        || -> Result<_, Error> {
            Ok(if parts.is_empty() {
                (None, vec![], vec![], None)
            } else {
                // The part's extent: the page's camera frames its contact
                // with the tool.
                let part_box = scene::bounds_of(meshes.iter().map(|(_, m)| m));
                let index = pose_index;
                let overlays = overlay
                    .map(|m| ("contact_patch".to_owned(), m, crate::math::Mat4::identity()))
                    .into_iter()
                    .collect();
                let staged = scene::stage(
                    kin,
                    &program,
                    &toolpath.tool,
                    (&meshes, &placement),
                    pose_place,
                    &times.block_s,
                    overlays,
                    (tol, options.formats),
                )?;
                let (mesh_files, bodies, pose) = (staged.files, staged.bodies, staged.pose);
                playback = staged.playback;
                files.extend(mesh_files);
                // A failed run's scene shows where it failed; its exact
                // solids, for checking a program in CAD, would check none.
                let solids = if failures.is_empty() {
                    let (step_files, solids) =
                        solids::step_files(&parts, &toolpath.tool, &pose, options.step_tolerance)?;
                    files.extend(step_files);
                    solids
                } else {
                    Vec::new()
                };
                (
                    Some(index + 1),
                    bodies,
                    solids,
                    part_box.map(|b| scene::contact_box(b, &toolpath.tool, &pose)),
                )
            })
        },
        || {
            let mut tables = tables;
            let plots = match &options.annex.finish {
                Some(finish) => (finish.0)(&mut tables, &program, &passes),
                None => Vec::new(),
            };
            (tables, plots)
        },
    );
    let (pose_block, bodies, solids, part_box) = scene?;
    let mut report = Report {
        passes: passes.len(),
        cutting_passes: passes.iter().filter(|p| p.cuts).count(),
        points: toolpath.point_count(),
        blocks: program.blocks.len(),
        cycle_time_min: (times.accelerated_min * 1e4).round() / 1e4,
        files: files
            .iter()
            .map(|f| f.0.clone())
            .chain(["report.json".to_owned()])
            .collect(),
        pose_block,
        pose_along: pose_block.map_or(1.0, |_| pose_place.along),
        mesh_tolerance_mm: tol,
        bodies,
        step_tolerance_mm: options.step_tolerance,
        solids,
        axis_ranges: axis_ranges(&program),
        verifications: match &outcome {
            Some(o) => {
                // Its entry sits among the report's own fields: a key that
                // names a verification cannot be one of them.
                let key = o.key();
                if !(key.ends_with("verification") && crate::files::is_plain_name(key)) {
                    return Err(Error::Family(crate::family::FamilyError::Contract {
                        family: family.name().to_owned(),
                        message: format!(
                            "its verification's report key {} must be a plain name ending in 'verification'",
                            crate::names::quoted(key)
                        ),
                    }));
                }
                std::iter::once((
                    key.to_owned(),
                    o.to_json()
                        .map_err(|e| crate::family::DrawError::new(key, e))?,
                ))
                .collect()
            }
            None => Default::default(),
        },
        warnings: toolpath.warnings.clone(),
        notes: toolpath.notes.clone(),
        tables,
        verdict: Verdict::of(requested_any, failures, warnings, figures),
        collisions: Some(collisions),
        times: Some(times),
        playback,
        program_file: text.and(options.program_file.clone()),
        program_lines: lines,
        block_numbers: program
            .blocks
            .iter()
            .map(|b| b.number)
            .collect::<Option<Vec<u32>>>()
            .unwrap_or_default(),
        ..Report::of_run(family, machine, info, (values, origins), checks)
    };
    // The verification's own files: the tables it adds to, then its
    // plots (before the family's charts where it leads them, else after).
    let mut later = Vec::new();
    if let Some(o) = &outcome {
        let ctx = FilesContext {
            replay: replay_ctx,
            parts: &parts,
        };
        let crate::family::Drawn { files: made, marks } = o.files(&ctx, &report.tables)?;
        // Marks over a plot it drew, by the plot's name.
        report.marks = marks
            .into_iter()
            .filter(|(name, _)| name.ends_with(".svg") && made.iter().any(|f| &f.0 == name))
            .collect();
        // A verification draws and tabulates; the programs, the report and
        // the data files are the run's own, and every name is a file's.
        if let Some((name, _)) = made.iter().find(|(n, _)| {
            !crate::output::is_plain_file_name(n)
                || n.starts_with("program.")
                || n.starts_with("report.")
                || files.iter().any(|f| &f.0 == n)
        }) {
            return Err(Error::Family(crate::family::FamilyError::Contract {
                family: family.name().to_owned(),
                message: format!(
                    "its verification's file {} is not a name it may write: the programs, the report and the data files are the run's own",
                    crate::names::quoted(name)
                ),
            }));
        }
        if o.leads_charts() {
            for (name, bytes) in made {
                report.files.push(name.clone());
                files.push((name, bytes));
            }
        } else {
            later = made;
        }
    }
    let charted = Toolpath {
        tables: report.tables.clone(),
        ..toolpath.clone()
    };
    for plot in toolpath.plots.iter().chain(&finishing_plots) {
        let text = crate::chart::chart_svg(&charted, plot).map_err(|message| {
            Error::Family(crate::family::FamilyError::Contract {
                family: family.name().to_owned(),
                message,
            })
        })?;
        let name = format!("{}.svg", plot.file);
        if files.iter().chain(&later).any(|f| f.0 == name) {
            return Err(Error::Family(crate::family::FamilyError::Contract {
                family: family.name().to_owned(),
                message: format!("plot {}: a file of that name is written already", plot.file),
            }));
        }
        files.push((name.clone(), text.into_bytes()));
        report.files.push(name);
    }
    for (name, bytes) in later {
        report.files.push(name.clone());
        files.push((name, bytes));
    }
    crate::budget::check("the report")?;
    if let Some(keep) = &options.keep {
        let taken: Vec<String> = (report.files.iter().cloned())
            .chain(["report.html".into(), "report.json".into()])
            .collect();
        for (input, bytes) in kept::inputs(keep, &machine.origin, &taken)? {
            if input.role != "plugin" {
                report.files.push(input.file.clone());
                files.push((input.file.clone(), bytes));
            }
            report.inputs.push(input);
        }
    }
    if report.verdict.failed() {
        return Err(failed_run(report, files, part_box));
    }
    report.files.push("report.html".into());
    // The page lists the program the run wrote, or the file it verified.
    let listed = match (text, &options.program_file) {
        (Some(text), Some(file)) => Some((file.as_str(), text)),
        _ => page::written_program(&files, control.extension),
    };
    let html = page::page_of(&report, &files, listed, part_box);
    files.push(("report.html".into(), html.into_bytes()));
    files.push(("report.json".into(), report_json(&report)?));
    Ok(JobOutput {
        params: values.clone(),
        toolpath,
        program,
        outcome,
        report,
        files,
    })
}

/// Checks that the machine has every axis a parameter's value needs
/// ([`crate::params::ParamSpec::needs_axis`]): a mode the machine cannot
/// run is refused before any planning, naming the parameter, the axis and
/// the machine's axes.
///
/// # Failures
/// [`crate::machine::MachineError::Description`].
fn needed_axes_present(
    family: &dyn PartFamily,
    info: &crate::machine::MachineInfo,
    values: &Params,
) -> Result<(), Error> {
    for s in family.params() {
        let Some(axis) = &s.needs_axis else { continue };
        if values.get(&s.name) != Some(&ParamValue::Bool(true))
            || info.axes.iter().any(|a| &a.name == axis)
        {
            continue;
        }
        let has: Vec<&str> = info.axes.iter().map(|a| a.name.as_str()).collect();
        return Err(crate::machine::MachineError::Description {
            machine: info.name.clone(),
            message: format!(
                "family {}'s parameter {} = true needs the machine's axis {axis}, which {} has not (its axes: {}): set {} = false, or run it on a machine with {axis}",
                family.name(),
                s.name,
                info.name,
                has.join(", "),
                s.name
            ),
        }
        .into());
    }
    Ok(())
}

/// Checks every parameter that restates a machine body's place against the
/// machine's chain as the run uses it (`used`, its constants set from the
/// parameters): the chain is what the verification moves, so a constant
/// or a value it contradicts is refused, naming both. `given` is the
/// machine as opened, to say whether the value came from its constant.
///
/// # Failures
/// [`crate::machine::MachineError::Description`] naming the parameter or
/// constant, the body and the chain's value.
fn body_places_agree(
    family: &dyn PartFamily,
    given: &crate::machine::MachineInfo,
    used: &crate::machine::MachineInfo,
    values: &Params,
) -> Result<(), Error> {
    for s in family.params() {
        let Some((body, along)) = s.body_place() else {
            continue;
        };
        let axis = ["x", "y", "z"][along];
        let Some(chain) = crate::machine::body_offset(used, body, along)? else {
            return Err(crate::machine::MachineError::Description {
                machine: used.name.clone(),
                message: format!(
                    "family {} places its parameter {} at the body {body}, which this machine does not have",
                    family.name(),
                    s.name
                ),
            }
            .into());
        };
        let Some(value) = values.get(&s.name).and_then(ParamValue::as_number) else {
            continue;
        };
        if (value - chain).abs() <= crate::tolerance::SAME_RATIO * chain.abs().max(1.0) {
            continue;
        }
        let constant = s
            .machine
            .as_ref()
            .and_then(|c| given.constants.get(c).map(|v| (c, *v)));
        let from_constant = matches!(constant, Some((_, v)) if v == value);
        let said = match constant {
            Some((c, _)) if from_constant => format!("its constant {c} = {value} mm"),
            _ => format!("parameter {} = {value} mm", s.name),
        };
        let take = s.machine.as_ref().map_or_else(
            || "change the machine's chain".to_owned(),
            |c| format!("make the chain take the constant (a factor with constant = \"{c}\")"),
        );
        let fix = if from_constant {
            format!("{take}, or leave the constant out and the run takes the chain's")
        } else {
            format!("leave {} unset (the run takes the chain's), or {take} so that setting it moves the body", s.name)
        };
        return Err(crate::machine::MachineError::Description {
            machine: used.name.clone(),
            message: format!(
                "{said} disagrees with its chain of body {body}, which puts it at {chain} mm along {axis} from the tool (every axis at zero); the chain is what the verification moves: {fix}"
            ),
        }
        .into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A number JSON cannot hold (NaN, infinity) is found, with its place.
    #[test]
    fn non_finite_numbers_are_found() {
        let v = serde_json::json!({"a": 1.0, "notes": {"x": f64::NAN}});
        assert_eq!(null_at(&v, "report"), Some("report.notes.x".into()));
        assert_eq!(null_at(&serde_json::json!({"a": [1, 2]}), "r"), None);
    }
}
