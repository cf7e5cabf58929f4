//! The family of bodies of revolution ground with a wheel and a steady
//! rest: the cold-pilger mandrel, and any drawing plug or shaft a script
//! describes. Its pieces, one folder:
//!
//! - [`surface`]: the surface the passes leave, the wheel's true section
//!   (flat and roundings) on each generatrix, and [`phases`]: the crest
//!   over every spindle phase the program leaves open;
//! - [`rest`]: the steady rest riding that surface (U at every block and
//!   between blocks), the seed's formula beside it;
//! - the replay (this module, each pass in `grinding`): [`check_grinding`] reads a grinding program
//!   as a control does (its values as written, [`as_written`]), replays
//!   every block through the machine's forward kinematics, and simulates
//!   what the machine makes of it: the part turning while the wheel moves
//!   in straight lines between blocks, the wheel's section where each of
//!   generatrices (doubled from 16 until the finish stands to 0.1 um) meets it. Each pass's surface is
//!   compared with the nominal profile, the helical ridge included, and
//!   the worst place is named by z, block and pass;
//! - its outcome in the report ([`GrindingOutcome`]), its plots
//!   ([`profile_svg`], [`deviation_svgs`]) and its script bindings.
//!
//! The profile law of a mandrel (`profile::MandrelLaw`) stays with the
//! profiles (the profile builder's `law` segment uses it). The replay's
//! generic machinery (the program as written, forward kinematics block by
//! block, its passes, [`VerifyError`]) is [`crate::replay`]'s, re-exported
//! here.

use crate::machine::MachineKinematics;
use crate::math::Real;
use crate::offset::CapsuleEnvelope;
use crate::profile::Profile;
use crate::program::{AxisProgram, ProgramPass};
use crate::tool::Wheel;
use crate::transform::ToolFrame;
use crate::verdict::{Figure, Finding};
use serde::{Deserialize, Serialize};
use surface::{GroundSurface, PartLayer, GENERATRICES};

/// The most the finish's worst may move when the generatrices double for
/// the sampling to stand (mm): 0.1 um.
pub const SAMPLING_STEP: Real = 1e-4;

/// The most generatrices a replay doubles to; a finish whose worst still
/// moves there is reported with its last change.
pub const MAX_GENERATRICES: usize = 128;

pub use crate::replay::{as_written, passes_in, replay, replay_blocks, VerifyError};
pub use plots::deviation_svgs;
pub use profile_svg::profile_svg;

mod grinding;
mod outcome;
pub mod phases;
mod plots;
mod profile_svg;
pub mod rest;
mod script;
pub mod surface;

pub use outcome::{GrindingOutcome, KIND};
pub(crate) use script::SCRIPT_API;

/// How far a surface strays from the nominal profile over a range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Deviation {
    /// The most material left above the profile (mm, >= 0 where any).
    pub max_above: Real,
    /// Where (z).
    pub above_z: Real,
    /// The deepest cut below the profile (mm, <= 0 where any: a gouge).
    pub max_below: Real,
    /// Where (z).
    pub below_z: Real,
    /// The largest of the two in size (mm).
    pub max_abs: Real,
    /// Where the largest is (z).
    pub at_z: Real,
    /// The block (from 1, the program's and `report.csv`'s count) whose
    /// move forms the surface there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block: Option<usize>,
}

