//! `pilgrim run`: a family's parameters to a control's program, written
//! atomically.

use crate::machines;
use indicatif::{ProgressBar, ProgressStyle};
use pilgrim_kernel::program::post::{dialect, CLD};
use pilgrim_kernel::script::{Access, Check, Family, Limits, ParamValue};
use pilgrim_kernel::{AxisProgram, Motion, Toolpath};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What `run` was asked.
pub struct RunArgs {
    pub formats: crate::scene::Formats,
    pub pose_block: Option<usize>,
    pub tolerance: f64,
    pub script: PathBuf,
    pub params: Option<PathBuf>,
    pub sets: Vec<(String, String)>,
    pub machine: Option<String>,
    pub out: PathBuf,
    pub quiet: bool,
}

#[derive(Serialize, serde::Deserialize)]
struct ReportParam {
    value: ParamValue,
    unit: String,
}

#[derive(Serialize, serde::Deserialize)]
struct Report {
    pilgrim: String,
    script: String,
    machine: String,
    /// The --machine given (or the family's default), to reopen it.
    machine_spec: String,
    control: String,
    parameters: BTreeMap<String, ReportParam>,
    passes: usize,
    /// Passes with a move other than a rapid.
    #[serde(default)]
    cutting_passes: usize,
    points: usize,
    blocks: usize,
    cycle_time_min: f64,
    files: Vec<String>,
    checks: Vec<Check>,
    /// The block (from 1) the 3-D scene places the tool at.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pose_block: Option<usize>,
    /// Chordal tolerance of the meshes (mm).
    tolerance_mm: f64,
    /// The bodies written as STL.
    #[serde(default)]
    bodies: Vec<crate::scene::BodyFile>,
    /// Each programmed axis's range over the program: [min, max] (mm, deg).
    #[serde(default)]
    axis_ranges: BTreeMap<String, [f64; 2]>,
    /// The program replayed against the nominal part (families with fn verify).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    verification: Option<pilgrim_kernel::verify::GrindingCheck>,
    /// Figures the family noted.
    #[serde(default)]
    notes: BTreeMap<String, f64>,
}

/// `profile.svg`: the part's profiles and the wheel centre's path on the
/// finishing pass; the steady rest's track (U against z + B, when the family
/// notes `rest_offset_b_mm`); the nominal's curvature against the wheel's
/// limit 1/R_s.
fn profile_svg(
    profiles: &[(String, pilgrim_kernel::Profile)],
    toolpath: &Toolpath,
    v: &pilgrim_kernel::script::Verification,
    rounding: f64,
) -> String {
    use crate::svg::{Panel, Series};
    const COLORS: [&str; 4] = ["#444444", "#d08000", "#2a6fd8", "#2a9d4b"];
    let cutting: Vec<&pilgrim_kernel::Pass> = toolpath.passes.iter().filter(|p| p.cuts()).collect();
    let mut shape: Vec<Series> = profiles
        .iter()
        .enumerate()
        .map(|(i, (name, p))| Series {
            name: name.clone(),
            color: COLORS[i % 2],
            points: p.z().iter().copied().zip(p.x().iter().copied()).collect(),
        })
        .collect();
    if let Some(last) = cutting.last() {
        shape.push(Series {
            name: format!("wheel centre, {}", last.name),
            color: COLORS[2],
            points: last
                .points
                .iter()
                .map(|c| (c.point[2], c.point[0].hypot(c.point[1])))
                .collect(),
        });
    }
    let mut panels = vec![Panel {
        title: "profile (mm) and the wheel's path".into(),
        y_label: "radius x".into(),
        series: shape,
    }];
    let u = toolpath.aux_names.iter().position(|a| a == "U");
    if let (Some(u), Some(b)) = (u, toolpath.notes.get("rest_offset_b_mm")) {
        panels.push(Panel {
            title: "steady rest: support centre U at z + B, every pass".into(),
            y_label: "U".into(),
            series: cutting
                .iter()
                .enumerate()
                .map(|(i, p)| Series {
                    name: p.name.clone(),
                    color: COLORS[i % COLORS.len()],
                    points: p
                        .points
                        .iter()
                        .map(|c| (c.point[2] + b, c.aux[u]))
                        .collect(),
                })
                .collect(),
        });
    }
    // Curvature as a share of the wheel's limit (1 = as round as the wheel):
    // the margin reads directly, and the curve keeps its shape however far
    // below the limit it is (the limit's line is drawn when it is near).
    // Corners (infinite curvature) are left out: the wheel pivots on convex
    // ones, and concave ones never get this far.
    let z = v.profile.z();
    let share: Vec<(f64, f64)> = z
        .iter()
        .zip(v.profile.curvature())
        .map(|(&z, k)| (z, k * rounding))
        .filter(|(_, s)| s.is_finite())
        .collect();
    let top = share.iter().fold(0.0f64, |m, (_, s)| m.max(s.abs()));
    let mut series = vec![Series {
        name: "R_s x curvature".into(),
        color: COLORS[0],
        points: share,
    }];
    if top >= 0.25 {
        series.push(Series {
            name: "the wheel's limit".into(),
            color: "#cc2222",
            points: vec![(z[0], 1.0), (z[z.len() - 1], 1.0)],
        });
    }
    panels.push(Panel {
        title: format!(
            "curvature of the nominal against the wheel's limit 1/R_s (R_s = {rounding} mm): largest {}",
            pilgrim_kernel::math::fixed(top, 4)
        ),
        y_label: "R_s x curvature".into(),
        series,
    });
    crate::svg::render(&panels)
}

