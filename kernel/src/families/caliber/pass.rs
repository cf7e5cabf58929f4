//! A pass of the wheel along the groove (docs/math.md §3.4, §3.5): the exact pose
//! of the torus at each block, within what the machine reaches, at a
//! uniform step of the roll's turn, and how far the seed's first-order
//! model is from it.

use super::groove::{Groove, GrooveError};
use super::pose::{exact_pose_toward, seed_pose, TorusWheel};
use crate::input::InputError;
use crate::math::{Real, Vec3};

/// An iteration whose turn (rad) moves less than this has converged to its
/// rounding: 1e-13 rad moves a point 1 m from the axis by 0.1 nm.
const TURN_STALL: Real = 1e-13;

/// Which plane the wheel's axis keeps, besides keeping the wheel's own
/// plane along the contact's trajectory (the seed's swivel, S001-11).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwivelPlane {
    /// Square to the radius through the contact: the seed's swivel about
    /// the contact's radial axis; the wheel's centre leaves the contact's
    /// plane through the roll's axis by the pressure angle's correction,
    /// which a machine with the cross axis Y carries (the Mannesmann).
    Contact,
    /// Square to the radius through the wheel's centre: what a machine
    /// without a cross axis reaches (the LZ-250, docs/math.md §3.5: its axis stays
    /// in the plane of the roll's axis and the circumferential direction
    /// at the wheel). Found by iterating the centre's angle.
    Wheel,
}

/// The wheel's pose at one block of a pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassPose {
    /// The contact's angle theta on the roll (rad).
    pub theta: Real,
    /// The contact point on the groove.
    pub contact: Vec3,
    /// The groove's normal there, out of the material.
    pub normal: Vec3,
    /// The wheel touching the groove there.
    pub wheel: TorusWheel,
    /// The roll's turn that brings the pose to the machine's plane (rad):
    /// the contact's theta ([`SwivelPlane::Contact`]) or the wheel
    /// centre's angle ([`SwivelPlane::Wheel`]); uniform along a pass.
    pub turn: Real,
    /// The distance between the seed's wheel centre and this one (mm).
    pub seed_centre_error: Real,
    /// The angle between the seed's wheel axis and this one (rad).
    pub seed_axis_error: Real,
}

/// How near a block's turn is solved to the step's (rad): 2.5e-8 mm at
/// 250 mm, far below the program's resolution.
pub const TURN_TOLERANCE: Real = 1e-10;

/// The largest number of blocks one pass may have.
pub const MAX_PASS_BLOCKS: usize = 1_000_000;

/// The unit radial direction at angle `t` about the roll's axis.
fn radial(t: Real) -> Vec3 {
    Vec3::new(t.cos(), t.sin(), 0.0)
}

/// The exact pose at the contact `(theta, psi)` for a wheel of largest
/// radius `r_k0` and rounding `r_k` keeping `plane`.
///
/// # Failures
/// `theta` outside the tables; a trajectory along the radius.
pub fn pose_at(
    groove: &Groove,
    theta: Real,
    psi: Real,
    r_k0: Real,
    r_k: Real,
    plane: SwivelPlane,
) -> Result<PassPose, GrooveError> {
    with_seed(groove, psi, exact_at(groove, theta, psi, r_k0, r_k, plane)?)
}

/// [`pose_at`] without the seed's comparison (its two errors NaN).
fn exact_at(
    groove: &Groove,
    theta: Real,
    psi: Real,
    r_k0: Real,
    r_k: Real,
    plane: SwivelPlane,
) -> Result<PassPose, GrooveError> {
    // The contact, the normal and the contact's trajectory along the pass.
    let (p, n, tangent) = groove.frame(theta, psi)?;
    let axis_for = |turn: Real| -> Result<Vec3, GrooveError> {
        let w = tangent.cross(&radial(turn));
        if !(w.norm() > crate::tolerance::SAME_RATIO * tangent.norm()) {
            return Err(InputError::out_of_range(
                "the contact's trajectory against the radius (sine of the angle)",
                w.norm() / tangent.norm(),
                "the pass must run round the roll",
            )
            .into());
        }
        let w = w.normalize();
        Ok(if w.z < 0.0 { -w } else { w })
    };
    // At the groove's edge the normal lies along the axis: the wheel's
    // centre then stands out along the radius at the turn.
    let place = |w: Vec3, turn: Real| {
        exact_pose_toward(p, n, w, r_k0, r_k, radial(turn)).map_err(GrooveError::from)
    };
    let (wheel, turn) = match plane {
        SwivelPlane::Contact => (place(axis_for(theta)?, theta)?, theta),
        SwivelPlane::Wheel => {
            let mut turn = theta;
            let mut wheel = place(axis_for(turn)?, turn)?;
            for _ in 0..50 {
                let next = wheel.centre.y.atan2(wheel.centre.x);
                // Unwrapped near the contact's angle.
                let next = theta + crate::math::wrap_angle(next - theta);
                let moved = (next - turn).abs();
                turn = next;
                wheel = place(axis_for(turn)?, turn)?;
                if moved < TURN_STALL {
                    break;
                }
            }
            (wheel, turn)
        }
    };
    Ok(PassPose {
        theta,
        contact: p,
        normal: n,
        wheel,
        turn,
        seed_centre_error: Real::NAN,
        seed_axis_error: Real::NAN,
    })
}

