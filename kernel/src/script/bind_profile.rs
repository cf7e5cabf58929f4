//! Profiles for scripts: `x(z)` from samples, the mandrel law, whole parts
//! chained from segments, derivative smoothing, and polylines (`Path`s) of
//! tool centres.

use super::floats::{err, kernel, numbers, Floats, Numbers};
use crate::math::Real;
use crate::profile::{Bulge, MandrelLaw, Polyline, Profile, ProfileBuilder, Smoothing};
use rhai::plugin::*;
use rhai::EvalAltResult;

/// How far a station profile's fillets' chords may stray from their arcs
/// unless the script says (mm): a tenth of a micron.
const STATION_CHORDAL: Real = 1e-4;

/// The keys `profile(z, x, interpolation, options)` reads.
const STATION_KEYS: [&str; 4] = ["fillets", "chamfers", "chordal", "tolerances"];

/// The stations' own tolerances a station profile's `options` give (one
/// a station: a text, `""` or `()` for the general one), or a refusal
/// naming the entry that is wrong.
fn tolerances(options: &rhai::Map, n: usize) -> Result<Vec<Option<String>>, Box<EvalAltResult>> {
    let Some(list) = options.get("tolerances") else {
        return Ok(vec![None; n]);
    };
    let list = (list.clone().into_array()).map_err(|_| {
        "profile: 'tolerances' must be an array, one a station (\"h6\", \"±0.01\", \"+0.02/-0.01\", or \"\" for the general tolerance)"
    })?;
    if list.len() != n {
        return err(format!(
            "profile: 'tolerances' has {} entries for {n} stations: give one a station (\"\" for the general tolerance)",
            list.len()
        ));
    }
    (list.iter().enumerate())
        .map(|(i, t)| {
            if t.is_unit() {
                return Ok(None);
            }
            let t = t.clone().into_string().map_err(|_| {
                format!("profile: tolerances[{i}] must be a text (\"h6\", \"±0.01\") or \"\"")
            })?;
            Ok((!t.trim().is_empty()).then_some(t))
        })
        .collect()
}

/// The corners a station profile's `options` give, or a refusal naming
/// the key or entry that is wrong.
fn corners(
    options: &rhai::Map,
) -> Result<Vec<(Real, crate::profile::CornerForm)>, Box<EvalAltResult>> {
    use crate::binding::floats::{err, number};
    use crate::profile::CornerForm;
    if let Some(k) = options.keys().find(|k| !STATION_KEYS.contains(&k.as_str())) {
        return err(format!(
            "profile: unknown key '{}' (keys: {})",
            crate::files::excerpt(k),
            STATION_KEYS.join(", ")
        ));
    }
    let mut out = Vec::new();
    for (key, form) in [
        ("fillets", CornerForm::Fillet as fn(Real) -> CornerForm),
        ("chamfers", CornerForm::Chamfer),
    ] {
        let Some(list) = options.get(key) else {
            continue;
        };
        let list = list
            .clone()
            .into_array()
            .map_err(|_| format!("profile: '{key}' must be an array of [z, mm]"))?;
        for (i, entry) in list.iter().enumerate() {
            let pair = entry.clone().into_array().unwrap_or_default();
            match pair
                .iter()
                .map(number)
                .collect::<Option<Vec<Real>>>()
                .as_deref()
            {
                Some(&[z, mm]) => out.push((z, form(mm))),
                _ => return err(format!("profile: {key}[{i}] must be [z, mm], two numbers")),
            }
        }
    }
    Ok(out)
}

/// The profile through stations `(z, x)` by `mode`, with `corners` (only
/// for a linear one) and the `chordal` `options` gives (`interpolation`
/// as the script wrote it, for messages).
fn unbanded(
    z: &[Real],
    x: &[Real],
    mode: crate::profile::Interpolation,
    corners: &[(Real, crate::profile::CornerForm)],
    options: &rhai::Map,
    interpolation: &str,
) -> Result<Profile, Box<EvalAltResult>> {
    if mode != crate::profile::Interpolation::Linear {
        if !corners.is_empty() {
            return err(format!(
                "profile: fillets and chamfers join straight lines: give interpolation \"linear\", not \"{}\"",
                crate::files::excerpt(interpolation)
            ));
        }
        let p = kernel(Profile::new(z.to_vec(), x.to_vec()))?;
        return Ok(p.with_interpolation(mode));
    }
    let chordal = match options.get("chordal") {
        None => STATION_CHORDAL,
        Some(d) => {
            crate::binding::floats::number(d).ok_or("profile: 'chordal' must be a number (mm)")?
        }
    };
    kernel(crate::profile::polyline_through(z, x, corners, chordal))
}