/// One row per block: block number, pass, motion, axis values, feed.
fn block_table(program: &AxisProgram, toolpath: &Toolpath) -> String {
    let mut out = String::from("block,pass,motion");
    for a in &program.axes {
        out += &format!(",{} ({})", a.name, a.unit);
    }
    out += ",feed (mm/min)\n";
    let names = toolpath
        .passes
        .iter()
        .flat_map(|p| std::iter::repeat_n(p.name.as_str(), p.points.len()));
    let decimals = program.decimals.unwrap_or(3);
    for (i, (b, pass)) in program.blocks.iter().zip(names).enumerate() {
        let motion = match b.motion {
            Motion::Rapid => "rapid",
            Motion::Linear => "linear",
            Motion::Thread { .. } => "thread",
        };
        out += &format!("{},\"{}\",{motion}", i + 1, pass.replace('"', "'"));
        for v in &b.values {
            out += &format!(",{}", pilgrim_kernel::math::fixed(*v, decimals));
        }
        out += &format!(",{}\n", pilgrim_kernel::math::fixed(b.feed, 1));
    }
    out
}

/// Minutes of cutting and rapid moves, from the program's feeds (rapids at
/// the slowest of the moving axes' maximum speeds).
fn cycle_time(program: &AxisProgram, info: &pilgrim_kernel::MachineInfo) -> f64 {
    let mut minutes = 0.0;
    for w in program.blocks.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let deltas: Vec<f64> = a.values.iter().zip(&b.values).map(|(x, y)| y - x).collect();
        let linear: f64 = program
            .axes
            .iter()
            .zip(&deltas)
            .filter(|(ax, _)| ax.unit == "mm")
            .map(|(_, d)| d * d)
            .sum::<f64>()
            .sqrt();
        let path = if linear > pilgrim_kernel::machine::LINEAR_RESOLUTION {
            linear
        } else {
            deltas.iter().map(|d| d * d).sum::<f64>().sqrt()
        };
        minutes += match b.motion {
            Motion::Rapid => program
                .axes
                .iter()
                .zip(&deltas)
                .filter_map(|(ax, d)| info.axis(&ax.name).map(|a| d.abs() / a.to_user(a.max_feed)))
                .fold(0.0, f64::max),
            _ if b.feed > 0.0 => path / b.feed,
            _ => 0.0,
        };
    }
    minutes
}

struct Stages {
    bar: ProgressBar,
}

impl Stages {
    fn new(quiet: bool, n: u64) -> Self {
        let bar = if quiet {
            ProgressBar::hidden()
        } else {
            ProgressBar::new(n)
        };
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        Self { bar }
    }

    fn next(&self, what: &str) {
        self.bar.set_message(what.to_owned());
        self.bar.inc(1);
    }
}

