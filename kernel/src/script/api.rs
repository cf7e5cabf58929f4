//! The kernel's API for scripts. Per-point work is native: functions take
//! and return whole arrays ([`Floats`]), so a family in Rhai runs near
//! native speed. Native functions return plain messages; Rhai adds the
//! script's position.

use crate::math::Real;
use crate::offset::{self, Side};
use crate::profile::{MandrelLaw, Profile};
use crate::tool::{Tool, Wheel};
use crate::toolpath::{ClPoint, Motion, Pass, Toolpath};
use rhai::plugin::*;
use rhai::{Array, Dynamic, Engine, EvalAltResult, Map};
use std::cell::RefCell;
use std::rc::Rc;

/// A shared, immutable array of numbers: the currency of the script API.
#[derive(Debug, Clone)]
pub struct Floats(pub Rc<Vec<Real>>);

impl Floats {
    /// Wraps a vector.
    pub fn new(v: Vec<Real>) -> Self {
        Self(Rc::new(v))
    }
}

/// A toolpath under construction, shared by handle.
pub type ToolpathHandle = Rc<RefCell<Toolpath>>;

fn err<T>(message: impl Into<String>) -> Result<T, Box<EvalAltResult>> {
    Err(message.into().into())
}

fn kernel<T, E: std::fmt::Display>(r: Result<T, E>) -> Result<T, Box<EvalAltResult>> {
    r.map_err(|e| e.to_string().into())
}

/// Reads a number, integer or float.
pub(crate) fn number(d: &Dynamic) -> Option<Real> {
    d.as_float()
        .ok()
        .or_else(|| d.as_int().ok().map(|i| i as Real))
}

/// A column of a pass: shared numbers (not copied), or one number for all.
enum Column {
    Shared(Rc<Vec<Real>>),
    Owned(Vec<Real>),
    Scalar(Real),
}

impl Column {
    #[inline]
    fn at(&self, i: usize) -> Real {
        match self {
            Column::Shared(v) => v[i],
            Column::Owned(v) => v[i],
            Column::Scalar(x) => *x,
        }
    }

    /// Reads `d` as a column of `n` values.
    fn read(d: &Dynamic, n: usize, what: &str) -> Result<Self, Box<EvalAltResult>> {
        if let Some(f) = d.read_lock::<Floats>() {
            if f.0.len() != n {
                return err(format!(
                    "{what} has {} values, the pass has {n} points",
                    f.0.len()
                ));
            }
            return Ok(Column::Shared(f.0.clone()));
        }
        if let Some(x) = number(d) {
            return Ok(Column::Scalar(x));
        }
        column(d, n, what).map(Column::Owned)
    }
}

/// Reads a column of `n` numbers: Floats, an array of numbers, or one
/// number repeated.
fn column(d: &Dynamic, n: usize, what: &str) -> Result<Vec<Real>, Box<EvalAltResult>> {
    let v = if let Some(f) = d.clone().try_cast::<Floats>() {
        f.0.as_ref().clone()
    } else if d.is_array() {
        let a = d.clone().cast::<Array>();
        a.iter()
            .enumerate()
            .map(|(i, x)| {
                number(x).ok_or_else(|| format!("{what}[{i}] is a {}, not a number", x.type_name()))
            })
            .collect::<Result<Vec<_>, _>>()?
    } else if let Some(x) = number(d) {
        return Ok(vec![x; n]);
    } else {
        return err(format!("{what} must be numbers, not a {}", d.type_name()));
    };
    if v.len() != n {
        return err(format!(
            "{what} has {} values, the pass has {n} points",
            v.len()
        ));
    }
    Ok(v)
}

fn len_of(d: &Dynamic) -> Option<usize> {
    if let Some(f) = d.clone().try_cast::<Floats>() {
        Some(f.0.len())
    } else if d.is_array() {
        Some(d.clone().cast::<Array>().len())
    } else {
        None
    }
}

/// Arrays of numbers.
#[export_module]
pub mod floats_api {
    use super::*;

