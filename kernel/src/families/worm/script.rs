//! Worm threads for scripts (docs/math.md §4): the worm's sizes, the thread
//! cutter, the acceleration and deceleration lengths, the plan of passes.
//! Angles are degrees here (as a process sheet gives them); lengths mm.

use crate::binding::floats::kernel;
use crate::binding::{ApiGroup, VerifyForm};
use crate::families::thread::script::{cutter_of, plan_map, VerifyMap};
use crate::families::thread::{self, ThreadCutter, WormSizes};
use crate::family::Verification;
use crate::math::Real;
use crate::tool::{Tool, ToolShape};
use rhai::plugin::*;
use rhai::{EvalAltResult, Map};

/// The worm's sizes, the cutter, S1 and S2, the plan.
#[export_module]
pub mod worm_api {
    use super::*;

    /// A cylindrical ZA worm: module `m`, `z1` starts, pitch diameter
    /// `d1`, clearance factor `c` (c*), profile half-angle `alpha_deg` in
    /// the axial section, thread thickness at the pitch line `s_a1` (0:
    /// half the axial pitch).
    #[rhai_fn(return_raw)]
    pub fn worm(
        m: Real,
        z1: i64,
        d1: Real,
        c: Real,
        alpha_deg: Real,
        s_a1: Real,
    ) -> Result<WormSizes, Box<EvalAltResult>> {
        worm_of(m, z1, d1, c, alpha_deg, s_a1, "ZA")
    }

    /// A cylindrical worm of flank kind `profile` (DIN 3975): `ZA`
    /// (straight in the axial section; `alpha_deg` the half-angle there),
    /// `ZN` (straight in the space's normal section) or `ZI` (involute
    /// helicoids), their `alpha_deg` the normal pressure angle; the rest
    /// as the six-argument `worm`.
    ///
    /// ```rhai
    /// let w = worm(5.0, 2, 50.0, 0.2, 20.0, 0.0, "ZI");
    /// ```
    #[rhai_fn(name = "worm", return_raw)]
    pub fn worm_of(
        m: Real,
        z1: i64,
        d1: Real,
        c: Real,
        alpha_deg: Real,
        s_a1: Real,
        profile: &str,
    ) -> Result<WormSizes, Box<EvalAltResult>> {
        kernel(WormSizes::with_profile(
            m,
            z1,
            d1,
            c,
            alpha_deg.to_radians(),
            (s_a1 != 0.0).then_some(s_a1),
            kernel(thread::WormProfile::parse(profile))?,
        ))
    }

    /// The flanks' kind: `ZA`, `ZN` or `ZI`.
    #[rhai_fn(get = "profile", pure)]
    pub fn profile(w: &mut WormSizes) -> String {
        w.profile.name().into()
    }

    /// The flanks' half-angle in the axial section at the pitch diameter
    /// (deg): a ZA worm's `alpha_deg`; a ZN or ZI worm's from its normal
    /// angle.
    #[rhai_fn(get = "axial_alpha_deg", pure)]
    pub fn axial_alpha_deg(w: &mut WormSizes) -> Real {
        w.axial_alpha().to_degrees()
    }

    /// The full-profile form cutter (tool `number`) ground to the worm's
    /// curved flanks (ZN, ZI): its tip the space at the root, its flanks
    /// the space's curves, `nose_radius` at its corners, reaching 2 mm
    /// above the worm's tip. It plunges straight in (flank order radial).
    #[rhai_fn(pure, return_raw)]
    pub fn form_cutter(
        w: &mut WormSizes,
        name: &str,
        number: i64,
        nose_radius: Real,
    ) -> Result<Tool, Box<EvalAltResult>> {
        let number = crate::binding::tool_number(name, number)?;
        let c = kernel(w.section().form_cutter(nose_radius))?;
        Ok(Tool::thread_cutter(name, number, c))
    }

