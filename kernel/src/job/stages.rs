//! A run in stages, each a function of the one before with a typed
//! result: [`Run::plan`] (the machine as the parameters set it, the
//! family's checks, the toolpath), the program ([`Run::build`] of the
//! toolpath, or [`Run::read`] of a text), [`Run::check`] (the family's
//! verification, the process's rules, the collisions) and
//! [`Run::render`] (the scene, the report, the plots, the page).
//! [`super::run`] and [`super::verify`] are the same stages; only the
//! program's stage differs.

use super::{
    block_table, collisions, data_files, enter, failed_run, json, kept, post_all, report_json,
    JobOptions, JobOutput, STAGES,
};
use crate::catalog::OpenMachine;
use crate::error::Error;
use crate::family::{
    Check, FamilyError, FilesContext, Outcome, PartBody, PartFamily, ReplayContext,
};
use crate::judged::Tables;
use crate::machine::MachineKinematics;
use crate::mesh::TriMesh;
use crate::params::{ParamValue, Params};
use crate::program::post::Dialect;
use crate::program::{build, AxisProgram, ProgramPass};
use crate::render::{page, scene, solids};
use crate::report::Report;
use crate::toolpath::{PlotSpec, Toolpath};
use crate::verdict::{Finding, Verdict};
use std::collections::BTreeMap;

/// A run's files: each name with its bytes.
type Files = Vec<(String, Vec<u8>)>;

/// The part's bodies and their meshes, by name.
type Bodies = (Vec<PartBody>, Vec<(String, TriMesh)>);

/// The scene as the report gives it, its files and the playback's times
/// (block, seconds).
type Staged = (Shown, Files, Vec<(usize, f32)>);

/// What every stage reads: the family, the machine, the parameters (and
/// where each came from), the run's options, and the text of the program
/// to verify where the run verifies one.
pub(super) struct Run<'a> {
    /// The family.
    pub family: &'a dyn PartFamily,
    /// The machine as opened.
    pub machine: &'a OpenMachine,
    /// The parameters' values.
    pub values: &'a Params,
    /// Where each value came from.
    pub origins: &'a BTreeMap<String, String>,
    /// The run's options.
    pub options: &'a JobOptions,
    /// The program's text, where the run verifies one.
    pub text: Option<&'a str>,
}

/// The plan: the machine as the parameters set its constants, the
/// family's checks (all passed), its toolpath and the control's dialect.
pub(super) struct Plan {
    changed: Option<Box<dyn MachineKinematics>>,
    checks: Vec<Check>,
    toolpath: Toolpath,
    control: &'static Dialect,
}

/// The program: as built or as read; the program the verification
/// replays where it is not that one (the text a control reads, read
/// back); its passes; the posted programs (or why none); the data files;
/// the text's line of each block and what the reading expanded.
pub(super) struct Programmed {
    program: AxisProgram,
    read_back: Option<AxisProgram>,
    passes: Vec<ProgramPass>,
    posted: Result<Files, Error>,
    data: Files,
    lines: Vec<usize>,
    expansions: Vec<crate::program::expansion::Expansion>,
}

/// The material a verification leaves and the program's moves against
/// it, for the process's rules (`None`: the family's verification gives
/// no blank).
type Material<'p> = Option<(Box<dyn crate::process::Stock>, crate::process::Moves<'p>)>;

/// What the checks found: the verification's outcome, the verdict's
/// figures, failures and warnings, the part's bodies and meshes, the
/// machine's bodies placed, the collisions, the scene's block and what the
/// verification shows there, the files so far, and the tables and charts
/// the report will show (the family's and its verification's, with those a
/// caller adds: [`Checked::add`]).
pub(super) struct Checked {
    outcome: Option<Box<dyn Outcome>>,
    verified: bool,
    figures: Vec<crate::verdict::Figure>,
    failures: Vec<Finding>,
    warnings: Vec<Finding>,
    parts: Vec<PartBody>,
    meshes: Vec<(String, TriMesh)>,
    placement: crate::collision::Placement,
    collisions: crate::collision::Collisions,
    pose_place: scene::PosePlace,
    overlay: Option<TriMesh>,
    files: Files,
    /// Which of `files` are the programs (dropped if a failure comes
    /// after them).
    program_files: Vec<String>,
    tables: Tables,
    plots: Vec<PlotSpec>,
}

/// The scene's results for the report: the block it shows (from 1), the
/// bodies' files, the exact solids, the box the page's camera frames.
type Shown = (
    Option<usize>,
    Vec<scene::BodyFile>,
    Vec<solids::SolidFile>,
    Option<([f64; 3], [f64; 3])>,
);

