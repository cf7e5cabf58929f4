//! `passes.xlsx`: the simulation's per-pass report as an Excel workbook,
//! as seed 004 writes one, beside `passes.csv`. Written with
//! `rust_xlsxwriter`; numbers stay numbers (shown to their decimals), each
//! column's unit in its header; the creation date fixed, so that the same
//! run writes the same bytes.
//!
//! - `passes`: one row per simulated thread pass, the columns of
//!   [`super::pass_table`] and the plan's;
//! - `starts`: each start's finished profile beside its nominal;
//! - `figures`: the verification's figures and the tolerances held, with
//!   units.

use super::ThreadCheck;
use rust_xlsxwriter::{DocProperties, ExcelDateTime, Format, Workbook, Worksheet, XlsxError};
use std::collections::BTreeMap;

/// A column: header (with its unit) and decimals shown (`None`: a whole
/// number or a text).
type Column<'a> = (&'a str, Option<usize>);

/// The number format of `decimals` places.
fn format_of(decimals: Option<usize>) -> Format {
    match decimals {
        Some(0) | None => Format::new().set_num_format("0"),
        Some(d) => Format::new().set_num_format(format!("0.{}", "0".repeat(d))),
    }
}

/// Writes the header row of `columns`, bold and frozen, each column wide
/// enough for its header.
fn header(sheet: &mut Worksheet, columns: &[Column<'_>]) -> Result<(), XlsxError> {
    let bold = Format::new().set_bold();
    for (j, (name, _)) in columns.iter().enumerate() {
        sheet.write_string_with_format(0, j as u16, *name, &bold)?;
        sheet.set_column_width(j as u16, (name.chars().count() + 2).max(10) as f64)?;
    }
    sheet.set_freeze_panes(1, 0)?;
    Ok(())
}

/// The workbook of `check`, with the plan's columns from `planned` where
/// it has one row per pass.
///
/// # Failures
/// The writer failing.
pub fn pass_workbook(
    check: &ThreadCheck,
    planned: Option<&BTreeMap<String, Vec<f64>>>,
) -> Result<Vec<u8>, crate::chart::DrawError> {
    build(check, planned).map_err(|e| crate::chart::DrawError::new("passes.xlsx", e))
}

/// The workbook: the passes, the starts and the figures, each a sheet.
fn build(
    check: &ThreadCheck,
    planned: Option<&BTreeMap<String, Vec<f64>>>,
) -> Result<Vec<u8>, XlsxError> {
    let mut book = Workbook::new();
    // A fixed date: the file is a function of the run alone.
    book.set_properties(
        &DocProperties::new()
            .set_title("pilgrim: the thread's passes, simulated")
            .set_creation_datetime(&ExcelDateTime::from_ymd(2000, 1, 1)?),
    );
    passes_sheet(&mut book, check, planned)?;
    starts_sheet(&mut book, check)?;
    figures_sheet(&mut book, check)?;
    book.save_to_buffer()
}

/// The sheet `passes`: a row per thread block simulated, with the plan's
/// columns where it has one row per pass.
fn passes_sheet(
    book: &mut Workbook,
    check: &ThreadCheck,
    planned: Option<&BTreeMap<String, Vec<f64>>>,
) -> Result<(), XlsxError> {
    let plan = super::plots::plan_columns(check, planned);
    let plan_names: Vec<String> = plan
        .iter()
        .map(|(k, _)| format!("plan: {k}{}", plan_unit(k)))
        .collect();
    let mut columns: Vec<Column<'_>> = vec![
        ("block", None),
        ("name", None),
        ("start", None),
        ("X (mm)", Some(3)),
        ("axial offset (mm)", Some(4)),
        ("chip area (mm²)", Some(5)),
        ("left flank load (mm²)", Some(5)),
        ("right flank load (mm²)", Some(5)),
        ("beyond the nominal (mm)", Some(5)),
        ("chip thickness (mm)", Some(5)),
        ("approach S1 (mm)", Some(3)),
        ("lead error at the face (ratio)", Some(6)),
        ("run-out S2 (mm)", Some(3)),
        ("lead error at the end (ratio)", Some(6)),
    ];
    columns.extend(plan_names.iter().map(|n| (n.as_str(), Some(5))));
    let formats: Vec<Format> = columns.iter().map(|c| format_of(c.1)).collect();
    let sheet = book.add_worksheet().set_name("passes")?;
    header(sheet, &columns)?;
    for (i, p) in check.passes.iter().enumerate() {
        let r = i as u32 + 1;
        let values = [
            p.block as f64,
            f64::from(p.start + 1),
            p.x,
            p.offset,
            p.chip_area,
            p.left_area,
            p.right_area,
            p.gouge,
            p.thickness,
            p.approach_mm,
            p.face_lead_error,
            p.runout_mm,
            p.end_lead_error,
        ];
        sheet.write_string(r, 1, &p.name)?;
        let at = [0u16, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13];
        for (&j, v) in at.iter().zip(values) {
            sheet.write_number_with_format(r, j, v, &formats[j as usize])?;
        }
        for (k, (_, c)) in plan.iter().enumerate() {
            let j = 14 + k;
            sheet.write_number_with_format(r, j as u16, c[i], &formats[j])?;
        }
    }
    Ok(())
}

