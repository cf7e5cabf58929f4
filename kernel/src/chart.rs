//! Charts of a run's tables ([`crate::toolpath::PlotSpec`]) as SVG, drawn
//! with plotters: axes with ticks and units, a grid, the legend outside
//! the data (below the chart).

use crate::toolpath::{PlotSpec, Toolpath};
use plotters::coord::types::RangedCoordf64 as RangedF64;
use plotters::prelude::*;

/// Line colours, in order (the legend's).
pub(crate) const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// The decimals the ticks of an axis spanning `range` need: one more than
/// the place of a tenth of the range (the ticks' spacing), at least 0.
pub(crate) fn tick_decimals(range: f64) -> usize {
    let step = (range / 10.0).abs();
    if !(step > 0.0) {
        return 1;
    }
    (1.0 - step.log10().floor()).clamp(0.0, 9.0) as usize
}

/// A legend in `area` (below a chart: never over the data): each item a
/// swatch of its colour and its name, `layout.2` to a row starting at
/// `layout.0` and `layout.1` apart (pixels), in text of `size`.
pub(crate) fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    items: &[(String, RGBColor)],
    layout: (i32, i32, usize),
    size: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (left, width, per_row) = layout;
    for (k, (name, c)) in items.iter().enumerate() {
        let (x, y) = (
            left + width * (k % per_row) as i32,
            12 + 24 * (k / per_row) as i32,
        );
        // A swatch, not a line: the chart's lines are its data alone.
        area.draw(&Rectangle::new([(x, y - 2), (x + 30, y + 2)], c.filled()))?;
        area.draw(&Text::new(
            name.clone(),
            (x + 38, y - 8),
            ("sans-serif", size),
        ))?;
    }
    Ok(())
}

/// A picture, a table or a section of the page that could not be drawn
/// or written: which, and the reason the drawing library or the data
/// gives.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{what}: {message}")]
pub struct DrawError {
    /// What was being drawn (a file's name, a section of the page).
    pub what: String,
    /// Why it could not be.
    pub message: String,
}

impl DrawError {
    /// `what` could not be drawn, for `why`.
    pub fn new(what: impl Into<String>, why: impl std::fmt::Display) -> Self {
        Self {
            what: what.into(),
            message: why.to_string(),
        }
    }
}

impl From<serde_json::Error> for DrawError {
    /// A report entry a section could not read.
    fn from(e: serde_json::Error) -> Self {
        Self::new("the report's entry", e)
    }
}

/// A chart's title: `base`, and for a corrected run (`corrected` its
/// correction's generation) that the program it charts is that
/// correction's, whose surface stands off the nominal by the correction.
pub fn titled(base: &str, corrected: Option<u32>) -> String {
    match corrected {
        Some(g) => format!("{base}; the program corrected (generation {g})"),
        None => base.to_owned(),
    }
}

