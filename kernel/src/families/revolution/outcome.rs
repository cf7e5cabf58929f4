//! A body of revolution's verification as the run uses it: the request
//! ([`crate::family::VerifyRequest`]) replays a program with
//! [`super::replay_grinding`]; the outcome gives the verdict's figures, the
//! report's `verification`, the plots (`profile.svg`, `deviation.svg`,
//! `finish.svg`, `stock.svg`) and the page's section.

use super::GrindingCheck;
use crate::family::{
    FilesContext, Outcome, OutcomeKind, PartGeometry, ReplayContext, Replayed, ReplayedPass,
    Verified, Verifier, VerifyRequest,
};
use crate::html::{escape, row};
use crate::math::fixed;
use crate::program::AxisProgram;
use crate::replay::VerifyError;
use crate::tool::ToolShape;
use crate::verdict::{Figure, Finding};
use std::fmt::Write;

impl Verifier for VerifyRequest {
    fn verify(&self, ctx: &ReplayContext<'_>) -> Result<Verified, VerifyError> {
        let ToolShape::Wheel(wheel) = ctx.tool.shape else {
            return Err(VerifyError::Contract(
                "fn verify(p) needs a grinding wheel".into(),
            ));
        };
        let (check, ground) = super::replay_grinding(
            ctx.program,
            ctx.machine,
            &ctx.tool.reference,
            &wheel,
            ctx.passes,
            &self.profile,
            self.blank.as_deref(),
            (self.from, self.to),
            self.tolerance,
        )?;
        let part = replayed(&check, &self.profile, ctx.passes);
        Ok(Verified {
            outcome: Box::new(GrindingOutcome {
                check,
                request: self.clone(),
                rounding: wheel.rounding_radius,
            }),
            stock: ground.map(|g| Box::new(g) as Box<dyn crate::process::Stock>),
            part: Some(part),
        })
    }

    /// A body of revolution measured along z: radii (`r_mm`) or diameters
    /// (`d_mm`) at `z_mm`, over the range held to the tolerance, against
    /// the nominal profile.
    fn nominal(&self) -> Option<crate::compensate::Nominal> {
        Some(crate::compensate::Nominal {
            coordinate: "z_mm",
            range: (self.from, self.to),
            quantities: vec![crate::compensate::Quantity {
                name: "radius".into(),
                values: &[("r_mm", 1.0), ("d_mm", 0.5)],
                select: None,
                nominal: self.profile.clone(),
                along: true,
                key: "dr_mm".into(),
                tolerance: Some(self.tolerance),
            }],
        })
    }

    /// A nominal interpolated through stations (no analytic derivatives)
    /// that swings beyond two neighbouring stations by more than the
    /// tolerance, within the range held to it: the stations do not give
    /// that bulge, and the program would grind it.
    fn warnings(&self) -> Vec<Finding> {
        let p = &self.profile;
        let swing = p.swing().filter(|s| {
            !p.has_analytic_derivatives()
                && s.beyond > self.tolerance
                && (self.from..=self.to).contains(&s.z)
        });
        swing
            .map(|s| {
                Finding::new(
                    SWING,
                    format!(
                        "the nominal's {} interpolation swings {} mm beyond its stations at z = {} mm (x = {} mm), more than the tolerance {} mm: its stations do not give that; interpolate them \"monotone\" or \"linear\" (with fillets), or give more stations",
                        p.interpolation().name(),
                        fixed(s.beyond, 4),
                        fixed(s.z, 3),
                        fixed(s.x, 4),
                        self.tolerance
                    ),
                )
            })
            .into_iter()
            .collect()
    }
}

/// The rule of a nominal that swings beyond its stations.
pub const SWING: &str = "the nominal follows its stations";

