//! Equidistants, drops, envelopes, wheel paths and ridges for scripts.
//! Wheel functions take the wheel's `Tool`, never its radius. (The ground
//! surface and the steady rest are the revolution family's:
//! `revolution/script.rs`.)

use crate::binding::floats::{err, kernel, numbers, Floats, Numbers};
use crate::binding::wheel_of;
use crate::math::Real;
use crate::offset::{self, Equidistant, Side};
use crate::profile::{Polyline, Profile};
use crate::tool::Tool;
use rhai::plugin::*;
use rhai::EvalAltResult;

/// The rounding radius of a wheel tool.
pub(super) fn rounding_radius(tool: &Tool) -> Result<Real, Box<EvalAltResult>> {
    wheel_of(tool).map(|w| w.rounding_radius)
}

fn to_side(s: &str) -> Result<Side, Box<EvalAltResult>> {
    match s {
        "outside" => Ok(Side::Outside),
        "inside" => Ok(Side::Inside),
        other => err(format!(
            "side must be \"outside\" or \"inside\", not \"{other}\""
        )),
    }
}

/// The share of a tolerance a wheel path may stray from the curve it
/// follows between nodes, and leave in a kink it bridges.
const PATH_SHARE: Real = 0.1;

/// Equidistants, drops, envelopes, wheel paths and ridges.
#[export_module]
pub mod offset_api {
    use super::*;

    /// The centres of the wheel's rounding touching the profile at each
    /// node (and round each convex corner), on `side` ("outside" or
    /// "inside"); refuses a wheel rounder than the profile, naming every z.
    /// The result has `.z`, `.x`, `.slope` and `.path`.
    #[rhai_fn(name = "equidistant", return_raw)]
    pub fn equidistant_tool(
        p: Profile,
        wheel: Tool,
        side: &str,
    ) -> Result<Equidistant, Box<EvalAltResult>> {
        kernel(offset::equidistant(
            &p,
            rounding_radius(&wheel)?,
            to_side(side)?,
        ))
    }

    /// As `equidistant(p, wheel, side)` for a circle of `radius`.
    #[rhai_fn(name = "equidistant", return_raw)]
    pub fn equidistant_radius(
        p: Profile,
        radius: Real,
        side: &str,
    ) -> Result<Equidistant, Box<EvalAltResult>> {
        kernel(offset::equidistant(&p, radius, to_side(side)?))
    }

    /// The centres' z.
    #[rhai_fn(get = "z", pure)]
    pub fn equidistant_z(e: &mut Equidistant) -> Floats {
        Floats::new(e.z.clone())
    }

    /// The centres' x.
    #[rhai_fn(get = "x", pure)]
    pub fn equidistant_x(e: &mut Equidistant) -> Floats {
        Floats::new(e.x.clone())
    }

    /// The profile's slope dx/dz where each centre touches it.
    #[rhai_fn(get = "slope", pure)]
    pub fn equidistant_slope(e: &mut Equidistant) -> Floats {
        Floats::new(e.slope.clone())
    }

    /// The centres as a path (z increasing).
    #[rhai_fn(get = "path", pure)]
    pub fn equidistant_path(e: &mut Equidistant) -> Polyline {
        e.path()
    }

    /// The centre x of a circle of `radius` at `centre_z` dropped onto the
    /// profile from outside.
    #[rhai_fn(return_raw)]
    pub fn drop_circle(
        p: Profile,
        centre_z: Real,
        radius: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        Ok(kernel(offset::drop_circle(&p, centre_z, radius, Side::Outside))?.centre_x)
    }

    /// The surface left by circles of `radius` centred on the path's points
    /// (a wheel from outside), evaluated at `at`; infinite where no circle
    /// reaches.
    #[rhai_fn(return_raw)]
    pub fn envelope(
        centres: Polyline,
        radius: Real,
        at: Numbers,
    ) -> Result<Floats, Box<EvalAltResult>> {
        let at = numbers(&at, "envelope at")?;
        let env = kernel(offset::CircleEnvelope::new(
            &centres.z,
            &centres.x,
            radius,
            Side::Outside,
        ))?;
        Ok(Floats::new(env.eval_many(&at)))
    }

    /// The path of the wheel's reference (the middle of its flat; the
    /// rounding's centre for a wheel rounded across its width) over the
    /// profile from outside: the roundings' equidistant, dilated by the
    /// flat, so that no part of the wheel's true section cuts into the
    /// profile. Refuses a wheel rounder than the profile, naming every z.
    #[rhai_fn(return_raw)]
    pub fn wheel_path(p: Profile, wheel: Tool) -> Result<Polyline, Box<EvalAltResult>> {
        let w = wheel_of(&wheel)?;
        let e = kernel(offset::equidistant(&p, w.rounding_radius, Side::Outside))?;
        kernel(offset::flat_path(&e.z, &e.x, w.flat(), Side::Outside))
    }

    /// As `wheel_path(p, wheel)`, following the curve the wheel must grind
    /// within a share of `tolerance` (mm): between the profile's nodes
    /// (a drawing's stations, far apart) the path's blocks stay within a
    /// tenth of it of the true path, and a concave kink the wheel bridges
    /// within a tenth of it (a taper's stations joined by lines) is no
    /// corner. A corner it cannot enter is refused, named by z.
    #[rhai_fn(name = "wheel_path", return_raw)]
    pub fn wheel_path_within(
        p: Profile,
        wheel: Tool,
        tolerance: Real,
    ) -> Result<Polyline, Box<EvalAltResult>> {
        kernel(crate::math::positive("wheel path tolerance", tolerance))?;
        let w = wheel_of(&wheel)?;
        let r = w.rounding_radius;
        let share = PATH_SHARE * tolerance;
        let fine = kernel(offset::refined(&p, r, Side::Outside, share))?;
        let e = kernel(offset::equidistant_within(&fine, r, Side::Outside, share))?;
        kernel(offset::flat_path(&e.z, &e.x, w.flat(), Side::Outside))
    }

    /// The ridge (mm) the wheel leaves on a straight generatrix at a feed
    /// of `feed_per_rev` mm per revolution of the part (docs/math.md §2.4).
    #[rhai_fn(return_raw)]
    pub fn ridge_height(wheel: Tool, feed_per_rev: Real) -> Result<Real, Box<EvalAltResult>> {
        kernel(crate::math::finite("feed per revolution", feed_per_rev))?;
        Ok(wheel_of(&wheel)?.ridge(feed_per_rev))
    }

    /// The largest feed per revolution (mm) whose ridge is at most
    /// `height` mm.
    #[rhai_fn(return_raw)]
    pub fn ridge_feed(wheel: Tool, height: Real) -> Result<Real, Box<EvalAltResult>> {
        kernel(crate::math::positive("ridge height", height))?;
        Ok(wheel_of(&wheel)?.feed_for_ridge(height))
    }
}