/// Runs the job; on any error nothing is written and the previous output
/// directory is left as it was.
pub fn run(args: &RunArgs) -> Result<String, String> {
    let stages = Stages::new(args.quiet, 7);
    stages.next("reading the family");
    let mut access = Access::default();
    if let Some(dir) = args.params.as_ref().and_then(|p| p.parent()) {
        access.input_dirs.push(if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir.to_owned()
        });
    }
    let family =
        Family::load(&args.script, &Limits::default(), &access).map_err(|e| e.to_string())?;
    let file_text = match &args.params {
        Some(p) => Some((
            p.display().to_string(),
            std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?,
        )),
        None => None,
    };
    let machine_spec = match &args.machine {
        Some(m) => m.clone(),
        None => family.default_machine().map_err(|e| e.to_string())?.ok_or_else(|| {
            format!("{}: no machine given: use --machine, or define fn default_machine() in the family", family.file())
        })?,
    };
    let machine = machines::open(&machine_spec)?;
    // Parameters tied to machine constants default to this machine's.
    let values = family
        .resolve_on(
            &machine.info().constants,
            file_text.as_ref().map(|(n, t)| (n.as_str(), t.as_str())),
            &args.sets,
        )
        .map_err(|e| e.to_string())?;
    stages.next("checking");
    let checks = family.checks(&values).map_err(|e| e.to_string())?;
    let failed: Vec<String> = checks
        .iter()
        .filter(|c| !c.ok)
        .map(|c| format!("{} ({})", c.name, c.detail))
        .collect();
    if !failed.is_empty() {
        return Err(format!(
            "{}: checks failed: {}",
            family.file(),
            failed.join("; ")
        ));
    }
    stages.next("computing the toolpath");
    let toolpath: Toolpath = family.toolpath(&values).map_err(|e| e.to_string())?;
    stages.next("inverse kinematics and limits");
    let name = args
        .script
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("pilgrim");
    let program =
        AxisProgram::build(&toolpath, machine.as_ref(), name).map_err(|e| e.to_string())?;
    let nominal = family.verification(&values).map_err(|e| e.to_string())?;
    let verification = match &nominal {
        None => None,
        Some(v) => {
            let pilgrim_kernel::ToolShape::Wheel(w) = toolpath.tool.shape else {
                return Err(format!(
                    "{}: fn verify(p) needs a grinding wheel",
                    family.file()
                ));
            };
            let passes: Vec<(String, usize)> = toolpath
                .passes
                .iter()
                .map(|p| (p.name.clone(), p.points.len()))
                .collect();
            Some(pilgrim_kernel::verify::check_grinding(
                &program,
                machine.as_ref(),
                &toolpath.tool.reference,
                w.rounding_radius,
                &passes,
                &v.profile,
                (v.from, v.to),
                v.tolerance,
            )?)
        }
    };
    stages.next("post-processing");
    let info = machine.info();
    let control = dialect(&info.control)
        .ok_or_else(|| format!("machine {}: unknown control '{}'", info.name, info.control))?;
    let control_text = machine
        .post(&program, control.name)
        .map_err(|e| e.to_string())?;
    let cld_text = machine
        .post(&program, CLD.name)
        .map_err(|e| e.to_string())?;
    let control_file = format!("program.{}", control.extension);
    let mut files: Vec<(String, Vec<u8>)> = vec![
        ("toolpath.json".into(), json(&toolpath)?.into_bytes()),
        ("program.json".into(), json(&program)?.into_bytes()),
        (control_file, control_text.into_bytes()),
        ("program.cld".into(), cld_text.into_bytes()),
        (
            "report.csv".into(),
            block_table(&program, &toolpath).into_bytes(),
        ),
    ];
    stages.next("3-D models");
    let profiles = if family.has_fn("part", 1) {
        part_profiles(&family, &values)?
    } else {
        vec![]
    };
    let (pose_block, bodies) = if family.has_fn("part", 1) {
        let parts = part_meshes(&family, &profiles, args.tolerance)?;
        let index = match args.pose_block {
            Some(0) => return Err("--pose-block counts blocks from 1".into()),
            Some(n) => n - 1,
            None => crate::scene::default_pose_block(&toolpath.passes),
        };
        let pose = crate::scene::tool_pose(&program, machine.as_ref(), &toolpath.tool, index)?;
        let tool = crate::scene::tool_mesh(&toolpath.tool, args.tolerance)?;
        let others = crate::scene::machine_bodies(&info.name, &program, index, args.tolerance)?;
        let (mesh_files, bodies) = crate::scene::files(&parts, tool, pose, others, args.formats)?;
        files.extend(mesh_files);
        (Some(index + 1), bodies)
    } else {
        (None, vec![])
    };
    let mut report = Report {
        pilgrim: env!("CARGO_PKG_VERSION").into(),
        script: args.script.display().to_string(),
        machine: info.name.clone(),
        machine_spec: machine_spec.clone(),
        control: info.control.clone(),
        parameters: family
            .params()
            .iter()
            .map(|s| {
                (
                    s.name.clone(),
                    ReportParam {
                        value: values[&s.name].clone(),
                        unit: s.unit.clone(),
                    },
                )
            })
            .collect(),
        passes: toolpath.passes.len(),
        cutting_passes: toolpath.passes.iter().filter(|p| p.cuts()).count(),
        points: toolpath.point_count(),
        blocks: program.blocks.len(),
        cycle_time_min: (cycle_time(&program, info) * 1e4).round() / 1e4,
        files: files
            .iter()
            .map(|f| f.0.clone())
            .chain(["report.json".to_owned()])
            .collect(),
        checks,
        pose_block,
        tolerance_mm: args.tolerance,
        bodies,
        axis_ranges: program
            .axes
            .iter()
            .filter_map(|a| {
                let col = program.column(&a.name)?;
                let lo = col.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = col.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                Some((a.name.clone(), [lo, hi]))
            })
            .collect(),
        verification,
        notes: toolpath.notes.clone(),
    };
    if let (Some(v), pilgrim_kernel::ToolShape::Wheel(w)) = (&nominal, toolpath.tool.shape) {
        files.push((
            "profile.svg".into(),
            profile_svg(&profiles, &toolpath, v, w.rounding_radius).into_bytes(),
        ));
        report.files.push("profile.svg".into());
    }
    files.push(("report.json".into(), json(&report)?.into_bytes()));
    stages.next("writing");
    write_atomically(&args.out, &files)?;
    stages.bar.finish_and_clear();
    let verified = report
        .verification
        .as_ref()
        .and_then(|v| v.passes.last())
        .map(|p| {
            format!(
                ", finish within {} mm of nominal",
                pilgrim_kernel::math::fixed(p.deviation.max_abs, 5)
            )
        })
        .unwrap_or_default();
    Ok(format!(
        "{}: {} cutting passes ({} in all), {} blocks for {} ({}), about {:.1} min{verified}; written to {}",
        family.file(),
        report.cutting_passes,
        report.passes,
        report.blocks,
        info.name,
        info.control,
        report.cycle_time_min,
        args.out.display()
    ))
}

