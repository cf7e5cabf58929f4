//! The worm's sizes (docs/math.md §4.1): standard cylindrical-worm practice, not
//! the seed's words (the seed names the inputs only).

use super::standards::StatedLimits;
use super::{Hand, Limits, ThreadLimits, ThreadProfile, ThreadSection};
use crate::input::InputError;
use crate::math::{positive, Real};
use crate::profile::FlankForm;
use serde::Serialize;
use std::f64::consts::PI;

/// A cylindrical worm, its flanks ZA (straight in the axial section), ZN
/// or ZI (DIN 3975: [`FlankForm`]), and the sizes derived from its module,
/// starts and pitch diameter. All lengths in mm, angles in radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WormSizes {
    /// Module m.
    pub module: Real,
    /// Number of starts z1.
    pub starts: u32,
    /// Pitch diameter d1.
    pub pitch_diameter: Real,
    /// Radial clearance factor c*.
    pub clearance: Real,
    /// The profile's angle as its kind gives it: a ZA worm's half-angle in
    /// the axial section, a ZN or ZI worm's normal pressure angle (the
    /// axial one at the pitch diameter is [`Self::axial_alpha`]).
    pub alpha: Real,
    /// The flanks' kind.
    pub profile: WormProfile,
    /// Axial thickness of the thread at the pitch line, S_a1 (in the axial
    /// section the thread is a rack: its chord at the pitch line is its
    /// axial thickness). `p_x / 2` unless thinned for backlash.
    pub thickness: Real,
}

/// A worm's flank kind (DIN 3975).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum WormProfile {
    /// Straight flanks in the axial section.
    #[default]
    ZA,
    /// Straight flanks in the space's normal section.
    ZN,
    /// Involute helicoids.
    ZI,
}

impl WormProfile {
    /// Its name as DIN 3975 writes it: `ZA`, `ZN`, `ZI`.
    pub fn name(self) -> &'static str {
        match self {
            Self::ZA => "ZA",
            Self::ZN => "ZN",
            Self::ZI => "ZI",
        }
    }

    /// The kind named `ZA`, `ZN` or `ZI` (any case).
    ///
    /// # Failures
    /// Any other name.
    pub fn parse(name: &str) -> Result<Self, InputError> {
        match name.to_ascii_uppercase().as_str() {
            "ZA" => Ok(Self::ZA),
            "ZN" => Ok(Self::ZN),
            "ZI" => Ok(Self::ZI),
            _ => Err(InputError::BadText {
                what: "worm profile".into(),
                value: crate::names::quoted(name),
                reason: "is not ZA, ZN or ZI".into(),
            }),
        }
    }
}

impl WormSizes {
    /// The worm of module `m`, `z1` starts, pitch diameter `d1`, clearance
    /// factor `c`, half-angle `alpha` and pitch-line thickness `s_a1`
    /// (`None`: half the axial pitch), its flanks ZA.
    ///
    /// # Failures
    /// A value that is not positive and finite (`c` may be 0); `z1` of 0;
    /// a half-angle beyond 45 degrees; a root at or below the axis; a
    /// thickness that leaves no space between the threads.
    pub fn new(
        m: Real,
        z1: i64,
        d1: Real,
        c: Real,
        alpha: Real,
        s_a1: Option<Real>,
    ) -> Result<Self, InputError> {
        Self::with_profile(m, z1, d1, c, alpha, s_a1, WormProfile::ZA)
    }

