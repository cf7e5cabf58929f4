//! The tables and charts a corrected run's report and page show of its
//! correction, made once its verification has predicted its part.

use super::record::largest;
use super::{Place, QuantityRecord, Tables};
use crate::compensate::Quantity;
use crate::math::Real;
use crate::toolpath::PlotSpec;
use std::collections::BTreeMap;

/// Each record's error expected after the correction, the same
/// unmodelled error repeating, from the corrected run's `tables`: the
/// part its verification predicts ([`PREDICTED`]) plus the measured minus
/// the first run's prediction, less the nominal. Where either run predicts
/// none, it stays the error plus the correction (the corrected run's own
/// deviation taken as the first's).
pub(super) fn after_run(
    records: &mut [QuantityRecord],
    quantities: &[Quantity],
    coordinate: &str,
    tables: &Tables,
) {
    for (r, q) in records.iter_mut().zip(quantities) {
        let at: Vec<f64> = r.places.iter().map(|p| p.at).collect();
        let Ok(Some(own)) = super::prior::predicted(tables, coordinate, q, &at) else {
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
pub(super) fn annex(
    column: &str,
    quantities: &[Quantity],
    records: &[QuantityRecord],
    (coordinate, unit): (&str, &str),
) -> (Tables, Vec<PlotSpec>) {
    let records: Vec<(&Quantity, &QuantityRecord)> = quantities.iter().zip(records).collect();
    let mut annex = (Tables::new(), Vec::new());
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
        along_part(&mut annex, name, r, column, (coordinate, unit));
    }
    by_value(&mut annex, &records);
    annex
}

/// Micrometres of the millimetres `v`.
fn um(v: &mut dyn Iterator<Item = f64>) -> Vec<f64> {
    v.map(|x| 1e3 * x).collect()
}

/// The columns of a compensation's table.
const COLUMNS: [&str; 4] = [
    "measured_error_um",
    "fit_um",
    "correction_um",
    "expected_after_um",
];

/// The table and chart `name` of `r`, a quantity corrected along the
/// coordinate `column`.
fn along_part(
    annex: &mut (Tables, Vec<PlotSpec>),
    name: String,
    r: &QuantityRecord,
    column: &str,
    (coordinate, unit): (&str, &str),
) {
    let columns = COLUMNS;
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
    annex.0.insert(name.clone(), table);
    annex.1.push(crate::toolpath::PlotSpec {
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

/// The quantities corrected by one value, by what selects them: one table
/// and chart per kind (a thread's starts' pitch diameters, their places),
/// each named by its quantity's name ("start 2's place").
fn by_value(annex: &mut (Tables, Vec<PlotSpec>), records: &[(&Quantity, &QuantityRecord)]) {
    let columns = COLUMNS;
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
        annex.0.insert(
            name.clone(),
            BTreeMap::from([
                (by.to_owned(), these.iter().map(|(_, s)| *s).collect()),
                (columns[0].into(), values(&|p| p.error)),
                (columns[2].into(), values(&|p| p.correction)),
                (columns[3].into(), values(&|p| p.expected_after)),
            ]),
        );
        annex.1.push(crate::toolpath::PlotSpec {
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
}
