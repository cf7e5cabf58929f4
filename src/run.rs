//! `pilgrim run`, `pilgrim verify` and `pilgrim export`: the kernel's job,
//! its files written atomically.

use indicatif::{ProgressBar, ProgressStyle};
use pilgrim_kernel::catalog::Catalog;
use pilgrim_kernel::job::{self, Formats, JobOptions};
use pilgrim_kernel::output::DirLock;
use pilgrim_kernel::params::ParamSource;
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::PartFamily;
use std::path::{Path, PathBuf};

/// What `run` was asked.
pub struct RunArgs {
    pub formats: Formats,
    pub pose_block: Option<usize>,
    pub mesh_tolerance: f64,
    pub step_tolerance: f64,
    pub script: PathBuf,
    pub params: Option<PathBuf>,
    pub sets: Vec<(String, String)>,
    pub machine: Option<String>,
    pub out: PathBuf,
    pub quiet: bool,
    pub script_seconds: f64,
    pub script_memory_mb: u64,
    pub run_seconds: f64,
    pub program_number: Option<u32>,
    pub also_post: Vec<String>,
}

/// A progress bar over the run's stages (hidden with --quiet).
fn progress(quiet: bool) -> ProgressBar {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(job::STAGES.len() as u64 + 2)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// Runs the job. A run that fails a check or its verification writes its
/// diagnostic (report, page, plots, scene; no program) where
/// [`pilgrim_kernel::output::failed_dir`] says; on any other error nothing
/// is written and the previous output directory is left as it was.
pub fn run(args: &RunArgs, catalog: &Catalog) -> Result<String, String> {
    positive_seconds(args.script_seconds, args.run_seconds)?;
    let _held = DirLock::take(&args.out, "pilgrim run").map_err(|e| e.to_string())?;
    pilgrim_kernel::budget::with_limit(args.run_seconds, "the run's", || run_within(args, catalog))
}

/// `--script-seconds` and `--run-seconds`, each refused unless positive.
pub(crate) fn positive_seconds(script: f64, run: f64) -> Result<(), String> {
    for (flag, v) in [("--script-seconds", script), ("--run-seconds", run)] {
        if !(v > 0.0) {
            return Err(format!("{flag} {v} must be > 0"));
        }
    }
    Ok(())
}

/// [`run`] within the run's time limit.
fn run_within(args: &RunArgs, catalog: &Catalog) -> Result<String, String> {
    let bar = progress(args.quiet);
    let next = |what: &str| {
        bar.set_message(what.to_owned());
        bar.inc(1);
    };
    next("reading the family");
    let limits = Limits {
        max_seconds: args.script_seconds,
        max_memory_mb: args.script_memory_mb,
        ..Limits::default()
    };
    let read = pilgrim_kernel::script::ReadLog::default();
    let family = load_family(
        &args.script,
        args.params.as_deref(),
        &limits,
        Vec::new(),
        &read,
    )?;
    let sources = sources(Vec::new(), args.params.as_deref(), &args.sets)?;
    let machine = catalog
        .open(&machine_spec(args.machine.as_deref(), &family)?)
        .map_err(|e| e.to_string())?;
    let options = JobOptions {
        program_name: args
            .script
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("pilgrim")
            .to_owned(),
        pose_block: args.pose_block,
        mesh_tolerance: args.mesh_tolerance,
        step_tolerance: args.step_tolerance,
        formats: args.formats,
        program_number: args.program_number,
        also_post: args.also_post.clone(),
        program_file: None,
        program_dir: None,
        // The script, its tables and the machine file beside the run's
        // files, for `verify DIR` and `compensate`.
        keep: Some(job::Keep {
            script: args.script.clone(),
            tables: read,
        }),
        offsets: None,
        corrected_by: None,
    };
    let out = match job::run(&family, &machine, &sources, &options, &mut |s| next(s)) {
        Ok(out) => out,
        Err(pilgrim_kernel::Error::Failed(failed)) => {
            bar.finish_and_clear();
            return Err(failed_run(&args.out, &failed, "the run"));
        }
        Err(e) => return Err(e.to_string()),
    };
    next("writing");
    pilgrim_kernel::output::write_dir(&args.out, &out.files).map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    let mut said = format!("{}; written to {}", out.summary(), args.out.display());
    for w in &out.report.verdict.warnings {
        said += &format!("\nwarning: {}", w.message);
    }
    Ok(said)
}

/// Writes what a run that failed a check or its verification leaves
/// (marked FAILED, no program) where the user looks, `out` or beside it
/// when an earlier good output is there; the message naming it. `what`
/// names the run (`the run`, `the corrected run`).
pub(crate) fn failed_run(
    out: &Path,
    failed: &pilgrim_kernel::job::FailedRun,
    what: &str,
) -> String {
    let message = failed.report.verdict.message();
    let dir = match pilgrim_kernel::output::write_failed(out, &failed.files) {
        Ok(dir) => dir,
        Err(e) => return format!("{message}\nthe diagnostic report could not be written: {e}"),
    };
    let kept = if dir != out {
        format!(
            "; {} (the last run that succeeded) is as it was",
            out.display()
        )
    } else {
        String::new()
    };
    format!(
        "{message}\n{what} FAILED: no program was written; see {}{kept}",
        dir.join("report.html").display()
    )
}

/// The family of `script`, reading files (its tables) beside `params`.
fn load_family(
    script: &Path,
    params: Option<&Path>,
    limits: &Limits,
    tables: Vec<(String, String)>,
    read: &pilgrim_kernel::script::ReadLog,
) -> Result<ScriptFamily, String> {
    let mut access = Access {
        tables,
        read: read.clone(),
        ..Access::default()
    };
    if let Some(dir) = params.and_then(Path::parent) {
        access.input_dirs.push(if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir.to_owned()
        });
    }
    ScriptFamily::load(script, limits, &access).map_err(|e| e.to_string())
}

