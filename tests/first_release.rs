//! Families written against the first release (`tests/fixtures/
//! families-first-release/`, unchanged): their old forms still run, each
//! with a warning naming today's form and the date it is kept until; what
//! today's checks refuse in them says what to change; and where a family's
//! default and a machine constant both set a quantity, the run says which
//! wins.

use crate::common::{pilgrim, report_of, root, s, scratch};

const FIXTURES: &str = "tests/fixtures/families-first-release";

/// The roll's steady rest is the first release's `rest_track` on a bare
/// profile: it runs, through today's kernel, and says which form replaces
/// it and until when the old one is kept. Its program, replayed with the
/// true wheel as the first release did not, gouges the taper by 2 mm (the
/// 40 mm wheel's 20 mm flat on a ball's path) and ridges the barrel at
/// 7.5 mm a turn: the failure says what to change, and changed so, on the
/// command line alone, the family verifies on the run and on `pilgrim
/// verify` of what it wrote.
#[test]
fn the_first_releases_roll_runs_and_is_told_what_to_change() {
    let dir = scratch("first-release", "roll");
    let script = root().join(FIXTURES).join("roll.rhai");
    let run = |name: &str, set: &[&str]| {
        let out = dir.join(name);
        let mut args = vec!["run", s(&script), "--out", s(&out)];
        for v in set {
            args.extend(["--set", v]);
        }
        let (code, _, err) = pilgrim(&args);
        (code, err, out)
    };
    let (code, err, out) = run("as-written", &[]);
    assert_eq!(code, 1, "{err}");
    assert!(!err.contains("no longer callable"), "{err}");
    let warnings = report_of(&out)["verdict"]["warnings"].to_string();
    assert!(
        warnings.contains(
            "rest_track(previous, cz, cx, wheel_radius, r_o, b), an earlier release's form"
        ) && warnings.contains("steady_rest(r_o, b, sample, tolerance)")
            && warnings.contains("kept until 2027-06-30"),
        "{warnings}"
    );
    for named in [
        "strays -2.0000",
        "the wheel's flat (20.000 mm between its roundings) cuts",
        "a wheel no wider than twice its rounding radius (20.000 mm)",
        "a finishing feed of at most 40.0 mm/min (0.2000 mm per revolution at 200 rpm)",
    ] {
        assert!(err.contains(named), "{named}: {err}");
    }
    // Those two changed, the pass's end is what is left, and said.
    let (code, err, _) = run("at-the-feed", &["wheel_w=20", "feed=40"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("the wheel leaves the end at z = 0.000 mm within its last revolution"),
        "{err}"
    );
    // A slower feed finishes the end within the tolerance too.
    let (code, err, out) = run("changed", &["wheel_w=20", "feed=30"]);
    assert_eq!(code, 0, "{err}");
    let report = report_of(&out);
    assert_eq!(report["verdict"]["status"], "passed");
    // The rest's U rides the surface before each pass at every block.
    let program = std::fs::read_to_string(out.join("toolpath.json")).unwrap();
    assert!(program.contains("\"U\""), "no U in the toolpath");
    let (code, _, err) = pilgrim(&["verify", s(&out), "--out", s(&dir.join("check")), "-q"]);
    assert_eq!(code, 0, "{err}");
}

/// The drawing plug, refused on the chuck meeting the steady rest, says
/// what would resolve it: the constants of both bodies, the family's
/// parameters that restate them, where its part starts, by how much they
/// overlap.
#[test]
fn the_first_releases_plug_is_told_what_to_change() {
    let out = scratch("first-release", "plug").join("run");
    let script = root().join(FIXTURES).join("plug.rhai");
    let (code, _, err) = pilgrim(&["run", s(&script), "--out", s(&out)]);
    assert_eq!(code, 1, "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("the chuck and the rest collide"))
        .unwrap_or_else(|| panic!("{err}"));
    for named in [
        "they overlap by ",
        "chuck_grip, chuck_length, chuck_radius",
        "rest_offset_b (the family's rest_b)",
        "rest_radius (the family's rest_r)",
        "where the family's part starts (z = -236.000 mm",
    ] {
        assert!(line.contains(named), "{named}: {line}");
    }
    let tail = err
        .lines()
        .find(|l| l.contains("the wheel and the tailstock_centre collide"))
        .unwrap_or_else(|| panic!("{err}"));
    assert!(
        tail.contains("centre_radius") && tail.contains("where the family's part ends"),
        "{tail}"
    );
}

/// A family's default for a quantity the machine states is replaced by
/// the machine's, and the run says so; a value set on the command line
/// replaces the machine's, and the run says that too.
#[test]
fn the_run_says_which_of_a_default_and_a_constant_wins() {
    let dir = scratch("first-release", "constants");
    let source = std::fs::read_to_string(root().join("scripts/mandrel.rhai")).unwrap();
    let edited = source.replacen("rest_b: #{ value: -180.0", "rest_b: #{ value: -150.0", 1);
    assert_ne!(edited, source);
    let script = dir.join("mandrel.rhai");
    std::fs::write(&script, edited).unwrap();
    let (code, said, err) = pilgrim(&["run", s(&script), "--out", s(&dir.join("a"))]);
    assert_eq!(code, 0, "{err}");
    // On the terminal, beside the run's summary.
    let err = format!("{said}{err}");
    assert!(
        err.contains("the machine's rest_offset_b = -180.0000 mm replaces the family's default rest_b = -150.0000 mm")
            && err.contains("--set rest_b=-150.0000"),
        "{err}"
    );
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/mandrel.rhai",
        "--set",
        "rest_b=-170",
        "--out",
        s(&dir.join("b")),
    ]);
    assert_eq!(code, 0, "{err}");
    let report = report_of(&dir.join("b"))["verdict"]["warnings"].to_string();
    assert!(
        report.contains("rest_b = -170.0000 mm (--set) sets the machine's rest_offset_b (the machine states -180.0000 mm) for the whole run"),
        "{report}"
    );
}

