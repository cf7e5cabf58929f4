//! `pilgrim compensate`: a run's finished part measured, the error its
//! replay did not predict (the measured minus the part its verification
//! predicted, the table [`PREDICTED`] in its report) fitted within the
//! measurement's uncertainty, the target moved against it, and the job
//! run again on the corrected target ([`compensate`]). The new run
//! is verified as usual, against the corrected target; `compensation.json`
//! beside its files holds the measurement, the nominal, the fit, the
//! correction and the program's changes, `correction.csv` the correction
//! the family read.
//!
//! The family takes its correction by a parameter named [`CORRECTION`], a
//! table's name, and its verification says what a measurement holds and
//! its nominal ([`crate::family::Verifier::nominal`]); the run knows no
//! family by name.

use super::{params_on, run as run_job, run_machine, Annex, JobOptions, JobOutput, Report, Tables};
use crate::catalog::Catalog;
use crate::compensate::{
    fit_error, fit_mean, read_measured, within_limit, CompensateError, ErrorFit, Measured,
    Quantity, PREDICTED,
};
use crate::error::Error;
use crate::family::PartFamily;
use crate::math::Real;
use crate::output::RunDir;
use crate::params::ParamSource;
use crate::profile::Table;
use crate::program::{pass_blocks, AxisProgram, ProgramPass};
use crate::script::{Access, Limits, ScriptFamily};
use crate::toolpath::Toolpath;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// How far (mm) a value of the run's report may be from the same value
/// predicted again and still be the same prediction: the report's values
/// are written to well below it, and a changed run moves them by far
/// more.
const SAME_PREDICTION: Real = 1e-7;

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

impl CompensateOptions {
    /// Checks the options that bound the correction: a gain in (0, 1] (a
    /// larger one overshoots, round after round, and never settles), a
    /// positive finite limit (NaN would compare false and turn the limit
    /// off) and uncertainty.
    ///
    /// # Failures
    /// The first option out of its range, named with its value.
    pub fn check(&self) -> Result<(), CompensateError> {
        let bad = |what: &str, value: f64, range: &str| {
            Err(CompensateError::Option {
                what: what.to_owned(),
                value,
                range: range.to_owned(),
            })
        };
        if !(self.gain > 0.0 && self.gain <= 1.0) {
            return bad(
                "the gain (--gain), the share of the error corrected,",
                self.gain,
                "in (0, 1]: above 1 each correction overshoots the last",
            );
        }
        if !(self.limit > 0.0 && self.limit.is_finite()) {
            return bad(
                "the correction's limit (--limit)",
                self.limit,
                "a positive finite number of mm",
            );
        }
        if !(self.uncertainty > 0.0 && self.uncertainty.is_finite()) {
            return bad(
                "the measurement's uncertainty (--uncertainty)",
                self.uncertainty,
                "a positive finite number of mm",
            );
        }
        Ok(())
    }
}

/// One measured place as `compensation.json` lists it.
#[derive(Debug, Clone, Serialize)]
pub struct Place {
    /// The coordinate.
    pub at: f64,
    /// The quantity measured (the rows there averaged).
    pub measured: f64,
    /// How far the rows there differ (several angular positions: out of
    /// round), the largest less the least: averaged, not corrected.
    pub spread: f64,
    /// The nominal there.
    pub nominal: f64,
    /// Measured minus nominal: the part's error.
    pub error: f64,
    /// The part the run's replay predicted there (none where its
    /// verification predicts none: its target taken for it).
    pub predicted: Option<f64>,
    /// What the replay does not model, which is fitted: the measured minus
    /// the prediction, plus the run's own correction where it was
    /// corrected.
    pub unmodelled: f64,
    /// The fit there.
    pub fitted: f64,
    /// The correction there: the corrected target minus the nominal (as
    /// `correction.csv` has it), the run's own correction replaced.
    pub correction: f64,
    /// The error from the nominal expected after it, the same unmodelled
    /// error repeating: the corrected run's predicted part plus the
    /// measured minus the first prediction (where both runs predict; else
    /// the error plus the correction).
    pub expected_after: f64,
}

/// One quantity's measurement, fit and correction.
#[derive(Debug, Clone, Serialize)]
pub struct QuantityRecord {
    /// The quantity (`radius`, `depth`, `start 2's pitch diameter`).
    pub name: String,
    /// The value's column read.
    pub column: String,
    /// The correction's column in `correction.csv`.
    pub key: String,
    /// Corrected along the coordinate (a smoothing spline), or by one
    /// value (the measured errors' mean).
    pub along: bool,
    /// The smoothing parameter found (along the coordinate).
    pub smooth: f64,
    /// The fit's residual, RMS (mm). As one value: how far the error
    /// varies along the part beyond its mean, which the correction leaves.
    pub rms_residual_mm: f64,
    /// The largest measured error (mm).
    pub max_error_mm: f64,
    /// The largest spread of the rows at one place (mm): out of round,
    /// averaged, not corrected.
    pub max_spread_mm: f64,
    /// The largest correction, an earlier one kept included (mm).
    pub max_correction_mm: f64,
    /// The largest error expected after the correction, the same error
    /// repeating (mm).
    pub max_expected_after_mm: f64,
    /// Every measured place.
    pub places: Vec<Place>,
}