impl Plan {
    /// The machine as the run uses it.
    fn kin<'a>(&'a self, machine: &'a OpenMachine) -> &'a dyn MachineKinematics {
        self.changed
            .as_deref()
            .unwrap_or_else(|| machine.kinematics.as_ref())
    }
}

impl Programmed {
    /// The program the verification replays.
    fn verified(&self) -> &AxisProgram {
        self.read_back.as_ref().unwrap_or(&self.program)
    }

    /// The program as built or read.
    pub(super) fn program(&self) -> &AxisProgram {
        &self.program
    }

    /// Its passes' blocks.
    pub(super) fn passes(&self) -> &[ProgramPass] {
        &self.passes
    }
}

impl Checked {
    /// The tables the report will show, so far.
    pub(super) fn tables(&self) -> &Tables {
        &self.tables
    }

    /// A caller's tables and charts of them, shown as the family's own (a
    /// compensated run's measured error, its fit and the correction): a
    /// table of a name already there is replaced.
    pub(super) fn add(&mut self, tables: Tables, plots: Vec<PlotSpec>) {
        self.tables.extend(tables);
        self.plots.extend(plots);
    }

    /// Adds figures and failures found after the checks (a corrected
    /// run's predicted part): they count in the verdict as the checks'.
    pub(super) fn judge(&mut self, figures: Vec<crate::verdict::Figure>, failures: Vec<Finding>) {
        self.figures.extend(figures);
        if !failures.is_empty() {
            // A run that failed writes no program a control could load.
            let programs = std::mem::take(&mut self.program_files);
            self.files.retain(|f| !programs.contains(&f.0));
        }
        self.failures.extend(failures);
    }
}

