//! A worm's verification as the run uses it: the request ([`ThreadRequest`])
//! simulates a program's cut pass by pass with [`simulate`]; the outcome
//! gives the verdict's figures, the report's `thread_verification`, the
//! finished worm's solid, the simulated areas in the family's `passes`
//! table, `passes.csv`, `passes.xlsx`, `passes.svg` and the page's section.

use super::{
    pass_table, passes_svg, simulate, thread_solid, SimulatedPass, ThreadCheck, ThreadRequest,
    ThreadStock, ThreadSweep,
};
use crate::family::{
    FilesContext, Outcome, OutcomeKind, PartBody, PartGeometry, ReplayContext, Swept, SweptBody,
    Verified, Verifier,
};
use crate::html::{escape, row};
use crate::math::{fixed, Real};
use crate::mesh::SceneError;
use crate::program::AxisProgram;
use crate::replay::VerifyError;
use crate::tool::ToolShape;
use crate::verdict::{Figure, Finding};
use std::collections::BTreeMap;
use std::fmt::Write;

impl Verifier for ThreadRequest {
    fn verify(&self, ctx: &ReplayContext<'_>) -> Result<Verified, VerifyError> {
        let ToolShape::ThreadCutter(c) = ctx.tool.shape else {
            return Err(VerifyError::Contract(
                "fn verify(p) of a worm needs a thread cutter".into(),
            ));
        };
        let check = simulate(ctx.program, ctx.machine, &ctx.tool.reference, &c, self)?;
        let stock = ThreadStock::new(&check, self, &c);
        Ok(Verified {
            outcome: Box::new(ThreadOutcome {
                check,
                request: self.clone(),
            }),
            stock: Some(Box::new(stock)),
            part: None,
        })
    }

    /// Each start's pitch diameter (`d2_mm`, over wires), at any places
    /// along the thread (`z_mm`, from -length to 0), against the one the
    /// cut aims at; a thread of several starts names each row's start
    /// (`start`, from 1). Corrected as one value per start: a start's
    /// passes move as one (the section is simulated once for the thread's
    /// length, so a taper along it is not followed).
    ///
    /// And each start's place along the axis (`dz_mm`: its space's middle
    /// at the pitch line from where it should stand, + towards +Z, the
    /// mean of its two flanks' axial errors there, as a CMM measures
    /// them), against 0, corrected as one value: its passes move along
    /// the axis.
    fn nominal(&self) -> Option<crate::compensate::Nominal> {
        let w = &self.section;
        let several = w.starts > 1;
        let along = vec![-self.length, -0.5 * self.length, 0.0];
        let quantity = |k: u32, what: &str, values, nominal: Real, key: &str| {
            Some(crate::compensate::Quantity {
                name: if several {
                    format!("start {k}'s {what}")
                } else {
                    what.into()
                },
                values,
                select: several.then_some(("start", f64::from(k))),
                nominal: crate::profile::Profile::new(along.clone(), vec![nominal; 3]).ok()?,
                along: false,
                key: format!("{key}_{k}_mm"),
                tolerance: None,
            })
        };
        let quantities = (1..=w.starts)
            .map(|k| {
                quantity(
                    k,
                    "pitch diameter",
                    &[("d2_mm", 1.0)],
                    w.pitch_diameter,
                    "dd2",
                )
            })
            .chain((1..=w.starts).map(|k| quantity(k, "place", &[("dz_mm", 1.0)], 0.0, "dz")))
            .collect::<Option<Vec<_>>>()?;
        Some(crate::compensate::Nominal {
            coordinate: "z_mm",
            range: (-self.length, 0.0),
            quantities,
        })
    }
}

/// A worm's cut simulated against its thread.
#[derive(Debug, Clone, PartialEq)]
pub struct ThreadOutcome {
    /// What the simulation found.
    pub check: ThreadCheck,
    /// What it was held to.
    pub request: ThreadRequest,
}

