//! [`Floats`], the currency of the script API: a shared, immutable array
//! of numbers that kernel functions take and return whole, so per-point
//! work stays native. Where the API takes numbers it accepts `Floats`, a
//! plain array of numbers, and (where one value may stand for all) a single
//! number alike ([`numbers`], [`Column`]).

use crate::math::Real;
use rhai::plugin::*;
use rhai::{Array, Dynamic, Engine, EvalAltResult};
use std::rc::Rc;

/// A shared, immutable array of numbers.
#[derive(Debug, Clone)]
pub struct Floats(pub Rc<Vec<Real>>);

impl Floats {
    /// Wraps a vector.
    pub fn new(v: Vec<Real>) -> Self {
        Self(Rc::new(v))
    }
}

/// The most values a `Floats` may hold: 10 million (80 MB).
pub const MAX_FLOATS: usize = 10_000_000;

/// What a binding declares for a parameter that takes numbers: `Floats`,
/// an array of numbers, or (where the function says so) one number. The
/// reference shows it as `Floats`.
pub type Numbers = Dynamic;

/// A binding's failure, as the message Rhai places in the script.
pub(crate) fn err<T>(message: impl Into<String>) -> Result<T, Box<EvalAltResult>> {
    Err(message.into().into())
}

/// A kernel result in a binding: its error as the script's message.
pub(crate) fn kernel<T, E: std::fmt::Display>(r: Result<T, E>) -> Result<T, Box<EvalAltResult>> {
    r.map_err(|e| e.to_string().into())
}

/// Reads a number, integer or float.
pub(crate) fn number(d: &Dynamic) -> Option<Real> {
    d.as_float()
        .ok()
        .or_else(|| d.as_int().ok().map(|i| i as Real))
}

/// Reads `d` as numbers: `Floats` (shared, not copied) or an array of
/// numbers; `what` names it in errors.
pub(crate) fn numbers(d: &Dynamic, what: &str) -> Result<Rc<Vec<Real>>, Box<EvalAltResult>> {
    if let Some(f) = d.read_lock::<Floats>() {
        return Ok(f.0.clone());
    }
    if d.is_array() {
        let a = d.read_lock::<Array>().ok_or("array")?;
        return a
            .iter()
            .enumerate()
            .map(|(i, x)| {
                number(x).ok_or_else(|| {
                    format!("{what}[{i}] is a {}, not a number", x.type_name()).into()
                })
            })
            .collect::<Result<Vec<_>, Box<EvalAltResult>>>()
            .map(Rc::new);
    }
    err(format!(
        "{what} must be numbers (Floats or an array), not a {}",
        d.type_name()
    ))
}

/// A column of `n` values: shared numbers (not copied), or one number for
/// all.
pub(crate) enum Column {
    Shared(Rc<Vec<Real>>),
    Scalar(Real),
}

impl Column {
    #[inline]
    pub(crate) fn at(&self, i: usize) -> Real {
        match self {
            Column::Shared(v) => v[i],
            Column::Scalar(x) => *x,
        }
    }

    /// Reads `d` as a column of `n` values: numbers, or one number for all.
    pub(crate) fn read(d: &Dynamic, n: usize, what: &str) -> Result<Self, Box<EvalAltResult>> {
        if let Some(x) = number(d) {
            return Ok(Column::Scalar(x));
        }
        let v = numbers(d, what)?;
        if v.len() != n {
            return err(format!(
                "{what} has {} values, the pass has {n} points",
                v.len()
            ));
        }
        Ok(Column::Shared(v))
    }
}

/// How many numbers `d` holds, if it holds numbers.
pub(crate) fn len_of(d: &Dynamic) -> Option<usize> {
    if let Some(f) = d.read_lock::<Floats>() {
        Some(f.0.len())
    } else {
        d.read_lock::<Array>().map(|a| a.len())
    }
}

/// Arrays of numbers.
#[export_module]
pub mod floats_api {
    use super::*;

    /// `x` with `decimals` decimals (0 to 12), as programs and reports
    /// write numbers (never `-0.000`).
    ///
    /// ```rhai
    /// fixed(2.0 / 3.0, 3) // "0.667"
    /// ```
    #[rhai_fn(name = "fixed")]
    pub fn fixed_text(x: Real, decimals: i64) -> String {
        crate::math::fixed(x, decimals.clamp(0, 12) as usize)
    }

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
        if n > MAX_FLOATS as i64 {
            return err(format!(
                "linspace of {n} points is more than the ceiling of {MAX_FLOATS}"
            ));
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
        if !(0..=MAX_FLOATS as i64).contains(&n) {
            return err(format!(
                "filled: {n} values is out of range (0 to the ceiling of {MAX_FLOATS})"
            ));
        }
        Ok(Floats::new(vec![value; n as usize]))
    }

    /// Numbers from an array of numbers (or `Floats`, as they are).
    #[rhai_fn(return_raw)]
    pub fn floats(values: Numbers) -> Result<Floats, Box<EvalAltResult>> {
        numbers(&values, "floats").map(Floats)
    }

    /// The numbers as an ordinary array (within the engine's array size).
    #[rhai_fn(pure, return_raw)]
    pub fn to_array(
        ctx: NativeCallContext<'_>,
        v: &mut Floats,
    ) -> Result<Array, Box<EvalAltResult>> {
        let max = ctx.engine().max_array_size();
        if max > 0 && v.0.len() > max {
            return err(format!(
                "to_array: {} values are more than the array size limit of {max}",
                v.0.len()
            ));
        }
        Ok(v.0.iter().map(|x| Dynamic::from_float(*x)).collect())
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
    #[rhai_fn(pure)]
    pub fn reversed(v: &mut Floats) -> Floats {
        Floats::new(v.0.iter().rev().copied().collect())
    }

    /// `a` followed by `b`.
    #[rhai_fn(name = "concat", return_raw)]
    pub fn concat_f(a: Numbers, b: Numbers) -> Result<Floats, Box<EvalAltResult>> {
        let (a, b) = (
            numbers(&a, "concat's first")?,
            numbers(&b, "concat's second")?,
        );
        if a.len() + b.len() > MAX_FLOATS {
            return err(format!(
                "concat: {} values are more than the ceiling of {MAX_FLOATS}",
                a.len() + b.len()
            ));
        }
        Ok(Floats::new(a.iter().chain(b.iter()).copied().collect()))
    }
}

/// `+ - * /` between Floats (elementwise, equal lengths) and numbers; unary
/// `-`.
pub(crate) fn register_arithmetic(engine: &mut Engine) {
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
