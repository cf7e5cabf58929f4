//! A thread's axial section as data: what every profile (ISO metric,
//! trapezoidal, ACME, buttress, the worms) gives the planning and the
//! verification, whatever standard it comes from.
//!
//! The section is a rack along the part's axis: each space (the groove a
//! cutter makes) has two flanks, each at its own angle from the radial
//! direction (a buttress's differ), a width at the pitch diameter, and a
//! root. The flanks are straight (every standard thread, ZA worms), or
//! the curves of a worm's flanks that are straight in another plane (ZN,
//! ZI: [`FlankForm`]), symmetric, their angles those at the pitch
//! diameter. An external thread's space opens outwards, from its root
//! (the minor diameter) to its crest (the major, the blank's); an internal
//! thread's opens inwards, from its root (the major) to its crest (the
//! minor, the bore). Lengths in mm, angles in radians.

use super::wires;
use crate::math::Real;
use crate::profile::FlankForm;
use serde::{Deserialize, Serialize};

/// The way the thread winds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Hand {
    /// Right-handed: advancing along +Z as it turns about +Z.
    #[default]
    Right,
    /// Left-handed.
    Left,
}

impl Hand {
    /// +1 for a right hand, -1 for a left: the sign of the axial advance
    /// per turn about +Z. In the axial section at the part's angle 0,
    /// start `k` of a multi-start thread lies `sign k` pitches along +Z
    /// from start 0 (a right hand's starts follow one another towards
    /// +Z as the start angle grows, a left hand's towards -Z).
    pub fn sign(self) -> Real {
        match self {
            Hand::Right => 1.0,
            Hand::Left => -1.0,
        }
    }

    /// The place, counted in pitches along +Z from start 0 modulo the
    /// starts, of start `k` in the section at angle 0; and, the map being
    /// its own inverse, the start at place `k` (see [`Hand::sign`]).
    pub fn start_place(self, k: i64, starts: u32) -> u32 {
        (self.sign() as i64 * k).rem_euclid(i64::from(starts)) as u32
    }

    /// `right` or `left`, as a message names the hand.
    pub fn name(self) -> &'static str {
        match self {
            Hand::Right => "right",
            Hand::Left => "left",
        }
    }
}

/// A diameter's limits (mm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    /// The least.
    pub min: Real,
    /// The most.
    pub max: Real,
}

impl Limits {
    /// Whether `v` lies within, `slack` either side.
    pub fn holds(&self, v: Real, slack: Real) -> bool {
        v >= self.min - slack && v <= self.max + slack
    }

    /// The width of the band.
    pub fn width(&self) -> Real {
        self.max - self.min
    }

    /// The middle of the band: what a cut aims at.
    pub fn middle(&self) -> Real {
        0.5 * (self.min + self.max)
    }
}

/// What the finished thread must hold, and whose limits they are.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThreadLimits {
    /// The pitch diameter (for a worm: the diameter where its thickness is
    /// measured).
    pub pitch_diameter: Limits,
    /// The crest: an external thread's major diameter, an internal
    /// thread's minor (the blank's or bore's, before the cut).
    pub crest: Limits,
    /// The root the cut makes: an external thread's minor diameter, an
    /// internal thread's major.
    pub root: Limits,
    /// Where the limits come from: a standard's class (`ISO 965-1 6g`) or
    /// `stated` (the user's, or pilgrim's stated default).
    pub source: String,
}

/// A thread as a standard names it: its section and the limits of the
/// finished thread.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThreadProfile {
    /// How the standard names it (`M20x2.5-6g`, `Tr40x7`, `1-5 ACME-2G`).
    pub designation: String,
    /// The standards its form and limits come from.
    pub standard: String,
    /// Its axial section and basic sizes.
    pub section: ThreadSection,
    /// The limits of the finished thread.
    pub limits: ThreadLimits,
}

impl ThreadProfile {
    /// The section a cut aims at: the pitch diameter in the middle of its
    /// limits (the flanks and the root moved with it), the crest (the
    /// blank turned, the bore bored) in the middle of its.
    pub fn aimed(&self) -> ThreadSection {
        ThreadSection {
            crest_diameter: self.limits.crest.middle(),
            ..self.section.aimed(self.limits.pitch_diameter.middle())
        }
    }
}

