//! A measurement read from a table (CSV or spreadsheet, [`Table`]): a
//! coordinate column and a value column, each named with its unit
//! (`z_mm`, `d_mm`), every row inside the part, dense enough to say
//! something everywhere along it.

use super::CompensateError;
use crate::math::Real;
use crate::profile::Table;

/// The fewest distinct places a measurement may have.
pub const MIN_POINTS: usize = 5;

/// What a family accepts as a measurement of its part.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSpec<'a> {
    /// The coordinate's column (`z_mm`).
    pub coordinate: &'a str,
    /// The value's columns, each with the factor that makes the quantity
    /// of it (`("r_mm", 1.0)`, `("d_mm", 0.5)`): the first the table has
    /// is read.
    pub values: &'a [(&'a str, Real)],
    /// The rows read: those whose column holds the value (a thread's
    /// `start`); `None`: every row.
    pub select: Option<(&'a str, Real)>,
    /// The part's extent along the coordinate.
    pub range: (Real, Real),
    /// Measured along the coordinate: the longest stretch of the range
    /// left without a measured place (its ends included), and at least
    /// [`MIN_POINTS`] places. `None`: one value (a row at least).
    pub max_gap: Option<Real>,
}

/// How far apart the rows at one place may be, in stated uncertainties:
/// further, one of them is wrong.
pub const SPREAD_ALLOWED: Real = 3.0;

/// A measurement: the quantity at each distinct place, in increasing
/// order (the rows at one place, as at several angular positions,
/// averaged).
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The file, as messages name it.
    pub file: String,
    /// The value's column read.
    pub column: String,
    /// The places, increasing.
    pub at: Vec<Real>,
    /// The quantity at each (the column's value times its factor).
    pub value: Vec<Real>,
    /// How many rows each place averages.
    pub rows: Vec<usize>,
    /// How far the rows at each place differ, the largest less the least
    /// (0 for one row): a mandrel measured at several angular positions is
    /// that far out of round there, which its mean does not show.
    pub spread: Vec<Real>,
}

