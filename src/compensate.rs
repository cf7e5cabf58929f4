//! `pilgrim compensate`: a run's finished part measured, the error fitted
//! within the measurement's uncertainty, the target moved against it, and
//! the job run again on the corrected target. The new run is verified as
//! usual, against the corrected target; `compensation.json` beside its
//! files holds the measurement, the nominal, the fit, the correction and
//! the program's changes.

use crate::run::{load_family_with, progress_free};
use pilgrim_kernel::catalog::Catalog;
use pilgrim_kernel::compensate::{fit_error, read_measured};
use pilgrim_kernel::job::{self, JobOptions};
use pilgrim_kernel::params::ParamSource;
use pilgrim_kernel::program::{pass_blocks, AxisProgram, ProgramPass};
use pilgrim_kernel::script::Limits;
use pilgrim_kernel::toolpath::Toolpath;
use pilgrim_kernel::PartFamily;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The parameter a family takes its correction by: a table's name.
const CORRECTION: &str = "correction";
/// The correction's table, beside the new run's files.
const CORRECTION_FILE: &str = "correction.csv";
/// The correction's places along the part.
const GRID: usize = 400;

/// What `compensate` was asked.
pub struct CompensateArgs {
    pub dir: PathBuf,
    pub measured: PathBuf,
    pub gain: f64,
    pub uncertainty: f64,
    pub limit: f64,
    pub out: PathBuf,
    pub script_seconds: f64,
    pub run_seconds: f64,
}

/// One measured place as `compensation.json` lists it.
#[derive(Serialize)]
struct Place {
    at: f64,
    measured: f64,
    nominal: f64,
    error: f64,
    fitted: f64,
    correction: f64,
}

/// `compensation.json`.
#[derive(Serialize)]
struct Compensation {
    run: String,
    measured_file: String,
    column: String,
    coordinate: &'static str,
    quantity: &'static str,
    uncertainty_mm: f64,
    gain: f64,
    limit_mm: f64,
    smooth: f64,
    rms_residual_mm: f64,
    max_error_mm: f64,
    max_correction_mm: f64,
    places: Vec<Place>,
    program: ProgramChange,
}

/// How the program changed: its text (a line diff, `similar`: lines
/// kept, added and removed), and how far its path moved. Lines are not
/// compared word by word: a corrected target may place its blocks anew
/// (the mandrel's are spaced to its profile), so which block became which
/// is not known; the path is.
#[derive(Serialize)]
struct ProgramChange {
    file: String,
    lines_kept: usize,
    lines_added: usize,
    lines_removed: usize,
    /// How far the tool's path moved, per axis: each block of the
    /// corrected program against the original's path in the same pass
    /// (its nearest point on the pass's polyline in the axes' space); none
    /// where the passes or axes differ.
    path_moved: Option<std::collections::BTreeMap<String, f64>>,
}

/// Runs `pilgrim compensate`; see the module's docs.
pub fn compensate(args: &CompensateArgs, catalog: &Catalog) -> Result<String, String> {
    crate::run::positive_seconds(args.script_seconds, args.run_seconds)?;
    pilgrim_kernel::budget::with_limit(args.run_seconds, "the compensation's", || {
        compensate_within(args, catalog)
    })
}

