//! A profile `x(z)` as cubic Bezier segments within a tolerance.
//!
//! A [`Profile`] is itself piecewise cubic: between nodes it is the cubic
//! Hermite of the node values and slopes (linear beside a kink). Each node
//! interval is therefore exactly one Bezier segment; the fit joins runs of
//! intervals into one segment (the Hermite of the run's end values and
//! slopes) wherever that stays within the tolerance at every node and at
//! three points inside every interval of the run, so that a smooth law of
//! thousands of nodes becomes a few dozen segments while kinks and straight
//! stretches stay as the profile has them.

use super::{Piece, Section, StepError};
use crate::math::Real;
use crate::profile::Profile;

/// A profile fitted as a section: the section and how closely it follows.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileFit {
    /// The section: the profile as cubic Bezier segments.
    pub section: Section,
    /// The largest deviation of the fitted curve from the profile found at
    /// the nodes and three points in each node interval (mm).
    pub deviation: Real,
    /// How many Bezier segments the fit has.
    pub segments: usize,
}

/// The fractions of a node interval where a candidate is compared.
const PROBES: [Real; 3] = [0.25, 0.5, 0.75];

/// The Hermite cubic through `(z0, x0, s0)` and `(z1, x1, s1)` at `z`.
fn hermite(z0: Real, x0: Real, s0: Real, z1: Real, x1: Real, s1: Real, z: Real) -> Real {
    crate::profile::hermite(&[z0, z1], &[x0, x1], &[s0, s1], z)
}

