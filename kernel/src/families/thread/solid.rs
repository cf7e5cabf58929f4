//! The finished worm as a closed solid: the simulated section swept
//! helically, right-handed about +Z (the section at the part's angle
//! `phi` is the one at 0 shifted `+lead phi / 2 pi` along the axis), from
//! z = -length to 0, with flat ends. A left hand is the right hand's
//! mirror in the plane y = 0, which holds the section at angle 0: the
//! section at `phi` is the one at 0 shifted `-lead phi / 2 pi`.
//!
//! The rings are sections across the axis; a ring's points are `n` angles
//! round the axis, the rings evenly spaced from -length to 0 as near
//! `lead / n` apart as a whole number of them allows, so that the sweep's
//! diagonals (ring j point k to ring j + 1 point k + 1) run along the
//! helices (within a small fraction of the spacing) and the profile is
//! sampled every `lead / n` along them; `n` is set by the chordal
//! tolerance at the tip.
//!
//! An internal thread's part is a nut: the same helical surface as the
//! hole through a cylinder of its outside diameter.

use super::ThreadCheck;
use crate::math::Real;
use crate::mesh::{sweep, MeshError, TriMesh};
use std::f64::consts::TAU;

/// The most points round the axis (and so the finest sampling).
pub const MAX_AROUND: usize = 2048;

/// The worm of `check`'s finished section, `length` long, its round
/// sampling within `tol` of the tip circle (at least 24 points); for an
/// internal thread, the nut round it, `outside` its outside diameter.
///
/// # Failures
/// A length or tolerance not positive; an internal thread without an
/// outside diameter beyond its thread; a mesh that cannot be closed.
pub fn thread_solid(
    check: &ThreadCheck,
    length: Real,
    tol: Real,
    outside: Option<Real>,
) -> Result<TriMesh, MeshError> {
    crate::math::positive("worm length", length)
        .map_err(|e| MeshError::Degenerate(e.to_string()))?;
    crate::math::positive("mesh tolerance", tol)
        .map_err(|e| MeshError::Degenerate(e.to_string()))?;
    let (w0, lead) = check.window;
    let hand = check.hand.sign();
    let outline = check.outline();
    let r_thread = outline.iter().map(|p| p[1]).fold(0.0, Real::max);
    let nut = nut_radius(check, outside, r_thread)?;
    // The outline between its corners, repeated with the lead.
    let radius = |z: Real| -> Real {
        let u = w0 + (z - w0).rem_euclid(lead);
        let k = outline
            .partition_point(|p| p[0] < u)
            .clamp(1, outline.len() - 1);
        let (a, b) = (outline[k - 1], outline[k]);
        let t = if b[0] > a[0] {
            ((u - a[0]) / (b[0] - a[0])).clamp(0.0, 1.0)
        } else {
            0.0
        };
        a[1] + t * (b[1] - a[1])
    };
    if outline.len() < 2 || !(r_thread > 0.0) {
        return Err(MeshError::Degenerate("the worm's section is empty".into()));
    }
    let n = points_round(r_thread, tol);
    // Rings evenly from -length to 0, as near lead / n apart as a whole
    // number of them allows: each quad's diagonal then strays from its
    // helix by at most a (2 rings)-th of a ring's spacing.
    let rings = (length * n as Real / lead).round();
    crate::mesh::check_triangles((2.0 * n as Real * (rings + 1.0)).min(1e18) as usize, tol)?;
    let rings_between = (rings as usize).max(1);
    let zs: Vec<Real> = (0..=rings_between)
        .map(|j| -length + length * j as Real / rings_between as Real)
        .collect();
    let rings: Vec<Vec<[Real; 3]>> = zs
        .iter()
        .map(|&z| {
            (0..n)
                .map(|k| {
                    let phi = TAU * k as Real / n as Real;
                    let r = radius(z - lead * phi / TAU);
                    [r * phi.cos(), hand * r * phi.sin(), z]
                })
                .collect()
        })
        .collect();
    match nut {
        None => sweep(&rings),
        Some(r) => {
            // The outside is straight along the axis: its two end rings,
            // as many points round as the tolerance asks there.
            let n = points_round(r, tol);
            let outside: Vec<Vec<[Real; 3]>> = [-length, 0.0]
                .iter()
                .map(|&z| {
                    (0..n)
                        .map(|k| {
                            let phi = TAU * k as Real / n as Real;
                            // Wound as the hole's rings.
                            [r * phi.cos(), hand * r * phi.sin(), z]
                        })
                        .collect()
                })
                .collect();
            crate::mesh::sweep_hollow(&outside, &rings)
        }
    }
}

/// How many points round a circle of radius `r` keep its chords within
/// `tol` of it: at least 24, at most [`MAX_AROUND`].
fn points_round(r: Real, tol: Real) -> usize {
    let step = 2.0 * (1.0 - (tol / r).min(1.0)).acos();
    ((TAU / step).ceil() as usize).clamp(24, MAX_AROUND)
}

