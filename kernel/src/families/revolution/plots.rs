//! The grinding replay's pictures (issue 14 §1), drawn with plotters:
//! `deviation.svg`, each cutting pass's surface minus the nominal in um
//! along z (its lowest and highest over the generatrices, ridges
//! included), `finish.svg`, the finishing pass alone against the
//! tolerance band, and `stock.svg`, the stock each pass removed along z
//! (the surface before it minus the surface it left: the blank's for the
//! first pass).

use crate::chart::DrawError;
use crate::chart::{tick_decimals, Marks, PassMark, PixelMap, PlaceMark, COLOURS};
use crate::families::revolution::{GrindingCheck, PassCheck};
use plotters::prelude::*;

/// One chart of `passes`' deviations (um) along z, with the tolerance
/// band's lines where `band` is given (mm); its map from (z, um) to the
/// picture's pixels.
fn draw(
    passes: &[&PassCheck],
    (title, y_desc): (&str, &str),
    band: Option<f64>,
) -> Result<(String, Marks, PixelMap), DrawError> {
    let (z0, z1, y0, y1) = extent(passes, title, band)?;
    let rows = (passes.len() + usize::from(band.is_some())).div_ceil(2) as u32;
    let mut svg = String::new();
    let size = (1100, 600 + 24 * rows);
    let map;
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| DrawError::new(title, format!("{e:?}"));
        root.fill(&WHITE).map_err(e)?;
        let (top, bottom) = root.split_vertically(600);
        let mut chart = ChartBuilder::on(&top)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(90)
            .build_cartesian_2d(z0..z1, y0..y1)
            .map_err(e)?;
        map = PixelMap::of(&chart, z0..z1, y0..y1);
        chart
            .configure_mesh()
            .x_desc("z along the part, mm")
            .y_desc(y_desc)
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
        crate::chart::legend(&bottom, &legend, (60, 520, 2), 14).map_err(e)?;
        root.present().map_err(e)?;
    }
    let marks = Marks {
        size: [size.0, size.1],
        ..Marks::default()
    };
    Ok((svg, marks, map))
}

/// The chart's extent: z over the passes, and their deviations (um) with
/// the band's lines, padded.
///
/// # Failures
/// Nothing to draw.
fn extent(
    passes: &[&PassCheck],
    title: &str,
    band: Option<f64>,
) -> Result<(f64, f64, f64, f64), DrawError> {
    let (mut z0, mut z1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in passes {
        for b in &p.along_z {
            (z0, z1) = (z0.min(b[0]), z1.max(b[0]));
            (y0, y1) = (y0.min(1e3 * b[1].min(b[2])), y1.max(1e3 * b[1].max(b[2])));
        }
    }
    if let Some(t) = band {
        (y0, y1) = (y0.min(-1e3 * t), y1.max(1e3 * t));
    }
    if !(z0.is_finite() && y0.is_finite()) {
        return Err(DrawError::new(title, "nothing to draw"));
    }
    if z1 - z0 < crate::tolerance::SAME_LENGTH {
        z1 = z0 + 1.0;
    }
    let pad = ((y1 - y0) * 0.06).max(0.05);
    let (y0, y1) = (y0 - pad, y1 + pad);
    Ok((z0, z1, y0, y1))
}

/// The most points a pass's mark over a plot keeps (every k-th beyond).
const MARK_POINTS: usize = 400;

/// Each pass's line over a plot of `passes` (its highest surface, um),
/// lit from its first block to the next pass's (`blocks`: the program's
/// count, where the last ends).
fn pass_marks(passes: &[PassCheck], map: &PixelMap, blocks: usize) -> Vec<PassMark> {
    passes
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let every = p.along_z.len().div_ceil(MARK_POINTS).max(1);
            let end = passes
                .get(k + 1)
                .map_or(blocks, |n| n.first_block.saturating_sub(1));
            PassMark {
                blocks: [p.first_block.saturating_sub(1), end],
                points: p
                    .along_z
                    .iter()
                    .step_by(every)
                    .map(|b| map.at(b[0], 1e3 * b[2]))
                    .collect(),
                closed: false,
            }
        })
        .collect()
}

/// The finish's worst place over a plot, where it is at a block.
fn worst_place(finish: &PassCheck, map: &PixelMap) -> Option<PlaceMark> {
    let d = &finish.deviation;
    let value = if d.max_above.abs() >= d.max_below.abs() {
        d.max_above
    } else {
        d.max_below
    };
    Some(PlaceMark {
        at: map.at(d.at_z, 1e3 * value),
        block: d.block?.checked_sub(1)?,
        label: format!("the worst of {}", finish.name),
    })
}

