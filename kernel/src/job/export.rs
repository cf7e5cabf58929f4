//! `pilgrim export DIR --block N`: a finished run's scene with the tool (and
//! the machine's other bodies) placed at another block.

use super::Report;
use crate::catalog::Catalog;
use crate::error::Error;
use crate::output::{RunDir, RunError};
use crate::program::AxisProgram;
use crate::render::scene::{self, Formats};
use crate::toolpath::Toolpath;

/// The most part bodies an export places (a family's part is a few
/// bodies; a report listing one body thousands of times is not a run's).
pub const MAX_PART_BODIES: usize = 64;

/// What an export made: the files to write over the run's, and the block.
#[derive(Debug, Clone)]
pub struct Exported {
    /// The files (name, bytes): the tool's and the machine bodies' STLs,
    /// the tool's STEP, `scene.glb` (and `.gltf`/`.bin` if asked),
    /// `report.html`, `report.json`.
    pub files: Vec<(String, Vec<u8>)>,
    /// The block (from 1) the scene is placed at.
    pub block: usize,
}

/// The machine to open for the finished run whose report is `report`
/// (`shown`: its directory, for messages): the one the command line names
/// (`given`), else the run's own if it is a built-in. A plugin or machine
/// file that only the run's files name is never opened.
///
/// # Failures
/// No `given` and a run on a machine that is not a built-in.
pub fn run_machine(
    report: &Report,
    catalog: &Catalog,
    given: Option<&str>,
    shown: &str,
) -> Result<String, Error> {
    match given {
        Some(m) => Ok(m.to_owned()),
        None if catalog
            .builtin_names()
            .iter()
            .any(|n| n.eq_ignore_ascii_case(&report.machine_spec)) =>
        {
            Ok(report.machine_spec.clone())
        }
        None => Err(RunError::MachineNotNamed {
            run: shown.to_owned(),
            machine: crate::files::excerpt(&report.machine_spec),
        }
        .into()),
    }
}

/// The scene of the run `run` placed at `block` (from 1; `None`: the
/// middle of the last cutting pass).
///
/// Nothing in the run's files is trusted: they are read only as the run
/// wrote them ([`RunDir::read`]: names its marker lists, no links), and
/// checked before any work: the toolpath as a run checks it, the program's
/// shape ([`crate::program::check_shape`]), the part bodies (plain names,
/// each once, at most `MAX_PART_BODIES`, their files the run's); the
/// machine is the built-in the report names, or the one the caller names
/// (`machine`, what the user gave on the command line): a plugin or a
/// machine file named only by the report is never opened.
///
/// # Failures
/// A file of the run missing or not what the run wrote; a run without 3-D
/// models; a report naming a machine that is not a built-in, with no
/// `machine` given; block 0; the machine or the replay failing.
pub fn export(
    run: &RunDir,
    catalog: &Catalog,
    machine: Option<&str>,
    block: Option<usize>,
    formats: Formats,
) -> Result<Exported, Error> {
    let shown = crate::files::shown_path(run.path());
    let Finished {
        mut report,
        program,
        toolpath,
    } = Finished::read(run, &shown)?;
    let machine = catalog.open(&run_machine(&report, catalog, machine, &shown)?)?;
    let kin = machine.kinematics.as_ref();
    let passes = crate::program::pass_blocks(&program, &toolpath.passes);
    let place = match block {
        Some(0) => return Err(Error::BlockFromOne { option: "--block" }),
        Some(n) => scene::PosePlace::at_end(n - 1),
        None => scene::default_pose_block(&program, &passes),
    };
    let parts = part_meshes(run, &report, &shown)?;
    let (text, as_read) = program_text(run, &report, &program, kin, &shown)?;
    // The scene moves as the run's did: the same program, timed as read.
    let times = crate::timing::times(
        as_read.as_ref().map_or(&program, |r| &r.program),
        kin.info(),
        &passes,
    );
    let placement = scene::placement(kin, &program, &toolpath, &parts)?;
    let staged = scene::stage(
        kin,
        &program,
        &toolpath.tool,
        (&parts, &placement),
        place,
        &times.block_s,
        vec![],
        (report.mesh_tolerance_mm, formats),
    )?;
    report.playback = staged.playback;
    report.pose_block = Some(place.block + 1);
    report.pose_along = place.along;
    report.bodies = staged.bodies;
    let mut all: Vec<(String, Vec<u8>)> = (staged.files.into_iter())
        .filter(|(n, _)| {
            n == "scene.glb" || !(report.bodies.iter()).any(|b| b.kind == "part" && &b.file == n)
        })
        .collect();
    // The tool's exact solid moves with it.
    let pose = staged.pose;
    let (tool_steps, tool_solids) =
        crate::render::solids::step_files(&[], &toolpath.tool, &pose, report.step_tolerance_mm)?;
    report.solids.retain(|s| s.kind != "tool");
    report.solids.extend(tool_solids);
    all.extend(tool_steps);
    let view = scene::bounds_of(parts.iter().map(|(_, m)| m))
        .map(|b| scene::contact_box(b, &toolpath.tool, &pose));
    if let Some(read) = as_read {
        report.program_lines = read.lines;
        report.program_expansions = read.expansions;
    }
    let html = page(run, &report, &all, text, view)?;
    all.push(("report.html".into(), html.into_bytes()));
    all.push(("report.json".into(), super::report_json(&report)?));
    Ok(Exported {
        files: all,
        block: place.block + 1,
    })
}

