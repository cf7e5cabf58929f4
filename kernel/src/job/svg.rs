//! `profile.svg`: a grinding job's profile, the wheel's path, the track of
//! each moving body the toolpath drives (the steady rest) and the
//! curvature, as panels of line plots (hand-written SVG, fixed decimals:
//! the same job gives the same bytes).

use crate::machine::{bodies_of, MachineKinematics};
use crate::math::fixed;
use crate::profile::Profile;
use crate::program::pass_blocks;
use crate::program::{axis_rows, AxisProgram};
use crate::toolpath::{Pass, Toolpath};

/// One line of a panel.
struct Series {
    name: String,
    color: &'static str,
    points: Vec<(f64, f64)>,
}

/// One plot: a title, the y quantity, lines sharing the z axis.
struct Panel {
    title: String,
    y_label: String,
    series: Vec<Series>,
}

const COLORS: [&str; 4] = ["#444444", "#d08000", "#2a6fd8", "#2a9d4b"];

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
    toolpath: &Toolpath,
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    nominal: &Profile,
    rounding: f64,
) -> Result<String, String> {
    let cutting: Vec<&Pass> = toolpath.passes.iter().filter(|p| p.cuts()).collect();
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
            points: last
                .points
                .iter()
                .map(|c| (c.point[2], c.point[0].hypot(c.point[1])))
                .collect(),
        });
    }
    let mut panels = vec![Panel {
        title: "profile (mm) and the wheel's path".into(),
        y_label: "radius x".into(),
        series: shape,
    }];
    let info = machine.info();
    for body in bodies_of(info).map_err(|e| e.to_string())? {
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
        for (i, (p, blocks)) in pass_blocks(program, &toolpath.passes)
            .filter(|(p, _)| p.cuts())
            .enumerate()
        {
            let rows = axis_rows(program, info, names, blocks.clone())?;
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
            color: "#cc2222",
            points: vec![(z[0], 1.0), (z[z.len() - 1], 1.0)],
        });
    }
    panels.push(Panel {
        title: format!(
            "curvature of the nominal against the wheel's limit 1/R_s (R_s = {rounding} mm): largest {}",
            fixed(top, 4)
        ),
        y_label: "R_s x curvature".into(),
        series,
    });
    Ok(render(&panels))
}

const W: f64 = 900.0;
const H: f64 = 220.0;
const M: f64 = 60.0;

/// The SVG of the panels, stacked, over the z range of all their points.
fn render(panels: &[Panel]) -> String {
    let all = || {
        panels
            .iter()
            .flat_map(|p| p.series.iter().flat_map(|s| s.points.iter()))
    };
    let (z0, z1) = all().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
        (a.min(p.0), b.max(p.0))
    });
    let height = panels.len() as f64 * (H + M) + M;
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
        W + 2.0 * M,
        height,
        W + 2.0 * M,
        height
    );
    for (k, panel) in panels.iter().enumerate() {
        let top = M + k as f64 * (H + M);
        let pts = || {
            panel
                .series
                .iter()
                .flat_map(|s| s.points.iter())
                .filter(|p| p.1.is_finite())
        };
        let (y0, y1) = pts().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.1), b.max(p.1))
        });
        let (y0, y1) = if y1 > y0 {
            (y0, y1)
        } else {
            (y0 - 1.0, y0 + 1.0)
        };
        let sx = |z: f64| M + (z - z0) / (z1 - z0).max(1e-12) * W;
        let sy = |y: f64| top + H - (y - y0) / (y1 - y0) * H;
        out += &format!(
            "<text x=\"{M}\" y=\"{}\" font-weight=\"bold\">{}</text>\n<rect x=\"{M}\" y=\"{top}\" width=\"{W}\" height=\"{H}\" fill=\"none\" stroke=\"#888\"/>\n",
            top - 8.0,
            xml(&panel.title)
        );
        out += &format!(
            "<text x=\"4\" y=\"{}\">{}</text>\n<text x=\"4\" y=\"{}\">{}</text>\n<text x=\"4\" y=\"{}\" fill=\"#555\">{}</text>\n",
            top + 12.0,
            fixed(y1, 4),
            top + H,
            fixed(y0, 4),
            top + H / 2.0,
            xml(&panel.y_label)
        );
        out += &format!(
            "<text x=\"{M}\" y=\"{}\">z = {} mm</text>\n<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{} mm</text>\n",
            top + H + 14.0,
            fixed(z0, 1),
            M + W,
            top + H + 14.0,
            fixed(z1, 1)
        );
        for (i, s) in panel.series.iter().enumerate() {
            let path: Vec<String> = s
                .points
                .iter()
                .filter(|p| p.1.is_finite())
                .map(|p| format!("{},{}", fixed(sx(p.0), 2), fixed(sy(p.1), 2)))
                .collect();
            out += &format!(
                "<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\" points=\"{}\"/>\n<text x=\"{}\" y=\"{}\" fill=\"{}\">{}</text>\n",
                s.color,
                path.join(" "),
                M + W - 200.0,
                top + 16.0 + 14.0 * i as f64,
                s.color,
                xml(&s.name)
            );
        }
    }
    out += "</svg>\n";
    out
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
