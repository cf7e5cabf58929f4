//! Transforms for scripts (docs/math.md §1): the six elementary factors, the
//! universal chain of seed 003, and points mapped through them. Angles the
//! script gives are degrees, in functions named `_deg`.

use super::floats::{err, kernel, numbers, Floats, Numbers};
use crate::math::{Mat4, Real};
use crate::transform::FactorGeometry;
use crate::transform::{map_points, Chain, FactorKind};
use rhai::plugin::*;
use rhai::EvalAltResult;

/// A 4x4 transform for scripts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform(pub Mat4);

/// Points `(x, y, z)` as three arrays.
#[derive(Debug, Clone)]
pub struct Points {
    x: Floats,
    y: Floats,
    z: Floats,
}

fn factor(kind: FactorKind, value: Real) -> Transform {
    Transform(kind.matrix(value))
}

/// Transforms (docs/math.md §1): the elementary factors and the universal chain.
#[export_module]
pub mod transform_api {
    use super::*;

    /// A translation along X by `mm`. Compose with `*`.
    ///
    /// ```rhai
    /// let a = rz_deg(30.0) * tx(10.0);
    /// ```
    pub fn tx(mm: Real) -> Transform {
        factor(FactorKind::Tx, mm)
    }

    /// A translation along Y by `mm`.
    pub fn ty(mm: Real) -> Transform {
        factor(FactorKind::Ty, mm)
    }

    /// A translation along Z by `mm`.
    pub fn tz(mm: Real) -> Transform {
        factor(FactorKind::Tz, mm)
    }

    /// A rotation about X by `deg` degrees (right-handed).
    pub fn rx_deg(deg: Real) -> Transform {
        factor(FactorKind::Rx, deg.to_radians())
    }

    /// A rotation about Y by `deg` degrees.
    pub fn ry_deg(deg: Real) -> Transform {
        factor(FactorKind::Ry, deg.to_radians())
    }

    /// A rotation about Z by `deg` degrees.
    pub fn rz_deg(deg: Real) -> Transform {
        factor(FactorKind::Rz, deg.to_radians())
    }

    /// The universal chain of seed 003 (S003-3) for its fifteen parameters
    /// in the seed's order `a b c phi a1 b1 c1 theta a2 b2 c2 psi a3 b3 c3`
    /// (mm; the angles phi, theta, psi in degrees).
    #[rhai_fn(return_raw)]
    pub fn universal_deg(q: Numbers) -> Result<Transform, Box<EvalAltResult>> {
        let q = numbers(&q, "universal_deg")?;
        if q.len() != 15 {
            return err(format!("universal_deg needs 15 values, got {}", q.len()));
        }
        let mut v = q.as_ref().clone();
        for i in [3, 7, 11] {
            v[i] = v[i].to_radians();
        }
        kernel(Chain::universal().matrix(&v)).map(Transform)
    }

    /// `a` then `b` in the product `a * b` (b acts first on a point).
    #[rhai_fn(name = "*")]
    pub fn compose(a: Transform, b: Transform) -> Transform {
        Transform(a.0 * b.0)
    }

    /// The points `(x, y, z)` mapped by `t`; the result has `.x`, `.y`, `.z`.
    #[rhai_fn(pure, return_raw)]
    pub fn apply(
        t: &mut Transform,
        x: Numbers,
        y: Numbers,
        z: Numbers,
    ) -> Result<Points, Box<EvalAltResult>> {
        let (x, y, z) = (
            numbers(&x, "apply x")?,
            numbers(&y, "apply y")?,
            numbers(&z, "apply z")?,
        );
        let [x, y, z] = kernel(map_points(&t.0, &x, &y, &z))?;
        Ok(Points {
            x: Floats::new(x),
            y: Floats::new(y),
            z: Floats::new(z),
        })
    }

    /// The points' x.
    #[rhai_fn(get = "x", pure)]
    pub fn points_x(p: &mut Points) -> Floats {
        p.x.clone()
    }

    /// The points' y.
    #[rhai_fn(get = "y", pure)]
    pub fn points_y(p: &mut Points) -> Floats {
        p.y.clone()
    }

    /// The points' z.
    #[rhai_fn(get = "z", pure)]
    pub fn points_z(p: &mut Points) -> Floats {
        p.z.clone()
    }
}
