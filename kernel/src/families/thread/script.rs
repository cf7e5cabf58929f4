//! Threads of any profile for scripts: a thread named as a drawing names
//! it ([`crate::families::thread::designated`]), its sizes as the cut aims at them,
//! the plan of passes over its section, and its verification (the worm's
//! simulation, held to the standard's limits). Angles in degrees; lengths
//! mm.

use crate::binding::floats::Floats;
use crate::binding::floats::{kernel, number};
use crate::binding::{ApiGroup, VerifyForm};
use crate::families::thread::standards::{LoadFlank, StatedLimits};
use crate::families::thread::{self, FlankOrder, PlanSettings, ThreadCutter, ThreadTolerances};
use crate::families::thread::{Drawing, Hand, ThreadProfile};
use crate::family::Verification;
use crate::math::Real;
use crate::profile::Table;
use crate::tool::Tool;
use crate::tool::ToolShape;
use rhai::plugin::*;
use rhai::Array;
use rhai::{EvalAltResult, Map};

/// The keys of a drawing's map, in the order the docs give them.
const DRAWING_KEYS: [&str; 6] = [
    "internal",
    "pitch_allowance",
    "pitch_tolerance",
    "crest_tolerance",
    "root_tolerance",
    "load",
];

/// The drawing of a script's map: every key of [`DRAWING_KEYS`].
fn drawing(m: &Map) -> Result<Drawing, Box<EvalAltResult>> {
    if let Some(k) = m.keys().find(|k| !DRAWING_KEYS.contains(&k.as_str())) {
        return Err(format!(
            "thread_profile: unknown drawing key '{k}' (keys: {})",
            DRAWING_KEYS.join(", ")
        )
        .into());
    }
    let text = |k: &str| -> Result<String, Box<EvalAltResult>> {
        m.get(k)
            .and_then(|v| v.clone().into_string().ok())
            .ok_or_else(|| format!("thread_profile: drawing key '{k}' must be a string").into())
    };
    let num = |k: &str| -> Result<Real, Box<EvalAltResult>> {
        let v = m
            .get(k)
            .and_then(number)
            .ok_or_else(|| format!("thread_profile: drawing key '{k}' must be a number (mm)"))?;
        if !(v.is_finite() && v >= 0.0) {
            return Err(
                format!("thread_profile: drawing key '{k}' = {v} must be 0 or more (mm)").into(),
            );
        }
        Ok(v)
    };
    let internal = match text("internal")?.as_str() {
        "auto" => None,
        "internal" => Some(true),
        "external" => Some(false),
        other => {
            return Err(format!(
                "thread_profile: internal = '{other}' is not auto, internal or external"
            )
            .into())
        }
    };
    let load = match text("load")?.as_str() {
        "chuck" => LoadFlank::TowardsChuck,
        "tailstock" => LoadFlank::AwayFromChuck,
        other => {
            return Err(format!(
                "thread_profile: load = '{other}' is not chuck or tailstock (the way a buttress's load flank faces)"
            )
            .into())
        }
    };
    Ok(Drawing {
        internal,
        stated: StatedLimits {
            pitch_allowance: num("pitch_allowance")?,
            pitch_tolerance: num("pitch_tolerance")?,
            crest_tolerance: num("crest_tolerance")?,
            root_tolerance: num("root_tolerance")?,
        },
        load,
    })
}

/// A thread's sizes, the plan over its section.
#[export_module]
pub mod thread_api {
    use super::*;

    /// The thread `designation` names (`M20x2.5-6g`, `M30x2-6H`, `Tr40x7`,
    /// `Tr40x14(P7)`, `1-5 ACME-2G`, `2-8 BUTT 7/45`, `LH` at the end for a
    /// left hand), with what its designation leaves to the drawing:
    /// `#{ internal: "auto" | "internal" | "external", pitch_allowance,
    /// pitch_tolerance, crest_tolerance, root_tolerance (mm: the limits
    /// of threads whose standard leaves them to the drawing: trapezoidal,
    /// buttress), load: "chuck" | "tailstock" (which way a buttress's load
    /// flank faces) }`.
    ///
    /// ```rhai
    /// let t = thread_profile("M20x2.5-6g", #{ internal: "auto", pitch_allowance: 0.0,
    ///     pitch_tolerance: 0.2, crest_tolerance: 0.3, root_tolerance: 0.3, load: "chuck" });
    /// t.pitch_diameter    // 18.249: the middle of 6g's band
    /// ```
    #[rhai_fn(return_raw)]
    pub fn thread_profile(
        designation: &str,
        drawing: Map,
    ) -> Result<ThreadProfile, Box<EvalAltResult>> {
        kernel(crate::families::thread::designated(
            designation,
            &super::drawing(&drawing)?,
        ))
    }