/// The profile's section of revolution, fitted within `tol`.
///
/// # Failures
/// A tolerance that is not positive; a radius not above zero (the solid
/// would pinch, or end in a point, which the end faces cannot close), named
/// by its z.
pub fn profile_section(body: &str, profile: &Profile, tol: Real) -> Result<ProfileFit, StepError> {
    crate::math::positive("STEP tolerance", tol)?;
    let (z, x) = (profile.z(), profile.x());
    let n = z.len();
    for i in 0..n {
        if !(x[i] > 0.0) {
            return Err(StepError::Section {
                body: body.to_owned(),
                message: format!(
                    "the profile's radius at z = {} is {}: a solid of revolution with flat ends needs a positive radius",
                    z[i], x[i]
                ),
            });
        }
    }
    let slopes = profile.slopes();
    let d2 = profile.second_derivatives();
    let kink = |i: usize| d2[i].is_infinite();
    // The profile's own slope at each end of an interval: the Hermite's, or
    // the chord's beside a kink (where the profile is linear).
    let chord = |i: usize| (x[i + 1] - x[i]) / (z[i + 1] - z[i]);
    let own = |i: usize| {
        if kink(i) || kink(i + 1) {
            (chord(i), chord(i))
        } else {
            (slopes[i], slopes[i + 1])
        }
    };
    // The profile at the probes of every interval, computed once.
    let probes: Vec<[Real; 3]> = (0..n - 1)
        .map(|i| {
            let (s0, s1) = own(i);
            PROBES.map(|f| {
                let zq = z[i] + f * (z[i + 1] - z[i]);
                hermite(z[i], x[i], s0, z[i + 1], x[i + 1], s1, zq)
            })
        })
        .collect();
    // The largest deviation of the run i..j as one Hermite (end slopes
    // from the intervals at its ends).
    let run_error = |i: usize, j: usize| -> (Real, Real, Real) {
        let (s0, s1) = (own(i).0, own(j - 1).1);
        let mut worst: Real = 0.0;
        for k in i..j {
            if k > i {
                worst = worst.max((hermite(z[i], x[i], s0, z[j], x[j], s1, z[k]) - x[k]).abs());
            }
            for (f, p) in PROBES.iter().zip(probes[k]) {
                let zq = z[k] + f * (z[k + 1] - z[k]);
                worst = worst.max((hermite(z[i], x[i], s0, z[j], x[j], s1, zq) - p).abs());
            }
        }
        (worst, s0, s1)
    };
    let mut pts = Vec::new();
    let mut deviation: Real = 0.0;
    let mut i = 0;
    while i < n - 1 {
        // The longest run from i that fits: doubling, then bisection.
        let (mut good, mut bad) = (i + 1, None);
        while bad.is_none() && good < n - 1 {
            let j = (i + 2 * (good - i)).min(n - 1);
            if run_error(i, j).0 <= tol {
                good = j;
            } else {
                bad = Some(j);
            }
        }
        if let Some(mut bad) = bad {
            while bad - good > 1 {
                let mid = (good + bad) / 2;
                if run_error(i, mid).0 <= tol {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
        }
        let (err, s0, s1) = if good == i + 1 {
            let (s0, s1) = own(i);
            (0.0, s0, s1)
        } else {
            run_error(i, good)
        };
        deviation = deviation.max(err);
        let h = z[good] - z[i];
        pts.push([z[i] + h / 3.0, x[i] + h / 3.0 * s0]);
        pts.push([z[good] - h / 3.0, x[good] - h / 3.0 * s1]);
        pts.push([z[good], x[good]]);
        i = good;
    }
    let segments = pts.len() / 3;
    Ok(ProfileFit {
        section: Section {
            start: [z[0], x[0]],
            pieces: vec![Piece::Cubic(pts)],
        },
        deviation,
        segments,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::MandrelLaw;

    /// The Bezier segments' points at many z, against the profile.
    fn worst_gap(fit: &ProfileFit, profile: &Profile) -> Real {
        let Piece::Cubic(pts) = fit
            .section
            .pieces
            .iter()
            .find(|p| matches!(p, Piece::Cubic(_)))
            .unwrap()
        else {
            unreachable!()
        };
        let mut from = [profile.z()[0], profile.x()[0]];
        let mut worst: Real = 0.0;
        for seg in pts.chunks_exact(3) {
            let b = [from, seg[0], seg[1], seg[2]];
            for k in 0..=200 {
                let (p, _) = super::super::bezier_at(&b, k as Real / 200.0);
                worst = worst.max((p[1] - profile.eval(p[0]).unwrap()).abs());
            }
            from = seg[2];
        }
        worst
    }

    /// A mandrel's law of thousands of nodes becomes few segments, and the
    /// curve (sampled finely, not at the fit's own probes) stays within the
    /// tolerance; its volume is the profile's.
    #[test]
    fn a_law_is_fitted_within_tolerance() {
        let law = MandrelLaw::new(40.0, 48.0, 300.0, 0.01, 2.5).unwrap();
        let p = law.profile(0.1, 0.0).unwrap();
        let fit = profile_section("part", &p, 1e-3).unwrap();
        assert!(fit.segments < p.len() / 20, "{} segments", fit.segments);
        assert!(fit.deviation <= 1e-3);
        let gap = worst_gap(&fit, &p);
        assert!(gap <= 1e-3, "{gap}");
        // pi * integral of x^2, by Simpson over the profile's own curve.
        let m = 30_000;
        let (a, b) = p.z_range();
        let h = (b - a) / m as Real;
        let zs: Vec<Real> = (0..=m).map(|k| a + h * k as Real).collect();
        let xs = p.eval_many(&zs).unwrap();
        let squares: Vec<Real> = xs.iter().map(|x| x * x).collect();
        let v = std::f64::consts::PI * crate::math::simpson(&squares, h);
        let lateral = 2.0 * std::f64::consts::PI * 48.0 / 2.0 * (b - a);
        assert!(
            (fit.section.volume() - v).abs() <= 1e-3 * lateral,
            "{} {v}",
            fit.section.volume()
        );
    }

    /// Kinks stay kinks: a cylinder, a cone and a cylinder again are three
    /// straight runs, exact.
    #[test]
    fn kinks_and_lines_are_kept_exactly() {
        let p = crate::profile::ProfileBuilder::start(0.0, 10.0)
            .line_to(20.0, 10.0)
            .line_to(30.0, 15.0)
            .line_to(50.0, 15.0)
            .build(1e-4, 0.5)
            .unwrap();
        let fit = profile_section("blank", &p, 1e-6).unwrap();
        assert!(worst_gap(&fit, &p) < 1e-9);
        assert!(fit.segments <= 9, "{} segments", fit.segments);
        let v = std::f64::consts::PI
            * (100.0 * 20.0 + 10.0 / 3.0 * (100.0 + 150.0 + 225.0) + 225.0 * 20.0);
        assert!((fit.section.volume() - v).abs() < 1e-6 * v);
    }

    /// A radius of zero inside, or a tolerance of zero, is refused.
    #[test]
    fn pinched_profiles_are_refused() {
        let p = Profile::new(vec![0.0, 1.0, 2.0], vec![1.0, 0.0, 1.0]).unwrap();
        let e = profile_section("part", &p, 1e-3).unwrap_err().to_string();
        assert!(e.contains("z = 1") && e.contains("part"), "{e}");
        let ok = Profile::new(vec![0.0, 1.0, 2.0], vec![1.0, 1.0, 1.0]).unwrap();
        assert!(profile_section("part", &ok, 0.0).is_err());
    }
}
