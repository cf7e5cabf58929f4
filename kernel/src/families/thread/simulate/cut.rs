//! The cut: the program replayed and every thread block's cutter
//! subtracted from the section.

use super::{
    diameter, edges, flank_radii, measure, nominal_flanks_deg, nominal_spaces, poly, rect,
    segment_distance, thread_middle, SimulatedPass, ThreadCheck, ThreadRequest,
};
use crate::families::thread::{Hand, ThreadCutter};
use crate::machine::MachineKinematics;
use crate::math::Real;
use crate::program::{block_name, AxisProgram};
use crate::replay::{as_written, replay, VerifyError};
use crate::toolpath::Motion;
use crate::transform::ToolFrame;
use crate::verdict::Finding;
use geo::{Area, BooleanOps, MultiPolygon, Polygon};

/// Replays `program` (as written) on `machine` and simulates the cut of
/// `cutter` (tracked at `tool`) in the worm's axial section; see the
/// module's docs.
///
/// # Failures
/// The replay failing; a thread block that tapers (X changes), whose lead
/// is not the worm's within the position tolerance over the thread, or
/// that does not run over the whole thread; a move other than a thread
/// that crosses the blank; any cut deeper than the form tolerance beyond
/// the nominal space (named by block); the finished profile beyond a
/// tolerance (named by start and flank). Each a [`VerifyError::Failed`].
pub fn simulate(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    cutter: &ThreadCutter,
    req: &ThreadRequest,
) -> Result<ThreadCheck, VerifyError> {
    // An internal thread is simulated as its external twin in rho = -r
    // (see `mirrored`), and its results turned back.
    let inside = req.section.internal;
    // The program's X is the thread's own: its radius in rho.
    let rho = req.section.opening();
    let twin;
    let req = if inside {
        twin = req.mirrored();
        &twin
    } else {
        req
    };
    let cut = Cut::new(program, (machine, tool), cutter, req, rho)?;
    let mut material =
        MultiPolygon::new(vec![rect(cut.w0, cut.w0 + cut.lead, cut.r_core, cut.r_a)]);
    let mut passes = Vec::new();
    let mut chips = Vec::new();
    let mut lead_error: Real = 0.0;
    // What fails is found and the simulation goes on, so that a failed run
    // shows every pass and the profile it leaves.
    let mut found: Vec<(usize, String)> = Vec::new();
    let mut ticker = crate::budget::Ticker::new("the thread's simulation", 16);
    let speeds: Vec<Real> = crate::program::spindle_speeds(&cut.written).collect();
    for i in 1..cut.written.blocks.len() {
        ticker.tick()?;
        let (from, to) = (cut.at(i - 1), cut.at(i));
        let Motion::Thread { lead, start_deg } = cut.written.blocks[i].motion else {
            found.extend(cut.clear_move(i, from, to).map(|m| (i, m)));
            continue;
        };
        let block = ThreadBlock {
            i,
            lead,
            start_deg,
            rpm: speeds[i],
            from,
            to,
        };
        let (faults, err_len, cuts) = cut.block_faults(&block);
        lead_error = lead_error.max(err_len);
        found.extend(faults.into_iter().map(|m| (i, m)));
        if !cuts {
            continue;
        }
        let (pass, chip, faults) = cut.pass(&block, &mut material);
        found.extend(faults.into_iter().map(|m| (i, m)));
        chips.push(chip);
        passes.push(pass);
    }
    if passes.is_empty() {
        return Err(VerifyError::NoCuttingPass);
    }
    let failures: Vec<Finding> = (found.into_iter())
        .map(|(i, m)| {
            Finding::new("verification", VerifyError::Failed(m).to_string())
                .at(i, block_name(&cut.written, i))
        })
        .collect();
    let check = cut.check(material, passes, chips, failures, lead_error);
    Ok(if inside { check.mirrored() } else { check })
}