    /// `n` numbers evenly spaced from `a` to `b` (both included).
    ///
    /// ```rhai
    /// let t = linspace(0.0, 1.0, 5);   // 0, 0.25, 0.5, 0.75, 1
    /// ```
    #[rhai_fn(return_raw)]
    pub fn linspace(a: Real, b: Real, n: i64) -> Result<Floats, Box<EvalAltResult>> {
        if n < 2 {
            return err(format!("linspace needs at least 2 points, got {n}"));
        }
        if n > 10_000_000 {
            return err(format!("linspace of {n} points is more than 10 million"));
        }
        let m = (n - 1) as Real;
        Ok(Floats::new(
            (0..n)
                .map(|i| {
                    if i == n - 1 {
                        b
                    } else {
                        a + (b - a) * i as Real / m
                    }
                })
                .collect(),
        ))
    }

    /// The grid `a, a + step, ..., b` (the last step may be shorter).
    #[rhai_fn(return_raw)]
    pub fn grid(a: Real, b: Real, step: Real) -> Result<Floats, Box<EvalAltResult>> {
        kernel(crate::profile::uniform_grid(a, b, step)).map(Floats::new)
    }

    /// `n` copies of `value`.
    #[rhai_fn(return_raw)]
    pub fn filled(n: i64, value: Real) -> Result<Floats, Box<EvalAltResult>> {
        if !(0..=10_000_000).contains(&n) {
            return err(format!("filled: {n} values is out of range"));
        }
        Ok(Floats::new(vec![value; n as usize]))
    }

    /// Numbers from an array of numbers.
    #[rhai_fn(return_raw)]
    pub fn floats(values: Array) -> Result<Floats, Box<EvalAltResult>> {
        let n = values.len();
        column(&Dynamic::from_array(values), n, "floats").map(Floats::new)
    }

    /// The numbers as an ordinary array.
    #[rhai_fn(pure)]
    pub fn to_array(v: &mut Floats) -> Array {
        v.0.iter().map(|x| Dynamic::from_float(*x)).collect()
    }

    /// Number of values.
    #[rhai_fn(get = "len", pure)]
    pub fn len(v: &mut Floats) -> i64 {
        v.0.len() as i64
    }

    /// The value at `i` (from 0; negative counts from the end).
    #[rhai_fn(index_get, pure, return_raw)]
    pub fn get(v: &mut Floats, i: i64) -> Result<Real, Box<EvalAltResult>> {
        let n = v.0.len() as i64;
        let k = if i < 0 { n + i } else { i };
        if !(0..n).contains(&k) {
            return err(format!("index {i} is out of range for {n} values"));
        }
        Ok(v.0[k as usize])
    }

    /// Elementwise sine (radians).
    #[rhai_fn(name = "sin", pure)]
    pub fn sin_f(v: &mut Floats) -> Floats {
        Floats::new(v.0.iter().map(|x| x.sin()).collect())
    }

    /// Elementwise cosine (radians).
    #[rhai_fn(name = "cos", pure)]
    pub fn cos_f(v: &mut Floats) -> Floats {
        Floats::new(v.0.iter().map(|x| x.cos()).collect())
    }

    /// Elementwise arctangent (radians).
    #[rhai_fn(name = "atan", pure)]
    pub fn atan_f(v: &mut Floats) -> Floats {
        Floats::new(v.0.iter().map(|x| x.atan()).collect())
    }

    /// Elementwise square root.
    #[rhai_fn(name = "sqrt", pure)]
    pub fn sqrt_f(v: &mut Floats) -> Floats {
        Floats::new(v.0.iter().map(|x| x.sqrt()).collect())
    }

    /// Elementwise absolute value.
    #[rhai_fn(name = "abs", pure)]
    pub fn abs_f(v: &mut Floats) -> Floats {
        Floats::new(v.0.iter().map(|x| x.abs()).collect())
    }

    /// The smallest value.
    #[rhai_fn(name = "min", pure)]
    pub fn min_f(v: &mut Floats) -> Real {
        v.0.iter().copied().fold(Real::INFINITY, Real::min)
    }

    /// The largest value.
    #[rhai_fn(name = "max", pure)]
    pub fn max_f(v: &mut Floats) -> Real {
        v.0.iter().copied().fold(Real::NEG_INFINITY, Real::max)
    }

    /// The sum.
    #[rhai_fn(pure)]
    pub fn sum(v: &mut Floats) -> Real {
        v.0.iter().sum()
    }

    /// The values in reverse order.
    #[rhai_fn(name = "reverse", pure)]
    pub fn reverse_f(v: &mut Floats) -> Floats {
        Floats::new(v.0.iter().rev().copied().collect())
    }