/// The chart `spec` from `toolpath`'s tables as SVG text.
///
/// # Failures
/// A table or column the toolpath does not have; no finite values.
pub fn chart_svg(toolpath: &Toolpath, spec: &PlotSpec) -> Result<String, String> {
    let table = toolpath
        .tables
        .get(&spec.table)
        .ok_or_else(|| format!("plot {}: no table '{}'", spec.file, spec.table))?;
    let column = |name: &str| {
        table.get(name).ok_or_else(|| {
            format!(
                "plot {}: table '{}' has no column '{name}'",
                spec.file, spec.table
            )
        })
    };
    let xs = column(&spec.x)?;
    let series = spec
        .y
        .iter()
        .map(|n| Ok((n.as_str(), column(n)?)))
        .collect::<Result<Vec<_>, String>>()?;
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (_, ys) in &series {
        for (x, y) in xs.iter().zip(ys.iter()) {
            (x0, x1, y0, y1) = (x0.min(*x), x1.max(*x), y0.min(*y), y1.max(*y));
        }
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(format!("plot {}: nothing to draw", spec.file));
    }
    if x1 - x0 < crate::tolerance::ROUNDING {
        x1 = x0 + 1.0;
    }
    let pad = ((y1 - y0) * 0.05).max(crate::tolerance::SAME_RATIO * y1.abs().max(1.0));
    let (y0, y1) = (y0 - pad, y1 + pad);
    let legend_rows = series.len().div_ceil(3) as u32;
    let mut svg = String::new();
    {
        let root =
            SVGBackend::with_string(&mut svg, (1000, 560 + 24 * legend_rows)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| format!("plot {}: {e:?}", spec.file);
        root.fill(&WHITE).map_err(e)?;
        let (top, bottom) = root.split_vertically(560);
        let mut chart = ChartBuilder::on(&top)
            .caption(&spec.title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(90)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(spec.x_label.as_str())
            .y_desc(spec.y_label.as_str())
            // One number of decimals an axis, never "-0.0".
            .x_label_formatter(&|v| crate::math::fixed(*v, tick_decimals(x1 - x0)))
            .y_label_formatter(&|v| crate::math::fixed(*v, tick_decimals(y1 - y0)))
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .draw()
            .map_err(e)?;
        for (k, (_, ys)) in series.iter().enumerate() {
            let c = COLOURS[k % COLOURS.len()];
            chart
                .draw_series(LineSeries::new(
                    xs.iter().zip(ys.iter()).map(|(x, y)| (*x, *y)),
                    c.stroke_width(2),
                ))
                .map_err(e)?;
        }
        let items: Vec<(String, RGBColor)> = series
            .iter()
            .enumerate()
            .map(|(k, (name, _))| (name.to_string(), COLOURS[k % COLOURS.len()]))
            .collect();
        legend(&bottom, &items, (110, 300, 3), 16).map_err(e)?;
        root.present().map_err(e)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tool::{Tool, Wheel};

    /// A chart names its lines and axes; a missing column is named.
    #[test]
    fn charts_draw_their_tables() {
        let mut tp = Toolpath::new(
            "t",
            Tool::wheel("w", 1, Wheel::new(200.0, 8.0, 16.0).unwrap()),
            100.0,
            vec![],
        );
        tp.tables.insert(
            "d".into(),
            [
                ("x".to_owned(), vec![0.0, 1.0, 2.0]),
                ("before".to_owned(), vec![0.0, 2.0, 1.0]),
            ]
            .into_iter()
            .collect(),
        );
        let mut spec = PlotSpec {
            file: "f".into(),
            title: "Derivative".into(),
            table: "d".into(),
            x: "x".into(),
            y: vec!["before".into()],
            x_label: "theta, deg".into(),
            y_label: "mm/deg".into(),
        };
        let svg = chart_svg(&tp, &spec).unwrap();
        assert!(svg.contains("<svg") && svg.contains("before") && svg.contains("theta, deg"));
        spec.y.push("after".into());
        let e = chart_svg(&tp, &spec).unwrap_err();
        assert!(e.contains("no column 'after'"), "{e}");
    }
}

/// What the page's player marks over a plot (`report.json` `marks`, by the
/// plot's file name): each pass's line, lit while the player is in its
/// blocks, and places (a verification's worst) that take the player to
/// their block when clicked. In the SVG's pixels, so the page lays them
/// over the picture as it is drawn.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Marks {
    /// The SVG's width and height (px).
    pub size: [u32; 2],
    /// Each pass's line.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub passes: Vec<PassMark>,
    /// The places to click.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub places: Vec<PlaceMark>,
}

/// A pass's line over a plot.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassMark {
    /// The blocks it is lit for (from 0: the first, and one past the last).
    pub blocks: [usize; 2],
    /// Its points (px); closed where `closed`.
    pub points: Vec<[f32; 2]>,
    /// A region's outline (the worm's chip), else an open line.
    #[serde(default)]
    pub closed: bool,
}

/// A place over a plot that takes the player to its block.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlaceMark {
    /// Where (px).
    pub at: [f32; 2],
    /// Its block (from 0).
    pub block: usize,
    /// What it is (`deepest gouge`).
    pub label: String,
}

/// A chart's data coordinates to its SVG's pixels, read from plotters'
/// own mapping at two corners of the data (both axes linear).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelMap {
    scale: [f64; 2],
    offset: [f64; 2],
}

impl PixelMap {
    /// The map of `chart`, whose data spans `x` by `y`.
    pub fn of<DB: DrawingBackend>(
        chart: &ChartContext<'_, DB, Cartesian2d<RangedF64, RangedF64>>,
        x: std::ops::Range<f64>,
        y: std::ops::Range<f64>,
    ) -> Self {
        let (a, b) = (
            chart.backend_coord(&(x.start, y.start)),
            chart.backend_coord(&(x.end, y.end)),
        );
        let axis = |p0: i32, p1: i32, v0: f64, v1: f64| {
            let s = if v1 != v0 {
                f64::from(p1 - p0) / (v1 - v0)
            } else {
                0.0
            };
            (s, f64::from(p0) - s * v0)
        };
        let (sx, ox) = axis(a.0, b.0, x.start, x.end);
        let (sy, oy) = axis(a.1, b.1, y.start, y.end);
        Self {
            scale: [sx, sy],
            offset: [ox, oy],
        }
    }

    /// The pixel of the data point (x, y), to a tenth of a pixel.
    pub fn at(&self, x: f64, y: f64) -> [f32; 2] {
        let r = |v: f64| ((v * 10.0).round() / 10.0) as f32;
        [
            r(self.scale[0] * x + self.offset[0]),
            r(self.scale[1] * y + self.offset[1]),
        ]
    }
}
