//! 3-D output of a run: the part's bodies, the tool placed where the program
//! puts it at one block, as STL files and one glTF scene.

use pilgrim_kernel::mesh::{self, frame_from_pose, Scene, StlFormat, TriMesh};
use pilgrim_kernel::{AxisProgram, MachineKinematics, Point3, Tool, ToolShape, Vec3};
use serde::{Deserialize, Serialize};

/// A body written to a file, for the report.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BodyFile {
    /// The body's name.
    pub name: String,
    /// `part` or `tool`.
    pub kind: String,
    /// Its STL file.
    pub file: String,
    /// Triangles.
    pub triangles: usize,
    /// Enclosed volume (mm^3).
    pub volume_mm3: f64,
}

const PART_COLOR: [f32; 4] = [0.72, 0.72, 0.76, 1.0];
const TOOL_COLOR: [f32; 4] = [0.25, 0.42, 0.85, 1.0];

/// The tool's solid in its own frame and the file name it is written as.
pub fn tool_mesh(tool: &Tool, tol: f64) -> Result<Option<(TriMesh, &'static str)>, String> {
    Ok(match tool.shape {
        ToolShape::Wheel(w) => Some((mesh::wheel(&w, tol).map_err(|e| e.to_string())?, "wheel")),
        ToolShape::EndMill { diameter, length } => Some((
            mesh::cylinder(diameter / 2.0, length, tol).map_err(|e| e.to_string())?,
            "cutter",
        )),
        ToolShape::Insert { .. } => None,
    })
}

const REST_COLOR: [f32; 4] = [0.85, 0.55, 0.2, 1.0];

/// Other moving bodies of the machine placed at block `index` (from 0): for
/// a built-in machine with a `rest` body (the 3K152VF20's steady rest), a
/// roller of its `rest_radius` and 40 mm long across the axial section,
/// placed by the body's chain at the block's axis values.
pub fn machine_bodies(
    machine_name: &str,
    program: &AxisProgram,
    index: usize,
    tol: f64,
) -> Result<Vec<(String, TriMesh, pilgrim_kernel::Mat4)>, String> {
    let Ok(m) = pilgrim_kernel::Machine::builtin(machine_name) else {
        return Ok(vec![]);
    };
    let Some(chain) = m.body_chain("rest") else {
        return Ok(vec![]);
    };
    let Some(block) = program.blocks.get(index) else {
        return Ok(vec![]);
    };
    let mut q = Vec::new();
    for name in chain.axis_names() {
        let Some(col) = program.axes.iter().position(|a| &a.name == name) else {
            return Ok(vec![]); // the program does not drive the rest
        };
        let v = block.values[col];
        let rotary = m
            .axis(name)
            .is_some_and(|a| a.kind == pilgrim_kernel::AxisKind::Rotary);
        q.push(if rotary { v.to_radians() } else { v });
    }
    let radius = m.constant("rest_radius").unwrap_or(25.0);
    let length = 40.0;
    // The roller along Y, centred on the support's circle in the XZ section.
    let roller = mesh::cylinder(radius, length, tol)
        .map_err(|e| e.to_string())?
        .transformed(
            &(pilgrim_kernel::Mat4::from_axis_angle(
                &pilgrim_kernel::Vec3::x_axis(),
                std::f64::consts::FRAC_PI_2,
            ) * pilgrim_kernel::Mat4::new_translation(&Vec3::new(0.0, 0.0, -length / 2.0))),
        );
    let pose = chain.matrix(&q).map_err(|e| e.to_string())?;
    Ok(vec![("rest".into(), roller, pose)])
}

/// Block index (from 0) where the scene shows the tool by default: the
/// middle block of the last pass that cuts (has a move other than a rapid),
/// the tool at work on the finish; else the first block of the last pass.
pub fn default_pose_block(passes: &[pilgrim_kernel::Pass]) -> usize {
    let (mut start, mut last_start, mut pick) = (0, 0, None);
    for p in passes {
        if p.cuts() {
            pick = Some(start + p.points.len() / 2);
        }
        last_start = start;
        start += p.points.len();
    }
    pick.unwrap_or(last_start)
}

/// The rigid motion of the tool at block `index` (from 0): the machine's
/// forward kinematics of the block's axis values.
pub fn tool_pose(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &Tool,
    index: usize,
) -> Result<pilgrim_kernel::Mat4, String> {
    let pose =
        pilgrim_kernel::verify::replay_blocks(program, machine, &tool.reference, index..index + 1)?;
    Ok(frame_from_pose(
        &tool.reference,
        Point3::new(pose[0], pose[1], pose[2]),
        Vec3::new(pose[3], pose[4], pose[5]),
    ))
}

/// Which 3-D files to write beside the default binary STL and `.glb`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Formats {
    /// STL as ASCII instead of binary.
    pub stl_ascii: bool,
    /// Also `scene.gltf` + `scene.bin`.
    pub gltf: bool,
}

/// Files to write: (name, bytes).
pub type Files = Vec<(String, Vec<u8>)>;

/// The files of the scene: each part body's STL, the tool's STL placed at
/// the block, and `scene.glb`; with the bodies' records.
pub fn files(
    parts: &[(String, TriMesh)],
    tool: Option<(TriMesh, &'static str)>,
    tool_pose: pilgrim_kernel::Mat4,
    others: Vec<(String, TriMesh, pilgrim_kernel::Mat4)>,
    formats: Formats,
) -> Result<(Files, Vec<BodyFile>), String> {
    let mut scene = Scene::new();
    let mut out = Vec::new();
    let mut bodies = Vec::new();
    let mut stl = |name: &str,
                   kind: &str,
                   m: &TriMesh,
                   out: &mut Vec<(String, Vec<u8>)>|
     -> Result<(), String> {
        m.check_closed().map_err(|e| format!("{name}: {e}"))?;
        let file = format!("{name}.stl");
        let mut bytes = Vec::new();
        let format = if formats.stl_ascii {
            StlFormat::Ascii
        } else {
            StlFormat::Binary
        };
        mesh::write_stl(m, name, format, &mut bytes).map_err(|e| e.to_string())?;
        bodies.push(BodyFile {
            name: name.to_owned(),
            kind: kind.to_owned(),
            file: file.clone(),
            triangles: m.triangle_count(),
            volume_mm3: (m.volume() * 1000.0).round() / 1000.0,
        });
        out.push((file, bytes));
        Ok(())
    };
    for (name, m) in parts {
        stl(name, "part", m, &mut out)?;
        scene.add(
            name,
            m.clone(),
            pilgrim_kernel::Mat4::identity(),
            PART_COLOR,
        );
    }
    if let Some((m, name)) = tool {
        stl(name, "tool", &m.transformed(&tool_pose), &mut out)?;
        scene.add(name, m, tool_pose, TOOL_COLOR);
    }
    for (name, m, pose) in others {
        stl(&name, "machine", &m.transformed(&pose), &mut out)?;
        scene.add(&name, m, pose, REST_COLOR);
    }
    let mut glb = Vec::new();
    mesh::write_glb(&scene, &mut glb).map_err(|e| e.to_string())?;
    out.push(("scene.glb".into(), glb));
    if formats.gltf {
        let (mut text, mut bin) = (Vec::new(), Vec::new());
        mesh::write_gltf(&scene, "scene.bin", &mut text, &mut bin).map_err(|e| e.to_string())?;
        out.push(("scene.gltf".into(), text));
        out.push(("scene.bin".into(), bin));
    }
    Ok((out, bodies))
}
