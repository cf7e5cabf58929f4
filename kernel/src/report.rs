//! What a run reports: `report.json` ([`Report`]) and `report.csv` (a row
//! per block), with the program's cycle time and each axis's range; what a
//! failed run leaves ([`FailedRun`]). Below the run ([`crate::job`]) and
//! the page, which read it, and below [`crate::error`], which carries a
//! failed run.

use crate::family::Check;
use crate::machine::MachineInfo;
use crate::math::fixed;
use crate::params::ParamValue;
use crate::program::{block_label, label_in, AxisProgram};
use crate::toolpath::Motion;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A parameter's value as used, with its unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReportParam {
    /// The value.
    pub value: ParamValue,
    /// Its unit.
    pub unit: String,
    /// Where a value other than the family's default came from (`--set`,
    /// a parameter file, a run's report, a machine's constant); none for
    /// the default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<String>,
}

/// An input a run kept: `report.json`'s `inputs`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct KeptInput {
    /// What it is: `family` (the script), `table` (a table the script
    /// read), `machine` (a machine file or script), `plugin` (a machine
    /// library: its digest only).
    pub role: String,
    /// Its name among the run's files (a plugin: the library's file name
    /// as the run found it, not a file of the run).
    pub file: String,
    /// The SHA-256 of its bytes, in hexadecimal.
    pub sha256: String,
}

/// `report.json`: what a run did, with what, and what it found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// pilgrim's version.
    pub pilgrim: String,
    /// The family (its script's file).
    pub script: String,
    /// The machine's name.
    pub machine: String,
    /// The machine as it was named (the --machine given, or the family's
    /// default).
    pub machine_spec: String,
    /// The control's dialect.
    pub control: String,
    /// What corrected the run, where `pilgrim compensate` made it: the
    /// measurement's file, the generation, the gain and uncertainty, as
    /// the page's heading says it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corrected_by: Option<String>,
    /// The program file a verification read (`pilgrim verify`), as shown
    /// in messages; none for a run, whose program is its own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub program_file: Option<String>,
    /// Each block's `N` as the file a verification read numbers it; empty
    /// where the writer numbers the blocks ([`block_label`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub block_numbers: Vec<u32>,
    /// Every parameter's value as used, with its unit.
    pub parameters: BTreeMap<String, ReportParam>,
    /// Passes in all.
    pub passes: usize,
    /// Passes with a move other than a rapid.
    #[serde(default)]
    pub cutting_passes: usize,
    /// Toolpath points.
    pub points: usize,
    /// Program blocks.
    pub blocks: usize,
    /// Minutes the program runs, its moves ramped within the axes'
    /// acceleration ([`crate::timing`]; at the programmed feeds where the
    /// machine states no acceleration).
    pub cycle_time_min: f64,
    /// The files written.
    pub files: Vec<String>,
    /// The inputs the run kept beside its files, each with its digest
    /// (`job::kept`); empty for a run made before runs kept them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<KeptInput>,
    /// The family's checks.
    pub checks: Vec<Check>,
    /// The block (from 1) the 3-D scene places the tool at.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose_block: Option<usize>,
    /// How far through that block's move the tool stands (1: at its end;
    /// 0.5: halfway, where the block cuts a thread).
    #[serde(default = "at_end", skip_serializing_if = "is_at_end")]
    pub pose_along: f64,
    /// Chordal tolerance of the meshes (mm).
    pub mesh_tolerance_mm: f64,
    /// The bodies written as STL.
    #[serde(default)]
    pub bodies: Vec<BodyFile>,
    /// Largest deviation of a STEP solid's B-spline from the family's
    /// profile (mm).
    #[serde(default)]
    pub step_tolerance_mm: f64,
    /// The bodies written as exact solids (STEP).
    #[serde(default)]
    pub solids: Vec<SolidFile>,
    /// Each programmed axis's range over the program: [min, max] (mm, deg).
    #[serde(default)]
    pub axis_ranges: BTreeMap<String, [f64; 2]>,
    /// What the family's verification found, under its kind's key
    /// (`verification`, `groove_verification`, `thread_verification`: each
    /// family's own entry, [`crate::family::Outcome::to_json`]), at the top
    /// level of `report.json`.
    #[serde(flatten)]
    pub verifications: BTreeMap<String, serde_json::Value>,
    /// What the family warned of.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Figures the family noted.
    #[serde(default)]
    pub notes: BTreeMap<String, f64>,
    /// Tables the family reported (name to columns).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub tables: BTreeMap<String, BTreeMap<String, Vec<f64>>>,
    /// What the run found: passed, failed or not verified, every figure
    /// against its tolerance, what failed and where, what it warns of.
    #[serde(default)]
    pub verdict: crate::verdict::Verdict,
    /// The collision check: every pair's smallest clearance along the
    /// program; `None` where the run checked none (a refused program).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub collisions: Option<crate::collision::Collisions>,
    /// The program's times: at its programmed feeds and with the axes'
    /// acceleration, in all and per pass ([`crate::timing`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub times: Option<crate::timing::Times>,
    /// The page's marks over the verification's plots, by the plot's file
    /// name: each pass's line, the worst places ([`crate::chart::Marks`]).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub marks: BTreeMap<String, crate::chart::Marks>,
    /// The scene's animation keys for the page's player: each key's block
    /// (from 0) and time (s). Not in `report.json`: the run and the
    /// export make it with the scene.
    #[serde(skip)]
    pub playback: Vec<(usize, f32)>,
    /// The line (from 1) each block's move stands on in the program the
    /// page lists, as the lint read it ([`crate::program::lint::TextProgram`]).
    /// Not in `report.json`: the run and the export read it with the text.
    #[serde(skip)]
    pub program_lines: Vec<usize>,
    /// The runs of blocks a cycle, a loop or a subprogram's call made
    /// from the program's text, each with the lines it was read from.
    /// Not in `report.json`: the run and the export read it with the text.
    #[serde(skip)]
    pub program_expansions: Vec<crate::program::expansion::Expansion>,
}