    /// The designation, as the standard writes it.
    #[rhai_fn(get = "designation", pure)]
    pub fn designation(t: &mut ThreadProfile) -> String {
        t.designation.clone()
    }
    /// Where the form and the limits come from (`ISO 68-1, ISO 965-1`;
    /// the limits' source: `ISO 965-1 6g`, `stated`).
    #[rhai_fn(get = "standard", pure)]
    pub fn standard(t: &mut ThreadProfile) -> String {
        format!("{} ({})", t.standard, t.limits.source)
    }
    /// An internal thread (a nut's).
    #[rhai_fn(get = "internal", pure)]
    pub fn internal(t: &mut ThreadProfile) -> bool {
        t.section.internal
    }
    /// Left-handed.
    #[rhai_fn(get = "left_hand", pure)]
    pub fn left_hand(t: &mut ThreadProfile) -> bool {
        t.section.hand == Hand::Left
    }
    /// The pitch between neighbouring threads (mm).
    #[rhai_fn(get = "pitch", pure)]
    pub fn pitch(t: &mut ThreadProfile) -> Real {
        t.section.pitch
    }
    /// The lead (mm).
    #[rhai_fn(get = "lead", pure)]
    pub fn lead(t: &mut ThreadProfile) -> Real {
        t.section.lead()
    }
    /// The number of starts.
    #[rhai_fn(get = "starts", pure)]
    pub fn starts(t: &mut ThreadProfile) -> i64 {
        i64::from(t.section.starts)
    }
    /// The pitch diameter the cut aims at: the middle of its limits (mm).
    #[rhai_fn(get = "pitch_diameter", pure)]
    pub fn pitch_diameter(t: &mut ThreadProfile) -> Real {
        t.aimed().pitch_diameter
    }
    /// The root's diameter the cut aims at (mm): external, the minor;
    /// internal, the major.
    #[rhai_fn(get = "root_diameter", pure)]
    pub fn root_diameter(t: &mut ThreadProfile) -> Real {
        t.aimed().root_diameter
    }
    /// The crest's diameter: the blank's (external) or the bore's
    /// (internal), the middle of its limits (mm).
    #[rhai_fn(get = "crest_diameter", pure)]
    pub fn crest_diameter(t: &mut ThreadProfile) -> Real {
        t.aimed().crest_diameter
    }
    /// The depth the cut makes, crest to root (mm).
    #[rhai_fn(get = "depth", pure)]
    pub fn depth(t: &mut ThreadProfile) -> Real {
        t.aimed().depth()
    }
    /// The space's width at the root (mm): the widest cutter tip.
    #[rhai_fn(get = "root_space", pure)]
    pub fn root_space(t: &mut ThreadProfile) -> Real {
        t.aimed().root_space()
    }
    /// The root's rounding the standard gives (mm; 0: a flat root).
    #[rhai_fn(get = "root_radius", pure)]
    pub fn root_radius(t: &mut ThreadProfile) -> Real {
        t.section.root_radius
    }
    /// The flank towards -Z's angle from the radial (deg).
    #[rhai_fn(get = "left_flank_deg", pure)]
    pub fn left_flank_deg(t: &mut ThreadProfile) -> Real {
        t.section.flanks[0].to_degrees()
    }
    /// The flank towards +Z's (deg).
    #[rhai_fn(get = "right_flank_deg", pure)]
    pub fn right_flank_deg(t: &mut ThreadProfile) -> Real {
        t.section.flanks[1].to_degrees()
    }
    /// The flanks the roughing passes follow: `alternating` for a
    /// symmetric profile; for an asymmetric one (a buttress) its steeper
    /// flank, `left` or `right`, so that the infeed runs along the load
    /// flank and the open flank takes the chip.
    /// A worm's curved flanks (ZN, ZI): `radial`, its form cutter
    /// plunging straight in.
    #[rhai_fn(get = "infeed", pure)]
    pub fn infeed(t: &mut ThreadProfile) -> String {
        if !t.section.form.is_axial() {
            return "radial".into();
        }
        let [l, r] = t.section.flanks;
        match l.total_cmp(&r) {
            std::cmp::Ordering::Equal => "alternating",
            std::cmp::Ordering::Less => "left",
            std::cmp::Ordering::Greater => "right",
        }
        .into()
    }
    /// Its flanks are curves in the axial section (a ZN or ZI worm's),
    /// cut by `form_cutter`.
    #[rhai_fn(get = "curved", pure)]
    pub fn curved(t: &mut ThreadProfile) -> bool {
        !t.section.form.is_axial()
    }
    /// The full-profile form cutter (tool `number`) ground to a worm's
    /// curved flanks (ZN, ZI), `nose_radius` at its corners, reaching 2
    /// mm above the crest: plunged to the root the cut aims at, it makes
    /// the basic curve moved radially with the pitch diameter.
    ///
    /// ```rhai
    /// let c = t.form_cutter("form cutter", 1, 0.2);
    /// ```
    #[rhai_fn(pure, return_raw)]
    pub fn form_cutter(
        t: &mut ThreadProfile,
        name: &str,
        number: i64,
        nose_radius: Real,
    ) -> Result<Tool, Box<EvalAltResult>> {
        let number = crate::binding::tool_number(name, number)?;
        let c = kernel(t.section.form_cutter(nose_radius))?;
        Ok(Tool::thread_cutter(name, number, c))
    }
    /// The largest tool of the tool table `tools` (read by `read_table`;
    /// its columns in `docs/families.md`) that cuts this thread over
    /// `length` mm: `#{ name, number, nose (mm; 0: the standard's root
    /// rounding), row (as the table numbers it), shank, least_diameter (mm:
    /// the least major or bore it works on), bodies (its
    /// sizes of the machine's bodies riding with it, for `with_bodies`) }`.
    /// None fits: the error names the nearest tool and what it lacks.
    ///
    /// ```rhai
    /// let pick = t.pick_tool(read_table("thread-tools.csv"), 30.0);
    /// let c = thread_cutter(pick.name, pick.number, t.root_space, 0.2, 30.0, 30.0, 3.0)
    ///     .with_bodies(pick.bodies);
    /// ```
    #[rhai_fn(pure, return_raw)]
    pub fn pick_tool(
        t: &mut ThreadProfile,
        tools: Table,
        length: Real,
    ) -> Result<Map, Box<EvalAltResult>> {
        let table = kernel(thread::tools::ToolTable::read(&tools))?;
        let aimed = t.aimed();
        let need = thread::tools::Need {
            thread: t.designation.clone(),
            inside: aimed.internal,
            included: aimed
                .form
                .is_axial()
                .then(|| (aimed.flanks[0] + aimed.flanks[1]).to_degrees()),
            pitch: aimed.pitch,
            depth: aimed.depth(),
            diameter: aimed.crest_diameter,
            length,
        };
        let tool = kernel(table.pick(&need))?;
        let mut m = Map::new();
        m.insert("name".into(), tool.name.clone().into());
        m.insert("number".into(), i64::from(tool.number).into());
        m.insert("nose".into(), tool.nose.unwrap_or(0.0).into());
        m.insert("row".into(), (tool.row as i64).into());
        m.insert("shank".into(), tool.shank.into());
        m.insert("least_diameter".into(), tool.least_diameter.into());
        let bodies: Map = tool
            .bodies
            .iter()
            .map(|(k, v)| (k.as_str().into(), (*v).into()))
            .collect();
        m.insert("bodies".into(), bodies.into());
        Ok(m)
    }