/// One cutting pass's surface against the nominal profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PassCheck {
    /// The pass's name.
    pub name: String,
    /// Its first block (from 1).
    pub first_block: usize,
    /// Its cutting feed (mm/min).
    pub feed_mm_min: Real,
    /// The spindle speed it ran at (rpm).
    pub spindle_rpm: Real,
    /// The feed per revolution of the part, `F / S` (mm).
    pub feed_per_rev_mm: Real,
    /// The ridge the wheel leaves at that feed on a straight generatrix
    /// (mm), `R_s - sqrt(R_s^2 - ((f - flat)/2)^2)`.
    pub ridge_mm: Real,
    /// Its surface against the nominal, over every generatrix simulated
    /// (blocks from 1): ridges included.
    pub deviation: Deviation,
    /// How far the highest surface any spindle phase leaves (what the
    /// steady rest rides on: [`crate::families::revolution::phases`]) stands above the
    /// highest generatrix simulated, after this pass (mm): the stand-off
    /// the spindle's unknown phase allows the rest.
    pub phase_stand_off_mm: Real,
    /// Where it is largest (z).
    pub phase_stand_off_z: Real,
    /// The most it removed under the wheel's path (mm): the surface
    /// before it (the pass before's, or the blank's) less the one it
    /// leaves, at the valleys; none where there is no blank.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub removed_mm: Option<Real>,
    /// The most it leaves above the nominal at the valleys between its
    /// ridges (mm): the stock for the next pass.
    #[serde(default)]
    pub left_mm: Real,
    /// The stretches of z `[from, to]` (mm) of the range checked that
    /// neither this pass nor any before it has ground: not judged, and
    /// said where it is the finish.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub uncovered: Vec<[Real; 2]>,
    /// Its surface minus the nominal along z, for drawing: `[z, lowest,
    /// highest]` over the generatrices, in at most [`PROFILE_BUCKETS`]
    /// stretches of z (each the extremes within it, so no ridge is lost).
    #[serde(skip)]
    pub along_z: Vec<[Real; 3]>,
    /// What would bring the finish within the tolerance, where the replay
    /// can tell (the finishing pass only): a feed whose ridges it holds, a
    /// path for the wheel's flat.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub to_change: Vec<String>,
    /// Its surface in each stretch the nominal tolerances on its own
    /// ([`crate::profile::Band`]), which its deviation leaves out.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bands: Vec<BandCheck>,
}

/// A pass's surface in a stretch with its own band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandCheck {
    /// The band: its stretch, its half-width on the radius and where the
    /// drawing gives it.
    pub band: crate::profile::Band,
    /// The most material left above the nominal there (mm).
    pub max_above: Real,
    /// The deepest cut below it there (mm, <= 0 where any).
    pub max_below: Real,
    /// Where the larger of the two in size is (z).
    pub at_z: Real,
}

impl BandCheck {
    /// The larger of its deviations in size, signed (mm).
    pub fn worst(&self) -> Real {
        if self.max_above >= -self.max_below {
            self.max_above
        } else {
            self.max_below
        }
    }

    /// Its failure, if the surface leaves the band.
    pub fn failure(&self) -> Option<String> {
        let w = self.worst();
        (w.abs() > self.band.half).then(|| {
            format!(
                "the finished surface strays {} mm from the nominal at z = {} mm, beyond its own band of ±{} mm on the radius ({})",
                crate::math::fixed(w, 5),
                crate::math::fixed(self.at_z, 3),
                crate::math::fixed(self.band.half, 5),
                self.band.source
            )
        })
    }
}

/// The most stretches of z a pass's deviation is kept in for drawing.
pub const PROFILE_BUCKETS: usize = 1500;

/// `values` (`z`, per generatrix lowest and highest) in at most `n`
/// stretches of equal length in z, each its middle and the extremes in it.
fn bucketed(zs: &[Real], lo: &[Real], hi: &[Real], n: usize) -> Vec<[Real; 3]> {
    let (Some(&z0), Some(&z1)) = (zs.first(), zs.last()) else {
        return Vec::new();
    };
    let width = ((z1 - z0) / n as Real).max(Real::MIN_POSITIVE);
    let mut out: Vec<[Real; 3]> = Vec::new();
    let mut current: Option<(usize, [Real; 3])> = None;
    for ((&z, &l), &h) in zs.iter().zip(lo).zip(hi) {
        let k = (((z - z0) / width) as usize).min(n - 1);
        match &mut current {
            Some((c, b)) if *c == k => {
                b[1] = b[1].min(l);
                b[2] = b[2].max(h);
            }
            _ => {
                if let Some((_, b)) = current.take() {
                    out.push(b);
                }
                current = Some((k, [z0 + (k as Real + 0.5) * width, l, h]));
            }
        }
    }
    out.extend(current.map(|(_, b)| b));
    out
}