    /// The worm of [`Self::new`] with flanks of kind `profile`, `alpha` as
    /// that kind gives it (the normal pressure angle of ZN and ZI).
    ///
    /// # Failures
    /// Those of [`Self::new`]; a ZI worm whose root lies inside its base
    /// cylinder (its flanks would not reach the root).
    pub fn with_profile(
        m: Real,
        z1: i64,
        d1: Real,
        c: Real,
        alpha: Real,
        s_a1: Option<Real>,
        profile: WormProfile,
    ) -> Result<Self, InputError> {
        positive("module m", m)?;
        if z1 <= 0 || z1 > 100 {
            return Err(InputError::out_of_range(
                "number of starts z1",
                z1 as f64,
                "from 1 to 100",
            ));
        }
        positive("pitch diameter d1", d1)?;
        crate::math::finite("clearance factor c*", c)?;
        if !(0.0..=1.0).contains(&c) {
            return Err(InputError::out_of_range(
                "clearance factor c*",
                c,
                "from 0 to 1",
            ));
        }
        positive("profile half-angle", alpha)?;
        if alpha > PI / 4.0 {
            return Err(InputError::out_of_range(
                "profile half-angle (deg)",
                alpha.to_degrees(),
                "at most 45",
            ));
        }
        let mut w = Self {
            module: m,
            starts: z1 as u32,
            pitch_diameter: d1,
            clearance: c,
            alpha,
            profile,
            thickness: PI * m / 2.0,
        };
        if let Some(s) = s_a1 {
            positive("thread thickness S_a1", s)?;
            w.thickness = s;
        }
        if w.root_diameter() <= 0.0 {
            return Err(InputError::out_of_range(
                "pitch diameter d1",
                d1,
                format!(
                    "above 2 (1 + c*) m = {} so that the root stays off the axis",
                    2.0 * (1.0 + c) * m
                ),
            ));
        }
        if let Some(base) = w.section().form.base_radius() {
            if base >= w.root_radius() {
                return Err(InputError::out_of_range(
                    "root diameter d_f1 of the ZI worm",
                    w.root_diameter(),
                    format!(
                        "above its base cylinder's diameter {:.4} (a larger pitch diameter, module or normal angle)",
                        2.0 * base
                    ),
                ));
            }
        }
        if !(w.root_space() > 0.0) {
            return Err(InputError::out_of_range(
                "thread thickness S_a1",
                w.thickness,
                format!(
                    "below {:.4} mm, so that a space remains at the root",
                    w.thickness + w.root_space()
                ),
            ));
        }
        Ok(w)
    }

    /// Axial pitch `p_x = pi m`.
    pub fn axial_pitch(&self) -> Real {
        PI * self.module
    }

    /// Lead `P_z = z1 p_x`.
    pub fn lead(&self) -> Real {
        Real::from(self.starts) * self.axial_pitch()
    }

    /// Thread height `h1 = (2 + c*) m`.
    pub fn height(&self) -> Real {
        (2.0 + self.clearance) * self.module
    }

    /// Tip diameter `d_a1 = d1 + 2 m` (the blank's).
    pub fn tip_diameter(&self) -> Real {
        self.pitch_diameter + 2.0 * self.module
    }

    /// Root diameter `d_f1 = d1 - 2 (1 + c*) m`.
    pub fn root_diameter(&self) -> Real {
        self.pitch_diameter - 2.0 * (1.0 + self.clearance) * self.module
    }

    /// Pitch radius.
    pub fn pitch_radius(&self) -> Real {
        self.pitch_diameter / 2.0
    }

    /// Tip radius.
    pub fn tip_radius(&self) -> Real {
        self.tip_diameter() / 2.0
    }

    /// Root radius.
    pub fn root_radius(&self) -> Real {
        self.root_diameter() / 2.0
    }

    /// Lead angle `gamma = atan(z1 m / d1)`.
    pub fn lead_angle(&self) -> Real {
        (Real::from(self.starts) * self.module / self.pitch_diameter).atan()
    }

    /// Width of the space between threads along the axis at radius `r`:
    /// `p_x - S_a1` at the pitch line; a ZA worm's narrower by `2
    /// tan(alpha)` per mm towards the root, a ZN or ZI worm's on its
    /// flanks' curves ([`ThreadSection::space_at`]).
    pub fn space_at(&self, r: Real) -> Real {
        self.section().space_at(r)
    }

    /// Width of the space at the root: the widest tip a cutter may have.
    pub fn root_space(&self) -> Real {
        self.space_at(self.root_radius())
    }

    /// Area of one thread space in the axial section, between root and
    /// tip.
    pub fn space_area(&self) -> Real {
        self.section().space_area()
    }

    /// The flanks' half-angle in the axial section at the pitch diameter:
    /// a ZA worm's `alpha`; a ZN or ZI worm's from its normal angle and
    /// its flanks' curve.
    pub fn axial_alpha(&self) -> Real {
        self.section().flanks[0]
    }

