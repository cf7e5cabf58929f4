//! `pilgrim compensate` on the default mandrel: a measured part in, a
//! corrected program out.

use crate::common::{self, pilgrim, s, scratch};
use std::path::Path;

/// The default mandrel's nominal diameter at z (mm): the law over the
/// working part, the end cone after it (scripts/mandrel.rhai's defaults),
/// written here from docs/math.md §2.1, not taken from the kernel.
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

/// How much of its radius the wheel wears over the mandrel's finishing
/// pass (mm), dressed before it: the error of the mandrel's example.
const WEAR: f64 = 0.006;

/// The wheel of [`WEAR`]: what it has lost at `share` (0 to 1) of the
/// finishing pass's path.
fn worn(share: f64, _z: f64) -> f64 {
    WEAR * share
}

/// The mandrel's finished part with an error of the process in the loop,
/// replayed from the program's text by the replay of
/// `tests/mandrel_fidelity.rs` (which shares no code with the kernel's):
/// the wheel's true section placed at the moments each generatrix passes
/// under it, the part turning at S, every axis straight between blocks at
/// the block's F, the section standing higher by `error(share, z)` (mm)
/// when the wheel has gone `share` of the finishing pass's path and stands
/// at z (a wheel worn by as much, a part given way). At each z of `at`:
/// the highest generatrix (what a micrometer's flat anvils touch) and the
/// lowest, radii (mm). The finishing pass is the program's last `; pass`
/// group, cutting below every pass before it over the ground length.
fn finish_with(
    run: &Path,
    program: &str,
    at: &[f64],
    error: &dyn Fn(f64, f64) -> f64,
) -> Vec<(f64, f64)> {
    use crate::mandrel_fidelity::{phases_for, read_program, Pass, Section};
    let report = common::report_of(run);
    let param = |n: &str| report["parameters"][n]["value"].as_f64().unwrap();
    let section = Section {
        r: param("rounding_r"),
        flat: (param("wheel_w") - 2.0 * param("rounding_r")).max(0.0),
    };
    let written = read_program(&std::fs::read_to_string(run.join(program)).unwrap());
    let k = written
        .groups
        .iter()
        .rposition(|g| g.0.starts_with("pass "))
        .expect("a pass");
    let before = *written.groups[..k]
        .iter()
        .rev()
        .find_map(|g| g.1.last())
        .unwrap();
    let pass = Pass::new(before, &written.groups[k].1);
    // The path's length at each of the pass's points (each block at its
    // own feed: the length runs linearly in time within a block).
    let mut length = vec![0.0];
    for i in 1..pass.z.len() {
        let d = (pass.z[i] - pass.z[i - 1]).hypot(pass.x[i] - pass.x[i - 1]);
        length.push(length[i - 1] + d);
    }
    let total = length[length.len() - 1];
    let at_time = |t: f64| {
        let (i, s) = pass.segment_at(t);
        let share = (length[i - 1] + s * (length[i] - length[i - 1])) / total;
        error(share, pass.at(t).0)
    };
    let period = 1.0 / written.spindle;
    let phases = phases_for(&pass, section, period);
    at.iter()
        .map(|&z| pass.cut_worn(section, period, phases, z, f64::INFINITY, &at_time))
        .collect()
}

/// The largest distance of a replayed finish from the nominal radius
/// (mm): its highest and lowest generatrices at the places `at`.
fn off_nominal(finish: &[(f64, f64)], at: &[f64]) -> f64 {
    finish
        .iter()
        .zip(at)
        .map(|(&(hi, lo), &z)| (hi - law(z) / 2.0).abs().max((lo - law(z) / 2.0).abs()))
        .fold(0.0, f64::max)
}

/// Every 0.5 mm over the default mandrel's ground length.
fn fine() -> Vec<f64> {
    (0..=880).map(|i| 0.5 * i as f64).collect()
}

/// The places of the mandrel's measurements: every 10 mm from 0 to 440
/// but on the edge between the law and the end cone (z = 400), where a
/// bench's anvils do not sit.
fn bench_places() -> Vec<f64> {
    (0..=44)
        .map(|i| 10.0 * i as f64)
        .filter(|&z| z != 400.0)
        .collect()
}

/// A measuring bench's table of the part `finish` (its highest
/// generatrices at [`bench_places`]): diameters to 0.1 um.
fn bench_table(finish: &[(f64, f64)]) -> String {
    let mut t = String::from("z_mm,d_mm\n");
    for (z, (hi, _)) in bench_places().iter().zip(finish) {
        t += &format!("{z:.1},{:.4}\n", 2.0 * hi);
    }
    t
}

/// The default mandrel run into `dir/run`.
fn mandrel_run(dir: &Path) -> std::path::PathBuf {
    ran(&dir.join("run"), "mandrel", &[])
}