impl Report {
    /// The label of block `index` (from 0) as the program numbers it.
    pub fn block_label(&self, index: usize) -> String {
        match self.block_numbers.get(index) {
            Some(n) => format!("N{n}"),
            None => block_label(&self.control, index),
        }
    }

    /// The parameters whose values are not the family's defaults, each
    /// with where it came from: `tolerance = 0.005 mm (--set)`.
    pub fn not_defaults(&self) -> Vec<String> {
        self.parameters
            .iter()
            .filter_map(|(k, p)| {
                let from = p.from.as_ref()?;
                let value = toml::Value::try_from(&p.value)
                    .map(|v| v.to_string())
                    .unwrap_or_default();
                let unit = if p.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", p.unit)
                };
                Some(format!("{k} = {value}{unit} ({from})"))
            })
            .collect()
    }

    /// The parameter values the run used, as a source a run or a
    /// verification takes (`label`: where they come from, for messages).
    ///
    /// # Failures
    /// A value TOML cannot hold (not finite).
    pub fn params_source(
        &self,
        label: &str,
    ) -> Result<crate::params::ParamSource, crate::params::ParamError> {
        self.params_source_text(label)
            .map_err(|message| crate::params::ParamError::Source {
                source_name: label.to_owned(),
                message,
            })
    }

    /// [`Self::params_source`], its failure as text.
    fn params_source_text(&self, label: &str) -> Result<crate::params::ParamSource, String> {
        let values: BTreeMap<&str, &ParamValue> = self
            .parameters
            .iter()
            .map(|(k, p)| (k.as_str(), &p.value))
            .collect();
        let text = toml::to_string(&values).map_err(|e| e.to_string())?;
        Ok(crate::params::ParamSource::Toml {
            label: label.to_owned(),
            text,
        })
    }

    /// The report of a run of `family` on `machine` (described by `info`,
    /// its constants as the run set them) with `values` (and where each
    /// came from), its `checks` made: what a run knows before its
    /// toolpath, the rest empty.
    pub fn of_run(
        family: &dyn crate::family::PartFamily,
        machine: &crate::catalog::OpenMachine,
        info: &MachineInfo,
        (values, origins): (&crate::params::Params, &BTreeMap<String, String>),
        checks: Vec<Check>,
    ) -> Self {
        Self {
            pilgrim: crate::version::VERSION.into(),
            script: family.name().to_owned(),
            machine: info.name.clone(),
            machine_spec: machine.spec.clone(),
            corrected_by: None,
            program_file: None,
            block_numbers: Vec::new(),
            control: info.control.clone(),
            parameters: family
                .params()
                .iter()
                .filter_map(|s| {
                    let value = values.get(&s.name)?.clone();
                    let from = (value != s.default)
                        .then(|| origins.get(&s.name).cloned())
                        .flatten();
                    Some((
                        s.name.clone(),
                        ReportParam {
                            value,
                            unit: s.unit.clone(),
                            from,
                        },
                    ))
                })
                .collect(),
            passes: 0,
            cutting_passes: 0,
            points: 0,
            blocks: 0,
            cycle_time_min: 0.0,
            files: Vec::new(),
            inputs: Vec::new(),
            checks,
            pose_block: None,
            pose_along: 1.0,
            mesh_tolerance_mm: 0.0,
            bodies: Vec::new(),
            step_tolerance_mm: 0.0,
            solids: Vec::new(),
            axis_ranges: BTreeMap::new(),
            verifications: BTreeMap::new(),
            warnings: Vec::new(),
            notes: BTreeMap::new(),
            tables: BTreeMap::new(),
            verdict: crate::verdict::Verdict::default(),
            collisions: None,
            times: None,
            marks: BTreeMap::new(),
            playback: Vec::new(),
            program_lines: Vec::new(),
            program_expansions: Vec::new(),
        }
    }
}