    /// One space's area in the axial section, as the cut aims at it
    /// (mm^2).
    #[rhai_fn(get = "space_area", pure)]
    pub fn space_area(t: &mut ThreadProfile) -> Real {
        t.aimed().space_area()
    }

    /// The universal cutter's axial offset to each flank, `a_1z` (mm).
    #[rhai_fn(pure, return_raw, name = "axial_offset")]
    pub fn thread_axial_offset(
        t: &mut ThreadProfile,
        tool: Tool,
    ) -> Result<Real, Box<EvalAltResult>> {
        Ok(thread::axial_offset(&t.aimed(), &cutter_of(&tool)?))
    }

    /// The passes over the section the cut aims at, as the worm's `plan`
    /// (the same settings and columns).
    #[rhai_fn(pure, return_raw, name = "plan")]
    pub fn thread_plan(
        t: &mut ThreadProfile,
        tool: Tool,
        settings: Map,
    ) -> Result<Map, Box<EvalAltResult>> {
        plan_map(&t.aimed(), &tool, &settings)
    }
}

/// The thread's part of the script API, as the reference lists it.
pub(crate) const SCRIPT_API: ApiGroup = ApiGroup {
    title: "Threads of any profile: designations, sizes, passes (`Thread`)",
    types: |e| {
        e.register_type_with_name::<ThreadProfile>("Thread");
    },
    register: |e, _| {
        e.register_global_module(rhai::exported_module!(thread_api).into());
    },
    verify: Some(VerifyForm {
        key: "thread_profile",
        form: "#{ thread_profile, length, space_centre, outside_diameter (a nut's, optional), tolerance: #{ form, position, flank_angle_deg, lead (optional) } }",
        keys: &[
            "thread_profile",
            "length",
            "space_centre",
            "outside_diameter",
            "tolerance",
            "correction",
            "place_correction",
        ],
        read: verification,
    }),
};

