//! The caliber replay's pictures (issue 14 §1), drawn with plotters:
//! `deviation_map.svg`, the distance from the groove to the swept wheel over
//! (theta, psi) as a heat map, and `section.svg`, the wheel's rounding at
//! every pass in the groove's section where the most material is left.

use crate::chart::DrawError;
use crate::chart::{tick_decimals, Marks, PassMark, PixelMap, PlaceMark};
use crate::families::caliber::{GrooveCheck, GrooveRequest};
use plotters::prelude::*;

/// Colour levels of the heat map, an odd number: the middle one is zero.
const LEVELS: usize = 21;

/// The colour of level `k` of [`LEVELS`]: blue (gouge) through white to red
/// (material left).
fn level_colour(k: usize) -> RGBColor {
    let t = 2.0 * k as f64 / (LEVELS - 1) as f64 - 1.0; // -1..1
    let mix = |a: f64, b: f64, f: f64| (a + (b - a) * f).round() as u8;
    if t < 0.0 {
        let f = -t;
        RGBColor(
            mix(255.0, 33.0, f),
            mix(255.0, 102.0, f),
            mix(255.0, 172.0, f),
        )
    } else {
        RGBColor(
            mix(255.0, 178.0, t),
            mix(255.0, 24.0, t),
            mix(255.0, 43.0, t),
        )
    }
}

/// The level of `v` on a scale of +-`limit`.
fn level(v: f64, limit: f64) -> usize {
    let t = (v / limit).clamp(-1.0, 1.0);
    ((t + 1.0) / 2.0 * (LEVELS - 1) as f64).round() as usize
}

/// `deviation_map.svg`: each cell of the check's map coloured by its
/// distance (um) on a scale of +- the tolerance (or the largest distance,
/// if larger), cells of one colour along theta drawn as one rectangle;
/// the colour bar beside it; the worst places marked; the title says which
/// correction's program it charts, if `corrected`.
///
/// # Failures
/// An empty map; plotters failing.
pub fn deviation_map_svg(
    check: &GrooveCheck,
    passes: &[(std::ops::Range<usize>, f64)],
    corrected: Option<u32>,
) -> Result<(String, Marks), DrawError> {
    let m = &check.map;
    let (nt, np) = (
        m.theta_deg.len().saturating_sub(1),
        m.psi_deg.len().saturating_sub(1),
    );
    if nt == 0 || np == 0 || m.mm.len() != nt * np {
        return Err(DrawError::new(
            "deviation_map.svg",
            "the groove's deviation map is empty",
        ));
    }
    let limit = check.tolerance.max(check.max_abs_mm);
    let e = |e: DrawingAreaErrorKind<std::io::Error>| DrawError::new("deviation_map.svg", e);
    let mut svg = String::new();
    let mut marks = Marks {
        size: [1000, 560],
        ..Marks::default()
    };
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let (main, bar) = root.split_horizontally(880);
        let (t0, t1) = (m.theta_deg[0], m.theta_deg[nt]);
        let (p0, p1) = (m.psi_deg[0], m.psi_deg[np]);
        let mut chart = ChartBuilder::on(&main)
            .caption(
                crate::chart::titled(
                    &format!(
                        "Groove minus swept wheel, um (+ material left, - gouge); tolerance +-{} um",
                        crate::math::fixed(check.tolerance * 1e3, 1)
                    ),
                    corrected,
                ),
                ("sans-serif", 17),
            )
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(t0..t1, p0..p1)
            .map_err(e)?;
        let map = PixelMap::of(&chart, t0..t1, p0..p1);
        map_marks(&mut marks, check, passes, &map);
        let (dt, dp) = (tick_decimals(t1 - t0), tick_decimals(p1 - p0));
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("theta, deg (round the roll)")
            .y_desc("psi, deg (across the groove)")
            .x_label_formatter(&|v| format!("{v:.dt$}"))
            .y_label_formatter(&|v| format!("{v:.dp$}"))
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(e)?;
        let rects = colour_runs(check, limit);
        chart.draw_series(rects).map_err(e)?;
        for (place, name) in [
            (&check.max_left, "most left"),
            (&check.max_gouge, "deepest gouge"),
        ] {
            if place.mm != 0.0 {
                let at = (place.theta_deg, place.psi_deg);
                chart
                    .draw_series([EmptyElement::at(at)
                        + Circle::new((0, 0), 6, BLACK.stroke_width(2))
                        + Text::new(
                            format!("{name} {} um", crate::math::fixed(place.mm * 1e3, 2)),
                            (8, -6),
                            ("sans-serif", 13),
                        )])
                    .map_err(e)?;
            }
        }
        colour_bar(&bar, limit)?;
        root.present().map_err(e)?;
    }
    Ok((svg, marks))
}