/// A thread's axial section and basic sizes: see the module's docs. What
/// the planning and the simulation take.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThreadSection {
    /// An internal thread (a nut's, cut inside a bore).
    pub internal: bool,
    /// The axial pitch P between neighbouring threads.
    pub pitch: Real,
    /// The number of starts.
    pub starts: u32,
    /// Right- or left-handed.
    pub hand: Hand,
    /// The basic major diameter (the nominal: d, D).
    pub major: Real,
    /// The basic pitch diameter (d2, D2, E).
    pub pitch_diameter: Real,
    /// The basic diameter of the root the cut makes (external: d3;
    /// internal: the major the nut's root reaches).
    pub root_diameter: Real,
    /// The basic diameter of the crest (external: the major; internal: the
    /// minor, D1).
    pub crest_diameter: Real,
    /// The flanks' angles from the radial direction: the space's flank
    /// towards -Z, then towards +Z (a symmetric thread's are equal, half
    /// its included angle).
    pub flanks: [Real; 2],
    /// The space's width along the axis at the pitch diameter (basic: P/2
    /// for every standard thread, the pitch less the thread's thickness).
    pub space_at_pitch: Real,
    /// The root's rounding (0: a flat root with sharp corners).
    pub root_radius: Real,
    /// How the flanks are generated: straight in this section, or a
    /// worm's curves (ZN, ZI; external, symmetric).
    #[serde(skip_serializing_if = "FlankForm::is_axial")]
    pub form: FlankForm,
}

impl ThreadSection {
    /// The same form cut to the pitch diameter `pitch_diameter` (a
    /// tolerance class's aim, the middle of its band): the flanks moved
    /// radially with it, the root as much deeper or shallower, the crest
    /// (the blank's, the bore's) where it was.
    pub fn aimed(&self, pitch_diameter: Real) -> ThreadSection {
        let shift = pitch_diameter - self.pitch_diameter;
        ThreadSection {
            pitch_diameter,
            root_diameter: self.root_diameter + shift,
            ..self.clone()
        }
    }

    /// The full-profile form cutter ground to this section's curved
    /// flanks ([`crate::tool::ThreadCutter::ground_to`]): at its root, its
    /// corners rounded by `nose_radius`, reaching 2 mm above the crest.
    ///
    /// # Failures
    /// Straight flanks; those of `ground_to`.
    pub fn form_cutter(
        &self,
        nose_radius: Real,
    ) -> Result<crate::tool::ThreadCutter, crate::input::InputError> {
        crate::tool::ThreadCutter::ground_to(
            self.form,
            self.root_diameter / 2.0,
            nose_radius,
            self.depth() + 2.0,
        )
    }

    /// The lead: the starts' pitches.
    pub fn lead(&self) -> Real {
        Real::from(self.starts) * self.pitch
    }

    /// Which way the space opens from its root: +1 outwards (external),
    /// -1 inwards (internal).
    pub fn opening(&self) -> Real {
        if self.internal {
            -1.0
        } else {
            1.0
        }
    }

    /// The thread's depth: root to crest, radially.
    pub fn depth(&self) -> Real {
        (self.crest_diameter - self.root_diameter).abs() / 2.0
    }

    /// Curved flanks' distance from the space's middle at radius `r`:
    /// the form's curve moved radially with the pitch diameter (a section
    /// [`Self::aimed`] deeper is the same form cut deeper); `None` for
    /// straight flanks.
    fn curve_at(&self, r: Real) -> Option<Real> {
        let shift = self.pitch_diameter / 2.0 - self.form.reference()?;
        self.form.half_space(r - shift)
    }

    /// The space's width along the axis at radius `r` (its flanks
    /// extended beyond the root and crest).
    pub fn space_at(&self, r: Real) -> Real {
        match self.curve_at(r) {
            Some(half) => 2.0 * half,
            None => {
                let spread = self.flanks[0].tan() + self.flanks[1].tan();
                self.space_at_pitch + self.opening() * (r - self.pitch_diameter / 2.0) * spread
            }
        }
    }