/// Profiles and their generators.
#[export_module]
pub mod profile_api {
    use super::*;

    /// A profile `x(z)` from its samples (z increasing strictly, at least 3).
    ///
    /// ```rhai
    /// let disc = profile([-10.0, -5.0, 0.0], [40.0, 40.0, 40.0]);
    /// ```
    #[rhai_fn(return_raw)]
    pub fn profile(z: Numbers, x: Numbers) -> Result<Profile, Box<EvalAltResult>> {
        let (z, x) = (numbers(&z, "profile z")?, numbers(&x, "profile x")?);
        kernel(Profile::new(z.as_ref().clone(), x.as_ref().clone()))
    }

    /// A profile `x(z)` through a drawing's stations, interpolated between
    /// them by `interpolation`: `"linear"` (straight lines between the
    /// stations, each station a corner: a wheel's path swings round a
    /// convex one and is refused at a concave one it cannot enter, unless
    /// the corner is given a fillet, see the four-argument form),
    /// `"monotone"` (Fritsch-Carlson: never beyond two neighbouring
    /// stations), `"natural"` (the natural cubic spline, C2) or
    /// `"parabolic"` (the default of `profile(z, x)`). See `swing` for
    /// how far a smooth one goes beyond its stations.
    ///
    /// ```rhai
    /// let p = profile([0.0, 60.0, 340.0], [15.0, 15.0, 17.8], "monotone");
    /// ```
    #[rhai_fn(name = "profile", return_raw)]
    pub fn profile_by(
        z: Numbers,
        x: Numbers,
        interpolation: &str,
    ) -> Result<Profile, Box<EvalAltResult>> {
        stations(z, x, interpolation, rhai::Map::new())
    }

    /// As `profile(z, x, interpolation)`, with the drawing's corners:
    /// `options` may hold `fillets` and `chamfers` (arrays of `[z, mm]`:
    /// the station's z and the fillet's radius, or the chamfer's length
    /// along each line; only with `"linear"`), `chordal` (mm, how far
    /// a fillet's sampled chords may stray from its arc; default 1e-4)
    /// and `tolerances` (one a station, on its diameter `2 x`: an ISO 286
    /// shaft fit `"h6"`, `"±0.01"`, `"+0.02/-0.01"`, or `""` for the
    /// general one: the station is aimed at its band's middle, and a run
    /// of neighbouring stations with the same one is judged against it).
    /// Any other key is refused.
    ///
    /// ```rhai
    /// let p = profile([0.0, 360.0, 375.0], [9.0, 9.135, 8.0], "linear", #{ fillets: [[360.0, 5.0]] });
    /// ```
    #[rhai_fn(name = "profile", return_raw)]
    pub fn stations(
        z: Numbers,
        x: Numbers,
        interpolation: &str,
        options: rhai::Map,
    ) -> Result<Profile, Box<EvalAltResult>> {
        let mode = crate::binding::interpolation(interpolation)?;
        let corners = super::corners(&options)?;
        let (z, x) = (numbers(&z, "profile z")?, numbers(&x, "profile x")?);
        // Stations a drawing tolerances on their own: aimed at their
        // bands' middles, the bands kept for the verification.
        let given = super::tolerances(&options, z.len())?;
        let sources = crate::profile::station_sources(&z, &x);
        let (x, bands) = kernel(crate::profile::aimed(&z, &x, &given))?;
        let p = unbanded(&z, &x, mode, &corners, &options, interpolation)?;
        Ok(p.with_bands(bands).with_sources(sources))
    }

    /// Where the profile goes furthest beyond the two stations (nodes)
    /// of an interval, as a map `#{z, x, mm}` (`mm`: how far beyond the
    /// nearer station's x), or `()` where it never does: a drawing gives
    /// no such swing, so a family warns of one larger than its tolerance.
    ///
    /// ```rhai
    /// let s = p.swing();
    /// if s != () && s.mm > 0.001 { tp.warn(`the profile swings ${s.mm} mm at z = ${s.z}`); }
    /// ```
    #[rhai_fn(pure)]
    pub fn swing(p: &mut Profile) -> Dynamic {
        match p.swing() {
            Some(s) => {
                let mut m = rhai::Map::new();
                m.insert("z".into(), s.z.into());
                m.insert("x".into(), s.x.into());
                m.insert("mm".into(), s.beyond.into());
                m.into()
            }
            None => Dynamic::UNIT,
        }
    }

