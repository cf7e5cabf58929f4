//! The mandrel family (seed 000) checked from the program text it writes.

use pilgrim_kernel::families::revolution::GrindingCheck;
use pilgrim_kernel::program::{block_label, build, AxisProgram, PostProcessor, SharedPost};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::{MandrelLaw, Params, PartFamily, Profile, Side, Toolpath};
use std::collections::BTreeMap;
use std::path::Path;

use crate::common;
use common::{grinder, params_on};

const R_S: f64 = 20.0;

fn family() -> ScriptFamily {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/mandrel.rhai");
    ScriptFamily::load(&path, &Limits::default(), &Access::default()).unwrap()
}

/// The family's parameters with `sets` over its defaults.
fn params(fam: &ScriptFamily, sets: &[(&str, &str)]) -> Params {
    params_on(fam, &BTreeMap::new(), sets)
}

/// The blocks of each pass of a Sinumerik program: (Z, X, U), modal words
/// carried over, passes split at their comments.
fn passes_from_text(text: &str) -> Vec<(String, Vec<[f64; 3]>)> {
    let mut passes: Vec<(String, Vec<[f64; 3]>)> = Vec::new();
    let mut at = [f64::NAN; 3];
    for line in text.lines() {
        if let Some(c) = line.strip_prefix("; ") {
            if c.starts_with("pass ") || ["start", "approach", "end"].contains(&c) {
                passes.push((c.to_owned(), vec![]));
            }
            continue;
        }
        if !line.starts_with('N') {
            continue;
        }
        let mut moved = false;
        for w in line.split_whitespace() {
            let k = match w.as_bytes()[0] {
                b'Z' => 0,
                b'X' => 1,
                b'U' => 2,
                _ => continue,
            };
            at[k] = w[1..].parse().unwrap();
            moved = true;
        }
        if moved {
            if let Some(p) = passes.last_mut() {
                p.1.push(at);
            }
        }
    }
    passes
}

fn program_text() -> (ScriptFamily, String, AxisProgram) {
    let fam = family();
    let values = params(&fam, &[]);
    let tp = fam.toolpath(&values).unwrap();
    let program = build(&tp, &grinder(), "mandrel").unwrap();
    let text = SharedPost.post(&program, "sinumerik").unwrap();
    (fam, text, program)
}

/// Every finishing block puts the rounding's centre (Z, X + R_s) at R_s from
/// the nominal profile, read back from the program's text: the wheel's
/// blocks within 0.1 um, the blocks the steady rest adds on the wheel's
/// straight moves between them within the chords' half tolerance (0.5 um).
#[test]
fn finishing_blocks_stand_at_r_s_from_the_law() {
    let (_, text, _) = program_text();
    let passes = passes_from_text(&text);
    let (name, finish) = passes
        .iter()
        .rev()
        .find(|p| p.0.starts_with("pass "))
        .unwrap();
    assert!(name.contains("stock 0"), "{name}");
    let law = MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap();
    // The ground profile: the transition's line before the law, the end
    // cone (d 52 -> 44 mm over 40 mm) and its line beyond the part's end.
    let x = |z: f64| {
        if z < 0.0 {
            law.x(0.0) + law.dx(0.0) * z
        } else if z > 400.0 {
            26.0 - 0.1 * (z - 400.0)
        } else {
            law.x(z)
        }
    };
    let (mut worst, mut on): (f64, usize) = (0.0, 0);
    for b in finish {
        let (cz, cx) = (b[0], b[1] + R_S);
        // Nearest point of the profile: a fine search, then golden sections.
        let d2 = |z: f64| (z - cz).powi(2) + (x(z) - cx).powi(2);
        let mut best = cz;
        for i in 0..=400 {
            let z = cz - 2.0 + 4.0 * i as f64 / 400.0;
            if d2(z) < d2(best) {
                best = z;
            }
        }
        let dist = d2(common::golden_min(d2, best - 0.01, best + 0.01, 100)).sqrt();
        worst = worst.max((dist - R_S).abs());
        on += usize::from((dist - R_S).abs() <= 1e-4);
    }
    assert!(
        worst <= 0.5e-3 + 1e-4,
        "a finishing block is {worst:e} mm off R_s"
    );
    // The rest adds a few blocks to the finish: most are the wheel's.
    assert!(on * 10 >= finish.len() * 7, "{on} of {}", finish.len());
    assert!(finish.len() > 20);
}