/// `first`, then the parameters of the `params` file, then the `sets`.
fn sources(
    mut first: Vec<ParamSource>,
    params: Option<&Path>,
    sets: &[(String, String)],
) -> Result<Vec<ParamSource>, String> {
    if let Some(p) = params {
        first.push(ParamSource::Toml {
            label: p.display().to_string(),
            text: pilgrim_kernel::files::read_text(p, pilgrim_kernel::files::MAX_TEXT_BYTES)
                .map_err(|e| e.to_string())?,
        });
    }
    first.push(ParamSource::Pairs {
        label: "--set".into(),
        pairs: sets.to_vec(),
    });
    Ok(first)
}

/// The machine named on the command line, else the family's default.
fn machine_spec(given: Option<&str>, family: &ScriptFamily) -> Result<String, String> {
    match given {
        Some(m) => Ok(m.to_owned()),
        None => family
            .default_machine()
            .map_err(|e| e.to_string())?
            .ok_or_else(|| {
                pilgrim_kernel::Error::NoMachine {
                    family: family.name().to_owned(),
                }
                .to_string()
            }),
    }
}

/// What `verify` was asked.
pub struct VerifyArgs {
    pub target: PathBuf,
    pub family: Option<PathBuf>,
    pub machine: Option<String>,
    pub params: Option<PathBuf>,
    pub sets: Vec<(String, String)>,
    pub offsets: Option<PathBuf>,
    pub out: PathBuf,
    pub script_seconds: f64,
    pub run_seconds: f64,
}

/// `pilgrim verify`: a run's program (`target` its output directory) or a
/// program file, read as its control reads it and verified against the
/// family. The report goes to `args.out`, FAILED where the program fails
/// (then the error names the block).
pub fn verify(args: &VerifyArgs, catalog: &Catalog) -> Result<String, String> {
    positive_seconds(args.script_seconds, args.run_seconds)?;
    pilgrim_kernel::output::apart(&args.out, &args.target).map_err(|e| e.to_string())?;
    let _held = DirLock::take(&args.out, "pilgrim verify").map_err(|e| e.to_string())?;
    pilgrim_kernel::budget::with_limit(args.run_seconds, "the verification's", || {
        verify_within(args, catalog)
    })
}

