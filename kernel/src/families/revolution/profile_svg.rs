//! `profile.svg`: a grinding job's profile, the wheel's path, the track of
//! each moving body the toolpath drives (the steady rest) and the
//! curvature, as panels of line plots drawn with plotters (the same job
//! gives the same bytes).

use crate::chart::DrawError;
use crate::machine::{bodies_of, MachineKinematics};
use crate::math::fixed;
use crate::profile::Profile;
use crate::program::{axis_rows, AxisProgram, ProgramPass};
use crate::transform::ToolFrame;

/// One line of a panel.
struct Series {
    name: String,
    color: plotters::style::RGBColor,
    points: Vec<(f64, f64)>,
}

/// One plot: a title, the y quantity, lines sharing the z axis.
struct Panel {
    title: String,
    y_label: String,
    series: Vec<Series>,
}

const COLORS: [plotters::style::RGBColor; 4] = [
    plotters::style::RGBColor(0x44, 0x44, 0x44),
    plotters::style::RGBColor(0xd0, 0x80, 0x00),
    plotters::style::RGBColor(0x2a, 0x6f, 0xd8),
    plotters::style::RGBColor(0x2a, 0x9d, 0x4b),
];

/// `profile.svg`: the part's profiles and the wheel centre's path on the
/// finishing pass; for each machine body moved by an axis the toolpath
/// drives (the steady rest's U), that axis against the z of the body's
/// origin in every cutting pass; the nominal's curvature against the
/// wheel's limit 1/R_s.
///
/// # Failures
/// The machine's bodies or the program's axes not matching.
pub fn profile_svg(
    profiles: &[(String, Profile)],
    program: &AxisProgram,
    passes: &[ProgramPass],
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    nominal: &Profile,
    rounding: f64,
) -> Result<String, DrawError> {
    let cutting: Vec<&ProgramPass> = passes.iter().filter(|p| p.cuts).collect();
    let mut shape: Vec<Series> = profiles
        .iter()
        .enumerate()
        .map(|(i, (name, p))| Series {
            name: name.clone(),
            color: COLORS[i % 2],
            points: p.z().iter().copied().zip(p.x().iter().copied()).collect(),
        })
        .collect();
    if let Some(last) = cutting.last() {
        shape.push(Series {
            name: format!("wheel centre, {}", last.name),
            color: COLORS[2],
            points: crate::replay::replay_blocks(program, machine, tool, last.blocks.clone())
                .map_err(|e| DrawError::new("profile.svg", e))?
                .chunks_exact(6)
                .map(|p| (p[2], p[0].hypot(p[1])))
                .collect(),
        });
    }
    let mut panels = vec![Panel {
        title: "profile (mm) and the wheel's path".into(),
        y_label: "radius x".into(),
        series: shape,
    }];
    panels.extend(body_panels(program, machine, &cutting)?);
    panels.push(curvature_panel(nominal, rounding));
    render(&panels)
}

/// A panel for each machine body an axis of the program drives (the
/// steady rest's U), its axis over z at every cutting pass.
///
/// # Failures
/// The machine's bodies or the program's axes not matching.
fn body_panels(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    cutting: &[&ProgramPass],
) -> Result<Vec<Panel>, DrawError> {
    let mut panels = Vec::new();
    let info = machine.info();
    for body in bodies_of(info).map_err(|e| DrawError::new("profile.svg", e))? {
        let Some(axis) = info
            .driven_axes
            .iter()
            .find(|a| info.axis(a).and_then(|x| x.body.as_deref()) == Some(body.name()))
        else {
            continue;
        };
        let Some(col) = program.axes.iter().position(|a| &a.name == axis) else {
            continue;
        };
        let names = body.chain().axis_names();
        let mut series = Vec::new();
        for (i, p) in cutting.iter().enumerate() {
            let blocks = p.blocks.clone();
            let rows = axis_rows(program, info, names, blocks.clone())
                .map_err(|e| DrawError::new("profile.svg", e))?;
            let points = rows
                .chunks_exact(names.len().max(1))
                .zip(&program.blocks[blocks])
                .map(|(q, b)| (body.chain().frame_unchecked(q).pos.z, b.values[col]))
                .collect();
            series.push(Series {
                name: p.name.clone(),
                color: COLORS[i % COLORS.len()],
                points,
            });
        }
        let label = if body.spec().label.is_empty() {
            body.name()
        } else {
            &body.spec().label
        };
        panels.push(Panel {
            title: format!("{label} {axis} at z + B, every pass"),
            y_label: axis.clone(),
            series,
        });
    }
    Ok(panels)
}

