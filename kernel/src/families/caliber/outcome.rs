//! A caliber's verification as the run uses it: the request
//! ([`GrooveRequest`]) replays a program in 3-D with [`check_groove`]; the
//! outcome gives the verdict's figures, the report's
//! `groove_verification`, the contact patch at the scene's block, the
//! plots (`deviation_map.svg`, `section.svg`) and the page's section.

use super::{check_groove, contact_patch, GrooveCheck, GroovePlace, GrooveRequest, GrooveStock};
use crate::family::{FilesContext, Outcome, OutcomeKind, ReplayContext, Verified, Verifier};
use crate::html::{escape, row};
use crate::math::fixed;
use crate::program::AxisProgram;
use crate::replay::VerifyError;
use crate::tool::{ToolShape, Wheel};
use crate::verdict::{Figure, Finding};
use std::collections::BTreeMap;
use std::fmt::Write;

/// The wheel of `ctx`, which a groove's replay needs.
fn wheel_of(ctx: &ReplayContext<'_>) -> Result<Wheel, VerifyError> {
    match ctx.tool.shape {
        ToolShape::Wheel(w) => Ok(w),
        _ => Err(VerifyError::Contract(
            "fn verify(p) needs a grinding wheel".into(),
        )),
    }
}

impl Verifier for GrooveRequest {
    fn verify(&self, ctx: &ReplayContext<'_>) -> Result<Verified, VerifyError> {
        let wheel = wheel_of(ctx)?;
        let stock = self.stock.map(|allowance| {
            Box::new(GrooveStock::new(self, allowance, &wheel, ctx.passes))
                as Box<dyn crate::process::Stock>
        });
        let check = check_groove(
            ctx.program,
            ctx.machine,
            &ctx.tool.reference,
            &wheel,
            ctx.passes,
            self,
        )?;
        Ok(Verified {
            outcome: Box::new(GrooveOutcome {
                check,
                request: self.clone(),
                wheel,
            }),
            stock,
            part: None,
        })
    }

    /// The groove measured over theta (`theta_deg`, deg): its depth
    /// (`Hp_mm` or `depth_mm`) and its width at the periphery (`B_mm` or
    /// `width_mm`), as its tables give them, against the groove's tables
    /// as ground (smoothed), over their range.
    fn nominal(&self) -> Option<crate::compensate::Nominal> {
        let g = &self.groove;
        let in_deg = |p: &crate::profile::Profile| {
            let deg: Vec<f64> = p.z().iter().map(|t| t.to_degrees()).collect();
            crate::profile::Profile::new(deg, p.x().to_vec())
                .ok()
                .map(|d| d.with_interpolation(p.interpolation()))
        };
        let (lo, hi) = g.theta_range();
        let quantity = |name: &str, values, p, key: &str| {
            Some(crate::compensate::Quantity {
                name: name.into(),
                values,
                select: None,
                nominal: in_deg(p)?,
                along: true,
                key: key.into(),
                tolerance: None,
            })
        };
        Some(crate::compensate::Nominal {
            coordinate: "theta_deg",
            range: (lo.to_degrees(), hi.to_degrees()),
            quantities: vec![
                quantity(
                    "depth",
                    &[("Hp_mm", 1.0), ("depth_mm", 1.0)],
                    g.depth(),
                    "dhp_mm",
                )?,
                quantity(
                    "width",
                    &[("B_mm", 1.0), ("width_mm", 1.0)],
                    g.width(),
                    "db_mm",
                )?,
            ],
        })
    }
}

/// A caliber program replayed against its groove.
#[derive(Debug, Clone, PartialEq)]
pub struct GrooveOutcome {
    /// What the replay found.
    pub check: GrooveCheck,
    /// What it was held to.
    pub request: GrooveRequest,
    /// The wheel.
    pub wheel: Wheel,
}