/// [`verify`] within its time limit.
fn verify_within(args: &VerifyArgs, catalog: &Catalog) -> Result<String, String> {
    let limits = Limits {
        max_seconds: args.script_seconds,
        ..Limits::default()
    };
    let (family, mut first, spec, program, file, report_label) = if args.target.is_dir() {
        // A run's directory: its program in the control's dialect, its
        // family, parameters and (built-in) machine as its report says.
        let run = pilgrim_kernel::output::RunDir::open(&args.target).map_err(|e| e.to_string())?;
        let report: job::Report = serde_json::from_str(
            &run.read_text("report.json", pilgrim_kernel::files::MAX_DATA_BYTES)
                .map_err(|e| e.to_string())?,
        )
        .map_err(|e| format!("{}/report.json: {e}", args.target.display()))?;
        let shown = args.target.display().to_string();
        // The script and machine the run kept (an older run's: the paths
        // its report names).
        let kept = job::kept::kept(
            &run,
            &report,
            args.family.as_deref(),
            args.machine.as_deref(),
            &shown,
        )
        .map_err(|e| e.to_string())?;
        let script = match (&kept, &args.family) {
            (Some((s, _)), _) => s.clone(),
            (None, Some(f)) => f.clone(),
            (None, None) if Path::new(&report.script).is_file() => PathBuf::from(&report.script),
            (None, None) => {
                return Err(format!(
                    "{}: the run's family '{}' (its report names it from where the run was made) is not there: name its script with --family",
                    args.target.display(),
                    report.script
                ))
            }
        };
        // A compensated run's correction, read beside its files.
        let tables = job::run_correction(&run, &report)
            .map_err(|e| e.to_string())?
            .into_iter()
            .collect();
        let family = load_family(
            &script,
            args.params.as_deref(),
            &limits,
            tables,
            &Default::default(),
        )?;
        let label = format!("{}/report.json", args.target.display());
        let first = vec![report.params_source(&label).map_err(|e| e.to_string())?];
        let spec = match kept.and_then(|k| k.1) {
            Some(spec) => spec,
            None => job::run_machine(&report, catalog, args.machine.as_deref(), &shown)
                .map_err(|e| e.to_string())?,
        };
        let name = pilgrim_kernel::program::post::dialect(&report.control)
            .map(|d| format!("program.{}", d.extension))
            .ok_or_else(|| {
                format!(
                    "{label}: the control '{}' is not a dialect pilgrim reads",
                    report.control
                )
            })?;
        let text = run
            .read_text(&name, pilgrim_kernel::files::MAX_DATA_BYTES)
            .map_err(|e| e.to_string())?;
        (
            family,
            first,
            spec,
            text,
            args.target.join(&name),
            Some(label),
        )
    } else {
        let script = args.family.as_ref().ok_or_else(|| {
            format!(
                "{}: a program file is verified against a family: name its script with --family",
                args.target.display()
            )
        })?;
        let family = load_family(
            script,
            args.params.as_deref(),
            &limits,
            Vec::new(),
            &Default::default(),
        )?;
        let spec = machine_spec(args.machine.as_deref(), &family)?;
        let text =
            pilgrim_kernel::files::read_text(&args.target, pilgrim_kernel::files::MAX_DATA_BYTES)
                .map_err(|e| e.to_string())?;
        (family, Vec::new(), spec, text, args.target.clone(), None)
    };
    first = sources(first, args.params.as_deref(), &args.sets)?;
    let machine = catalog.open(&spec).map_err(|e| e.to_string())?;
    // A run's report says what the run was asked; a tolerance looser than
    // the family's is taken only from this command's own line.
    if let Some(label) = &report_label {
        let (values, origins) =
            job::params_traced(&family, &machine, &first).map_err(|e| e.to_string())?;
        for s in family.params().iter().filter(|s| s.tolerance) {
            let (Some(v), Some(d)) = (
                values.get(&s.name).and_then(|v| v.as_number()),
                s.default.as_number(),
            ) else {
                continue;
            };
            if v > d && origins.get(&s.name) == Some(label) {
                return Err(format!(
                    "{label}: {} = {v} {} is looser than the family's {d}: a verification takes a looser tolerance only from its own command line (--set {}={v}, or --params), never from a file a run wrote",
                    s.name, s.unit, s.name
                ));
            }
        }
    }
    // A program file is read in its machine's control's dialect: one whose
    // extension is another dialect's was written for another control.
    let control = &machine.kinematics.info().control;
    let ext = file.extension().and_then(|e| e.to_str()).unwrap_or("");
    let dialects = pilgrim_kernel::program::post::DIALECTS;
    if let (Some(theirs), Some(ours)) = (
        dialects
            .iter()
            .find(|d| d.extension.eq_ignore_ascii_case(ext)),
        pilgrim_kernel::program::post::dialect(control),
    ) {
        // Two dialects may share an extension (Fanuc's and Haas's .nc).
        if !ours.extension.eq_ignore_ascii_case(ext) {
            return Err(format!(
                "{}: a .{ext} file is a {} program, and machine {}'s control reads {} (.{}): verify it on a machine whose control is {} (a machine file's control = \"{}\")",
                file.display(),
                theirs.name,
                machine.kinematics.info().name,
                ours.name,
                ours.extension,
                theirs.name,
                theirs.name
            ));
        }
    }
    let offsets = match &args.offsets {
        Some(f) => {
            let text = pilgrim_kernel::files::read_text(f, pilgrim_kernel::files::MAX_TEXT_BYTES)
                .map_err(|e| e.to_string())?;
            let o = pilgrim_kernel::program::offsets::Offsets::from_toml_str(
                &text,
                &pilgrim_kernel::files::shown_path(f),
            )
            .map_err(|e| e.to_string())?;
            let axes: Vec<char> = (machine.kinematics.info().axes.iter())
                .filter_map(|a| a.name.chars().next())
                .collect();
            if let Some(a) = o.unknown_axes(&axes).first() {
                return Err(format!(
                    "{}: {a} names an axis the machine {} has not",
                    pilgrim_kernel::files::shown_path(f),
                    machine.kinematics.info().name
                ));
            }
            Some(o)
        }
        None => None,
    };
    let options = JobOptions {
        program_name: "verify".into(),
        program_file: Some(pilgrim_kernel::files::shown_path(&file)),
        offsets,
        program_dir: file.parent().map(std::path::Path::to_path_buf),
        ..JobOptions::default()
    };
    let what = args.target.display();
    match job::verify(&family, &machine, &first, &program, &options, &mut |_| {}) {
        Ok(out) => {
            pilgrim_kernel::output::write_dir(&args.out, &out.files).map_err(|e| e.to_string())?;
            if out.report.verdict.status == pilgrim_kernel::verdict::Status::NotVerified {
                return Err(format!(
                    "{what}: {}; report in {}",
                    job::NOT_VERIFIED,
                    args.out.display()
                ));
            }
            let mut said = format!(
                "{what}: verified{}; report in {}",
                out.summary()
                    .split_once(", about")
                    .map_or(String::new(), |(_, s)| format!(": about{s}")),
                args.out.display()
            );
            for w in &out.report.verdict.warnings {
                said += &format!("\nwarning: {}", w.message);
            }
            let set = out.report.not_defaults();
            if !set.is_empty() {
                said += &format!(
                    "\nverified with parameters not the family's defaults: {}",
                    set.join(", ")
                );
            }
            Ok(said)
        }
        Err(pilgrim_kernel::Error::Failed(failed)) => {
            let message = failed.report.verdict.message();
            let dir = pilgrim_kernel::output::write_failed(&args.out, &failed.files)
                .map_err(|e| format!("{message}\nthe report could not be written: {e}"))?;
            Err(format!(
                "{what}: {message}\nthe program FAILED its verification; see {}",
                dir.join("report.html").display()
            ))
        }
        Err(e) => Err(format!("{what}: {e}")),
    }
}

/// `pilgrim export DIR --block N`: the run's scene placed at another block.
pub fn export(
    dir: &Path,
    catalog: &Catalog,
    machine: Option<&str>,
    block: Option<usize>,
    formats: Formats,
) -> Result<String, String> {
    let _held = DirLock::take(dir, "pilgrim export").map_err(|e| e.to_string())?;
    let run = pilgrim_kernel::output::RunDir::open(dir).map_err(|e| e.to_string())?;
    let e = job::export(&run, catalog, machine, block, formats).map_err(|e| e.to_string())?;
    pilgrim_kernel::output::update_dir(&run, &e.files).map_err(|e| e.to_string())?;
    Ok(format!(
        "{}: the scene placed at block {}",
        dir.display(),
        e.block
    ))
}