/// `pose` with how far the seed's model is from it.
fn with_seed(groove: &Groove, psi: Real, pose: PassPose) -> Result<PassPose, GrooveError> {
    let (theta, wheel) = (pose.theta, pose.wheel);
    let (r_k0, r_k) = (wheel.major + wheel.minor, wheel.minor);
    // The seed's centre and axis (docs/math.md §3.4): the rounding centre along
    // the roll's axis at x_k (swivelled), the wheel's centre on the
    // equidistant R_e at theta - dtheta + dtheta_1 (the centre lies on the
    // outward normal of the polar curve R_m, behind the contact where R_m
    // grows), its axis swivelled by epsilon from the roll's axis toward
    // the turn that keeps it square to the trajectory.
    let s = seed_pose(groove, theta, psi, r_k0, r_k)?;
    let t_s = theta - s.dtheta + s.dtheta_1;
    let centre = Vec3::new(s.r_e * t_s.cos(), s.r_e * t_s.sin(), s.x_k_swivelled);
    let along = Vec3::new(-theta.sin(), theta.cos(), 0.0);
    let seed_axis = s.epsilon.cos() * Vec3::z() - s.epsilon.sin() * along;
    Ok(PassPose {
        seed_centre_error: (centre - wheel.centre).norm(),
        seed_axis_error: seed_axis.dot(&wheel.axis).clamp(-1.0, 1.0).acos(),
        ..pose
    })
}

/// The poses of the pass at `psi` (rad) over the whole groove, at a
/// uniform step `step` (rad) of the roll's turn (the last step shorter if
/// the range is not a whole number of steps): each the exact pose
/// ([`pose_at`]) whose turn is the step's, found on the contact's theta by
/// the secant method within a bracket (Illinois, to `TURN_TOLERANCE`), not interpolated (docs/math.md §3.4's
/// re-interpolation, done exactly).
///
/// # Failures
/// A step not positive or of more than [`MAX_PASS_BLOCKS`] blocks; the
/// wheel's radii; a turn the contact cannot reach within the tables.
pub fn pass_poses(
    groove: &Groove,
    psi: Real,
    step: Real,
    r_k0: Real,
    r_k: Real,
    plane: SwivelPlane,
) -> Result<Vec<PassPose>, GrooveError> {
    crate::math::positive("theta step of the program (rad)", step)?;
    let (lo, hi) = groove.theta_range();
    let at = |t: Real| exact_at(groove, t, psi, r_k0, r_k, plane);
    let (first, last) = (at(lo)?, at(hi)?);
    let span = last.turn - first.turn;
    let steps = (span / step - crate::tolerance::COUNT_SLACK)
        .ceil()
        .max(1.0);
    if !(steps <= MAX_PASS_BLOCKS as Real) {
        return Err(InputError::out_of_range(
            "blocks of one pass (the groove's turn over the theta step)",
            steps,
            format!("at most {MAX_PASS_BLOCKS}: a larger step"),
        )
        .into());
    }
    let steps = steps as usize;
    let mut poses = Vec::with_capacity(steps + 1);
    poses.push(with_seed(groove, psi, first)?);
    for k in 1..steps {
        let target = first.turn + step * k as Real;
        let prev: PassPose = *poses.last().expect("the first pose is in");
        let out_of_reach = |why: &str| -> GrooveError {
            InputError::out_of_range(
                "the roll's turn a pass reaches (deg)",
                target.to_degrees(),
                format!("{why} at psi = {:.3} deg", psi.to_degrees()),
            )
            .into()
        };
        // The turn runs ahead of theta by a nearly constant amount: start
        // from the last pose's offset.
        let guess = (target - (prev.turn - prev.theta)).clamp(lo, hi);
        let (a, b) = bracket(&at, prev, guess, target, step, hi)?;
        if !(b.1.turn >= target - crate::tolerance::ROUNDING) {
            return Err(out_of_reach(
                "within the turns the groove's tables give the wheel",
            ));
        }
        let best = illinois(&at, a, b, target)?;
        if !((best.turn - target).abs() < 10.0 * TURN_TOLERANCE) {
            return Err(out_of_reach(
                "a turn the wheel reaches (the turn is not monotone in theta there)",
            ));
        }
        poses.push(with_seed(groove, psi, best)?);
    }
    poses.push(with_seed(groove, psi, last)?);
    Ok(poses)
}

