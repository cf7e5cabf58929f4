//! The run corrected, as its files give it and as it is predicted again:
//! its report, its line of corrections, its family and machine (kept
//! beside it), the nominal, its program, its own correction, and the part
//! its program makes verified again and compared with its report's.

use super::{CompensateOptions, Lineage, Tables, CORRECTION, SAME_PREDICTION};
use crate::catalog::Catalog;
use crate::compensate::{CompensateError, Nominal, Quantity, PREDICTED};
use crate::error::Error;
use crate::family::PartFamily;
use crate::job::{params_on, run_machine, JobOptions, Report};
use crate::output::{RunDir, RunError};
use crate::params::ParamSource;
use crate::profile::Table;
use crate::program::{pass_blocks, AxisProgram, ProgramPass};
use crate::script::{Access, ReadLog, ScriptFamily};
use crate::toolpath::Toolpath;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The first run's program and its passes' blocks, as read on a thread of
/// their own.
pub(super) type FirstProgram =
    std::thread::JoinHandle<Result<(AxisProgram, Vec<ProgramPass>), RunError>>;

/// The run corrected: see the module's docs.
pub(super) struct Prior {
    /// The run's directory as given, in messages.
    pub shown: String,
    run: RunDir,
    /// Its report.
    pub report: Report,
    /// The corrected run's lineage.
    pub lineage: Lineage,
    /// The family's script.
    pub script: PathBuf,
    /// The tables the family reads beside its script, as read.
    pub tables_read: ReadLog,
    /// The run's parameters, as its report gives them.
    pub base: ParamSource,
    /// The machine, as the catalog opens it.
    pub spec: String,
    /// What the part is measured by, and its nominal.
    pub nominal: Nominal,
    /// The program's file name (`program.mpf`).
    pub program_file: String,
    /// Its text.
    pub before: String,
    /// The run's own correction table, as its parameters name it.
    correction: Option<(String, String)>,
}

impl Prior {
    /// The run in `dir` as its files give it, for a correction by
    /// `measured`.
    ///
    /// # Failures
    /// A file unreadable or not as pilgrim writes it; the measurement
    /// applied already along the run's line; the family gone, or taking no
    /// correction or no measurement; the control not one pilgrim reads.
    pub fn open(
        dir: &Path,
        catalog: &Catalog,
        measured: &Table,
        options: &CompensateOptions,
    ) -> Result<Self, Error> {
        let shown = dir.display().to_string();
        let run = RunDir::open(dir).map_err(Error::from)?;
        let report: Report = serde_json::from_str(&read(&run, "report.json")?).map_err(|e| {
            RunError::NotAsWritten {
                file: format!("{shown}/report.json"),
                what: crate::files::excerpt(&e.to_string()),
            }
        })?;
        let lineage = lineage(&run, &shown, measured, options)?;
        // The script and machine the run kept beside its files (an older
        // run's: the paths its report names).
        let kept = crate::job::kept::kept(&run, &report, None, None, &shown)?;
        let script = match &kept {
            Some((s, _)) => s.clone(),
            None => PathBuf::from(&report.script),
        };
        if !script.is_file() {
            return Err(RunError::FamilyGone {
                run: shown.clone(),
                script: crate::files::excerpt(&report.script),
            }
            .into());
        }
        let label = format!("{shown}/report.json");
        let base = report.params_source(&label).map_err(Error::from)?;
        let spec = match kept.and_then(|k| k.1) {
            Some(spec) => spec,
            None => run_machine(&report, catalog, None, &shown)?,
        };
        let program_file = crate::program::post::dialect(&report.control)
            .map(|d| format!("program.{}", d.extension))
            .ok_or_else(|| RunError::UnknownControl {
                file: label.clone(),
                control: crate::files::excerpt(&report.control),
            })?;
        let tables_read = ReadLog::default();
        let nominal = nominal_of(&script, &tables_read, catalog, (&spec, &base), options)?;
        Ok(Self {
            before: read(&run, &program_file)?,
            correction: run_correction(&run, &report)?,
            nominal,
            shown,
            run,
            report,
            lineage,
            script,
            tables_read,
            base,
            spec,
            program_file,
        })
    }

