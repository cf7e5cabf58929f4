//! The measurement against the run: each quantity's error fitted within
//! the measurement's uncertainty, the correction along the part (the
//! table the corrected run reads) and the records of both.

use super::prior::{predicted, Previous};
use super::record::largest;
use super::{CompensateOptions, Place, QuantityRecord, Tables, GRID};
use crate::compensate::{
    fit_error, fit_mean, read_measured, within_limit, CompensateError, ErrorFit, Measured, Nominal,
    Quantity,
};
use crate::error::Error;
use crate::profile::Table;

/// One quantity measured and fitted.
pub(super) struct Fitted {
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

/// Each quantity of the nominal measured by `measured` and fitted, in the
/// nominal's order: `None` where the measurement has none of its columns.
///
/// # Failures
/// The measurement refused or holding none of the quantities; a fit
/// that cannot be made.
pub(super) fn fit_all(
    nominal: &Nominal,
    measured: &Table,
    previous: &Previous,
    first_tables: &Tables,
    options: &CompensateOptions,
) -> Result<Vec<Option<Fitted>>, Error> {
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
        let previous = previous.at(nominal.coordinate, q, &m.at)?;
        fitted.push(Some(fit_one(
            nominal,
            q,
            m,
            previous,
            first_tables,
            options,
        )?));
    }
    if fitted.iter().all(Option::is_none) {
        return Err(CompensateError::Nothing {
            file: measured.source().to_owned(),
            wanted: (nominal.quantities.iter())
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
    Ok(fitted)
}

/// The quantity `q` measured (`m`) against the nominal, the run's own
/// correction there (`previous`) and the part the run's replay predicted
/// (in `first_tables`), and what that does not model fitted.
///
/// # Failures
/// The nominal or the prediction not evaluable there; the fit.
fn fit_one(
    nominal: &Nominal,
    q: &Quantity,
    m: Measured,
    previous: Vec<f64>,
    first_tables: &Tables,
    options: &CompensateOptions,
) -> Result<Fitted, Error> {
    let at_nominal = q.nominal.eval_many(&m.at)?;
    // The part the run's replay predicted: its target, the nominal
    // moved by its correction, and its deviation from it.
    let predicted = predicted(first_tables, nominal.coordinate, q, &m.at)?.map(|d| {
        (0..m.at.len())
            .map(|i| at_nominal[i] + previous[i] + d[i])
            .collect::<Vec<f64>>()
    });
    let error: Vec<f64> = (m.value.iter().zip(&at_nominal))
        .map(|(v, n)| v - n)
        .collect();
    // What the run's replay does not model: the measured minus the part
    // it predicted (its target, the nominal moved by the run's own
    // correction, where its verification predicts none), plus that
    // correction. Fitted and corrected against, it replaces the run's
    // correction, so a part measured as its run predicted keeps it.
    let unmodelled: Vec<f64> = (0..m.at.len())
        .map(|i| {
            let expected = (predicted.as_ref()).map_or(at_nominal[i] + previous[i], |p| p[i]);
            m.value[i] - expected + previous[i]
        })
        .collect();
    let fit = if q.along {
        fit_error(&m.at, &unmodelled, options.uncertainty)?
    } else {
        fit_mean(&m.at, &unmodelled, options.uncertainty)?
    };
    Ok(Fitted {
        m,
        at_nominal,
        error,
        predicted,
        previous,
        fit,
    })
}

/// The correction along the part: the table the corrected run reads
/// (`correction.csv`'s text) and each quantity's column of it.
pub(super) struct Correction {
    /// The table's text.
    pub csv: String,
    /// Each quantity's correction at the grid's places, the run's own
    /// included, in the nominal's order.
    pub columns: Vec<Vec<f64>>,
}

/// The correction of every quantity on a grid along the part: the run's
/// own correction, plus the fit's shift where the quantity was measured.
///
/// # Failures
/// A correction beyond its limit, named by where.
pub(super) fn correction(
    nominal: &Nominal,
    fitted: &[Option<Fitted>],
    previous: &Previous,
    options: &CompensateOptions,
) -> Result<Correction, Error> {
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
    let (coordinate, unit) = nominal.names();
    let mut columns: Vec<Vec<f64>> = Vec::new();
    for (q, f) in nominal.quantities.iter().zip(fitted) {
        let mut total = previous.at(nominal.coordinate, q, &grid)?;
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
    let mut csv = std::iter::once(nominal.coordinate)
        .chain(nominal.quantities.iter().map(|q| q.key.as_str()))
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    for (i, z) in grid.iter().enumerate() {
        csv += &format!("{z:.6}");
        for c in &columns {
            csv += &format!(",{:.9}", c[i]);
        }
        csv += "\n";
    }
    Ok(Correction { csv, columns })
}

/// The quantities measured: their records and the quantities, in the
/// same order, and the names of those not measured.
pub(super) type Records = (Vec<QuantityRecord>, Vec<Quantity>, Vec<String>);

/// The records of the quantities measured (with the quantities, in the
/// same order) and the names of those not measured.
///
/// # Failures
/// A fit not evaluable at its places.
pub(super) fn records(
    nominal: &Nominal,
    fitted: &[Option<Fitted>],
    columns: &[Vec<f64>],
    gain: f64,
) -> Result<Records, Error> {
    let mut records = Vec::new();
    let mut of = Vec::new();
    let mut not_measured = Vec::new();
    for ((q, f), total) in nominal.quantities.iter().zip(fitted).zip(columns) {
        let Some(f) = f else {
            not_measured.push(q.name.clone());
            continue;
        };
        let fit_at = f.fit.at(&f.m.at)?;
        let shift: Vec<f64> = fit_at.iter().map(|v| -gain * v).collect();
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
        of.push(q.clone());
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
    Ok((records, of, not_measured))
}
