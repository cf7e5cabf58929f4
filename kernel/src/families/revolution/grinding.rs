//! The grinding passes replayed one after another on `m` generatrices:
//! each pass's wheel path timed as the control runs it, the wheel's
//! section where each generatrix meets it, the surface it leaves (the
//! lowest of its sweep, the earlier sweeps' and the blank) against the
//! nominal profile, the surface over every spindle phase, and the block
//! whose touch forms the worst place.

use super::phases::{Infeed, TimedPath};
use super::surface::{touches, GroundSurface, PassLayer, Touches, WheelSection};
use super::{
    bucketed, BandCheck, Deviation, GrindingCheck, GroundStock, PassCheck, PROFILE_BUCKETS,
};
use crate::machine::{Axis, AxisKind, MachineInfo, MachineKinematics};
use crate::math::{positive, Real};
use crate::offset::{CapsuleEnvelope, Side};
use crate::profile::{Profile, ProfileError};
use crate::program::{AxisProgram, ProgramPass};
use crate::replay::{as_written, replay, VerifyError};
use crate::tool::Wheel;
use crate::toolpath::Motion;
use crate::transform::ToolFrame;
use std::collections::BTreeMap;
use std::ops::Range;

/// How far either side of a ridge's crest the touches that form it are
/// looked for (mm): well below the least gap between touches the replay
/// resolves.
const CREST_SIDE: Real = 1e-4;

/// A generatrix's sweeps so far, each with the block (from 1) of each of
/// its touches.
type Sweeps = Vec<(CapsuleEnvelope, Vec<usize>)>;

/// [`super::replay_grinding`] on `m` generatrices (even), with the
/// finish's worst over every other one.
#[allow(clippy::too_many_arguments)]
pub(super) fn replay_on(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    wheel: &Wheel,
    passes: &[ProgramPass],
    nominal: &Profile,
    blank: Option<&Profile>,
    range: (Real, Real),
    tolerance: Real,
    m: usize,
) -> Result<(GrindingCheck, Option<GroundStock>, Real), VerifyError> {
    positive("verification tolerance", tolerance)?;
    let (written, resolution) = as_written(program);
    if tolerance < 2.0 * resolution {
        return Err(VerifyError::Resolution {
            tolerance,
            resolution,
        });
    }
    let info = machine.info();
    let axes: Vec<Option<&Axis>> = written.axes.iter().map(|a| info.axis(&a.name)).collect();
    let on = Setting {
        written: &written,
        poses: replay(&written, machine, tool)?,
        known: axes.iter().flatten().copied().collect(),
        axes,
        info,
        rapid: rapid(info),
        wheel,
        nominal,
        blank,
        range,
        tolerance,
        m,
    };
    let mut out = GrindingCheck {
        tolerance,
        generatrices: m,
        sampling_change_mm: 0.0,
        resolution_mm: resolution,
        passes: Vec::new(),
    };
    let mut run = Run {
        earlier: (0..m).map(|_| Vec::new()).collect(),
        ordinals: vec![Vec::new(); m],
        cut_blocks: Vec::new(),
        phases: GroundSurface::new(blank.unwrap_or(nominal).clone()),
        phase_states: Vec::new(),
        block_time: BTreeMap::new(),
    };
    let (mut rpm, mut half_worst) = (written.spindle_rpm, 0.0);
    for pass in passes {
        crate::budget::check("the grinding replay")?;
        for b in &written.blocks[pass.blocks.clone()] {
            if let Some(s) = b.spindle {
                rpm = s;
            }
        }
        if pass.cuts {
            let (mut check, half) = on.pass(pass, rpm, &mut run)?;
            check.removed_mm = blank.map(|b| super::removed(&check, out.passes.last(), b, nominal));
            out.passes.push(check);
            half_worst = half;
        }
    }
    let Some(finish) = out.passes.last_mut() else {
        return Err(VerifyError::NoCuttingPass);
    };
    finish.to_change = to_change(finish, (wheel, nominal), (tolerance, range), &run.earlier);
    let stock = match blank {
        Some(b) => {
            run.phase_states.push(run.phases);
            let mut stock = GroundStock::new(
                &out,
                b,
                nominal,
                wheel,
                &run.earlier,
                &run.ordinals,
                run.cut_blocks,
            )?;
            stock.phases = run.phase_states;
            stock.block_time = run.block_time;
            Some(stock)
        }
        None => None,
    };
    Ok((out, stock, half_worst))
}