/// The surface each pass left, for a family's own judgement: over z
/// (`z_mm`, in the stretches the pass's drawing keeps, at most
/// [`super::PROFILE_BUCKETS`]), the lowest and highest radius over the
/// generatrices (`radius_low_mm`, `radius_high_mm`) and their deviations
/// from the nominal (`deviation_low_mm`, `deviation_high_mm`).
fn replayed(
    check: &GrindingCheck,
    nominal: &crate::profile::Profile,
    passes: &[crate::program::ProgramPass],
) -> Replayed {
    let passes = check
        .passes
        .iter()
        .map(|p| {
            let z: Vec<f64> = p.along_z.iter().map(|b| b[0]).collect();
            let at = |b: &[f64; 3], k: usize| nominal.eval(b[0]).map_or(f64::NAN, |r| r + b[k]);
            let columns = std::collections::BTreeMap::from([
                ("z_mm".to_owned(), z),
                (
                    "deviation_low_mm".to_owned(),
                    p.along_z.iter().map(|b| b[1]).collect(),
                ),
                (
                    "deviation_high_mm".to_owned(),
                    p.along_z.iter().map(|b| b[2]).collect(),
                ),
                (
                    "radius_low_mm".to_owned(),
                    p.along_z.iter().map(|b| at(b, 1)).collect(),
                ),
                (
                    "radius_high_mm".to_owned(),
                    p.along_z.iter().map(|b| at(b, 2)).collect(),
                ),
            ]);
            ReplayedPass {
                name: p.name.clone(),
                blocks: passes
                    .iter()
                    .find(|q| q.blocks.start + 1 == p.first_block)
                    .map_or(p.first_block - 1..p.first_block, |q| q.blocks.clone()),
                cuts: true,
                columns,
            }
        })
        .collect();
    Replayed {
        what: "the surface's radius over z".into(),
        passes,
        sampling_change: check.sampling_change_mm,
    }
}

/// A grinding program replayed against its body of revolution.
#[derive(Debug, Clone, PartialEq)]
pub struct GrindingOutcome {
    /// What the replay found.
    pub check: GrindingCheck,
    /// What it was held to.
    pub request: VerifyRequest,
    /// The wheel's rounding radius (mm), for the curvature's panel.
    pub rounding: f64,
}

impl Outcome for GrindingOutcome {
    fn key(&self) -> &'static str {
        KIND.key
    }

    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        serde_json::to_value(&self.check)
    }

    fn findings(&self, program: &AxisProgram) -> (Vec<Figure>, Vec<Finding>) {
        self.check.findings(program)
    }

    fn summary(&self) -> String {
        self.check
            .passes
            .last()
            .map(|p| {
                format!(
                    ", finish within {} mm of nominal",
                    fixed(p.deviation.max_abs, 5)
                )
            })
            .unwrap_or_default()
    }

    /// The part the finish leaves ([`crate::compensate::PREDICTED`]): its
    /// highest generatrix's deviation from the target along z, a row per
    /// stretch of the finish's drawing (at most [`super::PROFILE_BUCKETS`]).
    fn extend_tables(
        &self,
        tables: &mut std::collections::BTreeMap<
            String,
            std::collections::BTreeMap<String, Vec<f64>>,
        >,
    ) {
        let (Some(finish), Some(nominal)) = (self.check.passes.last(), self.request.nominal())
        else {
            return;
        };
        let mut table = std::collections::BTreeMap::from([(
            nominal.coordinate.to_owned(),
            finish.along_z.iter().map(|b| b[0]).collect(),
        )]);
        for q in &nominal.quantities {
            table.insert(q.key.clone(), finish.along_z.iter().map(|b| b[2]).collect());
        }
        tables.insert(crate::compensate::PREDICTED.into(), table);
    }

    fn files(
        &self,
        ctx: &FilesContext<'_>,
        _tables: &std::collections::BTreeMap<String, std::collections::BTreeMap<String, Vec<f64>>>,
    ) -> Result<crate::family::Drawn, crate::family::DrawError> {
        let profiles: Vec<(String, crate::profile::Profile)> = ctx
            .parts
            .iter()
            .filter_map(|b| match &b.geometry {
                PartGeometry::Revolution(p) => Some((b.name.clone(), p.clone())),
                PartGeometry::Swept(_) => None,
            })
            .collect();
        let r = &ctx.replay;
        let text = super::profile_svg(
            &profiles,
            r.program,
            r.passes,
            r.machine,
            &r.tool.reference,
            &self.request.profile,
            self.rounding,
        )?;
        let mut drawn =
            crate::family::Drawn::from(vec![("profile.svg".to_owned(), text.into_bytes())]);
        // The surface before the first pass: the blank the replay cut into.
        let n = &self.request;
        let start = |z: f64| Some(n.blank.as_deref()?.eval(z).ok()? - n.profile.eval(z).ok()?);
        for (name, text, marks) in
            super::deviation_svgs(&self.check, start, r.program.blocks.len(), ctx.corrected)?
        {
            drawn.marks.insert(name.clone(), marks);
            drawn.files.push((name, text.into_bytes()));
        }
        Ok(drawn)
    }
}