/// Bad parameters stop the run with a clear message, and nothing is written.
#[test]
fn bad_mandrel_parameters_are_refused_and_nothing_is_written() {
    let dir = std::env::temp_dir().join(format!("pilgrim-mandrel-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.join("out");
    let run = |sets: &[&str]| {
        let mut args = vec![
            "run",
            "scripts/mandrel.rhai",
            "--out",
            common::s(&out),
            "--quiet",
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        let (code, _, err) = common::pilgrim(&args);
        (code, err)
    };
    let (code, err) = run(&[]);
    assert_eq!(code, 0, "{err}");
    let before = std::fs::read(out.join("program.mpf")).unwrap();
    rest_stands_where_u_puts_it(&out, -180.0);
    for (sets, expected) in [
        (
            vec!["d_min=60"],
            "mandrel d_min = 60 is out of range: at most d_max = 52",
        ),
        (vec!["l_r=0"], "mandrel L_r must be > 0, got 0"),
        (vec!["n=0"], "mandrel n must be > 0, got 0"),
        (vec!["stock=-0.1"], "the stock is not negative"),
        (
            vec!["n=30", "rounding_r=60", "wheel_w=130"],
            "tool radius 60 mm exceeds the profile's radius of curvature",
        ),
        (vec!["rest_r=140"], "axis U at 1"),
        (
            vec!["d_mn=40"],
            "unknown parameter 'd_mn' from --set (parameters: clearance, cone_d, cone_len, correction, cuts, d_max, d_min",
        ),
        (
            vec!["cuts=[0.15,0.1]"],
            "the cuts add up to the stock (cuts add up to 0.25 mm, stock 0.3 mm)",
        ),
        (vec!["cuts=[0.4,-0.1]"], "no cut is negative"),
        (
            vec!["correction=nothere.csv"],
            "nothere.csv: not a readable file beside the script or the parameter file",
        ),
        (
            vec!["shank_len=100"],
            "pass 1: the steady rest's support at point 1 of the pass (z_r = z + B, B = -180.0000 mm) has nothing under it: its centre at z = -190.1200",
        ),
        (
            vec!["spindle=5000"],
            "spindle speed S5000 is outside the range of spindle S of machine 3K152VF20, [0, 630] rpm",
        ),
        (
            vec!["tolerance=0.0001"],
            "a verification tolerance of 0.0001 mm is finer than twice the program's resolution (0.0001 mm steps)",
        ),
        (vec!["tolerance=0.000001"], "tolerance"),
        (
            vec!["finish_feed=2000"],
            "verification failed: the finished surface strays",
        ),
    ] {
        let (code, err) = run(&sets);
        assert_eq!(code, 1, "{sets:?}: {err}");
        assert!(err.contains(expected), "{sets:?}: {err}");
        assert_eq!(
            std::fs::read(out.join("program.mpf")).unwrap(),
            before,
            "{sets:?}"
        );
    }
    // The wheel too round is refused naming the places, near the law's end.
    let (_, err) = run(&["n=30", "rounding_r=60", "wheel_w=130"]);
    assert!(err.contains("z = 39"), "{err}");
    // U beyond its travel names the block as the program numbers it.
    let (_, err) = run(&["rest_r=140"]);
    assert!(
        err.contains("N40 in \"approach\": axis U at ")
            && err.contains("outside its travel [0, 150] mm"),
        "{err}"
    );
    // A finish whose ridge breaks the tolerance names the pass and its feed.
    let (_, err) = run(&["finish_feed=2000"]);
    assert!(
        err.contains("(pass 4, stock 0.0 um: 5.0125 mm per revolution, a ridge of 0.15766 mm)"),
        "{err}"
    );
    // What failed is written beside the good output, which stays: marked
    // FAILED, the deviation plots and the scene at the block that left the
    // worst place, no program; the next good run removes it.
    let failed = dir.join("out.failed");
    assert!(
        err.contains(&format!("see {}", failed.join("report.html").display()))
            && err.contains("(the last run that succeeded) is as it was"),
        "{err}"
    );
    let r: serde_json::Value = common::report_of(&failed);
    assert_eq!(r["verdict"]["status"], "failed");
    let at = r["verdict"]["failures"][0]["block_index"].clone();
    assert!(
        at.as_u64().is_some() && r["pose_block"] == at,
        "{}",
        r["verdict"]
    );
    for f in [
        "deviation.svg",
        "finish.svg",
        "profile.svg",
        "scene.glb",
        "wheel.stl",
    ] {
        assert!(failed.join(f).is_file(), "{f}");
    }
    assert!(!failed.join("program.mpf").exists() && !failed.join("program.cld").exists());
    let page = std::fs::read_to_string(failed.join("report.html")).unwrap();
    assert!(page.contains("FAILED: no program was written") && page.contains("strays"));
    let (code, err) = run(&[]);
    assert_eq!(code, 0, "{err}");
    assert!(
        !failed.exists(),
        "the stale diagnostic stays beside a good output"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The rest's roller in `out/rest.stl` stands where the pose block's U and
/// the machine's offset `b` put it: its top on the far side at
/// -(U - R_o), touching the part, its middle at z = Z + B.
fn rest_stands_where_u_puts_it(out: &Path, b: f64) {
    let report: serde_json::Value = common::report_of(out);
    let block = report["pose_block"].as_u64().unwrap() as usize;
    let mut csv = csv::Reader::from_path(out.join("report.csv")).unwrap();
    let header = csv.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = csv.records().map(Result::unwrap).collect();
    assert_eq!(rows.len() as u64, report["blocks"].as_u64().unwrap());
    let row = &rows[block - 1];
    let col = |name: &str| header.iter().position(|h| h.starts_with(name)).unwrap();
    let (z, u): (f64, f64) = (
        row[col("Z ")].parse().unwrap(),
        row[col("U ")].parse().unwrap(),
    );
    let rest = pilgrim_kernel::mesh::read_stl(&out.join("rest.stl")).unwrap();
    rest.check_closed().unwrap();
    let (lo, hi) = rest.bounds();
    assert!(
        (hi[0] + (u - 25.0)).abs() < 1e-3,
        "roller top {} for U {u}",
        hi[0]
    );
    let middle = 0.5 * (lo[2] + hi[2]);
    assert!(
        (middle - (z + b)).abs() < 1e-3,
        "roller at z = {middle}, Z {z} + B {b}"
    );
}

/// The family's toolpath and program for `values` on the 3K152VF20, and a
/// replay verification of any program against the family's nominal.
fn job(
    fam: &ScriptFamily,
    values: &Params,
) -> (
    Toolpath,
    AxisProgram,
    impl Fn(&AxisProgram) -> Result<GrindingCheck, String>,
) {
    let tp = fam.toolpath(values).unwrap();
    let grinder = grinder();
    let program = build(&tp, &grinder, "mandrel").unwrap();
    let v = fam
        .verification(values)
        .unwrap()
        .unwrap()
        .into_profile()
        .unwrap();
    let passes = pilgrim_kernel::program::pass_blocks(&program, &tp.passes);
    let reference = tp.tool.reference;
    let pilgrim_kernel::ToolShape::Wheel(wheel) = tp.tool.shape else {
        panic!("the mandrel's tool is a wheel")
    };
    let check = move |program: &AxisProgram| {
        pilgrim_kernel::families::revolution::check_grinding(
            program,
            &grinder,
            &reference,
            &wheel,
            &passes,
            &v.profile,
            v.blank.as_deref(),
            (v.from, v.to),
            v.tolerance,
        )
        .and_then(|c| c.verified(program))
        .map_err(|e| e.to_string())
    };
    (tp, program, check)
}

/// The default job verifies, and one corrupted block of the finishing pass
/// fails verification naming that block.
#[test]
fn verification_catches_a_corrupted_block() {
    let fam = family();
    let values = params(&fam, &[]);
    let (_, mut program, check) = job(&fam, &values);
    let ok = check(&program).unwrap();
    let finish = ok.passes.last().unwrap();
    assert!(finish.deviation.max_abs <= 1e-3, "{finish:?}");
    // Each earlier pass leaves its stock: the first pass, one of three
    // equal roughing cuts of the stock less the 20 um finish, 206.7 um.
    let left = 0.3 - (0.3 - 0.02) / 3.0;
    assert!(
        (ok.passes[0].deviation.max_below - left).abs() < 1e-3,
        "{:?}",
        ok.passes[0]
    );
    // Each pass cuts into the surface before it, the blank's first: no
    // ridge stands above the 0.3 mm of stock, nor above the surface the
    // pass before left, stretch by stretch (within 0.1 um of sampling).
    assert!(
        ok.passes[0].deviation.max_above <= 0.3 + 1e-6,
        "pass 1 stands {} mm above the nominal: above the blank",
        ok.passes[0].deviation.max_above
    );
    for w in ok.passes.windows(2) {
        for (a, b) in w[0].along_z.iter().zip(&w[1].along_z) {
            assert_eq!(a[0], b[0]);
            assert!(
                b[2] <= a[2] + 1e-4,
                "{} at z {}: {} mm above the nominal, over {} left before it",
                w[1].name,
                b[0],
                b[2],
                a[2]
            );
        }
    }
    // The curves drawn (deviation.svg, finish.svg) hold each pass's
    // extremes exactly, ridges and all.
    for p in &ok.passes {
        let low = p.along_z.iter().map(|b| b[1]).fold(f64::INFINITY, f64::min);
        let high = p
            .along_z
            .iter()
            .map(|b| b[2])
            .fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(
            (low, high),
            (p.deviation.max_below, p.deviation.max_above),
            "{}",
            p.name
        );
        assert!(p.along_z.len() <= pilgrim_kernel::families::revolution::PROFILE_BUCKETS);
    }
    // Block 40 of the finishing pass goes 5 um too deep.
    let k = finish.first_block - 1 + 40;
    let x = program.axes.iter().position(|a| a.name == "X").unwrap();
    program.blocks[k].values[x] -= 0.005;
    let e = check(&program).unwrap_err();
    // The move into the block or the one out of it.
    let named = |k| {
        format!(
            "where {} in \"{}\" cuts it",
            block_label("sinumerik", k),
            finish.name
        )
    };
    assert!(
        e.contains(&named(k)) || e.contains(&named(k + 1)),
        "{e} (k {k}: {})",
        named(k)
    );
    assert!(e.contains("strays -0.00"), "{e}");
}

/// The example parameter files run and verify.
#[test]
fn example_parameter_files_run() {
    for f in ["mandrel-small.toml", "mandrel-large.toml"] {
        let out = std::env::temp_dir().join(format!(
            "pilgrim-mandrel-example-{}-{f}",
            std::process::id()
        ));
        let params = format!("scripts/examples/{f}");
        let (code, stdout, stderr) = common::pilgrim(&[
            "run",
            "scripts/mandrel.rhai",
            "--params",
            &params,
            "--out",
            common::s(&out),
        ]);
        assert_eq!(code, 0, "{f}: {stderr}");
        assert!(stdout.contains("finish within 0.000"), "{f}: {stdout}");
        let svg = std::fs::read_to_string(out.join("profile.svg")).unwrap();
        assert!(svg.starts_with("<svg ") && svg.ends_with("</svg>\n"), "{f}");
        // Each pass's deviation, and the finish against the tolerance band.
        let dev = std::fs::read_to_string(out.join("deviation.svg")).unwrap();
        let fin = std::fs::read_to_string(out.join("finish.svg")).unwrap();
        assert!(
            dev.contains("pass 1, stock") && dev.contains("surface minus nominal, um"),
            "{f}"
        );
        assert!(fin.contains("tolerance +-1.0 um"), "{f}");
        // The stock each pass removed, the first from the blank.
        let stock = std::fs::read_to_string(out.join("stock.svg")).unwrap();
        assert!(
            stock.contains("stock removed, um") && stock.contains("pass 1, stock"),
            "{f}"
        );
        // Three panels (plotters charts): blank, part and the wheel
        // centre's path; the rest's track in each pass; the curvature (far
        // below the wheel's limit, so no limit line). Legends name them.
        // (plotters writes a text's content on its own line.)
        assert_eq!(svg.matches(">\nz, mm\n</text>").count(), 3, "{f}");
        for name in [
            ">\nblank\n<",
            ">\npart\n<",
            ">\nwheel centre, pass ",
            ">\nR_s x curvature\n<",
        ] {
            assert!(svg.contains(name), "{f}: {name}");
        }
        assert_eq!(
            svg.matches(", stock ").count(),
            if f.contains("small") { 5 } else { 6 } + 1,
            "{f}"
        );
        assert!(!svg.contains("the wheel's limit\n<"), "{f}");
        std::fs::remove_dir_all(&out).ok();
    }
}

/// The default run's STEP solids are the family's bodies: the part's and
/// the blank's volumes those of their profiles (pi integral of x^2 by
/// Simpson, independent of the fit) within the STEP tolerance times the
/// lateral area, the wheel's by Pappus's theorem; FreeCAD imports them in CI
/// (`.ci/freecad_check.py`) and checks the same volumes. Its report page
/// shows the run's own figures, plots, program and scene; headless Chromium
/// opens it in CI (`.ci/page/check.js`).
#[test]
fn step_solids_and_page_are_the_runs() {
    let out = common::scratch("mandrel", "step").join("out");
    let (code, _, err) = common::pilgrim(&[
        "run",
        "scripts/mandrel.rhai",
        "-q",
        "--out",
        common::s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = common::report_of(&out);
    let tol = report["step_tolerance_mm"].as_f64().unwrap();
    assert_eq!(tol, 1e-3);
    // The page opens with the verdict: passed, the finish as a share of
    // its tolerance.
    let verdict = &report["verdict"];
    assert_eq!(verdict["status"], "passed");
    let finish = &verdict["figures"][0];
    let share = finish["value"].as_f64().unwrap().abs() / finish["tolerance"].as_f64().unwrap();
    assert!(share > 0.5 && share <= 1.0, "{finish}");
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.contains("<b>PASSED: every check and figure held</b>"));
    // The page names the finish's worst place by the block the program
    // numbers (it once named the block after it).
    let finish = &report["verification"]["passes"][3]["deviation"];
    let b = finish["block"].as_u64().unwrap() as usize;
    let worst = format!(
        "the worst at z = {:.3} mm, {}.",
        finish["at_z"].as_f64().unwrap(),
        block_label("sinumerik", b - 1)
    );
    assert!(page.contains(&worst), "{worst} not on the page");
    assert!(
        page.contains(&format!("{:.1}%", 100.0 * share)),
        "no share on the page"
    );
    let solid = |name: &str| {
        report["solids"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["name"] == name)
            .unwrap_or_else(|| panic!("no solid {name}"))
            .clone()
    };
    let fam = family();
    let values = params(&fam, &[]);
    for body in fam.part(&values).unwrap() {
        let pilgrim_kernel::PartGeometry::Revolution(p) = &body.geometry else {
            panic!("{} is not a body of revolution", body.name)
        };
        let (v, area) = common::revolution_volume_and_area(p);
        let s = solid(&body.name);
        let allowed = tol * area;
        let got = s["volume_mm3"].as_f64().unwrap();
        assert!(
            (got - v).abs() <= allowed,
            "{}: {got} vs {v} +- {allowed}",
            body.name
        );
        assert!(s["deviation_mm"].as_f64().unwrap() <= tol);
        let text = std::fs::read_to_string(out.join(format!("{}.step", body.name))).unwrap();
        assert!(text.contains(&format!("PRODUCT('{0}','{0}'", body.name)));
        common::leave_step_for_freecad(&out, "mandrel", &body.name, v, allowed);
    }
    // The wheel: D 500, R_s 20, width 40 (the family's defaults): the
    // rectangle turned less the two corners outside the rounding.
    let (r, rho, b) = (250.0, 20.0, 40.0);
    let pi = std::f64::consts::PI;
    let corner = rho * rho * (1.0 - pi / 4.0);
    let centroid = r - rho + 2.0 * rho / (3.0 * (4.0 - pi));
    let v = pi * r * r * b - 2.0 * 2.0 * pi * centroid * corner;
    let got = solid("wheel")["volume_mm3"].as_f64().unwrap();
    assert!((got - v).abs() <= 1e-3, "wheel: {got} vs {v}");
    common::leave_step_for_freecad(&out, "mandrel", "wheel", v, 1e-6 * v);
    common::leave_for_checkers(&out, "mandrel");
    // The rest's stand-off between blocks, charted per pass on a 1 mm
    // grid, keeps the extremes the report notes.
    let gaps = report["tables"]["rest_gap"].as_object().unwrap();
    let (mut hi, mut lo) = (f64::MIN, f64::MAX);
    for (name, col) in gaps.iter().filter(|(n, _)| n.starts_with("pass ")) {
        for v in col.as_array().unwrap() {
            let v = v.as_f64().unwrap();
            (hi, lo) = (hi.max(v), lo.min(v));
        }
        assert_eq!(
            col.as_array().unwrap().len(),
            gaps["z_mm"].as_array().unwrap().len(),
            "{name}"
        );
    }
    let note = |n: &str| report["notes"][n].as_f64().unwrap() * 1e3;
    assert!(
        (hi - note("rest_max_gap_between_blocks_mm")).abs() < 1e-9,
        "{hi}"
    );
    assert!(
        (lo + note("rest_max_press_between_blocks_mm")).abs() < 1e-9,
        "{lo}"
    );
    assert!(report["files"]
        .as_array()
        .unwrap()
        .iter()
        .any(|f| f == "rest_gap.svg"));
    // The page of the same run: its figures are the run's files.
    common::check_page(&out, "program.mpf", 6.0);
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    let finish = &report["verification"]["passes"][3]["deviation"];
    assert!(page.contains(&format!(
        "within <b>{:.5} mm</b> of the nominal; the worst at z = {:.3} mm",
        finish["max_abs"].as_f64().unwrap(),
        finish["at_z"].as_f64().unwrap()
    )));
    for f in ["profile.svg", "deviation.svg", "finish.svg", "stock.svg"] {
        assert!(page.contains(&format!("alt=\"{f}\"")), "{f}");
    }
    common::leave_page_for_chromium(&out, "mandrel");
    std::fs::remove_dir_all(out.parent().unwrap()).ok();
}

/// The report's comparison is fair and the figure holds: the uniform step it
/// names is the longest that keeps every chord of the wheel's path within
/// half the tolerance (a fifth longer breaks it, round the end cone's
/// corner), and the adaptive blocks are at least 3x fewer.
#[test]
fn adaptive_spacing_beats_the_uniform_step_threefold() {
    let fam = family();
    let values = params(&fam, &[]);
    let tp = fam.toolpath(&values).unwrap();
    let (adaptive, uniform, step) = (
        tp.notes["adaptive_blocks"],
        tp.notes["uniform_blocks"],
        tp.notes["uniform_step_mm"],
    );
    assert!(uniform >= 3.0 * adaptive, "{adaptive} vs {uniform}");
    let ground = fam
        .call_with_params("ground_profile", &values)
        .unwrap()
        .cast::<Profile>();
    let e = pilgrim_kernel::equidistant(&ground, R_S, Side::Outside).unwrap();
    let path = Profile::new(e.z.clone(), e.x.clone()).unwrap();
    let s = path.arc_length();
    // The largest distance of the path from its chords at a uniform step h
    // of arc length (points placed on the path by interpolation).
    let at = |t: f64| {
        let i = s.partition_point(|&v| v < t).clamp(1, s.len() - 1);
        let f = (t - s[i - 1]) / (s[i] - s[i - 1]);
        (
            e.z[i - 1] + f * (e.z[i] - e.z[i - 1]),
            e.x[i - 1] + f * (e.x[i] - e.x[i - 1]),
        )
    };
    let worst = |h: f64| {
        let total = s[s.len() - 1];
        let mut worst: f64 = 0.0;
        let mut t = 0.0;
        while t < total {
            let (a, b) = (at(t), at((t + h).min(total)));
            let (dz, dx) = (b.0 - a.0, b.1 - a.1);
            for k in s.partition_point(|&v| v <= t)..s.partition_point(|&v| v < t + h) {
                let d = ((e.z[k] - a.0) * dx - (e.x[k] - a.1) * dz).abs() / dz.hypot(dx);
                worst = worst.max(d);
            }
            t += h;
        }
        worst
    };
    let half = 0.5e-3;
    assert!(worst(step) <= half * 1.01, "{}", worst(step));
    assert!(worst(1.2 * step) > half, "{}", worst(1.2 * step));
}

/// A pass schedule given as a list of cuts: each pass leaves what the list
/// says (checked by replay), a cut of 0 is a spark-out pass at the finish.
#[test]
fn a_list_of_cuts_sets_the_passes() {
    let fam = family();
    let values = params(&fam, &[("cuts", "[0.15, 0.1, 0.04, 0.01, 0]")]);
    let (tp, program, check) = job(&fam, &values);
    let names: Vec<&str> = tp.passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "approach",
            "pass 1, stock 150.0 um",
            "pass 2, stock 50.0 um",
            "pass 3, stock 10.0 um",
            "pass 4, stock 0.0 um",
            "pass 5, stock 0.0 um, spark-out",
        ]
    );
    // The uniform step's count is for the same five passes (the default
    // job's four passes at the same step).
    let four = fam.toolpath(&params(&fam, &[])).unwrap();
    let (adaptive, uniform) = (tp.notes["adaptive_blocks"], tp.notes["uniform_blocks"]);
    assert_eq!(uniform, four.notes["uniform_blocks"] / 4.0 * 5.0);
    assert!(uniform >= 3.0 * adaptive, "{adaptive} vs {uniform}");
    let ok = check(&program).unwrap();
    let left: Vec<f64> = ok.passes.iter().map(|p| p.deviation.max_below).collect();
    for (got, want) in left.iter().zip([0.15, 0.05, 0.01, 0.0, 0.0]) {
        assert!((got - want).abs() < 1e-3, "{left:?}");
    }
}

/// The rest's parameters are the machine's constants: they follow the
/// machine the run uses, and setting one sets the machine's for the whole
/// run: with `--set rest_b=-150` the chain places the rest's roller at
/// Z - 150 where U puts it (and U rides the surface there:
/// `mandrel_fidelity.rs`).
#[test]
fn rest_parameters_are_the_machines() {
    let fam = family();
    let constants: BTreeMap<String, f64> = [("rest_radius", 30.0), ("rest_offset_b", -170.0)]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect();
    let on = params_on(&fam, &constants, &[]);
    assert_eq!(on["rest_r"], pilgrim_kernel::ParamValue::Float(30.0));
    assert_eq!(on["rest_b"], pilgrim_kernel::ParamValue::Float(-170.0));
    let set = params_on(&fam, &constants, &[("rest_r", "25")]);
    assert_eq!(
        set["rest_r"],
        pilgrim_kernel::ParamValue::Float(25.0),
        "--set wins"
    );
    let out = std::env::temp_dir().join(format!("pilgrim-rest-b-{}", std::process::id()));
    let (code, _, err) = common::pilgrim(&[
        "run",
        "scripts/mandrel.rhai",
        "--set",
        "rest_b=-150",
        "--out",
        common::s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    rest_stands_where_u_puts_it(&out, -150.0);
    std::fs::remove_dir_all(&out).ok();
    // A whole-number parameter cannot follow a fractional constant.
    let bad = ScriptFamily::from_source(
        "fn params() { #{ n: #{ value: 3, machine: \"rest_radius\" } } }\nfn toolpath(p) { () }",
        "bad.rhai",
        &Limits::default(),
        &Access::default(),
    )
    .unwrap();
    let e = pilgrim_kernel::params::resolve(
        bad.params(),
        &BTreeMap::from([("rest_radius".to_owned(), 2.5)]),
        &[],
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("the machine's constant rest_radius"),
        "{e}"
    );
}

/// The process's rules on `program` (the default mandrel's, changed), the
/// material the grinding replay cut: the errors' rules and messages.
fn process_errors(
    fam: &ScriptFamily,
    values: &Params,
    program: &AxisProgram,
) -> Vec<(String, String)> {
    let tp = fam.toolpath(values).unwrap();
    let grinder = grinder();
    let v = fam
        .verification(values)
        .unwrap()
        .unwrap()
        .into_profile()
        .unwrap();
    let pilgrim_kernel::ToolShape::Wheel(wheel) = tp.tool.shape else {
        panic!("the mandrel's tool is a wheel")
    };
    let (_, stock) = pilgrim_kernel::families::revolution::replay_grinding(
        program,
        &grinder,
        &tp.tool.reference,
        &wheel,
        &pilgrim_kernel::program::pass_blocks(program, &tp.passes),
        &v.profile,
        v.blank.as_deref(),
        (v.from, v.to),
        v.tolerance,
    )
    .unwrap();
    let stock = stock.expect("the mandrel gives its blank");
    use pilgrim_kernel::MachineKinematics;
    let limits = pilgrim_kernel::process::ProcessLimits::of(grinder.info());
    pilgrim_kernel::process::check(program, &grinder, &tp.tool.reference, Some(&stock), &limits)
        .unwrap()
        .errors
        .into_iter()
        .map(|f| (f.rule, f.message))
        .collect()
}

/// The process as a machinist checks it, on the default mandrel: the
/// steady rest comes onto the turning part at its approach feed and the
/// wheel into the stock at the infeed feed, at the first pass and at
/// every reversal (the program shows both: `N50 G1 U.. F100.0`, `N60 X..
/// F2.0`); the same program with the rest brought on at rapid, the
/// first infeed at the traverse feed, or the wheel's rapid in lowered
/// into the stock is refused, naming the block. (The default once plunged
/// 2 mm at `F2000.0` and brought the rest on under G0.)
#[test]
fn the_process_meets_the_part_at_its_feeds() {
    let fam = family();
    let values = params(&fam, &[]);
    let (_, program, _) = job(&fam, &values);
    assert_eq!(process_errors(&fam, &values, &program), vec![]);
    let text = SharedPost.post(&program, "sinumerik").unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let at = |n: &str| lines.iter().find(|l| l.starts_with(n)).unwrap().to_string();
    assert!(
        at("N40 ").starts_with("N40 U") && !at("N40 ").contains("G1"),
        "{}",
        at("N40 ")
    );
    assert!(
        at("N50 ").starts_with("N50 G1 U") && at("N50 ").ends_with(" F100.0"),
        "{}",
        at("N50 ")
    );
    assert!(
        at("N60 ").starts_with("N60 X") && at("N60 ").ends_with(" F2.0"),
        "{}",
        at("N60 ")
    );
    // Every reversal into the stock at F2.0 too: each pass's first block.
    for (i, l) in lines.iter().enumerate() {
        if l.starts_with("; pass ") {
            assert!(lines[i + 1].ends_with(" F2.0"), "{}", lines[i + 1]);
        }
    }
    let index = |n: &str| {
        (0..program.blocks.len())
            .find(|&k| block_label("sinumerik", k) == n)
            .unwrap()
    };
    let changed = |f: &dyn Fn(&mut AxisProgram)| {
        let mut p = program.clone();
        f(&mut p);
        process_errors(&fam, &values, &p)
    };
    // The rest onto the turning part at rapid.
    let e = changed(&|p| p.blocks[index("N50")].motion = pilgrim_kernel::Motion::Rapid);
    assert!(
        e.len() == 1
            && e[0]
                .1
                .starts_with("N50 in \"approach\": rest comes onto the part at rapid"),
        "{e:?}"
    );
    // The wheel into the stock at the traverse feed. (It comes down in a
    // fraction of a revolution, so the pass's first millimetres are not
    // ground round: the rest meets them later, and says so too.)
    let e = changed(&|p| p.blocks[index("N60")].feed = 1200.0);
    assert!(
        e.iter()
            .all(|(rule, _)| rule == pilgrim_kernel::process::INFEED
                || rule == pilgrim_kernel::process::RIDING)
            && e[0].1.contains("N60 in \"pass 1")
            && e[0].1.contains(
                "into the stock at F1200.0 mm/min; the machine's infeed feed is at most 2 mm/min"
            ),
        "{e:?}"
    );
    // A rapid through the stock: the wheel's rapid in brought down to the
    // first cut's depth.
    let x = program.axes.iter().position(|a| a.name == "X").unwrap();
    let e = changed(&|p| {
        let deep = p.blocks[index("N60")].values[x];
        for k in [index("N30"), index("N40"), index("N50")] {
            p.blocks[k].values[x] = deep;
        }
    });
    assert!(
        e.iter()
            .any(|(rule, m)| rule == pilgrim_kernel::process::RAPID
                && m.starts_with("N30 in \"start\": a rapid into the material")),
        "{e:?}"
    );
}

/// The seed's schedule (four equal cuts of 75 um, roughing at 2000 mm/min)
/// is refused: its finishing pass takes 75 um, more than the machine's
/// finishing stock (30 um); and the report warns that its roughing ridges,
/// 158 um high, stand above their cuts, so that passes 1 to 3 leave the
/// surface before them untouched at the crests. Nothing said so before.
#[test]
fn a_heavy_finish_fails_and_tall_ridges_are_reported() {
    let out = common::scratch("mandrel", "seed-schedule").join("out");
    let (code, _, err) = common::pilgrim(&[
        "run",
        "scripts/mandrel.rhai",
        "-q",
        "--out",
        common::s(&out),
        "--set",
        "rough_feed=2000",
        "--set",
        "finish_cut=0.075",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("the finishing pass \"pass 4, stock 0.0 um\" takes 0.07")
            && err.contains("more than the finishing stock 0.03 mm"),
        "{err}"
    );
    let r: serde_json::Value = common::report_of(&out);
    let warnings: Vec<&str> = r["verdict"]["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w["rule"] == pilgrim_kernel::process::RIDGE)
        .map(|w| w["message"].as_str().unwrap())
        .collect();
    assert_eq!(warnings.len(), 3, "{warnings:?}");
    assert!(
        warnings[0].contains("pass \"pass 1, stock 225.0 um\" leaves ridges 0.157")
            && warnings[0].contains("on a cut of 0.07"),
        "{warnings:?}"
    );
    // With a finishing stock as large as its cut, it runs, and warns.
    let (code, said, err) = common::pilgrim(&[
        "run",
        "scripts/mandrel.rhai",
        "--out",
        common::s(&out),
        "--set",
        "rough_feed=2000",
        "--set",
        "finish_cut=0.075",
        "--set",
        "finish_stock=0.08",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(said.contains("warning: N"), "{said}");
}

/// A machine's chain is the one truth of where its bodies stand: a machine
/// file whose rest chain places the rest 180 mm before the wheel while its
/// constant `rest_offset_b` says 150 mm is refused before anything is
/// computed, naming both; without the constant the rest's offset comes
/// from the chain, and a `--set` the chain cannot follow (it holds a
/// number, not the constant) is refused naming the chain's value.
#[test]
fn the_rests_place_comes_from_the_machines_chain() {
    let dir = common::scratch("mandrel", "rest-literal");
    // The 3K152VF20 written as a machine file, its rest placed by a
    // literal -180 mm while its constant says -150 mm.
    let (code, grinder, err) = common::pilgrim(&["machines", "--toml", "3K152VF20"]);
    assert_eq!(code, 0, "{err}");
    let mut text = grinder.clone();
    for (from, to) in [
        ("constant = \"rest_offset_b\"", "value = -180.0"),
        ("rest_offset_b = -180.0", "rest_offset_b = -150.0"),
    ] {
        assert!(text.contains(from), "{from} not in\n{grinder}");
        // The rest's roller and its arm both stand by the constant.
        text = text.replace(from, to);
    }
    let file = dir.join("grinder-rest-literal.toml");
    std::fs::write(&file, &text).unwrap();
    let out = dir.join("run");
    let run = |machine: &Path, sets: &[&str]| {
        let mut args = vec![
            "run",
            "scripts/mandrel.rhai",
            "--machine",
            common::s(machine),
            "--out",
            common::s(&out),
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        common::pilgrim(&args)
    };
    let (code, _, err) = run(&file, &[]);
    assert_ne!(code, 0, "{err}");
    assert!(
        err.contains("rest_offset_b = -150 mm")
            && err.contains("body rest")
            && err.contains("-180 mm"),
        "{err}"
    );
    assert!(!out.join("program.mpf").exists());
    // Without the constant: the chain's -180 mm.
    let plain = dir.join("grinder.toml");
    std::fs::write(&plain, text.replace("rest_offset_b = -150.0\n", "")).unwrap();
    let (code, _, err) = run(&plain, &[]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["parameters"]["rest_b"]["value"], -180.0);
    rest_stands_where_u_puts_it(&out, -180.0);
    let (code, _, err) = run(&plain, &["rest_b=-150"]);
    assert_ne!(code, 0, "{err}");
    assert!(
        err.contains("rest_b = -150 mm") && err.contains("-180 mm"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