fn compensate_within(args: &CompensateArgs, catalog: &Catalog) -> Result<String, String> {
    let shown = args.dir.display().to_string();
    let run = pilgrim_kernel::output::RunDir::open(&args.dir).map_err(|e| e.to_string())?;
    let limit = pilgrim_kernel::files::MAX_DATA_BYTES;
    let report: job::Report = serde_json::from_str(
        &run.read_text("report.json", limit)
            .map_err(|e| e.to_string())?,
    )
    .map_err(|e| format!("{shown}/report.json: {e}"))?;
    let script = PathBuf::from(&report.script);
    if !script.is_file() {
        return Err(format!(
            "{shown}: the run's family '{}' is not there (its report names it from where the run was made)",
            report.script
        ));
    }
    let limits = Limits {
        max_seconds: args.script_seconds,
        ..Limits::default()
    };
    let family = load_family_with(&script, None, &limits, Vec::new())?;
    if !family.params().iter().any(|p| p.name == CORRECTION) {
        return Err(format!(
            "{}: the family takes no correction: its script declares no `{CORRECTION}` parameter (a table's name)",
            script.display()
        ));
    }
    let label = format!("{shown}/report.json");
    let base = report.params_source(&label)?;
    let spec = job::run_machine(&report, catalog, None, &shown).map_err(|e| e.to_string())?;
    let machine = catalog.open(&spec).map_err(|e| e.to_string())?;
    // The nominal: the run's parameters with no correction.
    let nominal_sources = vec![
        base.clone(),
        ParamSource::Pairs {
            label: "the nominal".into(),
            pairs: vec![(CORRECTION.into(), String::new())],
        },
    ];
    let params = job::params_on(&family, &machine, &nominal_sources).map_err(|e| e.to_string())?;
    let nominal = family
        .verification(&params)
        .map_err(|e| e.to_string())?
        .and_then(|v| v.nominal())
        .ok_or_else(|| {
            format!(
                "{}: the family's verification takes no measurement of its part",
                script.display()
            )
        })?;
    // The measurement against it.
    let table = pilgrim_kernel::profile::read_table(&args.measured).map_err(|e| e.to_string())?;
    let m = read_measured(&table, &nominal.spec()).map_err(|e| e.to_string())?;
    let at_nominal = nominal
        .profile
        .eval_many(&m.at)
        .map_err(|e| format!("{}: the nominal: {e}", m.file))?;
    let error: Vec<f64> = m
        .value
        .iter()
        .zip(&at_nominal)
        .map(|(v, n)| v - n)
        .collect();
    let fit = fit_error(&m.at, &error, args.uncertainty).map_err(|e| e.to_string())?;
    let (from, to) = nominal.range;
    let grid: Vec<f64> = (0..=GRID)
        .map(|i| from + (to - from) * i as f64 / GRID as f64)
        .collect();
    let coordinate = nominal.coordinate.trim_end_matches("_mm");
    let correction = fit
        .correction(&grid, args.gain, args.limit, coordinate)
        .map_err(|e| format!("{}: {e}", m.file))?;
    let mut csv = String::from("z_mm,dr_mm\n");
    for (z, d) in correction.z().iter().zip(correction.x()) {
        csv += &format!("{z:.6},{d:.9}\n");
    }
    // The corrected run.
    let family = load_family_with(
        &script,
        None,
        &limits,
        vec![(CORRECTION_FILE.into(), csv.clone())],
    )?;
    let sources = vec![
        base,
        ParamSource::Pairs {
            label: "compensate".into(),
            pairs: vec![(CORRECTION.into(), CORRECTION_FILE.into())],
        },
    ];
    let options = JobOptions {
        program_name: script
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("pilgrim")
            .to_owned(),
        ..JobOptions::default()
    };
    let fitted = fit.at(&m.at).map_err(|e| e.to_string())?;
    let program_file = pilgrim_kernel::program::post::dialect(&report.control)
        .map(|d| format!("program.{}", d.extension))
        .ok_or_else(|| {
            format!(
                "{label}: the control '{}' is not a dialect pilgrim reads",
                report.control
            )
        })?;
    let before = run
        .read_text(&program_file, limit)
        .map_err(|e| e.to_string())?;
    let read_json = |name: &str| -> Result<String, String> {
        run.read_text(name, limit).map_err(|e| e.to_string())
    };
    let old_program: AxisProgram = serde_json::from_str(&read_json("program.json")?)
        .map_err(|e| format!("{shown}/program.json: {e}"))?;
    let old_toolpath: Toolpath = serde_json::from_str(&read_json("toolpath.json")?)
        .map_err(|e| format!("{shown}/toolpath.json: {e}"))?;
    let out = match job::run(&family, &machine, &sources, &options, &mut progress_free) {
        Ok(out) => out,
        Err(pilgrim_kernel::Error::Failed(failed)) => {
            let message = failed.report.verdict.message();
            let dir = pilgrim_kernel::output::write_failed(&args.out, &failed.files)
                .map_err(|e| format!("{message}\nthe report could not be written: {e}"))?;
            return Err(format!(
                "{message}\nthe corrected run FAILED: no program was written; see {}",
                dir.join("report.html").display()
            ));
        }
        Err(e) => return Err(e.to_string()),
    };
    let record = Compensation {
        run: shown.clone(),
        measured_file: m.file.clone(),
        column: m.column.clone(),
        coordinate: nominal.coordinate,
        quantity: nominal.quantity,
        uncertainty_mm: args.uncertainty,
        gain: args.gain,
        limit_mm: args.limit,
        smooth: fit.smooth,
        rms_residual_mm: fit.rms_residual,
        max_error_mm: error.iter().fold(0.0, |a: f64, e| a.max(e.abs())),
        max_correction_mm: correction.x().iter().fold(0.0, |a: f64, c| a.max(c.abs())),
        places: (0..m.at.len())
            .map(|i| Place {
                at: m.at[i],
                measured: m.value[i],
                nominal: at_nominal[i],
                error: error[i],
                fitted: fitted[i],
                correction: -args.gain * fitted[i],
            })
            .collect(),
        program: ProgramChange {
            path_moved: path_moved(
                &old_program,
                &pass_blocks(&old_program, &old_toolpath.passes),
                &out.program,
                &pass_blocks(&out.program, &out.toolpath.passes),
            ),
            ..change(
                &program_file,
                &before,
                &out.files
                    .iter()
                    .find(|(n, _)| *n == program_file)
                    .map(|(_, b)| String::from_utf8_lossy(b).into_owned())
                    .unwrap_or_default(),
            )
        },
    };
    let mut files = out.files.clone();
    files.push((CORRECTION_FILE.into(), csv.into_bytes()));
    files.push((
        "compensation.json".into(),
        (serde_json::to_string_pretty(&record).map_err(|e| e.to_string())? + "\n").into_bytes(),
    ));
    pilgrim_kernel::output::write_dir(&args.out, &files).map_err(|e| e.to_string())?;
    Ok(format!(
        "{shown}: measured {} places of {} ({}), the error up to {:.4} mm fitted within {} mm (RMS residual {:.4} mm); the target moved by up to {:.4} mm; {}; written to {}",
        m.at.len(),
        nominal.quantity,
        m.file,
        record.max_error_mm,
        args.uncertainty,
        fit.rms_residual,
        record.max_correction_mm,
        out.summary(),
        args.out.display()
    ))
}

