//! What a thread's verification is asked: the thread, its starts and
//! length, the tolerances it is held to.

use super::mirrored_limits;
use crate::families::thread::{ThreadSection, WormSizes};
use crate::math::Real;
use serde::{Deserialize, Serialize};

/// What the finished worm must hold.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ThreadTolerances {
    /// Flank form and any cut beyond the nominal (mm, normal to the flank).
    pub form: Real,
    /// Axial thickness at the pitch line (mm).
    pub thickness: Real,
    /// Root and tip diameters (mm).
    pub diameter: Real,
    /// Each start's place along the axis, and the lead's error over the
    /// thread's length (mm).
    pub position: Real,
    /// Flank angles (rad).
    pub flank_angle: Real,
    /// The lead's error allowed where each pass's cutting edges meet the
    /// worm's face and leave its far end, as a ratio of the lead (docs/math.md
    /// §4.2's `a`).
    pub lead: Real,
}

/// The lead's usual allowed error at a thread's ends, as a ratio (Fanuc's
/// practice, docs/math.md §4.2): the default of [`ThreadTolerances::lead`].
pub const LEAD_ERROR: Real = 0.01;

/// What the family asks the simulation to check.
#[derive(Debug, Clone, PartialEq)]
pub struct ThreadRequest {
    /// The thread's section, external or internal.
    pub section: ThreadSection,
    /// How far inside the root and the crest the flanks are measured (mm,
    /// beside the cutter's nose radius at the root).
    pub flank_margin: Real,
    /// The thread's length: from z = 0 to z = -length (mm).
    pub length: Real,
    /// Where start 0's space is centred in the section at part angle 0
    /// (z, mm; any z the same modulo the lead).
    pub space_centre: Real,
    /// The tolerances.
    pub tolerances: ThreadTolerances,
    /// A standard's limits the finished thread must hold besides: each
    /// start's pitch diameter within `pitch_diameter` (`None`: the
    /// tolerances alone).
    pub limits: Option<crate::families::thread::ThreadLimits>,
    /// The finished part's name: its solid's files (`worm.stl`).
    pub part: &'static str,
    /// An internal thread's part, a nut: its outside diameter (mm). `None`
    /// for an external thread, whose part is solid to its axis.
    pub outside_diameter: Option<Real>,
    /// A measured part's correction of each start's pitch diameter (mm;
    /// `pilgrim compensate`): start k's aimed space moved radially by half
    /// of it. Empty: none.
    pub pitch_shift: Vec<Real>,
    /// A measured part's correction of each start's place along the axis
    /// (mm, + towards +Z; `pilgrim compensate`): start k's aimed space
    /// moved by it, as its passes are. Empty: none.
    pub place_shift: Vec<Real>,
}

impl ThreadRequest {
    /// The request for the worm `sizes`: its section, the flanks measured
    /// a tenth of the module inside the root and the tip.
    pub fn worm(
        sizes: &WormSizes,
        length: Real,
        space_centre: Real,
        tolerances: ThreadTolerances,
    ) -> Self {
        Self {
            section: sizes.section(),
            flank_margin: 0.1 * sizes.module,
            length,
            space_centre,
            tolerances,
            limits: None,
            part: "worm",
            outside_diameter: None,
            pitch_shift: Vec::new(),
            place_shift: Vec::new(),
        }
    }
}

impl ThreadRequest {
    /// An internal thread's external twin in rho = -r: the section's
    /// diameters and the limits negated. An internal thread's space opens
    /// inwards from its root (the major) to its crest (the bore); in rho
    /// it opens outwards from the root's rho to the crest's, as an
    /// external thread's does, its flanks along the axis unchanged. So
    /// the simulation, written for external threads, cuts it as it is:
    /// the cutter's tip at rho = -x reaching towards +rho (towards the
    /// axis, where its body stands inside the bore).
    pub(super) fn mirrored(&self) -> Self {
        let t = &self.section;
        Self {
            section: ThreadSection {
                internal: false,
                major: -t.major,
                pitch_diameter: -t.pitch_diameter,
                root_diameter: -t.root_diameter,
                crest_diameter: -t.crest_diameter,
                ..t.clone()
            },
            limits: self.limits.as_ref().map(mirrored_limits),
            pitch_shift: self.pitch_shift.iter().map(|d| -d).collect(),
            ..self.clone()
        }
    }

    /// How far start `k`'s aimed space stands along the axis from its
    /// nominal place: its place's correction ([`Self::place_shift`]).
    pub(super) fn start_shift(&self, k: u32) -> Real {
        self.place_shift.get(k as usize).copied().unwrap_or(0.0)
    }

    /// Start `k`'s section as the cut aims at it: the section aimed at its
    /// pitch diameter moved by its correction (its space moved radially,
    /// [`ThreadSection::aimed`]).
    pub(super) fn start_section(&self, k: u32) -> ThreadSection {
        let w = &self.section;
        match self.pitch_shift.get(k as usize) {
            Some(&d) if d != 0.0 => w.aimed(w.pitch_diameter + d),
            _ => w.clone(),
        }
    }
}