impl Run<'_> {
    /// `result`, the stages' outcome, as the run gives it: a run stopped by
    /// its time limit after its inputs were read leaves its report, FAILED,
    /// saying where it stopped (a caller's cancel asked for nothing more:
    /// no report).
    pub(super) fn stopped(&self, result: Result<JobOutput, Error>) -> Result<JobOutput, Error> {
        match result {
            Err(Error::OverTime(o)) if !o.cancelled => {
                let info = self.machine.kinematics.info();
                let message =
                    format!("{o}; nothing was verified (give it more time: --run-seconds)");
                let failed = vec![Finding::new("the run's time limit", message)];
                let mut report = Report::of_run(
                    self.family,
                    self.machine,
                    info,
                    (self.values, self.origins),
                    Vec::new(),
                );
                report.program_file = self.text.and(self.options.program_file.clone());
                report.verdict = Verdict::of(true, failed, Vec::new(), Vec::new());
                Err(failed_run(report, Vec::new(), None, self.listed()))
            }
            other => other,
        }
    }

    /// The family's contract broken: `message`, naming it.
    fn contract(&self, message: String) -> Error {
        Error::Family(FamilyError::Contract {
            family: self.family.name().to_owned(),
            message,
        })
    }

    /// The FAILED report of a run that stopped before its program was
    /// checked: every parameter, the checks, the program's file where it
    /// verifies one, and what `failed`.
    fn early_report(
        &self,
        plan_checks: Vec<Check>,
        info: &crate::machine::MachineInfo,
        failed: Vec<Finding>,
        verified: bool,
    ) -> Error {
        let mut report = Report::of_run(
            self.family,
            self.machine,
            info,
            (self.values, self.origins),
            plan_checks,
        );
        report.program_file = self.text.and(self.options.program_file.clone());
        report.verdict = Verdict::of(verified, failed, Vec::new(), Vec::new());
        failed_run(report, Vec::new(), None, self.listed())
    }

    /// The user's program a verification reads, its file's name and text:
    /// the page lists it whatever the verdict.
    fn listed(&self) -> Option<(&str, &str)> {
        match (self.text, &self.options.program_file) {
            (Some(text), Some(file)) => Some((file.as_str(), text)),
            _ => None,
        }
    }

    /// The machine with the constants the parameters set otherwise.
    fn machine_as_set(&self) -> Result<Option<Box<dyn MachineKinematics>>, Error> {
        let have = &self.machine.kinematics.info().constants;
        let overrides: Vec<(String, f64)> = (self.family.params().iter())
            .filter_map(|s| {
                let c = s.machine.as_ref()?;
                let have = *have.get(c)?;
                let want = match &self.values[&s.name] {
                    ParamValue::Bool(b) => f64::from(u8::from(*b)),
                    v => v.as_number()?,
                };
                (want != have).then(|| (c.clone(), want))
            })
            .collect();
        Ok(if overrides.is_empty() {
            None
        } else {
            Some(self.machine.kinematics.with_constants(&overrides)?)
        })
    }

    /// The plan: the machine as set, its bodies and axes checked against
    /// the parameters, the family's checks (a failed one ends the run with
    /// its report), the toolpath with the caller's tables and plots.
    pub(super) fn plan(&self, stage: &mut dyn FnMut(&str)) -> Result<Plan, Error> {
        let changed = self.machine_as_set()?;
        let kin = changed
            .as_deref()
            .unwrap_or_else(|| self.machine.kinematics.as_ref());
        let info = kin.info();
        super::body_places_agree(
            self.family,
            self.machine.kinematics.info(),
            info,
            self.values,
        )?;
        super::needed_axes_present(self.family, info, self.values)?;
        enter(stage, STAGES[0])?;
        let checks = self.family.checks(self.values)?;
        for c in &checks {
            for (what, t) in [("a check's name", &c.name), ("a check's detail", &c.detail)] {
                crate::names::check_text(what, t)
                    .map_err(|e| self.contract(format!("fn checks(p): {e}")))?;
            }
        }
        let failed: Vec<Finding> = (checks.iter().filter(|c| !c.ok))
            .map(|c| {
                Finding::new(
                    "the family's checks",
                    format!(
                        "{}: check failed: {} ({})",
                        self.family.name(),
                        c.name,
                        c.detail
                    ),
                )
            })
            .collect();
        if !failed.is_empty() {
            // Nothing to replay or draw: the report says which checks
            // failed, with every parameter.
            return Err(self.early_report(checks, info, failed, false));
        }
        enter(stage, STAGES[1])?;
        let toolpath = self.family.toolpath(self.values)?;
        enter(stage, STAGES[2])?;
        let control =
            crate::program::post::dialect(&info.control).ok_or_else(|| Error::UnknownControl {
                machine: info.name.clone(),
                control: info.control.clone(),
            })?;
        Ok(Plan {
            changed,
            checks,
            toolpath,
            control,
        })
    }

    /// The program built from the plan's toolpath, posted in the
    /// machine's dialect (and the others asked for) and read back as its
    /// control reads it, while a second thread writes the data files.
    pub(super) fn build(
        &self,
        plan: &Plan,
        stage: &mut dyn FnMut(&str),
    ) -> Result<Programmed, Error> {
        let kin = plan.kin(self.machine);
        let info = kin.info();
        let options = self.options;
        let mut program = build(&plan.toolpath, kin, &options.program_name)?;
        program.number = options.program_number.unwrap_or(0);
        let passes = crate::program::pass_blocks(&program, &plan.toolpath.passes);
        enter(stage, STAGES[3])?;
        let toolpath = &plan.toolpath;
        let (posted, data) = crate::budget::beside(
            || post_all(self.machine, info, &program, &options.also_post),
            || data_files(toolpath, &program),
        );
        let [toolpath_json, program_json, csv] = data?;
        let data = vec![
            ("toolpath.json".into(), toolpath_json),
            ("program.json".into(), program_json),
            ("report.csv".into(), csv),
        ];
        let (posted, read_back, lines, expansions) = match posted {
            Ok((files, read)) => (Ok(files), Some(read.program), read.lines, read.expansions),
            Err(e) => (Err(e), None, Vec::new(), Vec::new()),
        };
        Ok(Programmed {
            program,
            read_back,
            passes,
            posted,
            data,
            lines,
            expansions,
        })
    }

    /// The program of `text` read as the control reads it, its passes as
    /// the motion and its comments give them; a text the verification
    /// cannot take ends the run with its report, naming what was refused.
    pub(super) fn read(
        &self,
        plan: &Plan,
        text: &str,
        stage: &mut dyn FnMut(&str),
    ) -> Result<Programmed, Error> {
        let kin = plan.kin(self.machine);
        let info = kin.info();
        let refused_on = |message: String, line: Option<usize>| {
            self.early_report(
                plan.checks.clone(),
                info,
                vec![Finding::new("the program's text", message).on_line(line)],
                true,
            )
        };
        let refused = |message: String| refused_on(message, None);
        let frame = crate::program::frame(info);
        let dir = self.options.program_dir.clone();
        let beside = move |name: &str| crate::files::beside(dir.as_deref(), name);
        let crate::program::lint::TextProgram {
            program: read,
            lines,
            expansions,
            ..
        } = crate::program::lint::read_with(
            text,
            &frame,
            plan.control,
            &info.axes,
            self.options.offsets.as_ref(),
            Some(&beside),
            Some(&info.constants),
        )
        .map_err(|e| refused_on(e.to_string(), refused_line(&e, text)))?;
        // No more blocks than a run writes: the replays' work is bounded.
        crate::program::check_shape(&read).map_err(|m| refused(format!("the program: {m}")))?;
        let passes = crate::replay::passes_in(&read, kin, &plan.toolpath.tool.reference)
            .map_err(|e| refused(e.to_string()))?;
        enter(stage, STAGES[3])?;
        let data = vec![
            ("program.json".into(), json(&read)?),
            ("report.csv".into(), block_table(&read)?.into_bytes()),
        ];
        Ok(Programmed {
            program: read,
            read_back: None,
            passes,
            posted: Ok(Vec::new()),
            data,
            lines,
            expansions,
        })
    }
}