/// A finished run's report, program and toolpath, read and checked.
struct Finished {
    report: Report,
    program: AxisProgram,
    toolpath: Toolpath,
}

impl Finished {
    /// The run's files read as the run wrote them (`shown`: its directory,
    /// for messages) and checked: the program's shape, the toolpath, the
    /// part bodies (plain names, each once, at most [`MAX_PART_BODIES`]).
    ///
    /// # Failures
    /// A file missing or not as the run wrote it; a run without 3-D models.
    fn read(run: &RunDir, shown: &str) -> Result<Self, Error> {
        let bad = |name: &str, e: String| not_as_written(shown, name, &e);
        let report: Report = serde_json::from_str(&read(run, "report.json")?)
            .map_err(|e| bad("report.json", e.to_string()))?;
        let program: AxisProgram = serde_json::from_str(&read(run, "program.json")?)
            .map_err(|e| bad("program.json", e.to_string()))?;
        crate::program::check_shape(&program).map_err(|e| bad("program.json", e.to_string()))?;
        let toolpath: Toolpath = serde_json::from_str(&read(run, "toolpath.json")?)
            .map_err(|e| bad("toolpath.json", e.to_string()))?;
        (toolpath.validate()).map_err(|e| bad("toolpath.json", e.to_string()))?;
        let part_bodies: Vec<&scene::BodyFile> =
            report.bodies.iter().filter(|b| b.kind == "part").collect();
        if part_bodies.len() > MAX_PART_BODIES {
            return Err(bad(
                "report.json",
                format!(
                    "{} part bodies, more than the {MAX_PART_BODIES} an export places",
                    part_bodies.len()
                ),
            ));
        }
        for (i, b) in part_bodies.iter().enumerate() {
            if part_bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(bad(
                    "report.json",
                    format!("the body {} is listed twice", crate::names::quoted(&b.name)),
                ));
            }
        }
        if report.bodies.is_empty() {
            return Err(RunError::NoModels {
                run: shown.to_owned(),
            }
            .into());
        }
        Ok(Self {
            report,
            program,
            toolpath,
        })
    }
}

/// The run's file `name` (in `shown`) is not what the run wrote: `e`.
fn not_as_written(shown: &str, name: &str, e: &str) -> Error {
    RunError::NotAsWritten {
        file: format!("{shown}/{name}"),
        what: crate::files::excerpt(e),
    }
    .into()
}

