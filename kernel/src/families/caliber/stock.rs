//! The turned groove as the process's rules see it: the wheel's depth in
//! the material at every block.

use super::check::{placed, wheel_distance, GrooveRequest};
use super::groove::Groove;
use super::pose::TorusWheel;
use super::section::GrooveSection;
use crate::math::{Real, Vec3};
use crate::program::ProgramPass;
use crate::tool::Wheel;

/// The least step (rad) of the search for the least distance: 2.5 um
/// along the groove, where the distance's error is of second order
/// (hundredths of a micron).
const LEAST_STEP: Real = 1e-5;

/// The groove's material for the process's rules ([`crate::process`]):
/// the roll with its groove as turned, before any pass grinds it (its
/// surface `stock` into the groove's open space from the nominal
/// everywhere: each pass, grinding its strip's whole allowance, meets it
/// so); every pass a finishing pass taking the allowance.
#[derive(Debug)]
pub struct GrooveStock {
    groove: Groove,
    stock: Real,
    wheel: Wheel,
    passes: Vec<crate::process::PassStock>,
    /// The last pose measured: consecutive blocks start from it.
    memo: std::cell::Cell<Option<Measured>>,
}

/// A pose measured against the groove: the pose, the wheel's depth in the
/// stock there, and the groove's nearest point `(theta, psi)`.
type Measured = ([Real; 6], Real, (Real, Real));

impl GrooveStock {
    /// The material of `req`'s groove, its allowance `stock`, ground by
    /// `passes` with `wheel`.
    pub fn new(req: &GrooveRequest, stock: Real, wheel: &Wheel, passes: &[ProgramPass]) -> Self {
        let passes = passes
            .iter()
            .filter(|p| p.cuts)
            .map(|p| crate::process::PassStock {
                name: p.name.clone(),
                first_block: p.blocks.start,
                cut: stock,
                ridge: 0.0,
                finishes: true,
            })
            .collect();
        Self {
            groove: req.groove.clone(),
            stock,
            wheel: *wheel,
            passes,
            memo: std::cell::Cell::new(None),
        }
    }

    /// The least distance from the wheel to the nominal groove, and where
    /// on the groove: a grid about the wheel's angle from a cold start; on
    /// a warm one, a pattern search from `from`, the groove's point of a
    /// pose close by, its theta moved by as much as the wheel turned about
    /// the roll since. The wheel rides along the groove from block to
    /// block, so that point is then within hundredths of a milliradian of
    /// the nearest, and the search starts at steps of 1/400 of a cold
    /// one's (the default caliber's depths agree with a search from the
    /// cold steps within 1e-7 mm at every block, 7e-7 mm with its edges
    /// rounded, where this one finds the nearer point).
    fn nearest(&self, w: &TorusWheel, from: Option<Warm>) -> (Real, (Real, Real)) {
        use std::f64::consts::FRAC_PI_2;
        let (lo, hi) = self.groove.theta_range();
        // The sections last built, for the next points at their theta:
        // the search steps about its best point's theta, which it built.
        let built: std::cell::RefCell<Vec<(Real, Option<GrooveSection>)>> = Default::default();
        let f = |t: Real, p: Real| {
            let t = t.clamp(lo, hi);
            let mut built = built.borrow_mut();
            let at = match built.iter().position(|(at, _)| *at == t) {
                Some(i) => i,
                None => {
                    if built.len() == 3 {
                        built.remove(0);
                    }
                    built.push((t, self.groove.section(t).ok()));
                    built.len() - 1
                }
            };
            built[at].1.as_ref().map_or(Real::INFINITY, |s| {
                wheel_distance(
                    w,
                    &self.groove.point_of(s, t, p.clamp(-FRAC_PI_2, FRAC_PI_2)),
                )
            })
        };
        let turn = w.centre.y.atan2(w.centre.x);
        let (mut best, scale) = match from {
            Some(warm) => {
                let t = (warm.at.0 + crate::math::wrap_angle(turn - warm.turn)).clamp(lo, hi);
                let tp = (t, warm.at.1);
                ((f(tp.0, tp.1), tp), 0.0025)
            }
            None => {
                let mut best = (Real::INFINITY, (turn, 0.0));
                for i in -5..=5 {
                    let t = turn + 0.03 * i as Real;
                    for j in -11..=11 {
                        let p = 8f64.to_radians() * j as Real;
                        let d = f(t, p);
                        if d < best.0 {
                            best = (d, (t, p));
                        }
                    }
                }
                (best, 1.0)
            }
        };
        // Down to 1e-5 rad (2.5 um along the groove): at the least distance
        // the error is of second order, hundredths of a micron.
        let (mut st, mut sp) = (0.01 * scale, 2f64.to_radians() * scale);
        let mut streak = 0;
        while st > LEAST_STEP {
            let (t, p) = best.1;
            let next = [(t, p + sp), (t, p - sp), (t + st, p), (t - st, p)]
                .into_iter()
                .map(|(a, b)| (f(a, b), (a.clamp(lo, hi), b.clamp(-FRAC_PI_2, FRAC_PI_2))))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            match next {
                // A step that gains is taken; after three in a row the
                // steps double (up to a cold start's), so that a warm
                // start that was off travels as fast as a cold one.
                Some(n) if n.0 < best.0 => {
                    best = n;
                    streak += 1;
                    if streak >= 3 {
                        st = (2.0 * st).min(0.01);
                        sp = (2.0 * sp).min(2f64.to_radians());
                    }
                }
                _ => {
                    streak = 0;
                    st /= 2.0;
                    sp /= 2.0;
                }
            }
        }
        best
    }
}

