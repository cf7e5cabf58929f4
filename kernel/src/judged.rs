//! A replayed part judged by its family's own code (a script's `judge`):
//! the figures with their tolerances, the findings with their blocks and
//! the tables it returned, as the run, the verdict, the report and the page
//! treat a built-in verification's. [`Judged`] stands alone (a
//! verification of the family's own, on a replay the kernel made: radius
//! over angle, [`crate::replay::polar`]) or beside a built-in
//! verification's outcome ([`WithJudged`]: a drawing plug keeps the
//! revolution's verification and adds its land's figures).

use crate::family::{FilesContext, Outcome, OutcomeKind, ReplayContext};
use crate::html::{escape, row_at};
use crate::math::fixed;
use crate::program::AxisProgram;
use crate::verdict::{Figure, Finding};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write;

/// Tables by name, each a map of columns.
pub type Tables = BTreeMap<String, BTreeMap<String, Vec<f64>>>;

/// One figure a family's judgement returned.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JudgedFigure {
    /// What it is.
    pub name: String,
    /// Its value (signed where the sign says something).
    pub value: f64,
    /// What it may be at most in size.
    pub tolerance: f64,
    /// Its unit.
    pub unit: String,
    /// Where it is, in the family's words (`at 212.5 deg`).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub place: String,
    /// The block (from 0) where it is, if at one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block: Option<usize>,
}

impl JudgedFigure {
    /// Where it is: its place in the family's words, then its block as
    /// `label` names it.
    fn where_(&self, label: &dyn Fn(usize) -> String) -> String {
        match self.block {
            Some(b) if self.place.is_empty() => label(b),
            Some(b) => format!("{}, {}", self.place, label(b)),
            None => self.place.clone(),
        }
    }
}

/// One finding a family's judgement returned: something wrong that is not
/// a figure against a tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JudgedFinding {
    /// The rule it breaks.
    pub rule: String,
    /// What is wrong and what to change.
    pub message: String,
    /// The block (from 0) where it is, if at one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block: Option<usize>,
}

/// What a family's judgement of its replayed part returned.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Judged {
    /// Who judged (`scripts/cam_disc.rhai: fn judge(p, part)`).
    pub by: String,
    /// What it judged (`radius over angle at z = 0 mm`).
    pub replayed: String,
    /// How far (mm) the replay's last refinement moved what it found.
    pub sampling_change_mm: f64,
    /// Its figures.
    pub figures: Vec<JudgedFigure>,
    /// Its findings.
    #[serde(default)]
    pub findings: Vec<JudgedFinding>,
    /// Its tables (written with the family's own).
    #[serde(skip)]
    pub tables: Tables,
}

impl Judged {
    /// The verdict's figures and findings, the blocks named as `program`
    /// numbers them.
    pub fn verdict(&self, program: &AxisProgram) -> (Vec<Figure>, Vec<Finding>) {
        let name = |b: usize| crate::program::block_name(program, b);
        let mut figures = Vec::new();
        let mut findings = Vec::new();
        for f in &self.figures {
            let place = f.where_(&name);
            let mut figure = Figure::new(&f.name, f.value, f.tolerance, &f.unit, place.clone());
            if let Some(b) = f.block {
                figure = figure.at_block(b);
            }
            if f.value.abs() > f.tolerance || !f.value.is_finite() {
                let message = format!(
                    "{} is {} {} where {} {} is allowed{}{} ({})",
                    f.name,
                    fixed(f.value, 5),
                    f.unit,
                    fixed(f.tolerance, 5),
                    f.unit,
                    if place.is_empty() { "" } else { ", " },
                    place,
                    self.by
                );
                let finding = Finding::new(&f.name, message);
                findings.push(match f.block {
                    Some(b) => finding.at(b, name(b)),
                    None => finding,
                });
            }
            figures.push(figure);
        }
        for f in &self.findings {
            let finding = Finding::new(&f.rule, format!("{} ({})", f.message, self.by));
            findings.push(match f.block {
                Some(b) => finding.at(b, name(b)),
                None => finding,
            });
        }
        (figures, findings)
    }

    /// The run's summary of it: its worst figure against its tolerance.
    pub fn summary(&self) -> String {
        self.figures
            .iter()
            .max_by(|a, b| share(a).total_cmp(&share(b)))
            .map(|f| {
                format!(
                    ", {} {} {} (tolerance {})",
                    f.name,
                    fixed(f.value, 5),
                    f.unit,
                    fixed(f.tolerance, 5)
                )
            })
            .unwrap_or_default()
    }