/// The grinding replay in `report.json` (`verification`) and on the page.
pub const KIND: OutcomeKind = OutcomeKind {
    key: "verification",
    section,
};

/// The page's section: the finish and every pass's figures.
fn section(
    entry: &serde_json::Value,
    label: &dyn Fn(usize) -> String,
) -> Result<String, crate::family::DrawError> {
    let v: GrindingCheck = serde_json::from_value(entry.clone())?;
    let mut out = String::new();
    let _ = write!(
        out,
        "<h2>Verification: the program replayed</h2>\n<p>Tolerance {} mm; {} generatrices (the finish's worst moved {} um from {}); values read at {} mm as written.</p>\n",
        fixed(v.tolerance, 4),
        v.generatrices,
        fixed(v.sampling_change_mm * 1e3, 4),
        v.generatrices / 2,
        fixed(v.resolution_mm, 4)
    );
    if let Some(f) = v.passes.last() {
        // The block counts from 1 (the program's and report.csv's).
        let block = f
            .deviation
            .block
            .map_or_else(String::new, |b| format!(", {}", escape(&label(b - 1))));
        let _ = writeln!(
            out,
            "<p class=\"verdict\">Finish ({}) within <b>{} mm</b> of the nominal; the worst at z = {} mm{block}.</p>",
            escape(&f.name),
            fixed(f.deviation.max_abs, 5),
            fixed(f.deviation.at_z, 3)
        );
    }
    out.push_str("<table><tr><th>pass</th><th>removed, um</th><th>feed, mm/min</th><th>feed a rev, mm</th><th>ridge, um</th><th>highest, um (z)</th><th>lowest, um (z)</th></tr>\n");
    for (k, p) in v.passes.iter().enumerate() {
        row(
            &mut out,
            &[
                escape(&pass_title(k, p)),
                p.removed_mm
                    .map_or_else(|| "-".into(), |r| fixed(r * 1e3, 1)),
                fixed(p.feed_mm_min, 1),
                fixed(p.feed_per_rev_mm, 3),
                fixed(p.ridge_mm * 1e3, 2),
                format!(
                    "{} ({})",
                    fixed(p.deviation.max_above * 1e3, 2),
                    fixed(p.deviation.above_z, 2)
                ),
                format!(
                    "{} ({})",
                    fixed(p.deviation.max_below * 1e3, 2),
                    fixed(p.deviation.below_z, 2)
                ),
            ],
        );
    }
    out.push_str("</table>\n");
    Ok(out)
}

/// How the page names cutting pass `k` (from 0): by its order and what it
/// removed and left at its valleys ("pass 3: 93.4 um removed, 20.0 um
/// left"), with the
/// program's own name where a comment gave one other than "pass N".
fn pass_title(k: usize, p: &super::PassCheck) -> String {
    let order = format!("pass {}", k + 1);
    let what = match p.removed_mm {
        Some(r) => format!(
            "{order}: {} um removed, {} um left",
            fixed(r * 1e3, 1),
            fixed(p.left_mm * 1e3, 1)
        ),
        None => format!("{order}: {} um left", fixed(p.left_mm * 1e3, 1)),
    };
    if p.name == order {
        what
    } else {
        format!("{what} ({})", p.name)
    }
}
