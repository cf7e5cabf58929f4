//! `profile.svg`: a grinding job's profile, the wheel's path, the steady
//! rest's track and the curvature, as panels of line plots (hand-written
//! SVG, fixed decimals: the same job gives the same bytes).

use pilgrim_kernel::math::fixed;

/// One line of a panel.
pub struct Series {
    pub name: String,
    pub color: &'static str,
    pub points: Vec<(f64, f64)>,
}

/// One plot: a title, the y quantity, lines sharing the z axis.
pub struct Panel {
    pub title: String,
    pub y_label: String,
    pub series: Vec<Series>,
}

const W: f64 = 900.0;
const H: f64 = 220.0;
const M: f64 = 60.0;

/// The SVG of the panels, stacked, over the z range of all their points.
pub fn render(panels: &[Panel]) -> String {
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