/// The nominal's curvature as a share of the wheel's limit.
fn curvature_panel(nominal: &Profile, rounding: f64) -> Panel {
    // Curvature as a share of the wheel's limit (1 = as round as the wheel):
    // the margin reads directly, and the curve keeps its shape however far
    // below the limit it is (the limit's line is drawn when it is near).
    // Corners (infinite curvature) are left out: the wheel pivots on convex
    // ones, and concave ones never get this far.
    let z = nominal.z();
    let share: Vec<(f64, f64)> = z
        .iter()
        .zip(nominal.curvature())
        .map(|(&z, k)| (z, k * rounding))
        .filter(|(_, s)| s.is_finite())
        .collect();
    let top = share.iter().fold(0.0f64, |m, (_, s)| m.max(s.abs()));
    let mut series = vec![Series {
        name: "R_s x curvature".into(),
        color: COLORS[0],
        points: share,
    }];
    if top >= 0.25 {
        series.push(Series {
            name: "the wheel's limit".into(),
            color: plotters::style::RGBColor(0xcc, 0x22, 0x22),
            points: vec![(z[0], 1.0), (z[z.len() - 1], 1.0)],
        });
    }
    Panel {
        title: format!(
            "curvature of the nominal against the wheel's limit 1/R_s (R_s = {rounding} mm): largest {}",
            fixed(top, 4)
        ),
        y_label: "R_s x curvature".into(),
        series,
    }
}

impl Panel {
    /// The range of its finite values, padded by 5 % (1 either side of a
    /// single value).
    fn y_range(&self) -> (f64, f64) {
        let (y0, y1) = (self.series.iter())
            .flat_map(|s| s.points.iter())
            .filter(|p| p.1.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.1), b.max(p.1))
            });
        if y1 > y0 {
            let pad = 0.05 * (y1 - y0);
            (y0 - pad, y1 + pad)
        } else {
            (y0 - 1.0, y0 + 1.0)
        }
    }
}

/// The panels as SVG, stacked, sharing the z range of all their points,
/// each a plotters chart (axes with ticks and units, a grid, the legend
/// below the data).
fn render(panels: &[Panel]) -> Result<String, DrawError> {
    use plotters::prelude::*;
    let all = || {
        panels
            .iter()
            .flat_map(|p| p.series.iter().flat_map(|s| s.points.iter()))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
    };
    let (z0, z1) = all().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
        (a.min(p.0), b.max(p.0))
    });
    if !z0.is_finite() {
        return Err(DrawError::new("profile.svg", "nothing to draw"));
    }
    let z1 = if z1 > z0 { z1 } else { z0 + 1.0 };
    const CHART: u32 = 300;
    let rows: Vec<u32> = panels
        .iter()
        .map(|p| p.series.len().div_ceil(3) as u32)
        .collect();
    let height: u32 = rows.iter().map(|r| CHART + 24 * r + 8).sum();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1100, height)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| DrawError::new("profile.svg", format!("{e:?}"));
        root.fill(&WHITE).map_err(e)?;
        let mut rest = root;
        for (panel, r) in panels.iter().zip(&rows) {
            let (area, below) = rest.split_vertically(CHART + 24 * r + 8);
            rest = below;
            let (top, legend_area) = area.split_vertically(CHART);
            let (y0, y1) = panel.y_range();
            let mut chart = ChartBuilder::on(&top)
                .caption(&panel.title, ("sans-serif", 18))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(90)
                .build_cartesian_2d(z0..z1, y0..y1)
                .map_err(e)?;
            chart
                .configure_mesh()
                .x_desc("z, mm")
                .y_desc(panel.y_label.as_str())
                .x_label_formatter(&|v| fixed(*v, crate::chart::tick_decimals(z1 - z0)))
                .y_label_formatter(&|v| fixed(*v, crate::chart::tick_decimals(y1 - y0)))
                .label_style(("sans-serif", 13))
                .axis_desc_style(("sans-serif", 14))
                .draw()
                .map_err(e)?;
            let mut items = Vec::new();
            for s in &panel.series {
                let c = s.color;
                chart
                    .draw_series(LineSeries::new(
                        s.points.iter().copied().filter(|p| p.1.is_finite()),
                        c.stroke_width(2),
                    ))
                    .map_err(e)?;
                items.push((s.name.clone(), c));
            }
            crate::chart::legend(&legend_area, &items, (110, 320, 3), 14).map_err(e)?;
        }
        rest.present().map_err(e)?;
    }
    Ok(svg)
}