/// Reads `table` as `spec` asks.
///
/// # Failures
/// The coordinate's column missing, or none of the value's
/// ([`CompensateError::NoValueColumn`]), or the selecting column; a cell
/// empty or not a number (named by row and column); a row outside the
/// part; no row selected; along the coordinate, fewer than [`MIN_POINTS`]
/// places or a stretch longer than `spec.max_gap` without one (named by
/// where it runs).
pub fn read_measured(
    table: &Table,
    spec: &MeasuredSpec<'_>,
    uncertainty: Real,
) -> Result<Measured, CompensateError> {
    let file = table.source().to_owned();
    let at = table.column(spec.coordinate)?;
    let (column, factor) = spec
        .values
        .iter()
        .find(|(c, _)| table.column_index(c).is_ok())
        .ok_or_else(|| CompensateError::NoValueColumn {
            file: file.clone(),
            wanted: spec
                .values
                .iter()
                .map(|(c, _)| format!("'{c}'"))
                .collect::<Vec<_>>()
                .join(" or "),
            available: table.headers().join(", "),
        })?;
    let value = table.column(column)?;
    // Another column of the same quantity must say the same, within the
    // uncertainty: one of two that disagree is not the part.
    for (other, f) in spec.values.iter().filter(|(c, _)| c != column) {
        if table.column_index(other).is_err() {
            continue;
        }
        let theirs = table.column(other)?;
        if let Some(i) = (0..value.len()).find(|&i| {
            (value[i] * factor - theirs[i] * f).abs()
                > uncertainty * (1.0 + crate::tolerance::LIMIT_SLACK)
        }) {
            return Err(CompensateError::Inconsistent {
                file,
                what: format!(
                    "row {}: '{column}' {} and '{other}' {} measure the same quantity {} mm apart, more than the uncertainty {uncertainty} mm: give one of them",
                    table.row_number(i),
                    value[i],
                    theirs[i],
                    crate::math::fixed((value[i] * factor - theirs[i] * f).abs(), 4)
                ),
            });
        }
    }
    let selected = match spec.select {
        Some((c, want)) => table.column(c)?.iter().map(|&v| v == want).collect(),
        None => vec![true; at.len()],
    };
    let (from, to) = spec.range;
    // (place, value, row number)
    let mut rows: Vec<(Real, Real, usize)> = Vec::with_capacity(at.len());
    for (i, (&s, &v)) in at.iter().zip(&value).enumerate() {
        if !selected[i] {
            continue;
        }
        if !(from..=to).contains(&s) {
            return Err(CompensateError::Outside {
                file,
                row: table.row_number(i),
                column: spec.coordinate.to_owned(),
                value: s,
                from,
                to,
            });
        }
        rows.push((s, v * factor, table.row_number(i)));
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut m = Measured {
        file: file.clone(),
        column: (*column).to_owned(),
        at: Vec::new(),
        value: Vec::new(),
        rows: Vec::new(),
        spread: Vec::new(),
    };
    // Each place's least and largest row, and their rows' numbers.
    let mut bounds: Vec<(Real, Real)> = Vec::new();
    let mut bound_rows: Vec<(usize, usize)> = Vec::new();
    for (s, v, row) in rows {
        match m.at.last() {
            Some(&last) if last == s => {
                let k = m.rows.len() - 1;
                let n = m.rows[k] as Real;
                m.value[k] = (m.value[k] * n + v) / (n + 1.0);
                m.rows[k] += 1;
                if v < bounds[k].0 {
                    bounds[k].0 = v;
                    bound_rows[k].0 = row;
                }
                if v > bounds[k].1 {
                    bounds[k].1 = v;
                    bound_rows[k].1 = row;
                }
            }
            _ => {
                m.at.push(s);
                m.value.push(v);
                m.rows.push(1);
                bounds.push((v, v));
                bound_rows.push((row, row));
            }
        }
    }
    m.spread = bounds.iter().map(|(lo, hi)| hi - lo).collect();
    // Rows at one place further apart than the uncertainty allows are not
    // an out-of-round part measured at several angles but a wrong row.
    if let Some(k) = (0..m.at.len()).find(|&k| {
        m.spread[k] > SPREAD_ALLOWED * uncertainty * (1.0 + crate::tolerance::LIMIT_SLACK)
    }) {
        let (lo, hi) = bound_rows[k];
        let (a, b) = (lo.min(hi), lo.max(hi));
        return Err(CompensateError::Inconsistent {
            file,
            what: format!(
                "{} = {}: rows {a} and {b} are {} mm apart, more than {SPREAD_ALLOWED} times the uncertainty {uncertainty} mm (averaged, they would hide a wrong row): correct the measurement, or state its uncertainty",
                spec.coordinate,
                m.at[k],
                crate::math::fixed(m.spread[k], 4)
            ),
        });
    }
    if m.at.is_empty() {
        let (c, want) = spec.select.unwrap_or(("", 0.0));
        return Err(CompensateError::TooSparse {
            file,
            what: format!("no row measures {c} {want} (column '{c}')"),
        });
    }
    let Some(max_gap) = spec.max_gap else {
        return Ok(m);
    };
    if m.at.len() < MIN_POINTS {
        return Err(CompensateError::TooSparse {
            file,
            what: format!(
                "{} distinct places in column '{}': at least {MIN_POINTS} are needed to fit the error",
                m.at.len(),
                spec.coordinate
            ),
        });
    }
    // The ends of the part count as the gaps' bounds.
    let mut edges = vec![from];
    edges.extend(&m.at);
    edges.push(to);
    if let Some(w) = edges.windows(2).find(|w| w[1] - w[0] > max_gap) {
        return Err(CompensateError::TooSparse {
            file,
            what: format!(
                "nothing measured from {} = {} to {}: at most {} may be left between measured places (the part runs from {from} to {to})",
                spec.coordinate, w[0], w[1], max_gap
            ),
        });
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::read_table_str;

    const SPEC: MeasuredSpec<'static> = MeasuredSpec {
        coordinate: "z_mm",
        values: &[("r_mm", 1.0), ("d_mm", 0.5)],
        select: None,
        range: (0.0, 100.0),
        max_gap: Some(30.0),
    };

    fn table(text: &str) -> Table {
        read_table_str(text, "bench.csv").unwrap()
    }

    /// Diameters read as radii, sorted, the rows at one place averaged.
    #[test]
    fn a_measurement_is_read_by_its_columns() {
        let m = read_measured(
            &table(
                "z_mm,d_mm,note\n50,40.004,\n0,38,a\n25,39.002,\n50,40.000,b\n75,41,\n100,42,\n",
            ),
            &SPEC,
            1e-3,
        )
        .unwrap();
        assert_eq!(m.column, "d_mm");
        assert_eq!(m.at, vec![0.0, 25.0, 50.0, 75.0, 100.0]);
        assert_eq!(m.rows, vec![1, 1, 2, 1, 1]);
        assert!((m.value[2] - 20.001).abs() < 1e-12, "{:?}", m.value);
        // Out of round by 2 um on the radius at z = 50.
        assert!((m.spread[2] - 0.002).abs() < 1e-12 && m.spread[0] == 0.0);
        assert!((m.value[1] - 19.501).abs() < 1e-12);
    }

    /// Each bad measurement is named: the column, the row, where the part
    /// is left unmeasured.
    #[test]
    fn bad_measurements_are_named() {
        let e = |t: &str| {
            read_measured(&table(t), &SPEC, 1e-3)
                .unwrap_err()
                .to_string()
        };
        let s = e("z_mm,x_mm\n0,1\n");
        assert!(
            s.contains("no column 'r_mm' or 'd_mm' (columns: z_mm, x_mm)"),
            "{s}"
        );
        let s = e("z_mm,d_mm\n0,38\n25,39\n120,40\n");
        assert!(
            s.contains("bench.csv, row 4, column z_mm: 120 is outside the part (0 to 100)"),
            "{s}"
        );
        let s = e("z_mm,d_mm\n0,38\n10,39\n20,40\n");
        assert!(s.contains("3 distinct places"), "{s}");
        let s = e("z_mm,d_mm\n0,38\n10,39\n20,40\n30,40\n40,41\n");
        assert!(s.contains("nothing measured from z_mm = 40 to 100"), "{s}");
        let s = e("z_mm,d_mm\n0,38\n10,x\n");
        assert!(
            s.contains("row 3") && s.contains("'x' is not a number"),
            "{s}"
        );
    }

    /// One value per selected rows: a thread's start, any places; a start
    /// no row measures is named.
    #[test]
    fn a_selected_quantity_takes_its_rows() {
        let spec = MeasuredSpec {
            select: Some(("start", 2.0)),
            max_gap: None,
            values: &[("d2_mm", 1.0)],
            ..SPEC
        };
        let m = read_measured(
            &table("z_mm,start,d2_mm\n10,1,18.3\n10,2,18.31\n20,2,18.33\n"),
            &spec,
            1e-3,
        )
        .unwrap();
        assert_eq!(m.at, vec![10.0, 20.0]);
        assert_eq!(m.value, vec![18.31, 18.33]);
        let e = read_measured(&table("z_mm,start,d2_mm\n10,1,18.3\n"), &spec, 1e-3)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bench.csv: no row measures start 2 (column 'start')"),
            "{e}"
        );
    }
}
