//! 3-D output of a run: the part's bodies, the tool placed where the program
//! puts it at one block, the machine's other moving bodies (a steady rest)
//! placed by their chains, as STL files and one glTF scene.

use crate::family::{PartBody, PartGeometry};
use crate::machine::MachineKinematics;
use crate::math::{Mat4, Point3, Vec3};
pub use crate::mesh::SceneError;
use crate::mesh::{self, frame_from_pose, MeshError, Scene, StlFormat, TriMesh};
use crate::program::ProgramPass;
use crate::program::{axis_rows, AxisProgram};
pub use crate::report::BodyFile;
use crate::tool::{Tool, ToolShape, WheelOrigin};

const PART_COLOR: [f32; 4] = [0.72, 0.72, 0.76, 1.0];
const TOOL_COLOR: [f32; 4] = [0.25, 0.42, 0.85, 1.0];
const MACHINE_COLOR: [f32; 4] = [0.85, 0.55, 0.2, 1.0];
const OVERLAY_COLOR: [f32; 4] = [0.9, 0.1, 0.1, 1.0];

fn mesh_err(body: &str) -> impl Fn(MeshError) -> SceneError + '_ {
    move |source| SceneError::Mesh {
        body: body.to_owned(),
        source,
    }
}

/// The part's bodies as closed meshes (bodies of revolution turned about Z).
///
/// # Failures
/// A body whose mesh fails, named.
pub fn part_meshes(parts: &[PartBody], tol: f64) -> Result<Vec<(String, TriMesh)>, SceneError> {
    parts
        .iter()
        .map(|b| {
            let m = match &b.geometry {
                PartGeometry::Revolution(p) => mesh::body_of_revolution(p, tol)
                    .map_err(mesh_err(&format!("part '{}'", b.name)))?,
                PartGeometry::Swept(s) => s.mesh.clone(),
            };
            Ok((b.name.clone(), m))
        })
        .collect()
}

/// What the page's camera frames: a box about the tool's programmed point
/// at the pose (where it meets the part), reaching each way two of the
/// part's radii or the wheel's radius, whichever is more (at least 20
/// mm): the contact, the tool and the part round it, not the machine's
/// far bodies. `part_box` is the part's bounding box.
pub fn contact_box(
    part_box: ([f64; 3], [f64; 3]),
    tool: &Tool,
    at: &ToolAt,
) -> ([f64; 3], [f64; 3]) {
    let (lo, hi) = part_box;
    let radius = [lo[0], hi[0], lo[1], hi[1]]
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    let wheel = match tool.shape {
        ToolShape::Wheel(w) => w.diameter / 2.0,
        _ => 0.0,
    };
    let h = (2.0 * radius).max(wheel).max(20.0);
    let c = [at.pose[(0, 3)], at.pose[(1, 3)], at.pose[(2, 3)]];
    (c.map(|v| v - h), c.map(|v| v + h))
}

/// The bounding box of `meshes` together (`None` for none).
pub fn bounds_of<'a>(meshes: impl Iterator<Item = &'a TriMesh>) -> Option<([f64; 3], [f64; 3])> {
    meshes.map(TriMesh::bounds).reduce(|a, b| {
        (
            std::array::from_fn(|k| a.0[k].min(b.0[k])),
            std::array::from_fn(|k| a.1[k].max(b.1[k])),
        )
    })
}

/// The tool's solid in its own frame, standing `at` (a thread cutter's
/// blade follows the thread it cuts there: [`crate::blade::ThreadBlade`]),
/// and the file name it is written as.
///
/// # Failures
/// The tool's mesh failing.
pub fn tool_mesh(
    tool: &Tool,
    at: &ToolAt,
    tol: f64,
) -> Result<Option<(TriMesh, &'static str)>, SceneError> {
    Ok(match tool.shape {
        ToolShape::Wheel(w) => {
            let m = mesh::wheel(&w, tol).map_err(mesh_err("wheel"))?;
            let m = match tool.origin {
                WheelOrigin::Periphery => m,
                WheelOrigin::Centre => m.transformed(&Mat4::new_translation(&Vec3::new(
                    -0.5 * w.diameter,
                    0.0,
                    0.0,
                ))),
            };
            Some((m, "wheel"))
        }
        ToolShape::EndMill { diameter, length } => Some((
            mesh::cylinder(diameter / 2.0, length, tol).map_err(mesh_err("cutter"))?,
            "cutter",
        )),
        ToolShape::Insert { .. } => None,
        ToolShape::ThreadCutter(c) => Some((
            thread_blade(&c, at).mesh(tol).map_err(mesh_err("cutter"))?,
            "cutter",
        )),
    })
}