/// A grinding program replayed: each cutting pass's surface against the
/// nominal profile; the last one must hold the tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GrindingCheck {
    /// The tolerance held (mm).
    pub tolerance: Real,
    /// The generatrices each pass was simulated on: doubled from
    /// [`GENERATRICES`] until the finish's worst moves by less than
    /// [`SAMPLING_STEP`] between half of them and all, or
    /// [`MAX_GENERATRICES`].
    pub generatrices: usize,
    /// How far the finish's worst (its largest deviation in size) moved
    /// from half the generatrices to all (mm).
    #[serde(default)]
    pub sampling_change_mm: Real,
    /// The smallest step the program's values carry (mm), which the replay
    /// reads them at.
    pub resolution_mm: Real,
    /// Each cutting pass (the last is the finish).
    pub passes: Vec<PassCheck>,
}

/// Replays a grinding program as the machine runs it (docs/math.md §2.4): the
/// values rounded as written, every axis moving in a straight line between
/// blocks at the block's feed while the part turns at the program's
/// spindle speed; on each generatrix (16, doubled while the finish's worst moves by
/// 0.1 um or more, up to [`MAX_GENERATRICES`]) the wheel's true
/// section (its flat and roundings; its tracked point is the middle of the
/// flat) left at the moments it passed under the wheel, cut into the
/// surface the passes before left on that generatrix (into `blank`, where
/// given, before the first); each cutting pass's surface, ridges included,
/// against `nominal` over `[from, to]`, the worst generatrix counting.
/// `passes` are the program's ([`crate::program::pass_blocks`] of the
/// toolpath it was built from, or as its text groups them).
///
/// # Failures
/// A tolerance finer than twice the program's resolution; the replay
/// failing; a pass that does not cover the range; no cutting pass. The
/// finishing pass straying more than `tolerance` from the nominal is the
/// check's own finding ([`GrindingCheck::failure`], naming the deviation,
/// its z, the block and the pass with its feed).
#[allow(clippy::too_many_arguments)]
pub fn check_grinding(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    wheel: &Wheel,
    passes: &[ProgramPass],
    nominal: &Profile,
    blank: Option<&Profile>,
    range: (Real, Real),
    tolerance: Real,
) -> Result<GrindingCheck, VerifyError> {
    replay_grinding(
        program, machine, tool, wheel, passes, nominal, blank, range, tolerance,
    )
    .map(|(check, _)| check)
}

/// [`check_grinding`], and the material as the replay cut it
/// ([`GroundStock`], for the process's rules) where the family gives the
/// blank.
///
/// # Failures
/// As [`check_grinding`].
#[allow(clippy::too_many_arguments)]
pub fn replay_grinding(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    wheel: &Wheel,
    passes: &[ProgramPass],
    nominal: &Profile,
    blank: Option<&Profile>,
    range: (Real, Real),
    tolerance: Real,
) -> Result<(GrindingCheck, Option<GroundStock>), VerifyError> {
    // Every other generatrix of `m` is one of `m / 2`: one replay on `m`
    // says how far doubling from `m / 2` moved the finish's worst.
    let mut m = 2 * GENERATRICES;
    loop {
        let (mut check, stock, half) = grinding::replay_on(
            program, machine, tool, wheel, passes, nominal, blank, range, tolerance, m,
        )?;
        let worst = check.passes.last().map_or(0.0, |p| p.deviation.max_abs);
        check.sampling_change_mm = (worst - half).abs();
        if check.sampling_change_mm < SAMPLING_STEP || m >= MAX_GENERATRICES {
            return Ok((check, stock));
        }
        m *= 2;
    }
}

/// The spacing of [`GroundStock`]'s grid along z (mm): the wheel's and the
/// rest's footprints are sampled this finely.
pub const STOCK_STEP: Real = 0.05;

