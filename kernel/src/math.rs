//! Numeric aliases and small helpers shared by every module.
//!
//! The kernel works in `f64` millimetres and radians (ARCHITECTURE §3).
//! There is no global epsilon: every approximate operation takes its
//! tolerance as an argument and documents what it bounds.

use crate::error::InputError;

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

/// `v` with `decimals` digits after the point, never printing `-0.000`
/// (a value that rounds to zero prints unsigned).
///
/// ```
/// use pilgrim_kernel::math::fixed;
/// assert_eq!(fixed(-0.0004, 3), "0.000");
/// assert_eq!(fixed(-1.2346, 3), "-1.235");
/// ```
pub fn fixed(v: Real, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_owned(),
        _ => s,
    }
}

/// Index of the last element of the sorted slice `xs` that is `<= x`, or
/// `None` when `x < xs[0]`. `xs` must be sorted ascending.
#[inline]
pub fn floor_index(xs: &[Real], x: Real) -> Option<usize> {
    let n = xs.partition_point(|&v| v <= x);
    n.checked_sub(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_index_brackets() {
        let xs = [0.0, 1.0, 2.0];
        assert_eq!(floor_index(&xs, -0.5), None);
        assert_eq!(floor_index(&xs, 0.0), Some(0));
        assert_eq!(floor_index(&xs, 1.5), Some(1));
        assert_eq!(floor_index(&xs, 9.0), Some(2));
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
