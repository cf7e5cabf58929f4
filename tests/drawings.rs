//! Nominals as drawings give them: a tapered drawing mandrel from its
//! table of stations (`scripts/examples/taper_mandrel.rhai`), ground and
//! verified, its finish replayed here from the program's text against a
//! nominal built here from the stations and the fillet's own geometry.

use crate::common::{pilgrim, report_of, root, s, scratch};
use crate::mandrel_fidelity::{phases_for, read_program, Pass, Section};
use std::path::{Path, PathBuf};

const SCRIPT: &str = "scripts/examples/taper_mandrel.rhai";

fn taper_run(name: &str, sets: &[&str]) -> (PathBuf, i32, String) {
    let out = scratch("drawings", name).join("run");
    let mut args = vec!["run", SCRIPT, "--out", s(&out), "-q"];
    for set in sets {
        args.extend(["--set", set]);
    }
    let (code, _, err) = pilgrim(&args);
    (out, code, err)
}

/// `pilgrim verify` of the run in `out` (into `check` beside it) passes.
fn verifies(out: &Path) {
    let check = out.with_file_name("check");
    let (code, _, err) = pilgrim(&["verify", s(out), "--out", s(&check), "-q"]);
    assert_eq!(code, 0, "{err}");
}

/// The stations (z, radius) of the shipped table.
fn stations() -> Vec<(f64, f64)> {
    let text =
        std::fs::read_to_string(root().join("scripts/examples/taper_bar_stations.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[0].parse().unwrap(), c[1].parse::<f64>().unwrap() / 2.0)
        })
        .collect()
}

/// The stations the nominal aims at: the first one's Ø18 h4 (ISO 286-2's
/// table: 0/-5 um) at its band's middle, 1.25 um low on the radius.
fn aimed_stations() -> Vec<(f64, f64)> {
    let mut st = stations();
    st[0].1 -= 0.00125;
    st
}

/// The drawing's nominal radius at z: straight lines between stations, the
/// corner at the second last station rounded by a tangent arc of `fillet`
/// (its tangent points `fillet tan(turn / 2)` along each line, its centre
/// `fillet` below both lines).
fn drawn(st: &[(f64, f64)], fillet: f64, z: f64) -> f64 {
    let k = st.len() - 2;
    let (p0, p1, p2) = (st[k - 1], st[k], st[k + 1]);
    let a = (p1.1 - p0.1).atan2(p1.0 - p0.0);
    let b = (p2.1 - p1.1).atan2(p2.0 - p1.0);
    let t = fillet * (0.5 * (a - b)).tan();
    let (t1, t2) = (
        (p1.0 - t * a.cos(), p1.1 - t * a.sin()),
        (p1.0 + t * b.cos(), p1.1 + t * b.sin()),
    );
    if (t1.0..=t2.0).contains(&z) {
        let (cz, cx) = (t1.0 + fillet * a.sin(), t1.1 - fillet * a.cos());
        return cx + (fillet * fillet - (z - cz).powi(2)).sqrt();
    }
    let i = st
        .windows(2)
        .position(|w| z <= w[1].0)
        .unwrap_or(st.len() - 2);
    let (q0, q1) = (st[i], st[i + 1]);
    q0.1 + (q1.1 - q0.1) * (z - q0.0) / (q1.0 - q0.0)
}

/// The lowest and highest the finishing (last) pass leaves from `nominal`
/// over `[from, to]`, replayed from the program as the control moves it.
fn finish_from(
    dir: &Path,
    rounding: f64,
    from: f64,
    to: f64,
    nominal: &dyn Fn(f64) -> f64,
) -> (f64, f64) {
    let text = std::fs::read_to_string(dir.join("program.mpf")).unwrap();
    let written = read_program(&text);
    let passes: Vec<_> = written
        .groups
        .iter()
        .filter(|g| g.0.starts_with("pass "))
        .collect();
    let finish = &passes.last().unwrap().1;
    let before = *passes[passes.len() - 2].1.last().unwrap();
    let pass = Pass::new(before, finish);
    // A wheel rounded across its width: no flat.
    let section = Section {
        r: rounding,
        flat: 0.0,
    };
    let period = 1.0 / written.spindle;
    let phases = phases_for(&pass, section, period);
    let (mut below, mut above) = (0.0_f64, 0.0_f64);
    let n = 15_000;
    for i in 0..=n {
        let z = from + (to - from) * i as f64 / n as f64;
        let (crest, valley) = pass.cut(section, period, phases, z, f64::INFINITY);
        below = below.min(valley - nominal(z));
        above = above.max(crest - nominal(z));
    }
    (below, above)
}