impl<'a> Run<'a> {
    /// The replay's context: the program the verification replays, on the
    /// machine as set, with the toolpath's tool, in its passes.
    fn replay_ctx<'b>(&'b self, plan: &'b Plan, made: &'b Programmed) -> ReplayContext<'b> {
        ReplayContext {
            family: self.family.name(),
            program: made.verified(),
            machine: plan.kin(self.machine),
            tool: &plan.toolpath.tool,
            passes: &made.passes,
        }
    }

    /// A verification's error as the run gives it: its contract broken is
    /// the family's.
    fn verify_error(&self, e: crate::replay::VerifyError) -> Error {
        match e {
            crate::replay::VerifyError::Contract(message) => self.contract(message),
            e => e.into(),
        }
    }

    /// The family's verification of the program (`None` where the family
    /// asks none), with the material it leaves and the program's moves
    /// against it (made once: the process's rules read them too). Passes
    /// found from a text's motion that never meet the material (a retract
    /// and a return at feed) cut nothing: the passes are regrouped and the
    /// verification is made again on those that cut.
    fn verification<'p>(
        &'p self,
        plan: &'p Plan,
        made: &mut Programmed,
        requested: Option<&crate::family::Verification>,
    ) -> Result<(Option<Box<dyn Outcome>>, Material<'p>), Error> {
        let verify = |made: &Programmed| match requested {
            None => Ok((None, None)),
            Some(r) => {
                let v = (r.verifier().verify(&self.replay_ctx(plan, made)))
                    .map_err(|e| self.verify_error(e))?;
                Ok::<_, Error>((Some(v.outcome), v.stock))
            }
        };
        let (outcome, stock) = verify(made)?;
        let Some(stock) = stock else {
            return Ok((outcome, None));
        };
        let kin = plan.kin(self.machine);
        let moves = crate::process::Moves::new(made.verified(), kin, &plan.toolpath.tool.reference)
            .map_err(|e| self.verify_error(e))?;
        let regrouped = match self.text {
            Some(_) => {
                let step = crate::process::ProcessLimits::of(kin.info()).rapid_clearance;
                let contact = crate::process::Contact::new(
                    &moves,
                    stock.as_ref(),
                    step.max(crate::process::LEAST_SUBSTEP),
                );
                crate::replay::regrouped(made.verified(), &made.passes, |b| contact.touches(b))
                    .map_err(|e| self.verify_error(e))?
            }
            None => None,
        };
        let Some(passes) = regrouped else {
            return Ok((outcome, Some((stock, moves))));
        };
        // The program is the same: only its passes changed.
        made.passes = passes;
        let (outcome, stock) = verify(made)?;
        Ok((outcome, stock.map(|s| (s, moves))))
    }

    /// What the run warns of before any check: the family's own warnings,
    /// its verification's (a nominal that strays from its source), and
    /// which of a family's parameter and a machine constant set a quantity.
    fn stated(&self, plan: &Plan, requested: Option<&crate::family::Verification>) -> Vec<Finding> {
        let mut warnings: Vec<Finding> = (plan.toolpath.warnings.iter())
            .map(|w| Finding::new("the family", w.clone()))
            .collect();
        warnings.extend(requested.iter().flat_map(|r| r.verifier().warnings()));
        warnings.extend(super::constants::stated(
            self.family.params(),
            self.values,
            self.origins,
            self.machine.kinematics.info(),
        ));
        warnings
    }

    /// The family's parameters that restate a machine constant, as
    /// (constant, parameter).
    fn restated(&self) -> Vec<(String, String)> {
        (self.family.params().iter())
            .filter_map(|p| Some((p.machine.clone()?, p.name.clone())))
            .collect()
    }

    /// The checks: the family's verification of the program as written,
    /// the part's bodies, the process's rules over the material the
    /// verification knows and the collisions along the whole program, the
    /// scene's block and what the verification shows there, the programs
    /// (none where anything failed).
    pub(super) fn check(&self, plan: &Plan, made: &mut Programmed) -> Result<Checked, Error> {
        if self.options.pose_block == Some(0) {
            return Err(Error::BlockFromOne {
                option: "--pose-block",
            });
        }
        let requested = self.family.verification(self.values)?;
        let (outcome, material) = self.verification(plan, made, requested.as_ref())?;
        let (mut figures, mut failures) = match &outcome {
            Some(o) => o.findings(made.verified()),
            None => (Vec::new(), Vec::new()),
        };
        let mut warnings = self.stated(plan, requested.as_ref());
        let (parts, meshes) = self.bodies(outcome.as_deref())?;
        let kin = plan.kin(self.machine);
        let info = kin.info();
        let tol = self.options.mesh_tolerance;
        let tool = &plan.toolpath.tool;
        let restated = self.restated();
        // One placement of the machine's bodies for the check and the scene.
        let placement = scene::placement(kin, &made.program, &plan.toolpath, &meshes)?;
        // The process, checked as well as the geometry; and, on a second
        // thread, the machine's bodies, the tool and the part clear of each
        // other along the whole program (neither reads the other).
        let (process, collisions) = crate::budget::beside(
            || {
                let limits = crate::process::ProcessLimits::of(kin.info());
                match &material {
                    Some((stock, moves)) => {
                        crate::process::check_on(made.verified(), moves, stock.as_ref(), &limits)
                    }
                    None => {
                        crate::process::check(made.verified(), kin, &tool.reference, None, &limits)
                    }
                }
            },
            || {
                collisions(
                    made.verified(),
                    info,
                    &placement,
                    tool,
                    &meshes,
                    tol,
                    &restated,
                )
            },
        );
        let (process, collisions) = (process?, collisions?);
        failures.extend(process.errors);
        warnings.extend(process.warnings);
        figures.extend(process.figures);
        if material.is_none() {
            warnings.push(Finding::new(
                "the process",
                "the rules that need the material (rapids through air only, into the stock at the infeed feed, the steady rest's approach, the finishing stock) were not checked: the family's verification gives no blank",
            ));
        }
        failures.extend(collisions.findings.iter().cloned());
        let mut checked = Checked {
            verified: requested.is_some(),
            figures,
            failures,
            warnings,
            parts,
            meshes,
            placement,
            collisions,
            pose_place: scene::PosePlace::at_end(0),
            overlay: None,
            files: Vec::new(),
            program_files: Vec::new(),
            tables: Self::tables(plan, outcome.as_deref()),
            plots: Vec::new(),
            outcome,
        };
        self.pose_and_programs(plan, made, &mut checked)?;
        Ok(checked)
    }

    /// The tables the report will show: the toolpath's, then its
    /// verification's.
    fn tables(plan: &Plan, outcome: Option<&dyn Outcome>) -> Tables {
        let mut tables = plan.toolpath.tables.clone();
        if let Some(o) = outcome {
            o.extend_tables(&mut tables);
        }
        tables
    }

    /// The part's bodies (the family's, with those its verification made:
    /// the finished worm) and their meshes.
    fn bodies(&self, outcome: Option<&dyn Outcome>) -> Result<Bodies, Error> {
        let mut parts = self.family.part(self.values)?;
        if let Some(b) = parts.iter().find(|b| !crate::files::is_plain_name(&b.name)) {
            return Err(self.contract(format!(
                "fn part(p): the body name '{}' is not a plain name (letters, digits, _ or -, at most 64): it becomes a file name",
                crate::files::excerpt(&b.name)
            )));
        }
        let tol = self.options.mesh_tolerance;
        if let Some(o) = outcome {
            parts.extend(o.bodies(tol, self.options.step_tolerance)?);
        }
        let meshes = scene::part_meshes(&parts, tol).map_err(|source| Error::Part {
            family: self.family.name().to_owned(),
            source,
        })?;
        Ok((parts, meshes))
    }

    /// The scene's block (where asked; a failed run's, where it failed;
    /// else the middle of the last cutting pass) and what the verification
    /// shows there (the caliber's contact patch); the programs a run that
    /// passed writes, after the JSON files, the block table after them.
    fn pose_and_programs(
        &self,
        plan: &Plan,
        made: &mut Programmed,
        c: &mut Checked,
    ) -> Result<(), Error> {
        c.pose_place = match (
            self.options.pose_block,
            c.failures.iter().find_map(|f| f.block_index),
        ) {
            (Some(n), _) => scene::PosePlace::at_end(n - 1),
            (None, Some(b)) => scene::PosePlace::at_end(b - 1),
            (None, None) => scene::default_pose_block(made.verified(), &made.passes),
        };
        let ctx = self.replay_ctx(plan, made);
        c.overlay = match &mut c.outcome {
            Some(o) => o
                .at_pose(&ctx, c.pose_place.block)
                .map_err(|e| self.verify_error(e))?,
            None => None,
        };
        // A run that failed writes no program a control could load.
        let programs = match std::mem::replace(&mut made.posted, Ok(Vec::new())) {
            Ok(_) if !c.failures.is_empty() => Vec::new(),
            Ok(p) => p,
            // A program that does not read back as the axis program (a
            // plugin's own post, a block its dialect cannot write): no
            // program, the report says why.
            Err(e @ (Error::Lint(_) | Error::Post(_))) => {
                c.failures
                    .push(Finding::new("the program's text", e.to_string()));
                Vec::new()
            }
            Err(e) => return Err(e),
        };
        let (table, mut files): (Vec<_>, Vec<_>) = std::mem::take(&mut made.data)
            .into_iter()
            .partition(|f| f.0 == "report.csv");
        c.program_files = programs.iter().map(|p| p.0.clone()).collect();
        files.extend(programs);
        files.extend(table);
        c.files = files;
        Ok(())
    }
}