/// The deviation's largest (in size) and where, from its most above and
/// below; the generatrix of it (of `g_above` and `g_below`). Where every z
/// ground has a band of its own, the general tolerance judges nothing: 0.
fn settle(d: &mut Deviation, g_above: usize, g_below: usize) -> usize {
    if d.max_above == Real::NEG_INFINITY {
        d.max_above = 0.0;
    }
    if d.max_below == Real::INFINITY {
        d.max_below = 0.0;
    }
    if d.max_above >= -d.max_below {
        (d.max_abs, d.at_z) = (d.max_above.abs(), d.above_z);
        g_above
    } else {
        (d.max_abs, d.at_z) = (d.max_below.abs(), d.below_z);
        g_below
    }
}

/// Whether `z` is in band `b`'s stretch (its ends included).
fn within(b: &crate::profile::Band, z: Real) -> bool {
    let slack = crate::tolerance::SAME_RATIO * (1.0 + z.abs());
    z >= b.from - slack && z <= b.to + slack
}

/// The pass's surface (`spread` at `zs`) in each of `bands`, where it
/// has been ground.
fn band_checks(bands: &[crate::profile::Band], zs: &[Real], spread: &Spread) -> Vec<BandCheck> {
    bands
        .iter()
        .filter_map(|b| {
            let mut c = BandCheck {
                band: b.clone(),
                max_above: Real::NEG_INFINITY,
                max_below: Real::INFINITY,
                at_z: b.from,
            };
            let (mut above_z, mut below_z) = (b.from, b.from);
            for (i, &z) in zs.iter().enumerate() {
                if !(spread.touched[i] && within(b, z)) {
                    continue;
                }
                if spread.hi[i] > c.max_above {
                    (c.max_above, above_z) = (spread.hi[i], z);
                }
                if spread.lo[i] < c.max_below {
                    (c.max_below, below_z) = (spread.lo[i], z);
                }
            }
            if !c.max_above.is_finite() {
                return None;
            }
            c.at_z = if c.max_above >= -c.max_below {
                above_z
            } else {
                below_z
            };
            Some(c)
        })
        .collect()
}

