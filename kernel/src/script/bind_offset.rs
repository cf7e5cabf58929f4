//! Equidistants, drops, envelopes and the steady rest for scripts. Wheel
//! functions take the wheel's `Tool`, never its radius.

use super::floats::{err, kernel, numbers, Floats, Numbers};
use crate::math::Real;
use crate::offset::rest::{RestSetup, RestTrack};
use crate::offset::{self, Equidistant, Side};
use crate::profile::{Polyline, Profile};
use crate::tool::{Tool, ToolShape};
use rhai::plugin::*;
use rhai::EvalAltResult;

/// The rounding radius of a wheel tool.
pub(super) fn rounding_radius(tool: &Tool) -> Result<Real, Box<EvalAltResult>> {
    match tool.shape {
        ToolShape::Wheel(w) => Ok(w.rounding_radius),
        _ => err(format!("tool '{}' is not a grinding wheel", tool.name)),
    }
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

/// Equidistants, drops, envelopes and the steady rest.
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

    /// A steady rest (MATH §2.3): its support, a circle of
    /// `support_radius` in the axial section, stands at `offset` along z
    /// from the wheel (z_r = z + offset). Its track samples the surface
    /// under the support every `sample` mm, and the wheel's swept surface
    /// to `resolution` mm.
    #[rhai_fn(return_raw)]
    pub fn steady_rest(
        support_radius: Real,
        offset: Real,
        sample: Real,
        resolution: Real,
    ) -> Result<RestSetup, Box<EvalAltResult>> {
        kernel(crate::math::positive("rest support radius", support_radius))?;
        kernel(crate::math::finite("rest offset", offset))?;
        kernel(crate::math::positive("rest surface sample", sample))?;
        kernel(crate::math::positive("rest resolution", resolution))?;
        Ok(RestSetup {
            radius: support_radius,
            offset_b: offset,
            sample,
            resolution,
        })
    }

    /// The steady rest along a pass (MATH §2.3): the wheel's rounding
    /// centre moves along `centres` (one way along z) over a workpiece whose
    /// surface before the pass is `previous`. The result has, per block,
    /// `.centre_x`, `.contact_z`, `.contact_x` (the exact drop on the current
    /// surface) and `.seed_centre_x` (the seed's formula on it), and
    /// `.max_model_difference` (mm) with `.max_difference_block` (from 0).
    #[rhai_fn(return_raw)]
    pub fn rest_track(
        previous: Profile,
        centres: Polyline,
        wheel: Tool,
        rest: RestSetup,
    ) -> Result<RestTrack, Box<EvalAltResult>> {
        kernel(offset::rest::track(
            &previous,
            &centres.z,
            &centres.x,
            rounding_radius(&wheel)?,
            &rest,
        ))
    }

    /// The support centre's x at each block (exact model).
    #[rhai_fn(get = "centre_x", pure)]
    pub fn track_centre_x(t: &mut RestTrack) -> Floats {
        Floats::new(t.centre_x.clone())
    }

    /// The contact point's z at each block.
    #[rhai_fn(get = "contact_z", pure)]
    pub fn track_contact_z(t: &mut RestTrack) -> Floats {
        Floats::new(t.contact_z.clone())
    }

    /// The contact point's x at each block.
    #[rhai_fn(get = "contact_x", pure)]
    pub fn track_contact_x(t: &mut RestTrack) -> Floats {
        Floats::new(t.contact_x.clone())
    }

    /// The support centre's x by the seed's formula at each block.
    #[rhai_fn(get = "seed_centre_x", pure)]
    pub fn track_seed_centre_x(t: &mut RestTrack) -> Floats {
        Floats::new(t.seed_centre_x.clone())
    }

    /// The largest |seed - exact| over the pass (mm).
    #[rhai_fn(get = "max_model_difference", pure)]
    pub fn track_difference(t: &mut RestTrack) -> Real {
        t.max_model_difference
    }

    /// The block (from 0) where it is.
    #[rhai_fn(get = "max_difference_block", pure)]
    pub fn track_difference_block(t: &mut RestTrack) -> i64 {
        t.max_difference_block as i64
    }

    /// The surface after a pass: the lower of `previous` and what the
    /// wheel's rounding leaves moving along `centres`, at `previous`'s
    /// nodes, the swept surface exact to `resolution` (mm).
    #[rhai_fn(return_raw)]
    pub fn cut(
        previous: Profile,
        centres: Polyline,
        wheel: Tool,
        resolution: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        kernel(offset::rest::after_pass(
            &previous,
            &centres.z,
            &centres.x,
            rounding_radius(&wheel)?,
            resolution,
        ))
    }

    /// The steady rest's support centre x at `at_z` on `surface` by the
    /// exact drop of a circle of `support_radius`.
    #[rhai_fn(return_raw)]
    pub fn rest_exact_centre(
        surface: Profile,
        at_z: Real,
        support_radius: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        Ok(kernel(offset::rest::exact_u(&surface, at_z, support_radius))?.centre_x)
    }

    /// The same by the seed's first-order formula.
    #[rhai_fn(return_raw)]
    pub fn rest_seed_centre(
        surface: Profile,
        at_z: Real,
        support_radius: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        kernel(offset::rest::seed_u(&surface, at_z, support_radius))
    }
}
