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
mod constants;
mod export;
pub mod kept;
mod stages;

pub use crate::render::scene::{default_pose_block, BodyFile, Formats, PosePlace, SceneError};
pub use crate::render::solids::SolidFile;
use crate::render::{page, scene};
pub use crate::report::{axis_ranges, block_table, FailedRun, Report, ReportParam};
pub use compensate::{
    compensate, run_correction, CompensateOptions, Compensation, Place, ProgramChange, CORRECTION,
    CORRECTION_FILE,
};
pub use export::{export, run_machine, Exported};
pub use kept::{Keep, KeptInput};

use crate::catalog::OpenMachine;
use crate::error::Error;
use crate::family::{Outcome, PartFamily};
use crate::params::{ParamSource, ParamValue, Params};
use crate::program::post::{dialect, CLD};
use crate::program::AxisProgram;
use crate::toolpath::Toolpath;
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
    /// What the run keeps of its inputs beside its files, if it keeps them
    /// (`pilgrim run` and `compensate` do; [`kept`]).
    pub keep: Option<Keep>,
    /// The shop's offset table a verified program's tool and work offsets
    /// are read by (`--offsets`), if given.
    pub offsets: Option<crate::program::offsets::Offsets>,
    /// The folder a verified program's subprogram calls read their files
    /// from (the program file's own), if any: a file is named by the
    /// dialect's rule (`O1234.nc`, `KONTUR.SPF`, `name.ngc`), never by a
    /// path.
    pub program_dir: Option<std::path::PathBuf>,
    /// What corrected the run (`pilgrim compensate`), for its report, its
    /// page and its charts' titles; `None` for a run of its own.
    pub corrected_by: Option<CorrectedBy>,
}

/// What corrected a run: the correction's generation (its charts' titles
/// say it) and the sentence its report and page show.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CorrectedBy {
    /// 1 for the first correction of a program, 2 for its correction's.
    pub generation: u32,
    /// The generation, the run it corrects, the measurement, the gain and
    /// the uncertainty, in one sentence.
    pub said: String,
}

/// The tables a run keeps by name, each its columns by name.
pub use crate::judged::Tables;

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
            keep: None,
            offsets: None,
            program_dir: None,
            corrected_by: None,
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
        .map_err(|e| crate::family::DrawError::new("a JSON file", e).into())
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
    let value = serde_json::to_value(report)
        .map_err(|e| crate::family::DrawError::new("report.json", e))?;
    if let Some(at) = null_at(&value, "report") {
        return Err(crate::family::DrawError::new(
            "report.json",
            format!("{at} is not a finite number: the run's figures are out of range"),
        )
        .into());
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

/// The failed run of `report` with the `files` made so far: the page (it
/// lists `listed`, the user's program a verification read) and
/// `report.json` added.
fn failed_run(
    mut report: Report,
    mut files: Vec<(String, Vec<u8>)>,
    part_box: Option<([f64; 3], [f64; 3])>,
    listed: Option<(&str, &str)>,
) -> Error {
    report.files = files
        .iter()
        .map(|f| f.0.clone())
        .chain(["report.html".to_owned(), "report.json".to_owned()])
        .collect();
    let html = page::page_of(&report, &files, listed, part_box);
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
    restated: &[(String, String)],
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
            restated,
        },
    )
    .map_err(|e| match e {
        crate::collision::CollisionError::OverTime(o) => Error::OverTime(o),
        e => Error::Collision(e),
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
    let (mut values, mut came_from) =
        crate::params::resolve_traced(family.params(), &constants, sources)?;
    let control = &machine.kinematics.info().control;
    for s in family.params() {
        if s.machine.as_deref() != Some(crate::params::MACHINE_CONTROL) {
            continue;
        }
        let from = came_from.get(&s.name).cloned().unwrap_or_default();
        match values.get(&s.name) {
            Some(ParamValue::Text(t)) if t == control || from == crate::params::DEFAULT_SOURCE => {}
            Some(ParamValue::Text(t)) => {
                return Err(crate::params::ParamError::Bad {
                    name: s.name.clone(),
                    source_name: from,
                    message: format!(
                        "'{}' is not the machine's control ({control}): the parameter reads the machine's; choose the machine instead",
                        crate::files::excerpt(t)
                    ),
                }
                .into())
            }
            _ => {
                return Err(crate::params::ParamError::Bad {
                    name: s.name.clone(),
                    source_name: "the family".into(),
                    message: "a parameter that reads the machine's control must be text".into(),
                }
                .into())
            }
        }
        values.insert(s.name.clone(), ParamValue::Text(control.clone()));
        came_from.insert(s.name.clone(), "the machine's control".into());
    }
    Ok((values, came_from))
}

/// [`run`] of the program the run builds (`text` `None`), or [`verify`] of
/// `text`: the stages ([`stages`]) one after the other.
fn run_on(
    family: &dyn PartFamily,
    machine: &OpenMachine,
    sources: &[ParamSource],
    options: &JobOptions,
    stage: &mut dyn FnMut(&str),
    text: Option<&str>,
) -> Result<JobOutput, Error> {
    let (values, origins) = params_traced(family, machine, sources)?;
    let run = stages::Run {
        family,
        machine,
        values: &values,
        origins: &origins,
        options,
        text,
    };
    let staged = (|| {
        let plan = run.plan(stage)?;
        let mut made = match text {
            None => run.build(&plan, stage)?,
            Some(text) => run.read(&plan, text, stage)?,
        };
        let checked = run.check(&plan, &mut made)?;
        run.render(plan, made, checked, stage)
    })();
    run.stopped(staged)
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
