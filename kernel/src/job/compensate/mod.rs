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

mod after;
mod annex;
mod change;
mod fit;
mod prior;
mod record;

pub use super::Tables;
use super::{stages, JobOptions, JobOutput};
use crate::catalog::Catalog;
use crate::compensate::{CompensateError, Quantity};
use crate::error::Error;
use crate::math::Real;
use crate::output::RunError;
use crate::params::ParamSource;
use crate::profile::Table;
use crate::script::{Limits, ScriptFamily};
pub use change::ProgramChange;
pub use prior::run_correction;
use prior::{FirstProgram, Prior};
pub use record::{Compensation, Lineage, Place, QuantityRecord};

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
    /// The measurement's columns by the family's names, as the user maps
    /// them (`z` or `z_mm` to `Position Z [mm]`): only these are read.
    /// Empty: the family's own names, read from the table as they are.
    pub columns: Vec<(String, String)>,
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

/// Compensates the run in `dir` (shown as `shown`) by the measurement
/// `measured`: see the module's docs. The corrected run's output holds
/// `correction.csv` and `compensation.json` besides its own files.
///
/// The part the run's program makes is predicted again (its program
/// verified) on a second thread while the correction is made from the
/// report's copy, and the two compared before anything is returned: an
/// edited report or program would move the target by its edit while
/// saying the part will be right.
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
    let prior = Prior::open(dir, catalog, measured, options)?;
    let mapped;
    let measured = if options.columns.is_empty() {
        measured
    } else {
        mapped = mapped_columns(measured, &prior.nominal, &options.columns)?;
        &mapped
    };
    let (corrected, again) = crate::budget::beside(
        || correct(&prior, catalog, measured, options),
        || prior.predicted_again(catalog, options),
    );
    prior.same_prediction(&again?)?;
    corrected
}

/// `measured` with only the columns `columns` maps, under the family's
/// names: each key the family's column (`z_mm`) or its name before the
/// unit (`z`).
///
/// # Failures
/// A key none of the family's columns; a column the table lacks.
fn mapped_columns(
    measured: &Table,
    nominal: &crate::compensate::Nominal,
    columns: &[(String, String)],
) -> Result<Table, Error> {
    let mut known: Vec<&str> = vec![nominal.coordinate];
    for q in &nominal.quantities {
        known.extend(q.values.iter().map(|v| v.0));
        known.extend(q.select.map(|s| s.0));
    }
    known.dedup();
    let mut mapping = Vec::new();
    for (key, column) in columns {
        let name = (known.iter())
            .find(|k| {
                k.eq_ignore_ascii_case(key)
                    || k.split('_')
                        .next()
                        .is_some_and(|p| p.eq_ignore_ascii_case(key))
            })
            .ok_or_else(|| CompensateError::ColumnKey {
                key: crate::files::excerpt(key),
                known: known.join(", "),
            })?;
        mapping.push(((*name).to_owned(), column.clone()));
    }
    Ok(measured.mapped(&mapping).map_err(CompensateError::from)?)
}

/// The run corrected by `measured`: the fit, the correction, the corrected
/// run, and what `compensation.json` records of them.
///
/// # Failures
/// As [`compensate`].
fn correct(
    prior: &Prior,
    catalog: &Catalog,
    measured: &Table,
    options: &CompensateOptions,
) -> Result<(JobOutput, Compensation), Error> {
    let nominal = &prior.nominal;
    let previous = prior.previous()?;
    let fitted = fit::fit_all(nominal, measured, &previous, &prior.report.tables, options)?;
    let correction = fit::correction(nominal, &fitted, &previous, options)?;
    let (records, quantities, not_measured) =
        fit::records(nominal, &fitted, &correction.columns, options.gain)?;
    // The first run's program, read while the corrected run starts.
    let first = prior.first_program();
    let family = prior.load(
        options,
        vec![(CORRECTION_FILE.into(), correction.csv.clone())],
    )?;
    let (mut out, (records, moved)) = corrected_run(
        prior,
        catalog,
        &family,
        first,
        records,
        &quantities,
        Asked {
            options,
            measured_file: measured.source(),
        },
    )
    .map_err(|e| match e {
        // A corrected run that fails its checks leaves its report.
        Error::Failed(failed) => Error::Failed(failed),
        refused => CompensateError::Corrected {
            file: measured.source().to_owned(),
            why: refused.to_string(),
        }
        .into(),
    })?;
    // None where the run stopped at its time limit before its program was
    // checked (its report says so).
    let moved = moved.transpose()?.flatten();
    let after = (out.files.iter())
        .find(|(n, _)| *n == prior.program_file)
        .map(|(_, b)| String::from_utf8_lossy(b).into_owned())
        .unwrap_or_default();
    let record = Compensation {
        run: prior.shown.clone(),
        measured_file: measured.source().to_owned(),
        coordinate: nominal.coordinate,
        uncertainty_mm: options.uncertainty,
        gain: options.gain,
        limit_mm: options.limit,
        quantities: records,
        not_measured,
        program: ProgramChange {
            path_moved: moved.as_ref().map(|m| m.largest.clone()),
            blocks_moved: moved.map(|m| m.blocks),
            ..change::change(&prior.program_file, &prior.before, &after)
        },
        lineage: prior.lineage.clone(),
    };
    out.files
        .push((CORRECTION_FILE.into(), correction.csv.into_bytes()));
    let json = serde_json::to_string_pretty(&record)
        .map_err(|e| crate::family::DrawError::new("compensation.json", e))?;
    out.files
        .push(("compensation.json".into(), (json + "\n").into_bytes()));
    Ok((out, record))
}