/// What would bring the finishing pass `finish` within `tolerance`, where
/// the replay can tell:
/// - its ridges above the tolerance: the feed (mm/min, at its speed) whose
///   ridges are half of it;
/// - a gouge the wheel's flat cuts deeper than its roundings at the
///   program's points would (`earlier`: every generatrix's sweeps): the
///   path is a ball's of the rounding radius, which a wheel with a flat
///   does not follow;
/// - material left within a turn's feed of an end of `range`: the wheel
///   leaves the end within its last revolution there;
/// - material left where the `nominal` itself is concave tighter than the
///   wheel's rounding (a corner it does not bridge within a tenth of the
///   tolerance): no program grinds it, and its source is named.
fn to_change(
    finish: &PassCheck,
    (wheel, nominal): (&Wheel, &Profile),
    (tolerance, range): (Real, (Real, Real)),
    earlier: &[Sweeps],
) -> Vec<String> {
    let mut out = Vec::new();
    let d = &finish.deviation;
    let reach = wheel.rounding_radius + 0.5 * wheel.flat();
    let tight = (d.max_above > tolerance)
        .then(|| {
            let found = crate::offset::unbridged(
                nominal,
                wheel.rounding_radius,
                Side::Outside,
                0.1 * tolerance,
            );
            found.into_iter().find(|v| (v.z - d.above_z).abs() <= reach)
        })
        .flatten();
    if let Some(v) = tight {
        let what = match v.rho {
            0.0 => "a concave corner".to_owned(),
            rho => format!("concave at a radius of {} mm", crate::math::fixed(rho, 4)),
        };
        out.push(format!(
            "the nominal itself is {what} at z = {} mm{}, tighter than the wheel's rounding ({} mm): no program grinds it with this wheel; check the drawing's value there, or give it a fillet of at least the rounding",
            crate::math::fixed(v.z, 3),
            v.source.map_or(String::new(), |s| format!(" ({s})")),
            crate::math::fixed(wheel.rounding_radius, 3)
        ));
    }
    if finish.ridge_mm > tolerance && finish.spindle_rpm > 0.0 {
        let f = wheel.feed_for_ridge(0.5 * tolerance);
        out.push(format!(
            "a finishing feed of at most {} mm/min ({} mm per revolution at {} rpm) leaves ridges of half the tolerance",
            crate::math::fixed(f * finish.spindle_rpm, 1),
            crate::math::fixed(f, 4),
            crate::math::fixed(finish.spindle_rpm, 0)
        ));
    }
    let flat = wheel.flat();
    if flat > 0.0 && d.max_below < -tolerance {
        // The sweep that cut deepest there, against its roundings alone.
        let z = d.below_z;
        let deepest = (earlier.iter().flatten())
            .map(|(env, _)| (env.eval(z), env))
            .filter(|(v, _)| v.is_finite())
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((cut, env)) = deepest {
            let deeper = env.circles().eval(z) - cut;
            if deeper > tolerance {
                out.push(format!(
                    "the wheel's flat ({} mm between its roundings) cuts {} mm deeper there than its roundings at the program's points would: the path is a ball's of the rounding radius; a wheel with a flat needs the flat's path (wheel_path(profile, wheel, tolerance) in a script), or a wheel no wider than twice its rounding radius ({} mm)",
                    crate::math::fixed(flat, 3),
                    crate::math::fixed(deeper, 5),
                    crate::math::fixed(2.0 * wheel.rounding_radius, 3)
                ));
            }
        }
    }
    let f = finish.feed_per_rev_mm;
    let at_end = [range.0, range.1]
        .into_iter()
        .find(|e| (d.above_z - e).abs() <= f);
    if let Some(end) = at_end.filter(|_| d.max_above > tolerance) {
        out.push(format!(
            "the wheel leaves the end at z = {} mm within its last revolution, the helix unfinished there: run the pass past the end by at least a revolution's feed ({} mm), or let the wheel stand a revolution at it",
            crate::math::fixed(end, 3),
            crate::math::fixed(f, 4)
        ));
    }
    out
}

/// A rapid moves the wheel as fast as the slowest linear axis may (mm/min).
fn rapid(info: &MachineInfo) -> Real {
    info.axes
        .iter()
        .filter(|a| a.kind == AxisKind::Linear)
        .map(|a| a.max_feed)
        .fold(Real::INFINITY, Real::min)
}

/// What every pass is replayed on: the program as written, its poses, the
/// machine, the wheel, the profiles and the range checked.
struct Setting<'a> {
    written: &'a AxisProgram,
    /// The replayed poses, 6 per block.
    poses: Vec<Real>,
    /// The machine's axis of each of the program's axes, where it has it.
    axes: Vec<Option<&'a Axis>>,
    /// Those the machine has.
    known: Vec<&'a Axis>,
    info: &'a MachineInfo,
    /// The wheel's speed on a rapid (mm/min).
    rapid: Real,
    wheel: &'a Wheel,
    nominal: &'a Profile,
    blank: Option<&'a Profile>,
    range: (Real, Real),
    tolerance: Real,
    /// The generatrices.
    m: usize,
}

/// What the passes replayed so far leave for the next.
struct Run {
    /// Each generatrix's earlier sweeps: the surface a pass cuts into is
    /// their lowest.
    earlier: Vec<Sweeps>,
    /// Each generatrix's sweeps' cutting passes (from 0).
    ordinals: Vec<Vec<usize>>,
    /// Each cutting pass's blocks (from 0).
    cut_blocks: Vec<Range<usize>>,
    /// The surface over every spindle phase so far.
    phases: GroundSurface,
    /// That surface before each cutting pass.
    phase_states: Vec<GroundSurface>,
    /// Each cutting block's pass (from 0) and minutes from its start.
    block_time: BTreeMap<usize, (usize, Real)>,
}

