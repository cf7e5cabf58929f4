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
    let rho = req.section.opening();
    let twin;
    let req = if inside {
        twin = req.mirrored();
        &twin
    } else {
        req
    };
    let w = &req.section;
    let tol = &req.tolerances;
    let fail = |m: String| VerifyError::Failed(m);
    let (written, _) = as_written(program);
    let poses = replay(&written, machine, tool)?;
    let at = |i: usize| (rho * poses[6 * i], poses[6 * i + 2]);
    let lead = w.lead();
    let (px, z1) = (w.pitch, w.starts);
    let (r_a, r_f) = (w.crest_diameter / 2.0, w.root_diameter / 2.0);
    let r_core = r_f - (2.0f64).min(r_f.abs() / 2.0);
    let c0 = req.space_centre;
    // The window starts in the middle of the crest before start 0's
    // space.
    let w0 = c0 - thread_middle(w)[0];
    let mut material = MultiPolygon::new(vec![rect(w0, w0 + lead, r_core, r_a)]);
    let spaces = nominal_spaces(req, c0);
    let nominal = MultiPolygon::new(spaces.iter().map(|s| poly(s)).collect());
    let mut passes = Vec::new();
    let mut chips = Vec::new();
    let mut lead_error: Real = 0.0;
    let x_axis = written.axes.iter().position(|a| a.name == "X");
    // The carriage's servo (docs/math.md §4.2): the machine's time constant and
    // the spindle's speed as written.
    let servo = machine
        .info()
        .constants
        .get("servo_time_constant")
        .copied()
        .filter(|t| *t > 0.0)
        .ok_or_else(|| {
            fail(format!(
                "machine {} states no servo_time_constant (s): the lead where the thread starts and ends cannot be checked",
                machine.info().name
            ))
        })?;
    // What fails is found and the simulation goes on, so that a failed run
    // shows every pass and the profile it leaves.
    let mut failures: Vec<Finding> = Vec::new();
    let mut found = |i: usize, m: String| {
        failures
            .push(Finding::new("verification", fail(m).to_string()).at(i, block_name(&written, i)));
    };
    let mut ticker = crate::budget::Ticker::new("the thread's simulation", 16);
    let speeds: Vec<Real> = crate::program::spindle_speeds(&written).collect();
    for i in 1..written.blocks.len() {
        ticker.tick()?;
        let (b, rpm) = (&written.blocks[i], speeds[i]);
        let name = || block_name(&written, i);
        let ((r0, z0), (r1, z1e)) = (at(i - 1), at(i));
        let Motion::Thread { lead: l, start_deg } = b.motion else {
            // Any other move must keep clear of the blank, but for the
            // retract straight out of the groove a thread block just cut.
            let low = r0.min(r1);
            let out_of_groove = matches!(written.blocks[i - 1].motion, Motion::Thread { .. })
                && z0 == z1e
                && r1 >= r0;
            if low < r_a - crate::tolerance::SAME_LENGTH && !out_of_groove {
                // The cutter's profile reaches its height above the tip; what
                // holds it is the collision check's.
                let half = cutter.width_at((r_a - low).min(cutter.height)) / 2.0;
                let (lo, hi) = (z0.min(z1e), z0.max(z1e));
                if hi > -req.length - half && lo < half {
                    found(i, format!(
                        "{}: a move that is not a thread block crosses the blank (tip at diameter {:.3}, z from {:.3} to {:.3}; the worm runs from z = {:.3} to 0 at diameter {:.3})",
                        name(), diameter(low), z0, z1e, -req.length, diameter(r_a)
                    ));
                }
            }
            continue;
        };
        if (r1 - r0).abs() > crate::tolerance::SAME_LENGTH {
            found(
                i,
                format!(
                    "{}: a thread block that changes X (from {:.4} to {:.4}) cuts a taper, not a worm",
                    name(),
                    diameter(r0),
                    diameter(r1)
                ),
            );
            continue;
        }
        let err_len = (l - lead).abs() * req.length / lead;
        lead_error = lead_error.max(err_len);
        if err_len > tol.position {
            found(i, format!(
                "{}: lead {l} mm is not the worm's {lead:.6} mm: {err_len:.4} mm out over the thread's {} mm (tolerance {} mm)",
                name(), req.length, tol.position
            ));
        }
        if z0.min(z1e) > -req.length || z0.max(z1e) < 0.0 {
            found(
                i,
                format!(
                    "{}: the thread block runs from z = {z0:.3} to {z1e:.3}, not over the whole thread (z from {:.3} to 0)",
                    name(),
                    -req.length
                ),
            );
            continue;
        }
        // The spindle turns as M3 (the lint refuses any other word): a
        // block towards -Z cuts a right-hand helix, towards +Z a left.
        let dir = (z1e - z0).signum();
        let cuts = if dir < 0.0 { Hand::Right } else { Hand::Left };
        if cuts != w.hand {
            found(i, format!(
                "{}: a thread block towards {} with the spindle in M3 cuts a {}-hand helix, and the thread is {}-handed (cut it towards {})",
                name(),
                if dir < 0.0 { "-Z (the chuck)" } else { "+Z (the tailstock)" },
                cuts.name(),
                w.hand.name(),
                if dir < 0.0 { "+Z" } else { "-Z" },
            ));
            // Simulated still: the axial section at angle 0 is cut the
            // same, and a failed run shows every pass.
        }
        let z_sec = z0 - dir * l * start_deg / 360.0;
        let k_raw = ((z_sec - c0) / px).round();
        let start = w.hand.start_place(k_raw as i64, z1);
        let offset = z_sec - (c0 + k_raw * px);
        let zw = w0 + (z_sec - w0).rem_euclid(lead);
        let section = cutter.section(r_a + 1.0 - r1);
        let placed = |dz: Real| -> Polygon<Real> {
            poly(
                &section
                    .iter()
                    .map(|p| [p[0] + zw + dz, p[1] + r1])
                    .collect::<Vec<_>>(),
            )
        };
        let cutter_mp = MultiPolygon::new(vec![placed(-lead), placed(0.0), placed(lead)]);
        let chip = material.intersection(&cutter_mp);
        let chip_area = chip.unsigned_area();
        // The chip's thickness: the farthest its outline stands inside the
        // cutter's (the depth of the cut, normal to the edge that takes it).
        let thickness = chip
            .0
            .iter()
            .flat_map(|p| p.exterior().coords())
            .map(|c| {
                [-lead, 0.0, lead]
                    .iter()
                    .map(|dz| {
                        let n = section.len();
                        (0..n)
                            .map(|j| {
                                let at = |q: [Real; 2]| [q[0] + zw + dz, q[1] + r1];
                                segment_distance(
                                    [c.x, c.y],
                                    at(section[j]),
                                    at(section[(j + 1) % n]),
                                )
                            })
                            .fold(Real::INFINITY, Real::min)
                    })
                    .fold(Real::INFINITY, Real::min)
            })
            .fold(0.0, Real::max);
        let left_side = MultiPolygon::new(
            [-lead, 0.0, lead]
                .iter()
                .map(|dz| rect(zw + dz - lead / 2.0, zw + dz, r_core - 1.0, r_a + 2.0))
                .collect(),
        );
        let left_area = chip.intersection(&left_side).unsigned_area();
        let beyond = chip.difference(&nominal);
        let mut gouge: Real = 0.0;
        let mut worst = [0.0; 2];
        if beyond.unsigned_area() > crate::tolerance::NO_AREA {
            for (p, _) in edges(&beyond) {
                let q = [p.x, p.y];
                let d = spaces
                    .iter()
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
        }
        let x = x_axis.map(|k| b.values[k]).unwrap_or(diameter(r1));
        if gouge > tol.form {
            found(i, format!(
                "{}: the cutter cuts {:.4} mm beyond the nominal thread space (at z = {:.3} in the section, diameter {:.3}; X{x:.3}, offset {offset:.4} mm from start {}'s space; tolerance {} mm)",
                name(), gouge, worst[0], diameter(worst[1]), start + 1, tol.form
            ));
        }
        // Where the cutting edges at the blank's radius meet the thread's
        // near end and leave its far end: the servo's lead error there.
        let [left, right] = cutter.extent_at(r_a - r1);
        let (approach_mm, runout_mm) = if dir < 0.0 {
            (z0 - left, -req.length - (z1e + right))
        } else {
            (-req.length - (z0 + right), z1e - left)
        };
        let v = l * rpm / 60.0;
        let face_lead_error = crate::families::thread::approach_error(servo, v, approach_mm);
        let end_lead_error = crate::families::thread::runout_error(servo, v, runout_mm);
        for (what, e, length, minimum) in [
            (
                "where the leading cutting edge meets the worm's face",
                face_lead_error,
                approach_mm,
                crate::families::thread::approach_length(servo, v, tol.lead),
            ),
            (
                "where the trailing cutting edge leaves the thread's far end",
                end_lead_error,
                runout_mm,
                crate::families::thread::runout_length(servo, v) * (1.0 - tol.lead),
            ),
        ] {
            if e > tol.lead {
                found(i, format!(
                    "{}: the lead is {:.2}% off {what} ({:.3} mm from the block's {}; at least {:.3} mm keeps it within the allowed {}%)",
                    name(),
                    100.0 * e,
                    length,
                    if length == approach_mm { "start" } else { "end" },
                    minimum,
                    100.0 * tol.lead
                ));
            }
        }
        chips.push(
            chip.0
                .iter()
                .map(|p| p.exterior().coords().map(|c| [c.x, c.y]).collect())
                .collect(),
        );
        material = material.difference(&cutter_mp);
        passes.push(SimulatedPass {
            block: i + 1,
            name: name(),
            start,
            x,
            offset,
            chip_area,
            left_area,
            right_area: chip_area - left_area,
            gouge,
            thickness,
            approach_mm,
            face_lead_error,
            runout_mm,
            end_lead_error,
        });
    }
    if passes.is_empty() {
        return Err(VerifyError::NoCuttingPass);
    }
    let (starts, unmeasured) = measure(&material, req, cutter);
    let nominal_flanks = nominal_flanks_deg(w, &flank_radii(w, req.flank_margin, cutter));
    failures.extend(unmeasured);
    let check = ThreadCheck {
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
        space_area: Real::from(z1) * w.space_area(),
        lead_error,
        tolerances: *tol,
        chips,
        section: material,
        window: (w0, lead),
        internal: false,
        hand: w.hand,
    };
    Ok(if inside { check.mirrored() } else { check })
}