/// The program's text changes from `before` to `after` (`file`'s).
fn change(file: &str, before: &str, after: &str) -> ProgramChange {
    use similar::{DiffTag, TextDiff};
    let mut c = ProgramChange {
        file: file.to_owned(),
        lines_kept: 0,
        lines_added: 0,
        lines_removed: 0,
        path_moved: None,
    };
    for op in TextDiff::from_lines(before, after).ops() {
        let (o, n) = (op.old_range().len(), op.new_range().len());
        match op.tag() {
            DiffTag::Equal => c.lines_kept += o,
            _ => {
                c.lines_removed += o;
                c.lines_added += n;
            }
        }
    }
    c
}

/// How far each axis of `after`'s blocks stands from `before`'s path in
/// the same pass (see [`ProgramChange::path_moved`]).
fn path_moved(
    before: &AxisProgram,
    before_passes: &[ProgramPass],
    after: &AxisProgram,
    after_passes: &[ProgramPass],
) -> Option<std::collections::BTreeMap<String, f64>> {
    if before.axes != after.axes || before_passes.len() != after_passes.len() {
        return None;
    }
    let mut moved = vec![0.0f64; after.axes.len()];
    for (p, q) in before_passes.iter().zip(after_passes) {
        let line: Vec<&[f64]> = before
            .blocks
            .get(p.blocks.clone())?
            .iter()
            .map(|b| &b.values[..])
            .collect();
        for b in after.blocks.get(q.blocks.clone())? {
            // The nearest point of the polyline, segment by segment.
            let mut best: Option<(f64, Vec<f64>)> = None;
            for w in line
                .windows(2)
                .chain(line.get(..1).into_iter().filter(|_| line.len() == 1))
            {
                let (a, c) = (w[0], *w.get(1).unwrap_or(&w[0]));
                let d: Vec<f64> = a.iter().zip(c).map(|(a, c)| c - a).collect();
                let l2: f64 = d.iter().map(|x| x * x).sum();
                let t = if l2 > 0.0 {
                    (b.values
                        .iter()
                        .zip(a)
                        .zip(&d)
                        .map(|((v, a), d)| (v - a) * d)
                        .sum::<f64>()
                        / l2)
                        .clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let off: Vec<f64> = b
                    .values
                    .iter()
                    .zip(a)
                    .zip(&d)
                    .map(|((v, a), d)| v - a - t * d)
                    .collect();
                let dist: f64 = off.iter().map(|x| x * x).sum();
                if best.as_ref().is_none_or(|(bd, _)| dist < *bd) {
                    best = Some((dist, off));
                }
            }
            if let Some((_, off)) = best {
                for (m, o) in moved.iter_mut().zip(off) {
                    *m = m.max(o.abs());
                }
            }
        }
    }
    Some(
        after
            .axes
            .iter()
            .map(|a| a.name.clone())
            .zip(moved)
            .collect(),
    )
}

/// The default output directory: the run's, `-compensated` after it.
pub fn default_out(dir: &Path) -> PathBuf {
    let mut o = dir.as_os_str().to_owned();
    o.push("-compensated");
    PathBuf::from(o)
}
