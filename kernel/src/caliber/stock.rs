//! The turned groove as the process's rules see it: the wheel's depth in
//! the material at every block.

use super::check::{placed, wheel_distance, GrooveRequest};
use super::groove::Groove;
use super::pose::TorusWheel;
use super::section::GrooveSection;
use crate::math::{Real, Vec3};
use crate::program::ProgramPass;
use crate::tool::Wheel;

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
    /// on the groove: a grid about the wheel's angle from a cold start, a
    /// pattern search from the last pose's point on a warm one.
    fn nearest(&self, w: &TorusWheel, from: Option<(Real, Real)>) -> (Real, (Real, Real)) {
        use std::f64::consts::FRAC_PI_2;
        let (lo, hi) = self.groove.theta_range();
        // The last section built, for the next point at its theta (the
        // search steps psi at one theta, and the grid runs psi inside).
        let last: std::cell::RefCell<Option<(Real, GrooveSection)>> = Default::default();
        let f = |t: Real, p: Real| {
            let t = t.clamp(lo, hi);
            let mut last = last.borrow_mut();
            if last.as_ref().is_none_or(|(at, _)| *at != t) {
                *last = self.groove.section(t).ok().map(|s| (t, s));
            }
            last.as_ref().map_or(Real::INFINITY, |(_, s)| {
                wheel_distance(
                    w,
                    &self.groove.point_of(s, t, p.clamp(-FRAC_PI_2, FRAC_PI_2)),
                )
            })
        };
        let mut best = match from {
            Some(tp) => (f(tp.0, tp.1), tp),
            None => {
                let turn = w.centre.y.atan2(w.centre.x);
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
                best
            }
        };
        // Down to 1e-5 rad (2.5 um along the groove): at the least distance
        // the error is of second order, hundredths of a micron.
        let (mut st, mut sp) = (0.01, 2f64.to_radians());
        while st > 1e-5 {
            let (t, p) = best.1;
            let next = [(t + st, p), (t - st, p), (t, p + sp), (t, p - sp)]
                .into_iter()
                .map(|(a, b)| (f(a, b), (a.clamp(lo, hi), b.clamp(-FRAC_PI_2, FRAC_PI_2))))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            match next {
                Some(n) if n.0 < best.0 => best = n,
                _ => {
                    st /= 2.0;
                    sp /= 2.0;
                }
            }
        }
        best
    }
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
            .map(|m| m.2);
        let (distance, at) = self.nearest(&w, warm);
        let depth = self.stock - distance;
        self.memo.set(Some((key, depth, at)));
        depth
    }

    fn passes(&self) -> Vec<crate::process::PassStock> {
        self.passes.clone()
    }
}