/// Joined by lines, the taper's stations kink by 1e-4 rad (no corners to
/// a 20 mm rounding) and the taper meets the entry cone at a convex corner
/// the drawing rounds with R10: the run passes, and the finish replayed
/// from the program stays within the tolerance of the nominal drawn here,
/// the fillet's arc included (no gouge at the corner), and within its own
/// band (h4, half the general tolerance's width) at the first station;
/// `pilgrim verify` agrees on the written program.
#[test]
fn the_taper_from_its_stations_with_a_fillet_is_ground_within_tolerance() {
    let (out, code, err) = taper_run("linear", &[]);
    assert_eq!(code, 0, "{err}");
    let st = aimed_stations();
    let (below, above) = finish_from(&out, 20.0, 0.0, 0.0, &|z| drawn(&st, 10.0, z));
    assert!(
        below >= -0.00125 && above <= 0.00125,
        "at the h4 station: valleys {below} mm, crests {above} mm"
    );
    let band = &report_of(&out)["verdict"].to_string();
    assert!(
        band.contains("its own band, station 2 (z = 0 mm), d 18 h4: +0/-0.005 mm"),
        "{band}"
    );
    let end = st[st.len() - 1].0;
    let (below, above) = finish_from(&out, 20.0, 0.0, end, &|z| drawn(&st, 10.0, z));
    assert!(
        below >= -0.002 && above <= 0.002,
        "valleys {below} mm, crests {above} mm"
    );
    // Round the fillet too, on its own.
    let k = st.len() - 2;
    let (b, a) = finish_from(&out, 20.0, st[k].0 - 2.0, st[k].0 + 2.0, &|z| {
        drawn(&st, 10.0, z)
    });
    assert!(b >= -0.002 && a <= 0.002, "at the fillet: {b}, {a}");
    verifies(&out);
}

/// Monotone through the stations, the run leaves the first station
/// outside its h4 band (said with the station and its fit) and passes
/// within h5; the natural spline swings beyond them before the cone, and
/// the run says where and by how much.
#[test]
fn a_smooth_nominal_passes_and_a_swinging_one_is_warned_of() {
    let (_, code, err) = taper_run("monotone-h4", &["interpolation=monotone"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("beyond its own band of ±0.00125 mm on the radius (station 2 (z = 0 mm), d 18 h4: +0/-0.005 mm)"),
        "{err}"
    );
    let (out, code, err) = taper_run("monotone", &["interpolation=monotone", "back_fit=h5"]);
    assert_eq!(code, 0, "{err}");
    let report = report_of(&out);
    assert_eq!(
        report["verdict"]["status"], "passed",
        "{}",
        report["verdict"]
    );
    assert!(!report.to_string().contains("swings"));
    let (out, code, err) = taper_run("natural", &["interpolation=natural", "back_fit=h5"]);
    assert_eq!(code, 0, "{err}");
    let warnings = report_of(&out)["verdict"]["warnings"].to_string();
    assert!(
        warnings.contains("natural interpolation swings 0.6") && warnings.contains("at z = 337."),
        "{warnings}"
    );
}

/// `program.mpf` with the finishing and spark-out passes' X tilted by
/// `slope` about z = `pivot` wherever the wheel is at or past `from`.
fn tilted(text: &str, from: f64, pivot: f64, slope: f64) -> String {
    let starts: Vec<usize> = (text.lines().enumerate())
        .filter(|(_, l)| l.starts_with("; pass "))
        .map(|(i, _)| i)
        .collect();
    let first = starts[starts.len() - 2];
    let mut z = f64::NAN;
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        let mut words: Vec<String> = line.split_whitespace().map(str::to_owned).collect();
        if let Some(w) = words
            .iter()
            .find(|w| w.starts_with('Z') && line.starts_with('N'))
        {
            z = w[1..].parse().unwrap();
        }
        if i > first && z >= from {
            for w in words
                .iter_mut()
                .filter(|w| w.starts_with('X') && line.starts_with('N'))
            {
                let x: f64 = w[1..].parse().unwrap();
                *w = format!("X{:.4}", x + slope * (z - pivot));
            }
        }
        out.push_str(&words.join(" "));
        out.push('\n');
    }
    out
}