/// `compensation.json`: see the module's docs.
#[derive(Debug, Clone, Serialize)]
pub struct Compensation {
    /// The run corrected (as given).
    pub run: String,
    /// The measurement's file.
    pub measured_file: String,
    /// The coordinate's column.
    pub coordinate: &'static str,
    /// The uncertainty the fit was held to (mm).
    pub uncertainty_mm: f64,
    /// The gain.
    pub gain: f64,
    /// The largest correction accepted (mm).
    pub limit_mm: f64,
    /// The quantities measured.
    pub quantities: Vec<QuantityRecord>,
    /// The quantities the part may be measured by that the measurement
    /// does not hold: not corrected (an earlier correction kept).
    pub not_measured: Vec<String>,
    /// How the program changed.
    pub program: ProgramChange,
    /// Where the corrected run comes from.
    pub lineage: Lineage,
}

/// A corrected run's line of descent: how many corrections it carries,
/// the run it corrected and every measurement applied along the line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Lineage {
    /// How many corrections the run's target carries (1: the first
    /// corrected run of a run that had none).
    pub generation: u32,
    /// The run corrected (as given).
    pub parent: String,
    /// The measurement's content digest ([`Table::digest`]).
    pub measurement_sha256: String,
    /// Every measurement's digest applied along the line, oldest first,
    /// this one last.
    pub applied: Vec<String>,
    /// The gain.
    pub gain: f64,
    /// The correction's limit (mm).
    pub limit_mm: f64,
}

