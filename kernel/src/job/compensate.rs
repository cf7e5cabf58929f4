//! `pilgrim compensate`: a run's finished part measured, the error fitted
//! within the measurement's uncertainty, the target moved against it, and
//! the job run again on the corrected target ([`compensate`]). The new run
//! is verified as usual, against the corrected target; `compensation.json`
//! beside its files holds the measurement, the nominal, the fit, the
//! correction and the program's changes, `correction.csv` the correction
//! the family read.
//!
//! The family takes its correction by a parameter named [`CORRECTION`], a
//! table's name, and its verification says what a measurement holds and
//! its nominal ([`crate::family::Verifier::nominal`]); the run knows no
//! family by name.

use super::{params_on, run as run_job, run_machine, Annex, JobOptions, JobOutput, Report};
use crate::catalog::Catalog;
use crate::compensate::{fit_error, read_measured, within_limit};
use crate::error::Error;
use crate::output::RunDir;
use crate::params::ParamSource;
use crate::profile::Table;
use crate::program::{pass_blocks, AxisProgram, ProgramPass};
use crate::script::{Access, Limits, ScriptFamily};
use crate::toolpath::Toolpath;
use crate::PartFamily;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// The parameter a family takes its correction by: a table's name.
pub const CORRECTION: &str = "correction";
/// The correction's table, beside the new run's files.
pub const CORRECTION_FILE: &str = "correction.csv";
/// The correction's places along the part.
const GRID: usize = 400;

/// What `compensate` is asked besides the run and the measurement.
#[derive(Debug, Clone)]
pub struct CompensateOptions {
    /// The share of the measured error the target moves against (1: all).
    pub gain: f64,
    /// The measurement's uncertainty (mm): the fit's residual.
    pub uncertainty: f64,
    /// The largest correction accepted (mm).
    pub limit: f64,
    /// The family's script's limits.
    pub limits: Limits,
}

/// One measured place as `compensation.json` lists it.
#[derive(Debug, Clone, Serialize)]
pub struct Place {
    /// The coordinate (mm).
    pub at: f64,
    /// The quantity measured (the rows there averaged).
    pub measured: f64,
    /// The nominal there.
    pub nominal: f64,
    /// Measured minus nominal.
    pub error: f64,
    /// The fit there.
    pub fitted: f64,
    /// The target's shift there.
    pub correction: f64,
}

/// `compensation.json`: see the module's docs.
#[derive(Debug, Clone, Serialize)]
pub struct Compensation {
    /// The run corrected (as given).
    pub run: String,
    /// The measurement's file and the column read.
    pub measured_file: String,
    /// The value's column.
    pub column: String,
    /// The coordinate's column.
    pub coordinate: &'static str,
    /// The quantity measured.
    pub quantity: &'static str,
    /// The uncertainty the fit was held to (mm).
    pub uncertainty_mm: f64,
    /// The gain.
    pub gain: f64,
    /// The largest correction accepted (mm).
    pub limit_mm: f64,
    /// The smoothing parameter found.
    pub smooth: f64,
    /// The fit's residual, RMS (mm).
    pub rms_residual_mm: f64,
    /// The largest measured error (mm).
    pub max_error_mm: f64,
    /// The largest correction (mm).
    pub max_correction_mm: f64,
    /// Every measured place.
    pub places: Vec<Place>,
    /// How the program changed.
    pub program: ProgramChange,
}

/// How the program changed: its text (a line diff, `similar`: lines
/// kept, added and removed), and how far its path moved. Lines are not
/// compared word by word: a corrected target may place its blocks anew
/// (the mandrel's are spaced to its profile), so which block became which
/// is not known; the path is.
#[derive(Debug, Clone, Serialize)]
pub struct ProgramChange {
    /// The program's file.
    pub file: String,
    /// Lines the same.
    pub lines_kept: usize,
    /// Lines the corrected program has that the first had not.
    pub lines_added: usize,
    /// Lines the first had that the corrected has not.
    pub lines_removed: usize,
    /// How far the tool's path moved, per axis: each block of the
    /// corrected program against the original's path in the same pass
    /// (its nearest point on the pass's polyline in the axes' space); none
    /// where the passes or axes differ.
    pub path_moved: Option<BTreeMap<String, f64>>,
}