    /// The flanks' form ([`FlankForm`]): the space's half at the pitch
    /// line, the helical parameter from the lead.
    fn form(&self) -> FlankForm {
        let half = (self.axial_pitch() - self.thickness) / 2.0;
        let p = self.lead() / std::f64::consts::TAU;
        match self.profile {
            WormProfile::ZA => FlankForm::Axial,
            WormProfile::ZN => FlankForm::zn(self.alpha, half, self.pitch_radius(), p),
            WormProfile::ZI => FlankForm::zi(self.alpha, half, self.pitch_radius(), p),
        }
    }

    /// The worm's section as a thread's: the axial pitch `pi m`, the
    /// flanks at the axial angle (a ZN or ZI worm's on their curves), the
    /// space at the pitch diameter the pitch less the thread's thickness
    /// there.
    pub fn section(&self) -> ThreadSection {
        // A ZN form is solved for (Newton's): once here.
        let form = self.form();
        let alpha = form.axial_angle(self.pitch_radius()).unwrap_or(self.alpha);
        ThreadSection {
            internal: false,
            pitch: self.axial_pitch(),
            starts: self.starts,
            hand: Hand::Right,
            major: self.tip_diameter(),
            pitch_diameter: self.pitch_diameter,
            root_diameter: self.root_diameter(),
            crest_diameter: self.tip_diameter(),
            flanks: [alpha; 2],
            space_at_pitch: self.axial_pitch() - self.thickness,
            root_radius: 0.0,
            form,
        }
    }

    /// The worm as a thread profile: its [`Self::section`], its diameters
    /// within `diameter` either side, its pitch diameter (where the
    /// thickness is measured) within the thickness's tolerance `thickness`
    /// over the flanks' spread.
    pub fn profile(&self, diameter: Real, thickness: Real) -> ThreadProfile {
        let band = |v: Real, t: Real| Limits {
            min: v - t,
            max: v + t,
        };
        let number = super::standards::number;
        let section = self.section();
        let alpha = section.flanks[0];
        ThreadProfile {
            designation: format!(
                "{} m{} z{} d{}",
                self.profile.name(),
                number(self.module),
                self.starts,
                number(self.pitch_diameter)
            ),
            standard: match self.profile {
                WormProfile::ZA => "docs/math.md §4.1 (ZA worm)".into(),
                _ => format!("docs/math.md §4.1, DIN 3975 ({} worm)", self.profile.name()),
            },
            section,
            limits: ThreadLimits {
                pitch_diameter: band(self.pitch_diameter, thickness / (2.0 * alpha.tan())),
                crest: band(self.tip_diameter(), diameter),
                root: band(self.root_diameter(), diameter),
                source: "stated".into(),
            },
        }
    }