/// The unit a plan's column is in, as a header shows it (` (mm)`); none
/// for its codes and counts (`kind`, `flank`, `start`).
fn plan_unit(column: &str) -> &'static str {
    match column {
        "planned_area" => " (mm²)",
        "depth" | "cumulative" | "offset" => " (mm)",
        _ => "",
    }
}

/// The sheet `starts`: each start's finished profile beside the nominal,
/// and as the gauges take it (its simple and functional pitch diameters,
/// the measurement over wires or between balls) beside the limits.
fn starts_sheet(book: &mut Workbook, check: &ThreadCheck) -> Result<(), XlsxError> {
    let (thickness, root, tip) = check.nominal;
    let columns: [Column<'_>; 25] = [
        ("start", None),
        ("position error (mm)", Some(4)),
        ("thickness (mm)", Some(4)),
        ("nominal thickness (mm)", Some(4)),
        ("left flank angle (deg)", Some(4)),
        ("nominal left flank angle (deg)", Some(4)),
        ("right flank angle (deg)", Some(4)),
        ("nominal right flank angle (deg)", Some(4)),
        ("left flank form (mm)", Some(4)),
        ("right flank form (mm)", Some(4)),
        ("pitch diameter (mm)", Some(4)),
        ("functional pitch diameter (mm)", Some(4)),
        ("least pitch diameter (mm)", Some(4)),
        ("greatest pitch diameter (mm)", Some(4)),
        ("over wires M (mm)", Some(4)),
        ("least M (mm)", Some(4)),
        ("greatest M (mm)", Some(4)),
        ("root diameter (mm)", Some(4)),
        ("nominal root diameter (mm)", Some(4)),
        ("least root diameter (mm)", Some(4)),
        ("greatest root diameter (mm)", Some(4)),
        ("tip diameter (mm)", Some(4)),
        ("nominal tip diameter (mm)", Some(4)),
        ("least tip diameter (mm)", Some(4)),
        ("greatest tip diameter (mm)", Some(4)),
    ];
    let formats: Vec<Format> = columns.iter().map(|c| format_of(c.1)).collect();
    let sheet = book.add_worksheet().set_name("starts")?;
    header(sheet, &columns)?;
    let limits = check.limits.as_ref();
    let band = |f: fn(&crate::families::thread::ThreadLimits) -> super::Limits| {
        limits.map(f).map(|l| [Some(l.min), Some(l.max)])
    };
    let [pd_min, pd_max] = band(|l| l.pitch_diameter).unwrap_or([None; 2]);
    let [root_min, root_max] = band(|l| l.root).unwrap_or([None; 2]);
    let [tip_min, tip_max] = band(|l| l.crest).unwrap_or([None; 2]);
    let [m_min, m_max] = check
        .over_wires_limits
        .map_or([None; 2], |[a, b]| [Some(a), Some(b)]);
    let [nominal_left, nominal_right] = check.nominal_flanks_deg;
    for (i, s) in check.starts.iter().enumerate() {
        let values = [
            Some(f64::from(s.start + 1)),
            Some(s.position_error),
            Some(s.thickness),
            Some(thickness),
            Some(s.left_angle_deg),
            Some(nominal_left),
            Some(s.right_angle_deg),
            Some(nominal_right),
            Some(s.left_form),
            Some(s.right_form),
            Some(s.pitch_diameter),
            s.functional_pitch_diameter,
            pd_min,
            pd_max,
            s.over_wires,
            m_min,
            m_max,
            Some(s.root_diameter),
            Some(root),
            root_min,
            root_max,
            Some(s.tip_diameter),
            Some(tip),
            tip_min,
            tip_max,
        ];
        for (j, v) in values.into_iter().enumerate() {
            if let Some(v) = v.filter(|v| v.is_finite()) {
                sheet.write_number_with_format(i as u32 + 1, j as u16, v, &formats[j])?;
            }
        }
    }
    Ok(())
}

/// The sheet `figures`: the areas, the loads, the lead's error and the
/// tolerances.
fn figures_sheet(book: &mut Workbook, check: &ThreadCheck) -> Result<(), XlsxError> {
    let t = &check.tolerances;
    let rows: [(&str, f64, &str); 12] = [
        ("area of the spaces (one lead)", check.space_area, "mm²"),
        ("area removed", check.removed_area, "mm²"),
        ("load on the left flanks", check.flank_loads[0], "mm²"),
        ("load on the right flanks", check.flank_loads[1], "mm²"),
        ("lead error over the thread", check.lead_error, "mm"),
        ("tolerance: flank form", t.form, "mm"),
        ("tolerance: thickness", t.thickness, "mm"),
        ("tolerance: diameters", t.diameter, "mm"),
        ("tolerance: position", t.position, "mm"),
        ("tolerance: flank angle", t.flank_angle.to_degrees(), "deg"),
        ("tolerance: lead error at the ends", t.lead, "ratio"),
        ("failures", check.failures.len() as f64, ""),
    ];
    let sheet = book.add_worksheet().set_name("figures")?;
    header(sheet, &[("figure", None), ("value", None), ("unit", None)])?;
    sheet.set_column_width(0, 36)?;
    let value = Format::new().set_num_format("0.000000");
    for (i, (name, v, unit)) in rows.iter().enumerate() {
        let r = i as u32 + 1;
        sheet.write_string(r, 0, *name)?;
        sheet.write_number_with_format(r, 1, *v, &value)?;
        sheet.write_string(r, 2, *unit)?;
    }
    Ok(())
}