/// The material of a body of revolution as the grinding replay cut it, for
/// the process's rules ([`crate::process`]): on a grid along z, the surface
/// the part has before each cutting pass and after the last (the highest of
/// the generatrices: what a wheel or a rest meets first), the blank
/// lowered by each pass's sweep; the wheel's section; what each pass cut.
#[derive(Debug, Clone)]
pub struct GroundStock {
    z0: Real,
    /// The surfaces' radii on the grid, one row per state: before cutting
    /// pass 1, 2, ..., after the last (`-inf` where there is no part).
    states: Vec<Vec<Real>>,
    /// Each cutting pass's blocks (from 0).
    blocks: Vec<std::ops::Range<usize>>,
    wheel: Wheel,
    passes: Vec<crate::process::PassStock>,
    /// The verification's tolerance (mm): the ridge a finishing pass may
    /// leave.
    tolerance: Real,
    /// The surface over every spindle phase before each cutting pass and
    /// after the last: what a body riding the part meets.
    phases: Vec<GroundSurface>,
    /// Each cutting block's pass (from 0) and time from the pass's start
    /// (minutes).
    block_time: std::collections::BTreeMap<usize, (usize, Real)>,
}

/// What pass `p` removed (mm): the most, over its stretches along z, of
/// the surface before it (the pass `before`'s, or the blank's over the
/// nominal) less the one it leaves, at the valleys.
fn removed(p: &PassCheck, before: Option<&PassCheck>, blank: &Profile, nominal: &Profile) -> Real {
    let mut cut: Real = 0.0;
    for (i, b) in p.along_z.iter().enumerate() {
        let under = match before {
            None => (blank.eval(b[0]).ok())
                .zip(nominal.eval(b[0]).ok())
                .map(|(x, y)| x - y),
            Some(q) => (q.along_z.get(i))
                .filter(|q| (q[0] - b[0]).abs() < crate::tolerance::SAME_LENGTH)
                .map(|q| q[1]),
        };
        if let Some(under) = under {
            cut = cut.max(under - b[1]);
        }
    }
    cut
}

impl GroundStock {
    #[allow(clippy::too_many_arguments)]
    fn new(
        check: &GrindingCheck,
        blank: &Profile,
        nominal: &Profile,
        wheel: &Wheel,
        sweeps: &[Vec<(CapsuleEnvelope, Vec<usize>)>],
        ordinals: &[Vec<usize>],
        blocks: Vec<std::ops::Range<usize>>,
    ) -> Result<Self, VerifyError> {
        let (z0, z1) = blank.z_range();
        let n = ((z1 - z0) / STOCK_STEP).ceil() as usize + 1;
        let zs: Vec<Real> = (0..n)
            .map(|i| (z0 + i as Real * STOCK_STEP).min(z1))
            .collect();
        let under = blank.eval_many(&zs)?;
        // Each generatrix's sweeps evaluated once.
        let evaluated: Vec<Vec<Vec<Real>>> = sweeps
            .iter()
            .map(|g| g.iter().map(|(e, _)| e.eval_many(&zs)).collect())
            .collect();
        let states = (0..=blocks.len())
            .map(|done| {
                (0..n)
                    .map(|i| {
                        (0..sweeps.len())
                            .map(|g| {
                                evaluated[g]
                                    .iter()
                                    .zip(&ordinals[g])
                                    .filter(|(_, p)| **p < done)
                                    .map(|(v, _)| v[i])
                                    .filter(|v| v.is_finite())
                                    .fold(under[i], Real::min)
                            })
                            .fold(Real::NEG_INFINITY, Real::max)
                    })
                    .collect()
            })
            .collect();
        // What each pass cut: the surfaces' difference at the valleys, the
        // blank before the first.
        let mut passes = Vec::new();
        for (k, p) in check.passes.iter().enumerate() {
            let cut = removed(
                p,
                k.checked_sub(1).map(|j| &check.passes[j]),
                blank,
                nominal,
            );
            passes.push(crate::process::PassStock {
                name: p.name.clone(),
                first_block: p.first_block - 1,
                cut,
                ridge: p.ridge_mm,
                finishes: p.deviation.max_abs <= check.tolerance,
            });
        }
        Ok(Self {
            z0,
            states,
            blocks,
            wheel: *wheel,
            passes,
            tolerance: check.tolerance,
            phases: Vec::new(),
            block_time: std::collections::BTreeMap::new(),
        })
    }

