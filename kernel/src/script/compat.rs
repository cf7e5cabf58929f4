//! Script functions of earlier releases, kept callable: each renamed or
//! re-shaped function of the script API answers under its old name and
//! shape for at least one release after the change, doing what it did
//! through today's kernel, and says once per run which function replaces
//! it (a warning in the report and on the error stream). `CHANGELOG.md`
//! lists each change and when the old form goes.
//!
//! `eval(p, z)` (today `x_at`) cannot be kept: `eval` is a Rhai keyword,
//! which no function may be named, and no release could call it. Two old
//! form is not kept either: the intermediate `cut(Profile, Path, Tool,
//! float)`, which lived between two releases. Calling it is an error
//! naming the replacement, not "function not found". (The first
//! release's `rest_track` on a bare profile is kept, with the ridge-free
//! model it had, by the revolution family, whose function it is.)

use crate::binding::floats::{err, kernel, Floats, Numbers};
pub use crate::binding::take_warnings;
use crate::binding::{deprecated, gone};
use crate::math::Real;
use crate::profile::{MandrelLaw, Polyline, Profile};
use crate::tool::Tool;
use rhai::plugin::*;
use rhai::{EvalAltResult, Map};

/// Earlier releases' names and shapes of today's functions: each says so
/// and calls today's binding, reshaping only what the old form took or
/// gave.
#[export_module]
pub mod compat_api {
    use super::*;
    use crate::binding::floats::floats_api;
    use crate::script::bind_offset::offset_api;
    use crate::script::bind_profile::{path_api, profile_api};
    use crate::script::bind_transform::{transform_api, Transform};

    /// Earlier form of `raised(p, z_from, z_to, dx)`.
    #[rhai_fn(return_raw)]
    pub fn raise(
        mut p: Profile,
        z_from: Real,
        z_to: Real,
        dx: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        deprecated("raise(p, z_from, z_to, dx)", "raised(p, z_from, z_to, dx)");
        profile_api::raised(&mut p, z_from, z_to, dx)
    }

    /// Earlier form of `resampled(p, step)`.
    #[rhai_fn(pure, return_raw)]
    pub fn resample(p: &mut Profile, step: Real) -> Result<Profile, Box<EvalAltResult>> {
        deprecated("resample(p, step)", "resampled(p, step)");
        profile_api::resampled(p, step)
    }

    /// Earlier form of `smoothed(p, iterations, anchor)`: a map
    /// `#{ profile, max_change, max_change_z }`.
    #[rhai_fn(pure, return_raw)]
    pub fn smooth(
        p: &mut Profile,
        iterations: i64,
        anchor: i64,
    ) -> Result<Map, Box<EvalAltResult>> {
        deprecated(
            "smooth(p, iterations, anchor)",
            "smoothed(p, iterations, anchor)",
        );
        let s = profile_api::smoothed(p, iterations, anchor)?;
        let mut m = Map::new();
        m.insert("max_change".into(), Dynamic::from_float(s.max_change));
        m.insert("max_change_z".into(), Dynamic::from_float(s.max_change_z));
        m.insert("profile".into(), Dynamic::from(s.profile));
        Ok(m)
    }

    /// Earlier form of `slope(law, z)`.
    #[rhai_fn(pure)]
    pub fn dx(law: &mut MandrelLaw, z: Real) -> Real {
        deprecated("dx(law, z)", "slope(law, z)");
        profile_api::law_slope(law, z)
    }

    /// Earlier form of `reversed(v)`.
    #[rhai_fn(name = "reverse", pure)]
    pub fn reverse_floats(v: &mut Floats) -> Floats {
        deprecated("reverse(v) of Floats", "reversed(v)");
        floats_api::reversed(v)
    }

    /// Earlier form of `path(z, x).simplified(tol)`: a map `#{ z, x }`.
    #[rhai_fn(return_raw)]
    pub fn simplify(z: Floats, x: Floats, tol: Real) -> Result<Map, Box<EvalAltResult>> {
        deprecated("simplify(z, x, tol)", "path(z, x).simplified(tol)");
        let mut p = path_api::path(Dynamic::from(z), Dynamic::from(x))?;
        let p = path_api::simplified(&mut p, tol)?;
        let mut m = Map::new();
        m.insert("z".into(), Dynamic::from(Floats::new(p.z)));
        m.insert("x".into(), Dynamic::from(Floats::new(p.x)));
        Ok(m)
    }

