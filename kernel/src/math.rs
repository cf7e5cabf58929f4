//! Numeric aliases and small helpers shared by every module.
//!
//! The kernel works in `f64` millimetres and radians (docs/architecture.md, conventions).
//! There is no global epsilon: every approximate operation takes its
//! tolerance as an argument and documents what it bounds.

use crate::input::InputError;

/// The scalar type of the kernel.
pub type Real = f64;
/// A 3-D vector (mm, or unitless for directions).
pub type Vec3 = nalgebra::Vector3<Real>;
/// A 3-D point (mm).
pub type Point3 = nalgebra::Point3<Real>;
/// A homogeneous 4x4 matrix acting on column vectors `(x, y, z, 1)`.
pub type Mat4 = nalgebra::Matrix4<Real>;
/// A 3x3 matrix (the rotation block of a [`Mat4`]).
pub type Mat3 = nalgebra::Matrix3<Real>;

/// Asserts that two reals (or two slices/vectors via their iterators) differ
/// by at most `tol`, printing both values and the difference on failure.
///
/// ```
/// pilgrim_kernel::assert_near!(1.0, 1.0 + 1e-12, 1e-9);
/// ```
#[macro_export]
macro_rules! assert_near {
    ($a:expr, $b:expr, $tol:expr $(,)?) => {{
        let (a, b, tol): (f64, f64, f64) = ($a, $b, $tol);
        assert!(
            (a - b).abs() <= tol,
            "assert_near failed: {} = {a}, {} = {b}, |diff| = {:e} > {tol:e}",
            stringify!($a),
            stringify!($b),
            (a - b).abs()
        );
    }};
    ($a:expr, $b:expr, $tol:expr, $($msg:tt)+) => {{
        let (a, b, tol): (f64, f64, f64) = ($a, $b, $tol);
        assert!(
            (a - b).abs() <= tol,
            "assert_near failed ({}): {a} vs {b}, |diff| = {:e} > {tol:e}",
            format!($($msg)+),
            (a - b).abs()
        );
    }};
}

/// Checks that `value` is finite, naming it `what` in the error.
pub fn finite(what: &str, value: Real) -> Result<Real, InputError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(InputError::NonFinite {
            what: what.to_owned(),
            index: None,
            value,
        })
    }
}

/// Checks that `value` is finite and strictly positive, naming it `what`.
pub fn positive(what: &str, value: Real) -> Result<Real, InputError> {
    finite(what, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(InputError::NotPositive {
            what: what.to_owned(),
            value,
        })
    }
}

/// Checks that every value of `values` is finite; the error names `what` and
/// the index of the first offending value.
pub fn all_finite(what: &str, values: &[Real]) -> Result<(), InputError> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(InputError::NonFinite {
            what: what.to_owned(),
            index: Some(i),
            value: values[i],
        }),
    }
}

