//! The worm's pass-by-pass files: `passes.svg`, the axial section with the
//! stock each pass removed coloured pass by pass (the seed's
//! "distribution" view), drawn with plotters; `passes.csv`, one row per
//! thread pass, written with the csv crate.

use crate::chart::DrawError;
use crate::chart::{Marks, PassMark, PixelMap};
use crate::families::thread::ThreadCheck;
use plotters::prelude::*;
use std::collections::BTreeMap;

/// The colour of pass `k` of `n`: from blue (the first) to red (the last).
fn pass_colour(k: usize, n: usize) -> HSLColor {
    let t = if n > 1 {
        k as f64 / (n - 1) as f64
    } else {
        0.0
    };
    HSLColor((1.0 - t) * 240.0 / 360.0, 0.75, 0.5)
}

/// `passes.svg`: one lead of the axial section, the finished worm grey,
/// each pass's chip in its colour, a colour strip below naming the first
/// and the last pass; and the page's marks, each pass's chip outlined
/// from its thread block to the next pass's (the program having
/// `blocks`); the title says which correction's program it charts, if
/// `corrected`.
///
/// # Failures
/// Drawing failing.
pub fn passes_svg(
    check: &ThreadCheck,
    blocks: usize,
    corrected: Option<u32>,
) -> Result<(String, Marks), DrawError> {
    let (w0, lead) = check.window;
    let (mut r0, mut r1) = (f64::INFINITY, f64::NEG_INFINITY);
    for chip in check.chips.iter().flatten().flatten() {
        (r0, r1) = (r0.min(chip[1]), r1.max(chip[1]));
    }
    if !r0.is_finite() {
        return Err(DrawError::new("passes.svg", "no chip to draw"));
    }
    let pad = 0.05 * (r1 - r0).max(1.0);
    let (r0, r1) = (r0 - 3.0 * pad, r1 + pad);
    let n = check.chips.len();
    let title = crate::chart::titled(
        &format!("Stock removed pass by pass in the axial section ({n} thread passes, one lead)"),
        corrected,
    );
    let mut svg = String::new();
    let mut marks = Marks {
        size: [1100, 700],
        ..Marks::default()
    };
    {
        let root = SVGBackend::with_string(&mut svg, (1100, 700)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| DrawError::new("passes.svg", format!("{e:?}"));
        root.fill(&WHITE).map_err(e)?;
        let (top, bottom) = root.split_vertically(640);
        let mut chart = ChartBuilder::on(&top)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d(w0..w0 + lead, r0..r1)
            .map_err(e)?;
        let map = PixelMap::of(&chart, w0..w0 + lead, r0..r1);
        chart
            .configure_mesh()
            .x_desc("z along the worm's axis, mm")
            .y_desc("radius, mm")
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .draw()
            .map_err(e)?;
        let grey = RGBColor(200, 200, 200);
        for p in &check.section.0 {
            let ring: Vec<(f64, f64)> = p.exterior().coords().map(|c| (c.x, c.y.max(r0))).collect();
            chart
                .draw_series(std::iter::once(Polygon::new(ring, grey.filled())))
                .map_err(e)?;
        }
        for (k, chip) in check.chips.iter().enumerate() {
            let c = pass_colour(k, n);
            for ring in chip {
                // The chip's copies a lead either side fall partly outside.
                let pts: Vec<(f64, f64)> = ring
                    .iter()
                    .map(|p| (p[0].clamp(w0, w0 + lead), p[1]))
                    .collect();
                if let Some(p) = check.passes.get(k) {
                    let end = check
                        .passes
                        .get(k + 1)
                        .map_or(blocks, |n| n.block.saturating_sub(1));
                    marks.passes.push(PassMark {
                        blocks: [p.block.saturating_sub(1), end],
                        points: pts.iter().map(|q| map.at(q.0, q.1)).collect(),
                        closed: true,
                    });
                }
                chart
                    .draw_series(std::iter::once(Polygon::new(pts, c.filled())))
                    .map_err(e)?;
            }
        }
        colour_strip(&bottom, n)?;
        root.present().map_err(e)?;
    }
    Ok((svg, marks))
}

/// The colour strip under the chart: pass 1 on the left to pass `n` on the
/// right.
fn colour_strip(
    bottom: &plotters::drawing::DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    n: usize,
) -> Result<(), DrawError> {
    let e = |e: DrawingAreaErrorKind<_>| DrawError::new("passes.svg", format!("{e:?}"));
    let width = 700.0;
    for k in 0..n {
        let x = 200 + (width * k as f64 / n as f64) as i32;
        let x1 = 200 + (width * (k + 1) as f64 / n as f64).ceil() as i32;
        bottom
            .draw(&Rectangle::new(
                [(x, 18), (x1, 38)],
                pass_colour(k, n).filled(),
            ))
            .map_err(e)?;
    }
    for (text, x) in [("pass 1".to_owned(), 130), (format!("pass {n}"), 910)] {
        bottom
            .draw(&Text::new(text, (x, 20), ("sans-serif", 16)))
            .map_err(e)?;
    }
    Ok(())
}

/// The plan's columns of the family's pass table `planned` that hold one
/// value per simulated pass, less those the simulation's own columns
/// repeat.
pub(super) fn plan_columns<'a>(
    check: &ThreadCheck,
    planned: Option<&'a BTreeMap<String, Vec<f64>>>,
) -> Vec<(&'a String, &'a Vec<f64>)> {
    planned
        .map(|t| {
            t.iter()
                .filter(|(k, c)| {
                    c.len() == check.passes.len()
                        && !["simulated_area", "left_area", "right_area", "block"]
                            .contains(&k.as_str())
                })
                .collect()
        })
        .unwrap_or_default()
}