impl Run<'_> {
    /// The run's outputs from what the checks found: the scene and its
    /// solids, the report, the
    /// verification's files, the family's charts, the kept inputs, the
    /// page; a run that failed ends with its report and no program.
    pub(super) fn render(
        &self,
        plan: Plan,
        made: Programmed,
        mut c: Checked,
        stage: &mut dyn FnMut(&str),
    ) -> Result<JobOutput, Error> {
        enter(stage, STAGES[4])?;
        let kin = plan.kin(self.machine);
        // The times of the program as its control reads it (feeds and
        // positions as written), as every other check takes it.
        let times = crate::timing::times(made.verified(), kin.info(), &made.passes);
        let scene = self.scene(&plan, &made, &c, &times.block_s);
        let (shown, scene_files, playback) = scene?;
        c.files.extend(scene_files);
        let part_box = shown.3;
        let mut report = self.report(&plan, &made, &mut c, shown, times)?;
        report.playback = playback;
        let later = self.verification_files(&plan, &made, &mut c, &mut report)?;
        let plots = std::mem::take(&mut c.plots);
        self.charts(&plan, &plots, later, &mut c.files, &mut report)?;
        crate::budget::check("the report")?;
        self.keep(&mut c.files, &mut report)?;
        if report.verdict.failed() {
            return Err(failed_run(report, c.files, part_box, self.listed()));
        }
        let mut files = c.files;
        report.files.push("report.html".into());
        // The page lists the program the run wrote, or the file it verified.
        let listed = self
            .listed()
            .or_else(|| page::written_program(&files, plan.control.extension));
        let html = page::page_of(&report, &files, listed, part_box);
        files.push(("report.html".into(), html.into_bytes()));
        files.push(("report.json".into(), report_json(&report)?));
        Ok(JobOutput {
            params: self.values.clone(),
            toolpath: plan.toolpath,
            program: made.program,
            outcome: c.outcome,
            report,
            files,
        })
    }

    /// The scene at its block (the tool, the machine's bodies, the part,
    /// what the verification shows there) and, for a run that passed, the
    /// exact solids: what the report says of them, their files, the
    /// playback's times.
    fn scene(
        &self,
        plan: &Plan,
        made: &Programmed,
        c: &Checked,
        block_s: &[f64],
    ) -> Result<Staged, Error> {
        if c.parts.is_empty() {
            return Ok(((None, vec![], vec![], None), Vec::new(), Vec::new()));
        }
        let tool = &plan.toolpath.tool;
        let tol = self.options.mesh_tolerance;
        // The part's extent: the page's camera frames its contact with
        // the tool.
        let part_box = scene::bounds_of(c.meshes.iter().map(|(_, m)| m));
        let overlays = (c.overlay.clone())
            .map(|m| ("contact_patch".to_owned(), m, crate::math::Mat4::identity()))
            .into_iter()
            .collect();
        let staged = scene::stage(
            plan.kin(self.machine),
            &made.program,
            tool,
            (&c.meshes, &c.placement),
            c.pose_place,
            block_s,
            overlays,
            (tol, self.options.formats),
        )?;
        let mut files = staged.files;
        // A failed run's scene shows where it failed; its exact solids,
        // for checking a program in CAD, would check none.
        let solids = if c.failures.is_empty() {
            let (step_files, solids) =
                solids::step_files(&c.parts, tool, &staged.pose, self.options.step_tolerance)?;
            files.extend(step_files);
            solids
        } else {
            Vec::new()
        };
        let framed = part_box.map(|b| scene::contact_box(b, tool, &staged.pose));
        let shown = (Some(c.pose_place.block + 1), staged.bodies, solids, framed);
        Ok((shown, files, staged.playback))
    }
}

