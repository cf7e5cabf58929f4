//! Three-point smoothing of a table's derivative (docs/math.md §3.2, S001-1).

use super::{Profile, ProfileError};
use crate::input::InputError;
use crate::math::Real;
use serde::{Deserialize, Serialize};

/// The result of [`Profile::smooth_derivative`]: the rebuilt profile and
/// what smoothing did to it, so that it is never applied silently.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Smoothing {
    /// The rebuilt profile (same z, anchor node unchanged).
    pub profile: Profile,
    /// First divided differences before smoothing (one per interval).
    pub d1_before: Vec<Real>,
    /// First divided differences after smoothing.
    pub d1_after: Vec<Real>,
    /// Second divided differences before (one per interior node).
    pub d2_before: Vec<Real>,
    /// Second divided differences after.
    pub d2_after: Vec<Real>,
    /// The change of x at every node (after minus before, mm).
    pub change: Vec<Real>,
    /// The largest change of x the smoothing made (mm).
    pub max_change: Real,
    /// The z where that change is.
    pub max_change_z: Real,
}

impl Profile {
    /// Smooths the first divided differences `a_i` by the three-point rule
    /// `a'_i = (a_{i-1} + 2 a_i + a_{i+1}) / 4`, `iterations` times (the seed
    /// uses 5; the end values use themselves as their missing neighbour),
    /// then rebuilds x by summing the smoothed differences outward from the
    /// node `anchor`, whose value is kept.
    ///
    /// ```
    /// use pilgrim_kernel::Profile;
    /// let p = Profile::new(vec![0.0, 1.0, 2.0, 3.0, 4.0], vec![0.0, 0.0, 1.0, 1.0, 1.0]).unwrap();
    /// let s = p.smooth_derivative(5, 2).unwrap();
    /// assert_eq!(s.profile.x()[2], 1.0); // the anchor stays
    /// assert!(s.max_change > 0.0);
    /// ```
    ///
    /// # Failures
    /// An anchor beyond the last node.
    pub fn smooth_derivative(
        &self,
        iterations: usize,
        anchor: usize,
    ) -> Result<Smoothing, ProfileError> {
        self.smooth_derivative_holding(iterations, anchor, None)
    }

    /// [`Self::smooth_derivative`] holding the nodes `held` (first and
    /// last, from 0) exactly: the differences between them keep their
    /// values through every iteration and are the fixed neighbours the
    /// rule blends into at the section's ends, so the smoothed slope meets
    /// the held one there; the anchor, inside the section, keeps its
    /// value, and so every node of the section does. A groove's sizing
    /// section sets the tube's finished size and must not move (docs/math.md §3.2).
    ///
    /// ```
    /// use pilgrim_kernel::Profile;
    /// let z: Vec<f64> = (0..9).map(|i| i as f64).collect();
    /// let x = vec![4.0, 3.0, 2.0, 1.0, 1.0, 1.0, 1.0, 2.0, 3.0];
    /// let p = Profile::new(z, x.clone()).unwrap();
    /// let s = p.smooth_derivative_holding(5, 4, Some((3, 6))).unwrap();
    /// assert_eq!(&s.profile.x()[3..=6], &x[3..=6]);
    /// ```
    ///
    /// # Failures
    /// An anchor beyond the last node, a held section beyond the nodes or
    /// of one node, an anchor outside the held section.
    pub fn smooth_derivative_holding(
        &self,
        iterations: usize,
        anchor: usize,
        held: Option<(usize, usize)>,
    ) -> Result<Smoothing, ProfileError> {
        if let Some((first, last)) = held {
            if !(first < last && last < self.len()) {
                return Err(InputError::out_of_range(
                    "the held section's last node",
                    last as Real,
                    format!("after its first, {first}, and at most {}", self.len() - 1),
                )
                .into());
            }
            if !(first..=last).contains(&anchor) {
                return Err(InputError::out_of_range(
                    "smoothing anchor node",
                    anchor as Real,
                    format!("inside the held section, nodes {first}..{last}"),
                )
                .into());
            }
        }
        if anchor >= self.len() {
            return Err(InputError::out_of_range(
                "smoothing anchor node",
                anchor as Real,
                format!("0..{}", self.len() - 1),
            )
            .into());
        }
        let d1_before = self.divided_differences();
        let mut a = d1_before.clone();
        let mut next = a.clone();
        let m = a.len();
        let fixed = |i: usize| held.is_some_and(|(first, last)| (first..last).contains(&i));
        for _ in 0..iterations {
            for i in 0..m {
                if fixed(i) {
                    next[i] = a[i];
                    continue;
                }
                let left = a[i.saturating_sub(1)];
                let right = a[(i + 1).min(m - 1)];
                next[i] = 0.25 * (left + 2.0 * a[i] + right);
            }
            std::mem::swap(&mut a, &mut next);
        }
        let z = self.z();
        let mut x = vec![0.0; self.len()];
        x[anchor] = self.x()[anchor];
        for i in anchor..self.len() - 1 {
            x[i + 1] = x[i] + a[i] * (z[i + 1] - z[i]);
        }
        for i in (0..anchor).rev() {
            x[i] = x[i + 1] - a[i] * (z[i + 1] - z[i]);
        }
        let profile = Profile::new(z.to_vec(), x)?.with_interpolation(self.interpolation());
        let change: Vec<Real> = profile
            .x()
            .iter()
            .zip(self.x())
            .map(|(a, b)| a - b)
            .collect();
        let (max_change, at) = change
            .iter()
            .enumerate()
            .map(|(i, c)| (c.abs(), i))
            .fold((0.0, anchor), |best, c| if c.0 > best.0 { c } else { best });
        Ok(Smoothing {
            d2_before: self.second_divided_differences(),
            d2_after: profile.second_divided_differences(),
            d1_before,
            d1_after: a,
            change,
            max_change,
            max_change_z: z[at],
            profile,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    #[test]
    fn smoothing_leaves_a_parabola_inside_and_removes_kinks() {
        // A parabola's divided differences are linear: the rule keeps them
        // away from the ends, so the rebuilt curve only moves near the ends.
        let z: Vec<Real> = (0..50).map(|i| i as Real).collect();
        let x: Vec<Real> = z.iter().map(|z| 0.01 * z * z).collect();
        let p = Profile::new(z.clone(), x.clone()).unwrap();
        let s = p.smooth_derivative(5, 25).unwrap();
        for i in 6..44 {
            assert_near!(s.d1_after[i], s.d1_before[i], 1e-12);
        }
        assert_near!(s.profile.x()[25], x[25], 0.0);

        // A kink (a jump of the slope) becomes a smooth bend: the largest
        // |second difference| falls, sign changes vanish.
        let xk: Vec<Real> = z
            .iter()
            .map(|&z| if z < 25.0 { 0.0 } else { 0.5 * (z - 25.0) })
            .collect();
        let p = Profile::new(z, xk).unwrap();
        let s = p.smooth_derivative(5, 10).unwrap();
        let peak = |v: &[Real]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(peak(&s.d2_after) < 0.25 * peak(&s.d2_before));
        assert!(s.d2_after.iter().all(|&d| d >= -1e-12));
        assert!(s.max_change > 0.0 && s.max_change < 1.0, "{}", s.max_change);
        assert!(p.smooth_derivative(1, 50).is_err());
    }
}