/// The colour bar beside the map: the levels from -`limit` to +`limit`
/// (mm), in um.
fn colour_bar(
    bar: &plotters::drawing::DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    limit: f64,
) -> Result<(), DrawError> {
    let e = |e: DrawingAreaErrorKind<std::io::Error>| DrawError::new("deviation_map.svg", e);
    let um = limit * 1e3;
    let mut scale = ChartBuilder::on(bar)
        .margin_top(40)
        .margin_bottom(56)
        .margin_right(50)
        .y_label_area_size(0)
        .right_y_label_area_size(44)
        .build_cartesian_2d(0.0..1.0, -um..um)
        .map_err(e)?;
    let d = tick_decimals(2.0 * um);
    scale
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc("um")
        .y_label_formatter(&|v| format!("{v:.d$}"))
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(e)?;
    let step = 2.0 * um / LEVELS as f64;
    scale
        .draw_series((0..LEVELS).map(|k| {
            let y = -um + step * k as f64;
            Rectangle::new([(0.0, y), (1.0, y + step)], level_colour(k).filled())
        }))
        .map_err(e)?;
    Ok(())
}

/// The map's cells as rectangles: runs of one colour along theta, per row
/// of psi, on a scale of +-`limit`.
fn colour_runs(check: &GrooveCheck, limit: f64) -> Vec<Rectangle<(f64, f64)>> {
    let m = &check.map;
    let (nt, np) = (m.theta_deg.len() - 1, m.psi_deg.len() - 1);
    let mut rects = Vec::new();
    for j in 0..np {
        let mut i = 0;
        while i < nt {
            let k = level(m.mm[i * np + j], limit);
            let mut end = i + 1;
            while end < nt && level(m.mm[end * np + j], limit) == k {
                end += 1;
            }
            rects.push(Rectangle::new(
                [
                    (m.theta_deg[i], m.psi_deg[j]),
                    (m.theta_deg[end], m.psi_deg[j + 1]),
                ],
                level_colour(k).filled(),
            ));
            i = end;
        }
    }
    rects
}

/// Each pass's line across the map at its psi, and the extremes' places,
/// into `marks` (`map`: the chart's pixels).
fn map_marks(
    marks: &mut Marks,
    check: &GrooveCheck,
    passes: &[(std::ops::Range<usize>, f64)],
    map: &PixelMap,
) {
    let m = &check.map;
    let (t0, t1) = (m.theta_deg[0], m.theta_deg[m.theta_deg.len() - 1]);
    marks.passes = passes
        .iter()
        .map(|(blocks, psi)| PassMark {
            blocks: [blocks.start, blocks.end],
            points: vec![map.at(t0, *psi), map.at(t1, *psi)],
            closed: false,
        })
        .collect();
    for (place, name) in [
        (&check.max_left, "most material left"),
        (&check.max_gouge, "deepest gouge"),
    ] {
        if let Some(block) = place.block_from_0().filter(|_| place.mm != 0.0) {
            marks.places.push(PlaceMark {
                at: map.at(place.theta_deg, place.psi_deg),
                block,
                label: name.into(),
            });
        }
    }
}

/// `section.svg`: the groove's section at the theta where the most material
/// is left, the roll's periphery, and the wheel's rounding (radius
/// `rounding`, mm) at every pass, each touching the section at its pass
/// angle psi: how the passes share the section.
///
/// # Failures
/// The groove's tables not covering that theta; plotters failing.
pub fn section_svg(
    check: &GrooveCheck,
    req: &GrooveRequest,
    rounding: f64,
) -> Result<String, DrawError> {
    let theta = check.max_left.theta_deg.to_radians();
    let g = &req.groove;
    let section = g
        .section(theta)
        .map_err(|e| DrawError::new("section.svg", e))?;
    let (curve, circles) = section_curves(g, &section, theta, &req.psi, rounding)?;
    let ((x0, x1), (y0, y1)) = equal_scales(&curve, &circles, rounding);
    let e = |e: DrawingAreaErrorKind<std::io::Error>| DrawError::new("section.svg", e);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 680)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let (area, below) = root.split_vertically(640);
        let mut chart = ChartBuilder::on(&area)
            .caption(section_caption(check, req, rounding), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(e)?;
        let (dx, dy) = (tick_decimals(x1 - x0), tick_decimals(y1 - y0));
        chart
            .configure_mesh()
            .x_desc("across the roll, mm")
            .y_desc("height above the periphery, mm")
            .x_label_formatter(&|v| format!("{v:.dx$}"))
            .y_label_formatter(&|v| format!("{v:.dy$}"))
            .label_style(("sans-serif", 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(e)?;
        let wheel = RGBColor(42, 111, 216);
        for &(cx, cy, _) in &circles {
            chart
                .draw_series(LineSeries::new(
                    (0..=72).map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / 72.0;
                        (cx + rounding * a.cos(), cy + rounding * a.sin())
                    }),
                    wheel.mix(0.35).stroke_width(1),
                ))
                .map_err(e)?;
        }
        chart
            .draw_series(LineSeries::new(
                [(x0, 0.0), (x1, 0.0)],
                RGBColor(120, 120, 120).stroke_width(1),
            ))
            .map_err(e)?;
        chart
            .draw_series(LineSeries::new(curve, BLACK.stroke_width(2)))
            .map_err(e)?;
        chart
            .draw_series(
                circles
                    .iter()
                    .map(|&(_, _, p)| Circle::new(p, 3, RGBColor(214, 39, 40).filled())),
            )
            .map_err(e)?;
        crate::chart::legend(&below, &section_legend(wheel), (72, 230, 4), 13).map_err(e)?;
        root.present().map_err(e)?;
    }
    Ok(svg)
}

