//! `pilgrim compensate` on the default mandrel: a measured part in, a
//! corrected program out.

use crate::common::{self, pilgrim, s, scratch};
use std::path::Path;

/// The default mandrel's nominal diameter at z (mm): the law over the
/// working part, the end cone after it (scripts/mandrel.rhai's defaults),
/// written here from MATH §2.1, not taken from the kernel.
fn law(z: f64) -> f64 {
    let (d_min, d_max, l, k, n) = (38.0, 52.0, 400.0, 0.012, 2.3);
    if z <= l {
        d_min + (d_max - d_min - k * l) * (z / l).powf(n) + k * z
    } else {
        d_max + (44.0 - d_max) * (z - l) / 40.0
    }
}

/// The error a wheel leaves that wears linearly along its finishing pass
/// (6 um of radius over the pass, which runs from z = 450 to -10): the part
/// larger where the pass ends.
fn wear(z: f64) -> f64 {
    0.006 * (450.0 - z) / 460.0
}

/// The default mandrel run into `dir/run`.
fn mandrel_run(dir: &Path) -> std::path::PathBuf {
    let run = dir.join("run");
    let (code, _, err) = pilgrim(&["run", "scripts/mandrel.rhai", "--out", s(&run), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    run
}

/// The finishing pass's largest deviation from its target (mm), as a
/// run's report says it.
fn finish_of(report: &serde_json::Value) -> f64 {
    report["verification"]["passes"]
        .as_array()
        .unwrap()
        .last()
        .unwrap()["deviation"]["max_abs"]
        .as_f64()
        .unwrap()
}

/// The largest distance of the run's `correction.csv` from `-error(z)`.
fn correction_off(out: &Path, error: &dyn Fn(f64) -> f64) -> f64 {
    let text = std::fs::read_to_string(out.join("correction.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let (z, dr) = l.split_once(',').unwrap();
            let (z, dr): (f64, f64) = (z.parse().unwrap(), dr.parse().unwrap());
            (dr + error(z)).abs()
        })
        .fold(0.0, f64::max)
}

/// `pilgrim compensate RUN --measured FILE --out OUT`, which must pass:
/// what it said and the corrected run's report.
fn compensated(run: &Path, measured: &Path, out: &Path) -> (String, serde_json::Value) {
    let (code, said, err) = pilgrim(&[
        "compensate",
        s(run),
        "--measured",
        s(measured),
        "--out",
        s(out),
    ]);
    assert_eq!(code, 0, "{err}");
    let report = common::report_of(out);
    assert_eq!(
        report["verdict"]["status"], "passed",
        "{}",
        report["verdict"]
    );
    (said, report)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// The example measurement (`scripts/examples/mandrel-measured.csv`) is
/// the default mandrel as a wearing wheel leaves it: each row the law plus
/// the wear, to its 10 nm. `compensate` fits the error (a straight line
/// here: its residual 0.0 um), moves the target against it by the whole
/// of it, and runs the job again: the corrected run is verified within the
/// tolerance of the corrected target, its correction the wear's negative
/// within 0.01 um, the wheel's X moved by it and the rest's U with it. The
/// part the corrected program makes with the same wear, the corrected
/// target plus the corrected run's finish deviation plus the wear, is
/// within the 1 um tolerance of the nominal, where the first run's part
/// is 5.9 um off.
#[test]
fn the_mandrel_is_corrected_by_its_measured_error() {
    let dir = scratch("compensate", "mandrel");
    let run = mandrel_run(&dir);
    let measured = common::root().join("scripts/examples/mandrel-measured.csv");
    let text = std::fs::read_to_string(&measured).unwrap();
    let rows: Vec<(f64, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('z'))
        .map(|l| {
            let (z, d) = l.split_once(',').unwrap();
            (z.parse().unwrap(), d.parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), 45);
    for &(z, d) in &rows {
        assert!((d - law(z) - 2.0 * wear(z)).abs() < 6e-6, "z {z}: {d}");
    }
    let out = dir.join("corrected");
    let (said, report) = compensated(&run, &measured, &out);
    assert!(said.contains("radius: 45 places"), "{said}");
    assert_eq!(
        report["parameters"]["correction"]["value"],
        "correction.csv"
    );
    let finish = finish_of(&report);
    let tolerance = report["verification"]["tolerance"].as_f64().unwrap();
    // The correction, every 1.1 mm along the ground length: the wear's
    // negative.
    let worst = correction_off(&out, &wear);
    assert!(
        worst < 1e-5,
        "the correction strays {worst} mm from the wear"
    );
    // The same wear on the corrected program's part: the corrected target
    // (nominal - fit), its finish within `finish` of it, plus the wear.
    let after = finish + worst;
    assert!(
        after <= tolerance,
        "{after} mm after, tolerance {tolerance}"
    );
    let before = rows
        .iter()
        .map(|&(z, d)| (d / 2.0 - law(z) / 2.0).abs())
        .fold(0.0, f64::max);
    assert!(before > 5.8e-3 && before > 5.0 * tolerance, "{before}");
    let c = json(&out.join("compensation.json"));
    assert_eq!(c["quantities"][0]["places"].as_array().unwrap().len(), 45);
    assert!(c["quantities"][0]["rms_residual_mm"].as_f64().unwrap() < 1e-5);
    // The program: its path moved by the correction. The wheel's X (its
    // centre, on radius) and the rest's U (riding the part) by the most
    // the correction asks (5.87 um at z = 0), Z by under a micrometre (the
    // nearest point of a sloped path).
    let moved = &c["program"]["path_moved"];
    let most = c["quantities"][0]["max_correction_mm"].as_f64().unwrap();
    for axis in ["X", "U"] {
        let m = moved[axis].as_f64().unwrap();
        assert!(
            (m - most).abs() < 2e-4,
            "{axis} moved {m}, the correction {most}"
        );
    }
    assert!(moved["Z"].as_f64().unwrap() < 1e-3, "{moved}");
    assert!(c["program"]["lines_added"].as_u64().unwrap() > 0);
    // The report's table and the page's chart: the error before and after.
    let table = &report["tables"]["compensation"];
    let after = table["expected_after_um"].as_array().unwrap();
    assert_eq!(after.len(), 45);
    assert!(
        after.iter().all(|a| a.as_f64().unwrap().abs() < 0.01),
        "{after:?}"
    );
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(out.join("compensation.svg").is_file() && page.contains("alt=\"compensation.svg\""));
    common::check_page(&out, "program.mpf", 8.0);
    common::leave_page_for_chromium(&out, "compensated-mandrel");
    // The corrected run's part measured in its turn, the wear repeating:
    // on the nominal. Compensating the corrected run keeps its correction
    // (the wear's negative), adding what the new measurement asks: none.
    let again = dir.join("again.csv");
    let mut t = String::from("z_mm,d_mm\n");
    for &(z, _) in &rows {
        t += &format!("{z},{}\n", law(z));
    }
    std::fs::write(&again, t).unwrap();
    let twice = dir.join("twice");
    let (code, _, err) = pilgrim(&[
        "compensate",
        s(&out),
        "--measured",
        s(&again),
        "--out",
        s(&twice),
    ]);
    assert_eq!(code, 0, "{err}");
    let kept = correction_off(&twice, &wear);
    assert!(
        kept < 1e-5,
        "the kept correction strays {kept} mm from the wear"
    );
}

/// Bad measurements and asks are refused, naming what, and nothing is
/// written: a row outside the part, a stretch left unmeasured, a
/// correction beyond its limit (naming where), a family that takes no
/// correction.
#[test]
fn bad_measurements_are_refused_and_nothing_is_written() {
    let dir = scratch("compensate", "bad");
    let run = mandrel_run(&dir);
    let table = |name: &str, rows: &[(f64, f64)]| {
        let p = dir.join(name);
        let mut t = String::from("z_mm,d_mm\n");
        for (z, d) in rows {
            t += &format!("{z},{d}\n");
        }
        std::fs::write(&p, t).unwrap();
        p
    };
    let every = |f: &dyn Fn(f64) -> f64| -> Vec<(f64, f64)> {
        (0..=44)
            .map(|i| (10.0 * i as f64, law(10.0 * i as f64) + f(10.0 * i as f64)))
            .collect()
    };
    let mut outside = every(&|_| 0.0);
    outside.push((470.0, 44.0));
    let sparse: Vec<(f64, f64)> = every(&|_| 0.0)
        .into_iter()
        .filter(|r| r.0 < 200.0)
        .collect();
    let large = every(&|z| 0.4 * z / 440.0);
    for (name, rows, says) in [
        (
            "outside.csv",
            outside,
            "row 47, column z_mm: 470 is outside the part (0 to 440)",
        ),
        (
            "sparse.csv",
            sparse,
            "nothing measured from z_mm = 190 to 440",
        ),
        ("large.csv", large, "beyond its limit of 0.1 mm"),
    ] {
        let f = table(name, &rows);
        let out = dir.join(format!("{name}.out"));
        let (code, _, err) =
            pilgrim(&["compensate", s(&run), "--measured", s(&f), "--out", s(&out)]);
        assert_ne!(code, 0, "{name}");
        assert!(err.contains(says), "{name}: {err}");
        assert!(!out.exists(), "{name}: {} written", out.display());
    }
    // The largest's place: the first z of the correction's grid (every
    // 1.1 mm) where it passes 0.1 mm on radius (0.2 z / 440).
    let f = dir.join("large.csv");
    let (_, _, err) = pilgrim(&["compensate", s(&run), "--measured", s(&f)]);
    assert!(err.contains("at z = 221.100 mm"), "{err}");
    assert!(!Path::new(&format!("{}-compensated", run.display())).exists());
    // The worm's family takes no correction (yet): refused, naming why.
    let worm = dir.join("worm");
    let (code, _, err) = pilgrim(&["run", "scripts/worm.rhai", "--out", s(&worm), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let f = dir.join("outside.csv");
    let (code, _, err) = pilgrim(&["compensate", s(&worm), "--measured", s(&f)]);
    assert_ne!(code, 0);
    assert!(err.contains("the family takes no correction"), "{err}");
    assert!(!Path::new(&format!("{}-compensated", worm.display())).exists());
}

/// A second error we can make: the part deflecting away from the wheel in
/// proportion to its unsupported length's cube (a cantilever from the
/// chuck's side at z = -300, 4 um at the far end), measured every 10 mm
/// without scatter and held to an uncertainty of 0.01 um. The smoothing
/// spline follows the curve: the correction is the deflection's negative
/// within 0.05 um, and the corrected program's part, the same deflection
/// repeating, is within the tolerance. (Held to 0.1 um, the fit strays
/// 0.26 um at the ends: the spline spends the stated residual where the
/// curve bends most, and the default finish's 0.92 um leaves the 1 um
/// tolerance no room for it.)
#[test]
fn a_deflection_is_corrected_along_its_curve() {
    let dir = scratch("compensate", "deflection");
    let run = mandrel_run(&dir);
    let bend = |z: f64| 0.004 * ((z + 300.0) / 740.0).powi(3);
    let measured = dir.join("bent.csv");
    let mut t = String::from("z_mm,r_mm\n");
    for i in 0..=44 {
        let z = 10.0 * i as f64;
        t += &format!("{z},{:.7}\n", law(z) / 2.0 + bend(z));
    }
    std::fs::write(&measured, t).unwrap();
    let out = dir.join("corrected");
    let (code, _, err) = pilgrim(&[
        "compensate",
        s(&run),
        "--measured",
        s(&measured),
        "--uncertainty",
        "0.00001",
        "--out",
        s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    let report = common::report_of(&out);
    assert_eq!(
        report["verdict"]["status"], "passed",
        "{}",
        report["verdict"]
    );
    let finish = finish_of(&report);
    let worst = correction_off(&out, &bend);
    assert!(
        worst < 5e-5,
        "the correction strays {worst} mm from the deflection"
    );
    let c = json(&out.join("compensation.json"));
    assert!(
        c["quantities"][0]["smooth"].as_f64().unwrap() > 0.0,
        "a curve, not the line"
    );
    let tolerance = report["verification"]["tolerance"].as_f64().unwrap();
    assert!(finish + worst <= tolerance, "{finish} + {worst}");
    assert!(bend(440.0) > 3.9e-3);
}

/// The groove 20 um shallow over its entry relief (theta to 20 deg), the
/// error fading out by 40 deg along half a cosine (a wheel worn on its
/// rounding as it starts, or a groove ground before the wheel came to
/// size): measured minus nominal depth (mm) at theta (deg).
fn shallow_entry(theta: f64) -> f64 {
    if theta <= 20.0 {
        -0.020
    } else if theta >= 40.0 {
        0.0
    } else {
        -0.010 * (1.0 + (std::f64::consts::PI * (theta - 20.0) / 20.0).cos())
    }
}

/// The default caliber measured with its groove 20 um shallow over its
/// entry (`scripts/examples/caliber-measured.csv`, checked here against
/// the groove as ground and the error's formula): compensated, the depth's
/// correction is the error's negative within the fit's reach, the width
/// (measured as ground) is left, the corrected program verifies against
/// the corrected groove, and the part it makes with the same error
/// repeating is within the tolerance (the corrected run's own deviation
/// plus what the correction leaves of the error), where the first was 20
/// um out.
#[test]
fn the_caliber_is_corrected_by_its_measured_groove() {
    let dir = scratch("compensate", "caliber");
    let run = dir.join("run");
    let (code, _, err) = pilgrim(&["run", "scripts/caliber.rhai", "--out", s(&run), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let g = crate::caliber::groove();
    let measured = common::root().join("scripts/examples/caliber-measured.csv");
    let text = std::fs::read_to_string(&measured).unwrap();
    let rows: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert_eq!(rows.len(), 57);
    for [theta, hp, b] in &rows {
        let r = theta.to_radians();
        let want = g.depth().eval(r).unwrap() + shallow_entry(*theta);
        assert!((hp - want).abs() < 1e-5, "theta {theta}: {hp} vs {want}");
        assert!(
            (b - g.width().eval(r).unwrap()).abs() < 1e-5,
            "theta {theta}"
        );
    }
    let out = dir.join("corrected");
    let (said, report) = compensated(&run, &measured, &out);
    assert!(said.contains("depth: 57 places"), "{said}");
    assert_eq!(
        report["parameters"]["correction"]["value"],
        "correction.csv"
    );
    let groove = &report["groove_verification"];
    let finish = groove["max_abs_mm"].as_f64().unwrap();
    let tolerance = groove["tolerance"].as_f64().unwrap();
    // The correction: the depth deepened by the shallow entry, the width
    // left as it was.
    let table = std::fs::read_to_string(out.join("correction.csv")).unwrap();
    let mut lines = table.lines();
    assert_eq!(lines.next(), Some("theta_deg,dhp_mm,db_mm"));
    let (mut left, mut width): (f64, f64) = (0.0, 0.0);
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
        left = left.max((v[1] + shallow_entry(v[0])).abs());
        width = width.max(v[2].abs());
    }
    // Within the file's last digit (0.01 um).
    assert!(width < 1e-5, "the width moved {width} mm");
    let c = json(&out.join("compensation.json"));
    let depth = &c["quantities"][0];
    assert_eq!(depth["name"], "depth");
    let after = depth["max_expected_after_mm"].as_f64().unwrap();
    // Where the error bends, a fit held to 1 um stays a few um off it.
    assert!(left < 5e-3 && after < 5e-3, "{left} {after}");
    let before = rows
        .iter()
        .map(|[theta, ..]| shallow_entry(*theta).abs())
        .fold(0.0, f64::max);
    assert!(before > tolerance, "{before}");
    assert!(
        finish + after < tolerance,
        "the part after: {finish} + {after} mm against {tolerance} mm"
    );
    // The program: the same blocks, the groove's entry deepened.
    assert!(c["program"]["blocks_moved"].as_u64().unwrap() > 0);
    assert!(c["program"]["path_moved"]["Z"].as_f64().unwrap() > 0.015);
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    for svg in ["compensation_hp.svg", "compensation_b.svg"] {
        assert!(
            out.join(svg).is_file() && page.contains(&format!("alt=\"{svg}\"")),
            "{svg}"
        );
    }
}

/// The default thread (M20x2.5-6g) measured over wires as a bar bending
/// away from the cutter by its unsupported length leaves it
/// (`scripts/examples/thread-measured.csv`: the pitch diameter 0.120 mm
/// large at the face, falling towards the chuck 50 mm away): out of 6g's
/// band before; compensated by its mean (a start's passes move as one),
/// the corrected program verifies against the band moved by the
/// correction, and with the same error repeating the part is inside 6g's
/// band. A two-start thread's starts, measured apart, are corrected each
/// by its own.
#[test]
fn a_thread_is_corrected_start_by_start() {
    let dir = scratch("compensate", "thread");
    let run = dir.join("run");
    let (code, _, err) = pilgrim(&["run", "scripts/thread.rhai", "--out", s(&run), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let first = common::report_of(&run);
    let band = &first["thread_verification"]["limits"]["pitch_diameter"];
    let (lo, hi) = (band["min"].as_f64().unwrap(), band["max"].as_f64().unwrap());
    let aim = 0.5 * (lo + hi);
    let bend = |z: f64| 0.120 * (z + 50.0) / 50.0;
    let measured = common::root().join("scripts/examples/thread-measured.csv");
    let rows: Vec<(f64, f64)> = std::fs::read_to_string(&measured)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            let (z, d) = l.split_once(',').unwrap();
            (z.parse().unwrap(), d.parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), 5);
    for &(z, d2) in &rows {
        assert!((d2 - aim - bend(z)).abs() < 1e-6, "z {z}: {d2}");
    }
    // Before: the part near the face is out of the band.
    assert!(rows.iter().any(|r| r.1 > hi), "{rows:?} against {hi}");
    let out = dir.join("corrected");
    let (said, report) = compensated(&run, &measured, &out);
    assert!(said.contains("pitch diameter: 5 places"), "{said}");
    let mean = rows.iter().map(|r| bend(r.0)).sum::<f64>() / 5.0;
    let table = std::fs::read_to_string(out.join("correction.csv")).unwrap();
    assert!(table.starts_with("z_mm,dd2_1_mm\n"), "{table}");
    for l in table.lines().skip(1) {
        let dd2: f64 = l.split_once(',').unwrap().1.parse().unwrap();
        assert!((dd2 + mean).abs() < 1e-6, "{dd2} against {mean}");
    }
    // After: the corrected run's simulated pitch diameter (at the
    // corrected target) with the same error repeating, at every place.
    let d2 = report["thread_verification"]["starts"][0]["pitch_diameter"]
        .as_f64()
        .unwrap();
    assert!((d2 - (aim - mean)).abs() < 0.01, "{d2}");
    for &(z, _) in &rows {
        let part = d2 + bend(z);
        assert!(part > lo && part < hi, "z {z}: {part} outside {lo} to {hi}");
    }
    let c = json(&out.join("compensation.json"));
    assert_eq!(c["quantities"][0]["along"], false);
    assert!(out.join("compensation.svg").is_file());

    // A G76 cycle places its passes itself: the corrected run fails its
    // check, and leaves its FAILED report, which names it, and no program.
    let g76 = dir.join("g76");
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/thread.rhai",
        "--set",
        "cycle=g76",
        "--out",
        s(&g76),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let failed = dir.join("g76-corrected");
    let (code, _, err) = pilgrim(&[
        "compensate",
        s(&g76),
        "--measured",
        s(&measured),
        "--out",
        s(&failed),
    ]);
    assert_ne!(code, 0);
    assert!(err.contains("no program was written"), "{err}");
    let report = common::report_of(&failed);
    assert_eq!(report["verdict"]["status"], "failed");
    assert!(
        report
            .to_string()
            .contains("a correction moves thread blocks, not a G76 cycle's"),
        "{report}"
    );
    assert!(!failed.join("program.nc").exists() && failed.join("report.html").is_file());

    // Two starts, each measured (start 2 cut after start 1 at each depth,
    // by a cutter worn a little more): each corrected by its own.
    let two = dir.join("two");
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/thread.rhai",
        "--set",
        "designation=Tr40x14(P7)",
        "--out",
        s(&two),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let aim_of = |r: &serde_json::Value, k: usize| {
        r["thread_verification"]["starts"][k]["pitch_diameter"]
            .as_f64()
            .unwrap()
    };
    let first = common::report_of(&two);
    // About the pitch diameter the cut aims at (the family's note).
    let d2 = first["notes"]["pitch_diameter_aimed_mm"].as_f64().unwrap();
    let file = dir.join("two.csv");
    let mut t = String::from("z_mm,start,d2_mm\n");
    for z in [-5.0, -15.0, -25.0] {
        t += &format!("{z},1,{}\n{z},2,{}\n", d2 + 0.02, d2 + 0.05);
    }
    std::fs::write(&file, t).unwrap();
    let out = dir.join("two-corrected");
    let (_, report) = compensated(&two, &file, &out);
    for (k, e) in [(0, 0.02), (1, 0.05)] {
        let moved = aim_of(&report, k) - aim_of(&first, k);
        assert!((moved + e).abs() < 2e-3, "start {}: moved {moved}", k + 1);
    }
    let table = &report["tables"]["compensation"];
    assert_eq!(table["start"], serde_json::json!([1.0, 2.0]));

    // A nut (cut outwards from its bore) measured 0.02 mm large: its
    // passes come in, its pitch diameter down by as much.
    let nut = dir.join("nut");
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/thread.rhai",
        "--params",
        "scripts/examples/thread-m30x2-6h.toml",
        "--out",
        s(&nut),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let first = common::report_of(&nut);
    let d2 = first["notes"]["pitch_diameter_aimed_mm"].as_f64().unwrap();
    let file = dir.join("nut.csv");
    let rows: String = [-5, -15, -25]
        .iter()
        .map(|z| format!("{z},{}\n", d2 + 0.02))
        .collect();
    std::fs::write(&file, format!("z_mm,d2_mm\n{rows}")).unwrap();
    let out = dir.join("nut-corrected");
    let (_, report) = compensated(&nut, &file, &out);
    let moved = aim_of(&report, 0) - aim_of(&first, 0);
    assert!((moved + 0.02).abs() < 2e-3, "the nut: moved {moved}");
}