/// The stock each pass removed along z (mm): its `along_z` replaced by
/// the surface before it minus the surface it left, at the valleys (the
/// lowest surfaces' difference) and at the ridges' tops (the highest's).
/// The surface before the first pass is `start` (the blank minus the
/// nominal at z, mm); where it is not known (no blank), the first pass is
/// left out.
/// Passes are matched stretch by stretch where their stretches lie at the
/// same z (the replay samples every pass at the same places).
pub fn removed(passes: &[PassCheck], start: impl Fn(f64) -> Option<f64>) -> Vec<PassCheck> {
    let mut out = Vec::with_capacity(passes.len());
    for (k, p) in passes.iter().enumerate() {
        let before = |i: usize, z: f64| -> Option<(f64, f64)> {
            if k == 0 {
                start(z).map(|s| (s, s))
            } else {
                let b = passes[k - 1].along_z.get(i)?;
                ((b[0] - z).abs() < crate::tolerance::SAME_LENGTH).then_some((b[1], b[2]))
            }
        };
        let along: Vec<[f64; 3]> = p
            .along_z
            .iter()
            .enumerate()
            .filter_map(|(i, b)| {
                let (lo, hi) = before(i, b[0])?;
                Some([b[0], lo - b[1], hi - b[2]])
            })
            .collect();
        if !along.is_empty() {
            out.push(PassCheck {
                along_z: along,
                ..p.clone()
            });
        }
    }
    out
}

/// `deviation.svg`, `finish.svg` and `stock.svg` of a grinding replay,
/// `start` the blank's surface minus the nominal at z (mm) where there is
/// a blank, with the page's marks: the finish's worst place on the first
/// two, each pass's line on the stock (the program having `blocks`); the
/// titles say which correction's program they chart, if `corrected`.
///
/// # Failures
/// A replay with no pass drawn; drawing failing.
pub fn deviation_svgs(
    check: &GrindingCheck,
    start: impl Fn(f64) -> Option<f64>,
    blocks: usize,
    corrected: Option<u32>,
) -> Result<[(String, String, Marks); 3], DrawError> {
    let title = |base: &str| crate::chart::titled(base, corrected);
    let all: Vec<&PassCheck> = check.passes.iter().collect();
    let finish = all
        .last()
        .copied()
        .ok_or_else(|| DrawError::new("deviation.svg", "the replay has no pass"))?;
    let stock = removed(&check.passes, start);
    let at_worst = |(svg, mut marks, map): (String, Marks, PixelMap)| {
        marks.places.extend(worst_place(finish, &map));
        (svg, marks)
    };
    let (deviation, deviation_marks) = at_worst(draw(
        &all,
        (
            &title(
                "Each pass's surface minus the nominal (lowest and highest over the generatrices)",
            ),
            "surface minus nominal, um",
        ),
        None,
    )?);
    let (finish_svg, finish_marks) = at_worst(draw(
        &[finish],
        (
            &title("The finish against the tolerance (ridges included)"),
            "surface minus nominal, um",
        ),
        Some(check.tolerance),
    )?);
    let (stock_svg, mut stock_marks, map) = draw(
        &stock.iter().collect::<Vec<_>>(),
        (
            &title("The stock each pass removed, at the valleys and at the ridges' tops"),
            "stock removed, um",
        ),
        None,
    )?;
    stock_marks.passes = pass_marks(&stock, &map, blocks);
    Ok([
        ("deviation.svg".into(), deviation, deviation_marks),
        ("finish.svg".into(), finish_svg, finish_marks),
        ("stock.svg".into(), stock_svg, stock_marks),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::families::revolution::Deviation;

    fn pass(name: &str, along_z: Vec<[f64; 3]>) -> PassCheck {
        let d = Deviation {
            max_above: 0.0,
            above_z: 0.0,
            max_below: 0.0,
            below_z: 0.0,
            max_abs: 0.0,
            at_z: 0.0,
            block: None,
        };
        PassCheck {
            name: name.into(),
            first_block: 1,
            feed_mm_min: 100.0,
            spindle_rpm: 100.0,
            feed_per_rev_mm: 1.0,
            ridge_mm: 0.0,
            deviation: d,
            phase_stand_off_mm: 0.0,
            phase_stand_off_z: 0.0,
            removed_mm: None,
            left_mm: 0.0,
            uncovered: Vec::new(),
            along_z,
            to_change: Vec::new(),
            bands: Vec::new(),
        }
    }

    /// Each pass removes the surface before it less the one it leaves,
    /// the first from the blank; stretches at other z are not matched; no
    /// blank leaves the first pass out.
    #[test]
    fn stock_removed_is_the_difference_of_surfaces() {
        let passes = vec![
            pass("rough", vec![[0.0, 0.10, 0.12], [1.0, 0.08, 0.11]]),
            pass("finish", vec![[0.0, -0.001, 0.002], [1.5, 0.0, 0.001]]),
        ];
        let got = removed(&passes, |z| Some(0.3 + 0.01 * z));
        assert_eq!(got.len(), 2);
        let r = &got[0].along_z;
        assert!((r[0][1] - 0.2).abs() < 1e-12 && (r[0][2] - 0.18).abs() < 1e-12);
        assert!((r[1][1] - 0.23).abs() < 1e-12 && (r[1][2] - 0.2).abs() < 1e-12);
        // The finish: z 0 matched (0.10 - -0.001, 0.12 - 0.002); z 1.5 not.
        assert_eq!(got[1].along_z.len(), 1);
        let f = got[1].along_z[0];
        assert!((f[1] - 0.101).abs() < 1e-12 && (f[2] - 0.118).abs() < 1e-12);
        let no_blank = removed(&passes, |_| None);
        assert_eq!(no_blank.len(), 1);
        assert_eq!(no_blank[0].name, "finish");
    }
}