/// The plug as today's API writes it (`scripts/examples/drawing_plug.rhai`:
/// its corners by `fillet`, what the first release's refusals named
/// changed) runs and verifies, its own figure (the land's form) beside
/// the profile's and the land's own band (its h4), on the run and on
/// `pilgrim verify` of what it wrote.
#[test]
fn the_plugs_example_runs_and_verifies() {
    let dir = scratch("first-release", "plug-example");
    let out = dir.join("run");
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/examples/drawing_plug.rhai",
        "--out",
        s(&out),
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");
    let check = dir.join("check");
    let (code, _, err) = pilgrim(&["verify", s(&out), "--out", s(&check), "-q"]);
    assert_eq!(code, 0, "{err}");
    for d in [&out, &check] {
        let report = report_of(d);
        let figure = &report["verification"]["judged"]["figures"][0];
        assert_eq!(
            figure["name"], "the land's spread from a cylinder",
            "{figure}"
        );
        let spread = figure["value"].as_f64().unwrap();
        assert!(spread > 0.0 && spread <= 0.002, "{figure}");
        // The land's own fit (Ø30 h4: 0/-6 um), judged over the land.
        let band = (report["verdict"]["figures"].as_array().unwrap().iter())
            .find(|f| f["name"].as_str().unwrap().contains("its own band"))
            .unwrap_or_else(|| panic!("{}", report["verdict"]));
        assert!(
            band["name"]
                .as_str()
                .unwrap()
                .ends_with("d 30.000 h4: +0/-0.006 mm")
                && band["tolerance"].as_f64() == Some(0.0015)
                && band["value"].as_f64().unwrap().abs() <= 0.0015,
            "{band}"
        );
        assert_eq!(report["verdict"]["status"], "passed");
    }
}