/// A thread cutter's blade standing `at`.
pub fn thread_blade(c: &crate::tool::ThreadCutter, at: &ToolAt) -> crate::blade::ThreadBlade {
    let tip_radius = at.pose[(0, 3)].hypot(at.pose[(1, 3)]);
    crate::blade::ThreadBlade::new(c, tip_radius, at.lead, at.pose)
}

/// A body placed in the part frame: name, mesh in its own frame, pose.
pub type Placed = (String, TriMesh, Mat4);

/// The machine's bodies placed for `program` and `toolpath`'s tool and
/// part ([`crate::collision::Placement`]: on the part frame by their
/// chains, on the tool from its spindle centre with the tool's own sizes,
/// at the ends of `parts`' largest body, none at a free end): one
/// placement for the collision check, the still scene and its motion.
///
/// # Failures
/// A body's description failing.
pub fn placement(
    machine: &dyn MachineKinematics,
    program: &AxisProgram,
    toolpath: &crate::toolpath::Toolpath,
    parts: &[(String, TriMesh)],
) -> Result<crate::collision::Placement, SceneError> {
    let axes: Vec<String> = program.axes.iter().map(|a| a.name.clone()).collect();
    let part_z = crate::collision::part_at_largest(parts).map(|(_, m)| crate::collision::part_z(m));
    let holding = crate::collision::Holding::of(&toolpath.tool, toolpath.free_end);
    crate::collision::Placement::new(machine.info(), &axes, &holding, part_z).map_err(placing)
}

fn placing(e: crate::collision::CollisionError) -> SceneError {
    SceneError::Place(e.to_string())
}

/// The machine's bodies that have a shape, placed by `placement` at
/// `place`, turned with the tool where it stands in a thread
/// ([`ToolAt::turn`]); a body the program or the run cannot place is left
/// out.
///
/// # Failures
/// A body's mesh failing.
fn machine_bodies(
    machine: &dyn MachineKinematics,
    program: &AxisProgram,
    place: PosePlace,
    at: &ToolAt,
    placement: &crate::collision::Placement,
    tol: f64,
) -> Result<Vec<Placed>, SceneError> {
    let program = &at_place(program, place)?;
    // In a thread the machine is shown turned with the tool.
    let turned = Mat4::from_axis_angle(&Vec3::z_axis(), at.turn);
    let q = axis_rows(program, machine.info(), placement.axes(), 0..1)
        .map_err(|e| SceneError::Place(e.to_string()))?;
    let tool_frame = placement.tool_frame(&q).map_err(placing)?;
    placement
        .bodies
        .iter()
        .enumerate()
        .map(|(i, body)| {
            let mesh = mesh::body_mesh(&body.solid, tol).map_err(mesh_err(&body.name))?;
            let pose = placement.body_frame(i, &q, &tool_frame).map_err(placing)?;
            Ok((body.name.clone(), mesh, turned * pose))
        })
        .collect()
}

/// The most keys of the scene's animation: a longer program is sampled
/// every so many blocks (the page's listing stays exact).
pub const MAX_KEYS: usize = 2000;