/// What the corrected run found besides its output: the records with the
/// part after, and how far its program's path moved from the first's
/// (why not, where the first could not be read; none where the run
/// stopped before its program was checked).
type Found = (
    Vec<QuantityRecord>,
    Option<Result<Option<change::Moved>, RunError>>,
);

/// What `compensate` was asked, as the corrected run needs it: the
/// options, and the measurement's file (named on its page).
struct Asked<'a> {
    options: &'a CompensateOptions,
    measured_file: &'a str,
}

/// The options of the corrected run: its program's name carrying the
/// correction's generation, the inputs kept, what corrected it.
fn corrected_options(
    prior: &Prior,
    options: &CompensateOptions,
    measured_file: &str,
) -> JobOptions {
    JobOptions {
        // The corrected program says it is one: its name carries the
        // correction's generation (Sinumerik's `%_N_MANDREL_C1_MPF`,
        // Fanuc's header comment beside the O-number it keeps).
        program_name: format!(
            "{}_C{}",
            (prior.script.file_stem().and_then(|s| s.to_str())).unwrap_or("pilgrim"),
            prior.lineage.generation
        ),
        keep: Some(super::Keep {
            script: prior.script.clone(),
            tables: prior.tables_read.clone(),
        }),
        corrected_by: Some(crate::job::CorrectedBy {
            generation: prior.lineage.generation,
            said: format!(
                "generation {} of {}, corrected by the measurement {} at gain {} (its fit held to the uncertainty {} mm); the correction in correction.csv, the fit in compensation.json",
                prior.lineage.generation,
                prior.shown,
                crate::files::excerpt(measured_file),
                options.gain,
                options.uncertainty
            ),
        }),
        ..JobOptions::default()
    }
}

/// The corrected run, in the run's stages: once its verification has
/// predicted its part, the correction's tables made with the part after,
/// and how far its program's path moved from the `first` run's, per pass
/// (their chart), are added to what the run shows before it renders.
///
/// # Failures
/// The run's: its parameters, its checks ([`Error::Failed`]), its program.
fn corrected_run(
    prior: &Prior,
    catalog: &Catalog,
    family: &ScriptFamily,
    first: FirstProgram,
    mut records: Vec<QuantityRecord>,
    quantities: &[Quantity],
    asked: Asked<'_>,
) -> Result<(JobOutput, Found), Error> {
    let Asked {
        options,
        measured_file,
    } = asked;
    let machine = catalog.open(&prior.spec)?;
    let sources = vec![
        prior.base.clone(),
        ParamSource::Pairs {
            label: "compensate".into(),
            pairs: vec![(CORRECTION.into(), CORRECTION_FILE.into())],
        },
    ];
    let job_options = corrected_options(prior, options, measured_file);
    let (values, origins) = super::params_traced(family, &machine, &sources)?;
    let run = stages::Run {
        family,
        machine: &machine,
        values: &values,
        origins: &origins,
        options: &job_options,
        text: None,
    };
    let nominal = &prior.nominal;
    let mut moved = None;
    let staged = (|| {
        let stage = &mut |_: &str| {};
        let plan = run.plan(stage)?;
        let mut made = run.build(&plan, stage)?;
        let mut checked = run.check(&plan, &mut made)?;
        annex::after_run(
            &mut records,
            quantities,
            nominal.coordinate,
            checked.tables(),
        );
        let (figures, failures) = after::judged(&records, quantities, nominal.coordinate, options);
        checked.judge(figures, failures);
        let (tables, mut plots) =
            annex::annex(nominal.coordinate, quantities, &records, nominal.names());
        checked.add(tables, Vec::new());
        let first = first
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p));
        moved = Some(first.map(|(program, passes)| {
            change::path_moved(&program, &passes, made.program(), made.passes())
        }));
        let mut moves = Tables::new();
        if let Some(Ok(Some(m))) = &moved {
            plots.push(change::moves_chart(m, &mut moves));
        }
        checked.add(moves, plots);
        run.render(plan, made, checked, stage)
    })();
    Ok((run.stopped(staged)?, (records, moved)))
}