/// A pose at theta with theta itself, an end of a bracket.
type End = (Real, PassPose);

/// A bracket of theta round the `target` turn: from the previous pose and
/// the `guess`, widened from `step` doubling, up to `hi`; where the turn
/// never reaches the target the upper end is `hi`'s, short of it.
fn bracket(
    at: &impl Fn(Real) -> Result<PassPose, GrooveError>,
    prev: PassPose,
    guess: Real,
    target: Real,
    step: Real,
    hi: Real,
) -> Result<(End, End), GrooveError> {
    let mut a = (prev.theta, prev);
    let mut b = (guess.max(prev.theta), at(guess.max(prev.theta))?);
    let mut widen = step;
    while b.1.turn < target && b.0 < hi {
        a = b;
        let t = (b.0 + widen).min(hi);
        b = (t, at(t)?);
        widen *= 2.0;
    }
    Ok((a, b))
}

/// The pose whose turn is `target` within [`TURN_TOLERANCE`], by the
/// secant method kept inside the bracket `a`..`b` (Illinois: an end kept
/// twice has its value halved, so that the bracket shrinks from both
/// sides); the last pose tried where it stalls.
fn illinois(
    at: &impl Fn(Real) -> Result<PassPose, GrooveError>,
    mut a: End,
    mut b: End,
    target: Real,
) -> Result<PassPose, GrooveError> {
    let mut best = if (a.1.turn - target).abs() < (b.1.turn - target).abs() {
        a.1
    } else {
        b.1
    };
    let mut side = 0;
    for _ in 0..200 {
        if (best.turn - target).abs() < TURN_TOLERANCE || b.0 - a.0 < TURN_STALL {
            break;
        }
        let span = b.1.turn - a.1.turn;
        let mut t = if span > 0.0 {
            a.0 + (target - a.1.turn) / span * (b.0 - a.0)
        } else {
            0.5 * (a.0 + b.0)
        };
        if !(t > a.0 && t < b.0) {
            t = 0.5 * (a.0 + b.0);
        }
        let c = at(t)?;
        best = c;
        if c.turn < target {
            if side == -1 {
                b.1.turn = target + 0.5 * (b.1.turn - target);
            }
            a = (t, c);
            side = -1;
        } else {
            if side == 1 {
                a.1.turn = target + 0.5 * (a.1.turn - target);
            }
            b = (t, c);
            side = 1;
        }
    }
    Ok(best)
}

/// The deepest a step-over is split: `2^20` poses at most between two
/// passes.
const MAX_STEP_OVER_DEPTH: usize = 20;

/// The wheel's poses stepping over, at the contact's `theta`, from the
/// pass at `from` to the pass at `to` (psi, rad), both ends left out: as
/// many as keep the rounding's centre within `sag` (mm) of the straight
/// move between neighbouring poses (halving the step where the middle
/// strays more). Across a concave section the straight move stands off
/// the groove, and none is needed; across a convex one, an edge's
/// rounding, it would cut a chord into it.
///
/// # Failures
/// `sag` not positive; `theta` outside the tables; the wheel's radii.
#[allow(clippy::too_many_arguments)]
pub fn step_over(
    groove: &Groove,
    theta: Real,
    (from, to): (Real, Real),
    r_k0: Real,
    r_k: Real,
    plane: SwivelPlane,
    sag: Real,
) -> Result<Vec<PassPose>, GrooveError> {
    crate::math::positive("the step-over's sag (mm)", sag)?;
    let at = |psi: Real| pose_at(groove, theta, psi, r_k0, r_k, plane);
    let mut out = Vec::new();
    split(&at, (from, at(from)?), (to, at(to)?), r_k, sag, 0, &mut out)?;
    Ok(out)
}

