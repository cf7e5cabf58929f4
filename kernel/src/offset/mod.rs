//! Equidistants of profiles and exact 2-D envelopes of tool circles
//! (docs/math.md §2.2, §2.3).
//!
//! A grinding wheel's rounding (radius `R_s`) is a circle in the part's
//! axial section. Its centre moves on the profile's equidistant
//! ([`equidistant`]); the surface it leaves is the envelope of its positions
//! ([`CircleEnvelope`]); the lowest position of a circle resting on a
//! surface is its "drop" ([`drop_circle`]), which is also the exact model of
//! the steady rest (the revolution family's). The envelope and the drop are computed
//! exactly on the sampled data and are the independent check of every
//! offset.

mod capsule;
mod drop;
mod envelope;
mod refine;

pub use capsule::{flat_path, CapsuleEnvelope};
pub use drop::{drop_circle, Drop};
pub use envelope::{swept_circles, CircleEnvelope, SweptCircles};
pub use refine::refined;

use crate::math::{positive, Real};
use crate::profile::{CurvatureViolation, Profile, ProfileError};
use serde::{Deserialize, Serialize};

/// Which side of a profile the tool stands on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// On the +x side: a wheel grinding an outer surface (a mandrel).
    #[default]
    Outside,
    /// On the -x side: a tool inside a bore, or under the curve.
    Inside,
}

impl Side {
    /// +1 for [`Side::Outside`], -1 for [`Side::Inside`].
    pub fn sign(self) -> Real {
        match self {
            Side::Outside => 1.0,
            Side::Inside => -1.0,
        }
    }
}

/// The centres of a tool circle of radius `radius` touching a profile at
/// each of its nodes, and along an arc round each convex corner (docs/math.md §2.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Equidistant {
    /// Centre z at each node (mm).
    pub z: Vec<Real>,
    /// Centre x at each node (mm).
    pub x: Vec<Real>,
    /// The profile's slope dx/dz at each node (`tan gamma`); on a corner's
    /// arc, the slope whose normal points to that centre.
    pub slope: Vec<Real>,
    /// The tool circle's radius (mm).
    pub radius: Real,
    /// The tool's side.
    pub side: Side,
}

impl Equidistant {
    /// The centres as a polyline (z increasing).
    pub fn path(&self) -> crate::profile::Polyline {
        crate::profile::Polyline {
            z: self.z.clone(),
            x: self.x.clone(),
        }
    }
}

/// Every node where a tool of `radius` on `side` is rounder than the
/// profile: the profile is concave seen from the tool and its radius of
/// curvature is below `radius` (docs/math.md §2.2's shaping condition).
pub fn curvature_violations(
    profile: &Profile,
    radius: Real,
    side: Side,
) -> Vec<CurvatureViolation> {
    sourced(
        profile,
        violations(
            profile.z(),
            &profile.slopes(),
            &profile.second_derivatives(),
            radius,
            side,
        ),
    )
}

/// `found` with the profile's source at each ([`Profile::source_at`]).
fn sourced(profile: &Profile, mut found: Vec<CurvatureViolation>) -> Vec<CurvatureViolation> {
    for v in &mut found {
        v.source = profile.source_at(v.z).map(|s| s.label.clone());
    }
    found
}

/// [`curvature_violations`] on derivatives already at hand.
fn violations(
    z: &[Real],
    d1: &[Real],
    d2: &[Real],
    radius: Real,
    side: Side,
) -> Vec<CurvatureViolation> {
    let sigma = side.sign();
    let mut out = Vec::new();
    for i in 0..z.len() {
        let k = crate::profile::curvature_of(d1[i], d2[i]) * sigma;
        if k * radius > 1.0 {
            out.push(CurvatureViolation {
                index: i,
                z: z[i],
                rho: 1.0 / k,
                source: None,
            });
        }
    }
    out
}