/// The section's caption: its passes, its theta and the wheel's rounding.
fn section_caption(check: &GrooveCheck, req: &GrooveRequest, rounding: f64) -> String {
    format!(
        "{} passes in the section at theta = {} deg (where the most material is left), wheel rounding r_k = {} mm",
        req.psi.len(),
        crate::math::fixed(check.max_left.theta_deg, 2),
        crate::math::fixed(rounding, 2)
    )
}

/// The section's legend, the wheel's rounding drawn in `wheel`.
fn section_legend(wheel: RGBColor) -> [(String, RGBColor); 4] {
    [
        ("the groove's section".into(), BLACK),
        ("the wheel's rounding at each pass".into(), wheel),
        ("its contact point".into(), RGBColor(214, 39, 40)),
        ("the roll's periphery".into(), RGBColor(120, 120, 120)),
    ]
}

/// Points in the section's plane (mm).
type Polyline = Vec<(f64, f64)>;

/// A wheel's rounding at a pass in the section: its centre and its contact
/// point.
type Rounding = (f64, f64, (f64, f64));

/// The groove's `section` at `theta` as a curve (x across the roll, y the
/// height above the periphery) and the wheel's rounding at each pass
/// angle of `psis`.
///
/// # Failures
/// The groove's normal not given there.
fn section_curves(
    g: &super::Groove,
    section: &super::section::GrooveSection,
    theta: f64,
    psis: &[f64],
    rounding: f64,
) -> Result<(Polyline, Vec<Rounding>), DrawError> {
    let er = crate::math::Vec3::new(theta.cos(), theta.sin(), 0.0);
    // In the section: x across the roll (mm), y the height above the
    // periphery (minus the depth).
    let curve: Vec<(f64, f64)> = (0..=360)
        .map(|k| {
            let psi = (-90.0 + 0.5 * k as f64).to_radians();
            let (x, z) = section.point(psi);
            (x, -z)
        })
        .collect();
    let mut circles = Vec::with_capacity(psis.len());
    for &psi in psis {
        let (x, z) = section.point(psi);
        let n = g
            .normal(theta, psi)
            .map_err(|e| DrawError::new("section.svg", e))?;
        // The normal points into the open groove: along the roll's axis
        // (section x) and outward (up in the section).
        circles.push((x + rounding * n.z, -z + rounding * n.dot(&er), (x, -z)));
    }
    Ok((curve, circles))
}

/// The picture's x and y ranges holding the `curve` and the `circles` of
/// radius `rounding`, on equal scales so that circles are round.
fn equal_scales(
    curve: &[(f64, f64)],
    circles: &[Rounding],
    rounding: f64,
) -> ((f64, f64), (f64, f64)) {
    let (mut x0, mut x1) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(x, y) in curve {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    for &(cx, cy, _) in circles {
        (x0, x1) = (x0.min(cx - rounding), x1.max(cx + rounding));
        (y0, y1) = (y0.min(cy - rounding), y1.max(cy + rounding));
    }
    let (w, h) = (900.0, 520.0);
    let scale = ((x1 - x0) / w).max((y1 - y0) / h) * 1.08;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (x0, x1) = (cx - 0.5 * w * scale, cx + 0.5 * w * scale);
    let (y0, y1) = (cy - 0.5 * h * scale, cy + 0.5 * h * scale);
    ((x0, x1), (y0, y1))
}
