//! The caliber job end to end (issue 12): the default run on the
//! Mannesmann replayed from `program.mpf` by a simulation of its own, the
//! LZ-250's figure, a corrupted block named by the verification, and bad
//! input refused with no output.

use crate::common;

use common::{pilgrim, pilgrim_in, root, s, scratch};
use lz_250::CaliberKinematics;
use pilgrim_kernel::families::caliber::{check_groove, Groove, GrooveRequest};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::PartFamily;
use std::path::Path;

const SCRIPT: &str = "scripts/caliber.rhai";

/// A wheel placed: its centre and axis.
type Wheel = ([f64; 3], [f64; 3]);

fn scratch_dir(name: &str) -> std::path::PathBuf {
    scratch("caliber", name)
}

/// The value of address `a` in a block's words (`X12.5`).
fn word(line: &str, a: char) -> Option<f64> {
    line.split_whitespace()
        .find(|w| w.starts_with(a) && w[1..].parse::<f64>().is_ok())
        .map(|w| w[1..].parse().unwrap())
}

/// The moves of a Sinumerik program as a control reads them: each block's
/// pass (counted by the pass comments, from 0) and its axes
/// `[X, Z, Y, A, B]` (modal: a word left out keeps its value), the feed
/// moves of the passes only.
fn moves(mpf: &str) -> Vec<(usize, [f64; 5])> {
    let mut at = [f64::NAN; 5];
    let mut pass: Option<usize> = None;
    let mut out = Vec::new();
    for line in mpf.lines() {
        let (code, comment) = line.split_once(';').unwrap_or((line, ""));
        if comment.trim_start().starts_with("pass ") {
            pass = Some(pass.map_or(0, |p| p + 1));
        }
        if comment.trim() == "end" {
            pass = None;
        }
        for (i, a) in ['X', 'Z', 'Y', 'A', 'B'].into_iter().enumerate() {
            if let Some(v) = word(code, a) {
                at[i] = v;
            }
        }
        if let Some(p) = pass {
            if word(code, 'N').is_some() && !code.contains("G0") {
                out.push((p, at));
            }
        }
    }
    out
}

/// The wheel's signed distance (torus with its disc), written here from
/// the geometry, not the kernel's.
fn distance(c: [f64; 3], w: [f64; 3], r_k0: f64, r_k: f64, q: [f64; 3]) -> f64 {
    let v = [q[0] - c[0], q[1] - c[1], q[2] - c[2]];
    let h = v[0] * w[0] + v[1] * w[1] + v[2] * w[2];
    let r = [v[0] - h * w[0], v[1] - h * w[1], v[2] - h * w[2]];
    let rho = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    if rho <= r_k0 - r_k {
        h.abs() - r_k
    } else {
        ((rho - (r_k0 - r_k)).powi(2) + h * h).sqrt() - r_k
    }
}

/// The wheels along every move of a program's passes (8 straight steps
/// each, as the control moves the axes), placed by the Mannesmann plugin's
/// closed form: by pass and by whole degree of the wheel centre's angle.
fn replayed(blocks: &[(usize, [f64; 5])]) -> Vec<Vec<Vec<Wheel>>> {
    let k = CaliberKinematics { cross: true };
    let pose = |row: &[f64; 5]| {
        let q = [
            row[0],
            row[1],
            row[2],
            row[3].to_radians(),
            row[4].to_radians(),
        ];
        k.pose(&q, [0.0; 3], [0.0, 0.0, 1.0])
    };
    let n_pass = blocks.last().unwrap().0 + 1;
    let mut buckets: Vec<Vec<Vec<Wheel>>> = vec![vec![Vec::new(); 360]; n_pass];
    for w in blocks.windows(2) {
        for s in 1..=8 {
            let t = s as f64 / 8.0;
            let mut row = [0.0; 5];
            for i in 0..5 {
                row[i] = w[0].1[i] + (w[1].1[i] - w[0].1[i]) * t;
            }
            let p = pose(&row);
            let deg = p[1].atan2(p[0]).to_degrees().rem_euclid(360.0) as usize % 360;
            buckets[w[1].0][deg].push(([p[0], p[1], p[2]], [p[3], p[4], p[5]]));
        }
    }
    buckets
}