    /// The surface when block `block` (from 0) begins: the one before the
    /// cutting pass it belongs to (the part as that pass finds it).
    fn state(&self, block: usize) -> &[Real] {
        let done = self.blocks.iter().filter(|r| r.end <= block).count();
        &self.states[done.min(self.states.len() - 1)]
    }

    /// The surface over every spindle phase at `along` (0 to 1) of the
    /// move into block `block` (from 0), with the pass in progress then.
    fn phases_at(
        &self,
        block: usize,
        along: Real,
    ) -> Option<(&GroundSurface, Option<PartLayer<'_>>)> {
        match self.block_time.get(&block) {
            Some(&(pass, t1)) => {
                let t0 = block
                    .checked_sub(1)
                    .and_then(|b| self.block_time.get(&b))
                    .filter(|(p, _)| *p == pass)
                    .map_or(t1, |(_, t)| *t);
                let layer = self.phases.last()?.layer(pass)?;
                Some((
                    self.phases.get(pass)?,
                    Some(layer.by_time(t0 + along.clamp(0.0, 1.0) * (t1 - t0))),
                ))
            }
            None => {
                let done = self.blocks.iter().filter(|r| r.end <= block).count();
                Some((
                    self.phases
                        .get(done.min(self.phases.len().checked_sub(1)?))?,
                    None,
                ))
            }
        }
    }

    /// The grid's indices within `half` of `z`, with their z.
    fn around(&self, z: Real, half: Real, n: usize) -> impl Iterator<Item = (usize, Real)> + '_ {
        let lo = ((z - half - self.z0) / STOCK_STEP).floor().max(0.0) as usize;
        let hi =
            (((z + half - self.z0) / STOCK_STEP).ceil().max(0.0) as usize).min(n.saturating_sub(1));
        (lo..=hi)
            .map(move |i| (i, self.z0 + i as Real * STOCK_STEP))
            .filter(move |(_, zi)| (zi - z).abs() <= half)
    }
}

impl crate::process::Stock for GroundStock {
    fn tool_depth(&self, block: usize, pose: &[Real]) -> Real {
        // The wheel's section: its roundings' centres a flat apart about
        // the tracked point, at its radius from the part's axis.
        let (z, r) = (pose[2], pose[0].hypot(pose[1]));
        let (rs, half_flat) = (self.wheel.rounding_radius, self.wheel.flat() / 2.0);
        let s = self.state(block);
        self.around(z, half_flat + rs, s.len())
            .map(|(i, zi)| {
                let off = ((zi - z).abs() - half_flat).max(0.0);
                let bottom = r - (rs * rs - off * off).max(0.0).sqrt();
                s[i] - bottom
            })
            .fold(Real::NEG_INFINITY, Real::max)
    }

    fn body_gap(
        &self,
        block: usize,
        along: Real,
        shape: &crate::process::Roller,
        frame: &crate::math::Mat4,
    ) -> Option<Real> {
        // A roller across the axial section: a circle of its radius in it,
        // dropped onto the highest surface any spindle phase leaves.
        let (x, y, z) = (frame[(0, 3)], frame[(1, 3)], frame[(2, 3)]);
        let (u, r) = (x.hypot(y), shape.radius);
        let (surface, extra) = self.phases_at(block, along)?;
        let drop = surface.support(z, r, STOCK_STEP, extra.as_ref()).ok()??;
        Some(u - drop.centre_x)
    }

    fn passes(&self) -> Vec<crate::process::PassStock> {
        self.passes.clone()
    }

    /// On the finishing pass (one that leaves the part at its nominal, or
    /// the last), the feed whose ridge is the tolerance; on any, the
    /// wheel's width (a turn's feed past it leaves a helix the wheel never
    /// touches).
    fn feed_limit(&self, block: usize) -> Option<crate::process::FeedLimit> {
        let i = self.blocks.iter().position(|r| r.contains(&block))?;
        let last = i + 1 == self.blocks.len();
        let pass = self.passes.get(i)?;
        let width = self.wheel.width;
        let ridge = self.wheel.feed_for_ridge(self.tolerance);
        Some(if (pass.finishes || last) && ridge < width {
            crate::process::FeedLimit {
                per_rev: ridge,
                why: format!(
                    "below it the finishing pass \"{}\" leaves ridges no higher than the tolerance {} mm (the wheel's rounding radius {} mm)",
                    pass.name,
                    self.tolerance,
                    crate::math::fixed(self.wheel.rounding_radius, 3)
                ),
            }
        } else {
            crate::process::FeedLimit {
                per_rev: width,
                why: format!(
                    "past the wheel's width ({} mm) a turn of pass \"{}\" leaves a helix the wheel never touches",
                    crate::math::fixed(width, 3),
                    pass.name
                ),
            }
        })
    }
}

