//! The exact "drop" of a circle onto a sampled profile.

use super::Side;
use crate::math::{finite, positive, Real};
use crate::profile::{Profile, ProfileError};
use serde::{Deserialize, Serialize};

/// Where a dropped circle comes to rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Drop {
    /// The circle centre's x (mm).
    pub centre_x: Real,
    /// The z of the contact point (mm).
    pub contact_z: Real,
    /// The x of the contact point (mm).
    pub contact_x: Real,
}

/// The closest position of a circle of `radius`, centred at `centre_z`,
/// brought toward the profile from `side` until it touches: for
/// [`Side::Outside`], the lowest centre x with no point of the profile inside
/// the circle, `max over |z - zc| <= r of x(z) + sqrt(r^2 - (z - zc)^2)`
/// (docs/math.md §2.3's exact rest model).
///
/// The profile is taken as the polyline through its nodes, and the result
/// is exact for that polyline: vertices, contacts inside segments and the
/// window's edges are all examined. Only the nodes within the circle's
/// reach are visited (binary search), so one drop costs O(log n + r/h).
///
/// # Failures
/// A radius that is not positive; a non-finite centre; a circle whose
/// reach misses the profile's z range altogether.
///
/// ```
/// use pilgrim_kernel::{drop_circle, Profile, Side};
/// let flat = Profile::new(vec![0.0, 10.0, 20.0], vec![3.0, 3.0, 3.0]).unwrap();
/// let d = drop_circle(&flat, 10.0, 2.0, Side::Outside).unwrap();
/// assert_eq!(d.centre_x, 5.0);
/// ```
pub fn drop_circle(
    profile: &Profile,
    centre_z: Real,
    radius: Real,
    side: Side,
) -> Result<Drop, ProfileError> {
    positive("drop circle radius", radius)?;
    finite("drop circle centre z", centre_z)?;
    let (z, x) = (profile.z(), profile.x());
    let n = z.len();
    let (zmin, zmax) = profile.z_range();
    let (a, b) = (centre_z - radius, centre_z + radius);
    if a > zmax || b < zmin {
        return Err(ProfileError::OutsideProfile {
            what: format!("a circle of radius {radius} centred"),
            z: centre_z,
            z_min: zmin,
            z_max: zmax,
        });
    }
    let sigma = side.sign();
    let r2 = radius * radius;
    let mut best = Drop {
        centre_x: Real::NEG_INFINITY,
        contact_z: centre_z,
        contact_x: Real::NAN,
    };
    let mut consider = |zq: Real, yq: Real, value: Real| {
        if value > best.centre_x {
            best = Drop {
                centre_x: value,
                contact_z: zq,
                contact_x: yq * sigma,
            };
        }
    };
    let lo = z.partition_point(|&v| v < a);
    let hi = z.partition_point(|&v| v <= b); // nodes lo..hi lie in the window
    for i in lo..hi {
        let y = sigma * x[i];
        let dz = z[i] - centre_z;
        consider(z[i], y, y + (r2 - dz * dz).max(0.0).sqrt());
    }
    for i in lo.saturating_sub(1)..hi.min(n - 1) {
        let (z0, z1) = (z[i], z[i + 1]);
        let (y0, y1) = (sigma * x[i], sigma * x[i + 1]);
        let m = (y1 - y0) / (z1 - z0);
        let line = |t: Real| y0 + m * (t - z0);
        let q = (1.0 + m * m).sqrt();
        // Tangency of the circle with the segment's line.
        let t = centre_z + radius * m / q;
        if t >= z0 && t <= z1 {
            consider(t, line(t), line(centre_z) + radius * q);
        }
        // The window's edges, where the segment crosses them.
        for e in [a, b] {
            if e > z0 && e < z1 {
                consider(e, line(e), line(e));
            }
        }
    }
    best.centre_x *= sigma;
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    #[test]
    fn drop_on_a_ridge_and_into_a_valley() {
        // A roof: the circle rests on the ridge vertex.
        let roof = Profile::new(vec![-10.0, 0.0, 10.0], vec![0.0, 5.0, 0.0]).unwrap();
        let d = drop_circle(&roof, 0.0, 2.0, Side::Outside).unwrap();
        assert_near!(d.centre_x, 7.0, 1e-12);
        assert_eq!(d.contact_z, 0.0);
        // A V valley at 45 degrees: the circle touches both flanks, centre r*sqrt(2) above the vertex.
        let v = Profile::new(vec![-10.0, 0.0, 10.0], vec![10.0, 0.0, 10.0]).unwrap();
        let d = drop_circle(&v, 0.0, 2.0, Side::Outside).unwrap();
        assert_near!(d.centre_x, 2.0 * 2.0_f64.sqrt(), 1e-12);
        // From inside the roof is a valley.
        let d = drop_circle(&roof, 0.0, 2.0, Side::Inside).unwrap();
        assert_near!(d.centre_x, 5.0 - 2.0 * (1.0 + 0.25_f64).sqrt(), 1e-12);
        // A circle hanging over the end rests on the last part there is.
        let d = drop_circle(&v, 11.0, 2.0, Side::Outside).unwrap();
        assert_near!(d.centre_x, 10.0 + (4.0_f64 - 1.0).sqrt(), 1e-12);
        assert!(drop_circle(&v, 30.0, 2.0, Side::Outside).is_err());
        assert!(drop_circle(&v, 0.0, -1.0, Side::Outside).is_err());
    }
}
