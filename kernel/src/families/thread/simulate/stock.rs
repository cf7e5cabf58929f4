//! The thread's material for the process's rules.

use super::{ThreadCheck, ThreadRequest};
use crate::families::thread::ThreadCutter;
use crate::math::Real;

/// The worm's material for the process's rules ([`crate::process`]): the
/// blank, a cylinder of the tip's radius over the thread's length, which
/// a tool moving otherwise than along the thread meets as the part turns
/// under it (the envelope of the section over a turn); and each thread
/// block's chip, the last at each start finishing it.
#[derive(Debug, Clone)]
pub struct ThreadStock {
    /// +1, or -1 for an internal thread: radii are taken as rho = -r, so
    /// that the material lies below the crest as an external thread's.
    rho: Real,
    tip_radius: Real,
    /// The material's far side in rho: a nut's outside (none: the axis,
    /// which no tool reaches).
    far: Real,
    length: Real,
    /// The cutter's outline about its tip's centre, sampled every 0.1 mm.
    outline: Vec<[Real; 2]>,
    passes: Vec<crate::process::PassStock>,
}

impl ThreadStock {
    /// The material of the worm of `req` that `check` simulated, cut by
    /// `cutter`.
    pub fn new(check: &ThreadCheck, req: &ThreadRequest, cutter: &ThreadCutter) -> Self {
        let section = cutter.section(cutter.height);
        let mut outline = Vec::new();
        for j in 0..section.len() {
            let (a, b) = (section[j], section[(j + 1) % section.len()]);
            let n = ((a[0] - b[0]).hypot(a[1] - b[1]) / 0.1).ceil().max(1.0) as usize;
            outline.extend((0..n).map(|i| {
                let t = i as Real / n as Real;
                [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
            }));
        }
        let last_of_start = |k: usize| {
            check.passes[k + 1..]
                .iter()
                .all(|p| p.start != check.passes[k].start)
        };
        let passes = check
            .passes
            .iter()
            .enumerate()
            .map(|(k, p)| crate::process::PassStock {
                name: p.name.clone(),
                first_block: p.block - 1,
                cut: p.thickness,
                ridge: 0.0,
                finishes: last_of_start(k),
            })
            .collect();
        let rho = req.section.opening();
        Self {
            rho,
            tip_radius: rho * req.section.crest_diameter / 2.0,
            far: req
                .outside_diameter
                .filter(|_| req.section.internal)
                .map_or(Real::NEG_INFINITY, |d| -d / 2.0),
            length: req.length,
            outline,
            passes,
        }
    }
}

impl crate::process::Stock for ThreadStock {
    fn tool_depth(&self, _: usize, pose: &[Real]) -> Real {
        let (z, r) = (pose[2], self.rho * pose[0].hypot(pose[1]));
        // Into the blank, the outline's points over it; off it, the
        // nearest's distance.
        self.outline
            .iter()
            .map(|p| {
                let (pz, pr) = (z + p[0], r + p[1]);
                let dz = (pz - 0.0).max(-self.length - pz).max(0.0);
                // Beyond the crest, or beyond a nut's outside.
                let dr = (pr - self.tip_radius).max(self.far - pr);
                if dz == 0.0 {
                    -dr
                } else {
                    -dz.hypot(dr.max(0.0))
                }
            })
            .fold(Real::NEG_INFINITY, Real::max)
    }

    fn passes(&self) -> Vec<crate::process::PassStock> {
        self.passes.clone()
    }
}