    /// Axial pitch `p_x = pi m` (mm).
    #[rhai_fn(get = "axial_pitch", pure)]
    pub fn axial_pitch(w: &mut WormSizes) -> Real {
        w.axial_pitch()
    }
    /// Lead `P_z = z1 p_x` (mm).
    #[rhai_fn(get = "lead", pure)]
    pub fn lead(w: &mut WormSizes) -> Real {
        w.lead()
    }
    /// Number of starts.
    #[rhai_fn(get = "starts", pure)]
    pub fn starts(w: &mut WormSizes) -> i64 {
        i64::from(w.starts)
    }
    /// Thread height `h1 = (2 + c*) m` (mm).
    #[rhai_fn(get = "height", pure)]
    pub fn height(w: &mut WormSizes) -> Real {
        w.height()
    }
    /// Tip diameter `d_a1` (mm): the blank's.
    #[rhai_fn(get = "tip_diameter", pure)]
    pub fn tip_diameter(w: &mut WormSizes) -> Real {
        w.tip_diameter()
    }
    /// Root diameter `d_f1` (mm).
    #[rhai_fn(get = "root_diameter", pure)]
    pub fn root_diameter(w: &mut WormSizes) -> Real {
        w.root_diameter()
    }
    /// Thread thickness at the pitch line `S_a1` (mm).
    #[rhai_fn(get = "thickness", pure)]
    pub fn thickness(w: &mut WormSizes) -> Real {
        w.thickness
    }
    /// The space's width at the root (mm): the widest cutter tip.
    #[rhai_fn(get = "root_space", pure)]
    pub fn root_space(w: &mut WormSizes) -> Real {
        w.root_space()
    }
    /// The lead angle (deg).
    #[rhai_fn(get = "lead_angle_deg", pure)]
    pub fn lead_angle_deg(w: &mut WormSizes) -> Real {
        w.lead_angle().to_degrees()
    }
    /// The profile half-angle (deg).
    #[rhai_fn(get = "alpha_deg", pure)]
    pub fn alpha_deg(w: &mut WormSizes) -> Real {
        w.alpha.to_degrees()
    }
    /// One space's area in the axial section (mm^2).
    #[rhai_fn(get = "space_area", pure)]
    pub fn space_area(w: &mut WormSizes) -> Real {
        w.space_area()
    }

    /// A thread cutter (tool `number`): tip width and nose radius (mm),
    /// flank angles from the radial (deg), profile height (mm); tracked
    /// at its tip's centre.
    #[rhai_fn(return_raw)]
    pub fn thread_cutter(
        name: &str,
        number: i64,
        tip_width: Real,
        nose_radius: Real,
        left_deg: Real,
        right_deg: Real,
        height: Real,
    ) -> Result<Tool, Box<EvalAltResult>> {
        let number = crate::binding::tool_number(name, number)?;
        let c = kernel(ThreadCutter::new(
            tip_width,
            nose_radius,
            left_deg.to_radians(),
            right_deg.to_radians(),
            height,
        ))?;
        Ok(Tool::thread_cutter(name, number, c))
    }

    /// The thread cutter `tool` on a boring bar, cutting inside a bore:
    /// its tip looks away from the axis, and the machine's bodies for
    /// tools inside a bore (a boring bar, with the tailstock away) hold
    /// it.
    /// ```rhai
    /// let tool = thread_cutter("boring bar", 2, 0.25, 0.1, 30.0, 30.0, 3.0).inside_bore();
    /// ```
    #[rhai_fn(return_raw)]
    pub fn inside_bore(tool: Tool) -> Result<Tool, Box<EvalAltResult>> {
        let mut c = cutter_of(&tool)?;
        c.inside = true;
        Ok(Tool {
            shape: ToolShape::ThreadCutter(c),
            ..tool
        })
    }

    /// The tool `tool` with its own sizes of the machine's bodies that ride
    /// with it (`bodies`: machine constant to mm, as a tool table's row
    /// gives them: its holder's, its boring bar's); the run places those
    /// bodies with them. A constant no such body is sized by is refused
    /// when the run places the bodies.
    ///
    /// ```rhai
    /// let tool = thread_cutter("bar 8", 4, 0.2, 0.1, 30.0, 30.0, 1.5).inside_bore()
    ///     .with_bodies(#{ bar_radius: 4.0, bar_tip: 5.3, bar_length: 40.0 });
    /// ```
    #[rhai_fn(return_raw)]
    pub fn with_bodies(tool: Tool, bodies: Map) -> Result<Tool, Box<EvalAltResult>> {
        let mut out = std::collections::BTreeMap::new();
        for (k, v) in bodies {
            let value = crate::binding::floats::number(&v)
                .filter(|x| x.is_finite() && *x > 0.0)
                .ok_or_else(|| format!("with_bodies: '{k}' must be a size of more than 0 (mm)"))?;
            out.insert(k.to_string(), value);
        }
        Ok(Tool {
            bodies: out,
            ..tool
        })
    }

