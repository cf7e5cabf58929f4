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

pub use capsule::{flat_path, CapsuleEnvelope};
pub use drop::{drop_circle, Drop};
pub use envelope::{swept_circles, CircleEnvelope, SweptCircles};

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
    violations(
        profile.z(),
        &profile.slopes(),
        &profile.second_derivatives(),
        radius,
        side,
    )
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
    positive("tool radius", radius)?;
    let slopes = profile.slopes();
    let d2 = profile.second_derivatives();
    let (pz, px) = (profile.z(), profile.x());
    let found = violations(pz, &slopes, &d2, radius, side);
    if !found.is_empty() {
        return Err(ProfileError::CurvatureBelowTool {
            tool_radius: radius,
            violations: found,
        });
    }
    let sigma = side.sign();
    let n = profile.len();
    // Convex kinks (the slope jumps away from the tool; concave ones were
    // refused above): there the centre swings round the corner on an arc.
    let corners: Vec<usize> = (1..n.saturating_sub(1))
        .filter(|&i| d2[i].is_infinite() && d2[i] * sigma < 0.0)
        .collect();
    drop(d2);
    let r = radius * sigma;
    let centre = |z: Real, x: Real, s: Real| {
        let c = 1.0 / (1.0 + s * s).sqrt();
        (z - r * s * c, x + r * c)
    };
    if corners.is_empty() {
        // One centre per node: the slopes become the result's as they are.
        let (z, x) = pz
            .iter()
            .zip(px)
            .zip(slopes.iter())
            .map(|((&z, &x), &s)| centre(z, x, s))
            .unzip();
        return Ok(Equidistant {
            z,
            x,
            slope: slopes.into_owned(),
            radius,
            side,
        });
    }
    let mut e = Equidistant {
        z: Vec::with_capacity(n),
        x: Vec::with_capacity(n),
        slope: Vec::with_capacity(n),
        radius,
        side,
    };
    let mut push = |z: Real, x: Real, s: Real| {
        let (cz, cx) = centre(z, x, s);
        e.z.push(cz);
        e.x.push(cx);
        e.slope.push(s);
    };
    let mut next = corners.iter().peekable();
    for i in 0..n {
        if next.next_if_eq(&&i).is_some() {
            let left = (px[i] - px[i - 1]) / (pz[i] - pz[i - 1]);
            let right = (px[i + 1] - px[i]) / (pz[i + 1] - pz[i]);
            let (a, b) = (left.atan(), right.atan());
            let steps = ((a - b).abs() / corner_step(radius)).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let gamma = a + (b - a) * k as Real / steps as Real;
                push(pz[i], px[i], gamma.tan());
            }
        } else {
            push(pz[i], px[i], slopes[i]);
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
}
