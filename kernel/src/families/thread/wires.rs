//! The measurement over wires (an external thread's three wires) and
//! between balls (an internal thread's two), as the wires and balls rest
//! on the helicoid: exactly, for any straight flanks, any lead.
//!
//! A wire lies along the space at the lead angle of the pitch cylinder,
//! its axis in the plane parallel to the measuring anvils (the placing of
//! ASME B1.2's appendix on wire measurement); a ball sits at a point. The
//! body rests where it touches both flanks of the helicoidal space: each
//! of its surface points, carried back along the helix into the axial
//! section through its centre (`z - lead * theta / 2 pi`), must stay inside
//! the section's space, and it touches a flank where the least such
//! margin is zero. The opposite wire or ball rests the same, one half-turn
//! on (the helicoid is the same after a half-turn and half a lead), so `M`
//! is twice the centre's radius plus (over wires) or less (between balls)
//! the body's diameter. A left-hand thread is a right-hand one seen in a
//! mirror through its axis: the same axial section, the same `M`.
//!
//! [`lead_corrected`] is ASME B1.2's formula for symmetric flanks: the
//! axial section's `M` plus `w/2 tan^2(lambda) cos(a) cot(a)` (`a` the
//! flank's half-angle, `lambda` the lead angle at the pitch diameter). It
//! is that placing's series to second order: the exact rest differs from
//! it by 0.02 um on a Tr40x7 and 0.3 um on a Tr40x14(P7).
//!
//! Hand-written: a two-unknown search over a body's surface; no crate
//! measures threads.

use crate::math::Real;
use crate::tolerance::{DERIVATIVE_STEP, ROUNDING, SAME_LENGTH};
use std::f64::consts::PI;

/// A space's flanks in the axial section through the body's centre, as
/// lines `z = a + b r` over the true radius: the flank towards -Z (the
/// space on its +Z side), the flank towards +Z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Space {
    /// The -Z flank's line `[a, b]`.
    pub left: [Real; 2],
    /// The +Z flank's line `[a, b]`.
    pub right: [Real; 2],
    /// An internal thread's space (opening towards the axis), measured
    /// between balls; an external one's over wires.
    pub internal: bool,
    /// The lead (mm per turn), positive for either hand.
    pub lead: Real,
}

/// Where a body rests in a space: its centre and where it touches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rest {
    /// The measurement over wires, or between balls (mm).
    pub m: Real,
    /// The centre's radius and axial place in the section (mm).
    pub centre: [Real; 2],
    /// The radii of its contacts with the -Z and the +Z flank (mm).
    pub contacts: [Real; 2],
}

/// The grid the search over a body's surface starts from, per parameter.
const GRID: usize = 24;
/// How many times the window round the grid's best is shrunk by four: the
/// window ends below 1e-6 of the body's size, the margin (quadratic in
/// the place near its least) below 1e-12 of it.
const REFINEMENTS: usize = 10;
/// The Newton steps allowed: the margins are nearly linear in the centre
/// (the axial section's rest is off by microns), so four or five reach
/// `SAME_LENGTH`.
const NEWTON_STEPS: usize = 12;

/// The body's surface point at parameters `(u, v)`.
type Surface<'a> = &'a dyn Fn(Real, Real) -> [Real; 3];

/// The least margin of a body's surface to one flank (each point carried
/// back into the axial section at angle 0, its distance inside the space
/// along the axis; negative into the material) and the radius of the
/// point where it is least. `domain` bounds the surface's parameters.
fn margin(
    space: &Space,
    surface: Surface<'_>,
    domain: [(Real, Real); 2],
    left: bool,
) -> (Real, Real) {
    let inside = |p: [Real; 3]| {
        let r = p[0].hypot(p[1]);
        let z = p[2] - space.lead * p[1].atan2(p[0]) / (2.0 * PI);
        let m = if left {
            z - (space.left[0] + space.left[1] * r)
        } else {
            (space.right[0] + space.right[1] * r) - z
        };
        (m, r)
    };
    let [(u0, u1), (v0, v1)] = domain;
    let (mut hu, mut hv) = ((u1 - u0) / GRID as Real, (v1 - v0) / GRID as Real);
    let mut best = (Real::INFINITY, 0.0, u0, v0);
    let consider = |u: Real, v: Real, best: &mut (Real, Real, Real, Real)| {
        let (m, r) = inside(surface(u, v));
        if m < best.0 {
            *best = (m, r, u, v);
        }
    };
    for i in 0..=GRID {
        for j in 0..=GRID {
            consider(u0 + hu * i as Real, v0 + hv * j as Real, &mut best);
        }
    }
    for _ in 0..REFINEMENTS {
        let (cu, cv) = (best.2, best.3);
        for i in 0..=8 {
            for j in 0..=8 {
                let (du, dv) = (i as Real / 4.0 - 1.0, j as Real / 4.0 - 1.0);
                consider(cu + hu * du, cv + hv * dv, &mut best);
            }
        }
        hu /= 4.0;
        hv /= 4.0;
    }
    (best.0, best.1)
}