/// The program's motion for the scene, on the machine: the tool (its node
/// `tool_name`) and every machine body that moves, placed by `placement`,
/// at the end of each block (of every k-th block where there are more than
/// [`MAX_KEYS`]), at the time the program reaches it as the machine moves
/// it (`block_s`: each block's seconds,
/// [`crate::timing::Times::block_s`]); and the part turning with the bodies
/// fixed to it (`turning`) as the machine's axes turn it
/// ([`super::spin`]). The tool and the moving bodies are placed on the
/// machine: the part frame turned by the rotary axes' turn of the part.
/// `None` when nothing moves.
///
/// # Failures
/// A body's description failing; the program lacking an axis.
fn motion(
    machine: &dyn MachineKinematics,
    program: &AxisProgram,
    (tool, tool_name): (&Tool, Option<&str>),
    placement: &crate::collision::Placement,
    block_s: &[f64],
    turning: Vec<String>,
) -> Result<Option<mesh::Motion>, SceneError> {
    let info = machine.info();
    let n = program.blocks.len();
    let moving: Vec<usize> = (0..placement.bodies.len())
        .filter(|&i| !placement.bodies[i].moved_by.is_empty())
        .collect();
    let tool_name = tool_name.filter(|_| placement.tool_axes().is_some());
    if n == 0 {
        return Ok(None);
    }
    let rows = axis_rows(program, info, placement.axes(), 0..n)
        .map_err(|e| SceneError::Place(e.to_string()))?;
    let w = placement.axes().len();
    let rotary: Vec<f64> = (0..n)
        .map(|k| placement.part_turn(&rows[k * w..(k + 1) * w]))
        .collect();
    let every = n.div_ceil(MAX_KEYS).max(1);
    let keyed = |k: usize| k.is_multiple_of(every) || k + 1 == n;
    let turns = super::spin::part_turns(
        machine,
        program,
        tool,
        &rotary,
        placement.spindle_turns_part,
        block_s,
    )?;
    let spin = if turns.iter().all(|&a| a == 0.0) || turning.is_empty() {
        None
    } else {
        super::spin::spin_keys(&turns, block_s, keyed).map(|(times, angles)| mesh::Spin {
            members: turning,
            times,
            angles,
        })
    };
    if moving.is_empty() && tool_name.is_none() && spin.is_none() {
        return Ok(None);
    }
    let (mut times, mut keys) = (Vec::new(), Vec::new());
    let mut tracks: Vec<(String, Vec<Mat4>)> = tool_name
        .into_iter()
        .map(str::to_owned)
        .chain(moving.iter().map(|&i| placement.bodies[i].name.clone()))
        .map(|name| (name, Vec::new()))
        .collect();
    let mut clock = 0.0;
    for k in 0..n {
        clock += block_s.get(k).copied().unwrap_or(0.0);
        let t = clock as f32;
        if !keyed(k) || times.last().is_some_and(|&last| t <= last) {
            continue;
        }
        times.push(t);
        keys.push(k);
        let q = &rows[k * w..(k + 1) * w];
        let on_machine = Mat4::from_axis_angle(&Vec3::z_axis(), rotary[k]);
        let frame = placement.tool_frame(q).map_err(placing)?;
        let mut track = tracks.iter_mut();
        if tool_name.is_some() {
            if let Some((_, poses)) = track.next() {
                poses.push(on_machine * frame);
            }
        }
        for (&i, (_, poses)) in moving.iter().zip(track) {
            poses.push(on_machine * placement.body_frame(i, q, &frame).map_err(placing)?);
        }
    }
    Ok(Some(mesh::Motion {
        name: "the program".into(),
        times,
        keys,
        tracks,
        spin,
    }))
}

/// Where the scene shows the tool and the machine's bodies: `along` of
/// the way through block `block`'s move (from 0; 1 is the block's end, its
/// axis values), the axes interpolated in straight lines from the block
/// before as the control moves them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosePlace {
    /// The block (from 0).
    pub block: usize,
    /// How far through its move, from 0 (the block before's end) to 1.
    pub along: f64,
}

impl PosePlace {
    /// The end of block `block` (from 0).
    pub fn at_end(block: usize) -> Self {
        Self { block, along: 1.0 }
    }
}

/// Where the scene shows the tool by default in `program`, built from
/// `passes`: the middle block of the last pass that cuts (has a move other
/// than a rapid), the tool at work on the finish, at its end; halfway
/// through it if it cuts a thread (whose end lies beyond the thread, where
/// the tool has left the part); else the first block of the last pass.
pub fn default_pose_block(program: &AxisProgram, passes: &[ProgramPass]) -> PosePlace {
    let (mut last_start, mut pick) = (0, None);
    for p in passes {
        if p.cuts {
            pick = Some(p.blocks.start + p.blocks.len() / 2);
        }
        last_start = p.blocks.start;
    }
    let block = pick.unwrap_or(last_start);
    let thread = program
        .blocks
        .get(block)
        .is_some_and(|b| matches!(b.motion, crate::toolpath::Motion::Thread { .. }));
    PosePlace {
        block,
        along: if thread && block > 0 { 0.5 } else { 1.0 },
    }
}

