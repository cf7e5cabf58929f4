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
    pub script: PathBuf,
    pub params: Option<PathBuf>,
    pub sets: Vec<(String, String)>,
    pub machine: Option<String>,
    pub out: PathBuf,
    pub quiet: bool,
}

#[derive(Serialize)]
struct ReportParam {
    value: ParamValue,
    unit: String,
}

#[derive(Serialize)]
struct Report {
    pilgrim: &'static str,
    script: String,
    machine: String,
    control: String,
    parameters: BTreeMap<String, ReportParam>,
    passes: usize,
    points: usize,
    blocks: usize,
    cycle_time_min: f64,
    files: Vec<String>,
    checks: Vec<Check>,
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
        let path = if linear > 1e-4 {
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
    let stages = Stages::new(args.quiet, 6);
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
    let values = family
        .resolve(
            file_text.as_ref().map(|(n, t)| (n.as_str(), t.as_str())),
            &args.sets,
        )
        .map_err(|e| e.to_string())?;
    let machine_spec = match &args.machine {
        Some(m) => m.clone(),
        None => family.default_machine().map_err(|e| e.to_string())?.ok_or_else(|| {
            format!("{}: no machine given: use --machine, or define fn default_machine() in the family", family.file())
        })?,
    };
    let machine = machines::open(&machine_spec)?;
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
    let mut files: Vec<(String, String)> = vec![
        ("toolpath.json".into(), json(&toolpath)?),
        ("program.json".into(), json(&program)?),
        (control_file, control_text),
        ("program.cld".into(), cld_text),
    ];
    let report = Report {
        pilgrim: env!("CARGO_PKG_VERSION"),
        script: args.script.display().to_string(),
        machine: info.name.clone(),
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
        points: toolpath.point_count(),
        blocks: program.blocks.len(),
        cycle_time_min: (cycle_time(&program, info) * 1e4).round() / 1e4,
        files: files
            .iter()
            .map(|f| f.0.clone())
            .chain(["report.json".to_owned()])
            .collect(),
        checks,
    };
    files.push(("report.json".into(), json(&report)?));
    stages.next("writing");
    write_atomically(&args.out, &files)?;
    stages.bar.finish_and_clear();
    Ok(format!(
        "{}: {} passes, {} blocks for {} ({}), about {:.1} min; written to {}",
        family.file(),
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
pub fn write_atomically(out: &Path, files: &[(String, String)]) -> Result<(), String> {
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

/// Writes one file through a temporary file and a rename.
pub fn write_file(path: &Path, text: &str) -> Result<(), String> {
    let tmp = path.with_extension(format!("tmp-{}", std::process::id()));
    std::fs::write(&tmp, text).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}