/// The margins to both flanks of a body of diameter `wire` centred at
/// radius `x`, axial place `z0` (a wire's axis tilted by `tilt` from the
/// tangent), with the radii where each is least.
fn margins(space: &Space, wire: Real, tilt: Real, [x, z0]: [Real; 2]) -> [(Real, Real); 2] {
    let rho = wire / 2.0;
    [true, false].map(|left| {
        if space.internal {
            let ball = |u: Real, v: Real| {
                let (s, c) = u.sin_cos();
                [x + rho * s * v.cos(), rho * s * v.sin(), z0 + rho * c]
            };
            margin(space, &ball, [(0.0, PI), (-PI, PI)], left)
        } else {
            let (s, c) = tilt.sin_cos();
            // Along its axis (0, c, s), round it by (1, 0, 0) and (0, -s, c).
            let wire = |t: Real, phi: Real| {
                let (a, b) = (rho * phi.cos(), rho * phi.sin());
                [x + a, t * c - b * s, z0 + t * s + b * c]
            };
            // Its contacts lie within its diameter along its axis: farther
            // along it, the wire leaves the pitch cylinder outwards, where
            // an external space widens.
            margin(space, &wire, [(-2.0 * rho, 2.0 * rho), (-PI, PI)], left)
        }
    })
}

/// The centre in the axial section where a body of diameter `wire` stands
/// half its diameter from both flank lines, the lead left out: where the
/// exact search starts.
fn axial_rest(space: &Space, wire: Real) -> Option<[Real; 2]> {
    let ([a, b], [a2, b2]) = (space.left, space.right);
    let across = 0.5 * wire * ((1.0 + b * b).sqrt() + (1.0 + b2 * b2).sqrt());
    let spread = b2 - b;
    (spread.abs() > ROUNDING).then(|| {
        let r = (a - a2 + across) / spread;
        [r, a + b * r + 0.5 * wire * (1.0 + b * b).sqrt()]
    })
}

