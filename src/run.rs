//! `pilgrim run` and `pilgrim export`: the kernel's job, its files written
//! atomically.

use indicatif::{ProgressBar, ProgressStyle};
use pilgrim_kernel::catalog::Catalog;
use pilgrim_kernel::job::{self, Formats, JobOptions};
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
    for (flag, v) in [
        ("--script-seconds", args.script_seconds),
        ("--run-seconds", args.run_seconds),
    ] {
        if !(v > 0.0) {
            return Err(format!("{flag} {v} must be > 0"));
        }
    }
    pilgrim_kernel::budget::with_limit(args.run_seconds, "the run's", || run_within(args, catalog))
}

/// [`run`] within the run's time limit.
fn run_within(args: &RunArgs, catalog: &Catalog) -> Result<String, String> {
    let bar = progress(args.quiet);
    let next = |what: &str| {
        bar.set_message(what.to_owned());
        bar.inc(1);
    };
    next("reading the family");
    let mut access = Access::default();
    if let Some(dir) = args.params.as_ref().and_then(|p| p.parent()) {
        access.input_dirs.push(if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir.to_owned()
        });
    }
    let limits = Limits {
        max_seconds: args.script_seconds,
        max_memory_mb: args.script_memory_mb,
        ..Limits::default()
    };
    let family = ScriptFamily::load(&args.script, &limits, &access).map_err(|e| e.to_string())?;
    let mut sources = Vec::new();
    if let Some(p) = &args.params {
        sources.push(ParamSource::Toml {
            label: p.display().to_string(),
            text: pilgrim_kernel::files::read_text(p, pilgrim_kernel::files::MAX_TEXT_BYTES)
                .map_err(|e| e.to_string())?,
        });
    }
    sources.push(ParamSource::Pairs {
        label: "--set".into(),
        pairs: args.sets.clone(),
    });
    let spec = match &args.machine {
        Some(m) => m.clone(),
        None => family
            .default_machine()
            .map_err(|e| e.to_string())?
            .ok_or_else(|| {
                pilgrim_kernel::Error::NoMachine {
                    family: family.name().to_owned(),
                }
                .to_string()
            })?,
    };
    let machine = catalog.open(&spec).map_err(|e| e.to_string())?;
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
    };
    let out = match job::run(&family, &machine, &sources, &options, &mut |s| next(s)) {
        Ok(out) => out,
        Err(pilgrim_kernel::Error::Failed(failed)) => {
            // What failed is written where the user looks, marked FAILED
            // and with no program; an earlier good output stays.
            bar.finish_and_clear();
            let message = failed.report.verdict.message();
            let dir =
                pilgrim_kernel::output::write_failed(&args.out, &failed.files).map_err(|e| {
                    format!("{message}\nthe diagnostic report could not be written: {e}")
                })?;
            let kept = if dir != args.out {
                format!(
                    "; {} (the last run that succeeded) is as it was",
                    args.out.display()
                )
            } else {
                String::new()
            };
            return Err(format!(
                "{message}\nthe run FAILED: no program was written; see {}{kept}",
                dir.join("report.html").display()
            ));
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

/// `pilgrim export DIR --block N`: the run's scene placed at another block.
pub fn export(
    dir: &Path,
    catalog: &Catalog,
    machine: Option<&str>,
    block: Option<usize>,
    formats: Formats,
) -> Result<String, String> {
    let run = pilgrim_kernel::output::RunDir::open(dir).map_err(|e| e.to_string())?;
    let e = job::export(&run, catalog, machine, block, formats).map_err(|e| e.to_string())?;
    pilgrim_kernel::output::update_dir(&run, &e.files).map_err(|e| e.to_string())?;
    Ok(format!(
        "{}: the scene placed at block {}",
        dir.display(),
        e.block
    ))
}
