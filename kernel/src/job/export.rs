//! `pilgrim export DIR --block N`: a finished run's scene with the tool (and
//! the machine's other bodies) placed at another block.

use super::scene::{self, Formats};
use super::Report;
use crate::catalog::Catalog;
use crate::error::Error;
use crate::program::AxisProgram;
use crate::toolpath::Toolpath;
use std::path::Path;

/// What an export made: the files to write over the run's, and the block.
#[derive(Debug, Clone)]
pub struct Exported {
    /// The files (name, bytes): the tool's and the machine bodies' STLs,
    /// `scene.glb` (and `.gltf`/`.bin` if asked), `report.json`.
    pub files: Vec<(String, Vec<u8>)>,
    /// The block (from 1) the scene is placed at.
    pub block: usize,
}

/// The scene of the run in `dir` placed at `block` (from 1; `None`: the
/// middle of the last cutting pass), the machine reopened from `catalog`.
///
/// # Failures
/// A file of the run missing or not what the run wrote; a run without 3-D
/// models; block 0; the machine or the replay failing.
pub fn export(
    dir: &Path,
    catalog: &Catalog,
    block: Option<usize>,
    formats: Formats,
) -> Result<Exported, Error> {
    let read = |name: &str| {
        std::fs::read_to_string(dir.join(name))
            .map_err(|e| Error::Read(format!("{}: {e}", dir.join(name).display())))
    };
    let parse = |name: &str, e: serde_json::Error| Error::Read(format!("{name}: {e}"));
    let mut report: Report =
        serde_json::from_str(&read("report.json")?).map_err(|e| parse("report.json", e))?;
    let program: AxisProgram =
        serde_json::from_str(&read("program.json")?).map_err(|e| parse("program.json", e))?;
    let toolpath: Toolpath =
        serde_json::from_str(&read("toolpath.json")?).map_err(|e| parse("toolpath.json", e))?;
    if report.bodies.is_empty() {
        return Err(Error::Read(format!(
            "{}: the run has no 3-D models (its family has no fn part(p))",
            dir.display()
        )));
    }
    let machine = catalog.open(&report.machine_spec)?;
    let kin = machine.kinematics.as_ref();
    let index = match block {
        Some(0) => return Err(Error::Options("--block counts blocks from 1".into())),
        Some(n) => n - 1,
        None => scene::default_pose_block(&toolpath.passes),
    };
    let parts = report
        .bodies
        .iter()
        .filter(|b| b.kind == "part")
        .map(|b| {
            crate::mesh::read_stl(&dir.join(&b.file))
                .map(|m| (b.name.clone(), m))
                .map_err(|e| Error::Read(e.to_string()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let pose = scene::tool_pose(&program, kin, &toolpath.tool, index)?;
    let tool = scene::tool_mesh(&toolpath.tool, report.mesh_tolerance_mm)?;
    let others = scene::machine_bodies(kin, &program, index, report.mesh_tolerance_mm)?;
    let (files, bodies) = scene::files(&parts, tool, pose, others, formats)?;
    report.pose_block = Some(index + 1);
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
    all.push(("report.json".into(), super::json(&report)?));
    Ok(Exported {
        files: all,
        block: index + 1,
    })
}
