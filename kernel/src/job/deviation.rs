//! The grinding replay's pictures (issue 14 §1), drawn with plotters:
//! `deviation.svg`, each cutting pass's surface minus the nominal in um
//! along z (its lowest and highest over the generatrices, ridges
//! included), and `finish.svg`, the finishing pass alone against the
//! tolerance band.

use super::chart::{tick_decimals, COLOURS};
use crate::verify::{GrindingCheck, PassCheck};
use plotters::prelude::*;

/// One chart of `passes`' deviations (um) along z, with the tolerance
/// band's lines where `band` is given (mm).
fn draw(passes: &[&PassCheck], title: &str, band: Option<f64>) -> Result<String, String> {
    let (mut z0, mut z1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in passes {
        for b in &p.along_z {
            (z0, z1) = (z0.min(b[0]), z1.max(b[0]));
            (y0, y1) = (y0.min(1e3 * b[1]), y1.max(1e3 * b[2]));
        }
    }
    if let Some(t) = band {
        (y0, y1) = (y0.min(-1e3 * t), y1.max(1e3 * t));
    }
    if !(z0.is_finite() && y0.is_finite()) {
        return Err(format!("{title}: nothing to draw"));
    }
    if z1 - z0 < 1e-9 {
        z1 = z0 + 1.0;
    }
    let pad = ((y1 - y0) * 0.06).max(0.05);
    let (y0, y1) = (y0 - pad, y1 + pad);
    let rows = (passes.len() + usize::from(band.is_some())).div_ceil(2) as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1100, 600 + 24 * rows)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| format!("{title}: {e:?}");
        root.fill(&WHITE).map_err(e)?;
        let (top, bottom) = root.split_vertically(600);
        let mut chart = ChartBuilder::on(&top)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(90)
            .build_cartesian_2d(z0..z1, y0..y1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("z along the part, mm")
            .y_desc("surface minus nominal, um")
            .x_label_formatter(&|v| crate::math::fixed(*v, tick_decimals(z1 - z0)))
            .y_label_formatter(&|v| crate::math::fixed(*v, tick_decimals(y1 - y0)))
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .draw()
            .map_err(e)?;
        let mut legend: Vec<(String, RGBColor)> = Vec::new();
        for (k, p) in passes.iter().enumerate() {
            let c = COLOURS[k % COLOURS.len()];
            for side in [1, 2] {
                chart
                    .draw_series(LineSeries::new(
                        p.along_z.iter().map(|b| (b[0], 1e3 * b[side])),
                        c.stroke_width(1),
                    ))
                    .map_err(e)?;
            }
            legend.push((
                format!(
                    "{} ({:.1} mm/min, ridge {:.2} um)",
                    p.name,
                    p.feed_mm_min,
                    1e3 * p.ridge_mm
                ),
                c,
            ));
        }
        if let Some(t) = band {
            let grey = RGBColor(90, 90, 90);
            for y in [-1e3 * t, 1e3 * t] {
                chart
                    .draw_series(LineSeries::new([(z0, y), (z1, y)], grey.stroke_width(2)))
                    .map_err(e)?;
            }
            legend.push((format!("tolerance +-{:.1} um", 1e3 * t), grey));
        }
        super::chart::legend(&bottom, &legend, (60, 520, 2), 14).map_err(e)?;
        root.present().map_err(e)?;
    }
    Ok(svg)
}

/// `deviation.svg` and `finish.svg` of a grinding replay.
///
/// # Failures
/// A replay with no pass drawn; drawing failing.
pub fn deviation_svgs(check: &GrindingCheck) -> Result<[(String, String); 2], String> {
    let all: Vec<&PassCheck> = check.passes.iter().collect();
    let finish = all.last().copied().ok_or("the replay has no pass")?;
    Ok([
        (
            "deviation.svg".into(),
            draw(
                &all,
                "Each pass's surface minus the nominal (lowest and highest over the generatrices)",
                None,
            )?,
        ),
        (
            "finish.svg".into(),
            draw(
                &[finish],
                "The finish against the tolerance (ridges included)",
                Some(check.tolerance),
            )?,
        ),
    ])
}