impl Run<'_> {
    /// The report of what the run made and found.
    fn report(
        &self,
        plan: &Plan,
        made: &Programmed,
        c: &mut Checked,
        (pose_block, bodies, solids, _): Shown,
        times: crate::timing::Times,
    ) -> Result<Report, Error> {
        let toolpath = &plan.toolpath;
        let program = &made.program;
        let info = plan.kin(self.machine).info();
        let verdict = Verdict::of(
            c.verified,
            std::mem::take(&mut c.failures),
            std::mem::take(&mut c.warnings),
            std::mem::take(&mut c.figures),
        );
        Ok(Report {
            corrected_by: self.options.corrected_by.as_ref().map(|c| c.said.clone()),
            passes: made.passes.len(),
            cutting_passes: made.passes.iter().filter(|p| p.cuts).count(),
            points: toolpath.point_count(),
            blocks: program.blocks.len(),
            cycle_time_min: (times.accelerated_min * 1e4).round() / 1e4,
            files: (c.files.iter().map(|f| f.0.clone()))
                .chain(["report.json".to_owned()])
                .collect(),
            pose_block,
            pose_along: pose_block.map_or(1.0, |_| c.pose_place.along),
            mesh_tolerance_mm: self.options.mesh_tolerance,
            bodies,
            step_tolerance_mm: self.options.step_tolerance,
            solids,
            axis_ranges: super::axis_ranges(program),
            verifications: match &c.outcome {
                Some(o) => self.entry(o.as_ref())?,
                None => Default::default(),
            },
            warnings: toolpath.warnings.clone(),
            notes: toolpath.notes.clone(),
            tables: std::mem::take(&mut c.tables),
            verdict,
            collisions: Some(c.collisions.clone()),
            times: Some(times),
            program_file: self.text.and(self.options.program_file.clone()),
            program_lines: made.lines.clone(),
            program_expansions: made.expansions.clone(),
            block_numbers: (program.blocks.iter().map(|b| b.number))
                .collect::<Option<Vec<u32>>>()
                .unwrap_or_default(),
            ..Report::of_run(
                self.family,
                self.machine,
                info,
                (self.values, self.origins),
                plan.checks.clone(),
            )
        })
    }

    /// The verification's entry in the report, under its key: a key among
    /// the report's own fields must name a verification and be plain.
    fn entry(&self, o: &dyn Outcome) -> Result<BTreeMap<String, serde_json::Value>, Error> {
        let key = o.key();
        if !(key.ends_with("verification") && crate::files::is_plain_name(key)) {
            return Err(self.contract(format!(
                "its verification's report key {} must be a plain name ending in 'verification'",
                crate::names::quoted(key)
            )));
        }
        let value = o
            .to_json()
            .map_err(|e| crate::family::DrawError::new(key, e))?;
        Ok(std::iter::once((key.to_owned(), value)).collect())
    }

    /// The verification's own files (tables, plots) and the marks over its
    /// plots: those that lead the family's charts (the worm's) added to
    /// the run's now, the others returned to follow the charts. A name
    /// that is the run's own is refused.
    fn verification_files(
        &self,
        plan: &Plan,
        made: &Programmed,
        c: &mut Checked,
        report: &mut Report,
    ) -> Result<Files, Error> {
        let Some(o) = &c.outcome else {
            return Ok(Vec::new());
        };
        let leads = o.leads_charts();
        let ctx = FilesContext {
            replay: self.replay_ctx(plan, made),
            parts: &c.parts,
            corrected: self.options.corrected_by.as_ref().map(|c| c.generation),
        };
        let crate::family::Drawn { files: made, marks } = o.files(&ctx, &report.tables)?;
        // Marks over a plot it drew, by the plot's name.
        report.marks = marks
            .into_iter()
            .filter(|(name, _)| name.ends_with(".svg") && made.iter().any(|f| &f.0 == name))
            .collect();
        // A verification draws and tabulates; the programs, the report and
        // the data files are the run's own, and every name is a file's.
        if let Some((name, _)) = made.iter().find(|(n, _)| {
            !crate::output::is_plain_file_name(n)
                || n.starts_with("program.")
                || n.starts_with("report.")
                || c.files.iter().any(|f| &f.0 == n)
        }) {
            return Err(self.contract(format!(
                "its verification's file {} is not a name it may write: the programs, the report and the data files are the run's own",
                crate::names::quoted(name)
            )));
        }
        if !leads {
            return Ok(made);
        }
        for (name, bytes) in made {
            report.files.push(name.clone());
            c.files.push((name, bytes));
        }
        Ok(Vec::new())
    }

    /// The family's charts (its plots and those the caller added),
    /// between the verification's files that lead them (`c.files` has
    /// them) and those that follow (`later`).
    fn charts(
        &self,
        plan: &Plan,
        finishing: &[crate::toolpath::PlotSpec],
        later: Files,
        files: &mut Files,
        report: &mut Report,
    ) -> Result<(), Error> {
        let charted = Toolpath {
            tables: report.tables.clone(),
            ..plan.toolpath.clone()
        };
        for plot in plan.toolpath.plots.iter().chain(finishing) {
            // A program read from a file draws what its own tables hold:
            // the plan's columns do not describe it.
            let mut plot = plot.clone();
            if self.text.is_some() {
                let table = charted.tables.get(&plot.table);
                let has = |c: &str| table.is_some_and(|t| t.contains_key(c));
                plot.y.retain(|c| has(c));
                if !has(&plot.x) || plot.y.is_empty() {
                    report.checks.push(crate::family::Check {
                        name: format!("plot {}", plot.file),
                        ok: true,
                        detail: "not drawn: its columns are the plan's, which a program read from a file does not follow".into(),
                    });
                    continue;
                }
            }
            let generation = self.options.corrected_by.as_ref().map(|c| c.generation);
            plot.title = crate::chart::titled(&plot.title, generation);
            let plot = &plot;
            let text = crate::chart::chart_svg(&charted, plot)
                .map_err(|message| self.contract(message))?;
            let name = format!("{}.svg", plot.file);
            if files.iter().chain(&later).any(|f| f.0 == name) {
                return Err(self.contract(format!(
                    "plot {}: a file of that name is written already",
                    plot.file
                )));
            }
            files.push((name.clone(), text.into_bytes()));
            report.files.push(name);
        }
        for (name, bytes) in later {
            report.files.push(name.clone());
            files.push((name, bytes));
        }
        Ok(())
    }

    /// The run's inputs kept beside its files, where the caller asks.
    fn keep(&self, files: &mut Files, report: &mut Report) -> Result<(), Error> {
        let Some(keep) = &self.options.keep else {
            return Ok(());
        };
        let taken: Vec<String> = (report.files.iter().cloned())
            .chain(["report.html".into(), "report.json".into()])
            .collect();
        for (input, bytes) in kept::inputs(keep, &self.machine.origin, &taken)? {
            if input.role != "plugin" {
                report.files.push(input.file.clone());
                files.push((input.file.clone(), bytes));
            }
            report.inputs.push(input);
        }
        Ok(())
    }
}