/// The equidistant of `profile` at `radius` on `side`:
/// `centre_i = (z_i - s R sin gamma_i, x_i + s R cos gamma_i)` with
/// `gamma_i = atan(dx/dz)` and `s` the side's sign.
///
/// At a convex corner (a kink of a built profile whose slope jumps away
/// from the tool) the tool pivots on the corner: the centres run along the
/// arc of radius R round it, from the normal of the segment before to the
/// normal of the one after (the slopes of the chords beside the kink, as
/// [`Profile::eval`] reads them), at points whose chords stay within
/// [`CORNER_SAG`] of the arc. A concave corner is a curvature violation.
///
/// # Tolerance
/// With analytic derivatives the centres are exact to rounding. With
/// estimated ones (divided differences), a centre is off by at most
/// `R |error of gamma|`, and the slope estimate's error is bounded in
/// [`Profile::slopes`]: for steps `h`, `|centre error| <= R h^2 max|x'''| / 3`.
///
/// # Failures
/// A radius that is not positive; [`ProfileError::CurvatureBelowTool`]
/// listing every z where the tool is rounder than the profile.
///
/// ```
/// use pilgrim_kernel::{equidistant, Profile, Side};
/// let p = Profile::new(vec![0.0, 1.0, 2.0], vec![5.0, 5.0, 5.0]).unwrap();
/// let e = equidistant(&p, 20.0, Side::Outside).unwrap();
/// assert_eq!(e.x, vec![25.0; 3]);
/// ```
pub fn equidistant(
    profile: &Profile,
    radius: Real,
    side: Side,
) -> Result<Equidistant, ProfileError> {
    equidistant_within(profile, radius, side, 0.0)
}

/// The places a tool of `radius` on `side` cannot follow `profile`
/// ([`curvature_violations`]), less the concave kinks it bridges leaving
/// at most `allowance` (mm) in them (as [`equidistant_within`] takes
/// them), each with its source.
pub fn unbridged(
    profile: &Profile,
    radius: Real,
    side: Side,
    allowance: Real,
) -> Vec<CurvatureViolation> {
    let (pz, px, d2) = (profile.z(), profile.x(), profile.second_derivatives());
    let n = profile.len();
    let bridged = |i: usize| {
        i > 0 && i + 1 < n && d2[i].is_infinite() && d2[i] * side.sign() > 0.0 && {
            // The turn from the chords beside the kink.
            let a = ((px[i] - px[i - 1]) / (pz[i] - pz[i - 1])).atan();
            let b = ((px[i + 1] - px[i]) / (pz[i + 1] - pz[i])).atan();
            radius * (1.0 / (0.5 * (b - a)).cos() - 1.0) <= allowance
        }
    };
    let found = violations(pz, &profile.slopes(), &d2, radius, side);
    sourced(
        profile,
        found.into_iter().filter(|v| !bridged(v.index)).collect(),
    )
}

/// [`equidistant`], a concave kink that the tool bridges leaving at most
/// `allowance` (mm) of material in the kink being no corner: a drawing's
/// stations joined by straight lines kink by 1e-4 rad at a taper's
/// stations, which a wheel of radius R bridges within `R (1 / cos(delta /
/// 2) - 1)`, nanometres. There the centre touches both lines (the two
/// offset lines' intersection). A concave kink bridged by more is a
/// corner the tool cannot enter, refused with its z.
///
/// # Failures
/// As [`equidistant`].
pub fn equidistant_within(
    profile: &Profile,
    radius: Real,
    side: Side,
    allowance: Real,
) -> Result<Equidistant, ProfileError> {
    positive("tool radius", radius)?;
    let slopes = profile.slopes();
    let d2 = profile.second_derivatives();
    let (pz, px) = (profile.z(), profile.x());
    let sigma = side.sign();
    let n = profile.len();
    // The turn at a kink, from the chords beside it (as `Profile::eval`
    // reads them): their two angles.
    let turn = |i: usize| {
        let left = (px[i] - px[i - 1]) / (pz[i] - pz[i - 1]);
        let right = (px[i + 1] - px[i]) / (pz[i + 1] - pz[i]);
        (left.atan(), right.atan())
    };
    let kink = |i: usize| i > 0 && i + 1 < n && d2[i].is_infinite();
    let found = unbridged(profile, radius, side, allowance);
    if !found.is_empty() {
        return Err(ProfileError::CurvatureBelowTool {
            tool_radius: radius,
            violations: found,
        });
    }
    let r = radius * sigma;
    let mut e = Equidistant {
        z: Vec::with_capacity(n),
        x: Vec::with_capacity(n),
        slope: Vec::with_capacity(n),
        radius,
        side,
    };
    // The centre at distance `reach` R along the normal of slope `s`.
    let mut push = |z: Real, x: Real, s: Real, reach: Real| {
        let c = reach / (1.0 + s * s).sqrt();
        e.z.push(z - r * s * c);
        e.x.push(x + r * c);
        e.slope.push(s);
    };
    for i in 0..n {
        if kink(i) && d2[i] * sigma < 0.0 {
            // A convex corner: the centre swings round it on an arc.
            let (a, b) = turn(i);
            let steps = ((a - b).abs() / corner_step(radius)).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let gamma = a + (b - a) * k as Real / steps as Real;
                push(pz[i], px[i], gamma.tan(), 1.0);
            }
        } else if kink(i) {
            // A concave kink left (not refused above) is one the tool
            // bridges: the centre touches both lines.
            let (a, b) = turn(i);
            let half = 0.5 * (b - a);
            push(pz[i], px[i], (a + half).tan(), 1.0 / half.cos());
        } else {
            push(pz[i], px[i], slopes[i], 1.0);
        }
    }
    Ok(e)
}