/// The thread's request from the map of a script's `fn verify(p)`: the
/// section the cut aims at, held to the standard's limits.
fn verification(m: &Map) -> Result<Verification, Option<String>> {
    let v = VerifyMap::<ThreadProfile>::read(
        m,
        "thread_profile",
        "form, position, flank_angle_deg, lead",
    )?;
    let (profile, section) = (&v.part, v.part.aimed());
    Ok(Verification::new(thread::ThreadRequest {
        // The flanks are measured a twentieth of the depth inside the root
        // and the crest.
        flank_margin: 0.05 * section.depth(),
        length: v.length,
        space_centre: v.space_centre,
        tolerances: ThreadTolerances {
            form: v.tolerance("form")?,
            // The standard's limits hold the thickness (by the pitch
            // diameter) and the diameters: these are the halves of their
            // bands, for the record.
            thickness: 0.25
                * profile.limits.pitch_diameter.width()
                * (section.flanks[0].tan() + section.flanks[1].tan()),
            diameter: 0.5
                * profile
                    .limits
                    .root
                    .width()
                    .max(profile.limits.crest.width()),
            position: v.tolerance("position")?,
            flank_angle: v.tolerance("flank_angle_deg")?.to_radians(),
            lead: v.lead()?,
        },
        limits: Some(profile.limits.clone()),
        part: "thread",
        // A nut's outside, where the script gives it.
        outside_diameter: match m.get("outside_diameter") {
            None => None,
            Some(d) => Some(number(d).filter(|d| *d > 0.0).ok_or_else(|| {
                Some(format!(
                    "fn verify(p): outside_diameter must be a number above 0 (the nut's, mm), not {d}"
                ))
            })?),
        },
        // A measured part's correction of each start's pitch diameter and
        // place along the axis, where the script gives them.
        pitch_shift: per_start(m, "correction", "pitch diameter's", section.starts)?,
        place_shift: per_start(m, "place_correction", "place's along the axis", section.starts)?,
        section,
    }))
}

/// The numbers under `key` of a verification's map, one per start (`what`
/// each is, for the message); none where the script gives none.
fn per_start(m: &Map, key: &str, what: &str, starts: u32) -> Result<Vec<Real>, Option<String>> {
    match m.get(key) {
        None => Ok(Vec::new()),
        Some(d) => match crate::binding::floats::numbers(d, key) {
            Ok(c) if c.len() == starts as usize => Ok(c.to_vec()),
            _ => Err(Some(format!(
                "fn verify(p): {key} must be {starts} numbers, each start's {what} (mm), not {d}"
            ))),
        },
    }
}

/// The thread cutter `tool` is, or why not.
pub(crate) fn cutter_of(tool: &Tool) -> Result<ThreadCutter, Box<EvalAltResult>> {
    match tool.shape {
        ToolShape::ThreadCutter(c) => Ok(c),
        _ => Err(format!("tool '{}' is not a thread cutter", tool.name).into()),
    }
}

/// The plan of passes over `section` for `tool` with a script's
/// `settings` (the worm's `plan` and the thread's), as columns.
pub(crate) fn plan_map(
    section: &crate::families::thread::ThreadSection,
    tool: &Tool,
    settings: &Map,
) -> Result<Map, Box<EvalAltResult>> {
    let s = plan_settings(settings)?;
    let passes = kernel(thread::plan(section, &cutter_of(tool)?, &s))?;
    let col = |f: &dyn Fn(&thread::PlannedPass) -> Real| {
        Dynamic::from(Floats::new(passes.iter().map(f).collect()))
    };
    let mut m = Map::new();
    m.insert(
        "kind".into(),
        Dynamic::from(
            passes
                .iter()
                .map(|p| {
                    Dynamic::from(match p.kind {
                        thread::PassKind::Rough => "rough",
                        thread::PassKind::Finish => "finish",
                        thread::PassKind::Side => "side",
                    })
                })
                .collect::<Array>(),
        ),
    );
    m.insert("start".into(), col(&|p| Real::from(p.start)));
    m.insert("depth".into(), col(&|p| p.depth));
    m.insert("cumulative".into(), col(&|p| p.cumulative));
    m.insert("offset".into(), col(&|p| p.offset));
    m.insert(
        "flank".into(),
        col(&|p| match p.flank {
            thread::Flank::Left => -1.0,
            thread::Flank::Radial => 0.0,
            thread::Flank::Right => 1.0,
        }),
    );
    m.insert("planned_area".into(), col(&|p| p.planned_area));
    Ok(m)
}