    /// How far the space reaches at radius `r` from its centre, the middle
    /// of its root (where a radial pass puts the cutter's tip): towards -Z,
    /// then +Z, each flank at its own angle (or on its curve).
    pub fn reach(&self, r: Real) -> [Real; 2] {
        if let Some(half) = self.curve_at(r) {
            return [half; 2];
        }
        let up = self.opening() * (r - self.root_diameter / 2.0);
        [0, 1].map(|k| self.root_space() / 2.0 + up * self.flanks[k].tan())
    }

    /// The space's width at its root (before the root's rounding): the
    /// widest tip a cutter may have.
    pub fn root_space(&self) -> Real {
        self.space_at(self.root_diameter / 2.0)
    }

    /// The space's area in the axial section, root to crest: a trapezoid,
    /// or between curved flanks by Simpson's rule over 256 intervals (the
    /// curves' fourth derivatives are small: well below 1e-9 mm^2).
    pub fn space_area(&self) -> Real {
        let (root, crest) = (self.root_diameter / 2.0, self.crest_diameter / 2.0);
        if self.form.is_axial() {
            return 0.5 * (self.root_space() + self.space_at(crest)) * self.depth();
        }
        let n = 256;
        let h = (crest - root) / n as Real;
        let sum: Real = (0..=n)
            .map(|i| {
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * self.space_at(root + h * i as Real)
            })
            .sum();
        (sum * h / 3.0).abs()
    }

    /// The space's outline in the axial section, its root centred on
    /// `centre` (z): four corners `[z, r]`, root first, the -Z flank's
    /// root corner first (curved flanks by their chords).
    pub fn space_outline(&self, centre: Real) -> [[Real; 2]; 4] {
        let (root, crest) = (self.root_diameter / 2.0, self.crest_diameter / 2.0);
        let (low, high) = (self.reach(root), self.reach(crest));
        [
            [centre - low[0], root],
            [centre + low[1], root],
            [centre + high[1], crest],
            [centre - high[0], crest],
        ]
    }

    /// The measurement over wires (external) or between balls (internal)
    /// of diameter `wire` laid in opposite spaces, the pitch diameter at
    /// `pitch_diameter`: each wire or ball as it rests on the helicoid
    /// ([`wires::resting`], the lead angle included). Straight flanks only
    /// (`None` for curved ones, or where the body misses a flank).
    pub fn over_wires(&self, wire: Real, pitch_diameter: Real) -> Option<Real> {
        if !self.form.is_axial() {
            return None;
        }
        // The flank lines `z = a + b r` of the space centred on z = 0, as
        // wide as `space_at_pitch` at the pitch diameter.
        let (s, r1, half) = (
            self.opening(),
            pitch_diameter / 2.0,
            self.space_at_pitch / 2.0,
        );
        let [t0, t1] = self.flanks.map(Real::tan);
        let left = [-half + s * r1 * t0, -s * t0];
        let right = [half - s * r1 * t1, s * t1];
        self.over_flanks(wire, pitch_diameter, left, right)
    }

    /// The measurement over wires of diameter `wire` laid in spaces whose
    /// flanks are the lines `left` and `right` (`z = a + b r` over this
    /// section's radius), the wires at the lead angle of
    /// `pitch_diameter`. An internal thread's twin, simulated in rho = -r
    /// (its radii negative), gets its measurement between balls negative,
    /// to be turned back with the twin's other diameters.
    pub fn over_flanks(
        &self,
        wire: Real,
        pitch_diameter: Real,
        left: [Real; 2],
        right: [Real; 2],
    ) -> Option<Real> {
        let twin = self.pitch_diameter < 0.0;
        let s: Real = if twin { -1.0 } else { 1.0 };
        let space = wires::Space {
            left: [left[0], s * left[1]],
            right: [right[0], s * right[1]],
            internal: self.internal || twin,
            lead: self.lead(),
        };
        let band = (
            (self.root_diameter / 2.0).abs(),
            (self.crest_diameter / 2.0).abs(),
        );
        wires::resting(&space, wire, pitch_diameter, band).map(|rest| s * rest.m)
    }

    /// The best wire of a straight-flanked profile: the one whose contacts
    /// straddle the pitch line equally ([`wires::best_wire`]; for symmetric
    /// flanks both on it).
    pub fn best_wire(&self) -> Option<Real> {
        self.form
            .is_axial()
            .then(|| wires::best_wire(self.flanks, self.space_at_pitch))
    }
}