/// The family's own figure, the entry cone's angle on the replayed part,
/// passes `pilgrim verify` on the program as written and fails it on the
/// program with its cone tilted by 2 arc-minutes (within the profile's
/// band of 10 um held by the built-in figure, so only the family's own
/// can see it).
#[test]
fn the_familys_own_figure_judges_an_edited_program() {
    let (out, code, err) = taper_run("cone", &["tolerance=0.01", "back_fit=h8"]);
    assert_eq!(code, 0, "{err}");
    let check = out.with_file_name("check");
    // A looser tolerance than the family's is taken from the command
    // line only.
    let loose = ["--set", "tolerance=0.01", "--set", "back_fit=h8"];
    let (code, _, err) =
        pilgrim(&[&["verify", s(&out), "--out", s(&check), "-q"][..], &loose].concat());
    assert_eq!(code, 0, "{err}");
    let figure = &report_of(&check)["verification"]["judged"]["figures"][0];
    assert_eq!(
        figure["name"],
        "the entry cone's half-angle from the nominal's"
    );
    assert!(figure["value"].as_f64().unwrap().abs() < 0.5, "{figure}");

    let st = stations();
    let (z0, z1) = (st[st.len() - 2].0, st[st.len() - 1].0);
    let program = out.join("program.mpf");
    let text = std::fs::read_to_string(&program).unwrap();
    let slope = (2.0_f64 / 60.0).to_radians().tan();
    std::fs::write(&program, tilted(&text, z0 + 1.0, 0.5 * (z0 + z1), slope)).unwrap();
    let edited = out.with_file_name("edited");
    let (code, _, err) = pilgrim(&[&["verify", s(&out), "--out", s(&edited)][..], &loose].concat());
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("the entry cone's half-angle from the nominal's is"),
        "{err}"
    );
    let report = report_of(&edited);
    let figure = &report["verification"]["judged"]["figures"][0];
    let off = figure["value"].as_f64().unwrap();
    assert!((off - 2.0).abs() < 0.5, "{figure}");
    // The profile's own figure still holds: only the family's saw it.
    assert!(!err.contains("the finished surface strays"), "{err}");
}

