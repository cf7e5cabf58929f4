//! The revolution family's script bindings: the surface the passes leave
//! on a body of revolution (the true wheel section on each generatrix,
//! the ridges' crests), how the wheel enters a pass, and the steady rest
//! riding that surface.

use super::phases::Infeed;
use super::rest::{self, RestSetup, RestTrack};
use super::surface::{GroundSurface, PassLayer, WheelSection};
use crate::binding::floats::{kernel, numbers, Floats, Numbers};
use crate::binding::{deprecated, wheel_of, ApiGroup, VerifyForm};
use crate::family::{Verification, VerifyRequest};
use crate::math::Real;
use crate::profile::{Polyline, Profile};
use crate::tool::Tool;
use rhai::plugin::*;
use rhai::EvalAltResult;

/// A wheel tool's section: roundings and flat.
fn section(tool: &Tool) -> Result<WheelSection, Box<EvalAltResult>> {
    let w = wheel_of(tool)?;
    Ok(WheelSection {
        radius: w.rounding_radius,
        flat: w.flat(),
    })
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
    kernel(rest::track(
        surface,
        centres,
        w,
        feed,
        infeed,
        spindle_rpm,
        rest,
    ))
}

/// The ground surface, the wheel's infeed, the steady rest.
#[export_module]
pub mod revolution_api {
    use super::*;

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

    /// A steady rest (docs/math.md §2.3): its support, a circle of
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

    /// The steady rest along a pass (docs/math.md §2.3): the wheel moves along
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

    /// How far U's straight line between blocks presses into the surface
    /// at most (mm).
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
        Ok(kernel(rest::exact_u(&surface, at_z, support_radius))?.centre_x)
    }

    /// The same by the seed's first-order formula.
    #[rhai_fn(return_raw)]
    pub fn rest_seed_centre(
        surface: Profile,
        at_z: Real,
        support_radius: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        kernel(rest::seed_u(&surface, at_z, support_radius))
    }
}

/// Earlier releases' forms of the steady rest's functions (see the script
/// host's `compat`).
#[export_module]
pub mod revolution_compat_api {
    use super::*;

    /// The first release's steady rest along a pass (kept until the date
    /// CHANGELOG.md names): the wheel's rounding centres at `(cz, cx)`, the
    /// rest's support of radius `r_o` at `b` along z from the wheel,
    /// riding `previous`, the surface before the pass, ridge-free (the
    /// model it had: the surface the pass is cutting, and the ridges
    /// between turns, are today's `rest_track`'s). A map of `centre_x`
    /// (the exact drop), `seed_centre_x` (the seed's formula),
    /// `contact_z` and `contact_x`, one per point of the pass: no blocks
    /// are added.
    #[rhai_fn(name = "rest_track", return_raw)]
    pub fn rest_track_first_release(
        previous: Profile,
        cz: Floats,
        cx: Floats,
        wheel_radius: Real,
        r_o: Real,
        b: Real,
    ) -> Result<rhai::Map, Box<EvalAltResult>> {
        deprecated(
            "rest_track(previous, cz, cx, wheel_radius, r_o, b)",
            "rest_track(ground_surface(previous), path(cz, cx), wheel, steady_rest(r_o, b, sample, tolerance), feed, spindle_rpm, infeed)",
        );
        kernel(crate::math::positive("wheel radius", wheel_radius))?;
        if cz.0.len() != cx.0.len() {
            return crate::binding::floats::err(format!(
                "rest_track: cz has {} points and cx {}",
                cz.0.len(),
                cx.0.len()
            ));
        }
        let mut columns: [Vec<Real>; 4] = Default::default();
        for &z in cz.0.iter() {
            let drop = kernel(rest::exact_u(&previous, z + b, r_o))?;
            let seed = kernel(rest::seed_u(&previous, z + b, r_o))?;
            for (c, v) in
                columns
                    .iter_mut()
                    .zip([drop.centre_x, seed, drop.contact_z, drop.contact_x])
            {
                c.push(v);
            }
        }
        let names = ["centre_x", "seed_centre_x", "contact_z", "contact_x"];
        Ok(names
            .into_iter()
            .zip(columns)
            .map(|(k, v)| (k.into(), Dynamic::from(Floats::new(v))))
            .collect())
    }

    /// Earlier form of the steady rest's seed formula at `z_r`.
    #[rhai_fn(return_raw)]
    pub fn rest_seed_u(surface: Profile, z_r: Real, r_o: Real) -> Result<Real, Box<EvalAltResult>> {
        deprecated(
            "rest_seed_u(surface, z_r, r_o)",
            "rest_track(...).seed_centre_x",
        );
        kernel(rest::seed_u(&surface, z_r, r_o))
    }

    /// Earlier form of the steady rest's exact drop at `z_r`.
    #[rhai_fn(return_raw)]
    pub fn rest_exact_u(
        surface: Profile,
        z_r: Real,
        r_o: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        deprecated(
            "rest_exact_u(surface, z_r, r_o)",
            "rest_track(...).centre_x",
        );
        Ok(kernel(rest::exact_u(&surface, z_r, r_o))?.centre_x)
    }
}

/// The revolution family's part of the script API.
pub(crate) const SCRIPT_API: ApiGroup = ApiGroup {
    title: "Bodies of revolution: the ground surface, the wheel's infeed, the steady rest (`GroundSurface`, `Infeed`, `SteadyRest`, `RestTrack`)",
    types: |e| {
        e.register_type_with_name::<GroundSurface>("GroundSurface")
            .register_type_with_name::<Infeed>("Infeed")
            .register_type_with_name::<RestSetup>("SteadyRest")
            .register_type_with_name::<RestTrack>("RestTrack");
    },
    register: |e, _| {
        e.register_global_module(rhai::exported_module!(revolution_api).into());
        e.register_global_module(rhai::exported_module!(revolution_compat_api).into());
    },
    verify: Some(VerifyForm {
        key: "profile",
        form: "#{ profile, from, to, tolerance } (and optionally blank, a profile)",
        keys: &["profile", "from", "to", "tolerance", "blank"],
        read: verification,
    }),
};

/// The body of revolution's request from the map of a script's
/// `fn verify(p)`: the nominal profile held to the tolerance over `from`
/// to `to`, the blank where the script gives it.
fn verification(m: &rhai::Map) -> Result<Verification, Option<String>> {
    let num = |k: &str| {
        m.get(k)
            .and_then(crate::binding::floats::number)
            .ok_or(None)
    };
    let profile = |k: &str| m.get(k).and_then(|p| p.clone().try_cast::<Profile>());
    Ok(Verification::new(VerifyRequest {
        profile: profile("profile").ok_or(None)?,
        from: num("from")?,
        to: num("to")?,
        tolerance: num("tolerance")?,
        blank: match m.get("blank") {
            None => None,
            Some(_) => Some(Box::new(profile("blank").ok_or_else(|| {
                Some("fn verify(p): blank must be a profile (the blank's)".to_owned())
            })?)),
        },
    }))
}