/// `pilgrim run scripts/<family>.rhai` with `extra` options into `out`,
/// which must pass: `out`.
fn ran(out: &Path, family: &str, extra: &[&str]) -> std::path::PathBuf {
    let script = format!("scripts/{family}.rhai");
    let mut args = vec!["run", &script, "--out", s(out), "--quiet"];
    args.extend(extra);
    let (code, _, err) = pilgrim(&args);
    assert_eq!(code, 0, "{family}: {err}");
    out.to_owned()
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

/// `pilgrim compensate RUN --measured FILE --out OUT` with `extra`
/// options: its exit code, what it said and its errors.
fn compensate(run: &Path, measured: &Path, out: &Path, extra: &[&str]) -> (i32, String, String) {
    let mut args = vec![
        "compensate",
        s(run),
        "--measured",
        s(measured),
        "--out",
        s(out),
    ];
    args.extend(extra);
    pilgrim(&args)
}

/// [`compensate`] with no options, which must pass: what it said and the
/// corrected run's report.
fn compensated(run: &Path, measured: &Path, out: &Path) -> (String, serde_json::Value) {
    let (code, said, err) = compensate(run, measured, out, &[]);
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

/// A wheel wearing [`WEAR`] of its radius along the default mandrel's
/// finishing pass, in the loop: the first program replayed with the wear
/// (`finish_with`) leaves the part 6.7 um off its nominal; measured at 44
/// places (`scripts/examples/mandrel-measured.csv` is that measurement),
/// `compensate` fits what the kernel's replay did not predict (the wear,
/// within 0.3 um) and moves the target against it; the corrected program,
/// replayed with the same wear, leaves the part within the 1 um tolerance
/// of the nominal on every generatrix's highest and lowest, every 0.5 mm,
/// and `compensation.json`'s expected part after is that replay's within
/// 0.1 um. The wheel's X and the rest's U moved by the correction, Z by
/// under a micrometre. Measured in its turn with the wear repeating (a
/// workbook this time), the corrected run compensated again keeps its
/// correction.
#[test]
fn the_mandrel_is_corrected_by_its_measured_error() {
    let dir = scratch("compensate", "mandrel");
    let run = mandrel_run(&dir);
    let fine = fine();
    let tolerance = common::report_of(&run)["verification"]["tolerance"]
        .as_f64()
        .unwrap();
    let before = off_nominal(&finish_with(&run, "program.mpf", &fine, &worn), &fine);
    assert!(before > 5.0 * tolerance, "before: {before}");
    // The example is the first program's part with the wear, measured.
    let measured = common::root().join("scripts/examples/mandrel-measured.csv");
    let bench = finish_with(&run, "program.mpf", &bench_places(), &worn);
    let rows = |text: &str| -> Vec<(f64, f64)> {
        text.lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with('z'))
            .map(|l| {
                let (z, d) = l.split_once(',').unwrap();
                (z.parse().unwrap(), d.parse().unwrap())
            })
            .collect()
    };
    let example = rows(&std::fs::read_to_string(&measured).unwrap());
    let replayed = rows(&bench_table(&bench));
    assert_eq!(example.len(), 44);
    for (e, r) in example.iter().zip(&replayed) {
        assert!(
            e.0 == r.0 && (e.1 - r.1).abs() < 1.5e-4,
            "{e:?} replayed {r:?}"
        );
    }
    let out = dir.join("corrected");
    let (said, report) = compensated(&run, &measured, &out);
    assert!(said.contains("radius: 44 places"), "{said}");
    assert_eq!(
        report["parameters"]["correction"]["value"],
        "correction.csv"
    );
    // The correction: the wear's negative, as the wheel wore it along z
    // (the pass runs from z = 450 to -10), where the kernel's prediction
    // and this replay's agree.
    let worst = correction_off(&out, &wear);
    assert!(
        worst < 3e-4,
        "the correction strays {worst} mm from the wear"
    );
    // After: the corrected program with the same wear.
    let after_part = finish_with(&out, "program.mpf", &fine, &worn);
    let after = off_nominal(&after_part, &fine);
    assert!(
        after <= tolerance,
        "after: {after} mm, tolerance {tolerance}"
    );
    let c = json(&out.join("compensation.json"));
    let places = c["quantities"][0]["places"].as_array().unwrap();
    assert_eq!(places.len(), 44);
    for p in places {
        let z = p["at"].as_f64().unwrap();
        let replay = after_part[(2.0 * z).round() as usize].0 - law(z) / 2.0;
        let said = p["expected_after"].as_f64().unwrap();
        assert!(
            (said - replay).abs() < 1e-4,
            "z {z}: expected {said}, replayed {replay}"
        );
    }
    // The program: its path moved by the correction. The wheel's X (its
    // centre, on radius) and the rest's U (riding the part) by the most
    // the correction asks, Z by under a micrometre (the nearest point of a
    // sloped path).
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    let moved = &c["program"]["path_moved"];
    let most = c["quantities"][0]["max_correction_mm"].as_f64().unwrap();
    for axis in ["X", "U"] {
        let m = moved[axis].as_f64().unwrap();
        assert!(
            (m - most).abs() < 3e-4,
            "{axis} moved {m}, the correction {most}"
        );
    }
    assert!(moved["Z"].as_f64().unwrap() < 1e-3, "{moved}");
    assert!(c["program"]["lines_added"].as_u64().unwrap() > 0);
    // On the page, per pass: the finish's X moved by the most.
    let per_pass = &report["tables"]["compensation_moves"];
    let x: Vec<f64> = per_pass["X_um"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(x.len(), per_pass["pass"].as_array().unwrap().len());
    assert!(
        (x[x.len() - 1] - 1e3 * moved["X"].as_f64().unwrap()).abs() < 1e-6,
        "{x:?}"
    );
    assert!(page.contains("alt=\"compensation_moves.svg\""));
    // The report's table and the page's chart: the error before and after.
    let table = &report["tables"]["compensation"];
    let after_um = table["expected_after_um"].as_array().unwrap();
    assert_eq!(after_um.len(), 44);
    assert!(
        after_um
            .iter()
            .all(|a| a.as_f64().unwrap().abs() <= 1e3 * tolerance),
        "{after_um:?}"
    );
    assert!(out.join("compensation.svg").is_file() && page.contains("alt=\"compensation.svg\""));
    // The charts' titles say which program they chart: the first run's
    // are the nominal's, the corrected run's say the correction's.
    let titled = |dir: &std::path::Path, file: &str| {
        std::fs::read_to_string(dir.join(file))
            .unwrap()
            .contains("the program corrected (generation 1)")
    };
    for file in ["deviation.svg", "finish.svg", "stock.svg"] {
        assert!(!titled(&run, file) && titled(&out, file), "{file}");
    }
    common::check_page(&out, "program.mpf", 8.0);
    common::leave_page_for_chromium(&out, "compensated-mandrel");
    // The corrected run verified again as it stands (after a hand edit):
    // its correction read beside its files.
    let (code, _, err) = pilgrim(&["verify", s(&out), "--out", s(&dir.join("reverified"))]);
    assert_eq!(code, 0, "{err}");
    // The corrected run's part measured in its turn, the wear repeating:
    // compensated again, the correction is kept (its unmodelled error is
    // the wear less the correction: nothing).
    // Measured on a CMM that writes a workbook: z_mm and d_mm as headers.
    let again = dir.join("again.xlsx");
    let mut book = rust_xlsxwriter::Workbook::new();
    let sheet = book.add_worksheet();
    sheet.write_string(0, 0, "z_mm").unwrap();
    sheet.write_string(0, 1, "d_mm").unwrap();
    let part = finish_with(&out, "program.mpf", &bench_places(), &worn);
    for (row, (z, (hi, _))) in (1u32..).zip(bench_places().iter().zip(&part)) {
        sheet.write_number(row, 0, *z).unwrap();
        sheet
            .write_number(row, 1, (2e4 * hi).round() / 1e4)
            .unwrap();
    }
    book.save(&again).unwrap();
    let twice = dir.join("twice");
    let (code, _, err) = compensate(&out, &again, &twice, &[]);
    assert_eq!(code, 0, "{err}");
    let finish = std::fs::read_to_string(twice.join("finish.svg")).unwrap();
    assert!(finish.contains("the program corrected (generation 2)"));
    let kept = correction_off(&twice, &wear);
    assert!(
        kept < 3e-4,
        "the kept correction strays {kept} mm from the wear"
    );
}

/// Bad measurements and asks are refused, naming what, and nothing is
/// written: a row outside the part, a stretch left unmeasured, a
/// correction beyond its limit (naming where), one the wheel cannot
/// follow (naming where), a run whose program was altered, a family that
/// takes no correction.
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
        let (code, _, err) = compensate(&run, &f, &out, &[]);
        assert_ne!(code, 0, "{name}");
        assert!(err.contains(says), "{name}: {err}");
        assert!(!out.exists(), "{name}: {} written", out.display());
    }
    // A narrow bump the part was measured with (60 um, sigma 0.8 mm at z
    // = 200, measured every 0.25 mm over it, held to 0.1 um): the target
    // corrected by it bends tighter than the wheel's 20 mm rounding can
    // follow, and the wheel's path refuses it, named by z.
    let mut t = String::from("z_mm,d_mm\n");
    let mut zs: Vec<f64> = (0..=44).map(|i| 10.0 * i as f64).collect();
    zs.extend((0..=32).map(|i| 196.0 + 0.25 * i as f64));
    zs.sort_by(f64::total_cmp);
    zs.dedup();
    for z in zs {
        let bump = 0.06 * (-0.5 * ((z - 200.0) / 0.8).powi(2)).exp();
        t += &format!("{z},{:.5}\n", law(z) + 2.0 * bump);
    }
    let f = dir.join("bump.csv");
    std::fs::write(&f, t).unwrap();
    let out = dir.join("bump.out");
    let (code, _, err) = compensate(&run, &f, &out, &["--uncertainty", "0.0001"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("bump.csv is refused")
            && err.contains("tool radius 20 mm exceeds the profile's radius of curvature")
            && err.contains("z = 200.0000"),
        "{err}"
    );
    assert!(!out.exists() && !dir.join("bump.out.failed").exists());
    // The largest's place: the first z of the correction's grid (every
    // 1.1 mm) where it passes 0.1 mm on radius (0.2 z / 440, less the
    // finish's own half micrometre above the nominal, which the run's
    // replay predicted).
    let f = dir.join("large.csv");
    let (_, _, err) = pilgrim(&["compensate", s(&run), "--measured", s(&f)]);
    assert!(err.contains("at z = 222.200 mm"), "{err}");
    assert!(!Path::new(&format!("{}-compensated", run.display())).exists());
    // The first run's program altered after it was written (it is read
    // while the corrected run is made): refused, naming the file, and
    // nothing written.
    let altered = dir.join("altered");
    std::fs::create_dir_all(&altered).unwrap();
    for entry in std::fs::read_dir(&run).unwrap() {
        let from = entry.unwrap().path();
        std::fs::copy(&from, altered.join(from.file_name().unwrap())).unwrap();
    }
    std::fs::write(altered.join("program.json"), "{").unwrap();
    let f = table("as-nominal.csv", &every(&|_| 0.0));
    let out = dir.join("altered.out");
    let (code, _, err) = compensate(&altered, &f, &out, &[]);
    assert_ne!(code, 0);
    assert!(err.contains("program.json"), "{err}");
    assert!(!out.exists(), "{} written", out.display());
    // The worm's family takes no correction (yet): refused, naming why.
    let worm = dir.join("worm");
    ran(&worm, "worm", &[]);
    let f = dir.join("outside.csv");
    let (code, _, err) = pilgrim(&["compensate", s(&worm), "--measured", s(&f)]);
    assert_ne!(code, 0);
    assert!(err.contains("the family takes no correction"), "{err}");
    assert!(!Path::new(&format!("{}-compensated", worm.display())).exists());
}

/// A second error we can make: the part deflecting away from the wheel in
/// proportion to its unsupported length's cube (a cantilever from the
/// chuck's side at z = -300, 4 um at the far end), in the loop: the first
/// program replayed with the wheel at z meeting the part given way by
/// `bend(z)`, measured every 10 mm to 1 nm of diameter (at two angular
/// positions 0.01 um apart: out of round, averaged and said; 1 um apart,
/// beyond 3 times the uncertainty stated, refused), compensated
/// with the measurement's uncertainty stated as 0.01 um; the smoothing
/// spline follows the curve (the correction within 0.1 um of the
/// deflection's negative), and the corrected program replayed with the
/// same deflection leaves the part within the tolerance of the nominal.
/// (Held to 0.1 um, the spline spends that residual at the ends, 0.25 um
/// off the curve there: with the default finish at 0.93 um of its 1 um,
/// the part after is 1.12 um off.)
#[test]
fn a_deflection_is_corrected_along_its_curve() {
    let dir = scratch("compensate", "deflection");
    let run = mandrel_run(&dir);
    let bend = |z: f64| 0.004 * ((z + 300.0) / 740.0).powi(3);
    let bent = |_: f64, z: f64| bend(z);
    let fine = fine();
    let tolerance = common::report_of(&run)["verification"]["tolerance"]
        .as_f64()
        .unwrap();
    let before = off_nominal(&finish_with(&run, "program.mpf", &fine, &bent), &fine);
    assert!(before > 3.0 * tolerance, "before: {before}");
    // Measured at two angular positions: 1 um apart on the radius (out of
    // round), more than 3 times the stated uncertainty, refused naming
    // the rows; 0.01 um apart, within it, averaged and said.
    let measured = dir.join("bent.csv");
    let bench = finish_with(&run, "program.mpf", &bench_places(), &bent);
    let table = |apart: f64| {
        let mut t = String::from("z_mm,angle_deg,d_mm\n");
        for (z, (hi, _)) in bench_places().iter().zip(&bench) {
            let d = 2.0 * hi;
            t += &format!("{z:.1},0,{:.6}\n{z:.1},90,{:.6}\n", d + apart, d - apart);
        }
        std::fs::write(&measured, t).unwrap();
    };
    table(0.001);
    let out = dir.join("corrected");
    let (code, _, err) = compensate(&run, &measured, &out, &["--uncertainty", "0.00001"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("rows 2 and 3 are 0.0010 mm apart"), "{err}");
    table(0.00001);
    let (code, said, err) = compensate(&run, &measured, &out, &["--uncertainty", "0.00001"]);
    assert_eq!(code, 0, "{err}");
    let report = common::report_of(&out);
    assert_eq!(
        report["verdict"]["status"], "passed",
        "{}",
        report["verdict"]
    );
    assert!(
        said.contains("the rows at one place differ by up to 0.0000 mm: out of round"),
        "{said}"
    );
    let worst = correction_off(&out, &bend);
    let c = json(&out.join("compensation.json"));
    let spread = c["quantities"][0]["max_spread_mm"].as_f64().unwrap();
    assert!((spread - 0.00001).abs() < 1e-9, "{spread}");
    assert!(
        c["quantities"][0]["smooth"].as_f64().unwrap() > 0.0,
        "a curve, not the line"
    );
    let after = off_nominal(&finish_with(&out, "program.mpf", &fine, &bent), &fine);
    assert!(
        worst < 1e-4,
        "the correction strays {worst} mm from the deflection"
    );
    assert!(
        after <= tolerance,
        "after: {after} mm, tolerance {tolerance}"
    );
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

/// The caliber program as the machine runs it with the wheelhead held
/// back over the groove's entry: each grinding block's Z (the wheel
/// centre's distance from the roll's axis) larger by
/// `-shallow_entry(theta)`, theta the roll's turn there (`-A`; both words
/// modal, the blocks grinding from the first G1 on), replayed as its
/// control reads it by `pilgrim verify` against the default caliber
/// (correction none), into `out`; its report, whatever its verdict.
fn held_back(program: &Path, out: &Path) -> serde_json::Value {
    let (mut a, mut grinding) = (0.0, false);
    let mut by = |l: &str| {
        if !l.starts_with('N') {
            return 0.0;
        }
        if let Some(v) = common::word(l, 'A') {
            a = v;
        }
        let words: Vec<&str> = l.split_whitespace().collect();
        if words.contains(&"G1") {
            grinding = true;
        } else if words.contains(&"G0") {
            grinding = false;
        }
        if grinding {
            -shallow_entry(-a)
        } else {
            0.0
        }
    };
    let args = [
        "--machine",
        "Mannesmann",
        "--family",
        "scripts/caliber.rhai",
    ];
    replayed_with(program, 'Z', &mut by, out, &args)
}

/// `program` as the machine runs it with an error of the process: each
/// block's `axis` word moved by `by(line)` (mm; called on every line in
/// order, comments too, so that it can follow modal words and pass names;
/// a word it moves by 0 is kept as written, one it moves is written to
/// the program's 3 decimals), saved beside `out` and replayed as its
/// control reads it by `pilgrim verify` with `args` (the machine, the
/// family, its parameters) into `out`: the report, whatever its verdict.
fn replayed_with(
    program: &Path,
    axis: char,
    by: &mut dyn FnMut(&str) -> f64,
    out: &Path,
    args: &[&str],
) -> serde_json::Value {
    let text: String = std::fs::read_to_string(program)
        .unwrap()
        .lines()
        .map(|l| {
            let d = by(l);
            if d == 0.0 || l.starts_with('(') || l.starts_with(';') {
                return format!("{l}\n");
            }
            let words: Vec<String> = l
                .split_whitespace()
                .map(|w| match w.strip_prefix(axis) {
                    Some(v) => format!("{axis}{:.3}", v.parse::<f64>().unwrap() + d),
                    None => w.to_owned(),
                })
                .collect();
            words.join(" ") + "\n"
        })
        .collect();
    let extension = program.extension().and_then(|e| e.to_str()).unwrap();
    let file = out.with_extension(extension);
    std::fs::write(&file, text).unwrap();
    let mut all = vec!["verify", s(&file)];
    all.extend(args);
    all.extend(["--out", s(out)]);
    pilgrim(&all);
    common::report_of(out)
}

/// The groove's depth and width (mm) at `theta` (deg) as a replay's
/// report predicts them: the groove as ground (`g`) and the report's
/// deviations from it.
fn groove_at(
    report: &serde_json::Value,
    g: &pilgrim_kernel::families::caliber::Groove,
    theta: f64,
) -> (f64, f64) {
    let t = &report["tables"]["predicted_deviation"];
    let col = |c: &str| -> Vec<f64> {
        t[c].as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (th, dhp, db) = (col("theta_deg"), col("dhp_mm"), col("db_mm"));
    let i = th.iter().position(|&x| (x - theta).abs() < 1e-6).unwrap();
    let r = theta.to_radians();
    (
        g.depth().eval(r).unwrap() + dhp[i],
        g.width().eval(r).unwrap() + db[i],
    )
}

/// The default caliber ground with its wheelhead held 20 um back over the
/// groove's entry ([`shallow_entry`]), in the loop: the first program so
/// replayed (`held_back`) leaves the groove 20 um off; measured every 5
/// deg (`scripts/examples/caliber-measured.csv` is that measurement),
/// `compensate` fits the depth's error the replay did not predict, and the
/// corrected program, replayed held back alike, leaves the groove within
/// the tolerance of the nominal everywhere (edge to edge, every 0.5 deg);
/// `compensation.json`'s expected depth after is that replay's within 1
/// um where the error is flat.
#[test]
fn the_caliber_is_corrected_by_its_measured_groove() {
    let dir = scratch("compensate", "caliber");
    let run = dir.join("run");
    ran(&run, "caliber", &[]);
    let g = crate::caliber::groove();
    let tolerance = common::report_of(&run)["groove_verification"]["tolerance"]
        .as_f64()
        .unwrap();
    let before = held_back(&run.join("program.mpf"), &dir.join("before"));
    let worst = before["groove_verification"]["max_abs_mm"]
        .as_f64()
        .unwrap();
    assert!(worst > 1.8 * tolerance, "before: {worst}");
    // The example is the held-back groove measured every 5 deg.
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
        let (h, w) = groove_at(&before, &g, *theta);
        assert!(
            (hp - h).abs() < 6e-5 && (b - w).abs() < 6e-5,
            "theta {theta}: {hp}, {b} against the replay's {h}, {w}"
        );
    }
    let out = dir.join("corrected");
    let (said, report) = compensated(&run, &measured, &out);
    assert!(said.contains("depth: 57 places"), "{said}");
    assert_eq!(
        report["parameters"]["correction"]["value"],
        "correction.csv"
    );
    // The correction: the depth deepened by the shallow entry, the width
    // left (within a micrometre: its measured deviations are the run's
    // own, which its replay predicted).
    let table = std::fs::read_to_string(out.join("correction.csv")).unwrap();
    let mut lines = table.lines();
    assert_eq!(lines.next(), Some("theta_deg,dhp_mm,db_mm"));
    let (mut flat, mut width): (f64, f64) = (0.0, 0.0);
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
        if v[0] <= 15.0 || v[0] >= 45.0 {
            flat = flat.max((v[1] + shallow_entry(v[0])).abs());
        }
        width = width.max(v[2].abs());
    }
    assert!(flat < 2e-3, "the depth's correction strays {flat} mm");
    assert!(width < 1e-3, "the width moved {width} mm");
    // After: the corrected program held back alike.
    let after = held_back(&out.join("program.mpf"), &dir.join("after"));
    let worst = after["groove_verification"]["max_abs_mm"].as_f64().unwrap();
    assert!(worst <= tolerance, "after: {worst} mm against {tolerance}");
    let c = json(&out.join("compensation.json"));
    let depth = &c["quantities"][0];
    assert_eq!(depth["name"], "depth");
    for p in depth["places"].as_array().unwrap() {
        let theta = p["at"].as_f64().unwrap();
        let (h, _) = groove_at(&after, &g, theta);
        let replayed = h - g.depth().eval(theta.to_radians()).unwrap();
        let said = p["expected_after"].as_f64().unwrap();
        if theta <= 15.0 || theta >= 45.0 {
            assert!(
                (said - replayed).abs() < 1e-3,
                "theta {theta}: {said} against {replayed}"
            );
        }
    }
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

/// The bar's bending of the thread's example (mm on diameter at z): held
/// in the chuck 50 mm from the face, it gives way to the cutter by its
/// unsupported length, 0.120 mm at the face.
fn bend(z: f64) -> f64 {
    0.120 * (z + 50.0) / 50.0
}

/// Each start's pitch diameter (mm) that the thread program `program`
/// cuts on a bar bent by [`bend`], at each z of `at`: the section at z is
/// cut while the cutter stands over it, so every pass there meets the bar
/// given way by `bend(z)`, which is the program with each X (on diameter)
/// larger by as much. That program is replayed as its control reads it by
/// `pilgrim verify` against the default thread (correction none), its
/// report read whatever its verdict (a bent part may fail it).
fn bent_pitch_diameters(dir: &Path, program: &Path, at: &[f64]) -> Vec<Vec<f64>> {
    std::fs::create_dir_all(dir).unwrap();
    let args = [
        "--machine",
        "fanuc-0i-tc",
        "--family",
        "scripts/thread.rhai",
    ];
    at.iter()
        .enumerate()
        .map(|(i, &z)| {
            let out = dir.join(format!("bent-{i}"));
            replayed_with(program, 'X', &mut |_| bend(z), &out, &args)["thread_verification"]
                ["starts"]
                .as_array()
                .unwrap()
                .iter()
                .map(|st| st["pitch_diameter"].as_f64().unwrap())
                .collect()
        })
        .collect()
}

/// The default thread (M20x2.5-6g) on a bar bending away from the cutter
/// by its unsupported length ([`bend`]): its program replayed on the bent
/// bar at five places is measured over wires there
/// (`scripts/examples/thread-measured.csv` is that measurement), out of
/// 6g's band near the face; compensated by its mean (a start's passes move
/// as one), the corrected program verifies against the band moved by the
/// correction, and replayed on the same bent bar its part is inside 6g's
/// band at every place. A two-start thread's starts, measured apart, are
/// corrected each by its own.
#[test]
fn a_thread_is_corrected_start_by_start() {
    let dir = scratch("compensate", "thread");
    let run = dir.join("run");
    ran(&run, "thread", &[]);
    let first = common::report_of(&run);
    let band = &first["thread_verification"]["limits"]["pitch_diameter"];
    let (lo, hi) = (band["min"].as_f64().unwrap(), band["max"].as_f64().unwrap());
    let aim = 0.5 * (lo + hi);
    let cut = first["thread_verification"]["starts"][0]["pitch_diameter"]
        .as_f64()
        .unwrap();
    // The first program on the bent bar: its pitch diameter the straight
    // bar's plus the bend, to the program's last digit (1 um on X).
    let places = [-2.0, -8.0, -14.0, -20.0, -26.0];
    let before: Vec<f64> =
        bent_pitch_diameters(&dir.join("before"), &run.join("program.nc"), &places)
            .into_iter()
            .map(|v| v[0])
            .collect();
    for (z, d2) in places.iter().zip(&before) {
        assert!((d2 - cut - bend(*z)).abs() < 1.5e-3, "z {z}: {d2}");
    }
    // The example is that measurement, to its 0.1 um.
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
    let replayed: Vec<(f64, f64)> = places.iter().copied().zip(before.iter().copied()).collect();
    assert_eq!(rows.len(), 5);
    for (&(z, d2), &(zr, r)) in rows.iter().zip(&replayed) {
        assert!(
            z == zr && (d2 - r).abs() < 0.6e-4,
            "z {z}: {d2}, replayed {r}"
        );
    }
    // Before: the part near the face is out of the band.
    assert!(before.iter().any(|&d| d > hi), "{before:?} against {hi}");
    let out = dir.join("corrected");
    let (said, report) = compensated(&run, &measured, &out);
    assert!(said.contains("pitch diameter: 5 places"), "{said}");
    // What the replay did not predict: the measured less the simulated cut.
    let mean = rows.iter().map(|r| r.1 - cut).sum::<f64>() / 5.0;
    let table = std::fs::read_to_string(out.join("correction.csv")).unwrap();
    // The start's place, not measured, left where it was.
    assert!(table.starts_with("z_mm,dd2_1_mm,dz_1_mm\n"), "{table}");
    for l in table.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
        assert!(
            (v[1] + mean).abs() < 1e-6 && v[2] == 0.0,
            "{v:?} against {mean}"
        );
    }
    assert!(said.contains("not measured: place"), "{said}");
    // After: the corrected program replayed on the same bent bar, at
    // every place inside 6g's band.
    let d2 = report["thread_verification"]["starts"][0]["pitch_diameter"]
        .as_f64()
        .unwrap();
    assert!((d2 - (aim - mean)).abs() < 0.01, "{d2}");
    let after: Vec<f64> =
        bent_pitch_diameters(&dir.join("after"), &out.join("program.nc"), &places)
            .into_iter()
            .map(|v| v[0])
            .collect();
    for (z, part) in places.iter().zip(&after) {
        assert!(
            *part > lo && *part < hi,
            "z {z}: {part} outside {lo} to {hi}"
        );
    }
    let c = json(&out.join("compensation.json"));
    assert_eq!(c["quantities"][0]["along"], false);
    assert!(out.join("compensation.svg").is_file());

    // A G76 cycle places its passes itself: the corrected run fails its
    // check, and leaves its FAILED report, which names it, and no program.
    let g76 = dir.join("g76");
    ran(&g76, "thread", &["--set", "cycle=g76"]);
    let failed = dir.join("g76-corrected");
    let (code, _, err) = compensate(&g76, &measured, &failed, &[]);
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
    ran(&two, "thread", &["--set", "designation=Tr40x14(P7)"]);
    let aim_of = |r: &serde_json::Value, k: usize| {
        r["thread_verification"]["starts"][k]["pitch_diameter"]
            .as_f64()
            .unwrap()
    };
    let first = common::report_of(&two);
    // Each start as the first program cut it (its simulation), larger by
    // what the replay did not model.
    let (d1, d2) = (aim_of(&first, 0), aim_of(&first, 1));
    let file = dir.join("two.csv");
    let mut t = String::from("z_mm,start,d2_mm\n");
    for z in [-5.0, -15.0, -25.0] {
        t += &format!("{z},1,{}\n{z},2,{}\n", d1 + 0.02, d2 + 0.05);
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
    ran(
        &nut,
        "thread",
        &["--params", "scripts/examples/thread-m30x2-6h.toml"],
    );
    let first = common::report_of(&nut);
    let d2 = aim_of(&first, 0);
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

/// Tr40x14(P7)'s program with start 2's passes `dz` mm along the axis from
/// where it puts them (its index late, as a control's start angle off by
/// as much of the lead leaves it), replayed as its control reads it by
/// `pilgrim verify` against the thread (correction none), into `out`:
/// each start's place from where it should stand (mm).
fn start_two_off(program: &Path, dz: f64, out: &Path) -> Vec<f64> {
    let mut two = false;
    let mut by = |l: &str| {
        if l.starts_with('(') {
            two = l.starts_with("(PASS") && l.contains(", START 2,");
        }
        if two {
            dz
        } else {
            0.0
        }
    };
    let args = [
        "--machine",
        "fanuc-0i-tc",
        "--family",
        "scripts/thread.rhai",
        "--set",
        "designation=Tr40x14(P7)",
    ];
    replayed_with(program, 'Z', &mut by, out, &args)["thread_verification"]["starts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|st| st["position_error"].as_f64().unwrap())
        .collect()
}

/// A two-start thread whose second start is cut 30 um along the axis from
/// its place (its index late), in the loop: measured (each start's place,
/// `dz_mm`, the mean of its flanks' axial errors at the pitch line),
/// compensated, start 2's passes move back by it and start 1's stay; the
/// corrected program replayed with the same error leaves both starts in
/// their places within a micrometre, where start 2 was 30 um off.
#[test]
fn a_start_out_of_its_place_is_moved_back() {
    let dir = scratch("compensate", "place");
    let run = dir.join("run");
    ran(&run, "thread", &["--set", "designation=Tr40x14(P7)"]);
    let before = start_two_off(&run.join("program.nc"), 0.03, &dir.join("before"));
    assert!(
        (before[1] - 0.03).abs() < 2e-3 && before[0].abs() < 1e-3,
        "{before:?}"
    );
    let measured = dir.join("places.csv");
    let mut t = String::from("z_mm,start,dz_mm\n");
    for (k, dz) in before.iter().enumerate() {
        t += &format!("-15,{},{dz:.4}\n", k + 1);
    }
    std::fs::write(&measured, t).unwrap();
    let out = dir.join("corrected");
    let (said, _) = compensated(&run, &measured, &out);
    assert!(said.contains("start 2's place: 1 places"), "{said}");
    assert!(
        said.contains("not measured: start 1's pitch diameter"),
        "{said}"
    );
    let table = std::fs::read_to_string(out.join("correction.csv")).unwrap();
    assert!(
        table.starts_with("z_mm,dd2_1_mm,dd2_2_mm,dz_1_mm,dz_2_mm\n"),
        "{table}"
    );
    let row: Vec<f64> = table
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|c| c.parse().unwrap())
        .collect();
    assert!(row[1] == 0.0 && row[2] == 0.0, "{row:?}");
    assert!(
        row[3].abs() < 1e-3 && (row[4] + 0.03).abs() < 1e-3,
        "{row:?}"
    );
    let after = start_two_off(&out.join("program.nc"), 0.03, &dir.join("after"));
    assert!(after.iter().all(|p| p.abs() < 1e-3), "after: {after:?}");
    // The page's chart, per start: start 2 moved back by 30 um.
    let table = &common::report_of(&out)["tables"]["compensation"];
    assert_eq!(table["start"], serde_json::json!([1.0, 2.0]));
    let moved = table["correction_um"][1].as_f64().unwrap();
    assert!((moved + 30.0).abs() < 1.0, "{table}");
}

/// The options that would let a correction run away are refused before
/// anything is read or written, naming the option and its value: a limit
/// that is not a positive finite number (`--limit NaN` turned the limit
/// off), a gain outside (0, 1] (`--gain 2` oscillates for ever), an
/// uncertainty that is not positive; and `--out` equal to the run, or
/// holding it, which would replace the measured run.
#[test]
fn options_that_run_away_or_overwrite_are_refused() {
    let dir = scratch("compensate", "options");
    let run = mandrel_run(&dir);
    let measured = std::path::Path::new("scripts/examples/mandrel-measured.csv");
    for (flag, value, says) in [
        ("--limit", "NaN", "the correction's limit"),
        ("--limit", "inf", "the correction's limit"),
        ("--limit=-1", "", "the correction's limit"),
        ("--limit", "0", "the correction's limit"),
        ("--gain", "2", "the gain"),
        ("--gain", "0", "the gain"),
        ("--gain", "NaN", "the gain"),
        ("--uncertainty", "0", "uncertainty"),
    ] {
        let out = dir.join("out");
        let extra: Vec<&str> = [flag, value]
            .into_iter()
            .filter(|a| !a.is_empty())
            .collect();
        let (code, _, err) = compensate(&run, measured, &out, &extra);
        assert_eq!(code, 1, "{flag} {value}: {err}");
        assert!(err.contains(says), "{flag} {value}: {err}");
        assert!(!out.exists(), "{flag} {value}");
    }
    let before = std::fs::read(run.join("program.mpf")).unwrap();
    for out in [run.clone(), run.parent().unwrap().to_owned()] {
        let (code, _, err) = compensate(&run, measured, &out, &[]);
        assert_eq!(code, 1, "{}: {err}", out.display());
        assert!(err.contains("--out"), "{err}");
    }
    assert_eq!(std::fs::read(run.join("program.mpf")).unwrap(), before);
}

/// A measurement is applied once: `compensation.json` records the
/// corrected run's lineage (its generation, the run it corrected, the
/// measurement's digest, the gain and limit), and the same measurement
/// (by content, whatever its file is called) given to the corrected run
/// is refused, naming the run that applied it (applied again, it grew
/// the correction each time while saying the part would be right).
#[test]
fn a_measurement_is_applied_once() {
    let dir = scratch("compensate", "applied-once");
    let run = mandrel_run(&dir);
    let measured = std::path::Path::new("scripts/examples/mandrel-measured.csv");
    let first = dir.join("first");
    compensated(&run, measured, &first);
    let record = json(&first.join("compensation.json"));
    let lineage = &record["lineage"];
    assert_eq!(lineage["generation"], 1, "{record}");
    assert_eq!(lineage["parent"].as_str(), Some(s(&run)));
    let digest = lineage["measurement_sha256"].as_str().unwrap();
    assert_eq!(digest.len(), 64);
    assert_eq!(lineage["applied"].as_array().unwrap().len(), 1);
    let copy = dir.join("again.csv");
    std::fs::copy(measured, &copy).unwrap();
    let out = dir.join("second");
    let (code, _, err) = compensate(&first, &copy, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("applied already") && err.contains(s(&first)),
        "{err}"
    );
    assert!(!out.exists());
}

/// A measurement that contradicts itself is refused, naming both sides:
/// two rows at one place further apart than 3 times the stated
/// uncertainty (averaged, a diameter's whole error would pass), and two
/// value columns of one quantity (`r_mm` and `d_mm` 50 um apart) further
/// apart than the uncertainty (one was used, without a word).
#[test]
fn a_measurement_that_contradicts_itself_is_refused() {
    let dir = scratch("compensate", "contradicts");
    let run = mandrel_run(&dir);
    let zs: Vec<f64> = (0..=44).map(|i| 10.0 * i as f64).collect();
    let mut rows = String::from("z_mm,d_mm\n");
    for &z in &zs {
        rows += &format!("{z},{}\n", law(z));
    }
    rows += &format!("200,{}\n", law(200.0) + 0.01);
    let apart = dir.join("apart.csv");
    std::fs::write(&apart, rows).unwrap();
    let out = dir.join("out");
    let (code, _, err) = compensate(&run, &apart, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("z_mm = 200") && err.contains("rows 22 and 47"),
        "{err}"
    );
    assert!(!out.exists());
    let mut both = String::from("z_mm,d_mm,r_mm\n");
    for &z in &zs {
        both += &format!("{z},{},{}\n", law(z), law(z) / 2.0 + 0.05);
    }
    let columns = dir.join("both.csv");
    std::fs::write(&columns, both).unwrap();
    let (code, _, err) = compensate(&run, &columns, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("'d_mm'") && err.contains("'r_mm'"), "{err}");
    assert!(!out.exists());
}

/// The run's prediction is recomputed, not read: `predicted_deviation` in
/// its `report.json` shifted by 0.09 mm (which would grind the part 0.18
/// mm undersize on diameter while saying "0.0009 mm expected after") is
/// refused, naming the file and the table; so is a program edited after
/// its run (its prediction is not the file's).
#[test]
fn the_runs_prediction_is_recomputed() {
    let dir = scratch("compensate", "prediction");
    let run = mandrel_run(&dir);
    let measured = std::path::Path::new("scripts/examples/mandrel-measured.csv");
    let original = std::fs::read_to_string(run.join("report.json")).unwrap();
    let mut r: serde_json::Value = serde_json::from_str(&original).unwrap();
    for v in r["tables"]["predicted_deviation"]["dr_mm"]
        .as_array_mut()
        .unwrap()
    {
        *v = serde_json::json!(v.as_f64().unwrap() + 0.09);
    }
    std::fs::write(run.join("report.json"), r.to_string()).unwrap();
    let out = dir.join("out");
    let (code, _, err) = compensate(&run, measured, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("report.json") && err.contains("predicted_deviation"),
        "{err}"
    );
    assert!(!out.exists());
    // The report as written, the program edited by hand.
    std::fs::write(run.join("report.json"), &original).unwrap();
    let program = std::fs::read_to_string(run.join("program.mpf")).unwrap();
    let line = program
        .lines()
        .skip_while(|l| !l.starts_with("; pass 4"))
        .nth(4)
        .unwrap()
        .to_owned();
    let x: f64 = line
        .split_whitespace()
        .find_map(|w| w.strip_prefix('X'))
        .unwrap()
        .parse()
        .unwrap();
    let edited = line.replacen(&format!("X{x:.4}"), &format!("X{:.4}", x + 0.0005), 1);
    std::fs::write(run.join("program.mpf"), program.replacen(&line, &edited, 1)).unwrap();
    let (code, _, err) = compensate(&run, measured, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("predicted_deviation"), "{err}");
}

/// Corrections converge: a constant error of the process (the wheel's
/// wear along the finishing pass, in the loop), the part measured (with a
/// bench's repeatability) and compensated round after round, is within the tolerance after 3 rounds,
/// and the correction then changes by less than the measurement's
/// uncertainty (a measurement of a corrected part is judged against the
/// corrected target: the new correction replaces the old, never adds to
/// it).
#[test]
fn corrections_converge_round_after_round() {
    let dir = scratch("compensate", "rounds");
    let mut run = mandrel_run(&dir);
    let fine = fine();
    let tolerance = common::report_of(&run)["verification"]["tolerance"]
        .as_f64()
        .unwrap();
    let uncertainty = 0.001;
    let mut corrections: Vec<Vec<f64>> = Vec::new();
    for round in 1..=4 {
        // Measured as a bench measures: the part, and its repeatability
        // (0.1 um either way, a fixed sequence that differs each round:
        // two measurements are never the same numbers).
        let bench: Vec<(f64, f64)> = finish_with(&run, "program.mpf", &bench_places(), &worn)
            .into_iter()
            .enumerate()
            .map(|(i, (hi, lo))| {
                let scatter = 5e-5 * [-1.0, 0.0, 1.0][(i + round) % 3];
                (hi + scatter, lo)
            })
            .collect();
        let measured = dir.join(format!("round-{round}.csv"));
        std::fs::write(&measured, bench_table(&bench)).unwrap();
        let out = dir.join(format!("round-{round}"));
        compensated(&run, &measured, &out);
        let c = json(&out.join("compensation.json"));
        assert_eq!(c["lineage"]["generation"], round);
        corrections.push(
            c["quantities"][0]["places"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| p["correction"].as_f64().unwrap())
                .collect(),
        );
        run = out;
        let after = off_nominal(&finish_with(&run, "program.mpf", &fine, &worn), &fine);
        if round >= 3 {
            assert!(
                after <= tolerance,
                "round {round}: {after} mm off, tolerance {tolerance}"
            );
            let (a, b) = (&corrections[round - 2], &corrections[round - 1]);
            let moved = a
                .iter()
                .zip(b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(
                moved < uncertainty,
                "round {round}: the correction moved {moved} mm"
            );
        }
    }
}

/// A wheel wearing linearly along the finishing pass with a 2 um bump on
/// the part besides (a local heat or a chip under the rest): held to the
/// default uncertainty (1 um) the fit is the straight line through the
/// wear, and the part it predicts after the correction is off by the bump;
/// the run says so, naming where, by how much and the uncertainty that
/// would follow it, and writes no program. Held to that uncertainty
/// (the table holds diameters to 0.01 um), the corrected program replayed
/// with the same error is within the tolerance at the measured places.
#[test]
fn a_bump_the_fit_does_not_follow_is_named() {
    let dir = scratch("compensate", "bump");
    let run = mandrel_run(&dir);
    let bump = |z: f64| 0.002 * (-((z - 200.0) / 15.0).powi(2)).exp();
    let error = |share: f64, z: f64| worn(share, z) + bump(z);
    // Measured every 5 mm (the bump is 30 mm wide), but on the edge at
    // z = 400.
    let places: Vec<f64> = (0..=88)
        .map(|i| 5.0 * i as f64)
        .filter(|&z| z != 400.0)
        .collect();
    let measured = dir.join("bump.csv");
    let bench = finish_with(&run, "program.mpf", &places, &error);
    let mut table = String::from("z_mm,d_mm\n");
    for (z, (hi, _)) in places.iter().zip(&bench) {
        table += &format!("{z:.1},{:.5}\n", 2.0 * hi);
    }
    std::fs::write(&measured, table).unwrap();
    let out = dir.join("corrected");
    let (code, _, err) = compensate(&run, &measured, &out, &[]);
    assert_eq!(code, 1, "{err}");
    let line = err
        .lines()
        .find(|l| {
            l.contains("the correction, its fit held to the uncertainty 0.001 mm, leaves the part")
        })
        .unwrap_or_else(|| panic!("{err}"));
    // Named on the bump (its crest at z = 200, 15 mm its half-width).
    let at: f64 = line
        .split("at z_mm = ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no place: {line}"));
    assert!((at - 200.0).abs() <= 15.0, "{line}");
    assert!(!out.join("program.mpf").exists());
    let report = common::report_of(&out);
    let figure = (report["verdict"]["figures"].as_array().unwrap().iter())
        .find(|f| f["name"] == "the part after the correction: its radius from the nominal")
        .unwrap_or_else(|| panic!("{}", report["verdict"]));
    assert!(figure["value"].as_f64().unwrap().abs() > 0.0015, "{figure}");
    // The uncertainty it names follows the bump.
    let named = line
        .split("--uncertainty ")
        .nth(1)
        .and_then(|r| r.split(')').next())
        .unwrap_or_else(|| panic!("no uncertainty named: {line}"));
    let out = dir.join("followed");
    let (code, _, err) = compensate(&run, &measured, &out, &["--uncertainty", named]);
    assert_eq!(code, 0, "{err}");
    // At the measured places, as the message says (between them the fit
    // is not measured: on a 0.5 mm grid the default finish's own 0.93 um
    // and what the fit leaves between places reach 1.06 um).
    let after: f64 = (finish_with(&out, "program.mpf", &places, &error).iter())
        .zip(&places)
        .map(|(&(hi, _), &z)| (hi - law(z) / 2.0).abs())
        .fold(0.0, f64::max);
    assert!(after <= 0.001, "after: {after} mm");
    // The corrected program says it is one, by its name.
    let program = std::fs::read_to_string(out.join("program.mpf")).unwrap();
    assert!(
        program.starts_with("%_N_MANDREL_C1_MPF"),
        "{}",
        &program[..80]
    );
}

/// A CMM's export as a German-language measuring program writes it
/// (feature, position Z, actual D, nominal D, deviation; once with
/// semicolons and decimal commas, once with commas and points), its
/// columns mapped by the user: both read the same, only the mapped columns
/// are read, and two mapped columns of one quantity must agree.
#[test]
fn a_measuring_programs_columns_are_mapped() {
    let dir = scratch("compensate", "cmm");
    let run = mandrel_run(&dir);
    let fixtures = common::root().join("tests/fixtures/cmm");
    let columns = r#"z="Position Z [mm]",d="Istwert D [mm]""#;
    let mut places = Vec::new();
    for file in [
        "mandrel-cmm-semicolon-german-headers.csv",
        "mandrel-cmm-comma-german-headers.csv",
    ] {
        let out = dir.join(file.trim_end_matches(".csv"));
        let (code, said, err) =
            compensate(&run, &fixtures.join(file), &out, &["--columns", columns]);
        assert_eq!(code, 0, "{file}: {err}");
        assert!(
            said.contains("(B (Position Z [mm]) as z_mm, C (Istwert D [mm]) as d_mm)"),
            "{said}"
        );
        let c = json(&out.join("compensation.json"));
        places.push(c["quantities"][0]["places"].clone());
        assert_eq!(c["quantities"][0]["column"], "d_mm", "{file}");
    }
    assert_eq!(places[0], places[1]);
    assert!(places[0].as_array().unwrap().len() > 20);
    let semicolons = fixtures.join("mandrel-cmm-semicolon-german-headers.csv");
    // Unmapped, the family's names are not there.
    let (code, _, err) = compensate(&run, &semicolons, &dir.join("unmapped"), &[]);
    assert_eq!(code, 1);
    assert!(
        err.contains("no column 'z_mm'") && err.contains("B (Position Z [mm])"),
        "{err}"
    );
    // A key the family does not measure.
    let (code, _, err) = compensate(
        &run,
        &semicolons,
        &dir.join("key"),
        &["--columns", "q=B,d=C"],
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("--columns: 'q' is none of the family's columns (z_mm, r_mm, d_mm)"),
        "{err}"
    );
    // The deviation mapped as the radius disagrees with the diameter.
    let (code, _, err) = compensate(
        &run,
        &semicolons,
        &dir.join("both"),
        &[
            "--columns",
            r#"z="Position Z [mm]",d="Istwert D [mm]",r="Abweichung [mm]""#,
        ],
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("r_mm") && err.contains("d_mm"), "{err}");
}