    /// The family of the run's script, given `tables` besides those beside
    /// it (the correction), its reads logged.
    ///
    /// # Failures
    /// The script refused.
    pub fn load(
        &self,
        options: &CompensateOptions,
        tables: Vec<(String, String)>,
    ) -> Result<ScriptFamily, Error> {
        load(&self.script, &self.tables_read, options, tables)
    }

    /// The run's own correction (a compensated run's target was the
    /// nominal moved by it), read.
    ///
    /// # Failures
    /// The table refused.
    pub fn previous(&self) -> Result<Previous, Error> {
        Ok(Previous(match &self.correction {
            Some((name, text)) => Some(crate::profile::read_table_str(
                text,
                &format!("{}/{name}", self.shown),
            )?),
            None => None,
        }))
    }

    /// The part the run's program makes, predicted again from the family,
    /// the run's parameters and its program as the control reads it: the
    /// tables its verification gives. The family and the machine are
    /// opened here: a script's engine and a machine stay on the thread
    /// that made them.
    ///
    /// # Failures
    /// The program refused, naming its file.
    pub fn predicted_again(
        &self,
        catalog: &Catalog,
        options: &CompensateOptions,
    ) -> Result<Tables, Error> {
        let family = self.load(options, self.correction.iter().cloned().collect())?;
        let machine = catalog.open(&self.spec)?;
        let again = crate::job::verify(
            &family,
            &machine,
            std::slice::from_ref(&self.base),
            &self.before,
            &JobOptions {
                program_name: "compensate".into(),
                ..JobOptions::default()
            },
            &mut |_| {},
        )
        .map_err(|e| RunError::PredictionRefused {
            file: format!("{}/{}", self.shown, self.program_file),
            why: e.to_string(),
        })?;
        Ok(again.report.tables)
    }

    /// The first run's program and its passes, read and parsed on a thread
    /// of their own (tens of megabytes of JSON for a caliber).
    pub fn first_program(&self) -> FirstProgram {
        let (run, shown) = (self.run.clone(), self.shown.clone());
        std::thread::spawn(move || {
            let parse = |name: &str| run.read_text(name, crate::files::MAX_DATA_BYTES);
            let bad = |name: &str, e: serde_json::Error| RunError::NotAsWritten {
                file: format!("{shown}/{name}"),
                what: crate::files::excerpt(&e.to_string()),
            };
            let program: AxisProgram = serde_json::from_str(&parse("program.json")?)
                .map_err(|e| bad("program.json", e))?;
            let toolpath: Toolpath = serde_json::from_str(&parse("toolpath.json")?)
                .map_err(|e| bad("toolpath.json", e))?;
            let passes = pass_blocks(&program, &toolpath.passes);
            Ok((program, passes))
        })
    }

    /// Checks the run's report says the prediction its program gives when
    /// verified again (`again`): every column of [`PREDICTED`], value for
    /// value, within [`SAME_PREDICTION`]. An edited report or program would
    /// move the target by its edit while saying the part will be right.
    ///
    /// # Failures
    /// A column missing or of another length, or a value that differs:
    /// named with the place and both values.
    pub fn same_prediction(&self, again: &Tables) -> Result<(), Error> {
        let label = format!("{}/report.json", self.shown);
        same_prediction(&self.report.tables, again, &label)
    }
}

/// A run's own correction, where it has one ([`Prior::previous`]).
pub(super) struct Previous(Option<Table>);

impl Previous {
    /// The correction of `q` at the places `at` along `coordinate` (held at
    /// its ends); 0 where the run has none of it.
    ///
    /// # Failures
    /// A column that is not a profile.
    pub fn at(&self, coordinate: &str, q: &Quantity, at: &[f64]) -> Result<Vec<f64>, Error> {
        match &self.0 {
            Some(t) if t.column_index(&q.key).is_ok() => {
                let p = t.profile(coordinate, &q.key)?;
                let (lo, hi) = p.z_range();
                let at: Vec<f64> = at.iter().map(|z| z.clamp(lo, hi)).collect();
                Ok(p.eval_many(&at)?)
            }
            _ => Ok(vec![0.0; at.len()]),
        }
    }
}