    /// Earlier form of `envelope(path(zc, xc), radius, at)`.
    #[rhai_fn(name = "envelope", return_raw)]
    pub fn envelope_of(
        zc: Floats,
        xc: Floats,
        radius: Real,
        at: Floats,
    ) -> Result<Floats, Box<EvalAltResult>> {
        deprecated(
            "envelope(zc, xc, radius, at)",
            "envelope(path(zc, xc), radius, at)",
        );
        let centres = path_api::path(Dynamic::from(zc), Dynamic::from(xc))?;
        offset_api::envelope(centres, radius, Dynamic::from(at))
    }

    /// Earlier form of `rx_deg`, `ry_deg`, `rz_deg`, `tx`, `ty`, `tz`:
    /// `kind` "tx", "ty", "tz" (mm) or "rx", "ry", "rz" (degrees).
    #[rhai_fn(return_raw)]
    pub fn transform(kind: &str, value: Real) -> Result<Transform, Box<EvalAltResult>> {
        let (new, name): (fn(Real) -> Transform, &str) = match kind {
            "tx" => (transform_api::tx, "tx"),
            "ty" => (transform_api::ty, "ty"),
            "tz" => (transform_api::tz, "tz"),
            "rx" => (transform_api::rx_deg, "rx_deg"),
            "ry" => (transform_api::ry_deg, "ry_deg"),
            "rz" => (transform_api::rz_deg, "rz_deg"),
            other => {
                return err(format!(
                    "transform: kind '{}' is none of tx, ty, tz, rx, ry, rz",
                    crate::files::excerpt(other)
                ))
            }
        };
        deprecated(
            &format!("transform(\"{kind}\", value)"),
            &format!("{name}(value)"),
        );
        Ok(new(value))
    }

    /// Earlier form of `universal_deg(q)`.
    #[rhai_fn(return_raw)]
    pub fn universal(q: Numbers) -> Result<Transform, Box<EvalAltResult>> {
        deprecated("universal(q)", "universal_deg(q)");
        transform_api::universal_deg(q)
    }

    /// Earlier form of `cut(ground_surface(previous), path(cz, cx), wheel,
    /// feed, spindle_rpm)`: the surface the wheel's rounding of radius
    /// `wheel_radius` leaves moving through `(cz, cx)` over `previous`, at
    /// `previous`'s nodes (the lower of the two: `envelope`'s). The old
    /// call gave no feed or spindle speed: the ridges between turns are
    /// left out, as the old model had none.
    #[rhai_fn(return_raw)]
    pub fn cut(
        previous: Profile,
        cz: Floats,
        cx: Floats,
        wheel_radius: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        deprecated(
            "cut(previous, cz, cx, wheel_radius)",
            "cut(ground_surface(previous), path(cz, cx), wheel, feed, spindle_rpm)",
        );
        let centres = path_api::path(Dynamic::from(cz), Dynamic::from(cx))?;
        let z = Floats::new(previous.z().to_vec());
        let env = offset_api::envelope(centres, wheel_radius, Dynamic::from(z.clone()))?;
        let x: Vec<Real> = previous
            .x()
            .iter()
            .zip(env.0.iter())
            .map(|(&a, &b)| a.min(b))
            .collect();
        kernel(Profile::new(z.0.to_vec(), x))
    }

    /// Not kept: see the module's docs.
    #[rhai_fn(name = "cut", return_raw)]
    pub fn cut_path(
        _previous: Profile,
        _centres: Polyline,
        _wheel: Tool,
        _feed: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        Err(gone(
            "cut(previous, centres, wheel, feed)",
            "cut(ground_surface(previous), centres, wheel, feed, spindle_rpm)",
            "the surface carries each pass's ridges, which needs the spindle speed",
        ))
    }
}