/// The lineage a run records in its `compensation.json` (none where it
/// was not corrected): its generation and the measurements applied.
///
/// # Failures
/// A `compensation.json` that is not what `compensate` writes, named.
fn lineage_of(run: &RunDir, shown: &str) -> Result<Option<(u32, Vec<String>)>, Error> {
    if !run.files().iter().any(|f| f == "compensation.json") {
        return Ok(None);
    }
    let text = run
        .read_text("compensation.json", crate::files::MAX_DATA_BYTES)
        .map_err(|e| Error::Read(e.to_string()))?;
    let bad = |what: &str| Error::Read(format!("{shown}/compensation.json: {what}"));
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(&e.to_string()))?;
    let l = &v["lineage"];
    let generation = l["generation"]
        .as_u64()
        .and_then(|g| u32::try_from(g).ok())
        .ok_or_else(|| bad("no lineage.generation"))?;
    let applied = l["applied"]
        .as_array()
        .ok_or_else(|| bad("no lineage.applied"))?
        .iter()
        .map(|d| {
            d.as_str()
                .map(str::to_owned)
                .ok_or_else(|| bad("a digest in lineage.applied is not text"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Some((generation, applied)))
}

impl Compensation {
    /// What was measured and corrected, in a line per quantity.
    pub fn summary(&self) -> String {
        let mut s: Vec<String> = self
            .quantities
            .iter()
            .map(|q| {
                let spread = if q.max_spread_mm > 0.0 {
                    format!(
                        " (the rows at one place differ by up to {:.4} mm: out of round, averaged, not corrected)",
                        q.max_spread_mm
                    )
                } else {
                    String::new()
                };
                format!(
                    "{}: {} places{spread}, the error up to {:.4} mm {} (RMS residual {:.4} mm), the target moved by up to {:.4} mm, {:.4} mm expected after",
                    q.name,
                    q.places.len(),
                    q.max_error_mm,
                    if q.along {
                        format!("fitted within {} mm", self.uncertainty_mm)
                    } else {
                        "corrected by its mean".to_owned()
                    },
                    q.rms_residual_mm,
                    q.max_correction_mm,
                    q.max_expected_after_mm
                )
            })
            .collect();
        if !self.not_measured.is_empty() {
            s.push(format!("not measured: {}", self.not_measured.join(", ")));
        }
        s.join("; ")
    }
}

/// How the program changed: its lines kept, added and removed, and how
/// far its path moved. Lines are counted as multisets, not aligned: a
/// corrected target may place its blocks anew (the mandrel's are spaced to
/// its profile), so which block became which is not known, and an
/// aligning diff (Myers') takes the product of the lines and the changes,
/// 20 s for a caliber's 52,000 blocks nearly all moved; the path is
/// compared instead, block by block.
#[derive(Debug, Clone, Serialize)]
pub struct ProgramChange {
    /// The program's file.
    pub file: String,
    /// Lines the same (each as often as both have it).
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
    /// The corrected program's blocks that stand more than
    /// [`MOVED`] mm off the original's path (in the axes' space); none
    /// where the passes or axes differ.
    pub blocks_moved: Option<usize>,
}

/// A block this far off the original program's path (mm, in the axes'
/// space: 0.1 um, the programs' last digit) has moved.
pub const MOVED: f64 = 1e-4;

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
    options.check()?;
    let shown = dir.display().to_string();
    let run = RunDir::open(dir).map_err(|e| Error::Read(e.to_string()))?;
    let limit = crate::files::MAX_DATA_BYTES;
    let read = |name: &str| {
        run.read_text(name, limit)
            .map_err(|e| Error::Read(e.to_string()))
    };
    let report: Report = serde_json::from_str(&read("report.json")?)
        .map_err(|e| Error::Read(format!("{shown}/report.json: {e}")))?;
    // A measurement is applied once along a line of corrections: the part
    // a corrected program made is measured anew.
    let digest = measured.digest();
    let (generation, mut applied) = lineage_of(&run, &shown)?.unwrap_or_default();
    if applied.contains(&digest) {
        return Err(Error::Options(format!(
            "{}: this measurement was applied already, in the line of corrections that made {shown} (its compensation.json): measure the part its corrected program made, and correct by that",
            measured.source()
        )));
    }
    applied.push(digest.clone());
    let lineage = Lineage {
        generation: generation + 1,
        parent: shown.clone(),
        measurement_sha256: digest,
        applied,
        gain: options.gain,
        limit_mm: options.limit,
    };
    // The script and machine the run kept beside its files (an older
    // run's: the paths its report names).
    let kept = super::kept::kept(&run, &report, None, None, &shown)?;
    let script = match &kept {
        Some((s, _)) => s.clone(),
        None => PathBuf::from(&report.script),
    };
    if !script.is_file() {
        return Err(Error::Read(format!(
            "{shown}: the run's family '{}' is not there (its report names it from where the run was made)",
            report.script
        )));
    }
    // The script reads its tables beside itself; the correction is given.
    let tables_read = crate::script::ReadLog::default();
    let load = |tables: Vec<(String, String)>| {
        let access = Access {
            tables,
            read: tables_read.clone(),
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
    let base = report
        .params_source(&label)
        .map_err(|e| Error::Read(e.to_string()))?;
    let spec = match kept.and_then(|k| k.1) {
        Some(spec) => spec,
        None => run_machine(&report, catalog, None, &shown)?,
    };
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
    let program_file = crate::program::post::dialect(&report.control)
        .map(|d| format!("program.{}", d.extension))
        .ok_or_else(|| {
            Error::Read(format!(
                "{label}: the control '{}' is not a dialect pilgrim reads",
                report.control
            ))
        })?;
    let before = read(&program_file)?;
    // The part the run's program makes, predicted again from the family,
    // the run's parameters and its program as the control reads it, on a
    // second thread while the correction is made from the report's copy;
    // the two are compared before anything is returned (an edited report
    // or program would move the target by its edit while saying the part
    // will be right). The family and the machine are opened on that
    // thread: a script's engine and a machine stay where they were made.
    let correction_text = run_correction(&run, &report)?;
    let recompute = || -> Result<Tables, Error> {
        let family = load(correction_text.iter().cloned().collect())?;
        let machine = catalog.open(&spec)?;
        let again = super::verify(
            &family,
            &machine,
            std::slice::from_ref(&base),
            &before,
            &JobOptions {
                program_name: "compensate".into(),
                ..JobOptions::default()
            },
            &mut |_| {},
        )
        .map_err(|e| {
            Error::Read(format!(
                "{shown}/{program_file}: the run's program, verified again to predict its part, is refused: {e}"
            ))
        })?;
        Ok(again.report.tables)
    };
    let first_tables = &report.tables;
    let correct = || -> Result<(JobOutput, Compensation), Error> {
        // A compensated run's correction: its target was the nominal moved by
        // it, and the new correction replaces it (see `unmodelled`).
        let previous = match &correction_text {
            Some((name, text)) => Some(crate::profile::read_table_str(
                text,
                &format!("{shown}/{name}"),
            )?),
            None => None,
        };
        let previous_at = |q: &Quantity, at: &[f64]| -> Result<Vec<f64>, Error> {
            match &previous {
                Some(t) if t.column_index(&q.key).is_ok() => {
                    let p = t.profile(nominal.coordinate, &q.key)?;
                    let (lo, hi) = p.z_range();
                    let at: Vec<f64> = at.iter().map(|z| z.clamp(lo, hi)).collect();
                    Ok(p.eval_many(&at)?)
                }
                _ => Ok(vec![0.0; at.len()]),
            }
        };
        // The measurement against it: each quantity it holds.
        // One per quantity, in the nominal's order: `None` where the
        // measurement has none of its columns.
        let mut fitted: Vec<Option<Fitted>> = Vec::new();
        for q in &nominal.quantities {
            let m = match read_measured(measured, &nominal.spec(q), options.uncertainty) {
                Ok(m) => m,
                Err(CompensateError::NoValueColumn { .. }) => {
                    fitted.push(None);
                    continue;
                }
                Err(e) => return Err(e.into()),
            };
            let at_nominal = q.nominal.eval_many(&m.at)?;
            let previous = previous_at(q, &m.at)?;
            // The part the run's replay predicted: its target, the nominal
            // moved by its correction, and its deviation from it.
            let predicted = predicted(first_tables, nominal.coordinate, q, &m.at)?.map(|d| {
                (0..m.at.len())
                    .map(|i| at_nominal[i] + previous[i] + d[i])
                    .collect::<Vec<f64>>()
            });
            let error: Vec<f64> = m
                .value
                .iter()
                .zip(&at_nominal)
                .map(|(v, n)| v - n)
                .collect();
            // What the run's replay does not model: the measured minus the
            // part it predicted (its target, the nominal moved by the run's own
            // correction, where its verification predicts none), plus that
            // correction. Fitted and corrected against, it replaces the run's
            // correction, so a part measured as its run predicted keeps it.
            let unmodelled: Vec<f64> = (0..m.at.len())
                .map(|i| {
                    let expected = predicted
                        .as_ref()
                        .map_or(at_nominal[i] + previous[i], |p| p[i]);
                    m.value[i] - expected + previous[i]
                })
                .collect();
            let fit = if q.along {
                fit_error(&m.at, &unmodelled, options.uncertainty)?
            } else {
                fit_mean(&m.at, &unmodelled, options.uncertainty)?
            };
            fitted.push(Some(Fitted {
                m,
                at_nominal,
                error,
                predicted,
                previous,
                fit,
            }));
        }
        if fitted.iter().all(Option::is_none) {
            return Err(CompensateError::Nothing {
                file: measured.source().to_owned(),
                wanted: nominal
                    .quantities
                    .iter()
                    .map(|q| {
                        let columns: Vec<String> =
                            q.values.iter().map(|(c, _)| format!("'{c}'")).collect();
                        format!("the {} ({})", q.name, columns.join(" or "))
                    })
                    .collect::<Vec<_>>()
                    .join(", "),
                available: measured.headers().join(", "),
            }
            .into());
        }
        let (from, to) = nominal.range;
        // Along the coordinate, every GRID-th of the range; as one value,
        // the ends and the middle (a profile's fewest).
        let places = if nominal.quantities.iter().any(|q| q.along) {
            GRID
        } else {
            2
        };
        let grid: Vec<f64> = (0..=places)
            .map(|i| from + (to - from) * i as f64 / places as f64)
            .collect();
        let (coordinate, unit) = nominal
            .coordinate
            .rsplit_once('_')
            .unwrap_or((nominal.coordinate, ""));
        let mut csv = std::iter::once(nominal.coordinate)
            .chain(nominal.quantities.iter().map(|q| q.key.as_str()))
            .collect::<Vec<_>>()
            .join(",")
            + "\n";
        let mut columns: Vec<Vec<f64>> = Vec::new();
        for (q, f) in nominal.quantities.iter().zip(&fitted) {
            let mut total = previous_at(q, &grid)?;
            if let Some(f) = f {
                let shift = f.fit.correction(&grid, options.gain)?;
                total.iter_mut().zip(&shift).for_each(|(t, s)| *t += s);
                let place = |s: f64| {
                    if q.along {
                        format!("of the {} at {coordinate} = {s:.3} {unit}", q.name)
                    } else {
                        format!("of the {}", q.name)
                    }
                };
                within_limit(&grid, &total, options.limit, &place, &f.m.file)?;
            }
            columns.push(total);
        }
        for (i, z) in grid.iter().enumerate() {
            csv += &format!("{z:.6}");
            for c in &columns {
                csv += &format!(",{:.9}", c[i]);
            }
            csv += "\n";
        }
        // The corrected run.
        let family = load(vec![(CORRECTION_FILE.into(), csv.clone())])?;
        let sources = vec![
            base.clone(),
            ParamSource::Pairs {
                label: "compensate".into(),
                pairs: vec![(CORRECTION.into(), CORRECTION_FILE.into())],
            },
        ];
        let mut records = Vec::new();
        let mut of = Vec::new();
        let mut not_measured = Vec::new();
        for ((q, f), total) in nominal.quantities.iter().zip(&fitted).zip(&columns) {
            let Some(f) = f else {
                not_measured.push(q.name.clone());
                continue;
            };
            let fit_at = f.fit.at(&f.m.at)?;
            let shift: Vec<f64> = fit_at.iter().map(|v| -options.gain * v).collect();
            let places: Vec<Place> = (0..f.m.at.len())
                .map(|i| Place {
                    at: f.m.at[i],
                    measured: f.m.value[i],
                    spread: f.m.spread[i],
                    nominal: f.at_nominal[i],
                    error: f.error[i],
                    predicted: f.predicted.as_ref().map(|p| p[i]),
                    unmodelled: f.fit.error[i],
                    fitted: fit_at[i],
                    correction: f.previous[i] + shift[i],
                    expected_after: f.error[i] + shift[i],
                })
                .collect();
            of.push(q);
            records.push(QuantityRecord {
                name: q.name.clone(),
                column: f.m.column.clone(),
                key: q.key.clone(),
                along: q.along,
                smooth: f.fit.smooth,
                rms_residual_mm: f.fit.rms_residual,
                max_error_mm: largest(f.error.iter().copied()),
                max_spread_mm: largest(f.m.spread.iter().copied()),
                max_correction_mm: largest(total.iter().copied()),
                max_expected_after_mm: largest(places.iter().map(|p| p.expected_after)),
                places,
            });
        }
        let quantities: Vec<Quantity> = of.into_iter().cloned().collect();
        let mut made = annex(
            nominal.coordinate,
            &quantities,
            &records,
            (coordinate, unit),
        );
        // The first run's program and its passes, read and parsed on a thread
        // of their own while the corrected run starts (tens of megabytes of
        // JSON for a caliber); its hook takes them.
        let first = {
            let (run, shown) = (run.clone(), shown.clone());
            std::thread::spawn(move || {
                let parse = |name: &str| run.read_text(name, limit).map_err(|e| e.to_string());
                let program: AxisProgram = serde_json::from_str(&parse("program.json")?)
                    .map_err(|e| format!("{shown}/program.json: {e}"))?;
                let toolpath: Toolpath = serde_json::from_str(&parse("toolpath.json")?)
                    .map_err(|e| format!("{shown}/toolpath.json: {e}"))?;
                let passes = pass_blocks(&program, &toolpath.passes);
                Ok::<_, String>((program, passes))
            })
        };
        let first = std::sync::Mutex::new(Some(first));
        // Once the corrected run's verification has predicted its part: the
        // annex's tables made again with the part after, and how far the
        // corrected program's path moved, per pass (its chart), kept for
        // compensation.json.
        // What the hook found, for compensation.json: the records with the
        // part after, and the moves.
        type Found = (Vec<QuantityRecord>, Result<Option<Moved>, String>);
        let (column, names) = (nominal.coordinate, (coordinate.to_owned(), unit.to_owned()));
        let hook_quantities = quantities.clone();
        let found: std::sync::Arc<std::sync::Mutex<Option<Found>>> = Default::default();
        let slot = found.clone();
        let hook_records = records;
        made.finish = Some(super::TablesHook(std::sync::Arc::new(
            move |tables, program, passes| {
                let mut records = hook_records.clone();
                after_run(&mut records, &hook_quantities, column, tables);
                let names = (names.0.as_str(), names.1.as_str());
                tables.extend(annex(column, &hook_quantities, &records, names).tables);
                let parsed = first.lock().ok().and_then(|mut h| h.take()).map(|h| {
                    h.join()
                        .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
                });
                let moved = match parsed {
                    Some(Ok((old_program, old_passes))) => {
                        Ok(path_moved(&old_program, &old_passes, program, passes))
                    }
                    Some(Err(e)) => Err(e),
                    None => Err("the first run's program was taken twice".into()),
                };
                let plots = moved
                    .as_ref()
                    .ok()
                    .and_then(Option::as_ref)
                    .map(|m| moves_chart(m, tables));
                if let Ok(mut s) = slot.lock() {
                    *s = Some((records, moved));
                }
                plots.into_iter().collect()
            },
        )));
        let job_options = JobOptions {
            program_name: script
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("pilgrim")
                .to_owned(),
            annex: made,
            keep: Some(super::Keep {
                script: script.clone(),
                tables: tables_read.clone(),
            }),
            ..JobOptions::default()
        };
        let mut out = run_job(&family, &machine, &sources, &job_options, &mut |_| {}).map_err(
            |e| match e {
                // A corrected run that fails its checks leaves its report.
                Error::Failed(failed) => Error::Failed(failed),
                refused => CompensateError::Corrected {
                    file: measured.source().to_owned(),
                    why: refused.to_string(),
                }
                .into(),
            },
        )?;
        // The run calls its hook once it has verified.
        let (records, moved) = found
            .lock()
            .ok()
            .and_then(|mut s| s.take())
            .ok_or_else(|| {
                crate::family::DrawError::new(
                    CORRECTION_FILE,
                    "the corrected run did not finish its tables",
                )
            })?;
        let moved = moved.map_err(Error::Read)?;
        let record = Compensation {
            run: shown.clone(),
            measured_file: measured.source().to_owned(),
            coordinate: nominal.coordinate,
            uncertainty_mm: options.uncertainty,
            gain: options.gain,
            limit_mm: options.limit,
            quantities: records,
            not_measured,
            program: {
                ProgramChange {
                    path_moved: moved.as_ref().map(|m| m.largest.clone()),
                    blocks_moved: moved.map(|m| m.blocks),
                    ..change(
                        &program_file,
                        &before,
                        &out.files
                            .iter()
                            .find(|(n, _)| *n == program_file)
                            .map(|(_, b)| String::from_utf8_lossy(b).into_owned())
                            .unwrap_or_default(),
                    )
                }
            },
            lineage,
        };
        out.files.push((CORRECTION_FILE.into(), csv.into_bytes()));
        out.files.push((
            "compensation.json".into(),
            (serde_json::to_string_pretty(&record)
                .map_err(|e| crate::family::DrawError::new("compensation.json", e))?
                + "\n")
                .into_bytes(),
        ));
        Ok((out, record))
    };
    let (corrected, again) = crate::budget::beside(correct, recompute);
    same_prediction(&report.tables, &again?, &label)?;
    corrected
}

/// The correction table a run keeps beside its files, as its parameters
/// name it (a compensated run's [`CORRECTION_FILE`]): `(name, text)`, to
/// give its family ([`crate::script::Access::tables`]) when the run is
/// made or verified again; none where the run took no correction.
///
/// # Failures
/// The table named but not there, or unreadable.
pub fn run_correction(run: &RunDir, report: &Report) -> Result<Option<(String, String)>, Error> {
    match report.parameters.get(CORRECTION).map(|p| &p.value) {
        Some(crate::params::ParamValue::Text(name)) if !name.is_empty() => {
            let text = run
                .read_text(name, crate::files::MAX_DATA_BYTES)
                .map_err(|e| Error::Read(e.to_string()))?;
            Ok(Some((name.clone(), text)))
        }
        _ => Ok(None),
    }
}

/// One quantity measured and fitted.
struct Fitted {
    m: Measured,
    at_nominal: Vec<f64>,
    /// Measured minus nominal.
    error: Vec<f64>,
    /// The run's predicted part (none where its verification predicts
    /// none).
    predicted: Option<Vec<f64>>,
    /// The run's own correction, at the measured places.
    previous: Vec<f64>,
    /// The fit of what the replay does not model (its `error`).
    fit: ErrorFit,
}

/// The largest value of `v` in size.
fn largest(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |a: f64, x| a.max(x.abs()))
}

/// The run's predicted deviation from its target for `q` at the places
/// `at`: the table [`PREDICTED`] its verification left in `tables`, along
/// `coordinate` (linearly between its rows, held at its ends). `None`
/// where the table or the quantity's column is not there.
///
/// # Failures
/// A table whose coordinate does not increase.
fn predicted(
    tables: &Tables,
    coordinate: &str,
    q: &Quantity,
    at: &[f64],
) -> Result<Option<Vec<f64>>, Error> {
    let Some(t) = tables.get(PREDICTED) else {
        return Ok(None);
    };
    let (Some(s), Some(values)) = (t.get(coordinate), t.get(&q.key)) else {
        return Ok(None);
    };
    let p = crate::profile::Profile::new(s.clone(), values.clone())
        .map_err(|e| Error::Read(format!("the run's table {PREDICTED}: {e}")))?
        .with_interpolation(crate::profile::Interpolation::Linear);
    let (lo, hi) = p.z_range();
    let at: Vec<f64> = at.iter().map(|z| z.clamp(lo, hi)).collect();
    Ok(Some(p.eval_many(&at)?))
}

/// Checks the run's `file` (its `report.json`, shown as `label`) says
/// the prediction its program gives when verified again (`again`): every
/// column of [`PREDICTED`], value for value, within 1e-7 mm.
///
/// # Failures
/// A column missing or of another length, or a value that differs: named
/// with the place and both values.
fn same_prediction(file: &Tables, again: &Tables, label: &str) -> Result<(), Error> {
    let empty = BTreeMap::new();
    let (theirs, ours) = (
        file.get(PREDICTED).unwrap_or(&empty),
        again.get(PREDICTED).unwrap_or(&empty),
    );
    let changed = |what: String| {
        Err(Error::Read(format!(
            "{label}: its table {PREDICTED} {what}: the report or the program was changed since the run (run the job again, and measure the part its program makes)"
        )))
    };
    for (column, want) in ours {
        let Some(have) = theirs.get(column) else {
            return changed(format!("has no column {column}"));
        };
        if have.len() != want.len() {
            return changed(format!(
                "holds {} values of {column} where the run's program gives {}",
                have.len(),
                want.len()
            ));
        }
        if let Some(i) = (0..want.len()).find(|&i| !((have[i] - want[i]).abs() <= SAME_PREDICTION))
        {
            return changed(format!(
                "says {column} = {} at its row {}, where the run's program, verified again, gives {}",
                have[i],
                i + 1,
                want[i]
            ));
        }
    }
    if let Some(extra) = theirs.keys().find(|c| !ours.contains_key(*c)) {
        return changed(format!(
            "has a column {extra} the run's program does not give"
        ));
    }
    Ok(())
}

/// Each record's error expected after the correction, the same
/// unmodelled error repeating, from the corrected run's `tables`: the
/// part its verification predicts ([`PREDICTED`]) plus the measured minus
/// the first run's prediction, less the nominal. Where either run predicts
/// none, it stays the error plus the correction (the corrected run's own
/// deviation taken as the first's).
fn after_run(
    records: &mut [QuantityRecord],
    quantities: &[Quantity],
    coordinate: &str,
    tables: &Tables,
) {
    for (r, q) in records.iter_mut().zip(quantities) {
        let at: Vec<f64> = r.places.iter().map(|p| p.at).collect();
        let Ok(Some(own)) = predicted(tables, coordinate, q, &at) else {
            continue;
        };
        // The corrected target is the nominal moved by the correction.
        for (p, own) in r.places.iter_mut().zip(own) {
            if let Some(first) = p.predicted {
                p.expected_after = p.correction + own + (p.measured - first);
            }
        }
        r.max_expected_after_mm = largest(r.places.iter().map(|p| p.expected_after));
    }
}

/// The tables and charts the corrected run's report and page show: per
/// quantity along the coordinate, its measured error, fit, the target's
/// shift and the error expected after it (the same error on the corrected
/// target, before the corrected run's own finish, which its verification
/// reports); the quantities corrected by one value together, by what
/// selects them (a thread's starts).
fn annex(
    column: &str,
    quantities: &[Quantity],
    records: &[QuantityRecord],
    (coordinate, unit): (&str, &str),
) -> Annex {
    let records: Vec<(&Quantity, &QuantityRecord)> = quantities.iter().zip(records).collect();
    let records = records.as_slice();
    let um = |v: &mut dyn Iterator<Item = f64>| v.map(|x| 1e3 * x).collect::<Vec<f64>>();
    let columns = [
        "measured_error_um",
        "fit_um",
        "correction_um",
        "expected_after_um",
    ];
    let mut annex = Annex::default();
    let along: Vec<&QuantityRecord> = records.iter().map(|p| p.1).filter(|r| r.along).collect();
    for r in &along {
        let name = if along.len() == 1 {
            "compensation".to_owned()
        } else {
            format!(
                "compensation_{}",
                r.key.trim_end_matches("_mm").trim_start_matches('d')
            )
        };
        let p = &r.places;
        let mut table = BTreeMap::from([
            (column.to_owned(), p.iter().map(|p| p.at).collect()),
            (columns[0].into(), um(&mut p.iter().map(|p| p.error))),
            (columns[1].into(), um(&mut p.iter().map(|p| p.fitted))),
            (columns[2].into(), um(&mut p.iter().map(|p| p.correction))),
            (
                columns[3].into(),
                um(&mut p.iter().map(|p| p.expected_after)),
            ),
        ]);
        let mut y: Vec<String> = columns.iter().map(|c| (*c).to_owned()).collect();
        // Beside the measured error, the one the run's replay predicted.
        if let Some(predicted) = p
            .iter()
            .map(|p| p.predicted.map(|v| v - p.nominal))
            .collect::<Option<Vec<f64>>>()
        {
            table.insert("predicted_error_um".into(), um(&mut predicted.into_iter()));
            y.insert(1, "predicted_error_um".into());
        }
        annex.tables.insert(name.clone(), table);
        annex.plots.push(crate::toolpath::PlotSpec {
            file: name.clone(),
            title: format!(
                "The {}'s error from the nominal, measured and as the run predicted it; the fit of their difference, the correction and the error expected after it",
                r.name
            ),
            table: name,
            x: column.to_owned(),
            y,
            x_label: format!("{coordinate}, {unit}"),
            y_label: format!("{}, um", r.name),
        });
    }
    // The quantities corrected by one value, by what selects them: one
    // table and chart per kind (a thread's starts' pitch diameters, their
    // places), each named by its quantity's name ("start 2's place").
    let ones: Vec<(&QuantityRecord, Real)> = records
        .iter()
        .filter(|(_, r)| !r.along)
        .map(|(q, r)| (*r, q.select.map_or(1.0, |s| s.1)))
        .collect();
    let kind = |r: &QuantityRecord| {
        r.name
            .rsplit_once("'s ")
            .map_or(r.name.clone(), |s| s.1.to_owned())
    };
    let mut kinds: Vec<String> = ones.iter().map(|(r, _)| kind(r)).collect();
    kinds.dedup();
    let by = records
        .iter()
        .find_map(|(q, _)| q.select.map(|s| s.0))
        .unwrap_or("quantity");
    for quantity in &kinds {
        let these: Vec<&(&QuantityRecord, Real)> =
            ones.iter().filter(|(r, _)| &kind(r) == quantity).collect();
        let name = if kinds.len() == 1 {
            "compensation".to_owned()
        } else {
            format!("compensation_{}", quantity.replace(' ', "_"))
        };
        let mean = |r: &QuantityRecord, f: &dyn Fn(&Place) -> f64| {
            1e3 * r.places.iter().map(f).sum::<f64>() / r.places.len() as f64
        };
        let values = |f: &dyn Fn(&Place) -> f64| these.iter().map(|(r, _)| mean(r, f)).collect();
        annex.tables.insert(
            name.clone(),
            BTreeMap::from([
                (by.to_owned(), these.iter().map(|(_, s)| *s).collect()),
                (columns[0].into(), values(&|p| p.error)),
                (columns[2].into(), values(&|p| p.correction)),
                (columns[3].into(), values(&|p| p.expected_after)),
            ]),
        );
        annex.plots.push(crate::toolpath::PlotSpec {
            file: name.clone(),
            title: format!(
                "The measured {quantity}'s error from the nominal (the mean of its places), the correction and the error expected after it, per {by}"
            ),
            table: name,
            x: by.to_owned(),
            y: [columns[0], columns[2], columns[3]].iter().map(|c| (*c).to_owned()).collect(),
            x_label: by.to_owned(),
            y_label: format!("{quantity}, um"),
        });
    }
    annex
}

/// The program's lines from `before` to `after` (`file`'s), counted as
/// multisets (see [`ProgramChange`]).
fn change(file: &str, before: &str, after: &str) -> ProgramChange {
    let mut count: std::collections::HashMap<&str, i64> = std::collections::HashMap::new();
    for l in before.lines() {
        *count.entry(l).or_default() += 1;
    }
    let mut kept = 0;
    for l in after.lines() {
        if let Some(n) = count.get_mut(l).filter(|n| **n > 0) {
            *n -= 1;
            kept += 1;
        }
    }
    ProgramChange {
        file: file.to_owned(),
        lines_kept: kept,
        lines_added: after.lines().count() - kept,
        lines_removed: before.lines().count() - kept,
        path_moved: None,
        blocks_moved: None,
    }
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
) -> Option<Moved> {
    if before.axes != after.axes || before_passes.len() != after_passes.len() {
        return None;
    }
    let n = after.axes.len();
    let mut by_pass: Vec<Vec<f64>> = Vec::with_capacity(after_passes.len());
    let mut blocks = 0;
    for (p, q) in before_passes.iter().zip(after_passes) {
        let mut moved: Vec<f64> = vec![0.0; n];
        let mut line: Vec<&[f64]> = before
            .blocks
            .get(p.blocks.clone())?
            .iter()
            .map(|b| b.values.as_slice())
            .collect();
        if line.len() == 1 {
            line.push(line[0]);
        }
        // Each segment's direction and squared length, once per pass.
        let dirs: Vec<(Vec<f64>, f64)> = line
            .windows(2)
            .map(|w| {
                let d: Vec<f64> = w[1].iter().zip(w[0]).map(|(b, a)| b - a).collect();
                let l2 = d.iter().map(|x| x * x).sum();
                (d, l2)
            })
            .collect();
        let mut near: usize = 0;
        for b in after.blocks.get(q.blocks.clone())? {
            let v = &b.values;
            // Where on segment k the block's nearest point lies (0 to 1),
            // and the squared distance to it; no allocation per segment.
            let nearest = |k: usize| {
                let (a, (d, l2)) = (line[k], &dirs[k]);
                let t = if *l2 > 0.0 {
                    let dot: f64 = v.iter().zip(a).zip(d).map(|((v, a), d)| (v - a) * d).sum();
                    (dot / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let dist2: f64 = v
                    .iter()
                    .zip(a)
                    .zip(d)
                    .map(|((v, a), d)| (v - a - d * t).powi(2))
                    .sum();
                (t, dist2)
            };
            let (lo, hi) = (
                near.saturating_sub(WINDOW),
                (near + WINDOW + 1).min(dirs.len()),
            );
            // The last block's segment first; a segment whose start lies
            // farther than its length beyond the best so far cannot be
            // nearer (nor tie), and is passed over. The same segment as a
            // search of every one in the window.
            let first = near.clamp(lo, hi.saturating_sub(1));
            let mut best = (first, nearest(first));
            for k in lo..hi {
                let from: f64 = v.iter().zip(line[k]).map(|(v, a)| (v - a).powi(2)).sum();
                let reach = best.1 .1.sqrt() + dirs[k].1.sqrt();
                if from > reach * reach * (1.0 + crate::tolerance::LIMIT_SLACK) {
                    continue;
                }
                let got = nearest(k);
                if got.1 < best.1 .1 || (got.1 == best.1 .1 && k < best.0) {
                    best = (k, got);
                }
            }
            let (k, (t, dist2)) = best;
            near = k;
            blocks += usize::from(dist2.sqrt() > MOVED);
            for (i, m) in moved.iter_mut().enumerate() {
                *m = m.max((v[i] - line[k][i] - dirs[k].0[i] * t).abs());
            }
        }
        by_pass.push(moved);
    }
    let names: Vec<String> = after.axes.iter().map(|a| a.name.clone()).collect();
    let largest = (0..n)
        .map(|i| by_pass.iter().map(|m| m[i]).fold(0.0, f64::max))
        .collect::<Vec<f64>>();
    Some(Moved {
        largest: names.iter().cloned().zip(largest).collect(),
        blocks,
        axes: names,
        by_pass,
    })
}

/// How far a corrected program's path moved from the first's
/// ([`path_moved`]).
#[derive(Debug, Clone)]
struct Moved {
    /// The largest move of each axis.
    largest: BTreeMap<String, f64>,
    /// The blocks moved more than [`MOVED`].
    blocks: usize,
    /// The axes, in the program's order.
    axes: Vec<String>,
    /// Each pass's largest move per axis (mm), in that order.
    by_pass: Vec<Vec<f64>>,
}

/// The table `compensation_moves` of `moved` (each pass's largest move
/// per axis, um) added to `tables`, and its chart.
fn moves_chart(moved: &Moved, tables: &mut Tables) -> crate::toolpath::PlotSpec {
    const TABLE: &str = "compensation_moves";
    let mut table = BTreeMap::from([(
        "pass".to_owned(),
        (1..=moved.by_pass.len()).map(|k| k as f64).collect(),
    )]);
    let mut y = Vec::new();
    for (i, axis) in moved.axes.iter().enumerate() {
        let column = format!("{axis}_um");
        table.insert(
            column.clone(),
            moved.by_pass.iter().map(|m| 1e3 * m[i]).collect(),
        );
        y.push(column);
    }
    tables.insert(TABLE.into(), table);
    crate::toolpath::PlotSpec {
        file: TABLE.into(),
        title: format!(
            "How far the corrected program's path moved from the first's, each pass's largest per axis ({} blocks moved more than {} um)",
            moved.blocks,
            1e3 * MOVED
        ),
        table: TABLE.into(),
        x: "pass".into(),
        y,
        x_label: "pass".into(),
        y_label: "moved, um (deg on a rotary axis: mdeg)".into(),
    }
}

/// How many segments either side of the last block's nearest one a block's
/// nearest is sought among.
const WINDOW: usize = 64;