    /// The worm as the thread family reads it from its designation
    /// (`ZI m5 z2 d50`): its section of `hand`, its diameters within the
    /// drawing's `stated` limits (external), named as read.
    pub fn drawn(&self, hand: Hand, stated: &StatedLimits) -> ThreadProfile {
        let basic = self.profile(0.0, 0.0);
        let mut designation = basic.designation;
        if self.alpha != 20f64.to_radians() {
            designation += &format!(" a{}", super::standards::number(self.alpha.to_degrees()));
        }
        if hand == Hand::Left {
            designation += "-LH";
        }
        ThreadProfile {
            designation,
            section: ThreadSection {
                hand,
                ..basic.section
            },
            limits: stated.limits(
                false,
                self.pitch_diameter,
                self.tip_diameter(),
                self.root_diameter(),
            ),
            ..basic
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// m = 5, z1 = 2, d1 = 50, c* = 0.2, alpha = 20 deg, computed by hand.
    #[test]
    fn sizes_of_a_two_start_module_5_worm() {
        let w = WormSizes::new(5.0, 2, 50.0, 0.2, 20f64.to_radians(), None).unwrap();
        assert!((w.axial_pitch() - 15.707_963).abs() < 1e-6);
        assert!((w.lead() - 31.415_927).abs() < 1e-6);
        assert!((w.height() - 11.0).abs() < 1e-12);
        assert!((w.tip_diameter() - 60.0).abs() < 1e-12);
        assert!((w.root_diameter() - 38.0).abs() < 1e-12);
        assert!((w.thickness - 7.853_982).abs() < 1e-6);
        // gamma = atan(10 / 50) = 11.3099 deg.
        assert!((w.lead_angle().to_degrees() - 11.309_932).abs() < 1e-6);
        // Space at the root: 7.853982 - 2 * 6 * tan 20 = 7.853982 - 4.367643.
        assert!((w.root_space() - 3.486_339).abs() < 1e-6);
        // At the tip: 7.853982 + 2 * 5 * tan 20 = 7.853982 + 3.639702.
        assert!((w.space_at(30.0) - 11.493_684).abs() < 1e-6);
        assert!((w.space_area() - 82.390_125).abs() < 1e-5);
    }

    #[test]
    fn bad_sizes_are_named() {
        let a = 20f64.to_radians();
        let e = WormSizes::new(5.0, 0, 50.0, 0.2, a, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("z1"), "{e}");
        let e = WormSizes::new(-1.0, 1, 50.0, 0.2, a, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("module m"), "{e}");
        let e = WormSizes::new(5.0, 1, 10.0, 0.2, a, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("pitch diameter d1"), "{e}");
        let e = WormSizes::new(5.0, 1, 50.0, 0.2, a, Some(15.0))
            .unwrap_err()
            .to_string();
        assert!(e.contains("S_a1"), "{e}");
    }

    /// The worm's sizes and its profile as a thread agree: the space at
    /// every radius, at the root, its area, lead and depth.
    #[test]
    fn a_worms_profile_is_its_sizes() {
        let w = WormSizes::new(5.0, 2, 50.0, 0.2, 20.0_f64.to_radians(), None).unwrap();
        let t = w.profile(0.05, 0.02);
        let near = |a: Real, b: Real| assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        for r in [w.root_radius(), 22.0, w.pitch_radius(), w.tip_radius()] {
            near(t.section.space_at(r), w.space_at(r));
        }
        near(t.section.root_space(), w.root_space());
        near(t.section.space_area(), w.space_area());
        near(t.section.lead(), w.lead());
        near(t.section.depth(), w.height());
    }

    /// A ZN or ZI worm: its section's space the pitch less the thickness
    /// at the pitch line, as a ZA worm's; its axial angle there from the
    /// normal angle (ZI: DIN 3975's `tan alpha_x = tan alpha_n / cos
    /// gamma`); named by its kind. A ZI worm whose root lies inside its
    /// base cylinder, and an unknown kind, are refused by name.
    #[test]
    fn zn_and_zi_worms_are_sized_from_their_normal_angle() {
        let a = 20f64.to_radians();
        for profile in [WormProfile::ZN, WormProfile::ZI] {
            let w = WormSizes::with_profile(5.0, 2, 50.0, 0.2, a, None, profile).unwrap();
            let t = w.section();
            assert!((t.space_at(25.0) - (w.axial_pitch() - w.thickness)).abs() < 1e-12);
            assert!(w
                .profile(0.05, 0.02)
                .designation
                .starts_with(profile.name()));
            assert!((w.height() - 11.0).abs() < 1e-12);
        }
        let zi = WormSizes::with_profile(5.0, 2, 50.0, 0.2, a, None, WormProfile::ZI).unwrap();
        let want = (a.tan() / zi.lead_angle().cos()).atan();
        assert!((zi.axial_alpha() - want).abs() < 1e-12);
        // m 5, one start, d1 20: r_b = 5.55 mm, the root 4.
        let e = WormSizes::with_profile(5.0, 1, 20.0, 0.2, a, None, WormProfile::ZI)
            .unwrap_err()
            .to_string();
        assert!(e.contains("root diameter d_f1 of the ZI worm = 8"), "{e}");
        assert!(e.contains("base cylinder"), "{e}");
        let e = WormProfile::parse("ZK").unwrap_err().to_string();
        assert!(e.contains("\"ZK\" is not ZA, ZN or ZI"), "{e}");
        assert_eq!(WormProfile::parse("zi").unwrap(), WormProfile::ZI);
    }
}
