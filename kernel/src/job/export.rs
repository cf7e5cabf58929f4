//! `pilgrim export DIR --block N`: a finished run's scene with the tool (and
//! the machine's other bodies) placed at another block.

use super::Report;
use crate::catalog::Catalog;
use crate::error::Error;
use crate::output::RunDir;
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
        None => Err(Error::Read(format!(
            "{shown}: the run's machine '{}' is not a built-in: name it with --machine (pilgrim loads a plugin or machine file only when the command line names it)",
            crate::files::excerpt(&report.machine_spec)
        ))),
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
    let dir = run.path();
    let shown = crate::files::shown_path(dir);
    let read = |name: &str| {
        run.read_text(name, crate::files::MAX_DATA_BYTES)
            .map_err(|e| Error::Read(e.to_string()))
    };
    let bad = |name: &str, e: String| {
        Error::Read(format!(
            "{shown}/{name}: {} (not as the run wrote it)",
            crate::files::excerpt(&e)
        ))
    };
    let mut report: Report = serde_json::from_str(&read("report.json")?)
        .map_err(|e| bad("report.json", e.to_string()))?;
    let program: AxisProgram = serde_json::from_str(&read("program.json")?)
        .map_err(|e| bad("program.json", e.to_string()))?;
    crate::program::check_shape(&program).map_err(|e| bad("program.json", e.to_string()))?;
    let toolpath: Toolpath = serde_json::from_str(&read("toolpath.json")?)
        .map_err(|e| bad("toolpath.json", e.to_string()))?;
    toolpath
        .validate()
        .map_err(|e| bad("toolpath.json", e.to_string()))?;
    let part_bodies: Vec<&crate::render::scene::BodyFile> =
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
        return Err(Error::Read(format!(
            "{shown}: the run has no 3-D models (its family has no fn part(p))"
        )));
    }
    let machine = catalog.open(&run_machine(&report, catalog, machine, &shown)?)?;
    let kin = machine.kinematics.as_ref();
    let place = match block {
        Some(0) => return Err(Error::Options("--block counts blocks from 1".into())),
        Some(n) => scene::PosePlace::at_end(n - 1),
        None => scene::default_pose_block(
            &program,
            &crate::program::pass_blocks(&program, &toolpath.passes),
        ),
    };
    let index = place.block;
    let mut stl_bytes = 0u64;
    let parts = part_bodies
        .iter()
        .map(|b| {
            // Only the run's own files, by the names the run gives them.
            if !crate::files::is_plain_name(&b.name) || b.file != format!("{}.stl", b.name) {
                return Err(Error::Read(format!(
                    "{shown}: report.json names the file '{}' for body '{}', which is not a file of this run",
                    crate::files::excerpt(&b.file),
                    crate::files::excerpt(&b.name)
                )));
            }
            let bytes = run
                .read(&b.file, crate::files::MAX_DATA_BYTES - stl_bytes)
                .map_err(|e| Error::Read(e.to_string()))?;
            stl_bytes += bytes.len() as u64;
            crate::mesh::read_stl_bytes(&bytes, &format!("{shown}/{}", b.file))
                .map(|m| (b.name.clone(), m))
                .map_err(|e| Error::Read(e.to_string()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    // The program's text as its control reads it, which the run timed: a
    // text that does not read back as program.json is not the run's.
    let control = crate::program::post::dialect(&report.control).ok_or_else(|| {
        Error::Read(format!(
            "{shown}: report.json names the control '{}', which pilgrim does not know",
            crate::files::excerpt(&report.control)
        ))
    })?;
    let program_file = format!("program.{}", control.extension);
    let text = match report.files.contains(&program_file) {
        true => Some(read(&program_file)?),
        false => None,
    };
    let as_read = match &text {
        Some(t) => Some(
            crate::program::lint::lint_read(t, &program, control, &kin.info().axes)
                .map_err(|e| bad(&program_file, e.to_string()))?,
        ),
        None => None,
    };
    // The scene moves as the run's did: the same program, timed as read.
    let times = crate::timing::times(
        as_read.as_ref().map_or(&program, |r| &r.program),
        kin.info(),
        &crate::program::pass_blocks(&program, &toolpath.passes),
    );
    let placement = scene::placement(kin, &program, &toolpath.tool, &parts)?;
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
    let (files, bodies, pose) = (staged.files, staged.bodies, staged.pose);
    report.playback = staged.playback;
    report.pose_block = Some(index + 1);
    report.pose_along = place.along;
    report.bodies = bodies;
    let mut all: Vec<(String, Vec<u8>)> = files
        .into_iter()
        .filter(|(n, _)| {
            n == "scene.glb"
                || !report
                    .bodies
                    .iter()
                    .any(|b| b.kind == "part" && &b.file == n)
        })
        .collect();
    // The tool's exact solid moves with it.
    let (tool_steps, tool_solids) =
        crate::render::solids::step_files(&[], &toolpath.tool, &pose, report.step_tolerance_mm)?;
    report.solids.retain(|s| s.kind != "tool");
    report.solids.extend(tool_solids);
    all.extend(tool_steps);
    // The page shows the new scene, with the run's plots and program.
    let mut shown: Vec<(String, Vec<u8>)> = Vec::new();
    // Only plots the run names by plain names, and its program.
    let plot = |n: &str| {
        n.strip_suffix(".svg")
            .is_some_and(crate::files::is_plain_name)
    };
    for name in report.files.iter().filter(|n| plot(n)) {
        shown.push((name.clone(), read(name)?.into_bytes()));
    }
    if let Some(t) = &text {
        shown.push((program_file.clone(), t.clone().into_bytes()));
    }
    shown.extend(all.iter().filter(|f| f.0 == "scene.glb").cloned());
    let view = scene::bounds_of(parts.iter().map(|(_, m)| m))
        .map(|b| scene::contact_box(b, &toolpath.tool, &pose));
    // The listing's lines as the lint read the program.
    let listed = crate::render::page::written_program(&shown, control.extension);
    report.program_lines = as_read.map(|r| r.lines).unwrap_or_default();
    let html = crate::render::page::page_of(&report, &shown, listed, view);
    all.push(("report.html".into(), html.into_bytes()));
    all.push(("report.json".into(), super::report_json(&report)?));
    Ok(Exported {
        files: all,
        block: index + 1,
    })
}
