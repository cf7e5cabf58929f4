//! The job as a kernel call: a part family written in Rust runs through the
//! same job as the Rhai one and makes the same files.

use pilgrim_kernel::catalog::Catalog;
use pilgrim_kernel::family::{Check, FamilyError, PartBody, PartFamily, PartGeometry};
use pilgrim_kernel::job::{self, JobOptions};
use pilgrim_kernel::params::{ParamSpec, ParamValue, Params};
use pilgrim_kernel::profile::Profile;
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::tool::Tool;
use pilgrim_kernel::toolpath::{ClPoint, Motion, Pass, Toolpath};
use std::f64::consts::PI;
use std::path::Path;

/// `scripts/examples/mill_circle.rhai` written in Rust, step for step: the
/// edge of a disc contoured on the vertical mill, the table turning.
struct MillCircle {
    specs: Vec<ParamSpec>,
}

impl MillCircle {
    fn new() -> Self {
        let spec = ParamSpec::new;
        let f = ParamValue::Float;
        let bounded = |s: ParamSpec, min: Option<f64>, max: f64| ParamSpec {
            min,
            max: Some(max),
            ..s
        };
        Self {
            specs: vec![
                bounded(
                    spec(
                        "radius",
                        f(40.0),
                        "mm",
                        "radius of the disc's finished edge",
                    ),
                    Some(0.1),
                    1000.0,
                ),
                bounded(
                    spec("tool_diameter", f(10.0), "mm", "end mill diameter"),
                    Some(0.1),
                    200.0,
                ),
                bounded(
                    spec(
                        "depth",
                        f(5.0),
                        "mm",
                        "depth of the contour below the top face (z = 0)",
                    ),
                    Some(0.01),
                    200.0,
                ),
                bounded(
                    spec(
                        "points",
                        ParamValue::Int(360),
                        "",
                        "points round the circle",
                    ),
                    None,
                    1e6,
                ),
                bounded(
                    spec("feed", f(600.0), "mm/min", "cutting speed along the edge"),
                    None,
                    20000.0,
                ),
                bounded(
                    spec("spindle", f(3000.0), "rpm", "spindle speed"),
                    Some(1.0),
                    30000.0,
                ),
                bounded(
                    spec(
                        "clearance",
                        f(5.0),
                        "mm",
                        "height of rapid moves above the top face",
                    ),
                    Some(0.0),
                    500.0,
                ),
                spec(
                    "turn_table",
                    ParamValue::Bool(true),
                    "",
                    "contour by turning the table (C) instead of moving X and Y",
                ),
            ],
        }
    }
}

fn num(p: &Params, name: &str) -> f64 {
    p[name].as_number().unwrap()
}

/// A pass's point, the tool's axis along +Z.
fn at(x: f64, y: f64, z: f64, motion: Motion, feed: f64, c: f64) -> ClPoint {
    ClPoint {
        point: [x, y, z],
        axis: [0.0, 0.0, 1.0],
        motion,
        feed,
        aux: vec![c],
    }
}

impl PartFamily for MillCircle {
    fn name(&self) -> &str {
        "mill_circle (Rust)"
    }

    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }

    fn default_machine(&self) -> Result<Option<String>, FamilyError> {
        Ok(Some("vertical-mill".into()))
    }

    fn checks(&self, p: &Params) -> Result<Vec<Check>, FamilyError> {
        Ok(vec![
            Check {
                name: "the cutter is smaller than the disc".into(),
                ok: num(p, "tool_diameter") < 2.0 * num(p, "radius"),
                detail: String::new(),
            },
            Check {
                name: "enough points for the circle".into(),
                ok: num(p, "points") >= 8.0,
                detail: String::new(),
            },
        ])
    }

    fn toolpath(&self, p: &Params) -> Result<Toolpath, FamilyError> {
        let (radius, d, depth) = (num(p, "radius"), num(p, "tool_diameter"), num(p, "depth"));
        let (feed, clearance) = (num(p, "feed"), num(p, "clearance"));
        let tool =
            Tool::end_mill("end mill", 1, d, 3.0 * depth).map_err(|e| FamilyError::Failed {
                family: self.name().into(),
                message: e.to_string(),
            })?;
        let r = radius + d / 2.0;
        let n = num(p, "points") as usize + 1;
        let m = (n - 1) as f64;
        let beta: Vec<f64> = (0..n)
            .map(|i| {
                if i == n - 1 {
                    2.0 * PI
                } else {
                    (2.0 * PI) * i as f64 / m
                }
            })
            .collect();
        let deg = 180.0 / PI;
        let mut tp = Toolpath::new("mill_circle", tool, num(p, "spindle"), vec!["C".into()]);
        let pass = |name: &str, points| Pass {
            name: name.into(),
            points,
        };
        tp.passes.push(pass(
            "approach",
            vec![
                at(r, 0.0, clearance, Motion::Rapid, 0.0, 0.0),
                at(r, 0.0, 1.0, Motion::Rapid, 0.0, 0.0),
            ],
        ));
        tp.passes.push(pass(
            "plunge",
            vec![at(r, 0.0, -depth, Motion::Linear, feed / 3.0, 0.0)],
        ));
        let turn = p["turn_table"] == ParamValue::Bool(true);
        let contour = beta
            .iter()
            .map(|b| {
                let (x, y) = (b.cos() * r, b.sin() * r);
                if turn {
                    at(x, y, -depth, Motion::Linear, feed / r * deg, b * deg)
                } else {
                    at(x, y, -depth, Motion::Linear, feed, 0.0)
                }
            })
            .collect();
        tp.passes.push(pass("contour", contour));
        let end_c = if turn { 360.0 } else { 0.0 };
        tp.passes.push(pass(
            "retract",
            vec![at(r, 0.0, clearance, Motion::Rapid, 0.0, end_c)],
        ));
        Ok(tp)
    }

    fn part(&self, p: &Params) -> Result<Vec<PartBody>, FamilyError> {
        let (radius, t) = (num(p, "radius"), 2.0 * num(p, "depth"));
        let disc = Profile::new(vec![-t, -t / 2.0, 0.0], vec![radius; 3]).map_err(|source| {
            FamilyError::Profile {
                family: self.name().into(),
                source,
            }
        })?;
        Ok(vec![PartBody {
            name: "part".into(),
            geometry: PartGeometry::Revolution(disc),
        }])
    }
}