/// An internal thread's nut's outside radius, from its diameter `outside`,
/// beyond the thread's largest radius `r_thread`; `None` for an external
/// thread.
fn nut_radius(
    check: &ThreadCheck,
    outside: Option<Real>,
    r_thread: Real,
) -> Result<Option<Real>, MeshError> {
    match (check.internal, outside) {
        (false, _) => Ok(None),
        (true, Some(d)) if d / 2.0 > r_thread => Ok(Some(d / 2.0)),
        (true, d) => Err(MeshError::Degenerate(format!(
            "the nut's outside diameter {} is not beyond its thread's {:.3} mm",
            d.map_or("(none given)".to_owned(), |d| format!("{d} mm")),
            2.0 * r_thread
        ))),
    }
}

/// The finished worm exactly, for STEP: the section `outline` (`(z, r)`
/// over one lead from `window`'s start, straight between its points,
/// repeated with the lead) swept helically as [`thread_solid`] meshes it,
/// from z = -length to 0. Its cross-sections are the pieces: piece `k` is
/// the outline's stretch `k` wound round the axis (at the part's angle
/// `phi`, the radius is the outline's at `z - lead phi / 2 pi`), and `v`
/// runs along the axis; the end faces are square to it.
#[derive(Debug, Clone, PartialEq)]
pub struct ThreadSweep {
    /// The outline's points kept (within the simplification's tolerance),
    /// the first repeated a lead on at the end.
    points: Vec<[Real; 2]>,
    lead: Real,
    length: Real,
    /// +1 for a right hand, -1 for a left (the right's mirror in y = 0).
    hand: Real,
    /// The largest radial distance of a dropped point from the outline
    /// kept (mm).
    simplified: Real,
    /// A nut's outside radius (an internal thread's part).
    outside: Option<Real>,
}

impl ThreadSweep {
    /// The worm of `check`'s finished section, `length` long (for an
    /// internal thread the nut round it, `outside` its outside diameter);
    /// points of the outline within `merge` (mm, radially) of the line
    /// between their neighbours kept are dropped (the simulation's outline
    /// has pairs a micrometre apart and long straight runs).
    ///
    /// # Failures
    /// A length or merge distance not positive, an empty section; an
    /// internal thread without an outside diameter beyond its thread.
    pub fn new(
        check: &ThreadCheck,
        length: Real,
        merge: Real,
        outside: Option<Real>,
    ) -> Result<Self, MeshError> {
        let degenerate = |e: crate::input::InputError| MeshError::Degenerate(e.to_string());
        crate::math::positive("worm length", length).map_err(degenerate)?;
        crate::math::positive("outline merge distance", merge).map_err(degenerate)?;
        let (_, lead) = check.window;
        let mut all = check.outline();
        if all.len() < 2 || !all.iter().any(|p| p[1] > 0.0) {
            return Err(MeshError::Degenerate("the worm's section is empty".into()));
        }
        let r_thread = all.iter().map(|p| p[1]).fold(0.0, Real::max);
        let outside = nut_radius(check, outside, r_thread)?;
        all.push([all[0][0] + lead, all[0][1]]);
        // Greedy: from each point kept, reach as far as every point passed
        // stays within `merge` of the chord, radially. Written here, not
        // geo's Ramer-Douglas-Peucker (SimplifyIdx): that bounds the
        // distance square to the chord, which on the steep flanks lets the
        // radius at a place stray several times `merge` (0.71 um for 0.25
        // um on the default worm).
        let off = |a: [Real; 2], b: [Real; 2], p: [Real; 2]| {
            let t = if b[0] > a[0] {
                (p[0] - a[0]) / (b[0] - a[0])
            } else {
                0.0
            };
            (a[1] + t * (b[1] - a[1]) - p[1]).abs()
        };
        let (mut points, mut simplified) = (vec![all[0]], 0.0 as Real);
        let mut from = 0;
        while from + 1 < all.len() {
            let mut to = from + 1;
            while to + 1 < all.len() {
                let worst = (from + 1..=to)
                    .map(|i| off(all[from], all[to + 1], all[i]))
                    .fold(0.0, Real::max);
                if worst > merge {
                    break;
                }
                to += 1;
            }
            simplified = (from + 1..to)
                .map(|i| off(all[from], all[to], all[i]))
                .fold(simplified, Real::max);
            points.push(all[to]);
            from = to;
        }
        Ok(ThreadSweep {
            points,
            lead,
            length,
            hand: check.hand.sign(),
            simplified,
            outside,
        })
    }

    /// The largest radial distance of a dropped outline point from the
    /// outline kept (mm).
    pub fn simplified(&self) -> Real {
        self.simplified
    }
}

impl crate::step::Sections for ThreadSweep {
    fn pieces(&self) -> usize {
        self.points.len() - 1
    }

    fn straight(&self, _: usize) -> bool {
        false
    }

    fn point(&self, k: usize, u: Real, v: Real) -> [Real; 3] {
        let (a, b) = (self.points[k], self.points[k + 1]);
        let (s, r) = (a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]));
        let z = -self.length + v * self.length;
        let phi = TAU * (z - s) / self.lead;
        [r * phi.cos(), self.hand * r * phi.sin(), z]
    }

    fn along(&self) -> usize {
        // Eight points a turn to start.
        (8.0 * self.length / self.lead).ceil() as usize + 1
    }

    fn outside(&self) -> Option<Real> {
        self.outside
    }
}

impl crate::family::SweptSolid for ThreadSweep {
    fn sections(&self) -> &dyn crate::step::Sections {
        self
    }

    fn simplified(&self) -> crate::math::Real {
        ThreadSweep::simplified(self)
    }
}