impl Outcome for ThreadOutcome {
    fn key(&self) -> &'static str {
        KIND.key
    }

    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        serde_json::to_value(&self.check)
    }

    fn findings(&self, _program: &AxisProgram) -> (Vec<Figure>, Vec<Finding>) {
        self.check.findings()
    }

    fn summary(&self) -> String {
        let w = &self.check;
        let form = w
            .starts
            .iter()
            .map(|s| s.left_form.abs().max(s.right_form.abs()))
            .fold(0.0, f64::max);
        format!(
            ", thread within tolerance (flank form {} mm; chips {:.2} of {:.2} mm^2 of space)",
            fixed(form, 4),
            w.removed_area,
            w.space_area
        )
    }

    fn bodies(
        &self,
        mesh_tolerance: f64,
        step_tolerance: f64,
    ) -> Result<Vec<PartBody>, SceneError> {
        // The finished worm: the simulated section swept along the helix.
        let mesh_error = |source| SceneError::Mesh {
            body: self.request.part.into(),
            source,
        };
        let (w, length) = (&self.check, self.request.length);
        let mesh = thread_solid(w, length, mesh_tolerance, self.request.outside_diameter)
            .map_err(mesh_error)?;
        // A quarter of the STEP tolerance for merging the outline's points,
        // the rest for the fit.
        let body = ThreadSweep::new(
            w,
            length,
            step_tolerance / 4.0,
            self.request.outside_diameter,
        )
        .map_err(mesh_error)?;
        Ok(vec![PartBody {
            name: self.request.part.into(),
            geometry: PartGeometry::Swept(Box::new(Swept {
                mesh,
                body: SweptBody::new(body),
            })),
        }])
    }

    fn extend_tables(&self, tables: &mut BTreeMap<String, BTreeMap<String, Vec<f64>>>) {
        // Each start's simulated pitch diameter less the one the cut aimed
        // at, its part's predicted deviation (crate::compensate::PREDICTED),
        // the same along the thread.
        let w = &self.check;
        if let Some(nominal) = self.request.nominal() {
            let (from, to) = nominal.range;
            let along = vec![from, 0.5 * (from + to), to];
            let mut table = BTreeMap::from([(nominal.coordinate.to_owned(), along)]);
            // The quantities are each start's pitch diameter, then each
            // start's place.
            let (pitch, place) = nominal.quantities.split_at(w.starts.len());
            for (k, ((d2, dz), s)) in pitch.iter().zip(place).zip(&w.starts).enumerate() {
                let aimed = self.request.section.pitch_diameter
                    + self.request.pitch_shift.get(k).copied().unwrap_or(0.0);
                table.insert(d2.key.clone(), vec![s.pitch_diameter - aimed; 3]);
                table.insert(dz.key.clone(), vec![s.position_error; 3]);
            }
            tables.insert(crate::compensate::PREDICTED.into(), table);
        }
        // The simulated areas beside the plan's, row for row, where the
        // family's "passes" table has one row per thread block.
        // A program whose thread blocks are not the plan's rows (one read
        // from a file: a shop's G76) has its own table, the program's.
        let planned = tables
            .get("passes")
            .is_some_and(|t| !t.is_empty() && t.values().all(|c| c.len() == w.passes.len()));
        if !planned && !w.passes.is_empty() {
            let n = w.passes.len();
            tables.insert(
                "passes".into(),
                BTreeMap::from([("pass".to_owned(), (1..=n).map(|k| k as f64).collect())]),
            );
        }
        if let Some(t) = tables.get_mut("passes") {
            if t.values().all(|c| c.len() == w.passes.len()) && !t.is_empty() {
                t.insert(
                    "simulated_area".into(),
                    w.passes.iter().map(|p| p.chip_area).collect(),
                );
                t.insert(
                    "left_area".into(),
                    w.passes.iter().map(|p| p.left_area).collect(),
                );
                t.insert(
                    "right_area".into(),
                    w.passes.iter().map(|p| p.right_area).collect(),
                );
                t.insert(
                    "block".into(),
                    w.passes.iter().map(|p| p.block as f64).collect(),
                );
            }
        }
    }

    fn leads_charts(&self) -> bool {
        true
    }

    fn files(
        &self,
        ctx: &FilesContext<'_>,
        tables: &BTreeMap<String, BTreeMap<String, Vec<f64>>>,
    ) -> Result<crate::family::Drawn, crate::family::DrawError> {
        let table = pass_table(&self.check, tables.get("passes"))?;
        let workbook = super::pass_workbook(&self.check, tables.get("passes"))?;
        let (svg, marks) = passes_svg(&self.check, ctx.replay.program.blocks.len(), ctx.corrected)?;
        Ok(crate::family::Drawn {
            files: vec![
                ("passes.csv".into(), table.into_bytes()),
                ("passes.xlsx".into(), workbook),
                ("passes.svg".into(), svg.into_bytes()),
            ],
            marks: [("passes.svg".to_owned(), marks)].into(),
        })
    }
}

/// The thread's simulation (a worm's, any standard thread's) in
/// `report.json` (`thread_verification`) and on the page.
pub const KIND: OutcomeKind = OutcomeKind {
    key: "thread_verification",
    section,
};

/// The page's section: chips, loads, leads and each start's figures.
fn section(
    entry: &serde_json::Value,
    _label: &dyn Fn(usize) -> String,
) -> Result<String, crate::family::DrawError> {
    let w: ThreadCheck = serde_json::from_value(entry.clone())?;
    let mut out = String::new();
    let _ = write!(
        out,
        "<h2>Verification: the thread cut simulated</h2>\n<p class=\"verdict\">Chips {} of {} mm<sup>2</sup> of space; flank loads {} / {} mm<sup>2</sup>; lead error {} mm.</p>\n",
        fixed(w.removed_area, 3),
        fixed(w.space_area, 3),
        fixed(w.flank_loads[0], 1),
        fixed(w.flank_loads[1], 1),
        fixed(w.lead_error, 5)
    );
    let worst = |f: fn(&SimulatedPass) -> f64| {
        w.passes
            .iter()
            .max_by(|a, b| f(a).total_cmp(&f(b)))
            .map_or_else(String::new, |p| {
                format!("{}% ({})", fixed(100.0 * f(p), 3), escape(&p.name))
            })
    };
    let _ = writeln!(
        out,
        "<p>The lead where each pass's cutting edges meet the worm's face (S1 from the edges): at most {}; where they leave its far end (S2): at most {}; allowed {}%.</p>",
        worst(|p| p.face_lead_error),
        worst(|p| p.end_lead_error),
        fixed(100.0 * w.tolerances.lead, 3)
    );
    out.push_str("<table><tr><th>start</th><th>flank angles, deg</th><th>form, um</th><th>thickness, mm</th><th>root / tip, mm</th><th>place, um</th></tr>\n");
    for s in &w.starts {
        row(
            &mut out,
            &[
                s.start.to_string(),
                format!(
                    "{} / {}",
                    fixed(s.left_angle_deg, 4),
                    fixed(s.right_angle_deg, 4)
                ),
                format!(
                    "{} / {}",
                    fixed(s.left_form * 1e3, 2),
                    fixed(s.right_form * 1e3, 2)
                ),
                fixed(s.thickness, 4),
                format!(
                    "{} / {}",
                    fixed(s.root_diameter, 3),
                    fixed(s.tip_diameter, 3)
                ),
                fixed(s.position_error * 1e3, 2),
            ],
        );
    }
    out.push_str("</table>\n");
    Ok(out)
}
