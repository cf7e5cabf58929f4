//! Verifying a program by replaying it (ARCHITECTURE §1's VERIFY stage).
//!
//! A grinding program moves the wheel's rounding centre in straight lines
//! between blocks. [`SweptWheel`] is the surface the rounding leaves along
//! those moves, in the part's axial section: the envelope of the circle
//! placed along each move densely enough that the discretisation itself is
//! below a stated resolution. [`SweptWheel::deviation`] compares it with the
//! nominal profile and names the block whose move left the largest error.

use crate::math::{positive, Real};
use crate::offset::{CircleEnvelope, Side};
use crate::profile::{Profile, ProfileError};
use serde::{Deserialize, Serialize};

/// The surface left by a wheel's rounding moved in straight lines between
/// centres (mm, axial section).
#[derive(Debug, Clone)]
pub struct SweptWheel {
    envelope: CircleEnvelope,
    /// For each placed circle, the block whose move placed it.
    block_of: Vec<usize>,
    resolution: Real,
}

/// How far a surface strays from the nominal profile over a range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Deviation {
    /// The most material left above the profile (mm, >= 0 where any).
    pub max_above: Real,
    /// Where (z).
    pub above_z: Real,
    /// The deepest cut below the profile (mm, <= 0 where any: a gouge).
    pub max_below: Real,
    /// Where (z).
    pub below_z: Real,
    /// The largest of the two in size (mm).
    pub max_abs: Real,
    /// Where the largest is (z).
    pub at_z: Real,
    /// The block (index from 0) whose move forms the surface there.
    pub block: Option<usize>,
}

impl SweptWheel {
    /// The surface left when the rounding (radius `radius`) moves through
    /// the centres `(z[i], x[i])`, block `i` after block `i - 1`. Circles are
    /// placed along each move at most `sqrt(8 radius resolution)` apart, so
    /// the scallops between them stay below `resolution` (mm).
    ///
    /// # Failures
    /// Fewer than one centre, arrays of different lengths, non-finite
    /// values, a radius or resolution that is not positive, or more than 50
    /// million circles.
    pub fn new(
        z: &[Real],
        x: &[Real],
        radius: Real,
        resolution: Real,
    ) -> Result<Self, ProfileError> {
        positive("wheel rounding radius", radius)?;
        positive("verification resolution", resolution)?;
        crate::math::all_finite("wheel centre z", z)?;
        crate::math::all_finite("wheel centre x", x)?;
        if z.len() != x.len() || z.is_empty() {
            return Err(crate::error::InputError::LengthMismatch {
                what: "wheel centres z and x".into(),
                left: z.len(),
                right: x.len(),
            }
            .into());
        }
        let (cz, cx, block_of) = crate::offset::swept_circles(z, x, radius, resolution)?;
        Ok(Self {
            envelope: CircleEnvelope::new(&cz, &cx, radius, Side::Outside)?,
            block_of,
            resolution,
        })
    }

    /// The surface's x at `z` (infinite where the wheel never reached).
    pub fn eval(&self, z: Real) -> Real {
        self.envelope.eval(z)
    }

    /// The block whose move forms the surface at `z`.
    pub fn block_at(&self, z: Real) -> Option<usize> {
        self.envelope.source_at(z).map(|i| self.block_of[i])
    }

    /// The deviation from `nominal` over `[z_from, z_to]`, sampled at `step`
    /// (and at the nominal's nodes inside the range).
    ///
    /// # Tolerance
    /// The surface is exact to [`Self::new`]'s resolution; between samples a
    /// deviation can peak by at most the surface's and the profile's
    /// curvature times `step^2 / 8`.
    ///
    /// # Failures
    /// A range outside the nominal profile; a step that is not positive;
    /// a place in the range the wheel never reached.
    pub fn deviation(
        &self,
        nominal: &Profile,
        z_from: Real,
        z_to: Real,
        step: Real,
    ) -> Result<Deviation, ProfileError> {
        positive("verification step", step)?;
        let mut zs = crate::profile::uniform_grid(z_from, z_to, step)?;
        zs.extend(
            nominal
                .z()
                .iter()
                .copied()
                .filter(|z| (z_from..=z_to).contains(z)),
        );
        zs.sort_by(Real::total_cmp);
        zs.dedup();
        let surface = self.envelope.eval_many(&zs);
        let profile = nominal.eval_many(&zs)?;
        let mut d = Deviation {
            max_above: Real::NEG_INFINITY,
            above_z: z_from,
            max_below: Real::INFINITY,
            below_z: z_from,
            max_abs: 0.0,
            at_z: z_from,
            block: None,
        };
        for ((&z, &s), &p) in zs.iter().zip(&surface).zip(&profile) {
            if !s.is_finite() {
                return Err(ProfileError::OutsideProfile {
                    what: "the wheel never reached the profile".into(),
                    z,
                    z_min: z_from,
                    z_max: z_to,
                });
            }
            let e = s - p;
            if e > d.max_above {
                (d.max_above, d.above_z) = (e, z);
            }
            if e < d.max_below {
                (d.max_below, d.below_z) = (e, z);
            }
        }
        (d.max_abs, d.at_z) = if d.max_above >= -d.max_below {
            (d.max_above.abs(), d.above_z)
        } else {
            (d.max_below.abs(), d.below_z)
        };
        d.block = self.block_at(d.at_z);
        Ok(d)
    }

    /// The resolution the surface was built to (mm).
    pub fn resolution(&self) -> Real {
        self.resolution
    }
}