/// A thread block as the cut reads it: its index, lead and start angle,
/// the spindle's speed, and where the tip stands before and after it
/// (rho, z).
struct ThreadBlock {
    i: usize,
    lead: Real,
    start_deg: Real,
    rpm: Real,
    from: (Real, Real),
    to: (Real, Real),
}

/// What the cut reads at every block: the request (an internal thread's
/// external twin), the program as written and its replayed poses, the
/// section's window (from `w0`, one lead long), the blank's radii, the
/// nominal spaces, the servo's time constant.
struct Cut<'a> {
    req: &'a ThreadRequest,
    cutter: &'a ThreadCutter,
    written: AxisProgram,
    poses: Vec<Real>,
    rho: Real,
    lead: Real,
    r_a: Real,
    r_core: Real,
    w0: Real,
    spaces: Vec<Vec<[Real; 2]>>,
    nominal: MultiPolygon<Real>,
    servo: Real,
    x_axis: Option<usize>,
}

impl<'a> Cut<'a> {
    /// The program replayed, the window placed and the servo read; `rho`
    /// turns the program's radii into the twin's (-1 inside a nut).
    ///
    /// # Failures
    /// The replay; a machine that states no servo time constant.
    fn new(
        program: &AxisProgram,
        (machine, tool): (&dyn MachineKinematics, &ToolFrame),
        cutter: &'a ThreadCutter,
        req: &'a ThreadRequest,
        rho: Real,
    ) -> Result<Self, VerifyError> {
        let w = &req.section;
        let (written, _) = as_written(program);
        let poses = replay(&written, machine, tool)?;
        let (r_a, r_f) = (w.crest_diameter / 2.0, w.root_diameter / 2.0);
        let c0 = req.space_centre;
        let spaces = nominal_spaces(req, c0);
        // The carriage's servo (docs/math.md §4.2): the machine's time
        // constant and the spindle's speed as written.
        let servo = (machine.info().constants.get("servo_time_constant"))
            .copied()
            .filter(|t| *t > 0.0)
            .ok_or_else(|| {
                VerifyError::Failed(format!(
                    "machine {} states no servo_time_constant (s): the lead where the thread starts and ends cannot be checked",
                    machine.info().name
                ))
            })?;
        Ok(Self {
            req,
            cutter,
            x_axis: written.axes.iter().position(|a| a.name == "X"),
            written,
            poses,
            rho,
            lead: w.lead(),
            r_a,
            r_core: r_f - (2.0f64).min(r_f.abs() / 2.0),
            // The window starts in the middle of the crest before start
            // 0's space.
            w0: c0 - thread_middle(w)[0],
            nominal: MultiPolygon::new(spaces.iter().map(|s| poly(s)).collect()),
            spaces,
            servo,
        })
    }

    /// Where the tip stands after block `i`: (rho, z).
    fn at(&self, i: usize) -> (Real, Real) {
        (self.rho * self.poses[6 * i], self.poses[6 * i + 2])
    }

    /// Block `i`'s name as the program numbers it.
    fn name(&self, i: usize) -> String {
        block_name(&self.written, i)
    }

    /// A move other than a thread block must keep clear of the blank, but
    /// for the retract straight out of the groove a thread block just cut:
    /// why not, where it does not.
    fn clear_move(
        &self,
        i: usize,
        (r0, z0): (Real, Real),
        (r1, z1): (Real, Real),
    ) -> Option<String> {
        let (r_a, length) = (self.r_a, self.req.length);
        let low = r0.min(r1);
        let out_of_groove = matches!(self.written.blocks[i - 1].motion, Motion::Thread { .. })
            && z0 == z1
            && r1 >= r0;
        if low >= r_a - crate::tolerance::SAME_LENGTH || out_of_groove {
            return None;
        }
        // The cutter's profile reaches its height above the tip; what
        // holds it is the collision check's.
        let half = self.cutter.width_at((r_a - low).min(self.cutter.height)) / 2.0;
        let (lo, hi) = (z0.min(z1), z0.max(z1));
        (hi > -length - half && lo < half).then(|| format!(
            "{}: a move that is not a thread block crosses the blank (tip at diameter {:.3}, z from {:.3} to {:.3}; the worm runs from z = {:.3} to 0 at diameter {:.3})",
            self.name(i), diameter(low), z0, z1, -length, diameter(r_a)
        ))
    }

