//! `pilgrim compensate`: the kernel's [`job::compensate`], its files
//! written atomically into the output directory (or, where the corrected
//! run fails its checks, its diagnostic beside it, no program).

use pilgrim_kernel::catalog::Catalog;
use pilgrim_kernel::job::{self, CompensateOptions};
use pilgrim_kernel::script::Limits;
use std::path::{Path, PathBuf};

/// What `compensate` was asked.
pub struct CompensateArgs {
    pub dir: PathBuf,
    pub measured: PathBuf,
    pub gain: f64,
    pub uncertainty: f64,
    pub limit: f64,
    pub columns: Vec<(String, String)>,
    pub out: PathBuf,
    pub script_seconds: f64,
    pub run_seconds: f64,
}

/// Runs `pilgrim compensate`: see [`job::compensate`].
pub fn compensate(args: &CompensateArgs, catalog: &Catalog) -> Result<String, String> {
    crate::run::positive_seconds(args.script_seconds, args.run_seconds)?;
    pilgrim_kernel::output::apart(&args.out, &args.dir).map_err(|e| e.to_string())?;
    let _held = pilgrim_kernel::output::DirLock::take(&args.out, "pilgrim compensate")
        .map_err(|e| e.to_string())?;
    pilgrim_kernel::budget::with_limit(args.run_seconds, "the compensation's", || {
        let table =
            pilgrim_kernel::profile::read_table(&args.measured).map_err(|e| e.to_string())?;
        let options = CompensateOptions {
            gain: args.gain,
            uncertainty: args.uncertainty,
            limit: args.limit,
            columns: args.columns.clone(),
            limits: Limits {
                max_seconds: args.script_seconds,
                ..Limits::default()
            },
        };
        let (out, c) = match job::compensate(&args.dir, catalog, &table, &options) {
            Ok(done) => done,
            Err(pilgrim_kernel::Error::Failed(failed)) => {
                return Err(crate::run::failed_run(
                    &args.out,
                    &failed,
                    "the corrected run",
                ));
            }
            Err(e) => return Err(e.to_string()),
        };
        pilgrim_kernel::output::write_dir(&args.out, &out.files).map_err(|e| e.to_string())?;
        Ok(format!(
            "{}: measured by {}: {}; {}; written to {}",
            c.run,
            c.measured_file,
            c.summary(),
            out.summary(),
            args.out.display()
        ))
    })
}

/// The default output directory: the run's, `-compensated` after it.
pub fn default_out(dir: &Path) -> PathBuf {
    let mut o = dir.as_os_str().to_owned();
    o.push("-compensated");
    PathBuf::from(o)
}