/// The drawing plug's DXF, written by ezdxf (`scripts/examples/
/// drawing_plug_dxf.py`), read as its nominal: in inches, the land's
/// radius, the fillet's arc about its centre, the corner's bulge, the nose
/// SPLINE within the chordal tolerance of the Bezier its four control
/// points make (evaluated here by Bernstein's polynomials); and the
/// example ground from it runs and verifies.
#[test]
fn the_dxf_plug_is_read_as_drawn_and_verified() {
    use pilgrim_kernel::profile::{profile_from_dxf, DxfOptions};
    let bytes = std::fs::read(root().join("scripts/examples/drawing_plug.dxf")).unwrap();
    let chordal = 1e-4;
    let options = DxfOptions {
        layer: "PROFILE".into(),
        diameter: false,
        chordal,
    };
    let p = profile_from_dxf(&bytes, "drawing_plug.dxf", &options).unwrap();
    let inch = 25.4;
    let a = 11.0_f64.to_radians();
    let (rb, rl, zc, rc, rf) = (0.7, 0.6, 1.0, 0.12, 0.25);
    let zf = zc + (rb - rl) / a.tan();
    let tf = rf * (a / 2.0).tan();
    let ze = zf + tf + 0.8;
    assert_eq!(p.z_range(), (-12.0 * inch, (ze + 0.22) * inch));
    // The stem, the back cylinder, the land.
    for (z, r) in [(-6.0, 0.47), (0.5, rb), (ze - 0.4, rl)] {
        let x = p.eval(z * inch).unwrap();
        assert!((x - r * inch).abs() < 1e-9, "z = {z} in: {x}");
    }
    // The fillet: its centre above the land's start, rf from its arc.
    let (cz, cx) = ((zf + tf) * inch, (rl + rf) * inch);
    let z = (zf + 0.3 * tf) * inch;
    let x = p.eval(z).unwrap();
    assert!(
        ((z - cz).hypot(x - cx) - rf * inch).abs() < chordal,
        "fillet at {z}: {x}"
    );
    // The corner's arc, about its centre below the back cylinder.
    let tc = rc * (a / 2.0).tan();
    let (kz, kx) = ((zc - tc) * inch, (rb - rc) * inch);
    let z = zc * inch;
    let x = p.eval(z).unwrap();
    assert!(
        ((z - kz).hypot(x - kx) - rc * inch).abs() < chordal,
        "corner: {x}"
    );
    // The nose: a cubic Bezier, sampled within the chordal tolerance.
    let ctrl = [
        (ze, rl),
        (ze + 0.08, rl),
        (ze + 0.16, rl - 0.04),
        (ze + 0.22, rl - 0.12),
    ];
    for k in 1..50 {
        let t = k as f64 / 50.0;
        let b = [
            (1.0 - t).powi(3),
            3.0 * t * (1.0 - t).powi(2),
            3.0 * t * t * (1.0 - t),
            t.powi(3),
        ];
        let z = inch * b.iter().zip(&ctrl).map(|(w, c)| w * c.0).sum::<f64>();
        let x = inch * b.iter().zip(&ctrl).map(|(w, c)| w * c.1).sum::<f64>();
        let got = p.eval(z).unwrap();
        assert!(
            (got - x).abs() <= 1.05 * chordal,
            "nose at t = {t}: {got} against {x}"
        );
    }
    let out = scratch("drawings", "dxf").join("run");
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/examples/drawing_plug_dxf.rhai",
        "--out",
        s(&out),
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(report_of(&out)["verdict"]["status"], "passed");
    // The drawing is kept beside the run, and the run verifies from it.
    assert!(out.join("drawing_plug.dxf").exists());
    verifies(&out);
}

/// A station mistyped (Ø17.156 for Ø18.156 at z = 240) makes the nominal
/// a valley no 20 mm rounding enters: the run is refused naming the
/// station as the profile numbers it (the stem's point first), its z and
/// its value, not a block; `pilgrim verify` of a good program against
/// that family says the same.
#[test]
fn a_mistyped_station_is_named_where_the_nominal_cannot_be_ground() {
    let dir = scratch("drawings", "mistyped");
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("taper_mandrel.rhai");
    std::fs::copy(root().join(SCRIPT), &script).unwrap();
    let table = std::fs::read_to_string(root().join("scripts/examples/taper_bar_stations.csv"))
        .unwrap()
        .replace("\n240,18.156,", "\n240,17.156,");
    std::fs::write(dir.join("taper_bar_stations.csv"), table).unwrap();
    let named = "z = 240.0000 (a corner: a fillet of at least the tool's radius grinds it; the nominal's station 6 (z = 240 mm, x = 8.578 mm))";
    let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&dir.join("run")), "-q"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(named), "{err}");
    let (good, code, err) = taper_run("for-the-mistyped", &[]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = pilgrim(&[
        "verify",
        s(&good.join("program.mpf")),
        "--family",
        s(&script),
        "--out",
        s(&dir.join("check")),
        "-q",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(named), "{err}");
}
