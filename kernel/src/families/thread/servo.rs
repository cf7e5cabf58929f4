//! Acceleration and deceleration lengths of a thread block (docs/math.md §4.2):
//! a CNC lathe has no rigid link between spindle and carriage, so the
//! carriage, a first-order servo of time constant `T`, lags its command
//! and the lead is wrong until it catches up.
//!
//! After a step to the velocity `V`, the carriage's speed error is
//! `a = exp(-t / T)` of `V`, reached after the carriage has moved
//! `S = T V (t/T - 1 + exp(-t/T)) = T V (-1 - ln a + a)`: Fanuc's exact
//! form of the approach `S1`; the run-out is the lag `S2 = T V`, over
//! which the carriage decelerates after the command stops.

use crate::math::Real;

/// The approach `S1 = T V (-1 - ln a + a)` (mm) for a lead error ratio `a`
/// (0 < a < 1), servo time constant `t` (s) and feed velocity `v` (mm/s).
pub fn approach_length(t: Real, v: Real, a: Real) -> Real {
    t * v * (-1.0 - a.ln() + a)
}

/// The run-out `S2 = T V` (mm).
pub fn runout_length(t: Real, v: Real) -> Real {
    t * v
}

/// The lead error ratio at the thread's start when the approach is only
/// `length` mm: the `a` whose [`approach_length`] it is (1 for no
/// approach at all).
pub fn approach_error(t: Real, v: Real, length: Real) -> Real {
    let target = length / (t * v);
    if !(target > 0.0) {
        return 1.0;
    }
    // g(a) = -1 - ln a + a falls from +inf at 0 to 0 at 1: bisect on ln a.
    let (mut lo, mut hi) = (-745.0f64, 0.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let a = mid.exp();
        if -1.0 - mid + a > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi)).exp()
}

/// The lead error ratio at the thread's end when the run-out is only
/// `length` mm: the carriage is `S2 - length` into its deceleration there,
/// at `1 - length / S2` of its speed lost.
pub fn runout_error(t: Real, v: Real, length: Real) -> Real {
    (1.0 - length / runout_length(t, v)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// S1 against the exact Fanuc form computed by hand, S2, and the
    /// inverse: lead 31.4159 mm at 100 rpm, T = 0.033 s, a = 0.01.
    #[test]
    fn lengths_and_their_errors() {
        let v = 31.415_926_5 * 100.0 / 60.0; // 52.3599 mm/s
        let s1 = approach_length(0.033, v, 0.01);
        // 0.033 * 52.3599 * (-1 + 4.605170 + 0.01) = 1.727876 * 3.615170
        assert!((s1 - 6.246_56).abs() < 1e-4, "{s1}");
        assert!((runout_length(0.033, v) - 1.727_876).abs() < 1e-5);
        // Without "+ a" (the form often quoted) it would be 0.0173 mm less.
        assert!((s1 - 0.033 * v * (-1.0 - 0.01f64.ln()) - 0.033 * v * 0.01).abs() < 1e-12);
        assert!((approach_error(0.033, v, s1) - 0.01).abs() < 1e-12);
        // Half the approach: a larger error.
        let a = approach_error(0.033, v, s1 / 2.0);
        assert!(a > 0.05 && a < 0.2, "{a}");
        assert!((approach_length(0.033, v, a) - s1 / 2.0).abs() < 1e-9);
        assert_eq!(approach_error(0.033, v, 0.0), 1.0);
        assert!((runout_error(0.033, v, 0.5 * runout_length(0.033, v)) - 0.5).abs() < 1e-12);
        assert_eq!(runout_error(0.033, v, 5.0), 0.0);
    }
}