impl Outcome for GrooveOutcome {
    fn key(&self) -> &'static str {
        KIND.key
    }

    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        serde_json::to_value(&self.check)
    }

    fn findings(&self, _program: &AxisProgram) -> (Vec<Figure>, Vec<Finding>) {
        self.check.findings()
    }

    /// The groove as cut ([`crate::compensate::PREDICTED`]): its depth's
    /// and its width's deviations from the target over theta
    /// ([`GrooveCheck::along_theta`]).
    fn extend_tables(&self, tables: &mut BTreeMap<String, BTreeMap<String, Vec<f64>>>) {
        let Some(nominal) = self.request.nominal() else {
            return;
        };
        let rows = &self.check.along_theta;
        let mut table = BTreeMap::from([(
            nominal.coordinate.to_owned(),
            rows.iter().map(|r| r[0]).collect(),
        )]);
        for (q, k) in nominal.quantities.iter().zip([1, 2]) {
            table.insert(q.key.clone(), rows.iter().map(|r| r[k]).collect());
        }
        tables.insert(crate::compensate::PREDICTED.into(), table);
    }

    fn summary(&self) -> String {
        let g = &self.check;
        format!(
            ", groove within {} mm of nominal (material left {} mm, gouge {} mm)",
            fixed(g.max_abs_mm, 5),
            fixed(g.max_left.mm, 5),
            fixed(g.max_gouge.mm, 5)
        )
    }

    fn at_pose(
        &mut self,
        ctx: &ReplayContext<'_>,
        block: usize,
    ) -> Result<Option<crate::mesh::TriMesh>, VerifyError> {
        Ok(contact_patch(
            &crate::replay::as_written(ctx.program).0,
            ctx.machine,
            &ctx.tool.reference,
            &self.wheel,
            &self.request,
            block,
        )?
        .map(|(p, m)| {
            self.check.patch = Some(p);
            m
        }))
    }

    fn files(
        &self,
        ctx: &FilesContext<'_>,
        tables: &BTreeMap<String, BTreeMap<String, Vec<f64>>>,
    ) -> Result<crate::family::Drawn, crate::family::DrawError> {
        // Each grinding pass's psi, as the family's pass table gives it a
        // row per cutting pass in order; none where the rows do not match.
        let cutting: Vec<_> = ctx.replay.passes.iter().filter(|p| p.cuts).collect();
        let passes: Vec<(std::ops::Range<usize>, f64)> = tables
            .get("passes")
            .and_then(|t| t.get("psi_deg"))
            .filter(|psi| psi.len() == cutting.len())
            .map(|psi| {
                cutting
                    .iter()
                    .zip(psi)
                    .filter(|(_, v)| v.is_finite())
                    .map(|(p, v)| (p.blocks.clone(), *v))
                    .collect()
            })
            .unwrap_or_default();
        let (map, marks) = super::deviation_map_svg(&self.check, &passes, ctx.corrected)?;
        let section = super::section_svg(&self.check, &self.request, self.wheel.rounding_radius)?;
        Ok(crate::family::Drawn {
            files: vec![
                ("deviation_map.svg".into(), map.into_bytes()),
                ("section.svg".into(), section.into_bytes()),
            ],
            marks: [("deviation_map.svg".to_owned(), marks)].into(),
        })
    }
}

/// The groove's replay in `report.json` (`groove_verification`) and on
/// the page.
pub const KIND: OutcomeKind = OutcomeKind {
    key: "groove_verification",
    section,
};

/// The page's section: the groove's extremes and where they are.
fn section(
    entry: &serde_json::Value,
    _label: &dyn Fn(usize) -> String,
) -> Result<String, crate::family::DrawError> {
    let g: GrooveCheck = serde_json::from_value(entry.clone())?;
    let mut out = String::new();
    let place = |p: &GroovePlace| {
        format!(
            "{} mm at theta {} deg, psi {} deg ({})",
            fixed(p.mm, 5),
            fixed(p.theta_deg, 2),
            fixed(p.psi_deg, 2),
            escape(&p.block)
        )
    };
    let _ = write!(
        out,
        "<h2>Verification: the groove replayed in 3-D</h2>\n<p class=\"verdict\">Within <b>{} mm</b> of the groove (tolerance {} mm), edge to edge (psi {} to {} deg), on {} samples.</p>\n<table>\n",
        fixed(g.max_abs_mm, 5),
        fixed(g.tolerance, 4),
        fixed(g.psi_range_deg[0], 0),
        fixed(g.psi_range_deg[1], 0),
        g.samples
    );
    row(&mut out, &["most material left".into(), place(&g.max_left)]);
    row(&mut out, &["deepest gouge".into(), place(&g.max_gouge)]);
    row(
        &mut out,
        &[
            "deepest cut into the periphery beside it".into(),
            format!(
                "{}, {} mm beyond the edge",
                place(&g.periphery_cut),
                fixed(g.periphery_cut.beyond_edge_mm, 3)
            ),
        ],
    );
    out.push_str("</table>\n");
    Ok(out)
}