/// Where a body of diameter `wire` rests in `space`, a wire at the lead
/// angle of the pitch diameter `pitch_diameter`: `None` where it does not
/// touch both flanks between the radii `band` (root and crest, either
/// order), or the search does not settle.
pub fn resting(
    space: &Space,
    wire: Real,
    pitch_diameter: Real,
    band: (Real, Real),
) -> Option<Rest> {
    let tilt = (space.lead / (PI * pitch_diameter.abs())).atan();
    let mut c = axial_rest(space, wire)?;
    let f = |c: [Real; 2]| margins(space, wire, tilt, c);
    let mut at = f(c);
    let settled = |at: &[(Real, Real); 2]| at.iter().all(|m| m.0.abs() <= SAME_LENGTH);
    let mut steps = 0;
    while !settled(&at) {
        steps += 1;
        if steps > NEWTON_STEPS {
            return None;
        }
        // The Jacobian by forward differences.
        let h = DERIVATIVE_STEP;
        let (dx, dz) = (f([c[0] + h, c[1]]), f([c[0], c[1] + h]));
        let j = [
            [(dx[0].0 - at[0].0) / h, (dz[0].0 - at[0].0) / h],
            [(dx[1].0 - at[1].0) / h, (dz[1].0 - at[1].0) / h],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det.abs() <= ROUNDING {
            return None;
        }
        let (f0, f1) = (at[0].0, at[1].0);
        c = [
            c[0] - (j[1][1] * f0 - j[0][1] * f1) / det,
            c[1] - (j[0][0] * f1 - j[1][0] * f0) / det,
        ];
        at = f(c);
    }
    let (lo, hi) = (band.0.min(band.1), band.0.max(band.1));
    let contacts = [at[0].1, at[1].1];
    contacts
        .iter()
        .all(|r| (lo..=hi).contains(r))
        .then(|| Rest {
            m: 2.0 * c[0] + if space.internal { -wire } else { wire },
            centre: c,
            contacts,
        })
}

/// ASME B1.2's measurement over wires of a symmetric straight-flanked
/// thread: the axial section's `M` plus the lead-angle correction `w/2
/// tan^2(lambda) cos(a) cot(a)`, for half-angle `half_angle`, the space
/// `space_at_pitch` wide at `pitch_diameter`, lead `lead`, wire `wire`.
pub fn lead_corrected(
    half_angle: Real,
    space_at_pitch: Real,
    pitch_diameter: Real,
    lead: Real,
    wire: Real,
) -> Real {
    let a = half_angle;
    let lambda = (lead / (PI * pitch_diameter)).atan();
    pitch_diameter + wire * (1.0 + 1.0 / a.sin()) - space_at_pitch / a.tan()
        + wire / 2.0 * lambda.tan().powi(2) * a.cos() / a.tan()
}

/// The best wire for straight flanks at `flanks` (radians from the
/// radial, -Z flank first) and a space `space_at_pitch` wide at the pitch
/// line: the wire whose contacts straddle the pitch line equally (for
/// symmetric flanks both on it, `space / cos(a)`; for a buttress's 7 and
/// 45 degrees, 0.5112 P), in the axial section.
pub fn best_wire(flanks: [Real; 2], space_at_pitch: Real) -> Real {
    let [l, r] = flanks;
    // The centre stands w/2 along each flank's normal from its contact;
    // the contacts' radii differ from the pitch line's by +-(w/4)(sin r -
    // sin l), which shifts the space's width by that times the flanks'
    // slopes.
    let k = 0.5 * (l.cos() + r.cos()) - 0.25 * (r.sin() - l.sin()) * (l.tan() - r.tan());
    space_at_pitch / k
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Tr40x7's space: 30 degrees included, 3.5 mm wide at the pitch
    /// diameter 36.5, over the lead `lead`.
    fn tr40(lead: Real) -> Space {
        let (a, r1) = (15f64.to_radians(), 18.25);
        Space {
            left: [-1.75 + r1 * a.tan(), -a.tan()],
            right: [1.75 - r1 * a.tan(), a.tan()],
            internal: false,
            lead,
        }
    }

    #[test]
    fn the_rest_agrees_with_asme_b1_2_on_a_trapezoidal() {
        let a = 15f64.to_radians();
        let w = 3.5 / a.cos();
        for (lead, series, correction) in [(7.0, 0.05e-3, 24.3e-3), (14.0, 0.5e-3, 97.0e-3)] {
            let rest = resting(&tr40(lead), w, 36.5, (16.5, 20.0)).unwrap();
            let formula = lead_corrected(a, 3.5, 36.5, lead, w);
            let axial = lead_corrected(a, 3.5, 36.5, 0.0, w);
            assert!(
                (rest.m - formula).abs() < series,
                "{lead}: {} {formula}",
                rest.m
            );
            assert!(
                (rest.m - axial - correction).abs() < 0.5e-3,
                "{}",
                rest.m - axial
            );
        }
    }

    /// The least of `f` over `[lo, hi]` by ternary search (`f` unimodal
    /// there).
    fn least(lo: Real, hi: Real, f: impl Fn(Real) -> Real) -> Real {
        f(crate::math::least_by_thirds(lo, hi, 200, &f))
    }

    #[test]
    fn every_contact_is_half_a_wire_from_the_axis() {
        // Independently: the wire's axis (a straight line) against each
        // helicoidal flank, the least distance between them searched over
        // the flank's radius and angle: the wire's radius, for the best
        // wire and one a tenth larger, single and two-start.
        let a = 15f64.to_radians();
        for lead in [7.0, 14.0] {
            let space = tr40(lead);
            let tilt = (lead / (PI * 36.5)).atan();
            let (s, c) = tilt.sin_cos();
            for w in [3.5 / a.cos(), 1.1 * 3.5 / a.cos()] {
                let rest = resting(&space, w, 36.5, (16.5, 20.0)).unwrap();
                let [x, z0] = rest.centre;
                for line in [space.left, space.right] {
                    let d = least(16.5, 20.0, |r| {
                        least(-0.3, 0.3, |th| {
                            let z = line[0] + line[1] * r + lead * th / (2.0 * PI);
                            let p = [r * th.cos() - x, r * th.sin(), z - z0];
                            let along = p[1] * c + p[2] * s;
                            (p[0].powi(2) + p[1].powi(2) + p[2].powi(2) - along * along).sqrt()
                        })
                    });
                    assert!(
                        (d - w / 2.0).abs() < 1e-6,
                        "{lead} {w}: {d} against {}",
                        w / 2.0
                    );
                }
            }
        }
    }

    #[test]
    fn balls_in_a_nut_and_the_buttress_best_wire() {
        // A nut's space, mirrored: the flanks' slopes turned over.
        let a = 30f64.to_radians();
        let (p, d2) = (2.5, 18.376);
        let nut = Space {
            left: [-p / 4.0 - d2 / 2.0 * a.tan(), a.tan()],
            right: [p / 4.0 + d2 / 2.0 * a.tan(), -a.tan()],
            internal: true,
            lead: p,
        };
        let w = best_wire([a, a], p / 2.0);
        assert!((w - p / 3f64.sqrt()).abs() < ROUNDING, "{w}");
        let rest = resting(&nut, w, d2, (8.5, 10.0)).unwrap();
        let axial = d2 - w * (1.0 + 1.0 / a.sin()) + p / 2.0 / a.tan();
        // A ball in a fine lead: a few microns from the axial figure, and
        // smaller (a helical space is narrower across the helix than along
        // the axis, so the ball stands nearer the opening).
        assert!(
            rest.m < axial && axial - rest.m < 3e-3,
            "{} {axial}",
            rest.m
        );
        let b = best_wire([7f64.to_radians(), 45f64.to_radians()], 0.5);
        assert!((b - 0.5112).abs() < 1e-4, "{b}");
    }
}