fn at_end() -> f64 {
    1.0
}

fn is_at_end(v: &f64) -> bool {
    *v == 1.0
}

/// Each programmed axis's range over the program: `[min, max]` in program
/// units.
pub fn axis_ranges(program: &AxisProgram) -> BTreeMap<String, [f64; 2]> {
    program
        .axes
        .iter()
        .filter_map(|a| {
            let col = program.column(&a.name)?;
            let lo = col.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = col.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            Some((a.name.clone(), [lo, hi]))
        })
        .collect()
}

/// `report.csv`: one row per block of the program, the start's and the
/// end's included: block number (from 1), the program's name for it
/// ([`block_label`]: `N570`), the pass (the last comment at or before it),
/// motion, axis values (the program's decimals; empty for an axis the
/// block keeps where it stands), feed; written by the `csv` crate (RFC
/// 4180, fields quoted where they need it), text cells as
/// [`crate::names::spreadsheet_text`] has them.
///
/// # Failures
/// The writer failing (it writes to memory).
pub fn block_table(program: &AxisProgram) -> Result<String, crate::family::DrawError> {
    block_table_text(program).map_err(|e| crate::family::DrawError::new("report.csv", e))
}

/// [`block_table`], its failure as text.
fn block_table_text(program: &AxisProgram) -> Result<String, String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec![
        "block".to_owned(),
        "label".into(),
        "pass".into(),
        "motion".into(),
    ];
    header.extend(
        program
            .axes
            .iter()
            .map(|a| format!("{} ({})", a.name, a.unit)),
    );
    header.push("feed (mm/min)".into());
    w.write_record(&header).map_err(|e| e.to_string())?;
    let decimals = program.decimals.unwrap_or(3);
    let mut pass = "";
    let mut ticker = crate::budget::Ticker::new("report.csv", 4096);
    for (i, b) in program.blocks.iter().enumerate() {
        ticker.tick().map_err(|e| e.to_string())?;
        if let Some(c) = &b.comment {
            pass = c;
        }
        let motion = match b.motion {
            Motion::Rapid => "rapid",
            Motion::Linear => "linear",
            Motion::Thread { .. } => "thread",
        };
        let mut row = vec![
            (i + 1).to_string(),
            label_in(&program.control, &program.blocks, i),
            crate::names::spreadsheet_text(pass),
            motion.to_owned(),
        ];
        row.extend(program.axes.iter().zip(&b.values).map(|(a, v)| {
            if b.keep.contains(&a.name) {
                String::new()
            } else {
                fixed(*v, decimals)
            }
        }));
        row.push(fixed(b.feed, 1));
        w.write_record(&row).map_err(|e| e.to_string())?;
    }
    let bytes = w.into_inner().map_err(|e| e.to_string())?;
    String::from_utf8(bytes).map_err(|e| e.to_string())
}

/// A body written to a file, for the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyFile {
    /// The body's name.
    pub name: String,
    /// `part`, `tool` or `machine`.
    pub kind: String,
    /// Its STL file.
    pub file: String,
    /// Triangles.
    pub triangles: usize,
    /// Enclosed volume (mm^3).
    pub volume_mm3: f64,
}

/// One STEP file a run wrote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolidFile {
    /// The body's name.
    pub name: String,
    /// `part` or `tool`.
    pub kind: String,
    /// Its STEP file.
    pub file: String,
    /// The solid's volume from its own section (mm^3).
    pub volume_mm3: f64,
    /// The largest deviation of its B-spline from the family's profile
    /// (mm); 0 for a section of lines and arcs, which is exact.
    pub deviation_mm: f64,
    /// Cubic Bezier segments its profile became (0 for lines and arcs); for
    /// a swept body, its faces across a section.
    pub segments: usize,
}

/// What a failed run leaves to look at: its report marked FAILED (with
/// the verdict: what failed, where, and every figure), `report.html`, the
/// plots and the scene at the place it failed, the data files; no program
/// a control could load. [`crate::error::Error::Failed`] carries it.
#[derive(Clone, PartialEq)]
pub struct FailedRun {
    /// The report.
    pub report: Report,
    /// Every file's name and bytes.
    pub files: Vec<(String, Vec<u8>)>,
}

impl std::fmt::Debug for FailedRun {
    /// What failed and the files' names (not their bytes: megabytes).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FailedRun")
            .field("failures", &self.report.verdict.message())
            .field(
                "files",
                &self
                    .files
                    .iter()
                    .map(|(n, _)| n.as_str())
                    .collect::<Vec<_>>(),
            )
            .finish()
    }
}