    /// What is wrong with a thread block before it cuts: a taper, a lead
    /// not the thread's, a block not over the whole thread, a helix of the
    /// other hand; the lead's error over the thread's length; and whether
    /// it is simulated (not a taper, over the whole thread).
    fn block_faults(&self, b: &ThreadBlock) -> (Vec<String>, Real, bool) {
        let (req, tol, w) = (self.req, &self.req.tolerances, &self.req.section);
        let ((r0, z0), (r1, z1)) = (b.from, b.to);
        let (name, l, lead) = (self.name(b.i), b.lead, self.lead);
        if (r1 - r0).abs() > crate::tolerance::SAME_LENGTH {
            return (vec![format!(
                "{name}: a thread block that changes X (from {:.4} to {:.4}) cuts a taper, not a worm",
                diameter(r0),
                diameter(r1)
            )], 0.0, false);
        }
        let mut faults = Vec::new();
        let err_len = (l - lead).abs() * req.length / lead;
        if err_len > tol.position {
            faults.push(format!(
                "{name}: lead {l} mm is not the worm's {lead:.6} mm: {err_len:.4} mm out over the thread's {} mm (tolerance {} mm)",
                req.length, tol.position
            ));
        }
        if z0.min(z1) > -req.length || z0.max(z1) < 0.0 {
            faults.push(format!(
                "{name}: the thread block runs from z = {z0:.3} to {z1:.3}, not over the whole thread (z from {:.3} to 0)",
                -req.length
            ));
            return (faults, err_len, false);
        }
        // The spindle turns as M3 (the lint refuses any other word): a
        // block towards -Z cuts a right-hand helix, towards +Z a left.
        // Simulated still: the axial section at angle 0 is cut the same,
        // and a failed run shows every pass.
        let towards_chuck = z1 < z0;
        let cuts = if towards_chuck {
            Hand::Right
        } else {
            Hand::Left
        };
        if cuts != w.hand {
            faults.push(format!(
                "{name}: a thread block towards {} with the spindle in M3 cuts a {}-hand helix, and the thread is {}-handed (cut it towards {})",
                if towards_chuck { "-Z (the chuck)" } else { "+Z (the tailstock)" },
                cuts.name(),
                w.hand.name(),
                if towards_chuck { "+Z" } else { "-Z" },
            ));
        }
        (faults, err_len, true)
    }

    /// The thread block `b` cut from `material`: its pass, its chip's
    /// outlines, and what is wrong with it (a gouge beyond the nominal
    /// space, the lead off where the cutter meets and leaves the thread).
    fn pass(
        &self,
        b: &ThreadBlock,
        material: &mut MultiPolygon<Real>,
    ) -> (SimulatedPass, Vec<Vec<[Real; 2]>>, Vec<String>) {
        let (w, tol) = (&self.req.section, &self.req.tolerances);
        let ((_, z0), (r1, z1)) = (b.from, b.to);
        let dir = (z1 - z0).signum();
        let z_sec = z0 - dir * b.lead * b.start_deg / 360.0;
        let c0 = self.req.space_centre;
        let k_raw = ((z_sec - c0) / w.pitch).round();
        let start = w.hand.start_place(k_raw as i64, w.starts);
        let offset = z_sec - (c0 + k_raw * w.pitch);
        let zw = self.w0 + (z_sec - self.w0).rem_euclid(self.lead);
        let chip = self.chip(material, zw, r1);
        let (gouge, worst) = self.gouge(&chip.chip);
        let x = (self.x_axis)
            .map(|k| self.written.blocks[b.i].values[k])
            .unwrap_or(diameter(r1));
        let mut faults = Vec::new();
        if gouge > tol.form {
            faults.push(format!(
                "{}: the cutter cuts {:.4} mm beyond the nominal thread space (at z = {:.3} in the section, diameter {:.3}; X{x:.3}, offset {offset:.4} mm from start {}'s space; tolerance {} mm)",
                self.name(b.i), gouge, worst[0], diameter(worst[1]), start + 1, tol.form
            ));
        }
        let ends = self.ends(b, &mut faults);
        let outlines = (chip.chip.0.iter())
            .map(|p| p.exterior().coords().map(|c| [c.x, c.y]).collect())
            .collect();
        *material = material.difference(&chip.cutter);
        let pass = SimulatedPass {
            block: b.i + 1,
            name: self.name(b.i),
            start,
            x,
            offset,
            chip_area: chip.area,
            left_area: chip.left_area,
            right_area: chip.area - chip.left_area,
            gouge,
            thickness: chip.thickness,
            approach_mm: ends[0].0,
            face_lead_error: ends[0].1,
            runout_mm: ends[1].0,
            end_lead_error: ends[1].1,
        };
        (pass, outlines, faults)
    }