    /// The page's section of it.
    fn html(&self, label: &dyn Fn(usize) -> String) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "<p>Judged by {} on {} (the replay's last refinement moved it {} um).</p>",
            escape(&self.by),
            escape(&self.replayed),
            fixed(self.sampling_change_mm * 1e3, 4)
        );
        out.push_str("<table><tr><th>figure</th><th>value</th><th>tolerance</th><th>unit</th><th>where</th></tr>\n");
        for f in &self.figures {
            let at = f.where_(label);
            row_at(
                &mut out,
                f.block,
                &[
                    escape(&f.name),
                    fixed(f.value, 5),
                    fixed(f.tolerance, 5),
                    escape(&f.unit),
                    escape(&at),
                ],
            );
        }
        out.push_str("</table>\n");
        for f in &self.findings {
            let at = f
                .block
                .map(|b| format!(" ({})", label(b)))
                .unwrap_or_default();
            let _ = writeln!(
                out,
                "<p class=\"fail\">{}: {}{}</p>",
                escape(&f.rule),
                escape(&f.message),
                escape(&at)
            );
        }
        out
    }
}

/// A figure's size as a share of its tolerance.
fn share(f: &JudgedFigure) -> f64 {
    if f.tolerance > 0.0 {
        f.value.abs() / f.tolerance
    } else {
        f64::INFINITY
    }
}

impl Outcome for Judged {
    fn key(&self) -> &'static str {
        KIND.key
    }

    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        serde_json::to_value(self)
    }

    fn findings(&self, program: &AxisProgram) -> (Vec<Figure>, Vec<Finding>) {
        self.verdict(program)
    }

    fn summary(&self) -> String {
        self.summary()
    }

    fn extend_tables(&self, tables: &mut Tables) {
        tables.extend(self.tables.clone());
    }
}

/// A family's judgement in `report.json` (`judged_verification`) and on
/// the page.
pub const KIND: OutcomeKind = OutcomeKind {
    key: "judged_verification",
    section,
};

/// The page's section of a judgement standing alone.
fn section(
    entry: &serde_json::Value,
    label: &dyn Fn(usize) -> String,
) -> Result<String, crate::family::DrawError> {
    let j: Judged = serde_json::from_value(entry.clone())?;
    Ok(format!(
        "<h2>Verification: the program replayed, judged by its family</h2>\n{}",
        j.html(label)
    ))
}

/// A built-in verification's outcome with the family's judgement beside
/// it: the built-in's key, report entry (with the judgement under
/// `judged`), files and section; the verdict holds both.
#[derive(Debug, Clone)]
pub struct WithJudged {
    /// The built-in verification's outcome.
    pub base: Box<dyn Outcome>,
    /// The family's judgement.
    pub judged: Judged,
}

/// The key under which a built-in verification's entry in `report.json`
/// carries the family's judgement.
pub const JUDGED_FIELD: &str = "judged";

impl Outcome for WithJudged {
    fn key(&self) -> &'static str {
        self.base.key()
    }

    fn to_json(&self) -> Result<serde_json::Value, serde_json::Error> {
        let mut v = self.base.to_json()?;
        let judged = self.judged.to_json()?;
        match v.as_object_mut() {
            Some(m) => {
                m.insert(JUDGED_FIELD.into(), judged);
                Ok(v)
            }
            None => Err(<serde_json::Error as serde::ser::Error>::custom(format!(
                "{}'s entry is not a map to add the family's judgement to",
                self.base.key()
            ))),
        }
    }

    fn findings(&self, program: &AxisProgram) -> (Vec<Figure>, Vec<Finding>) {
        let (mut figures, mut findings) = self.base.findings(program);
        let (f, g) = self.judged.verdict(program);
        figures.extend(f);
        findings.extend(g);
        (figures, findings)
    }

    fn summary(&self) -> String {
        format!("{}{}", self.base.summary(), self.judged.summary())
    }

    fn at_pose(
        &mut self,
        ctx: &ReplayContext<'_>,
        block: usize,
    ) -> Result<Option<crate::mesh::TriMesh>, crate::replay::VerifyError> {
        self.base.at_pose(ctx, block)
    }

    fn bodies(
        &self,
        mesh_tolerance: f64,
        step_tolerance: f64,
    ) -> Result<Vec<crate::family::PartBody>, crate::mesh::SceneError> {
        self.base.bodies(mesh_tolerance, step_tolerance)
    }

    fn leads_charts(&self) -> bool {
        self.base.leads_charts()
    }

    fn extend_tables(&self, tables: &mut Tables) {
        self.base.extend_tables(tables);
        self.judged.extend_tables(tables);
    }

    fn files(
        &self,
        ctx: &FilesContext<'_>,
        tables: &Tables,
    ) -> Result<crate::family::Drawn, crate::family::DrawError> {
        self.base.files(ctx, tables)
    }
}

/// The family's judgement in a built-in verification's page section: its
/// `judged` entry drawn after the built-in's own (empty where it has none).
pub fn judged_section(
    entry: &serde_json::Value,
    label: &dyn Fn(usize) -> String,
) -> Result<String, crate::family::DrawError> {
    match entry.get(JUDGED_FIELD) {
        None => Ok(String::new()),
        Some(j) => {
            let j: Judged = serde_json::from_value(j.clone())?;
            Ok(format!(
                "<h3>The family's own figures</h3>\n{}",
                j.html(label)
            ))
        }
    }
}
