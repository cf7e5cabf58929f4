//! The wheel on the groove: the seed's model (docs/math.md §3.4, S001-5..12) and
//! the exact torus (docs/math.md §3.5).

use super::groove::{Groove, GrooveError};
use crate::input::InputError;
use crate::math::{positive, Real, Vec3};

/// A torus wheel: its centre, its axis (unit), the radius of the circle
/// its rounding centres lie on (`R_k0 - r_k`) and the rounding's `r_k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusWheel {
    /// The wheel's centre (mm).
    pub centre: Vec3,
    /// Its axis (unit).
    pub axis: Vec3,
    /// `R_k0 - r_k` (mm).
    pub major: Real,
    /// The rounding's radius `r_k` (mm).
    pub minor: Real,
}

impl TorusWheel {
    /// The signed distance of `q` from the wheel's surface (mm): negative
    /// inside the wheel. Exact for the torus (the distance to the circle of
    /// rounding centres, less `r_k`); near the axis, where the torus is not
    /// the wheel's body, it measures to the torus all the same.
    pub fn distance(&self, q: &Vec3) -> Real {
        let v = q - self.centre;
        let h = v.dot(&self.axis);
        let rho = (v - h * self.axis).norm();
        (rho - self.major).hypot(h) - self.minor
    }
}

/// The torus wheel (largest radius `r_k0`, rounding `r_k`) touching a
/// surface at `p`, whose unit normal there is `n` (out of the material,
/// toward the wheel), with its axis along `w` (any direction not along
/// `n`; made unit): the rounding centre `C = p + r_k n`, the wheel's centre
/// `O = C + (r_k0 - r_k) u`, `u` the part of `n` across the axis (docs/math.md
/// §3.5). The wheel's surface passes through `p` with normal `-n`.
///
/// # Failures
/// Radii not positive or `r_k >= r_k0`; `w` along `n` or not finite.
pub fn exact_pose(
    p: Vec3,
    n: Vec3,
    w: Vec3,
    r_k0: Real,
    r_k: Real,
) -> Result<TorusWheel, InputError> {
    exact_pose_toward(p, n, w, r_k0, r_k, Vec3::zeros())
}

/// [`exact_pose`], the wheel's centre toward `away` (its part across the
/// axis) where `w` lies along `n`: the wheel's side face flat on the
/// surface, as at a groove's edge, where the wall is radial and the
/// wheel's plane along the edge; `u` tends to the radial direction there
/// as the contact nears the edge, so the radius out of the roll continues
/// the pass.
///
/// # Failures
/// As [`exact_pose`], and `w` along `n` with `away` along `w` or zero.
pub fn exact_pose_toward(
    p: Vec3,
    n: Vec3,
    w: Vec3,
    r_k0: Real,
    r_k: Real,
    away: Vec3,
) -> Result<TorusWheel, InputError> {
    positive("wheel radius R_k0", r_k0)?;
    positive("wheel rounding radius r_k", r_k)?;
    if r_k >= r_k0 {
        return Err(InputError::out_of_range(
            "wheel rounding radius r_k (mm)",
            r_k,
            format!("smaller than the wheel's radius R_k0 = {r_k0} mm"),
        ));
    }
    let (n, w) = (n.normalize(), w.normalize());
    let mut across = n - n.dot(&w) * w;
    if !(across.norm() > crate::tolerance::SAME_LENGTH) {
        across = away - away.dot(&w) * w;
    }
    if !(across.norm() > crate::tolerance::SAME_LENGTH) {
        return Err(InputError::out_of_range(
            "wheel axis against the surface normal (sine of the angle)",
            across.norm(),
            "the axis must not lie along the normal",
        ));
    }
    let c = p + r_k * n;
    Ok(TorusWheel {
        centre: c + (r_k0 - r_k) * across.normalize(),
        axis: w,
        major: r_k0 - r_k,
        minor: r_k,
    })
}