    /// The cutter's width at `r` above its tip (mm).
    #[rhai_fn(return_raw)]
    pub fn cutter_width(tool: Tool, r: Real) -> Result<Real, Box<EvalAltResult>> {
        Ok(cutter_of(&tool)?.width_at(r))
    }

    /// Where the cutter's cutting edges stand at `h` above its tip (mm from
    /// the tip's centre): `#{ left, right }`, left towards -z. At the
    /// blank's radius they are what S1 and S2 are measured from.
    ///
    /// ```rhai
    /// let e = cutter_edges(tool, 3.0);
    /// let leading = z_start - e.left;   // cutting towards -z
    /// ```
    #[rhai_fn(return_raw)]
    pub fn cutter_edges(tool: Tool, h: Real) -> Result<rhai::Map, Box<EvalAltResult>> {
        let [left, right] = cutter_of(&tool)?.extent_at(h);
        let mut m = rhai::Map::new();
        m.insert("left".into(), left.into());
        m.insert("right".into(), right.into());
        Ok(m)
    }

    /// The universal cutter's axial offset to each flank, `a_1z` (mm).
    #[rhai_fn(pure, return_raw)]
    pub fn axial_offset(w: &mut WormSizes, tool: Tool) -> Result<Real, Box<EvalAltResult>> {
        Ok(thread::axial_offset(&w.section(), &cutter_of(&tool)?))
    }

    /// The approach S1 = T V (-1 - ln a + a) (mm): servo time constant
    /// `t` (s), feed velocity `v` (mm/s), lead error ratio `a`.
    pub fn approach_length(t: Real, v: Real, a: Real) -> Real {
        thread::approach_length(t, v, a)
    }
    /// The run-out S2 = T V (mm).
    pub fn runout_length(t: Real, v: Real) -> Real {
        thread::runout_length(t, v)
    }
    /// The lead error ratio at the thread's start with an approach of
    /// `length` mm.
    pub fn approach_error(t: Real, v: Real, length: Real) -> Real {
        thread::approach_error(t, v, length)
    }
    /// The lead error ratio at the thread's end with a run-out of
    /// `length` mm.
    pub fn runout_error(t: Real, v: Real, length: Real) -> Real {
        thread::runout_error(t, v, length)
    }

    /// The passes, in the order cut, for `tool` (a thread cutter), with
    /// `settings`: `roughing_passes` (0: the rational number), `min_depth`,
    /// `finish_depth`, `finish_passes`, `order` ("alternating", "left",
    /// "right", "radial"), `axial_step`, `by_depth` (every start at each
    /// depth before the next). Columns: `kind` ("rough", "finish",
    /// "side"), `start` (from 0), `depth`, `cumulative`, `offset`, `flank`
    /// (-1 left, 0 radial, 1 right), `planned_area`.
    #[rhai_fn(pure, return_raw)]
    pub fn plan(w: &mut WormSizes, tool: Tool, settings: Map) -> Result<Map, Box<EvalAltResult>> {
        plan_map(&w.section(), &tool, &settings)
    }
}

/// The worm's part of the script API, as the reference lists it.
pub(crate) const SCRIPT_API: ApiGroup = ApiGroup {
    title: "Worm threads: sizes, cutter, S1 and S2, passes (`Worm`)",
    types: |e| {
        e.register_type_with_name::<WormSizes>("Worm");
    },
    register: |e, _| {
        e.register_global_module(rhai::exported_module!(worm_api).into());
    },
    verify: Some(VerifyForm {
        key: "worm",
        form: "#{ worm, length, space_centre, tolerance: #{ form, thickness, diameter, position, flank_angle_deg, lead (optional) } }",
        keys: &["worm", "length", "space_centre", "tolerance"],
        read: verification,
    }),
};

/// The worm's request from the map of a script's `fn verify(p)`.
fn verification(m: &Map) -> Result<Verification, Option<String>> {
    let v = VerifyMap::<WormSizes>::read(
        m,
        "worm",
        "form, thickness, diameter, position, flank_angle_deg",
    )?;
    Ok(Verification::new(thread::ThreadRequest::worm(
        &v.part,
        v.length,
        v.space_centre,
        thread::ThreadTolerances {
            form: v.tolerance("form")?,
            thickness: v.tolerance("thickness")?,
            diameter: v.tolerance("diameter")?,
            position: v.tolerance("position")?,
            flank_angle: v.tolerance("flank_angle_deg")?.to_radians(),
            lead: v.lead()?,
        },
    )))
}