    /// The profile's abscissae.
    #[rhai_fn(get = "z", pure)]
    pub fn profile_z(p: &mut Profile) -> Floats {
        Floats::new(p.z().to_vec())
    }

    /// The profile's ordinates.
    #[rhai_fn(get = "x", pure)]
    pub fn profile_x(p: &mut Profile) -> Floats {
        Floats::new(p.x().to_vec())
    }

    /// Number of nodes.
    #[rhai_fn(get = "len", pure)]
    pub fn profile_len(p: &mut Profile) -> i64 {
        p.len() as i64
    }

    /// dx/dz at every node (analytic where the generator knows it).
    #[rhai_fn(pure)]
    pub fn slopes(p: &mut Profile) -> Floats {
        Floats::new(p.slopes().into_owned())
    }

    /// Signed curvature at every node (1/mm; positive: concave seen from +x).
    #[rhai_fn(pure)]
    pub fn curvature(p: &mut Profile) -> Floats {
        Floats::new(p.curvature())
    }

    /// Radius of curvature at every node (mm).
    #[rhai_fn(pure)]
    pub fn curvature_radius(p: &mut Profile) -> Floats {
        Floats::new(p.curvature_radius())
    }

    /// Cumulative arc length (mm).
    #[rhai_fn(pure)]
    pub fn arc_length(p: &mut Profile) -> Floats {
        Floats::new(p.arc_length())
    }

    /// x at `z` (cubic Hermite between nodes).
    #[rhai_fn(pure, return_raw)]
    pub fn x_at(p: &mut Profile, z: Real) -> Result<Real, Box<EvalAltResult>> {
        kernel(p.eval(z))
    }

    /// The profile at a uniform step of z.
    #[rhai_fn(pure, return_raw)]
    pub fn resampled(p: &mut Profile, step: Real) -> Result<Profile, Box<EvalAltResult>> {
        kernel(p.resample_uniform(step))
    }

    /// The profile with `dx` added where `z_from <= z <= z_to` (a stock
    /// allowance over a stretch: the blank).
    #[rhai_fn(pure, return_raw)]
    pub fn raised(
        p: &mut Profile,
        z_from: Real,
        z_to: Real,
        dx: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        kernel(p.raised(z_from, z_to, dx))
    }

    /// The profile moved by the profile `d` along x at each z (`d` held
    /// at its end values beyond its range): a target corrected by a
    /// measured error, as `pilgrim compensate` gives it.
    ///
    /// ```rhai
    /// let t = read_table(p.correction);
    /// let target = ground.offset_by(profile(t["z_mm"], t["dr_mm"]));
    /// ```
    #[rhai_fn(pure, return_raw)]
    pub fn offset_by(p: &mut Profile, d: Profile) -> Result<Profile, Box<EvalAltResult>> {
        kernel(p.offset_by(&d))
    }

    /// Three-point smoothing of the derivative (seed 001): `iterations`
    /// passes, the profile rebuilt from node `anchor`. The result has
    /// `.profile`, `.max_change` (mm) and `.max_change_z`.
    #[rhai_fn(pure, return_raw)]
    pub fn smoothed(
        p: &mut Profile,
        iterations: i64,
        anchor: i64,
    ) -> Result<Smoothing, Box<EvalAltResult>> {
        if iterations < 0 || anchor < 0 {
            return err("smoothed: iterations and anchor must not be negative");
        }
        kernel(p.smooth_derivative(iterations as usize, anchor as usize))
    }

    /// The smoothed profile.
    #[rhai_fn(get = "profile", pure)]
    pub fn smoothing_profile(s: &mut Smoothing) -> Profile {
        s.profile.clone()
    }

    /// The largest change smoothing made to x (mm).
    #[rhai_fn(get = "max_change", pure)]
    pub fn smoothing_change(s: &mut Smoothing) -> Real {
        s.max_change
    }

    /// Where (z) the largest change is.
    #[rhai_fn(get = "max_change_z", pure)]
    pub fn smoothing_change_z(s: &mut Smoothing) -> Real {
        s.max_change_z
    }

    /// The mandrel's working-part law (docs/math.md §2.1): diameters `d_min` at 0
    /// and `d_max` at `length`, initial taper (diameter change per mm at 0),
    /// exponent.
    #[rhai_fn(return_raw)]
    pub fn mandrel_law(
        d_min: Real,
        d_max: Real,
        length: Real,
        taper: Real,
        exponent: Real,
    ) -> Result<MandrelLaw, Box<EvalAltResult>> {
        kernel(MandrelLaw::new(d_min, d_max, length, taper, exponent))
    }

