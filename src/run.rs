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
    pub script: PathBuf,
    pub params: Option<PathBuf>,
    pub sets: Vec<(String, String)>,
    pub machine: Option<String>,
    pub out: PathBuf,
    pub quiet: bool,
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

/// Runs the job; on any error nothing is written and the previous output
/// directory is left as it was.
pub fn run(args: &RunArgs, catalog: &Catalog) -> Result<String, String> {
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
    let family =
        ScriptFamily::load(&args.script, &Limits::default(), &access).map_err(|e| e.to_string())?;
    let mut sources = Vec::new();
    if let Some(p) = &args.params {
        sources.push(ParamSource::Toml {
            label: p.display().to_string(),
            text: std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?,
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
        formats: args.formats,
    };
    let out = job::run(&family, &machine, &sources, &options, &mut |s| next(s))
        .map_err(|e| e.to_string())?;
    next("writing");
    write_atomically(&args.out, &out.files)?;
    bar.finish_and_clear();
    Ok(format!(
        "{}; written to {}",
        out.summary(),
        args.out.display()
    ))
}

/// `pilgrim export DIR --block N`: the run's scene placed at another block.
pub fn export(
    dir: &Path,
    catalog: &Catalog,
    block: Option<usize>,
    formats: Formats,
) -> Result<String, String> {
    let e = job::export(dir, catalog, block, formats).map_err(|e| e.to_string())?;
    for (name, bytes) in &e.files {
        write_file(&dir.join(name), bytes)?;
    }
    Ok(format!(
        "{}: the scene placed at block {}",
        dir.display(),
        e.block
    ))
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

/// Writes one file through a temporary file and a rename.
pub fn write_file(path: &Path, text: &[u8]) -> Result<(), String> {
    let tmp = path.with_extension(format!("tmp-{}", std::process::id()));
    std::fs::write(&tmp, text).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}