/// How a pass's surface strays from the nominal over its generatrices.
struct Spread {
    /// The pass's deviation (its block not yet found).
    deviation: Deviation,
    /// The generatrix met (an index into the pass's sweeps) forming the
    /// largest of it.
    worst: usize,
    /// The largest over every other generatrix (mm).
    half_worst: Real,
    /// The least and the greatest over the generatrices at each z (mm).
    lo: Vec<Real>,
    hi: Vec<Real>,
    /// Whether any generatrix has been ground at each z, by this pass or
    /// an earlier one.
    touched: Vec<bool>,
}

impl Setting<'_> {
    /// One cutting pass replayed at `rpm` on the surface `run` holds,
    /// which it then holds too: its check, and its worst over every other
    /// generatrix.
    fn pass(
        &self,
        pass: &ProgramPass,
        rpm: Real,
        run: &mut Run,
    ) -> Result<(PassCheck, Real), VerifyError> {
        let blocks = pass.blocks.clone();
        let (timed, cutting_feed) = self.timed(blocks.clone())?;
        let t = touches(&timed, rpm, self.m)?;
        self.add_layer(timed, rpm, &blocks, run)?;
        // Each generatrix met: the wheel's section at its touches.
        let met: Vec<usize> = (0..t.z.len()).filter(|&g| !t.z[g].is_empty()).collect();
        let envs = met
            .iter()
            .map(|&g| {
                let (w, flat) = (self.wheel.rounding_radius, self.wheel.flat());
                CapsuleEnvelope::new(&t.z[g], &t.x[g], w, flat, Side::Outside)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let zs = self.grid(&envs, &run.earlier)?;
        let profile = self.nominal.eval_many(&zs)?;
        // The stretches with their own bands, judged apart.
        let bands = self.nominal.bands();
        let banded: Vec<bool> = (zs.iter())
            .map(|&z| bands.iter().any(|b| within(b, z)))
            .collect();
        let before = match self.blank {
            Some(b) => b.eval_many(&zs)?,
            None => vec![Real::INFINITY; zs.len()],
        };
        let mut spread = self.spread(
            pass,
            (&zs, &banded),
            &profile,
            &before,
            &envs,
            &met,
            &run.earlier,
        )?;
        let bands = band_checks(bands, &zs, &spread);
        // The phases' surface against the highest generatrix.
        let envelope = run.phases.cut_many(&zs);
        let (mut stand_off, mut stand_off_z) = (0.0, self.range.0);
        for i in 0..zs.len() {
            let s = envelope[i].min(before[i]) - (spread.hi[i] + profile[i]);
            if s.is_finite() && s > stand_off {
                (stand_off, stand_off_z) = (s, zs[i]);
            }
        }
        let worst_generatrix = met[spread.worst];
        keep(run, envs, &met, &t, blocks.clone());
        spread.deviation.block =
            self.forming_block(&run.earlier[worst_generatrix], spread.deviation.at_z, {
                let d = &spread.deviation;
                d.max_above >= -d.max_below
            })?;
        let f = if rpm > 0.0 { cutting_feed / rpm } else { 0.0 };
        // What is judged: where the part has been ground.
        let kept = |v: &[Real]| -> Vec<Real> {
            v.iter()
                .zip(&spread.touched)
                .filter(|(_, t)| **t)
                .map(|(x, _)| *x)
                .collect()
        };
        let (zs_kept, lo_kept, hi_kept) = (kept(&zs), kept(&spread.lo), kept(&spread.hi));
        let check = PassCheck {
            name: pass.name.clone(),
            first_block: blocks.start + 1,
            feed_mm_min: cutting_feed,
            spindle_rpm: rpm,
            feed_per_rev_mm: f,
            ridge_mm: self.wheel.ridge(f),
            deviation: spread.deviation,
            phase_stand_off_mm: stand_off,
            phase_stand_off_z: stand_off_z,
            removed_mm: None,
            left_mm: lo_kept.iter().copied().fold(0.0, Real::max),
            uncovered: stretches(&zs, &spread.touched),
            along_z: bucketed(&zs_kept, &lo_kept, &hi_kept, PROFILE_BUCKETS),
            to_change: Vec::new(),
            bands,
        };
        Ok((check, spread.half_worst))
    }

    /// The pass's layer (the wheel's true section along `timed` at
    /// `rpm`, over every spindle phase) added to `run`'s, its blocks timed.
    fn add_layer(
        &self,
        timed: TimedPath,
        rpm: Real,
        blocks: &Range<usize>,
        run: &mut Run,
    ) -> Result<(), VerifyError> {
        run.phase_states.push(run.phases.clone());
        let section = WheelSection {
            radius: self.wheel.rounding_radius,
            flat: self.wheel.flat(),
        };
        let layer = PassLayer::timed(timed, section, rpm)?;
        let pass_index = run.cut_blocks.len();
        run.block_time.extend(
            (blocks.clone())
                .zip(layer.path().times())
                .map(|(k, &tm)| (k, (pass_index, tm))),
        );
        run.phases = run.phases.with(layer);
        Ok(())
    }

    /// The wheel's path over `blocks` in the (z, x) plane, each point
    /// with the time it is reached, from the infeed of the block before;
    /// and the pass's cutting feed (mm/min, the largest of its moves).
    fn timed(&self, blocks: Range<usize>) -> Result<(TimedPath, Real), VerifyError> {
        let p = &self.poses;
        let z: Vec<Real> = blocks.clone().map(|b| p[6 * b + 2]).collect();
        let x: Vec<Real> = blocks
            .clone()
            .map(|b| p[6 * b].hypot(p[6 * b + 1]))
            .collect();
        let mut feeds = vec![0.0; z.len()];
        let mut cutting_feed: Real = 0.0;
        for (i, k) in blocks.clone().enumerate().skip(1) {
            let b = &self.written.blocks[k];
            if b.motion != Motion::Rapid {
                cutting_feed = cutting_feed.max(b.feed);
            }
            feeds[i] = self.line_feed(k, (z[i] - z[i - 1]).hypot(x[i] - x[i - 1]));
        }
        // The wheel came to the pass's first point by the block before it
        // (the infeed at its feed, the part turning all the while).
        let infeed = match blocks.start {
            k if k > 0 && !blocks.is_empty() => {
                let (iz, ix) = (p[6 * (k - 1) + 2], p[6 * (k - 1)].hypot(p[6 * (k - 1) + 1]));
                Some(Infeed {
                    z: iz,
                    x: ix,
                    feed: self.line_feed(k, (z[0] - iz).hypot(x[0] - ix)),
                })
            }
            _ => None,
        };
        Ok((TimedPath::entered(infeed, &z, &x, &feeds)?, cutting_feed))
    }

    /// The wheel's speed along its (z, x) line on block `k` (from block
    /// `k - 1`, `line` mm): the block's feed over the control's path
    /// (every linear axis of the block).
    fn line_feed(&self, k: usize, line: Real) -> Real {
        let (a, b) = (&self.written.blocks[k - 1], &self.written.blocks[k]);
        let deltas: Vec<Real> = a
            .values
            .iter()
            .zip(&b.values)
            .zip(&self.axes)
            .filter(|(_, ax)| ax.is_some())
            .map(|((p, q), _)| q - p)
            .collect();
        let path = crate::machine::feed_length(&self.known, &deltas, &self.info.setup.feed_group);
        let f = if b.motion == Motion::Rapid {
            self.rapid
        } else {
            b.feed
        };
        // A move that leaves the wheel standing (only the rest's U moves)
        // adds no length to the wheel's path and no time to it: the part's
        // turn meanwhile shifts every later touch alike, which the phases,
        // free over every spindle phase, already cover.
        if path > 0.0 && line > 0.0 {
            f * line / path
        } else {
            f
        }
    }

    /// Where a pass's surface is measured: a grid over the range (20
    /// times finer than the tolerance, within 5 to 50 um), the nominal's
    /// nodes, and where this pass's ridges and the earlier ones' peak.
    fn grid(&self, envs: &[CapsuleEnvelope], earlier: &[Sweeps]) -> Result<Vec<Real>, VerifyError> {
        let (z0, z1) = self.range;
        let step = (self.tolerance * 20.0).clamp(0.005, 0.05);
        let mut zs = crate::profile::uniform_grid(z0, z1, step)?;
        zs.extend(
            self.nominal
                .z()
                .iter()
                .copied()
                .filter(|z| (z0..=z1).contains(z)),
        );
        for env in envs.iter().chain(earlier.iter().flatten().map(|(e, _)| e)) {
            zs.extend(env.kinks(z0, z1));
        }
        // Each band's ends: a station's band is judged at its z.
        zs.extend(
            (self.nominal.bands().iter())
                .flat_map(|b| [b.from, b.to])
                .filter(|z| (z0..=z1).contains(z)),
        );
        zs.sort_by(Real::total_cmp);
        zs.dedup();
        Ok(zs)
    }

    /// The pass's surface on each generatrix met (`envs`, the generatrices
    /// `met`) at `zs` against the nominal `profile`: the lowest of its
    /// sweep, the earlier sweeps and the blank (`before`).
    #[allow(clippy::too_many_arguments)]
    fn spread(
        &self,
        pass: &ProgramPass,
        (zs, banded): (&[Real], &[bool]),
        profile: &[Real],
        before: &[Real],
        envs: &[CapsuleEnvelope],
        met: &[usize],
        earlier: &[Sweeps],
    ) -> Result<Spread, VerifyError> {
        let z0 = self.range.0;
        let mut d = Deviation {
            max_above: Real::NEG_INFINITY,
            above_z: z0,
            max_below: Real::INFINITY,
            below_z: z0,
            max_abs: 0.0,
            at_z: z0,
            block: None,
        };
        // The generatrix of the largest value above and below.
        let (mut g_above, mut g_below) = (0, 0);
        let (mut half_above, mut half_below) = (Real::NEG_INFINITY, Real::INFINITY);
        let mut lo = vec![Real::INFINITY; zs.len()];
        let mut hi = vec![Real::NEG_INFINITY; zs.len()];
        // Where some generatrix has been ground, by this pass or before.
        let mut touched = vec![false; zs.len()];
        for (g, env) in envs.iter().enumerate() {
            crate::budget::check("the grinding replay")?;
            let surface = env.eval_many(zs);
            let (under, reached) = cut_into(before, &earlier[met[g]], zs);
            for (i, ((&z, &s), &p)) in zs.iter().zip(&surface).zip(profile).enumerate() {
                // Where the sweep never reaches, the pass leaves what was
                // there (a pass may cover a stretch only); where no pass
                // has reached so far, the program has not ground the part
                // there: not judged, but said ([`PassCheck::uncovered`]).
                if !s.is_finite() && !reached[i] {
                    continue;
                }
                touched[i] = true;
                let left = if s.is_finite() {
                    s.min(under[i])
                } else {
                    under[i]
                };
                if !left.is_finite() {
                    return Err(self.never_reached(pass, met[g], z));
                }
                let e = left - p;
                (lo[i], hi[i]) = (lo[i].min(e), hi[i].max(e));
                if banded[i] {
                    continue;
                }
                if e > d.max_above {
                    (d.max_above, d.above_z, g_above) = (e, z, g);
                }
                if e < d.max_below {
                    (d.max_below, d.below_z, g_below) = (e, z, g);
                }
                if met[g].is_multiple_of(2) {
                    (half_above, half_below) = (half_above.max(e), half_below.min(e));
                }
            }
        }
        if !touched.iter().any(|&t| t) {
            return Err(self.never_reached(pass, met[0], self.range.0));
        }
        let half_worst = if half_above >= -half_below {
            half_above.abs()
        } else {
            half_below.abs()
        };
        let worst = settle(&mut d, g_above, g_below);
        Ok(Spread {
            deviation: d,
            worst,
            half_worst,
            lo,
            hi,
            touched,
        })
    }

    /// The refusal of a pass that leaves generatrix `g` (from 0) unmet at
    /// `z` where neither the blank nor an earlier pass gives a surface:
    /// the wheel never reached the profile there.
    fn never_reached(&self, pass: &ProgramPass, g: usize, z: Real) -> VerifyError {
        VerifyError::Pass {
            pass: pass.name.clone(),
            source: ProfileError::OutsideProfile {
                what: format!(
                    "generatrix {} of {}: the wheel never reached the profile",
                    g + 1,
                    self.m
                ),
                z,
                z_min: self.range.0,
                z_max: self.range.1,
            },
        }
    }

    /// The block whose move formed the surface at `z` on a generatrix
    /// with `sweeps` (this pass's last): of this pass's sweep or of the
    /// earlier one lowest there; none where the blank is lowest. Where the
    /// surface stands `above` the nominal at a ridge's crest between two
    /// touches, the move that made the gap is the later touch's: the block
    /// whose own move (at its feed) left the material there.
    fn forming_block(
        &self,
        sweeps: &Sweeps,
        z: Real,
        above: bool,
    ) -> Result<Option<usize>, VerifyError> {
        let (this, before) = sweeps
            .split_last()
            .expect("this pass's sweep was just kept");
        let at = [z];
        let lowest = std::iter::once(this)
            .chain(before)
            .map(|(e, b)| (e.eval_many(&at)[0], e, b))
            .filter(|(s, _, _)| s.is_finite())
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let blank_at = self.blank.map_or(Ok(Real::INFINITY), |b| b.eval(z))?;
        Ok(lowest
            .filter(|(s, _, _)| *s <= blank_at)
            .and_then(|(_, e, b)| {
                let at = e.source_at(z)?;
                let touch = if above {
                    // The touches either side of a crest (in time order).
                    [z - CREST_SIDE, z + CREST_SIDE]
                        .into_iter()
                        .filter_map(|q| e.source_at(q))
                        .fold(at, usize::max)
                } else {
                    at
                };
                b.get(touch).copied()
            }))
    }
}

/// The stretches `[from, to]` of `zs` where `touched` is false: where no
/// pass has ground the part.
fn stretches(zs: &[Real], touched: &[bool]) -> Vec<[Real; 2]> {
    let mut out: Vec<[Real; 2]> = Vec::new();
    let mut open: Option<Real> = None;
    for (i, (&z, &t)) in zs.iter().zip(touched).enumerate() {
        match (t, open) {
            (false, None) => open = Some(z),
            (true, Some(from)) => {
                out.push([from, zs[i - 1]]);
                open = None;
            }
            _ => {}
        }
    }
    if let (Some(from), Some(&to)) = (open, zs.last()) {
        out.push([from, to]);
    }
    out
}

/// The surface a sweep cuts into at `zs`: the lowest of the blank
/// (`before`) and the generatrix's `earlier` sweeps (those not finite where
/// they never reached: there they do not bound); and where any of those
/// sweeps reached.
fn cut_into(before: &[Real], earlier: &Sweeps, zs: &[Real]) -> (Vec<Real>, Vec<bool>) {
    let mut under = before.to_vec();
    let mut reached = vec![false; zs.len()];
    for (e, _) in earlier {
        for ((u, r), s) in under.iter_mut().zip(&mut reached).zip(e.eval_many(zs)) {
            if s.is_finite() {
                *u = u.min(s);
                *r = true;
            }
        }
    }
    (under, reached)
}

/// A pass's sweeps (`envs`, on the generatrices `met`, touched as `t`
/// says) kept in `run` for the passes after it.
fn keep(
    run: &mut Run,
    envs: Vec<CapsuleEnvelope>,
    met: &[usize],
    t: &Touches,
    blocks: Range<usize>,
) {
    for (env, &g) in envs.into_iter().zip(met) {
        let touched: Vec<usize> = t.block[g].iter().map(|&k| blocks.start + k + 1).collect();
        run.earlier[g].push((env, touched));
        run.ordinals[g].push(run.cut_blocks.len());
    }
    run.cut_blocks.push(blocks);
}