/// The plan's settings of a script's map, each key checked.
fn plan_settings(settings: &Map) -> Result<PlanSettings, Box<EvalAltResult>> {
    const KEYS: [&str; 7] = [
        "roughing_passes",
        "min_depth",
        "finish_depth",
        "finish_passes",
        "order",
        "axial_step",
        "by_depth",
    ];
    if let Some(k) = settings.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return Err(format!(
            "plan: unknown setting '{k}' (settings: {})",
            KEYS.join(", ")
        )
        .into());
    }
    let num = |k: &str| -> Result<Real, Box<EvalAltResult>> {
        settings
            .get(k)
            .and_then(number)
            .ok_or_else(|| format!("plan: '{k}' must be a number").into())
    };
    let count = |k: &str| -> Result<usize, Box<EvalAltResult>> {
        let v = num(k)?;
        if !(0.0..=thread::MAX_PASSES as Real).contains(&v) || v.fract() != 0.0 {
            return Err(format!(
                "plan: {k} = {v} must be a whole number from 0 to {}",
                thread::MAX_PASSES
            )
            .into());
        }
        Ok(v as usize)
    };
    let order = settings
        .get("order")
        .and_then(|d| d.clone().into_string().ok())
        .ok_or("plan: 'order' must be a string")?;
    let by_depth = settings
        .get("by_depth")
        .and_then(|d| d.as_bool().ok())
        .ok_or("plan: 'by_depth' must be true or false")?;
    let n = count("roughing_passes")?;
    Ok(PlanSettings {
        roughing_passes: (n > 0).then_some(n),
        min_depth: num("min_depth")?,
        finish_depth: num("finish_depth")?,
        finish_passes: count("finish_passes")?,
        order: FlankOrder::parse(&order).map_err(|e| format!("plan: {e}"))?,
        axial_step: num("axial_step")?,
        starts_by_depth: by_depth,
    })
}

/// What the worm's and the thread's `fn verify(p)` maps share: the object
/// under their key, `length`, `space_centre` and the `tolerance` map.
pub(crate) struct VerifyMap<T> {
    /// The object under the family's key (`worm`, `thread_profile`).
    pub part: T,
    /// The thread's length (mm).
    pub length: Real,
    /// Where start 0's space is centred (mm).
    pub space_centre: Real,
    tolerance: Map,
    keys: &'static str,
}

impl<T: Clone + 'static> VerifyMap<T> {
    /// The map `m` read: `Err(None)` where it is not of the form (no
    /// object of type `T` under `key`, no numbers, no tolerance map);
    /// `keys` lists the tolerance's keys in messages.
    pub(crate) fn read(m: &Map, key: &str, keys: &'static str) -> Result<Self, Option<String>> {
        let num = |k: &str| m.get(k).and_then(number).ok_or(None);
        Ok(Self {
            part: m
                .get(key)
                .and_then(|w| w.clone().try_cast::<T>())
                .ok_or(None)?,
            length: num("length")?,
            space_centre: num("space_centre")?,
            tolerance: m
                .get("tolerance")
                .and_then(|t| t.clone().try_cast::<Map>())
                .ok_or(None)?,
            keys,
        })
    }

    /// The tolerance `k`, a number.
    pub(crate) fn tolerance(&self, k: &str) -> Result<Real, Option<String>> {
        self.tolerance.get(k).and_then(number).ok_or_else(|| {
            Some(format!(
                "fn verify(p): tolerance.{k} must be a number (tolerance: {})",
                self.keys
            ))
        })
    }

    /// The lead's error allowed at the thread's ends: `tolerance.lead`,
    /// [`thread::LEAD_ERROR`] where it is left out.
    pub(crate) fn lead(&self) -> Result<Real, Option<String>> {
        match self.tolerance.get("lead") {
            None => Ok(thread::LEAD_ERROR),
            Some(_) => self.tolerance("lead"),
        }
    }
}