/// `program` with its blocks replaced by the one at `place` (the axes
/// interpolated between the block before and this one).
///
/// # Failures
/// A block beyond the program.
fn at_place(program: &AxisProgram, place: PosePlace) -> Result<AxisProgram, SceneError> {
    let b = program.blocks.get(place.block).ok_or_else(|| {
        SceneError::Place(format!(
            "block {} is beyond the program's {} blocks",
            place.block + 1,
            program.blocks.len()
        ))
    })?;
    let mut block = b.clone();
    if place.along < 1.0 {
        let before = &program.blocks[place.block.saturating_sub(1)];
        for (v, a) in block.values.iter_mut().zip(&before.values) {
            *v = a + (*v - a) * place.along;
        }
    }
    Ok(AxisProgram {
        name: program.name.clone(),
        number: program.number,
        machine: program.machine.clone(),
        control: program.control.clone(),
        tool_number: program.tool_number,
        tool_name: program.tool_name.clone(),
        spindle_rpm: program.spindle_rpm,
        decimals: program.decimals,
        axes: program.axes.clone(),
        blocks: vec![block],
        setup: program.setup.clone(),
        cycles: Vec::new(),
        fanuc_cycles: Vec::new(),
    })
}

/// Where the tool stands at a place of the program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolAt {
    /// Its rigid motion into the part frame.
    pub pose: Mat4,
    /// The lead of the thread it cuts there (mm; 0 outside a thread block).
    pub lead: f64,
    /// How far the part has turned since the thread's start (rad; 0
    /// outside a thread block): the scene shows the machine turned by it
    /// about the part's axis, so the tool stands in the thread it cuts.
    pub turn: f64,
}

/// The tool at `place`, in the part frame: the machine's forward
/// kinematics of the axis values there; in a thread block, turned about the
/// part's axis by the angle the spindle has turned the part since the
/// thread's start (its start angle, then one turn a lead), as the worm's
/// simulation places each cut (the thread family's): the tool stands
/// in the thread it cuts.
///
/// # Failures
/// A block beyond the program; the replay failing.
pub fn tool_pose(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &Tool,
    place: PosePlace,
) -> Result<ToolAt, SceneError> {
    let here = at_place(program, place)?;
    let pose = crate::replay::replay_blocks(&here, machine, &tool.reference, 0..1)
        .map_err(|e| SceneError::Place(e.to_string()))?;
    let frame = frame_from_pose(
        &tool.reference,
        Point3::new(pose[0], pose[1], pose[2]),
        Vec3::new(pose[3], pose[4], pose[5]),
    );
    let b = &here.blocks[0];
    let flat = ToolAt {
        pose: frame,
        lead: 0.0,
        turn: 0.0,
    };
    let crate::toolpath::Motion::Thread { lead, start_deg } = b.motion else {
        return Ok(flat);
    };
    if place.block == 0 {
        return Ok(flat);
    }
    // Where the block started: its thread's section at part angle 0 is
    // there, shifted by the start angle's share of the lead.
    let start = at_place(program, PosePlace::at_end(place.block - 1))?;
    let from = crate::replay::replay_blocks(&start, machine, &tool.reference, 0..1)
        .map_err(|e| SceneError::Place(e.to_string()))?;
    let angle = super::spin::thread_turn(from[2], pose[2], lead, start_deg, pose[2]);
    Ok(ToolAt {
        pose: Mat4::from_axis_angle(&Vec3::z_axis(), angle) * frame,
        lead,
        turn: angle,
    })
}

/// A run's scene, staged: its files and bodies, where the tool stands, the
/// player's keys (each key's block, from 0, and time, s).
#[derive(Debug, Clone)]
pub struct Staged {
    /// The files (STL, `scene.glb`, and the `.gltf` asked for).
    pub files: Files,
    /// The bodies written.
    pub bodies: Vec<BodyFile>,
    /// Where the tool stands.
    pub pose: ToolAt,
    /// The animation's keys, for the page's player.
    pub playback: Vec<(usize, f32)>,
}