/// The least signed distance from `q` to the default wheel (125 mm, its
/// rounding 8 mm) over the replayed `passes`, within 4 degrees of
/// `theta_deg`.
fn least_distance(
    buckets: &[Vec<Vec<Wheel>>],
    passes: std::ops::Range<usize>,
    theta_deg: f64,
    q: [f64; 3],
) -> f64 {
    let mut d = f64::INFINITY;
    for pass in passes {
        for off in -4i64..=4 {
            let b = (theta_deg.round() as i64 + off).rem_euclid(360) as usize;
            for s in &buckets[pass][b] {
                d = d.min(distance(s.0, s.1, 125.0, 8.0, q));
            }
        }
    }
    d
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

/// The groove the run ground: the example table, monotone between rows,
/// smoothed as the family does (5 iterations from the middle of the sizing
/// section, the section held).
pub(crate) fn groove() -> Groove {
    let t = pilgrim_kernel::profile::read_table(root().join("scripts/caliber-groove.csv")).unwrap();
    let g = Groove::from_tables(150.0, (&t, "theta_deg", "Hp_mm"), (&t, "theta_deg", "B_mm"))
        .unwrap()
        .with_interpolation(pilgrim_kernel::Interpolation::Monotone);
    g.smoothed(5, g.sizing_middle(), g.sizing_rows()).unwrap().0
}

/// The default job on the Mannesmann: every file, and the finish replayed
/// from `program.mpf` by this test's own simulation (the plugin's closed
/// form, the blocks read as written, each move in 8 straight steps, the
/// torus's distance written above) within the tolerance at every point of a
/// grid between the passes (where the scallops are) and on them.
#[test]
fn the_default_job_holds_its_tolerance_read_back_from_the_program() {
    let dir = scratch_dir("default");
    let out = dir.join("out");
    let (code, stdout, err) = pilgrim(&["run", SCRIPT, "--out", s(&out)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains("Mannesmann") && stdout.contains("groove within"),
        "{stdout}"
    );
    for f in [
        "program.mpf",
        "program.cld",
        "program.json",
        "toolpath.json",
        "report.json",
        "report.csv",
        "caliber.stl",
        "wheel.stl",
        "scene.glb",
        "smoothing_d1.svg",
        "smoothing_d2.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let r = report(&out);
    let v = &r["groove_verification"];
    let tol = v["tolerance"].as_f64().unwrap();
    assert_eq!(tol, 0.01);
    assert!(v["max_abs_mm"].as_f64().unwrap() <= tol);
    // The whole section, edge to edge, and the periphery beside it.
    assert_eq!(v["psi_range_deg"], serde_json::json!([-90.0, 90.0]));
    let cut = v["periphery_cut"]["mm"].as_f64().unwrap();
    assert!((-tol..=0.0).contains(&cut), "{}", v["periphery_cut"]);
    // The process's rules hold, the groove's stock measured: the wheel
    // comes in at rapid to its clearance off the turned groove and into it
    // at the infeed feed, along the groove's normal at the first contact,
    // by the linear axes alone (the turn and the swivel stand; at the
    // edge, where the first pass runs, the normal is along the roll's
    // axis: X alone).
    assert_eq!(r["verdict"]["status"], "passed", "{}", r["verdict"]);
    let mpf = std::fs::read_to_string(out.join("program.mpf")).unwrap();
    let first = mpf
        .lines()
        .skip_while(|l| !l.starts_with("; pass 1,"))
        .nth(1)
        .unwrap();
    assert!(
        first.starts_with("N40 G1 X")
            && first.ends_with(" F2.0")
            && !first.contains(" A")
            && !first.contains(" B"),
        "{first}"
    );
    // The contact patch is reported with a size and is in the scene.
    let patch = &v["patch"];
    assert!(
        patch["along_mm"].as_f64().unwrap() > 0.1 && patch["across_mm"].as_f64().unwrap() > 0.1,
        "{patch}"
    );
    // On the groove (the pose block's pass runs at its edge), and no
    // deeper into it than the verification found anywhere.
    assert!(patch["psi_deg"].as_f64().unwrap().abs() <= 90.0, "{patch}");
    assert!(
        patch["least_distance_mm"].as_f64().unwrap() >= -tol,
        "{patch}"
    );
    let doc = gltf::Gltf::from_slice(&std::fs::read(out.join("scene.glb")).unwrap()).unwrap();
    let names: Vec<String> = doc
        .nodes()
        .filter_map(|n| n.name().map(str::to_owned))
        .collect();
    assert!(
        names.iter().any(|n| n == "contact_patch") && names.iter().any(|n| n == "caliber"),
        "{names:?}"
    );
    // Per-pass seed-vs-exact table, and the smoothing's figures.
    let passes = r["tables"]["passes"]["psi_deg"].as_array().unwrap().len();
    assert_eq!(passes, r["cutting_passes"].as_u64().unwrap() as usize);
    assert!(r["notes"]["smoothing_hp_max_change_mm"].as_f64().unwrap() > 0.0);

    // The replay of this test's own.
    let mpf = std::fs::read_to_string(out.join("program.mpf")).unwrap();
    assert!(mpf.contains("FGROUP(A)"), "the roll's turn leads the feed");
    let blocks = moves(&mpf);
    assert!(blocks.len() > 40_000, "{}", blocks.len());
    assert!(blocks.iter().all(|b| b.1.iter().all(|v| v.is_finite())));
    let buckets = replayed(&blocks);
    let n_pass = buckets.len();
    let g = groove();
    let psis: Vec<f64> = r["tables"]["passes"]["psi_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap().to_radians())
        .collect();
    assert_eq!(psis.len(), n_pass);
    let mut worst: f64 = 0.0;
    for step in 0..=56 {
        let ti = (step as f64 * 5.0).to_radians();
        for j in 0..psis.len() - 1 {
            for psi in [psis[j], 0.5 * (psis[j] + psis[j + 1])] {
                let q = g.point(ti, psi).unwrap();
                let q = [q.x, q.y, q.z];
                let passes = j.saturating_sub(1)..(j + 3).min(n_pass);
                let d = least_distance(&buckets, passes, step as f64 * 5.0, q);
                worst = worst.max(d.abs());
            }
        }
    }
    eprintln!("replay of program.mpf by the test: largest |distance| {worst:.6} mm");
    assert!(
        worst <= tol,
        "the replay from program.mpf strays {worst} mm"
    );
    assert!(
        worst > 1e-4,
        "a replay that finds nothing at all is suspect: {worst}"
    );
    common::leave_for_checkers(&out, "caliber");
    // The heat map marks the report's worst places with their figures; the
    // section draws the wheel's rounding once per cutting pass.
    let report: serde_json::Value = common::report_of(&out);
    let g = &report["groove_verification"];
    let map = std::fs::read_to_string(out.join("deviation_map.svg")).unwrap();
    for (key, name) in [("max_left", "most left"), ("max_gouge", "deepest gouge")] {
        let um = g[key]["mm"].as_f64().unwrap() * 1e3;
        assert!(map.contains(&format!("{name} {um:.2} um")), "{name} {um}");
    }
    let section = std::fs::read_to_string(out.join("section.svg")).unwrap();
    assert_eq!(
        section
            .matches("opacity=\"0.35\" stroke=\"#2A6FD8\"")
            .count(),
        report["cutting_passes"].as_u64().unwrap() as usize
    );
    common::check_page(&out, "program.mpf", 8.0);
    assert!(std::fs::read_to_string(out.join("report.html"))
        .unwrap()
        .contains("Verification: the groove replayed in 3-D"));
    common::leave_page_for_chromium(&out, "caliber");
    // The wheel as an exact solid: R_k0 125, r_k 8, 16 wide, by Pappus (the
    // disc less the two corners outside the rounding).
    let (r, rho, b) = (125.0, 8.0, 16.0);
    let pi = std::f64::consts::PI;
    let corner = rho * rho * (1.0 - pi / 4.0);
    let v = pi * r * r * b - 4.0 * pi * (r - rho + 2.0 * rho / (3.0 * (4.0 - pi))) * corner;
    common::leave_step_for_freecad(&out, "caliber", "wheel", v, 1e-6 * v);
    // The roll's sector as an exact solid: its volume the section's moment
    // about the axis integrated over theta (Simpson), the groove's half
    // ellipse in closed form: the rim w (R^2 - hub^2) / 2 less, for the
    // groove of half-width a and depth h, int (R z - z^2 / 2) dx =
    // pi R a h / 2 - 2 a h^2 / 3.
    let g = groove();
    let (r_d, rim) = (150.0, 15.0);
    let width = g.width().x().iter().copied().fold(0.0, f64::max) + 2.0 * rim;
    let hub = r_d - g.depth().x().iter().copied().fold(0.0, f64::max) - rim;
    let (t0, t1) = g.theta_range();
    let m = 20_000;
    let moment = |t: f64| {
        let (a, h) = (g.width().eval(t).unwrap() / 2.0, g.depth().eval(t).unwrap());
        width * (r_d * r_d - hub * hub) / 2.0 - (pi * r_d * a * h / 2.0 - 2.0 * a * h * h / 3.0)
    };
    let step = (t1 - t0) / m as f64;
    let moments: Vec<f64> = (0..=m).map(|k| moment(t0 + step * k as f64)).collect();
    let v = pilgrim_kernel::math::simpson(&moments, step);
    // Within the tolerance over the whole surface (rim, faces, hub and
    // the groove at its widest, generously).
    let area =
        (t1 - t0) * (r_d * (width + pi * 60.0) + r_d * r_d + hub * width) + r_d * width * 2.0;
    common::check_fitted_solid(&out, "caliber", "caliber", v, area);
}

/// The LZ-250 reaches the same exact poses with its four axes (its figure
/// reported); asked for the Mannesmann's swivel about the contact's radius,
/// which needs the cross axis Y it has not, the run is refused before any
/// planning, naming the parameter, the axis and the machine, and writes
/// nothing.
#[test]
fn the_four_axis_machine_reports_its_figure_and_refuses_what_it_cannot_do() {
    let dir = scratch_dir("lz250");
    let out = dir.join("out");
    let (code, _, err) = pilgrim(&["run", SCRIPT, "--machine", "LZ-250", "--out", s(&out)]);
    assert_eq!(code, 0, "{err}");
    let r = report(&out);
    assert_eq!(r["machine"], "LZ-250");
    assert!(r["groove_verification"]["max_abs_mm"].as_f64().unwrap() <= 0.01);
    let mpf = std::fs::read_to_string(out.join("program.mpf")).unwrap();
    assert!(
        !mpf.lines()
            .any(|l| l.split(';').next().unwrap().contains(" Y")),
        "no Y on the LZ-250"
    );
    let bad = dir.join("bad");
    let (code, _, err) = pilgrim(&[
        "run",
        SCRIPT,
        "--machine",
        "LZ-250",
        "--set",
        "cross_axis=true",
        "--out",
        s(&bad),
    ]);
    assert_ne!(code, 0);
    for said in ["cross_axis", "axis Y", "LZ-250"] {
        assert!(err.contains(said), "{said} not in: {err}");
    }
    assert!(!err.contains("gouge"), "refused only after planning: {err}");
    assert!(!bad.exists(), "nothing written");
}

/// The sizing section (theta 200..250 deg in the example table, one depth
/// and width: it sets the tube's finished size) is the groove the family
/// grinds and verifies against, within 0.1 um, between its rows as on
/// them, though the smoothing changes the reliefs beside it by tens of
/// microns.
#[test]
fn the_sizing_section_is_held_through_the_smoothing() {
    let fam =
        ScriptFamily::load(&root().join(SCRIPT), &Limits::default(), &Access::default()).unwrap();
    let values = common::params_from(&fam, &Default::default(), None, &[]);
    let Some(req) = fam
        .verification(&values)
        .unwrap()
        .and_then(|v| v.request::<GrooveRequest>().cloned())
    else {
        panic!("the caliber asks for the groove's replay")
    };
    let t = pilgrim_kernel::profile::read_table(root().join("scripts/caliber-groove.csv")).unwrap();
    let (deg, hp, b) = (
        t.column("theta_deg").unwrap(),
        t.column("Hp_mm").unwrap(),
        t.column("B_mm").unwrap(),
    );
    let row = deg.iter().position(|&d| d == 224.0).unwrap();
    let (mut worst, mut at) = (0.0f64, 0.0);
    for i in 0..=2000 {
        let theta = 200.0 + 50.0 * i as f64 / 2000.0;
        let s = req.groove.section(theta.to_radians()).unwrap();
        let d = (s.ellipse.b - hp[row])
            .abs()
            .max((2.0 * s.half_width() - b[row]).abs());
        if d > worst {
            (worst, at) = (d, theta);
        }
    }
    assert!(
        worst < 1e-4,
        "the sizing section moved {worst} mm at theta {at} deg"
    );
    // The reliefs beside it do move: the smoothing is not a no-op.
    let row = deg.iter().position(|&d| d == 10.0).unwrap();
    let entry = req.groove.section(10f64.to_radians()).unwrap();
    assert!(
        (2.0 * entry.half_width() - b[row]).abs() > 0.01,
        "{}",
        entry.half_width()
    );
}

/// The verification measures the groove the run was asked for: the
/// tables interpolated between rows as `interpolation` says, the edges as
/// `edge_r` or `edge_c` say (the toolpath and the verification build it by
/// the script's one `smoothing(p)`).
#[test]
fn the_verification_measures_the_groove_asked_for() {
    use pilgrim_kernel::families::caliber::EdgeKind;
    use pilgrim_kernel::Interpolation;
    let fam =
        ScriptFamily::load(&root().join(SCRIPT), &Limits::default(), &Access::default()).unwrap();
    for (sets, interpolation, edge) in [
        (vec![], Interpolation::Monotone, None),
        (
            vec![("interpolation", "linear")],
            Interpolation::Linear,
            None,
        ),
        (
            vec![("interpolation", "parabolic"), ("edge_r", "2")],
            Interpolation::Parabolic,
            Some(EdgeKind::Rounding),
        ),
        (
            vec![("edge_c", "1.5")],
            Interpolation::Monotone,
            Some(EdgeKind::Chamfer),
        ),
    ] {
        let values = common::params_from(&fam, &Default::default(), None, &sets);
        let Some(req) = fam
            .verification(&values)
            .unwrap()
            .and_then(|v| v.request::<GrooveRequest>().cloned())
        else {
            panic!("the caliber asks for the groove's replay")
        };
        assert_eq!(req.groove.interpolation(), interpolation, "{sets:?}");
        assert_eq!(req.groove.edge().map(|e| e.0), edge, "{sets:?}");
        if let Some((_, size)) = req.groove.edge() {
            assert_eq!(size.interpolation(), interpolation, "{sets:?}");
        }
    }
}

/// A block moved 0.05 mm off its place in the program: the replay names
/// it (on a coarse job, for time).
#[test]
fn a_corrupted_block_is_named() {
    let fam =
        ScriptFamily::load(&root().join(SCRIPT), &Limits::default(), &Access::default()).unwrap();
    let machine = pilgrim_kernel::plugin::PluginMachine::from_entry(
        "Mannesmann",
        "pilgrim_plugin_mannesmann",
        mannesmann::pilgrim_plugin_mannesmann,
    )
    .unwrap();
    let values = common::params_from(
        &fam,
        &Default::default(),
        None,
        &[
            ("theta_step_deg", "3"),
            ("dpsi_deg", "4"),
            ("verify_theta_deg", "1.5"),
            ("tolerance", "0.5"),
        ],
    );
    let tp = fam.toolpath(&values).unwrap();
    let mut program = pilgrim_kernel::program::build(&tp, &machine, "caliber").unwrap();
    let Some(req) = fam
        .verification(&values)
        .unwrap()
        .and_then(|v| v.request::<GrooveRequest>().cloned())
    else {
        panic!("the caliber asks for the groove's replay")
    };
    let pilgrim_kernel::ToolShape::Wheel(wheel) = tp.tool.shape else {
        panic!("the caliber's tool is a wheel")
    };
    let check = |p: &pilgrim_kernel::program::AxisProgram| {
        check_groove(
            p,
            &machine,
            &tp.tool.reference,
            &wheel,
            &pilgrim_kernel::program::pass_blocks(p, &tp.passes),
            &req,
        )
        .and_then(|c| c.verified())
    };
    let clean = check(&program).unwrap();
    assert!(clean.max_abs_mm < 0.5, "{clean:?}");
    // Block 1000: Z (the wheel's radial position) 0.8 mm in: a gouge.
    let z = program.axes.iter().position(|a| a.name == "Z").unwrap();
    program.blocks[999].values[z] -= 0.8;
    let e = check(&program).unwrap_err().to_string();
    let name = pilgrim_kernel::program::block_name(&program, 999);
    assert!(
        e.contains("gouge") && e.contains(&name),
        "{e} (expected {name})"
    );
}

/// The groove is verified over its whole section whatever the passes
/// cover: passes that stop at psi 80 deg are refused, naming the material
/// they leave by the edge and what to change; a groove whose edge bends
/// toward the wheel's flat side (the example's reliefs as they were, a
/// cosine blend whose width falls ever faster from the groove's ends) is
/// refused naming where the wheel's side cuts it, and why.
#[test]
fn the_groove_is_verified_to_its_edges() {
    let dir = scratch_dir("edges");
    let short = dir.join("short");
    let (code, _, err) = pilgrim(&["run", SCRIPT, "--set", "psi_max_deg=80", "--out", s(&short)]);
    assert_ne!(code, 0, "passes short of the edge accepted");
    assert!(
        err.contains("psi = 90.000 deg") || err.contains("psi = -90.000 deg"),
        "{err}"
    );
    assert!(
        err.contains("material left") && err.contains("outermost passes"),
        "{err}"
    );
    let r = report(&short);
    assert_eq!(r["verdict"]["status"], "failed");
    let left = r["groove_verification"]["max_left"]["mm"].as_f64().unwrap();
    assert!(left > 0.1, "{left}");
    assert!(!short.join("program.mpf").exists());

    let bends = dir.join("bends");
    std::fs::create_dir_all(&bends).unwrap();
    std::fs::copy(
        root().join("tests/fixtures/caliber/cosine-relief.csv"),
        bends.join("groove.csv"),
    )
    .unwrap();
    std::fs::write(bends.join("p.toml"), "table = \"groove.csv\"\n").unwrap();
    let out = bends.join("out");
    let script = root().join(SCRIPT);
    let (code, _, err) = pilgrim_in(
        &bends,
        &["run", s(&script), "--params", "p.toml", "--out", s(&out)],
    );
    assert_ne!(code, 0, "an edge bending toward the wheel accepted");
    let r = report(&out);
    let g = &r["groove_verification"]["max_gouge"];
    let (theta, psi) = (
        g["theta_deg"].as_f64().unwrap(),
        g["psi_deg"].as_f64().unwrap(),
    );
    assert!(g["mm"].as_f64().unwrap() < -0.05, "{g}");
    assert!(psi.abs() > 80.0 && !(12.0..=267.0).contains(&theta), "{g}");
    assert!(err.contains("bends toward the wheel"), "{err}");
    // The wheel's side runs on past the edge into the periphery there.
    let cut = &r["groove_verification"]["periphery_cut"];
    assert!(cut["mm"].as_f64().unwrap() < -0.05, "{cut}");
    assert!(!out.join("program.mpf").exists());
}

/// The rounding of the groove's edge in section `(a, b)` (half-width,
/// depth) by radius `r`, found here as the circle `r` deep that stands `r`
/// from the ellipse (the least distance by golden-section search, the
/// centre by bisection), not by the kernel's tangent equation: its centre
/// along the axis and where it touches the ellipse, `(x, z)`.
fn rounding(a: f64, b: f64, r: f64) -> (f64, (f64, f64)) {
    let nearest = |xc: f64| {
        let d = |t: f64| (a * t.sin() - xc).hypot(b * t.cos() - r);
        let t = common::golden_min(d, 0.0, std::f64::consts::FRAC_PI_2, 200);
        (d(t), (a * t.sin(), b * t.cos()))
    };
    let (mut lo, mut hi) = (a - r, a + r);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if nearest(mid).0 < r {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, nearest(lo).1)
}

/// The 45 deg chamfer `c` of the groove's edge in section `(a, b)`: the
/// line from the periphery `c` beyond the edge, `(a + c - s, s)`, walked
/// in small steps to where it first enters the ellipse and bisected there,
/// not the kernel's quadratic: where it meets the ellipse, `(x, z)`.
fn chamfer(a: f64, b: f64, c: f64) -> (f64, f64) {
    let inside = |s: f64| ((a + c - s) / a).powi(2) + (s / b).powi(2) < 1.0;
    let step = c / 1000.0;
    let mut s = 0.0;
    while !inside(s + step) {
        s += step;
    }
    let (mut lo, mut hi) = (s, s + step);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if inside(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (a + c - lo, lo)
}

/// An edge as the tests find it in one section, on the right: where it
/// leaves the ellipse, where it meets the periphery, points along it in
/// order (its corners among them), and how far a point is from it.
struct EdgeModel {
    joint: (f64, f64),
    end_x: f64,
    points: Vec<(f64, f64)>,
    off: Box<dyn Fn(f64, f64) -> f64>,
}

/// The edge of `kind` ("rounding" or "chamfer") and `size` in the section
/// `(a, b)`.
fn edge_model(kind: &str, a: f64, b: f64, size: f64) -> EdgeModel {
    if kind == "rounding" {
        let (xc, joint) = rounding(a, b, size);
        let phi_t = (xc - joint.0).atan2(size - joint.1);
        let points = (0..=8)
            .map(|k| {
                let phi = phi_t * (1.0 - k as f64 / 8.0);
                (xc - size * phi.sin(), size * (1.0 - phi.cos()))
            })
            .collect();
        EdgeModel {
            joint,
            end_x: xc,
            points,
            off: Box::new(move |x, z| ((x - xc).hypot(z - size) - size).abs()),
        }
    } else {
        let joint = chamfer(a, b, size);
        let end = a + size;
        let points = (0..=8)
            .map(|k| {
                let v = k as f64 / 8.0;
                (joint.0 + (end - joint.0) * v, joint.1 * (1.0 - v))
            })
            .collect();
        EdgeModel {
            joint,
            end_x: end,
            points,
            off: Box::new(move |x, z| (x + z - end).abs() / std::f64::consts::SQRT_2),
        }
    }
}

/// The example groove with its edge from `fixture`'s `column` (a rounding
/// or a chamfer, `kind`): the run verifies it, the notes give its sizes,
/// the solid's first section lies on the ellipse and the edge as this
/// test finds it, and this test's own replay of `program.mpf` finds the
/// edge (its corners included) within the tolerance and the periphery
/// beside it uncut.
fn the_edge_from_the_table_is_ground_and_verified(
    name: &str,
    fixture: &str,
    kind: pilgrim_kernel::families::caliber::EdgeKind,
    column: &str,
    sizes: (f64, f64),
) {
    let dir = scratch_dir(name);
    std::fs::create_dir_all(&dir).unwrap();
    let table = root().join(fixture);
    std::fs::copy(&table, dir.join("groove.csv")).unwrap();
    std::fs::write(dir.join("p.toml"), "table = \"groove.csv\"\n").unwrap();
    let out = dir.join("out");
    let script = root().join(SCRIPT);
    let (code, _, err) = pilgrim_in(
        &dir,
        &["run", s(&script), "--params", "p.toml", "--out", s(&out)],
    );
    assert_eq!(code, 0, "{err}");
    let r = report(&out);
    assert_eq!(r["verdict"]["status"], "passed", "{}", r["verdict"]);
    let word = match kind {
        pilgrim_kernel::families::caliber::EdgeKind::Rounding => "rounding",
        pilgrim_kernel::families::caliber::EdgeKind::Chamfer => "chamfer",
    };
    assert_eq!(r["notes"][format!("edge_{word}_min_mm")], sizes.0);
    assert_eq!(r["notes"][format!("edge_{word}_max_mm")], sizes.1);
    let v = &r["groove_verification"];
    let tol = v["tolerance"].as_f64().unwrap();
    assert!(v["max_abs_mm"].as_f64().unwrap() <= tol, "{v}");
    assert_eq!(v["psi_range_deg"], serde_json::json!([-90.0, 90.0]));
    let cut = v["periphery_cut"]["mm"].as_f64().unwrap();
    assert!((-tol..=0.0).contains(&cut), "{}", v["periphery_cut"]);

    // The groove as ground, its edge from the same column.
    let t = pilgrim_kernel::profile::read_table(&table).unwrap();
    let g = Groove::from_tables(150.0, (&t, "theta_deg", "Hp_mm"), (&t, "theta_deg", "B_mm"))
        .unwrap()
        .with_interpolation(pilgrim_kernel::Interpolation::Monotone)
        .with_edge_from(kind, &t, "theta_deg", column)
        .unwrap();
    let g = g.smoothed(5, g.sizing_middle(), g.sizing_rows()).unwrap().0;
    let at = |theta: f64| {
        let th = theta.to_radians();
        let (a, b) = (
            g.width().eval(th).unwrap() / 2.0,
            g.depth().eval(th).unwrap(),
        );
        let size = g.edge().unwrap().1.eval(th).unwrap();
        (a, b, edge_model(word, a, b, size))
    };

    // The solid's first section (theta 0, y = 0): each point of the groove
    // on the ellipse or on the edge, some on the edge.
    let mut stl = std::fs::File::open(out.join("caliber.stl")).unwrap();
    let mesh = stl_io::read_stl(&mut stl).unwrap();
    let (a, b, edge) = at(0.0);
    let mut on_edge = 0;
    for p in &mesh.vertices {
        let (x, y, axial) = (p[0] as f64, p[1] as f64, p[2] as f64);
        let z = 150.0 - x; // depth from the periphery
        if y.abs() > 1e-9 || x < 0.0 || z <= 1e-4 || axial.abs() > edge.end_x + 1e-4 {
            continue;
        }
        if axial.abs() >= edge.joint.0 - 1e-4 && z <= edge.joint.1 + 1e-4 {
            let d = (edge.off)(axial.abs(), z);
            assert!(d < 2e-4, "({axial}, {z}) is {d} off the {word}");
            on_edge += 1;
        } else {
            let e = (axial / a).powi(2) + (z / b).powi(2);
            assert!(
                (e - 1.0).abs() < 2e-5,
                "({axial}, {z}) off the ellipse: {e}"
            );
        }
    }
    assert!(on_edge >= 2, "{on_edge} points of the solid on the {word}");

    // This test's replay of program.mpf on the edge, each side, every 5
    // degrees, against every pass; and on the periphery beside it.
    let mpf = std::fs::read_to_string(out.join("program.mpf")).unwrap();
    let blocks = moves(&mpf);
    let buckets = replayed(&blocks);
    let n_pass = buckets.len();
    let (mut worst, mut periphery): (f64, f64) = (0.0, f64::INFINITY);
    for step in 0..=56 {
        let theta = step as f64 * 5.0;
        let th = theta.to_radians();
        let (_, _, edge) = at(theta);
        let place = |x: f64, z: f64| [(150.0 - z) * th.cos(), (150.0 - z) * th.sin(), x];
        for side in [-1.0, 1.0] {
            for &(x, z) in &edge.points {
                let q = place(side * x, z);
                worst = worst.max(least_distance(&buckets, 0..n_pass, theta, q).abs());
            }
            for d in [0.05, 0.5, 2.0] {
                let q = place(side * (edge.end_x + d), 0.0);
                periphery = periphery.min(least_distance(&buckets, 0..n_pass, theta, q));
            }
        }
    }
    eprintln!(
        "the {word} replayed from program.mpf: largest |distance| {worst:.6} mm, periphery {periphery:.6} mm"
    );
    assert!(worst <= tol, "the replay strays {worst} mm on the {word}");
    assert!(periphery >= -tol, "the periphery is cut {periphery} mm");
}

/// A copy of `fixture` in `dir` whose data row `row` (from 0) has `value`
/// in column `col`, and the row as the file numbers it.
fn with_cell(fixture: &str, dir: &Path, row: usize, col: usize, value: &str) -> usize {
    std::fs::create_dir_all(dir).unwrap();
    let text = std::fs::read_to_string(root().join(fixture)).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let header = lines
        .iter()
        .position(|l| l.starts_with("theta_deg"))
        .unwrap();
    let mut cells: Vec<String> = lines[header + 1 + row]
        .split(',')
        .map(str::to_owned)
        .collect();
    cells[col] = value.into();
    lines[header + 1 + row] = cells.join(",");
    std::fs::write(dir.join("groove.csv"), lines.join("\n") + "\n").unwrap();
    std::fs::write(dir.join("p.toml"), "table = \"groove.csv\"\n").unwrap();
    header + 2 + row
}

/// Runs the caliber job in `dir` on its `groove.csv`: refused with every
/// one of `expect` in the error, nothing written.
fn refused(dir: &Path, expect: &[&str]) {
    let out = dir.join("out");
    let script = root().join(SCRIPT);
    let (code, _, err) = pilgrim_in(
        dir,
        &["run", s(&script), "--params", "p.toml", "--out", s(&out)],
    );
    assert_ne!(code, 0, "accepted");
    for e in expect {
        assert!(err.contains(e), "'{e}' not in: {err}");
    }
    assert!(!out.exists(), "output written");
}

/// The edge's rounding from the table's column (3 mm at the entry to 2 mm
/// from 20 deg): ground and verified; a radius not positive is refused
/// naming its cell.
#[test]
fn the_edges_rounding_from_the_table_is_ground_and_verified() {
    let fixture = "tests/fixtures/caliber/rounded-edge.csv";
    the_edge_from_the_table_is_ground_and_verified(
        "rounded",
        fixture,
        pilgrim_kernel::families::caliber::EdgeKind::Rounding,
        "edge_r_mm",
        (2.0, 3.0),
    );
    let bad = scratch_dir("rounded-bad");
    let row = with_cell(fixture, &bad, 5, 3, "-1");
    refused(
        &bad,
        &[
            "groove.csv",
            &format!("row {row}"),
            "edge_r_mm",
            "-1",
            "positive",
        ],
    );
}

/// The edge's 45 deg chamfer from the table's column (1.5 mm at the entry
/// to 1 mm from 20 deg): ground and verified, the wheel rolling round its
/// corners; a chamfer so large it meets the wall where it is flatter than
/// 45 deg (a concave corner) is refused naming its cell.
#[test]
fn the_edges_chamfer_from_the_table_is_ground_and_verified() {
    let fixture = "tests/fixtures/caliber/chamfered-edge.csv";
    the_edge_from_the_table_is_ground_and_verified(
        "chamfered",
        fixture,
        pilgrim_kernel::families::caliber::EdgeKind::Chamfer,
        "edge_c_mm",
        (1.0, 1.5),
    );
    let bad = scratch_dir("chamfered-bad");
    let row = with_cell(fixture, &bad, 100, 3, "12");
    refused(
        &bad,
        &[
            "groove.csv",
            &format!("row {row}"),
            "edge_c_mm",
            "12",
            "concave corner",
        ],
    );
}

/// Bad input: each a clear error naming the value and where it is, and no
/// output.
#[test]
fn bad_input_is_refused_with_no_output() {
    let dir = scratch_dir("bad");
    let good = std::fs::read_to_string(root().join("scripts/caliber-groove.csv")).unwrap();
    let rows: Vec<&str> = good.lines().collect();
    let header = rows
        .iter()
        .position(|l| l.starts_with("theta_deg"))
        .unwrap();
    let with = |row: usize, col: usize, value: &str| {
        let mut lines: Vec<String> = rows.iter().map(|l| l.to_string()).collect();
        let mut cells: Vec<String> = lines[header + row].split(',').map(str::to_owned).collect();
        cells[col] = value.to_owned();
        lines[header + row] = cells.join(",");
        lines.join("\n") + "\n"
    };
    let file_row = |row: usize| header + row + 1; // as the file numbers it
    let cases: Vec<(&str, String, Vec<String>, Vec<String>)> = vec![
        (
            "theta",
            with(5, 0, "3"),
            vec![],
            vec!["theta".into(), format!("row {}", file_row(5))],
        ),
        (
            "blank",
            with(7, 1, ""),
            vec![],
            vec![format!("row {}", file_row(7)), "Hp_mm".into()],
        ),
        (
            "text",
            with(9, 2, "wide"),
            vec![],
            vec![format!("row {}", file_row(9)), "B_mm".into(), "wide".into()],
        ),
        (
            "depth",
            with(11, 1, "-2"),
            vec![],
            vec![
                format!("row {}", file_row(11)),
                "Hp".into(),
                "positive".into(),
            ],
        ),
        (
            "width",
            with(12, 2, "0"),
            vec![],
            vec![
                format!("row {}", file_row(12)),
                "B".into(),
                "positive".into(),
            ],
        ),
        (
            "rounding",
            good.clone(),
            vec!["rounding_r=15".into()],
            vec!["r_k".into(), "theta".into(), "psi".into()],
        ),
        (
            "travel",
            good.clone(),
            vec!["roll_r=500".into()],
            vec!["N".into(), "travel".into()],
        ),
        (
            "both-edges",
            good.clone(),
            vec!["edge_r=2".into(), "edge_c=1".into()],
            vec![
                "rounded or chamfered".into(),
                "edge_r = 2".into(),
                "edge_c = 1".into(),
            ],
        ),
    ];
    // Widths from a second table whose row 20 is at another angle.
    let other = with(20, 0, "39.5");
    let mut cases = cases;
    cases.push((
        "two",
        good.clone(),
        vec!["width_table=width.csv".into()],
        vec![
            "width.csv".into(),
            format!("row {}", file_row(20)),
            "same angles".into(),
        ],
    ));
    for (name, table, sets, expect) in cases {
        let case = dir.join(name);
        std::fs::create_dir_all(&case).unwrap();
        std::fs::write(case.join("groove.csv"), table).unwrap();
        std::fs::write(case.join("width.csv"), &other).unwrap();
        std::fs::write(case.join("p.toml"), "table = \"groove.csv\"\n").unwrap();
        let out = case.join("out");
        let mut args = vec![
            "run".to_owned(),
            root().join(SCRIPT).to_str().unwrap().to_owned(),
            "--params".into(),
            "p.toml".into(),
            "--out".into(),
            s(&out).to_owned(),
        ];
        for kv in &sets {
            args.push("--set".into());
            args.push(kv.clone());
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = pilgrim_in(&case, &args);
        assert_ne!(code, 0, "{name}: accepted");
        for e in &expect {
            assert!(err.contains(e.as_str()), "{name}: '{e}' not in: {err}");
        }
        assert!(!out.exists(), "{name}: output written");
    }
}

/// A STEP tolerance no fit of the roll can hold (0.1 nm) is refused after
/// bounded work, naming the body and the option, and nothing is written.
#[test]
fn a_step_tolerance_no_fit_can_hold_is_refused() {
    let out = scratch_dir("step-tolerance").join("out");
    let (code, _, err) = pilgrim(&["run", SCRIPT, "--out", s(&out), "--step-tolerance", "1e-7"]);
    assert_ne!(code, 0, "accepted");
    assert!(
        err.contains("body 'caliber'") && err.contains("loosen --step-tolerance"),
        "{err}"
    );
    assert!(!out.exists(), "something was written");
}
