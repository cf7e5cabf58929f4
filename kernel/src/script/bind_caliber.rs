//! The caliber's groove for scripts (MATH §3): the groove from its tables,
//! its points, normals and sections, the scallop between passes, the pass
//! angles, and the seed's wheel pose. Angles are radians, as everywhere in
//! the script API; the tables give theta in degrees.

use super::floats::{kernel, Floats};
use crate::caliber::{self, Groove, SeedPose};
use crate::math::Real;
use crate::profile::Table;
use rhai::plugin::*;
use rhai::{Array, EvalAltResult};

/// The caliber's groove, scallop and pass angles, the seed's pose.
#[export_module]
pub mod caliber_api {
    use super::*;

    /// The groove of a roll of radius `roll_radius` (mm) from one table:
    /// the columns of theta (degrees), depth Hp and width B (mm), named by
    /// header, letter or number; errors name file, row and column.
    #[rhai_fn(return_raw)]
    pub fn groove(
        roll_radius: Real,
        table: Table,
        theta: &str,
        depth: &str,
        width: &str,
    ) -> Result<Groove, Box<EvalAltResult>> {
        kernel(Groove::from_tables(
            roll_radius,
            (&table, theta, depth),
            (&table, theta, width),
        ))
    }

    /// The groove's point `[x, y, z]` at `(theta, psi)` in the roll's frame.
    #[rhai_fn(pure, return_raw)]
    pub fn point(g: &mut Groove, theta: Real, psi: Real) -> Result<Array, Box<EvalAltResult>> {
        let p = kernel(g.point(theta, psi))?;
        Ok(vec![p.x.into(), p.y.into(), p.z.into()])
    }

    /// The groove's unit normal at `(theta, psi)`, out of the material.
    #[rhai_fn(pure, return_raw)]
    pub fn normal(g: &mut Groove, theta: Real, psi: Real) -> Result<Array, Box<EvalAltResult>> {
        let n = kernel(g.normal(theta, psi))?;
        Ok(vec![n.x.into(), n.y.into(), n.z.into()])
    }

    /// The smallest radius of curvature of the groove's sections (mm).
    #[rhai_fn(get = "min_curvature_radius", pure, return_raw)]
    pub fn min_curvature_radius(g: &mut Groove) -> Result<Real, Box<EvalAltResult>> {
        Ok(kernel(g.min_curvature_radius())?.0)
    }

    /// The tables' range of theta (rad) as `[from, to]`.
    #[rhai_fn(get = "theta_range", pure)]
    pub fn theta_range(g: &mut Groove) -> Array {
        let (a, b) = g.theta_range();
        vec![a.into(), b.into()]
    }

    /// The pass angles psi (rad) across the groove for a rounding `r_k`,
    /// at most `dpsi` apart out to `psi_max`: `#{ psi, scallop }`, the
    /// scallop (mm) the step leaves in the widest section.
    #[rhai_fn(pure, return_raw)]
    pub fn pass_angles(
        g: &mut Groove,
        r_k: Real,
        dpsi: Real,
        psi_max: Real,
    ) -> Result<rhai::Map, Box<EvalAltResult>> {
        let (psi, rz) = kernel(g.pass_angles(r_k, dpsi, psi_max))?;
        let mut m = rhai::Map::new();
        m.insert("psi".into(), Dynamic::from(Floats::new(psi)));
        m.insert("scallop".into(), rz.into());
        Ok(m)
    }

    /// The scallop (mm) two rounding circles of radius `r_k` leave `dpsi`
    /// apart in a section circle of radius `section_radius` (MATH §3.3).
    #[rhai_fn(return_raw)]
    pub fn scallop_height(
        section_radius: Real,
        r_k: Real,
        dpsi: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        kernel(caliber::scallop_height(section_radius, r_k, dpsi))
    }

    /// The largest step `dpsi` (rad) whose scallop is at most `rz` mm.
    #[rhai_fn(return_raw)]
    pub fn step_for_scallop(
        section_radius: Real,
        r_k: Real,
        rz: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        kernel(caliber::step_for_scallop(section_radius, r_k, rz))
    }

    /// The seed's pose of a wheel (largest radius `r_k0`, rounding `r_k`)
    /// on the pass at `psi`, at `theta` (MATH §3.4): `.x_k`, `.z_k`,
    /// `.psi_1`, `.mu`, `.dtheta`, `.epsilon`, `.dtheta_1`, ...
    #[rhai_fn(pure, return_raw)]
    pub fn seed_pose(
        g: &mut Groove,
        theta: Real,
        psi: Real,
        r_k0: Real,
        r_k: Real,
    ) -> Result<SeedPose, Box<EvalAltResult>> {
        kernel(caliber::seed_pose(g, theta, psi, r_k0, r_k))
    }

    /// The contact point's position along the roll's axis (mm).
    #[rhai_fn(get = "x_a", pure)]
    pub fn x_a(p: &mut SeedPose) -> Real {
        p.x_a
    }
    /// The contact point's depth from the periphery (mm).
    #[rhai_fn(get = "z_a", pure)]
    pub fn z_a(p: &mut SeedPose) -> Real {
        p.z_a
    }
    /// The section's normal angle at the contact (rad).
    #[rhai_fn(get = "psi_1", pure)]
    pub fn psi_1(p: &mut SeedPose) -> Real {
        p.psi_1
    }
    /// The rounding centre along the roll's axis (mm).
    #[rhai_fn(get = "x_k", pure)]
    pub fn x_k(p: &mut SeedPose) -> Real {
        p.x_k
    }
    /// The rounding centre's depth (mm).
    #[rhai_fn(get = "z_k", pure)]
    pub fn z_k(p: &mut SeedPose) -> Real {
        p.z_k
    }
    /// The pressure angle mu (rad).
    #[rhai_fn(get = "mu", pure)]
    pub fn mu(p: &mut SeedPose) -> Real {
        p.mu
    }
    /// The roll angle's correction (rad).
    #[rhai_fn(get = "dtheta", pure)]
    pub fn dtheta(p: &mut SeedPose) -> Real {
        p.dtheta
    }
    /// The swivel epsilon (rad).
    #[rhai_fn(get = "epsilon", pure)]
    pub fn epsilon(p: &mut SeedPose) -> Real {
        p.epsilon
    }
    /// The rounding centre along the axis with the swivel (mm).
    #[rhai_fn(get = "x_k_swivelled", pure)]
    pub fn x_k_swivelled(p: &mut SeedPose) -> Real {
        p.x_k_swivelled
    }
    /// The roll angle's swivel correction (rad).
    #[rhai_fn(get = "dtheta_1", pure)]
    pub fn dtheta_1(p: &mut SeedPose) -> Real {
        p.dtheta_1
    }
}