/// The finishing pass's failure: its surface strays from the nominal
/// beyond the tolerance (with `verification failed: ` before it, the
/// check's [`VerifyError::Failed`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the finished surface strays {} mm from the nominal profile at z = {}, \
     where {} cuts it ({pass}: {} mm per revolution, a ridge of {} mm) (tolerance {tolerance} mm){}",
    crate::math::fixed(*deviation, 5),
    crate::math::fixed(*z, 3),
    block.as_deref().unwrap_or("an unknown block"),
    crate::math::fixed(*feed_per_rev, 4),
    crate::math::fixed(*ridge, 5),
    to_change.iter().map(|c| format!("; {c}")).collect::<String>()
)]
pub struct FinishFailure {
    /// The signed deviation (mm; negative: a gouge).
    deviation: Real,
    /// Where (z, mm).
    z: Real,
    /// The block whose move formed the surface there, as the program
    /// names it (`N1130 in "pass 4, ..."`).
    block: Option<String>,
    /// The finishing pass.
    pass: String,
    /// Its feed per revolution (mm).
    feed_per_rev: Real,
    /// The ridge that feed leaves (mm).
    ridge: Real,
    /// The tolerance (mm).
    tolerance: Real,
    /// What would change it ([`PassCheck::to_change`]).
    to_change: Vec<String>,
}

impl GrindingCheck {
    /// The finishing pass's failure, if it strays more than the tolerance
    /// from the nominal ([`FinishFailure`], its block named as `program`, the
    /// one replayed, numbers it).
    pub fn failure(&self, program: &AxisProgram) -> Option<FinishFailure> {
        let finish = self.passes.last()?;
        let d = finish.deviation;
        (d.max_abs > self.tolerance).then(|| FinishFailure {
            deviation: if d.max_above.abs() >= d.max_below.abs() {
                d.max_above
            } else {
                d.max_below
            },
            z: d.at_z,
            block: d.block.map(|b| crate::program::block_name(program, b - 1)),
            pass: finish.name.clone(),
            feed_per_rev: finish.feed_per_rev_mm,
            ridge: finish.ridge_mm,
            tolerance: self.tolerance,
            to_change: finish.to_change.clone(),
        })
    }

    /// The check, or its failure as an error.
    ///
    /// # Failures
    /// [`Self::failure`].
    pub fn verified(self, program: &AxisProgram) -> Result<Self, VerifyError> {
        let band = || (self.passes.last()?.bands.iter()).find_map(BandCheck::failure);
        match self.failure(program).map(|e| e.to_string()).or_else(band) {
            Some(e) => Err(VerifyError::Failed(e)),
            None => Ok(self),
        }
    }