    /// The chip the cutter, its tip at `r1` and placed at `zw` in the
    /// window (with its copies one lead either side), takes of `material`.
    fn chip(&self, material: &MultiPolygon<Real>, zw: Real, r1: Real) -> Chip {
        let lead = self.lead;
        let section = self.cutter.section(self.r_a + 1.0 - r1);
        let placed = |dz: Real| -> Polygon<Real> {
            poly(
                &(section.iter())
                    .map(|p| [p[0] + zw + dz, p[1] + r1])
                    .collect::<Vec<_>>(),
            )
        };
        let cutter = MultiPolygon::new(vec![placed(-lead), placed(0.0), placed(lead)]);
        let chip = material.intersection(&cutter);
        // The chip's thickness: the farthest its outline stands inside the
        // cutter's (the depth of the cut, normal to the edge that takes it).
        let n = section.len();
        let inside = |c: &geo::Coord<Real>, dz: Real| {
            let at = |q: [Real; 2]| [q[0] + zw + dz, q[1] + r1];
            (0..n)
                .map(|j| segment_distance([c.x, c.y], at(section[j]), at(section[(j + 1) % n])))
                .fold(Real::INFINITY, Real::min)
        };
        let thickness = (chip.0.iter())
            .flat_map(|p| p.exterior().coords())
            .map(|c| {
                [-lead, 0.0, lead]
                    .iter()
                    .map(|dz| inside(c, *dz))
                    .fold(Real::INFINITY, Real::min)
            })
            .fold(0.0, Real::max);
        let left_side = MultiPolygon::new(
            [-lead, 0.0, lead]
                .iter()
                .map(|dz| {
                    rect(
                        zw + dz - lead / 2.0,
                        zw + dz,
                        self.r_core - 1.0,
                        self.r_a + 2.0,
                    )
                })
                .collect(),
        );
        Chip {
            area: chip.unsigned_area(),
            left_area: chip.intersection(&left_side).unsigned_area(),
            thickness,
            chip,
            cutter,
        }
    }

    /// How far `chip` reaches beyond the nominal spaces, and where.
    fn gouge(&self, chip: &MultiPolygon<Real>) -> (Real, [Real; 2]) {
        let beyond = chip.difference(&self.nominal);
        let mut gouge: Real = 0.0;
        let mut worst = [0.0; 2];
        if beyond.unsigned_area() <= crate::tolerance::NO_AREA {
            return (gouge, worst);
        }
        for (p, _) in edges(&beyond) {
            let q = [p.x, p.y];
            let d = (self.spaces.iter())
                .map(|s| {
                    (0..s.len())
                        .map(|j| segment_distance(q, s[j], s[(j + 1) % s.len()]))
                        .fold(Real::INFINITY, Real::min)
                })
                .fold(Real::INFINITY, Real::min);
            if d > gouge {
                gouge = d;
                worst = q;
            }
        }
        (gouge, worst)
    }