/// The family of `script`, given `tables` besides those beside it, its
/// reads logged in `log`.
///
/// # Failures
/// The script refused.
fn load(
    script: &Path,
    log: &ReadLog,
    options: &CompensateOptions,
    tables: Vec<(String, String)>,
) -> Result<ScriptFamily, Error> {
    let access = Access {
        tables,
        read: log.clone(),
        ..Access::default()
    };
    Ok(ScriptFamily::load(script, &options.limits, &access)?)
}

/// The nominal the family's verification measures the part by: the run's
/// parameters (`base`, on the machine `spec`) with no correction.
///
/// # Failures
/// The family taking no correction or no measurement; its script or the
/// machine refused.
fn nominal_of(
    script: &Path,
    log: &ReadLog,
    catalog: &Catalog,
    (spec, base): (&str, &ParamSource),
    options: &CompensateOptions,
) -> Result<Nominal, Error> {
    let family = load(script, log, options, Vec::new())?;
    if !family.params().iter().any(|p| p.name == CORRECTION) {
        return Err(CompensateError::NoCorrection {
            script: script.display().to_string(),
        }
        .into());
    }
    let machine = catalog.open(spec)?;
    let sources = vec![
        base.clone(),
        ParamSource::Pairs {
            label: "the nominal".into(),
            pairs: vec![(CORRECTION.into(), String::new())],
        },
    ];
    let params = params_on(&family, &machine, &sources)?;
    family
        .verification(&params)?
        .and_then(|v| v.nominal())
        .ok_or_else(|| {
            CompensateError::NotMeasured {
                script: script.display().to_string(),
            }
            .into()
        })
}

/// The text of the run's file `name`.
fn read(run: &RunDir, name: &str) -> Result<String, Error> {
    run.read_text(name, crate::files::MAX_DATA_BYTES)
        .map_err(Error::from)
}

/// The corrected run's lineage: the run's own, one generation on, with
/// `measured` applied. A measurement is applied once along a line of
/// corrections: the part a corrected program made is measured anew.
///
/// # Failures
/// The measurement applied already; the run's lineage unreadable.
fn lineage(
    run: &RunDir,
    shown: &str,
    measured: &Table,
    options: &CompensateOptions,
) -> Result<Lineage, Error> {
    let digest = measured.digest();
    let (generation, mut applied) = lineage_of(run, shown)?.unwrap_or_default();
    if applied.contains(&digest) {
        return Err(CompensateError::AppliedAlready {
            file: measured.source().to_string(),
            run: shown.to_owned(),
        }
        .into());
    }
    applied.push(digest.clone());
    Ok(Lineage {
        generation: generation + 1,
        parent: shown.to_owned(),
        measurement_sha256: digest,
        applied,
        gain: options.gain,
        limit_mm: options.limit,
    })
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
        .map_err(Error::from)?;
    let bad = |what: &str| RunError::NotAsWritten {
        file: format!("{shown}/compensation.json"),
        what: crate::files::excerpt(what),
    };
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
                .map_err(Error::from)?;
            Ok(Some((name.clone(), text)))
        }
        _ => Ok(None),
    }
}

/// The run's predicted deviation from its target for `q` at the places
/// `at`: the table [`PREDICTED`] its verification left in `tables`, along
/// `coordinate` (linearly between its rows, held at its ends). `None`
/// where the table or the quantity's column is not there.
///
/// # Failures
/// A table whose coordinate does not increase.
pub(super) fn predicted(
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
        .map_err(|e| RunError::NotAsWritten {
            file: format!("the run's table {PREDICTED}"),
            what: e.to_string(),
        })?
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
        Err(RunError::PredictionChanged {
            file: label.to_owned(),
            table: PREDICTED.to_owned(),
            what,
        }
        .into())
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