/// The text of the run's file `name`.
fn read(run: &RunDir, name: &str) -> Result<String, Error> {
    run.read_text(name, crate::files::MAX_DATA_BYTES)
        .map_err(Error::from)
}

/// The part's meshes, from the run's own STL files by the names the run
/// gives them, together no larger than a data file.
///
/// # Failures
/// A body's file not the run's, unreadable or not an STL.
fn part_meshes(
    run: &RunDir,
    report: &Report,
    shown: &str,
) -> Result<Vec<(String, crate::mesh::TriMesh)>, Error> {
    let mut stl_bytes = 0u64;
    (report.bodies.iter().filter(|b| b.kind == "part"))
        .map(|b| {
            if !crate::files::is_plain_name(&b.name) || b.file != format!("{}.stl", b.name) {
                return Err(RunError::NotTheRunsFile {
                    run: shown.to_owned(),
                    file: crate::files::excerpt(&b.file),
                    body: crate::files::excerpt(&b.name),
                }
                .into());
            }
            let bytes = run
                .read(&b.file, crate::files::MAX_DATA_BYTES - stl_bytes)
                .map_err(Error::from)?;
            stl_bytes += bytes.len() as u64;
            crate::mesh::read_stl_bytes(&bytes, &format!("{shown}/{}", b.file))
                .map(|m| (b.name.clone(), m))
                .map_err(Error::from)
        })
        .collect()
}

/// A run's program file (name and text) and the program as read of it.
type ProgramText = (
    Option<(String, String)>,
    Option<crate::program::lint::TextProgram>,
);

/// The program's file (name and text) where the run wrote one, and the
/// program as its control reads it, which the run timed: a text that does
/// not read back as `program` is not the run's.
///
/// # Failures
/// A control pilgrim does not know; the text unreadable or not the
/// run's program.
fn program_text(
    run: &RunDir,
    report: &Report,
    program: &AxisProgram,
    kin: &dyn crate::machine::MachineKinematics,
    shown: &str,
) -> Result<ProgramText, Error> {
    let control =
        crate::program::post::dialect(&report.control).ok_or_else(|| RunError::UnknownControl {
            file: format!("{shown}/report.json"),
            control: crate::files::excerpt(&report.control),
        })?;
    let file = format!("program.{}", control.extension);
    if !report.files.contains(&file) {
        return Ok((None, None));
    }
    let text = read(run, &file)?;
    let as_read = crate::program::lint::lint_read(&text, program, control, &kin.info().axes)
        .map_err(|e| not_as_written(shown, &file, &e.to_string()))?;
    Ok((Some((file, text)), Some(as_read)))
}

/// The page of `report` with the new scene (in `files`), the run's plots
/// (those it names by plain names) and its program's `text`.
///
/// # Failures
/// A plot unreadable.
fn page(
    run: &RunDir,
    report: &Report,
    files: &[(String, Vec<u8>)],
    text: Option<(String, String)>,
    view: Option<([f64; 3], [f64; 3])>,
) -> Result<String, Error> {
    let plot = |n: &str| {
        n.strip_suffix(".svg")
            .is_some_and(crate::files::is_plain_name)
    };
    let mut shown: Vec<(String, Vec<u8>)> = Vec::new();
    for name in report.files.iter().filter(|n| plot(n)) {
        shown.push((name.clone(), read(run, name)?.into_bytes()));
    }
    let listed = text.map(|(file, text)| {
        shown.push((file.clone(), text.clone().into_bytes()));
        (file, text)
    });
    shown.extend(files.iter().filter(|f| f.0 == "scene.glb").cloned());
    let listed = listed.as_ref().map(|(f, t)| (f.as_str(), t.as_str()));
    Ok(crate::render::page::page_of(report, &shown, listed, view))
}
