//! A fourth family, written outside the kernel in this folder and
//! registered by one line (`mod ring;` in `tests/main.rs`): a disc's edge
//! contoured on the vertical mill (the demo script's toolpath), with a
//! verification and a plot of its own. The run knows it by no name: its
//! replay, its figure, its report entry and its picture reach the outputs
//! through the kernel's traits alone.

use pilgrim_kernel::family::{
    FamilyError, FilesContext, Outcome, ReplayContext, Verification, Verified, Verifier,
};
use pilgrim_kernel::job::{self, JobOptions};
use pilgrim_kernel::params::{ParamSpec, Params};
use pilgrim_kernel::program::AxisProgram;
use pilgrim_kernel::replay::{as_written, replay, VerifyError};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::verdict::{Figure, Finding};
use pilgrim_kernel::{PartBody, PartFamily, Toolpath};
use std::collections::BTreeMap;

use crate::common::root;

/// The ring family: the demo's script for everything but the
/// verification, which is this file's; `picture` names its plot's file.
struct Ring {
    script: ScriptFamily,
    picture: &'static str,
}

impl PartFamily for Ring {
    fn name(&self) -> &str {
        "ring"
    }

    fn params(&self) -> &[ParamSpec] {
        self.script.params()
    }

    fn default_machine(&self) -> Result<Option<String>, FamilyError> {
        self.script.default_machine()
    }

    fn toolpath(&self, p: &Params) -> Result<Toolpath, FamilyError> {
        self.script.toolpath(p)
    }

    fn part(&self, p: &Params) -> Result<Vec<PartBody>, FamilyError> {
        self.script.part(p)
    }

    fn verification(&self, p: &Params) -> Result<Option<Verification>, FamilyError> {
        let num = |k: &str| p[k].as_number().unwrap();
        Ok(Some(Verification::new(RingRequest {
            // The cutter's axis runs on this circle.
            radius: num("radius") + num("tool_diameter") / 2.0,
            depth: num("depth"),
            tolerance: 0.002,
            picture: self.picture,
        })))
    }
}

/// What the ring must be: the cutter's axis on a circle about Z.
#[derive(Debug, Clone)]
struct RingRequest {
    radius: f64,
    depth: f64,
    tolerance: f64,
    picture: &'static str,
}

impl Verifier for RingRequest {
    fn verify(&self, ctx: &ReplayContext<'_>) -> Result<Verified, VerifyError> {
        // The tool's point at every block of the contour, in the part frame
        // (the table's turn included), from the program as written.
        let poses = replay(&as_written(ctx.program).0, ctx.machine, &ctx.tool.reference)?;
        let errors: Vec<(usize, f64)> = poses
            .chunks_exact(6)
            .enumerate()
            .filter(|(_, p)| (p[2] + self.depth).abs() < 1e-6)
            .map(|(k, p)| (k, p[0].hypot(p[1]) - self.radius))
            .collect();
        Ok(Verified {
            outcome: Box::new(RingOutcome {
                errors,
                tolerance: self.tolerance,
                picture: self.picture,
            }),
            stock: None,
            part: None,
        })
    }
}

/// The cutter's distance from the circle at each block of the contour.
#[derive(Debug, Clone)]
struct RingOutcome {
    /// (block from 0, radius error mm).
    errors: Vec<(usize, f64)>,
    tolerance: f64,
    picture: &'static str,
}

impl RingOutcome {
    fn worst(&self) -> (usize, f64) {
        self.errors
            .iter()
            .copied()
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            .unwrap_or((0, 0.0))
    }
}

impl Outcome for RingOutcome {
    fn key(&self) -> &'static str {
        // The picture's name "verdict.svg" stands for a family whose key
        // would take the report's own field.
        if self.picture == "verdict.svg" {
            "verdict"
        } else {
            "ring_verification"
        }
    }

    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        Ok(serde_json::json!({
            "blocks": self.errors.len(),
            "worst_mm": self.worst().1,
            "tolerance_mm": self.tolerance,
        }))
    }

    fn findings(&self, program: &AxisProgram) -> (Vec<Figure>, Vec<Finding>) {
        let (k, e) = self.worst();
        let place = pilgrim_kernel::program::block_name(program, k);
        let figure = Figure::new(
            "the contour's radius error",
            e.abs(),
            self.tolerance,
            "mm",
            place.clone(),
        );
        let failures = if e.abs() > self.tolerance {
            vec![Finding::new(
                "the ring",
                format!("the contour strays {e} mm from its circle at {place}"),
            )
            .at(k, place)]
        } else {
            Vec::new()
        };
        (vec![figure], failures)
    }

    fn summary(&self) -> String {
        format!(", ring within {:.4} mm of its circle", self.worst().1.abs())
    }

    fn files(
        &self,
        _ctx: &FilesContext<'_>,
        _tables: &BTreeMap<String, BTreeMap<String, Vec<f64>>>,
    ) -> Result<pilgrim_kernel::family::Drawn, pilgrim_kernel::family::DrawError> {
        // The radius error round the contour, as a polyline.
        let points: Vec<String> = self
            .errors
            .iter()
            .enumerate()
            .map(|(i, (_, e))| format!("{},{:.3}", i, 50.0 - e * 1e4))
            .collect();
        let svg = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {} 100\"><polyline fill=\"none\" stroke=\"black\" points=\"{}\"/></svg>\n",
            self.errors.len().max(1),
            points.join(" ")
        );
        Ok(vec![(self.picture.into(), svg.into_bytes())].into())
    }
}