    /// `a` followed by `b`.
    #[rhai_fn(name = "concat")]
    pub fn concat_f(a: Floats, b: Floats) -> Floats {
        Floats::new(a.0.iter().chain(b.0.iter()).copied().collect())
    }
}

/// Profiles and their generators.
#[export_module]
pub mod profile_api {
    use super::*;

    /// A profile `x(z)` from its samples (z increasing strictly, at least 3).
    #[rhai_fn(return_raw)]
    pub fn profile(z: Floats, x: Floats) -> Result<Profile, Box<EvalAltResult>> {
        kernel(Profile::new(z.0.as_ref().clone(), x.0.as_ref().clone()))
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
    #[rhai_fn(name = "eval", pure, return_raw)]
    pub fn eval_at(p: &mut Profile, z: Real) -> Result<Real, Box<EvalAltResult>> {
        kernel(p.eval(z))
    }

    /// The profile at a uniform step of z.
    #[rhai_fn(pure, return_raw)]
    pub fn resample(p: &mut Profile, step: Real) -> Result<Profile, Box<EvalAltResult>> {
        kernel(p.resample_uniform(step))
    }

    /// Three-point smoothing of the derivative (seed 001): `iterations`
    /// passes, rebuilt from node `anchor`. Returns
    /// `#{profile, max_change, max_change_z}`.
    #[rhai_fn(pure, return_raw)]
    pub fn smooth(
        p: &mut Profile,
        iterations: i64,
        anchor: i64,
    ) -> Result<Map, Box<EvalAltResult>> {
        if iterations < 0 || anchor < 0 {
            return err("smooth: iterations and anchor must not be negative");
        }
        let s = kernel(p.smooth_derivative(iterations as usize, anchor as usize))?;
        let mut m = Map::new();
        m.insert("max_change".into(), Dynamic::from_float(s.max_change));
        m.insert("max_change_z".into(), Dynamic::from_float(s.max_change_z));
        m.insert("profile".into(), Dynamic::from(s.profile));
        Ok(m)
    }

    /// The mandrel's working-part law (MATH §2.1): diameters `d_min` at 0 and
    /// `d_max` at `l_r`, initial taper `k`, exponent `n`.
    #[rhai_fn(return_raw)]
    pub fn mandrel_law(
        d_min: Real,
        d_max: Real,
        l_r: Real,
        k: Real,
        n: Real,
    ) -> Result<MandrelLaw, Box<EvalAltResult>> {
        kernel(MandrelLaw::new(d_min, d_max, l_r, k, n))
    }

    /// The law's radius x(z).
    #[rhai_fn(name = "x")]
    pub fn law_x(law: &mut MandrelLaw, z: Real) -> Real {
        law.x(z)
    }

    /// The law's slope dx/dz at z.
    #[rhai_fn(name = "dx")]
    pub fn law_dx(law: &mut MandrelLaw, z: Real) -> Real {
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

/// A whole part profile chained from segments, for scripts.
#[export_module]
pub mod builder_api {
    use super::*;
    use crate::profile::{Bulge, ProfileBuilder};

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

    /// The fewest points of the polyline `(z, x)` keeping every dropped one
    /// within `tol` of the chords (Douglas–Peucker): the adaptive spacing of
    /// a wheel's moves along its equidistant. Returns `#{ z, x }`.
    #[rhai_fn(return_raw)]
    pub fn simplify(z: Floats, x: Floats, tol: Real) -> Result<Map, Box<EvalAltResult>> {
        if z.0.len() != x.0.len() {
            return err(format!(
                "simplify: z has {} values, x {}",
                z.0.len(),
                x.0.len()
            ));
        }
        crate::math::positive("simplify tolerance", tol).map_err(|e| e.to_string())?;
        let keep = crate::profile::simplify_polyline(&z.0, &x.0, tol);
        let mut m = Map::new();
        m.insert(
            "z".into(),
            Dynamic::from(Floats::new(keep.iter().map(|&i| z.0[i]).collect())),
        );
        m.insert(
            "x".into(),
            Dynamic::from(Floats::new(keep.iter().map(|&i| x.0[i]).collect())),
        );
        Ok(m)
    }
}

/// Equidistants, drops, envelopes and the steady rest.
#[export_module]
pub mod offset_api {
    use super::*;

    fn side(s: &str) -> Result<Side, Box<EvalAltResult>> {
        match s {
            "outside" => Ok(Side::Outside),
            "inside" => Ok(Side::Inside),
            other => err(format!(
                "side must be \"outside\" or \"inside\", not \"{other}\""
            )),
        }
    }

    /// The centres of a tool circle of `radius` touching the profile at each
    /// node, on `side` ("outside" or "inside"); refuses a tool rounder than
    /// the profile, naming every z. Returns `#{z, x, slope}`.
    #[rhai_fn(return_raw)]
    pub fn equidistant(
        p: Profile,
        radius: Real,
        side_name: &str,
    ) -> Result<Map, Box<EvalAltResult>> {
        let e = kernel(offset::equidistant(&p, radius, side(side_name)?))?;
        let mut m = Map::new();
        m.insert("z".into(), Dynamic::from(Floats::new(e.z)));
        m.insert("x".into(), Dynamic::from(Floats::new(e.x)));
        m.insert("slope".into(), Dynamic::from(Floats::new(e.slope)));
        Ok(m)
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

    /// The surface left by circles of `radius` centred at `(zc, xc)` (a
    /// wheel from outside), evaluated at `at`; infinite where no circle reaches.
    #[rhai_fn(return_raw)]
    pub fn envelope(
        zc: Floats,
        xc: Floats,
        radius: Real,
        at: Floats,
    ) -> Result<Floats, Box<EvalAltResult>> {
        let env = kernel(offset::CircleEnvelope::new(
            &zc.0,
            &xc.0,
            radius,
            Side::Outside,
        ))?;
        Ok(Floats::new(env.eval_many(&at.0)))
    }

    /// The steady rest's centre x at `z_r` by the seed's first-order formula.
    #[rhai_fn(return_raw)]
    pub fn rest_seed_u(surface: Profile, z_r: Real, r_o: Real) -> Result<Real, Box<EvalAltResult>> {
        kernel(offset::rest::seed_u(&surface, z_r, r_o))
    }

    /// The steady rest along a pass (MATH §2.3): the wheel's rounding centre
    /// moves through `(cz, cx)` (one way along z) over a workpiece whose
    /// surface before the pass is `previous`; the rest's support (radius
    /// `r_o`) stands at `z_r = z + b`. Returns per block `#{ centre_x,
    /// contact_z, contact_x, seed_centre_x }` (Floats),
    /// `max_model_difference` (mm) between the exact drop on the current
    /// surface and the seed's formula on it, and `max_difference_block`
    /// (from 0), where that is.
    #[rhai_fn(return_raw)]
    pub fn rest_track(
        previous: Profile,
        cz: Floats,
        cx: Floats,
        wheel_radius: Real,
        r_o: Real,
        b: Real,
    ) -> Result<Map, Box<EvalAltResult>> {
        let setup = offset::rest::RestSetup {
            radius: r_o,
            offset_b: b,
            sample: 0.05,
            resolution: 1e-5,
        };
        let t = kernel(offset::rest::track(
            &previous,
            &cz.0,
            &cx.0,
            wheel_radius,
            &setup,
        ))?;
        let mut m = Map::new();
        m.insert("centre_x".into(), Dynamic::from(Floats::new(t.centre_x)));
        m.insert("contact_z".into(), Dynamic::from(Floats::new(t.contact_z)));
        m.insert("contact_x".into(), Dynamic::from(Floats::new(t.contact_x)));
        m.insert(
            "seed_centre_x".into(),
            Dynamic::from(Floats::new(t.seed_centre_x)),
        );
        m.insert(
            "max_model_difference".into(),
            Dynamic::from_float(t.max_model_difference),
        );
        m.insert(
            "max_difference_block".into(),
            Dynamic::from_int(t.max_difference_block as rhai::INT),
        );
        Ok(m)
    }

    /// The surface after a pass: the lower of `previous` and what the wheel's
    /// rounding leaves moving through `(cz, cx)`, at `previous`'s nodes.
    #[rhai_fn(return_raw)]
    pub fn cut(
        previous: Profile,
        cz: Floats,
        cx: Floats,
        wheel_radius: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        kernel(offset::rest::after_pass(
            &previous,
            &cz.0,
            &cx.0,
            wheel_radius,
            1e-5,
        ))
    }

    /// The profile with `dx` added where `z_from <= z <= z_to` (a stock
    /// allowance over the ground length: the blank).
    #[rhai_fn(return_raw)]
    pub fn raise(
        p: Profile,
        z_from: Real,
        z_to: Real,
        dx: Real,
    ) -> Result<Profile, Box<EvalAltResult>> {
        let x = p
            .z()
            .iter()
            .zip(p.x())
            .map(|(z, x)| {
                if (z_from..=z_to).contains(z) {
                    x + dx
                } else {
                    *x
                }
            })
            .collect();
        kernel(Profile::new(p.z().to_vec(), x))
    }

    /// The steady rest's centre x at `z_r` by the exact drop.
    #[rhai_fn(return_raw)]
    pub fn rest_exact_u(
        surface: Profile,
        z_r: Real,
        r_o: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        Ok(kernel(offset::rest::exact_u(&surface, z_r, r_o))?.centre_x)
    }
}

/// A 4x4 transform for scripts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform(pub crate::math::Mat4);

/// Transforms (MATH §1): the elementary factors and the universal chain.
#[export_module]
pub mod transform_api {
    use super::*;
    use crate::transform::{Chain, FactorKind};

    /// An elementary factor: `kind` "tx", "ty", "tz" (translation, mm) or
    /// "rx", "ry", "rz" (rotation, degrees). Compose with `*`.
    ///
    /// ```rhai
    /// let a = transform("rz", 30.0) * transform("tx", 10.0);
    /// ```
    #[rhai_fn(return_raw)]
    pub fn transform(kind: &str, value: Real) -> Result<Transform, Box<EvalAltResult>> {
        let k = FactorKind::ALL
            .into_iter()
            .find(|k| format!("{k:?}").eq_ignore_ascii_case(kind))
            .ok_or_else(|| {
                format!("transform kind must be tx, ty, tz, rx, ry or rz, not '{kind}'")
            })?;
        let v = if k.is_rotation() {
            value.to_radians()
        } else {
            value
        };
        Ok(Transform(k.matrix(v)))
    }

    /// The universal chain of seed 003 (S003-3) for its fifteen parameters
    /// in the seed's order `a b c phi a1 b1 c1 theta a2 b2 c2 psi a3 b3 c3`
    /// (mm; the angles phi, theta, psi in degrees).
    #[rhai_fn(return_raw)]
    pub fn universal(q: Array) -> Result<Transform, Box<EvalAltResult>> {
        if q.len() != 15 {
            return err(format!("universal needs 15 values, got {}", q.len()));
        }
        let mut v = column(&Dynamic::from_array(q), 15, "universal")?;
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

    /// The points `(x, y, z)` mapped by `t`: `#{ x, y, z }`.
    #[rhai_fn(return_raw)]
    pub fn apply(t: Transform, x: Floats, y: Floats, z: Floats) -> Result<Map, Box<EvalAltResult>> {
        let n = x.0.len();
        if y.0.len() != n || z.0.len() != n {
            return err(format!(
                "apply: x, y, z have {n}, {}, {} values",
                y.0.len(),
                z.0.len()
            ));
        }
        let (mut ox, mut oy, mut oz) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for i in 0..n {
            let p = t.0 * nalgebra::Vector4::new(x.0[i], y.0[i], z.0[i], 1.0);
            ox.push(p.x);
            oy.push(p.y);
            oz.push(p.z);
        }
        let mut m = Map::new();
        m.insert("x".into(), Dynamic::from(Floats::new(ox)));
        m.insert("y".into(), Dynamic::from(Floats::new(oy)));
        m.insert("z".into(), Dynamic::from(Floats::new(oz)));
        Ok(m)
    }
}

/// Tools.
#[export_module]
pub mod tool_api {
    use super::*;

    /// A grinding wheel tool: `diameter`, rounding radius, `width` (mm); the
    /// toolpath tracks its rounding's centre, the machine programs its lowest point.
    #[rhai_fn(return_raw)]
    pub fn wheel_tool(
        name: &str,
        number: i64,
        diameter: Real,
        rounding_radius: Real,
        width: Real,
    ) -> Result<Tool, Box<EvalAltResult>> {
        let w = kernel(Wheel::new(diameter, rounding_radius, width))?;
        Ok(Tool::wheel(name, tool_number(number)?, w))
    }

    /// An end mill tracked at its tip centre.
    #[rhai_fn(return_raw)]
    pub fn end_mill(
        name: &str,
        number: i64,
        diameter: Real,
        length: Real,
    ) -> Result<Tool, Box<EvalAltResult>> {
        kernel(Tool::end_mill(name, tool_number(number)?, diameter, length))
    }

    fn tool_number(n: i64) -> Result<u32, Box<EvalAltResult>> {
        u32::try_from(n).map_err(|_| format!("tool number {n} is out of range").into())
    }
}

/// Building toolpaths.
#[export_module]
pub mod toolpath_api {
    use super::*;

    /// A new, empty toolpath for `part` with `tool` at `rpm`; every point
    /// will carry the auxiliary values named in `aux_names` (e.g. `["U"]`).
    #[rhai_fn(return_raw)]
    pub fn new_toolpath(
        part: &str,
        tool: Tool,
        rpm: Real,
        aux_names: Array,
    ) -> Result<ToolpathHandle, Box<EvalAltResult>> {
        let names = aux_names
            .iter()
            .map(|d| {
                d.clone()
                    .into_string()
                    .map_err(|t| format!("auxiliary names must be strings, not {t}"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Rc::new(RefCell::new(Toolpath::new(part, tool, rpm, names))))
    }

    /// Notes a figure about the toolpath for the run's report.
    #[rhai_fn(name = "note", return_raw)]
    pub fn note(
        tp: &mut ToolpathHandle,
        name: &str,
        value: Real,
    ) -> Result<(), Box<EvalAltResult>> {
        crate::math::finite(&format!("note {name}"), value).map_err(|e| e.to_string())?;
        tp.borrow_mut().notes.insert(name.to_owned(), value);
        Ok(())
    }

    /// Number of points so far.
    #[rhai_fn(get = "point_count", pure)]
    pub fn point_count(tp: &mut ToolpathHandle) -> i64 {
        tp.borrow().point_count() as i64
    }

    /// Appends a pass. `data` holds columns (Floats, arrays, or one number
    /// for all points): `x`, `y`, `z` (the tracked point, mm), `feed`
    /// (mm/min; not for rapids), and optionally `motion` ("linear",
    /// "rapid", "thread"), `lead` (mm, threads), `i`, `j`, `k` (the tool's
    /// axis, default 0, 0, 1), `aux` (a map of the toolpath's auxiliary
    /// names to columns).
    ///
    /// ```rhai
    /// tp.add_pass("contour", #{ x: xs, y: ys, z: -5.0, feed: 600.0 });
    /// ```
    #[rhai_fn(return_raw)]
    pub fn add_pass(
        tp: &mut ToolpathHandle,
        name: &str,
        data: Map,
    ) -> Result<(), Box<EvalAltResult>> {
        const KEYS: [&str; 10] = [
            "x", "y", "z", "feed", "motion", "lead", "i", "j", "k", "aux",
        ];
        if let Some(k) = data.keys().find(|k| !KEYS.contains(&k.as_str())) {
            return err(format!(
                "add_pass: unknown key '{k}' (keys: {})",
                KEYS.join(", ")
            ));
        }
        let get = |k: &str| data.get(k).cloned();
        let n = ["x", "y", "z"]
            .iter()
            .find_map(|k| get(k).as_ref().and_then(len_of))
            .ok_or("add_pass: x, y or z must be an array of the pass's points")?;
        let col = |k: &str, default: Option<Real>| -> Result<Column, Box<EvalAltResult>> {
            match (get(k), default) {
                (Some(d), _) => Column::read(&d, n, k),
                (None, Some(v)) => Ok(Column::Scalar(v)),
                (None, None) => err(format!("add_pass: missing '{k}'")),
            }
        };
        let motion_name = match get("motion") {
            Some(m) => m
                .into_string()
                .map_err(|t| format!("add_pass: motion must be a string, not {t}"))?,
            None => "linear".into(),
        };
        let motion = match motion_name.as_str() {
            "linear" => Motion::Linear,
            "rapid" => Motion::Rapid,
            "thread" => {
                let lead = get("lead")
                    .as_ref()
                    .and_then(number)
                    .ok_or("add_pass: a thread needs a number 'lead'")?;
                Motion::Thread { lead }
            }
            other => {
                return err(format!(
                    "add_pass: motion must be linear, rapid or thread, not '{other}'"
                ))
            }
        };
        let (x, y, z) = (col("x", None)?, col("y", None)?, col("z", None)?);
        let feed = col("feed", (motion == Motion::Rapid).then_some(0.0))?;
        let (i, j, k) = (
            col("i", Some(0.0))?,
            col("j", Some(0.0))?,
            col("k", Some(1.0))?,
        );
        let mut t = tp.borrow_mut();
        let aux_map = match get("aux") {
            Some(a) => a
                .try_cast::<Map>()
                .ok_or("add_pass: aux must be a map of columns")?,
            None => Map::new(),
        };
        if let Some(extra) = aux_map
            .keys()
            .find(|a| !t.aux_names.iter().any(|n| n == a.as_str()))
        {
            return err(format!(
                "add_pass: '{extra}' is not one of the toolpath's auxiliary names ({})",
                t.aux_names.join(", ")
            ));
        }
        let aux = t
            .aux_names
            .iter()
            .map(|a| match aux_map.get(a.as_str()) {
                Some(d) => Column::read(d, n, &format!("aux.{a}")),
                None => err(format!("add_pass: missing aux.{a}")),
            })
            .collect::<Result<Vec<_>, Box<EvalAltResult>>>()?;
        let points = (0..n)
            .map(|p| ClPoint {
                point: [x.at(p), y.at(p), z.at(p)],
                axis: [i.at(p), j.at(p), k.at(p)],
                motion,
                feed: feed.at(p),
                aux: aux.iter().map(|c| c.at(p)).collect(),
            })
            .collect();
        t.passes.push(Pass {
            name: name.to_owned(),
            points,
        });
        Ok(())
    }
}

/// Registers the API: types, modules, arithmetic on [`Floats`].
pub fn register(engine: &mut Engine) {
    engine
        .register_type_with_name::<Floats>("Floats")
        .register_type_with_name::<Profile>("Profile")
        .register_type_with_name::<MandrelLaw>("MandrelLaw")
        .register_type_with_name::<Tool>("Tool")
        .register_type_with_name::<Transform>("Transform")
        .register_type_with_name::<crate::profile::ProfileBuilder>("ProfileBuilder")
        .register_type_with_name::<ToolpathHandle>("Toolpath");
    engine.register_global_module(exported_module!(floats_api).into());
    engine.register_global_module(exported_module!(profile_api).into());
    engine.register_global_module(exported_module!(builder_api).into());
    engine.register_global_module(exported_module!(offset_api).into());
    engine.register_global_module(exported_module!(transform_api).into());
    engine.register_global_module(exported_module!(tool_api).into());
    engine.register_global_module(exported_module!(toolpath_api).into());
    register_arithmetic(engine);
}

/// `+ - * /` between Floats (elementwise, equal lengths) and numbers.
fn register_arithmetic(engine: &mut Engine) {
    fn zip(
        a: &Floats,
        b: &Floats,
        op: fn(Real, Real) -> Real,
    ) -> Result<Floats, Box<EvalAltResult>> {
        if a.0.len() != b.0.len() {
            return err(format!(
                "arrays of {} and {} values cannot be combined",
                a.0.len(),
                b.0.len()
            ));
        }
        Ok(Floats::new(
            a.0.iter()
                .zip(b.0.iter())
                .map(|(x, y)| op(*x, *y))
                .collect(),
        ))
    }
    fn scalar(a: &Floats, s: Real, op: fn(Real, Real) -> Real, flip: bool) -> Floats {
        Floats::new(
            a.0.iter()
                .map(|x| if flip { op(s, *x) } else { op(*x, s) })
                .collect(),
        )
    }
    type Op = fn(Real, Real) -> Real;
    let ops: [(&str, Op); 4] = [
        ("+", |a, b| a + b),
        ("-", |a, b| a - b),
        ("*", |a, b| a * b),
        ("/", |a, b| a / b),
    ];
    for (name, op) in ops {
        engine.register_fn(name, move |a: Floats, b: Floats| zip(&a, &b, op));
        engine.register_fn(name, move |a: Floats, s: Real| scalar(&a, s, op, false));
        engine.register_fn(name, move |s: Real, a: Floats| scalar(&a, s, op, true));
        engine.register_fn(name, move |a: Floats, s: i64| {
            scalar(&a, s as Real, op, false)
        });
        engine.register_fn(name, move |s: i64, a: Floats| {
            scalar(&a, s as Real, op, true)
        });
    }
    engine.register_fn("-", |a: Floats| {
        Floats::new(a.0.iter().map(|x| -x).collect())
    });
}