    /// The finish's figure against the tolerance, and its failure.
    pub fn findings(&self, program: &AxisProgram) -> (Vec<Figure>, Vec<Finding>) {
        let Some(finish) = self.passes.last() else {
            return (Vec::new(), Vec::new());
        };
        let d = finish.deviation;
        let value = if d.max_above.abs() >= d.max_below.abs() {
            d.max_above
        } else {
            d.max_below
        };
        let block = d.block.map(|b| crate::program::block_name(program, b - 1));
        let place = format!(
            "z = {} mm{}",
            crate::math::fixed(d.at_z, 3),
            block.as_ref().map_or(String::new(), |b| format!(", {b}"))
        );
        let mut figure = Figure::new(
            &format!("{}: the surface from the nominal", finish.name),
            value,
            self.tolerance,
            "mm",
            place,
        );
        figure.block = d.block.and_then(|b| b.checked_sub(1));
        let failure = self.failure(program).map(|e| {
            let f = Finding::new(
                "verification",
                VerifyError::Failed(e.to_string()).to_string(),
            );
            match d.block {
                Some(b) => f.at(b - 1, crate::program::block_name(program, b - 1)),
                None => f,
            }
        });
        // What the program does not grind: verified on what it covers.
        let uncovered = (!finish.uncovered.is_empty()).then(|| {
            let stretches: Vec<String> = (finish.uncovered.iter())
                .map(|[a, b]| {
                    format!(
                        "z = {} to {} mm",
                        crate::math::fixed(*a, 3),
                        crate::math::fixed(*b, 3)
                    )
                })
                .collect();
            Finding::new(
                COVERAGE,
                format!(
                    "the program does not grind the nominal over {}: no pass's wheel reaches it (the rest is verified on what the program covers); extend the passes over it, or verify a nominal of what it grinds",
                    stretches.join(", ")
                ),
            )
        });
        // Each stretch with its own band, against it.
        let mut figures = vec![figure];
        let mut failures: Vec<Finding> = failure.into_iter().collect();
        for b in &finish.bands {
            let place = format!("z = {} mm", crate::math::fixed(b.at_z, 3));
            figures.push(Figure::new(
                &format!(
                    "{}: the surface in its own band, {}",
                    finish.name, b.band.source
                ),
                b.worst(),
                b.band.half,
                "mm",
                place,
            ));
            failures.extend(
                b.failure()
                    .map(|m| Finding::new("verification", VerifyError::Failed(m).to_string())),
            );
        }
        (figures, failures.into_iter().chain(uncovered).collect())
    }
}

/// The rule of a grinding program that leaves a stretch of the nominal
/// unground.
pub const COVERAGE: &str = "the program grinds the whole nominal";

/// The family, as the registry carries it.
pub const FAMILY: super::Family = super::Family {
    name: "revolution",
    kind: Some(&KIND),
    script: &[&SCRIPT_API],
};

#[cfg(test)]
mod tests {
    use super::*;

    /// A Fanuc thread block's lead and start angle, read at F's 0.0001 mm
    /// and Q's 0.001 deg; a Sinumerik feed at F's 0.1 mm/min; speeds in
    /// whole rpm.
    #[test]
    fn words_are_read_as_written() {
        let mut p = crate::program::test_program();
        p.blocks[4].motion = crate::toolpath::Motion::Thread {
            lead: 10.0 * std::f64::consts::PI,
            start_deg: 360.0 / 7.0,
        };
        p.blocks[1].feed = 100.94;
        p.blocks[2].spindle = Some(120.6);
        let (w, resolution) = as_written(&p);
        assert_eq!(resolution, 1e-3);
        assert_eq!(
            w.blocks[4].motion,
            crate::toolpath::Motion::Thread {
                lead: 31.4159,
                start_deg: 51.429
            }
        );
        assert_eq!(
            (w.blocks[1].feed, w.blocks[2].spindle),
            (100.9, Some(121.0))
        );
        assert_eq!(w.spindle_rpm, 399.0);
        assert_eq!(w.blocks[2].values[1], -0.0);
    }

    /// Drawing stretches keep each stretch's extremes: the ridges survive.
    #[test]
    fn stretches_keep_the_extremes() {
        let zs: Vec<f64> = (0..10_000).map(|i| i as f64 * 0.01).collect();
        let lo: Vec<f64> = zs.iter().map(|z| (z * 7.0).sin()).collect();
        let hi: Vec<f64> = lo.iter().map(|v| v + 0.5).collect();
        let b = bucketed(&zs, &lo, &hi, 100);
        assert_eq!(b.len(), 100);
        let min = b.iter().map(|x| x[1]).fold(f64::INFINITY, f64::min);
        let max = b.iter().map(|x| x[2]).fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(min, lo.iter().copied().fold(f64::INFINITY, f64::min));
        assert_eq!(max, hi.iter().copied().fold(f64::NEG_INFINITY, f64::max));
        assert!(b.windows(2).all(|w| w[1][0] > w[0][0]));
    }
}