/// [`step_over`] between the poses `a` and `b` (psi, pose), `depth`
/// halvings in: the middle pose if the rounding's centre strays more
/// than `sag` from the straight move, each half split likewise first.
fn split(
    at: &dyn Fn(Real) -> Result<PassPose, GrooveError>,
    a: (Real, PassPose),
    b: (Real, PassPose),
    r_k: Real,
    sag: Real,
    depth: usize,
    out: &mut Vec<PassPose>,
) -> Result<(), GrooveError> {
    let m = 0.5 * (a.0 + b.0);
    let pm = at(m)?;
    let centre = |p: &PassPose| p.contact + r_k * p.normal;
    let (ca, cb, cm) = (centre(&a.1), centre(&b.1), centre(&pm));
    let chord = cb - ca;
    let v = cm - ca;
    let off = v - v.dot(&chord) / chord.norm_squared().max(crate::tolerance::TINY) * chord;
    if off.norm() <= sag || depth >= MAX_STEP_OVER_DEPTH {
        return Ok(());
    }
    split(at, a, (m, pm), r_k, sag, depth + 1, out)?;
    out.push(pm);
    split(at, (m, pm), b, r_k, sag, depth + 1, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// A groove that deepens round the roll: the pressure angle is not 0.
    fn lifting() -> Groove {
        let theta: Vec<Real> = (0..=36).map(|i| i as Real * 5.0).collect();
        let hp: Vec<Real> = theta.iter().map(|t| 24.0 - 0.05 * t).collect();
        let b: Vec<Real> = hp.iter().map(|h| 2.1 * h).collect();
        Groove::new(150.0, (&theta, &theta), &hp, &b).unwrap()
    }

    /// The least distance from the wheel, moved in a straight line (centre
    /// and axis, as the control moves the axes) through `poses`, to the
    /// groove's section at `theta` from `psi_from` to 90 deg.
    fn least_on_the_way(g: &Groove, theta: Real, psi_from: Real, poses: &[PassPose]) -> Real {
        let mut least = Real::INFINITY;
        for w in poses.windows(2) {
            for s in 0..=20 {
                let t = s as Real / 20.0;
                let mut wheel = w[0].wheel;
                wheel.centre += t * (w[1].wheel.centre - w[0].wheel.centre);
                wheel.axis =
                    (w[0].wheel.axis + t * (w[1].wheel.axis - w[0].wheel.axis)).normalize();
                for k in 0..=400 {
                    let psi = psi_from + (FRAC_PI_2 - psi_from) * k as Real / 400.0;
                    least = least.min(wheel.distance(&g.point(theta, psi).unwrap()));
                }
            }
        }
        least
    }

    /// On the edge's convex rounding a straight step-over from one pass to
    /// the next cuts a chord into it; the step-over's poses keep it within
    /// the sag asked.
    #[test]
    fn stepping_over_the_rounding_keeps_off_it() {
        let g = lifting()
            .with_edge(crate::families::caliber::EdgeKind::Rounding, &[2.0; 37])
            .unwrap();
        let (r_k0, r_k) = (125.0, 8.0);
        let (psi, _) = g.pass_angles(r_k, 1f64.to_radians(), FRAC_PI_2).unwrap();
        // Two neighbouring passes on the rounding.
        let theta = 60f64.to_radians();
        let from = g.section(theta).unwrap().edge_from();
        let j = psi.iter().position(|&p| p > from + 0.02).unwrap();
        let (a, b) = (psi[j], psi[j + 1]);
        let plane = SwivelPlane::Wheel;
        let ends = [
            pose_at(&g, theta, a, r_k0, r_k, plane).unwrap(),
            pose_at(&g, theta, b, r_k0, r_k, plane).unwrap(),
        ];
        let straight = least_on_the_way(&g, theta, from, &ends);
        let sag = 1e-3;
        assert!(
            straight < -5.0 * sag,
            "a straight step over cuts {straight} mm"
        );
        let mut poses = vec![ends[0]];
        poses.extend(step_over(&g, theta, (a, b), r_k0, r_k, plane, sag).unwrap());
        poses.push(ends[1]);
        assert!(poses.len() > 2);
        let over = least_on_the_way(&g, theta, from, &poses);
        assert!(over > -sag, "the step-over cuts {over} mm");
        // Across the concave ellipse none is needed.
        let none = step_over(
            &g,
            theta,
            (0.0, psi[psi.len() / 2 + 1]),
            r_k0,
            r_k,
            plane,
            sag,
        );
        assert!(none.unwrap().is_empty());
    }

    /// Each pose touches the groove at the contact (the torus's distance 0
    /// there, its normal the groove's), keeps the wheel's plane along the
    /// trajectory, and keeps the plane it was asked for.
    #[test]
    fn poses_touch_and_keep_their_planes() {
        let g = lifting();
        for plane in [SwivelPlane::Contact, SwivelPlane::Wheel] {
            let poses = pass_poses(&g, 0.6, 2f64.to_radians(), 100.0, 8.0, plane).unwrap();
            for p in &poses {
                assert!(p.wheel.distance(&p.contact).abs() < 1e-9);
                let c = p.contact + 8.0 * p.normal;
                // The rounding centre is r_k along the normal and on the
                // torus's centre circle.
                assert!((p.wheel.distance(&c) + 8.0).abs() < 1e-9);
                let r = match plane {
                    SwivelPlane::Contact => radial(p.theta),
                    SwivelPlane::Wheel => radial(p.wheel.centre.y.atan2(p.wheel.centre.x)),
                };
                assert!(p.wheel.axis.dot(&r).abs() < 1e-9, "{plane:?}");
            }
            // A uniform step of the turn, the ends the groove's.
            for w in poses.windows(2).take(poses.len() - 2) {
                assert!((w[1].turn - w[0].turn - 2f64.to_radians()).abs() < 1e-9);
            }
            assert_eq!(poses[0].theta, 0.0);
            assert!((poses.last().unwrap().theta - 180f64.to_radians()).abs() < 1e-12);
        }
    }

    /// At the groove's edge (psi = +-90 deg) the wall is radial and the
    /// wheel's axis lies along its normal: the pose is the wheel's side
    /// face on the wall, its centre out along the radius, continuing the
    /// poses just inside the edge.
    #[test]
    fn the_edge_is_reached_by_the_wheels_side() {
        let g = lifting();
        for plane in [SwivelPlane::Contact, SwivelPlane::Wheel] {
            for side in [1.0, -1.0] {
                let edge = side * std::f64::consts::FRAC_PI_2;
                let p = pose_at(&g, 1.0, edge, 100.0, 8.0, plane).unwrap();
                assert!(p.wheel.distance(&p.contact).abs() < 1e-9);
                let near = pose_at(&g, 1.0, edge - side * 1e-5, 100.0, 8.0, plane).unwrap();
                assert!(
                    (near.wheel.centre - p.wheel.centre).norm() < 1e-3,
                    "{plane:?} {side}: {:?} against {:?}",
                    p.wheel.centre,
                    near.wheel.centre
                );
            }
        }
    }

    /// On a groove of constant depth the seed's model is the exact pose:
    /// no pressure angle, no swivel at the bottom.
    #[test]
    fn the_seed_is_exact_where_the_groove_does_not_lift() {
        let theta = [0.0, 90.0, 180.0];
        let g = Groove::new(150.0, (&theta, &theta), &[14.1; 3], &[29.0; 3]).unwrap();
        for psi in [0.0, 0.4, -0.9] {
            let p = pose_at(&g, 1.0, psi, 100.0, 8.0, SwivelPlane::Wheel).unwrap();
            assert!(p.seed_centre_error < 1e-6, "{}", p.seed_centre_error);
            assert!(p.seed_axis_error < 1e-6);
        }
        // Where it lifts, the seed's first-order model differs, a little.
        let p = pose_at(&lifting(), 1.0, 0.6, 100.0, 8.0, SwivelPlane::Contact).unwrap();
        assert!(
            p.seed_centre_error > 1e-4 && p.seed_centre_error < 2.0,
            "{p:?}"
        );
    }
}