/// The seed's wheel centre and corrections at `(theta, psi)` (docs/math.md §3.4),
/// for a wheel of largest radius `R_k0` and rounding `r_k`. Angles in rad,
/// lengths in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeedPose {
    /// The contact point A in the section: along the roll's axis.
    pub x_a: Real,
    /// Its depth from the periphery.
    pub z_a: Real,
    /// The angle of the section's normal at A, from the depth direction
    /// (S001-6).
    pub psi_1: Real,
    /// The rounding centre in the section, `x_A - r_k sin(psi_1)` (S001-5).
    pub x_k: Real,
    /// Its depth, `z_A - r_k cos(psi_1)`.
    pub z_k: Real,
    /// The wheel's section radius at the contact,
    /// `R_k0 - r_k (1 - cos(psi_1))` (S001-8).
    pub r_k: Real,
    /// The contact line's radius from the roll's axis, `R_d - z_A`.
    pub r_m: Real,
    /// The pressure angle `atan((dR_m/dtheta) / R_m)` (S001-10).
    pub mu: Real,
    /// The equidistant's radius `sqrt(R_k^2 + R_m^2 + 2 R_k R_m cos(mu))`
    /// (S001-9).
    pub r_e: Real,
    /// The roll angle's correction `asin(R_k sin(mu) / R_e)` (S001-7).
    pub dtheta: Real,
    /// The swivel `asin(dx / dD)`: the contact's axial change over the arc
    /// length of its trajectory (S001-11).
    pub epsilon: Real,
    /// The rounding centre along the axis with the swivel,
    /// `x_A - r_k sin(psi_1) cos(epsilon)` (S001-12).
    pub x_k_swivelled: Real,
    /// The roll angle's swivel correction `r_k sin(psi_1) sin(epsilon) / R_d`.
    pub dtheta_1: Real,
}

/// The seed's pose of a wheel (largest radius `r_k0`, rounding `r_k`) on
/// the pass at `psi` of `groove`, at `theta` (docs/math.md §3.4 with its
/// corrections: `psi_1` in S001-8, the `+` of the law of cosines in
/// S001-9). Derivatives along theta are central differences of 1e-6 rad
/// (one-sided at the tables' ends), as the groove's normal's.
///
/// # Failures
/// `theta` outside the tables; radii not positive.
pub fn seed_pose(
    groove: &Groove,
    theta: Real,
    psi: Real,
    r_k0: Real,
    r_k: Real,
) -> Result<SeedPose, GrooveError> {
    positive("wheel radius R_k0", r_k0)?;
    positive("wheel rounding radius r_k", r_k)?;
    let section = groove.section(theta)?;
    let (x_a, z_a) = section.point(psi);
    let psi_1 = section.normal_angle(psi);
    let r_d = groove.roll_radius();
    let (t0, t1) = groove.theta_pair(theta);
    let at = |t: Real| -> Result<(Real, Real), GrooveError> {
        let (x, z) = groove.section(t)?.point(psi);
        Ok((x, r_d - z))
    };
    let ((x0, rm0), (x1, rm1)) = (at(t0)?, at(t1)?);
    let r_m = r_d - z_a;
    let d_rm = (rm1 - rm0) / (t1 - t0);
    let d_x = (x1 - x0) / (t1 - t0);
    let mu = (d_rm / r_m).atan();
    let r_k_section = r_k0 - r_k * (1.0 - psi_1.cos());
    let r_e = (r_k_section * r_k_section + r_m * r_m + 2.0 * r_k_section * r_m * mu.cos()).sqrt();
    // The contact's trajectory: dD^2 = dx^2 + dR_m^2 + (R_m dtheta)^2.
    let d_d = d_x.hypot(d_rm).hypot(r_m);
    let epsilon = (d_x / d_d).asin();
    Ok(SeedPose {
        x_a,
        z_a,
        psi_1,
        x_k: x_a - r_k * psi_1.sin(),
        z_k: z_a - r_k * psi_1.cos(),
        r_k: r_k_section,
        r_m,
        mu,
        r_e,
        dtheta: (r_k_section * mu.sin() / r_e).asin(),
        epsilon,
        x_k_swivelled: x_a - r_k * psi_1.sin() * epsilon.cos(),
        dtheta_1: r_k * psi_1.sin() * epsilon.sin() / r_d,
    })
}