fn ring() -> Ring {
    ring_drawing("ring.svg")
}

fn ring_drawing(picture: &'static str) -> Ring {
    let script = ScriptFamily::load(
        &root().join("scripts/examples/mill_circle.rhai"),
        &Limits::default(),
        &Access::default(),
    )
    .unwrap();
    Ring { script, picture }
}

/// The ring's run: its verification's figure in the verdict, its entry in
/// report.json under its own key, its picture among the files and on the
/// page, its summary; a contour off its circle fails at its block.
#[test]
fn a_family_of_its_own_verifies_and_draws_through_the_traits() {
    let catalog = pilgrim_kernel::Catalog::new(&[]).unwrap();
    let family = ring();
    let machine = catalog
        .open(&family.default_machine().unwrap().unwrap())
        .unwrap();
    let out = job::run(&family, &machine, &[], &JobOptions::default(), &mut |_| {}).unwrap();
    let outcome = out.check::<RingOutcome>().expect("the ring's outcome");
    assert!(outcome.errors.len() > 300, "{}", outcome.errors.len());
    assert!(outcome.worst().1.abs() < 1e-3, "{:?}", outcome.worst());
    let figure = out
        .report
        .verdict
        .figures
        .iter()
        .find(|f| f.name == "the contour's radius error")
        .expect("the ring's figure in the verdict");
    assert!(figure.value <= figure.tolerance);
    assert_eq!(
        out.report.verifications["ring_verification"]["blocks"],
        serde_json::json!(outcome.errors.len())
    );
    assert!(out.report.files.iter().any(|f| f == "ring.svg"));
    assert!(out.summary().contains("ring within"));
    let page = &out.files.iter().find(|f| f.0 == "report.html").unwrap().1;
    let page = String::from_utf8_lossy(page);
    assert!(page.contains("PASSED") && page.contains("the contour&#39;s radius error"));
    // A contour whose circle is not the cutter's: the verdict fails at a
    // block of the contour.
    let sources = [pilgrim_kernel::ParamSource::Pairs {
        label: "--set".into(),
        pairs: vec![("tool_diameter".into(), "10.01".into())],
    }];
    struct Off(Ring);
    impl PartFamily for Off {
        fn name(&self) -> &str {
            "ring"
        }
        fn params(&self) -> &[ParamSpec] {
            self.0.params()
        }
        fn toolpath(&self, p: &Params) -> Result<Toolpath, FamilyError> {
            self.0.toolpath(p)
        }
        fn verification(&self, p: &Params) -> Result<Option<Verification>, FamilyError> {
            // Held to the circle of a 10 mm cutter, whatever it is given.
            let mut q = p.clone();
            q.insert(
                "tool_diameter".into(),
                pilgrim_kernel::ParamValue::Float(10.0),
            );
            self.0.verification(&q)
        }
    }
    let err = job::run(
        &Off(ring()),
        &machine,
        &sources,
        &JobOptions::default(),
        &mut |_| {},
    )
    .unwrap_err();
    let pilgrim_kernel::Error::Failed(failed) = err else {
        panic!("{err}")
    };
    assert!(
        failed.report.verdict.message().contains("strays"),
        "{}",
        failed.report.verdict.message()
    );
    // A verification draws; it never writes a program (past the lint) or
    // the run's own files.
    for name in ["program.nc", "report.json", "../ring.svg", "verdict.svg"] {
        let err = job::run(
            &ring_drawing(name),
            &machine,
            &[],
            &JobOptions::default(),
            &mut |_| {},
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("is not a name it may write")
                || err.contains("must be a plain name ending in 'verification'"),
            "{name}: {err}"
        );
    }
}