/// `passes.csv`: one row per simulated thread pass (block, its name,
/// start from 1, X, axial offset, chip area, left and right loads, gouge,
/// the approach and run-out from the cutting edges with the lead's error
/// where they meet the thread's ends)
/// and the plan's columns from `planned` where it has one row per pass;
/// text cells as [`crate::names::spreadsheet_text`] has them.
///
/// # Failures
/// The writer failing.
pub fn pass_table(
    check: &ThreadCheck,
    planned: Option<&BTreeMap<String, Vec<f64>>>,
) -> Result<String, DrawError> {
    let plan = plan_columns(check, planned);
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut head: Vec<String> = [
        "block",
        "name",
        "start",
        "x_mm",
        "offset_mm",
        "chip_area_mm2",
        "left_area_mm2",
        "right_area_mm2",
        "gouge_mm",
        "approach_mm",
        "face_lead_error",
        "runout_mm",
        "end_lead_error",
    ]
    .iter()
    .map(|s| (*s).to_owned())
    .collect();
    head.extend(
        plan.iter()
            .map(|(k, _)| crate::names::spreadsheet_text(&format!("plan_{k}"))),
    );
    w.write_record(&head)
        .map_err(|e| DrawError::new("passes.csv", e))?;
    for (i, p) in check.passes.iter().enumerate() {
        let mut row = vec![
            p.block.to_string(),
            crate::names::spreadsheet_text(&p.name),
            (p.start + 1).to_string(),
            crate::math::fixed(p.x, 3),
            crate::math::fixed(p.offset, 4),
            crate::math::fixed(p.chip_area, 5),
            crate::math::fixed(p.left_area, 5),
            crate::math::fixed(p.right_area, 5),
            crate::math::fixed(p.gouge, 5),
            crate::math::fixed(p.approach_mm, 3),
            crate::math::fixed(p.face_lead_error, 6),
            crate::math::fixed(p.runout_mm, 3),
            crate::math::fixed(p.end_lead_error, 6),
        ];
        row.extend(plan.iter().map(|(_, c)| crate::math::fixed(c[i], 5)));
        w.write_record(&row)
            .map_err(|e| DrawError::new("passes.csv", e))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| DrawError::new("passes.csv", e))?;
    String::from_utf8(bytes).map_err(|e| DrawError::new("passes.csv", e))
}