/// Where a search may start warm: the groove's nearest point `(theta,
/// psi)` of a pose close by, and that wheel's angle about the roll (rad).
#[derive(Debug, Clone, Copy)]
struct Warm {
    at: (Real, Real),
    turn: Real,
}

impl crate::process::Stock for GrooveStock {
    fn tool_depth(&self, _: usize, pose: &[Real]) -> Real {
        let key: [Real; 6] = std::array::from_fn(|i| pose[i]);
        let memo = self.memo.get();
        if let Some((_, d, _)) = memo.filter(|m| m.0 == key) {
            return d;
        }
        let w = placed(pose, &self.wheel);
        // Warm from the last pose's point when the wheel moved little.
        let warm = memo
            .filter(|m| {
                let c = Vec3::new(m.0[0], m.0[1], m.0[2]);
                (c - w.centre).norm() < 5.0
            })
            .map(|m| Warm {
                at: m.2,
                turn: m.0[1].atan2(m.0[0]),
            });
        let (distance, at) = self.nearest(&w, warm);
        let depth = self.stock - distance;
        self.memo.set(Some((key, depth, at)));
        depth
    }

    fn passes(&self) -> Vec<crate::process::PassStock> {
        self.passes.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;
    use crate::families::caliber::{pass_poses, SwivelPlane};
    use crate::process::Stock;

    /// Block after block along a pass, each search starting warm from the
    /// block before's point, the wheel's depth in the stock is what the
    /// geometry makes it: wheels posed to touch a groove that deepens round
    /// the roll, then moved 0.02 mm off it along the contact's normal, are
    /// 0.02 mm off the groove, so `stock - 0.02` deep in its allowance.
    #[test]
    fn the_warm_search_finds_each_blocks_depth() {
        let theta: Vec<Real> = (0..=36).map(|i| i as Real * 5.0).collect();
        let hp: Vec<Real> = theta.iter().map(|t| 24.0 - 0.05 * t).collect();
        let b: Vec<Real> = hp.iter().map(|h| 2.1 * h).collect();
        let groove = Groove::new(150.0, (&theta, &theta), &hp, &b).unwrap();
        let wheel = Wheel {
            diameter: 200.0,
            rounding_radius: 8.0,
            width: 16.0,
        };
        let req = GrooveRequest {
            groove,
            psi: vec![0.0],
            tolerance: 0.01,
            grid_theta: 0.5f64.to_radians(),
            grid_per_step: 1,
            patch_gap: 0.01,
            stock: Some(0.05),
        };
        let stock = GrooveStock::new(&req, 0.05, &wheel, &[]);
        let mut block = 0;
        for psi in [-1.2, -0.4, 0.0, 0.6, 1.3] {
            let poses = pass_poses(
                &req.groove,
                psi,
                1f64.to_radians(),
                100.0,
                8.0,
                SwivelPlane::Contact,
            )
            .unwrap();
            for p in &poses {
                let c = p.wheel.centre + 0.02 * p.normal;
                let a = p.wheel.axis;
                let depth = stock.tool_depth(block, &[c.x, c.y, c.z, a.x, a.y, a.z]);
                assert_near!(depth, 0.03, 1e-6);
                block += 1;
            }
        }
    }
}