    /// The law's radius x(z).
    #[rhai_fn(name = "x")]
    pub fn law_x(law: &mut MandrelLaw, z: Real) -> Real {
        law.x(z)
    }

    /// The law's slope dx/dz at z.
    #[rhai_fn(name = "slope")]
    pub fn law_slope(law: &mut MandrelLaw, z: Real) -> Real {
        law.dx(z)
    }

    /// The law sampled at `step` from `z_start`, with analytic derivatives.
    #[rhai_fn(name = "profile", return_raw)]
    pub fn law_profile(
        law: &mut MandrelLaw,
        step: Real,
        z_start: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        kernel(law.profile(step, z_start))
    }
}

/// A whole part profile chained from segments.
#[export_module]
pub mod builder_api {
    use super::*;

    /// Starts a whole part profile at `(z, x)`; chain segments left to right
    /// along z, then `build`.
    ///
    /// ```rhai
    /// let p = profile_start(-80.0, 18.0).cylinder(40.0).line_to(-30.0, 20.0)
    ///             .law(mandrel_law(40.0, 48.0, 300.0, 0.01, 2.5)).build(0.001, 1.0);
    /// ```
    pub fn profile_start(z: Real, x: Real) -> ProfileBuilder {
        ProfileBuilder::start(z, x)
    }

    /// A straight segment (cone or cylinder) to `(z, x)`.
    #[rhai_fn(name = "line_to")]
    pub fn line_to(b: ProfileBuilder, z: Real, x: Real) -> ProfileBuilder {
        b.line_to(z, x)
    }

    /// A cylinder of `length` at the current radius.
    #[rhai_fn(name = "cylinder")]
    pub fn cylinder(b: ProfileBuilder, length: Real) -> ProfileBuilder {
        b.cylinder(length)
    }

    /// The profile over `[from, to]` only (a ground stretch of a whole
    /// part's outline), its ends on the curve with the derivatives of the
    /// side inside.
    #[rhai_fn(pure, return_raw)]
    pub fn between(p: &mut Profile, from: Real, to: Real) -> Result<Profile, Box<EvalAltResult>> {
        kernel(p.between(from, to))
    }

    /// Rounds the corner at the current point, between the line ending
    /// here and the next `line_to`, by an arc of `radius` tangent to both
    /// (convex or concave as the corner turns): a drawing's `R` at a
    /// corner, its tangent points found by the kernel. Refused, naming the
    /// corner, where the lines are too short for it or in line.
    ///
    /// ```rhai
    /// let p = profile_start(0.0, 18.0).line_to(25.0, 18.0).fillet(3.0).line_to(40.0, 15.0).build(1e-4, 0.5);
    /// ```
    #[rhai_fn(name = "fillet")]
    pub fn fillet(b: ProfileBuilder, radius: Real) -> ProfileBuilder {
        b.fillet(radius)
    }

    /// An arc from the current point to `(z, x)` tangent to the line
    /// ending here (a drawing's arc given by its end and "tangent"): its
    /// radius follows from the two. Refused after anything but a line.
    #[rhai_fn(name = "tangent_arc_to")]
    pub fn tangent_arc_to(b: ProfileBuilder, z: Real, x: Real) -> ProfileBuilder {
        b.tangent_arc_to(z, x)
    }

    /// Cuts the corner at the current point, between the line ending here
    /// and the next `line_to`, by a straight line from `length` back along
    /// the one to `length` along the other (a chamfer `C length` at a
    /// square shoulder).
    #[rhai_fn(name = "chamfer")]
    pub fn chamfer(b: ProfileBuilder, length: Real) -> ProfileBuilder {
        b.chamfer(length)
    }

    /// Gives the element ending here (a line or an arc) a drawing's own
    /// tolerance on its diameter (`"h6"`, `"±0.01"`, `"+0.02/-0.01"`): its
    /// ends move to the band's middle, and a revolution's verification
    /// judges its stretch against the band. Refused at `build`, naming
    /// the segment, after a fillet, a chamfer or the mandrel law.
    ///
    /// ```rhai
    /// let p = profile_start(0.0, 15.0).line_to(10.0, 20.0).line_to(30.0, 20.0).toleranced("h6").line_to(40.0, 16.0).build(1e-4, 0.5);
    /// ```
    #[rhai_fn(name = "toleranced")]
    pub fn toleranced(b: ProfileBuilder, tolerance: &str) -> ProfileBuilder {
        b.toleranced(tolerance)
    }