/// `v` as a message shows a number from outside: as written in plain
/// decimals where that is short (1e-4 <= |v| < 1e15, and 0), in exponent
/// form beyond (`1e308`, not 309 digits), so that a value typed by a user
/// cannot swamp the message that names it.
pub fn shown(v: Real) -> String {
    /// The smallest size shown in plain decimals (four zeros after the
    /// point at most).
    const PLAIN_FROM: Real = 1e-4;
    /// The size from which a number is shown in exponent form.
    const PLAIN_TO: Real = 1e15;
    if v == 0.0 || !v.is_finite() || (PLAIN_FROM..PLAIN_TO).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `v` with `decimals` digits after the point, never printing `-0.000`
/// (a value that rounds to zero prints unsigned).
///
/// ```
/// use pilgrim_kernel::math::fixed;
/// assert_eq!(fixed(-0.0004, 3), "0.000");
/// assert_eq!(fixed(-1.2346, 3), "-1.235");
/// ```
///
/// The digits are those of `format!("{v:.decimals$}")` (the exact binary
/// value rounded half to even), found by integer arithmetic where the
/// value scaled by `10^decimals` fits 128 bits (up to 9 decimals, about
/// 1e15 at most): a program's 52k blocks print each of their values with
/// it, and the formatter's exact mode costs several times more.
pub fn fixed(v: Real, decimals: usize) -> String {
    match scaled_exactly(v, decimals) {
        Some((negative, q)) => {
            let mut s = String::with_capacity(24);
            if negative && q != 0 {
                s.push('-');
            }
            let unit = 10u128.pow(decimals as u32);
            s.push_str(&(q / unit).to_string());
            if decimals > 0 {
                let frac = (q % unit).to_string();
                s.push('.');
                s.extend(std::iter::repeat_n('0', decimals - frac.len()));
                s.push_str(&frac);
            }
            s
        }
        None => {
            let s = format!("{v:.decimals$}");
            match s.strip_prefix('-') {
                Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_owned(),
                _ => s,
            }
        }
    }
}

/// `|v| 10^decimals` rounded half to even, exactly, with `v`'s sign:
/// `None` for more than 9 decimals, a value not finite, or one too large
/// for 128 bits.
fn scaled_exactly(v: Real, decimals: usize) -> Option<(bool, u128)> {
    if decimals > 9 || !v.is_finite() {
        return None;
    }
    let bits = v.to_bits();
    let negative = bits >> 63 == 1;
    let exponent = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    // v = m 2^e exactly.
    let (m, e) = if exponent == 0 {
        (fraction, -1074)
    } else {
        (fraction | 1u64 << 52, exponent - 1075)
    };
    // Below 2^83: m < 2^53, 10^9 < 2^30.
    let n = u128::from(m) * 10u128.pow(decimals as u32);
    if e >= 0 {
        // Up to 2^123.
        return (e <= 40).then(|| (negative, n << e));
    }
    let shift = e.unsigned_abs();
    if shift >= 128 {
        // Less than 2^-45: rounds to zero.
        return Some((negative, 0));
    }
    let q = n >> shift;
    let rest = n & ((1u128 << shift) - 1);
    let half = 1u128 << (shift - 1);
    let up = rest > half || (rest == half && q & 1 == 1);
    Some((negative, q + u128::from(up)))
}

/// Sine and cosine of `x` together, sharing one argument reduction.
///
/// For `|x| < 1e5` rad the reduction to `[-pi/4, pi/4]` uses pi/2 in three
/// parts (Cody and Waite) and the polynomials are fdlibm's `__kernel_sin` and
/// `__kernel_cos`: the result is within about one unit in the last place,
/// like the system's, at about a third of the cost of calling `sin` and `cos`
/// separately (chain evaluation calls this for every rotation of every
/// pose). Larger or non-finite arguments go to `f64::sin_cos`.
///
/// ```
/// let (s, c) = pilgrim_kernel::math::sin_cos(1.0);
/// assert!((s - 1.0_f64.sin()).abs() <= 2e-16 && (c - 1.0_f64.cos()).abs() <= 2e-16);
/// ```
#[inline]
pub fn sin_cos(x: Real) -> (Real, Real) {
    if x.is_nan() || x.abs() >= 1e5 {
        return x.sin_cos();
    }
    let (sin, cos, n) = kernel_sin_cos(x);
    match n & 3 {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

/// Reduces `|x| < 1e5` to `r` in `[-pi/4, pi/4]` with `x = n pi/2 + r`, and
/// returns `(sin r, cos r, n mod 4)`.
// fdlibm's constants, kept digit for digit as published.
#[allow(clippy::excessive_precision)]
#[inline(always)]
fn kernel_sin_cos(x: Real) -> (Real, Real, i64) {
    const INV_PIO2: Real = std::f64::consts::FRAC_2_PI;
    const PIO2_1: Real = 1.570_796_326_734_125_614_17; // first 33 bits of pi/2
    const PIO2_1T: Real = 6.077_100_506_506_192_249_32e-11; // pi/2 - PIO2_1
    const S1: Real = -1.666_666_666_666_663_243_48e-1;
    const S2: Real = 8.333_333_333_322_489_461_24e-3;
    const S3: Real = -1.984_126_982_985_794_931_34e-4;
    const S4: Real = 2.755_731_370_707_006_767_89e-6;
    const S5: Real = -2.505_076_025_340_686_341_95e-8;
    const S6: Real = 1.589_690_995_211_550_102_21e-10;
    const C1: Real = 4.166_666_666_666_660_190_37e-2;
    const C2: Real = -1.388_888_888_887_410_957_49e-3;
    const C3: Real = 2.480_158_728_947_672_941_78e-5;
    const C4: Real = -2.755_731_435_139_066_330_35e-7;
    const C5: Real = 2.087_572_321_298_174_827_90e-9;
    const C6: Real = -1.135_964_755_778_819_482_65e-11;
    // x = n pi/2 + (y0 + y1), |y0| <= pi/4; n pi/2's first part is exact
    // because n has at most 17 bits and PIO2_1 33.
    // Round to nearest without a libm call: adding 1.5 * 2^52 leaves no
    // fraction bits (|x * 2/pi| < 2^51 here).
    const ROUND: Real = 6_755_399_441_055_744.0;
    let n = (x * INV_PIO2 + ROUND) - ROUND;
    let r = x - n * PIO2_1;
    let w = n * PIO2_1T;
    let y0 = r - w;
    let y1 = (r - y0) - w;
    let z = y0 * y0;
    let v = z * y0;
    let rs = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    let sin = y0 - ((z * (0.5 * y1 - v * rs) - y1) - v * S1);
    let rc = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let cos = w + (((1.0 - w) - hz) + (z * rc - y0 * y1));
    (sin, cos, (n as i64) & 3)
}

/// [`sin_cos`] of four values at once, written so that the lanes run side by
/// side (no branch inside the arithmetic); lanes outside `|x| < 1e5` go to
/// [`sin_cos`] one by one. Same results as [`sin_cos`].
#[inline]
pub fn sin_cos4(x: [Real; 4]) -> ([Real; 4], [Real; 4]) {
    if !x.iter().all(|v| v.abs() < 1e5) {
        let mut s = [0.0; 4];
        let mut c = [0.0; 4];
        for l in 0..4 {
            (s[l], c[l]) = sin_cos(x[l]);
        }
        return (s, c);
    }
    let mut s = [0.0; 4];
    let mut c = [0.0; 4];
    for l in 0..4 {
        let (ks, kc, n) = kernel_sin_cos(x[l]);
        // Quadrant n: swap sine and cosine on odd n (a select, exact);
        // signs from its bits.
        let odd = n & 1 == 1;
        let sign_s = 1.0 - 2.0 * ((n >> 1) & 1) as Real;
        let sign_c = 1.0 - 2.0 * (((n + 1) >> 1) & 1) as Real;
        s[l] = if odd { kc } else { ks } * sign_s;
        c[l] = if odd { ks } else { kc } * sign_c;
    }
    (s, c)
}

/// Where `f` is least over `[lo, hi]`, `f` having one valley there (a
/// convex function, the most of lines): by thirds, `steps` times, each
/// keeping two thirds of the bracket (100 take a bracket of a metre below
/// 1e-14 mm). Written here rather than taken from an optimisation crate:
/// the callers' functions are cheap and bounded, and a dozen lines keep
/// the search's every step in view.
pub fn least_by_thirds(lo: Real, hi: Real, steps: usize, f: impl Fn(Real) -> Real) -> Real {
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..steps {
        let (a, b) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if f(a) < f(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    0.5 * (lo + hi)
}

/// Index of the last element of the sorted slice `xs` that is `<= x`, or
/// `None` when `x < xs[0]`. `xs` must be sorted ascending.
#[inline]
pub fn floor_index(xs: &[Real], x: Real) -> Option<usize> {
    let n = xs.partition_point(|&v| v <= x);
    n.checked_sub(1)
}

/// The angle `t` (rad) in `(-pi, pi]`.
pub fn wrap_angle(t: Real) -> Real {
    let w = t.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

/// Simpson's rule over `samples` of a function at an even number of equal
/// steps `h` (an odd number of samples): exact for cubics. The tests' oracle
/// for volumes and areas.
///
/// # Panics
/// An even number of samples (or fewer than three): a caller's mistake.
pub fn simpson(samples: &[Real], h: Real) -> Real {
    let m = samples.len().saturating_sub(1);
    assert!(
        m >= 2 && m.is_multiple_of(2),
        "Simpson needs an even number of steps, not {m}"
    );
    let inner: Real = samples[1..m]
        .iter()
        .enumerate()
        .map(|(k, y)| if k % 2 == 0 { 4.0 * y } else { 2.0 * y })
        .sum();
    (samples[0] + inner + samples[m]) * h / 3.0
}

#[cfg(test)]
mod tests {
    /// A number from outside is shown short: plain where that is short, in
    /// exponent form beyond.
    #[test]
    fn numbers_are_shown_short() {
        use super::shown;
        assert_eq!(shown(0.001), "0.001");
        assert_eq!(shown(-25.5), "-25.5");
        assert_eq!(shown(0.0), "0");
        assert_eq!(shown(1e308), "1e308");
        assert_eq!(shown(-2.5e-7), "-2.5e-7");
        assert!(shown(f64::MAX).len() < 30);
    }

    /// Simpson is exact for a cubic: int of x^3 - x over [0, 2] = 2.
    #[test]
    fn simpson_is_exact_for_cubics() {
        let ys: Vec<super::Real> = (0..=4)
            .map(|k| {
                let x = 0.5 * k as super::Real;
                x * x * x - x
            })
            .collect();
        assert!((super::simpson(&ys, 0.5) - 2.0).abs() < 1e-14);
    }

    use super::*;

    /// The integer formatting of a fixed number prints what the
    /// formatter's exact mode prints: random values of every magnitude a
    /// program holds, ties at every decimal, subnormals, huge values.
    #[test]
    fn fixed_prints_what_the_formatter_prints() {
        let reference = |v: Real, d: usize| {
            let s = format!("{v:.d$}");
            match s.strip_prefix('-') {
                Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_owned(),
                _ => s,
            }
        };
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            1.5,
            2.5,
            -2.5,
            0.125,
            0.375,
            -0.125,
            1e-300,
            5e-324,
            1e15,
            1e20,
            -1e30,
            123456.0005,
            0.0004,
            -0.0004,
            999.9995,
            1.0 / 3.0,
        ];
        for _ in 0..200_000 {
            let r = next();
            // A magnitude from 1e-6 to 1e7, a sign, a mantissa.
            let mag = 10f64.powi((r % 14) as i32 - 6);
            let x = (next() >> 11) as Real / (1u64 << 53) as Real;
            values.push(if r & 1 << 40 == 0 { mag * x } else { -mag * x });
            // Exact ties: k / 2^j, j small.
            values.push((next() % 100_000) as Real / (1u64 << (next() % 12)) as Real);
        }
        for &v in &values {
            for d in 0..=10 {
                assert_eq!(fixed(v, d), reference(v, d), "{v:e} at {d} decimals");
            }
        }
    }

    #[test]
    fn floor_index_brackets() {
        let xs = [0.0, 1.0, 2.0];
        assert_eq!(floor_index(&xs, -0.5), None);
        assert_eq!(floor_index(&xs, 0.0), Some(0));
        assert_eq!(floor_index(&xs, 1.5), Some(1));
        assert_eq!(floor_index(&xs, 9.0), Some(2));
    }

    #[test]
    fn sin_cos_agrees_with_the_system_to_an_ulp() {
        let mut worst: f64 = 0.0;
        let mut x = -1e5 + 0.123;
        while x < 1e5 {
            for v in [x, x * 1e-3, x * 1e-7] {
                let (s, c) = sin_cos(v);
                worst = worst.max((s - v.sin()).abs()).max((c - v.cos()).abs());
            }
            x += 0.777;
        }
        assert!(worst <= 3e-16, "{worst:e}");
        // The four-lane form gives the same bits.
        let mut x = -1e5 + 0.5;
        while x < 1e5 {
            let v = [x, -x * 0.37, x * 1e-4, 2.0 * x];
            let (s4, c4) = sin_cos4(v);
            for l in 0..4 {
                assert_eq!((s4[l], c4[l]), sin_cos(v[l]), "{}", v[l]);
            }
            x += 3.3;
        }
        let (s4, _) = sin_cos4([1.0, 2e5, f64::NAN, 3.0]);
        assert_eq!(s4[1], 2e5_f64.sin());
        assert!(s4[2].is_nan());
        for v in [
            0.0,
            -0.0,
            1e-300,
            std::f64::consts::FRAC_PI_4,
            1e6,
            1e300,
            f64::NAN,
            f64::INFINITY,
        ] {
            let (s, c) = sin_cos(v);
            let (es, ec) = v.sin_cos();
            assert!(
                (s - es).abs() <= 3e-16 || (s.is_nan() && es.is_nan()),
                "{v}"
            );
            assert!(
                (c - ec).abs() <= 3e-16 || (c.is_nan() && ec.is_nan()),
                "{v}"
            );
        }
    }

    #[test]
    fn checks_name_the_value() {
        let e = positive("wheel radius", -2.0).unwrap_err();
        assert!(e.to_string().contains("wheel radius"), "{e}");
        assert!(e.to_string().contains("-2"), "{e}");
        let e = all_finite("x", &[1.0, f64::NAN]).unwrap_err();
        assert!(e.to_string().contains("x[1]"), "{e}");
    }
}