    /// Where the cutting edges at the blank's radius meet the thread's
    /// near end and leave its far end, and the servo's lead error there
    /// (approach, run-out); a lead beyond its tolerance added to `faults`.
    fn ends(&self, b: &ThreadBlock, faults: &mut Vec<String>) -> [(Real, Real); 2] {
        let (req, tol) = (self.req, &self.req.tolerances);
        let ((r1, z0), (_, z1)) = ((b.to.0, b.from.1), b.to);
        let [left, right] = self.cutter.extent_at(self.r_a - r1);
        let (approach_mm, runout_mm) = if z1 < z0 {
            (z0 - left, -req.length - (z1 + right))
        } else {
            (-req.length - (z0 + right), z1 - left)
        };
        let (servo, v) = (self.servo, b.lead * b.rpm / 60.0);
        let face_lead_error = crate::families::thread::approach_error(servo, v, approach_mm);
        let end_lead_error = crate::families::thread::runout_error(servo, v, runout_mm);
        for (what, e, length, minimum, from) in [
            (
                "where the leading cutting edge meets the worm's face",
                face_lead_error,
                approach_mm,
                crate::families::thread::approach_length(servo, v, tol.lead),
                "start",
            ),
            (
                "where the trailing cutting edge leaves the thread's far end",
                end_lead_error,
                runout_mm,
                crate::families::thread::runout_length(servo, v) * (1.0 - tol.lead),
                "end",
            ),
        ] {
            if e > tol.lead {
                faults.push(format!(
                    "{}: the lead is {:.2}% off {what} ({:.3} mm from the block's {from}; at least {:.3} mm keeps it within the allowed {}%)",
                    self.name(b.i),
                    100.0 * e,
                    length,
                    minimum,
                    100.0 * tol.lead
                ));
            }
        }
        [(approach_mm, face_lead_error), (runout_mm, end_lead_error)]
    }

    /// The check of the finished `material`: every pass, the starts
    /// measured, the nominal flanks, the limits and the figures over the
    /// passes.
    fn check(
        &self,
        material: MultiPolygon<Real>,
        passes: Vec<SimulatedPass>,
        chips: Vec<Vec<Vec<[Real; 2]>>>,
        mut failures: Vec<Finding>,
        lead_error: Real,
    ) -> ThreadCheck {
        let (req, w) = (self.req, &self.req.section);
        let (starts, unmeasured) = measure(&material, req, self.cutter, lead_error);
        let nominal_flanks = nominal_flanks_deg(w, &flank_radii(w, req.flank_margin, self.cutter));
        failures.extend(unmeasured);
        ThreadCheck {
            failures,
            nominal: (
                w.pitch - w.space_at_pitch,
                w.root_diameter,
                w.crest_diameter,
            ),
            nominal_alpha_deg: nominal_flanks[0],
            nominal_flanks_deg: nominal_flanks,
            limits: req.limits.clone(),
            wire: req.limits.as_ref().and(w.best_wire()),
            over_wires_limits: req.limits.as_ref().and_then(|l| {
                let wire = w.best_wire()?;
                let m = |d: Real| w.over_wires(wire, d);
                let (a, b) = (m(l.pitch_diameter.min)?, m(l.pitch_diameter.max)?);
                Some([a.min(b), a.max(b)])
            }),
            removed_area: passes.iter().map(|p| p.chip_area).sum(),
            flank_loads: [
                passes.iter().map(|p| p.left_area).sum(),
                passes.iter().map(|p| p.right_area).sum(),
            ],
            passes,
            starts,
            space_area: Real::from(w.starts) * w.space_area(),
            lead_error,
            tolerances: req.tolerances,
            chips,
            section: material,
            window: (self.w0, self.lead),
            internal: false,
            hand: w.hand,
        }
    }
}

/// What one thread block cuts: the cutter placed (with its copies), the
/// chip, its area, the share on the left flank and its thickness.
struct Chip {
    cutter: MultiPolygon<Real>,
    chip: MultiPolygon<Real>,
    area: Real,
    left_area: Real,
    thickness: Real,
}
