//! Equidistants, drops, envelopes and the steady rest for scripts. Wheel
//! functions take the wheel's `Tool`, never its radius.

use super::floats::{err, kernel, numbers, Floats, Numbers};
use crate::math::Real;
use crate::offset::phases::Infeed;
use crate::offset::rest::{RestSetup, RestTrack};
use crate::offset::surface::{GroundSurface, PassLayer, WheelSection};
use crate::offset::{self, Equidistant, Side};
use crate::profile::{Polyline, Profile};
use crate::tool::{Tool, ToolShape};
use rhai::plugin::*;
use rhai::EvalAltResult;

/// The wheel of a wheel tool.
pub(super) fn wheel_of(tool: &Tool) -> Result<crate::tool::Wheel, Box<EvalAltResult>> {
    match tool.shape {
        ToolShape::Wheel(w) => Ok(w),
        _ => err(format!("tool '{}' is not a grinding wheel", tool.name)),
    }
}

/// The rounding radius of a wheel tool.
pub(super) fn rounding_radius(tool: &Tool) -> Result<Real, Box<EvalAltResult>> {
    wheel_of(tool).map(|w| w.rounding_radius)
}

/// A wheel tool's section: roundings and flat.
fn section(tool: &Tool) -> Result<WheelSection, Box<EvalAltResult>> {
    let w = wheel_of(tool)?;
    Ok(WheelSection {
        radius: w.rounding_radius,
        flat: w.flat(),
    })
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

/// The surface after a pass (the bindings `cut`, with or without the
/// wheel's infeed).
fn cut_layer(
    surface: GroundSurface,
    centres: &Polyline,
    wheel: &Tool,
    feed: Real,
    infeed: Option<Infeed>,
    spindle_rpm: Real,
) -> Result<GroundSurface, Box<EvalAltResult>> {
    let w = section(wheel)?;
    let layer = PassLayer::new(&centres.z, &centres.x, w, feed, infeed, spindle_rpm);
    Ok(surface.with(kernel(layer)?))
}

/// The steady rest along a pass (the bindings `rest_track`, with or
/// without the wheel's infeed).
fn track_rest(
    surface: &GroundSurface,
    centres: &Polyline,
    wheel: &Tool,
    rest: &RestSetup,
    feed: Real,
    infeed: Option<Infeed>,
    spindle_rpm: Real,
) -> Result<RestTrack, Box<EvalAltResult>> {
    let w = section(wheel)?;
    kernel(offset::rest::track(
        surface,
        centres,
        w,
        feed,
        infeed,
        spindle_rpm,
        rest,
    ))
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

    /// The ridge (mm) the wheel leaves on a straight generatrix at a feed
    /// of `feed_per_rev` mm per revolution of the part (MATH §2.4).
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

    /// The surface of a part about to be ground: the blank, taken as the
    /// polyline through its nodes (a step stays a step).
    pub fn ground_surface(blank: Profile) -> GroundSurface {
        GroundSurface::new(blank)
    }

    /// The surface after a pass of the wheel along `centres` at `feed`
    /// (mm/min) while the part turns at `spindle_rpm`: on each generatrix
    /// the wheel's true section where it met it, the ridges' crests as one
    /// surface of revolution.
    /// The wheel is taken to have stood a revolution at the path's first
    /// point; give its `infeed` where it came down onto it.
    #[rhai_fn(return_raw)]
    pub fn cut(
        surface: GroundSurface,
        centres: Polyline,
        wheel: Tool,
        feed: Real,
        spindle_rpm: Real,
    ) -> Result<GroundSurface, Box<EvalAltResult>> {
        cut_layer(surface, &centres, &wheel, feed, None, spindle_rpm)
    }

    /// The surface after a pass as `cut`, the wheel having come to the
    /// path's first point by `infeed` (the part turning while it came
    /// down: the infeed's last revolution is what the first point keeps).
    #[rhai_fn(name = "cut", return_raw)]
    pub fn cut_entered(
        surface: GroundSurface,
        centres: Polyline,
        wheel: Tool,
        feed: Real,
        spindle_rpm: Real,
        infeed: Infeed,
    ) -> Result<GroundSurface, Box<EvalAltResult>> {
        cut_layer(surface, &centres, &wheel, feed, Some(infeed), spindle_rpm)
    }

    /// How the wheel comes to a pass's first point: a straight move from
    /// `(z, x)` at `feed` mm/min (the program's infeed block).
    #[rhai_fn(return_raw)]
    pub fn infeed(z: Real, x: Real, feed: Real) -> Result<Infeed, Box<EvalAltResult>> {
        kernel(crate::math::finite("infeed start z", z))?;
        kernel(crate::math::finite("infeed start x", x))?;
        kernel(crate::math::positive("infeed feed", feed))?;
        Ok(Infeed { z, x, feed })
    }

    /// The surface at `z`.
    #[rhai_fn(pure)]
    pub fn surface_x(s: &mut GroundSurface, z: Real) -> Real {
        s.eval_many(&[z], None)[0]
    }

    /// A steady rest (MATH §2.3): its support, a circle of
    /// `support_radius` in the axial section, stands at `offset` along z
    /// from the wheel (z_r = z + offset). Its track samples the surface
    /// under the support every `sample` mm, and adds blocks until the
    /// control's straight line of U between blocks stays within
    /// `tolerance` mm of the support's exact drop.
    #[rhai_fn(return_raw)]
    pub fn steady_rest(
        support_radius: Real,
        offset: Real,
        sample: Real,
        tolerance: Real,
    ) -> Result<RestSetup, Box<EvalAltResult>> {
        kernel(crate::math::positive("rest support radius", support_radius))?;
        kernel(crate::math::finite("rest offset", offset))?;
        kernel(crate::math::positive("rest surface sample", sample))?;
        kernel(crate::math::positive("rest tolerance", tolerance))?;
        Ok(RestSetup {
            radius: support_radius,
            offset_b: offset,
            sample,
            tolerance,
        })
    }

    /// The steady rest along a pass (MATH §2.3): the wheel moves along
    /// `centres` (one way along z) at `feed` mm/min, the part turning at
    /// `spindle_rpm`, over `surface`. The result's `.path` is the pass with
    /// the blocks the rest needs added (on the wheel's line); per point of
    /// it `.centre_x`, `.contact_z`, `.contact_x` (the exact drop on the
    /// current surface) and `.seed_centre_x` (the seed's formula on it);
    /// `.max_model_difference` (mm) with `.max_difference_block` (from 0);
    /// `.max_gap` and `.max_press` (mm): how far U's straight line between
    /// blocks stands off the surface or presses into it; `.added`.
    #[rhai_fn(return_raw)]
    pub fn rest_track(
        surface: GroundSurface,
        centres: Polyline,
        wheel: Tool,
        rest: RestSetup,
        feed: Real,
        spindle_rpm: Real,
    ) -> Result<RestTrack, Box<EvalAltResult>> {
        track_rest(&surface, &centres, &wheel, &rest, feed, None, spindle_rpm)
    }

    /// The steady rest along a pass as `rest_track`, the wheel having come
    /// to the path's first point by `infeed`.
    #[rhai_fn(name = "rest_track", return_raw)]
    pub fn rest_track_entered(
        surface: GroundSurface,
        centres: Polyline,
        wheel: Tool,
        rest: RestSetup,
        feed: Real,
        spindle_rpm: Real,
        infeed: Infeed,
    ) -> Result<RestTrack, Box<EvalAltResult>> {
        track_rest(
            &surface,
            &centres,
            &wheel,
            &rest,
            feed,
            Some(infeed),
            spindle_rpm,
        )
    }

    /// The pass with the rest's blocks added.
    #[rhai_fn(get = "path", pure)]
    pub fn track_path(t: &mut RestTrack) -> Polyline {
        t.path.clone()
    }

    /// The support centre's x at each point (exact model).
    #[rhai_fn(get = "centre_x", pure)]
    pub fn track_centre_x(t: &mut RestTrack) -> Floats {
        Floats::new(t.centre_x.clone())
    }

    /// The contact point's z at each point.
    #[rhai_fn(get = "contact_z", pure)]
    pub fn track_contact_z(t: &mut RestTrack) -> Floats {
        Floats::new(t.contact_z.clone())
    }

    /// The contact point's x at each point.
    #[rhai_fn(get = "contact_x", pure)]
    pub fn track_contact_x(t: &mut RestTrack) -> Floats {
        Floats::new(t.contact_x.clone())
    }

    /// The support centre's x by the seed's formula at each point.
    #[rhai_fn(get = "seed_centre_x", pure)]
    pub fn track_seed_centre_x(t: &mut RestTrack) -> Floats {
        Floats::new(t.seed_centre_x.clone())
    }

    /// The largest |seed - exact| over the pass (mm).
    #[rhai_fn(get = "max_model_difference", pure)]
    pub fn track_difference(t: &mut RestTrack) -> Real {
        t.max_model_difference
    }

    /// The point (from 0) where it is.
    #[rhai_fn(get = "max_difference_block", pure)]
    pub fn track_difference_block(t: &mut RestTrack) -> i64 {
        t.max_difference_block as i64
    }

    /// How far U's straight line between blocks stands off the surface at
    /// most (mm).
    #[rhai_fn(get = "max_gap", pure)]
    pub fn track_gap(t: &mut RestTrack) -> Real {
        t.max_gap
    }

    /// How far it presses into the surface at most (mm).
    /// `track.stand_off_on(grid)`: U's straight line between blocks
    /// minus the exact drop (mm; + off the surface, - into it) at each z
    /// of `grid` (increasing, evenly spaced; the support centre's z): the
    /// largest checked value within half a step, else interpolated; 0
    /// beyond the pass's reach.
    #[rhai_fn(name = "stand_off_on", pure, return_raw)]
    pub fn track_stand_off_on(
        t: &mut RestTrack,
        grid: Numbers,
    ) -> Result<Floats, Box<EvalAltResult>> {
        let grid = numbers(&grid, "stand-off grid")?;
        kernel(crate::profile::check_abscissa("stand-off grid", &grid))?;
        Ok(Floats::new(t.stand_off_on(&grid)))
    }

    #[rhai_fn(get = "max_press", pure)]
    pub fn track_press(t: &mut RestTrack) -> Real {
        t.max_press
    }

    /// Points the rest added to the pass.
    #[rhai_fn(get = "added", pure)]
    pub fn track_added(t: &mut RestTrack) -> i64 {
        t.added as i64
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