fn json<T: Serialize>(v: &T) -> Result<String, String> {
    serde_json::to_string_pretty(v)
        .map(|s| s + "\n")
        .map_err(|e| e.to_string())
}

/// Writes the files into a temporary directory beside `out`, then swaps it
/// in: a failure leaves `out` as it was and no half-written file.
pub fn write_atomically(out: &Path, files: &[(String, Vec<u8>)]) -> Result<(), String> {
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    };
    let base = out
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| format!("{}: not a directory name", out.display()))?;
    std::fs::create_dir_all(&parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    let tmp = parent.join(format!(".{base}.tmp-{}", std::process::id()));
    let old = parent.join(format!(".{base}.old-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    let result = (|| {
        std::fs::create_dir(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
        for (name, text) in files {
            let p = tmp.join(name);
            std::fs::write(&p, text).map_err(|e| format!("{}: {e}", p.display()))?;
        }
        if out.exists() {
            std::fs::rename(out, &old).map_err(|e| format!("{}: {e}", out.display()))?;
        }
        std::fs::rename(&tmp, out).map_err(|e| {
            let _ = std::fs::rename(&old, out);
            format!("{}: {e}", out.display())
        })?;
        let _ = std::fs::remove_dir_all(&old);
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}

/// The part's bodies from `fn part(p)`: a profile, or a map of named
/// profiles.
fn part_profiles(
    family: &Family,
    values: &BTreeMap<String, ParamValue>,
) -> Result<Vec<(String, pilgrim_kernel::Profile)>, String> {
    let d = family
        .call_with_params("part", values)
        .map_err(|e| e.to_string())?;
    let shape = || {
        format!(
            "{}: fn part(p) must return a profile or a map of named profiles",
            family.file()
        )
    };
    let profiles: Vec<(String, pilgrim_kernel::Profile)> =
        if let Some(p) = d.clone().try_cast::<pilgrim_kernel::Profile>() {
            vec![("part".into(), p)]
        } else {
            let map = d.try_cast::<rhai::Map>().ok_or_else(shape)?;
            map.into_iter()
                .map(|(k, v)| {
                    v.try_cast::<pilgrim_kernel::Profile>()
                        .map(|p| (k.to_string(), p))
                        .ok_or_else(shape)
                })
                .collect::<Result<_, _>>()?
        };
    Ok(profiles)
}

/// Each profile turned about Z into a solid.
fn part_meshes(
    family: &Family,
    profiles: &[(String, pilgrim_kernel::Profile)],
    tol: f64,
) -> Result<Vec<(String, pilgrim_kernel::mesh::TriMesh)>, String> {
    profiles
        .iter()
        .map(|(name, p)| {
            pilgrim_kernel::mesh::body_of_revolution(p, tol)
                .map(|m| (name.clone(), m))
                .map_err(|e| format!("{}: part '{name}': {e}", family.file()))
        })
        .collect()
}

/// `pilgrim export DIR --block N`: the scene of a finished run placed at
/// another block (the tool's STL, `scene.glb`, and the report's block).
pub fn export(
    dir: &Path,
    block: Option<usize>,
    formats: crate::scene::Formats,
) -> Result<String, String> {
    let read = |name: &str| {
        std::fs::read_to_string(dir.join(name))
            .map_err(|e| format!("{}: {e}", dir.join(name).display()))
    };
    let mut report: Report =
        serde_json::from_str(&read("report.json")?).map_err(|e| format!("report.json: {e}"))?;
    let program: AxisProgram =
        serde_json::from_str(&read("program.json")?).map_err(|e| format!("program.json: {e}"))?;
    let toolpath: Toolpath =
        serde_json::from_str(&read("toolpath.json")?).map_err(|e| format!("toolpath.json: {e}"))?;
    if report.bodies.is_empty() {
        return Err(format!(
            "{}: the run has no 3-D models (its family has no fn part(p))",
            dir.display()
        ));
    }
    let machine = machines::open(&report.machine_spec)?;
    let index = match block {
        Some(0) => return Err("--block counts blocks from 1".into()),
        Some(n) => n - 1,
        None => crate::scene::default_pose_block(&toolpath.passes),
    };
    let parts = report
        .bodies
        .iter()
        .filter(|b| b.kind == "part")
        .map(|b| {
            pilgrim_kernel::mesh::read_stl(&dir.join(&b.file))
                .map(|m| (b.name.clone(), m))
                .map_err(|e| e.to_string())
        })
        .collect::<Result<Vec<_>, _>>()?;
    let pose = crate::scene::tool_pose(&program, machine.as_ref(), &toolpath.tool, index)?;
    let tool = crate::scene::tool_mesh(&toolpath.tool, report.tolerance_mm)?;
    let others =
        crate::scene::machine_bodies(&machine.info().name, &program, index, report.tolerance_mm)?;
    let (files, bodies) = crate::scene::files(&parts, tool, pose, others, formats)?;
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
    all.push(("report.json".into(), json(&report)?.into_bytes()));
    for (name, bytes) in &all {
        write_file(&dir.join(name), bytes)?;
    }
    Ok(format!(
        "{}: the scene placed at block {}",
        dir.display(),
        index + 1
    ))
}

/// Writes one file through a temporary file and a rename.
pub fn write_file(path: &Path, text: &[u8]) -> Result<(), String> {
    let tmp = path.with_extension(format!("tmp-{}", std::process::id()));
    std::fs::write(&tmp, text).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}
