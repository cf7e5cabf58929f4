//! The mandrel's working-part law (docs/math.md §2.1, S000-1, corrected).

use super::{Profile, ProfileError};
use crate::input::InputError;
use crate::math::{finite, positive, Real};
use serde::{Deserialize, Serialize};

/// The diameter law of a cold-pilger mandrel's working part:
///
/// `d(z) = d_min + (d_max - d_min - k L_r) (z / L_r)^n + k z`, `x(z) = d(z) / 2`,
///
/// for `0 <= z <= L_r`. The seed prints the last term as `k z^2`; the
/// linear term is the one that gives `d(L_r) = d_max` (docs/math.md §2.1).
///
/// ```
/// use pilgrim_kernel::MandrelLaw;
/// let law = MandrelLaw::new(40.0, 48.0, 300.0, 0.01, 2.5).unwrap();
/// assert_eq!(law.x(0.0), 20.0);
/// assert!((law.x(300.0) - 24.0).abs() < 1e-12);
/// assert!((law.dx(0.0) - 0.005).abs() < 1e-15); // k / 2
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MandrelLaw {
    /// Diameter at z = 0 (mm).
    pub d_min: Real,
    /// Diameter at z = L_r (mm).
    pub d_max: Real,
    /// Length of the working part (mm).
    pub l_r: Real,
    /// Initial taper: diameter change per mm at z = 0.
    pub k: Real,
    /// Exponent of the law (>= 1).
    pub n: Real,
}

impl MandrelLaw {
    /// A law from its parameters.
    ///
    /// # Failures
    /// Non-finite values; `d_min <= 0`; `d_min > d_max`; `L_r <= 0`;
    /// `n < 1` (the slope would be infinite at z = 0).
    pub fn new(
        d_min: Real,
        d_max: Real,
        l_r: Real,
        k: Real,
        n: Real,
    ) -> Result<Self, ProfileError> {
        positive("mandrel d_min", d_min)?;
        positive("mandrel d_max", d_max)?;
        positive("mandrel L_r", l_r)?;
        finite("mandrel k", k)?;
        positive("mandrel n", n)?;
        if d_min > d_max {
            return Err(InputError::out_of_range(
                "mandrel d_min",
                d_min,
                format!("at most d_max = {d_max}"),
            )
            .into());
        }
        if n < 1.0 {
            return Err(InputError::out_of_range(
                "mandrel n",
                n,
                "at least 1 (for n < 1 the slope is infinite at z = 0)",
            )
            .into());
        }
        Ok(Self {
            d_min,
            d_max,
            l_r,
            k,
            n,
        })
    }

    /// The coefficient `d_max - d_min - k L_r` of the power term.
    fn c(&self) -> Real {
        self.d_max - self.d_min - self.k * self.l_r
    }

    /// Diameter at z (mm).
    pub fn diameter(&self, z: Real) -> Real {
        self.d_min + self.c() * (z / self.l_r).powf(self.n) + self.k * z
    }

    /// Radius `x(z) = d(z) / 2` (mm).
    pub fn x(&self, z: Real) -> Real {
        0.5 * self.diameter(z)
    }

    /// dx/dz at z.
    pub fn dx(&self, z: Real) -> Real {
        let t = if self.n == 1.0 {
            1.0 / self.l_r
        } else {
            self.n * z.powf(self.n - 1.0) / self.l_r.powf(self.n)
        };
        0.5 * (self.c() * t + self.k)
    }

    /// d2x/dz2 at z (infinite at z = 0 when 1 < n < 2 and the power term is not zero).
    pub fn d2x(&self, z: Real) -> Real {
        if self.n == 1.0 || self.c() == 0.0 {
            return 0.0;
        }
        0.5 * self.c() * self.n * (self.n - 1.0) * z.powf(self.n - 2.0) / self.l_r.powf(self.n)
    }

    /// The working part sampled at a uniform step over `[0, L_r]` (the last
    /// step may be shorter), with analytic derivatives; `z_start` shifts it
    /// along the axis.
    ///
    /// # Failures
    /// A step that is not positive, or more than [`super::MAX_NODES`] nodes.
    pub fn profile(&self, step: Real, z_start: Real) -> Result<Profile, ProfileError> {
        let zs = uniform_grid(0.0, self.l_r, step)?;
        let (mut z, mut x, mut d1, mut d2) = (vec![], vec![], vec![], vec![]);
        for t in zs {
            z.push(z_start + t);
            x.push(self.x(t));
            d1.push(self.dx(t));
            d2.push(self.d2x(t));
        }
        Profile::with_derivatives(z, x, d1, d2)
    }
}

/// The grid `a, a + h, a + 2h, ..., b` (the last step may be shorter; at
/// least 3 nodes: a range shorter than two steps is halved).
///
/// # Failures
/// A step that is not positive and finite, or more than [`super::MAX_NODES`] nodes.
pub fn uniform_grid(a: Real, b: Real, step: Real) -> Result<Vec<Real>, ProfileError> {
    positive("grid step", step)?;
    // The small margin keeps a range that is a whole number of steps from
    // getting a sliver of a last step through rounding.
    let count = super::check_node_count(
        "grid step",
        ((b - a) / step - crate::tolerance::COUNT_SLACK).ceil(),
        step,
    )?
    .max(2);
    let h = if count == 2 && 2.0 * step > b - a {
        0.5 * (b - a)
    } else {
        step
    };
    let mut g: Vec<Real> = (0..count).map(|i| a + h * i as Real).collect();
    g.push(b);
    Ok(g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    #[test]
    fn bad_parameters_are_refused() {
        assert!(MandrelLaw::new(50.0, 40.0, 300.0, 0.0, 2.0)
            .unwrap_err()
            .to_string()
            .contains("d_min"));
        assert!(MandrelLaw::new(40.0, 50.0, 0.0, 0.0, 2.0)
            .unwrap_err()
            .to_string()
            .contains("L_r"));
        assert!(MandrelLaw::new(40.0, 50.0, 300.0, 0.0, 0.0)
            .unwrap_err()
            .to_string()
            .contains("mandrel n"));
        assert!(MandrelLaw::new(40.0, 50.0, 300.0, 0.0, 0.5).is_err());
        assert!(MandrelLaw::new(40.0, 50.0, 300.0, f64::NAN, 2.0).is_err());
    }

    #[test]
    fn analytic_derivatives_match_differences() {
        let law = MandrelLaw::new(38.0, 50.0, 320.0, 0.012, 2.7).unwrap();
        let h = 1e-4;
        for z in [1.0, 50.0, 160.0, 319.0] {
            assert_near!(law.dx(z), (law.x(z + h) - law.x(z - h)) / (2.0 * h), 1e-9);
            assert_near!(
                law.d2x(z),
                (law.dx(z + h) - law.dx(z - h)) / (2.0 * h),
                1e-9
            );
        }
        let p = law.profile(0.7, 10.0).unwrap();
        assert_eq!(p.z_range(), (10.0, 330.0));
        assert!(p.has_analytic_derivatives());
    }

    #[test]
    fn grid_ends_exactly() {
        let g = uniform_grid(0.0, 1.0, 0.3).unwrap();
        assert_eq!(g, vec![0.0, 0.3, 0.6, 0.8999999999999999, 1.0]);
        assert_eq!(uniform_grid(0.0, 1.0, 5.0).unwrap(), vec![0.0, 0.5, 1.0]);
        assert_eq!(uniform_grid(0.0, 1.0, 0.5).unwrap(), vec![0.0, 0.5, 1.0]);
    }
}