/// Arc points round a corner are spaced so that their chords stay within
/// this distance of the arc (mm).
pub const CORNER_SAG: Real = 1e-6;

/// The angle between arc points round a corner for a tool of `radius`:
/// chords within [`CORNER_SAG`] of the arc.
fn corner_step(radius: Real) -> Real {
    2.0 * (2.0 * CORNER_SAG / radius).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    #[test]
    fn tight_concave_places_are_listed_with_z() {
        // x = z^2 / 20: radius of curvature 10 (1 + z^2/100)^1.5, 10 at the bottom.
        let z: Vec<Real> = (0..=8).map(|i| -2.0 + 0.5 * i as Real).collect();
        let x: Vec<Real> = z.iter().map(|z| z * z / 20.0).collect();
        let p = Profile::new(z, x).unwrap();
        let e = equidistant(&p, 10.2, Side::Outside).unwrap_err();
        match &e {
            ProfileError::CurvatureBelowTool { violations, .. } => {
                let zs: Vec<Real> = violations.iter().map(|v| v.z).collect();
                assert_eq!(zs, [-1.0, -0.5, 0.0, 0.5, 1.0]);
                assert!(violations.iter().all(|v| v.rho < 10.2));
            }
            other => panic!("{other}"),
        }
        assert!(
            e.to_string()
                .contains("at 5 place(s): z = -1.0000 (rho = 10.1504)"),
            "{e}"
        );
        // The same curve is convex seen from inside: any radius fits.
        assert!(equidistant(&p, 12.0, Side::Inside).is_ok());
        assert!(equidistant(&p, 8.0, Side::Outside).is_ok());
        assert!(equidistant(&p, 0.0, Side::Outside).is_err());
        assert!(equidistant(&p, f64::NAN, Side::Outside).is_err());
    }

    #[test]
    fn inside_equidistant_of_a_line() {
        let p = Profile::new(vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 2.0]).unwrap();
        let e = equidistant(&p, 2.0_f64.sqrt(), Side::Inside).unwrap();
        assert_near!(e.z[0], 1.0, 1e-12);
        assert_near!(e.x[0], -1.0, 1e-12);
    }

    /// A taper's stations joined by lines kink by 1e-4 rad: a wheel of 20
    /// mm bridges each by nanometres, so within a tenth of a micron they
    /// are no corners and its centre touches both lines; a real concave
    /// corner is still refused, named as a corner.
    #[test]
    fn kinks_the_wheel_bridges_are_no_corners() {
        let (z, d) = (
            [0.0, 60.0, 120.0, 180.0, 240.0],
            [18.0, 18.028, 18.064, 18.110, 18.156],
        );
        let x: Vec<Real> = d.iter().map(|d| d / 2.0).collect();
        let p = crate::profile::polyline_through(&z, &x, &[], 1e-5).unwrap();
        let e = equidistant(&p, 20.0, Side::Outside)
            .unwrap_err()
            .to_string();
        assert!(e.contains("z = 60.0000 (a corner:"), "{e}");
        let c = equidistant_within(&p, 20.0, Side::Outside, 1e-4).unwrap();
        assert_eq!(c.z.len(), z.len());
        for i in 1..z.len() - 1 {
            for j in [i - 1, i + 1] {
                // Distance from the centre to the line through stations
                // i and j.
                let (dz, dx) = (z[j] - z[i], x[j] - x[i]);
                let off = ((c.z[i] - z[i]) * dx - (c.x[i] - x[i]) * dz).abs() / dz.hypot(dx);
                assert_near!(off, 20.0, 1e-9, "station {i} to {j}");
            }
        }
        let shoulder =
            crate::profile::polyline_through(&[0.0, 10.0, 20.0], &[5.0, 5.0, 8.0], &[], 1e-5)
                .unwrap();
        let e = equidistant_within(&shoulder, 2.0, Side::Outside, 1e-4)
            .unwrap_err()
            .to_string();
        assert!(e.contains("z = 10.0000 (a corner:"), "{e}");
    }
}