/// The scene of `program` on `machine` at `place`: the part's bodies
/// `parts`, the tool, the machine's bodies as `placement` places them
/// ([`placement`]), the `overlays`, and the program's motion at the
/// blocks' times `block_s`; one definition for the run and for `pilgrim
/// export`.
///
/// # Failures
/// The replay, a body's placement or mesh, a writer failing.
#[allow(clippy::too_many_arguments)]
pub fn stage(
    machine: &dyn MachineKinematics,
    program: &AxisProgram,
    tool: &Tool,
    (parts, placement): (&[(String, TriMesh)], &crate::collision::Placement),
    place: PosePlace,
    block_s: &[f64],
    overlays: Vec<Placed>,
    (tol, formats): (f64, Formats),
) -> Result<Staged, SceneError> {
    let pose = tool_pose(program, machine, tool, place)?;
    let solid = tool_mesh(tool, &pose, tol)?;
    let others = machine_bodies(machine, program, place, &pose, placement, tol)?;
    // What turns with the part: its bodies, the overlays on it, and the
    // machine's bodies that stand still in its frame (a chuck, an arbor),
    // as the collision check holds them.
    let turning = parts
        .iter()
        .map(|(name, _)| name.clone())
        .chain(overlays.iter().map(|o| o.0.clone()))
        .chain(
            placement
                .bodies
                .iter()
                .filter(|b| b.moved_by.is_empty())
                .map(|b| b.name.clone()),
        )
        .collect();
    let motion = motion(
        machine,
        program,
        (tool, solid.as_ref().map(|(_, name)| *name)),
        placement,
        block_s,
        turning,
    )?;
    let playback = motion
        .as_ref()
        .map(|m| {
            m.keys
                .iter()
                .copied()
                .zip(m.times.iter().copied())
                .collect()
        })
        .unwrap_or_default();
    let (files, bodies) = files(parts, solid, pose.pose, others, overlays, motion, formats)?;
    Ok(Staged {
        files,
        bodies,
        pose,
        playback,
    })
}

/// Which 3-D files to write beside the default binary STL and `.glb`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Formats {
    /// STL as ASCII instead of binary.
    pub stl_ascii: bool,
    /// Also `scene.gltf` + `scene.bin`.
    pub gltf: bool,
}

/// Files to write: (name, bytes).
pub type Files = Vec<(String, Vec<u8>)>;

/// The files of the scene: each part body's STL, the tool's STL placed at
/// the block, the machine's bodies' STLs, and `scene.glb`; with the bodies'
/// records. `overlays` are surfaces shown in the scene only (a contact
/// patch: open meshes, no STL).
///
/// # Failures
/// A mesh that is not closed, or a writer failing.
pub fn files(
    parts: &[(String, TriMesh)],
    tool: Option<(TriMesh, &'static str)>,
    tool_pose: Mat4,
    others: Vec<Placed>,
    overlays: Vec<Placed>,
    motion: Option<mesh::Motion>,
    formats: Formats,
) -> Result<(Files, Vec<BodyFile>), SceneError> {
    // The scene as a whole is bounded as each mesh is.
    let total: usize = parts.iter().map(|(_, m)| m.triangle_count()).sum::<usize>()
        + tool.as_ref().map_or(0, |(m, _)| m.triangle_count())
        + others
            .iter()
            .chain(&overlays)
            .map(|p| p.1.triangle_count())
            .sum::<usize>();
    if total > mesh::MAX_TRIANGLES {
        return Err(SceneError::Place(format!(
            "the scene would hold {total} triangles, more than the ceiling {}",
            mesh::MAX_TRIANGLES
        )));
    }
    let mut scene = Scene::new();
    let mut out = Vec::new();
    let mut bodies = Vec::new();
    let mut stl = |name: &str,
                   kind: &str,
                   m: &TriMesh,
                   out: &mut Vec<(String, Vec<u8>)>|
     -> Result<(), SceneError> {
        m.check_closed().map_err(mesh_err(name))?;
        let file = format!("{name}.stl");
        let mut bytes = Vec::new();
        let format = if formats.stl_ascii {
            StlFormat::Ascii
        } else {
            StlFormat::Binary
        };
        mesh::write_stl(m, name, format, &mut bytes).map_err(mesh_err(name))?;
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
        scene.add(name, m.clone(), Mat4::identity(), PART_COLOR);
    }
    if let Some((m, name)) = tool {
        stl(name, "tool", &m.transformed(&tool_pose), &mut out)?;
        scene.add(name, m, tool_pose, TOOL_COLOR);
    }
    for (name, m, pose) in others {
        stl(&name, "machine", &m.transformed(&pose), &mut out)?;
        scene.add(&name, m, pose, MACHINE_COLOR);
    }
    for (name, m, pose) in overlays {
        scene.add(&name, m, pose, OVERLAY_COLOR);
    }
    scene.motion = motion;
    let mut glb = Vec::new();
    mesh::write_glb(&scene, &mut glb).map_err(mesh_err("scene"))?;
    out.push(("scene.glb".into(), glb));
    if formats.gltf {
        let (mut text, mut bin) = (Vec::new(), Vec::new());
        mesh::write_gltf(&scene, "scene.bin", &mut text, &mut bin).map_err(mesh_err("scene"))?;
        out.push(("scene.gltf".into(), text));
        out.push(("scene.bin".into(), bin));
    }
    Ok((out, bodies))
}