    /// Declares the joint at the current point tangent, as a drawing says
    /// an arc meets a line: `build` refuses it, naming the joint and its
    /// turn, where the two meet at an angle.
    ///
    /// ```rhai
    /// let p = profile_start(0.0, 20.0).line_to(10.0, 20.0).tangent().arc_to(16.0, 18.0, 10.0, "out").build(1e-4, 0.5);
    /// ```
    #[rhai_fn(name = "tangent")]
    pub fn tangent(b: ProfileBuilder) -> ProfileBuilder {
        b.tangent()
    }

    /// An arc of `radius` to `(z, x)`, bulging "out" (convex, centre below)
    /// or "in" (a fillet, centre above).
    #[rhai_fn(name = "arc_to", return_raw)]
    pub fn arc_to(
        b: ProfileBuilder,
        z: Real,
        x: Real,
        radius: Real,
        bulge: &str,
    ) -> Result<ProfileBuilder, Box<EvalAltResult>> {
        let bulge = match bulge {
            "out" => Bulge::Out,
            "in" => Bulge::In,
            other => {
                return err(format!(
                    "arc bulge must be \"out\" or \"in\", not \"{other}\""
                ))
            }
        };
        Ok(b.arc_to(z, x, radius, bulge))
    }

    /// An arc to `(z, x)` about the centre `(cz, cx)` (a drawing's arc
    /// dimensioned by its centre), bulging away from it. Refused at
    /// `build` where the current point lies at another distance from the
    /// centre than the end.
    ///
    /// ```rhai
    /// let p = profile_start(0.0, 20.0).line_to(10.0, 20.0).tangent().arc_about(16.0, 18.0, 10.0, 10.0).build(1e-4, 0.5);
    /// ```
    #[rhai_fn(name = "arc_about")]
    pub fn arc_about(b: ProfileBuilder, z: Real, x: Real, cz: Real, cx: Real) -> ProfileBuilder {
        b.arc_about(z, x, cz, cx)
    }

    /// The mandrel law from the current z (the current x must be d_min / 2).
    #[rhai_fn(name = "law")]
    pub fn law(b: ProfileBuilder, law: MandrelLaw) -> ProfileBuilder {
        b.law(law)
    }

    /// The profile, chords within `tol` (mm), nodes at most `max_step` apart.
    #[rhai_fn(name = "build", return_raw)]
    pub fn build(
        b: ProfileBuilder,
        tol: Real,
        max_step: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        kernel(b.build(tol, max_step))
    }
}

/// Paths: polylines of points `(z, x)` in order, either way along z (a
/// wheel's centres along a pass).
#[export_module]
pub mod path_api {
    use super::*;

    /// The path through `(z[i], x[i])`.
    #[rhai_fn(return_raw)]
    pub fn path(z: Numbers, x: Numbers) -> Result<Polyline, Box<EvalAltResult>> {
        let (z, x) = (numbers(&z, "path z")?, numbers(&x, "path x")?);
        kernel(Polyline::new(z.as_ref().clone(), x.as_ref().clone()))
    }

    /// The points' z.
    #[rhai_fn(get = "z", pure)]
    pub fn path_z(p: &mut Polyline) -> Floats {
        Floats::new(p.z.clone())
    }

    /// The points' x.
    #[rhai_fn(get = "x", pure)]
    pub fn path_x(p: &mut Polyline) -> Floats {
        Floats::new(p.x.clone())
    }

    /// Number of points.
    #[rhai_fn(get = "len", pure)]
    pub fn path_len(p: &mut Polyline) -> i64 {
        p.len() as i64
    }

    /// The fewest of its points keeping every dropped one within `tol` (mm)
    /// of the chords (greedy longest chords): the adaptive spacing of a
    /// wheel's moves along its equidistant.
    #[rhai_fn(pure, return_raw)]
    pub fn simplified(p: &mut Polyline, tol: Real) -> Result<Polyline, Box<EvalAltResult>> {
        kernel(crate::math::positive("simplify tolerance", tol))?;
        Ok(p.simplified(tol))
    }

    /// The same points in reverse order.
    #[rhai_fn(name = "reversed", pure)]
    pub fn path_reversed(p: &mut Polyline) -> Polyline {
        p.reversed()
    }

    /// Every point moved by `dx` in x (a stock left on the finished path).
    #[rhai_fn(pure, return_raw)]
    pub fn shifted(p: &mut Polyline, dx: Real) -> Result<Polyline, Box<EvalAltResult>> {
        kernel(crate::math::finite("shift", dx))?;
        Ok(p.shifted(dx))
    }
}