/// The line (from 1) of the program's own `text` a reading's refusal `e`
/// stands on: its `line N`, or the first line whose block is its `N`;
/// none where it is in another file or names no place of the text.
fn refused_line(e: &crate::program::lint::LintError, text: &str) -> Option<usize> {
    let place = e.place.split(" in ").next().unwrap_or("");
    if place.contains(" of ") {
        return None;
    }
    if let Some(n) = place.strip_prefix("line ") {
        return n.parse().ok();
    }
    let n = place
        .strip_prefix('N')
        .filter(|n| n.bytes().all(|b| b.is_ascii_digit()))?;
    text.lines()
        .position(|l| {
            l.split_whitespace()
                .next()
                .and_then(|w| w.strip_prefix('N'))
                .is_some_and(|w| w.trim_start_matches('0') == n.trim_start_matches('0'))
        })
        .map(|i| i + 1)
}

#[cfg(test)]
mod tests {
    use super::refused_line;
    use crate::program::lint::LintError;

    /// A refusal's line: its `line N`, or the line its `N` opens; none in
    /// a subprogram's file or where the text has no such block.
    #[test]
    fn a_refusal_is_placed_on_its_line() {
        let text = "%\nO0001\nN10 G00 X1.\nN020 G01 Z2.\n%\n";
        let at = |place: &str| {
            refused_line(
                &LintError {
                    what: "reading",
                    dialect: "fanuc".into(),
                    place: place.into(),
                    message: String::new(),
                },
                text,
            )
        };
        assert_eq!(at("line 2"), Some(2));
        assert_eq!(at("N10"), Some(3));
        assert_eq!(at("N20 in \"pass 1\""), Some(4));
        assert_eq!(at("N10 of O2000"), None);
        assert_eq!(at("N99"), None);
    }
}