fn run(family: &dyn PartFamily) -> job::JobOutput {
    let catalog = Catalog::new(&[]).unwrap();
    let spec = family.default_machine().unwrap().unwrap();
    let machine = catalog.open(&spec).unwrap();
    let options = JobOptions {
        program_name: "mill_circle".into(),
        ..JobOptions::default()
    };
    let mut stages = vec![];
    let out = job::run(family, &machine, &[], &options, &mut |s| {
        stages.push(s.to_owned())
    })
    .unwrap();
    assert_eq!(stages, job::STAGES);
    out
}

/// The Rust family and the script make the same toolpath, program, posts,
/// models and block table through the same job; the reports differ only in
/// the family's name and the checks' details.
#[test]
fn a_rust_family_runs_through_the_same_job_as_the_rhai_one() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/examples/mill_circle.rhai");
    let rhai = ScriptFamily::load(&script, &Limits::default(), &Access::default()).unwrap();
    let (a, b) = (run(&MillCircle::new()), run(&rhai));
    assert_eq!(a.params, b.params);
    let mut specs = MillCircle::new().params().to_vec();
    specs.sort_by(|a, b| a.name.cmp(&b.name));
    assert_eq!(specs, rhai.params());
    assert_eq!(a.toolpath, b.toolpath);
    assert_eq!(a.program, b.program);
    let names = |o: &job::JobOutput| o.files.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b));
    for ((name, x), (_, y)) in a.files.iter().zip(&b.files) {
        // The report and its page name the family and its checks' words.
        if name != "report.json" && name != "report.html" {
            assert!(x == y, "{name} differs");
        }
    }
    let (mut ra, rb) = (a.report.clone(), b.report.clone());
    assert_eq!(ra.script, "mill_circle (Rust)");
    ra.script = rb.script.clone();
    for (c, d) in ra.checks.iter_mut().zip(&rb.checks) {
        c.detail = d.detail.clone();
    }
    assert_eq!(ra, rb);
    assert!(a
        .summary()
        .starts_with("mill_circle (Rust): 2 cutting passes (4 in all), 368 blocks"));
}

/// A failed check stops the job, naming the family and the check.
#[test]
fn a_failed_check_stops_the_job() {
    let catalog = Catalog::new(&[]).unwrap();
    let machine = catalog.open("vertical-mill").unwrap();
    let sources = [pilgrim_kernel::ParamSource::Pairs {
        label: "--set".into(),
        pairs: vec![("points".into(), "4".into())],
    }];
    let e = job::run(
        &MillCircle::new(),
        &machine,
        &sources,
        &JobOptions::default(),
        &mut |_| {},
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "mill_circle (Rust): check failed: enough points for the circle ()"
    );
    // Failure is a state of the product: the report says which check, with
    // every parameter, marked FAILED, and there is no program.
    let pilgrim_kernel::Error::Failed(run) = e else {
        panic!("a failed run")
    };
    assert!(run.report.verdict.failed());
    let names: Vec<&str> = run.files.iter().map(|f| f.0.as_str()).collect();
    assert_eq!(names, ["report.html", "report.json"]);
    let page = String::from_utf8(run.files[0].1.clone()).unwrap();
    assert!(page.contains("FAILED") && page.contains("enough points for the circle"));
}