/// Compensates the run in `dir` (shown as `shown`) by the measurement
/// `measured`: see the module's docs. The corrected run's output holds
/// `correction.csv` and `compensation.json` besides its own files.
///
/// # Failures
/// The run's files unreadable; its family's script gone, or taking no
/// correction or no measurement; the measurement refused
/// ([`crate::compensate::read_measured`]); the correction beyond its limit
/// (named by where); the corrected run failing ([`Error::Failed`], its
/// diagnostic files in it).
pub fn compensate(
    dir: &std::path::Path,
    catalog: &Catalog,
    measured: &Table,
    options: &CompensateOptions,
) -> Result<(JobOutput, Compensation), Error> {
    let shown = dir.display().to_string();
    let run = RunDir::open(dir).map_err(|e| Error::Read(e.to_string()))?;
    let limit = crate::files::MAX_DATA_BYTES;
    let read = |name: &str| {
        run.read_text(name, limit)
            .map_err(|e| Error::Read(e.to_string()))
    };
    let report: Report = serde_json::from_str(&read("report.json")?)
        .map_err(|e| Error::Read(format!("{shown}/report.json: {e}")))?;
    let script = PathBuf::from(&report.script);
    if !script.is_file() {
        return Err(Error::Read(format!(
            "{shown}: the run's family '{}' is not there (its report names it from where the run was made)",
            report.script
        )));
    }
    // The script reads its tables beside itself; the correction is given.
    let load = |tables: Vec<(String, String)>| {
        let access = Access {
            tables,
            ..Access::default()
        };
        ScriptFamily::load(&script, &options.limits, &access)
    };
    let family = load(Vec::new())?;
    if !family.params().iter().any(|p| p.name == CORRECTION) {
        return Err(Error::Options(format!(
            "{}: the family takes no correction: its script declares no `{CORRECTION}` parameter (a table's name)",
            script.display()
        )));
    }
    let label = format!("{shown}/report.json");
    let base = report.params_source(&label).map_err(Error::Read)?;
    let spec = run_machine(&report, catalog, None, &shown)?;
    let machine = catalog.open(&spec)?;
    // The nominal: the run's parameters with no correction.
    let nominal_sources = vec![
        base.clone(),
        ParamSource::Pairs {
            label: "the nominal".into(),
            pairs: vec![(CORRECTION.into(), String::new())],
        },
    ];
    let params = params_on(&family, &machine, &nominal_sources)?;
    let nominal = family
        .verification(&params)?
        .and_then(|v| v.nominal())
        .ok_or_else(|| {
            Error::Options(format!(
                "{}: the family's verification takes no measurement of its part",
                script.display()
            ))
        })?;
    // The measurement against it.
    let m = read_measured(measured, &nominal.spec())?;
    let at_nominal = nominal.profile.eval_many(&m.at)?;
    let error: Vec<f64> = m
        .value
        .iter()
        .zip(&at_nominal)
        .map(|(v, n)| v - n)
        .collect();
    let fit = fit_error(&m.at, &error, options.uncertainty)?;
    let (from, to) = nominal.range;
    let grid: Vec<f64> = (0..=GRID)
        .map(|i| from + (to - from) * i as f64 / GRID as f64)
        .collect();
    let coordinate = nominal.coordinate.trim_end_matches("_mm");
    // A compensated run's correction stays, the new one added: the
    // measured error is then the first correction's and the process's.
    let previous = match report.parameters.get(CORRECTION).map(|p| &p.value) {
        Some(crate::params::ParamValue::Text(name)) if !name.is_empty() => {
            let t = crate::profile::read_table_str(&read(name)?, &format!("{shown}/{name}"))?;
            let p = t.profile("z_mm", "dr_mm")?;
            let (lo, hi) = p.z_range();
            grid.iter()
                .map(|z| p.eval(z.clamp(lo, hi)))
                .collect::<Result<Vec<f64>, _>>()?
        }
        _ => vec![0.0; grid.len()],
    };
    let shift = fit.correction(&grid, options.gain)?;
    let total: Vec<f64> = shift.iter().zip(&previous).map(|(s, p)| s + p).collect();
    within_limit(&grid, &total, options.limit, coordinate, &m.file)?;
    let correction = crate::profile::Profile::new(grid.clone(), total)?;
    let mut csv = String::from("z_mm,dr_mm\n");
    for (z, d) in correction.z().iter().zip(correction.x()) {
        csv += &format!("{z:.6},{d:.9}\n");
    }
    // The corrected run.
    let family = load(vec![(CORRECTION_FILE.into(), csv.clone())])?;
    let sources = vec![
        base,
        ParamSource::Pairs {
            label: "compensate".into(),
            pairs: vec![(CORRECTION.into(), CORRECTION_FILE.into())],
        },
    ];
    let fitted = fit.at(&m.at)?;
    // The table and chart the corrected run's report and page show: the
    // measured error, its fit, the target's shift and the error expected
    // after it (the same error on the corrected target, before the
    // corrected run's own finish, which its verification reports).
    let um = |v: &[f64]| v.iter().map(|x| 1e3 * x).collect::<Vec<f64>>();
    let shift: Vec<f64> = fitted.iter().map(|f| -options.gain * f).collect();
    let after: Vec<f64> = error.iter().zip(&shift).map(|(e, c)| e + c).collect();
    let mut annex = Annex::default();
    annex.tables.insert(
        "compensation".into(),
        BTreeMap::from([
            (nominal.coordinate.to_owned(), m.at.clone()),
            ("measured_error_um".into(), um(&error)),
            ("fit_um".into(), um(&fitted)),
            ("correction_um".into(), um(&shift)),
            ("expected_after_um".into(), um(&after)),
        ]),
    );
    annex.plots.push(crate::toolpath::PlotSpec {
        file: "compensation".into(),
        title: format!(
            "The measured {}'s error from the nominal, its fit, the correction and the error expected after it",
            nominal.quantity
        ),
        table: "compensation".into(),
        x: nominal.coordinate.to_owned(),
        y: vec![
            "measured_error_um".into(),
            "fit_um".into(),
            "correction_um".into(),
            "expected_after_um".into(),
        ],
        x_label: format!("{}, mm", coordinate),
        y_label: format!("{}, um", nominal.quantity),
    });
    let job_options = JobOptions {
        program_name: script
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("pilgrim")
            .to_owned(),
        annex,
        ..JobOptions::default()
    };
    let program_file = crate::program::post::dialect(&report.control)
        .map(|d| format!("program.{}", d.extension))
        .ok_or_else(|| {
            Error::Read(format!(
                "{label}: the control '{}' is not a dialect pilgrim reads",
                report.control
            ))
        })?;
    let before = read(&program_file)?;
    let old_program: AxisProgram = serde_json::from_str(&read("program.json")?)
        .map_err(|e| Error::Read(format!("{shown}/program.json: {e}")))?;
    let old_toolpath: Toolpath = serde_json::from_str(&read("toolpath.json")?)
        .map_err(|e| Error::Read(format!("{shown}/toolpath.json: {e}")))?;
    let mut out = run_job(&family, &machine, &sources, &job_options, &mut |_| {})?;
    let record = Compensation {
        run: shown.clone(),
        measured_file: m.file.clone(),
        column: m.column.clone(),
        coordinate: nominal.coordinate,
        quantity: nominal.quantity,
        uncertainty_mm: options.uncertainty,
        gain: options.gain,
        limit_mm: options.limit,
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
                correction: shift[i],
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
    out.files.push((CORRECTION_FILE.into(), csv.into_bytes()));
    out.files.push((
        "compensation.json".into(),
        (serde_json::to_string_pretty(&record).map_err(|e| Error::Output(e.to_string()))? + "\n")
            .into_bytes(),
    ));
    Ok((out, record))
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
/// the same pass (see [`ProgramChange::path_moved`]). Both programs run
/// along their passes the same way, so each block's nearest segment is
/// sought near the one before's ([`WINDOW`] segments either side): the
/// work grows with the blocks, not with their square (a caliber's 52,000).
fn path_moved(
    before: &AxisProgram,
    before_passes: &[ProgramPass],
    after: &AxisProgram,
    after_passes: &[ProgramPass],
) -> Option<BTreeMap<String, f64>> {
    use nalgebra::DVector;
    if before.axes != after.axes || before_passes.len() != after_passes.len() {
        return None;
    }
    let mut moved = DVector::<f64>::zeros(after.axes.len());
    for (p, q) in before_passes.iter().zip(after_passes) {
        let mut line: Vec<DVector<f64>> = before
            .blocks
            .get(p.blocks.clone())?
            .iter()
            .map(|b| DVector::from_column_slice(&b.values))
            .collect();
        if line.len() == 1 {
            line.push(line[0].clone());
        }
        let mut near: usize = 0;
        for b in after.blocks.get(q.blocks.clone())? {
            let v = DVector::from_column_slice(&b.values);
            // The offset from segment k's nearest point.
            let offset = |k: usize| {
                let (a, d) = (&line[k], &line[k + 1] - &line[k]);
                let l2 = d.norm_squared();
                let t = if l2 > 0.0 {
                    ((&v - a).dot(&d) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                &v - a - d * t
            };
            let segments = line.len() - 1;
            let (lo, hi) = (
                near.saturating_sub(WINDOW),
                (near + WINDOW + 1).min(segments),
            );
            let (k, off) = (lo..hi)
                .map(|k| (k, offset(k)))
                .min_by(|a, b| a.1.norm_squared().total_cmp(&b.1.norm_squared()))?;
            near = k;
            moved = moved.zip_map(&off, |m, o| m.max(o.abs()));
        }
    }
    Some(
        after
            .axes
            .iter()
            .map(|a| a.name.clone())
            .zip(moved.iter().copied())
            .collect(),
    )
}

/// How many segments either side of the last block's nearest one a block's
/// nearest is sought among.
const WINDOW: usize = 64;
