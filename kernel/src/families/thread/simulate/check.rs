//! What the simulation found: each thread block's chip, each start's
//! finished profile, and the findings a verdict reads of them.

use super::{edges, flipped, mirrored_limits, no_section, vertical_top, ThreadTolerances};
use crate::families::thread::Hand;
use crate::math::Real;
use crate::replay::VerifyError;
use crate::verdict::{Figure, Finding};
use geo::MultiPolygon;
use serde::{Deserialize, Serialize};

/// One thread block as simulated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulatedPass {
    /// The block (from 1, the program's and `report.csv`'s count).
    pub block: usize,
    /// The block as the program names it (number and pass).
    pub name: String,
    /// The start it cut (from 0), by where it is.
    pub start: u32,
    /// X as written (diameter of the cutter's tip, mm).
    pub x: Real,
    /// Its axial offset from the start's nominal space centre (mm).
    pub offset: Real,
    /// The chip's area (mm^2).
    pub chip_area: Real,
    /// The chip's area on the cutter's left of its tip's centre (mm^2):
    /// the load on the left edge.
    pub left_area: Real,
    /// On its right (mm^2).
    pub right_area: Real,
    /// The deepest cut beyond the nominal space (mm; 0 where none).
    pub gouge: Real,
    /// The chip's thickness: the farthest its outline stands inside the
    /// cutter's (mm), the stock the pass takes.
    #[serde(default)]
    pub thickness: Real,
    /// How far the carriage travels before the leading cutting edge, at
    /// the blank's radius, meets the worm's face (mm): the pass's S1.
    pub approach_mm: Real,
    /// The lead's error there, as a ratio (the servo model of docs/math.md §4.2).
    pub face_lead_error: Real,
    /// How far before the block's end the trailing cutting edge, at the
    /// blank's radius, leaves the thread's far end (mm): the pass's S2.
    pub runout_mm: Real,
    /// The lead's error there, as a ratio.
    pub end_lead_error: Real,
}

/// The finished profile at one start's space.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StartProfile {
    /// The start (from 0).
    pub start: u32,
    /// The space's middle at the pitch line, less the nominal's (mm).
    pub position_error: Real,
    /// The axial thickness at the pitch line of the thread after this
    /// space (mm).
    pub thickness: Real,
    /// The left flank's angle from the radial (deg), fitted.
    pub left_angle_deg: Real,
    /// The right flank's (deg).
    pub right_angle_deg: Real,
    /// The left flank's largest deviation from the nominal, normal to it
    /// (mm; positive: material left, negative: cut too deep).
    pub left_form: Real,
    /// The right flank's (mm).
    pub right_form: Real,
    /// The diameter at the space's centre (mm).
    pub root_diameter: Real,
    /// The diameter at the middle of the thread after it (mm).
    pub tip_diameter: Real,
    /// The pitch diameter as a thread gauge takes it: where the space is
    /// as wide as the basic section's at its pitch diameter (P/2 for a
    /// standard thread), the space's own flanks measured (mm; 0 where the
    /// space is nowhere that wide between the flanks' measured band).
    #[serde(default)]
    pub pitch_diameter: Real,
    /// The measurement over two wires of the profile's best size laid in
    /// this start's spaces opposite each other (between balls, inside),
    /// the wires placed against the finished flanks (straight lines
    /// fitted to them) as a gauge lays them; the lead angle's correction
    /// left out (mm). Where the thread is held to a standard's limits and
    /// its flanks are symmetric.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub over_wires: Option<Real>,
    /// The functional (virtual) pitch diameter, as a GO gauge feels it:
    /// the perfect mating thread's that just fits the start's space at
    /// every radius its flanks were measured at, along the whole thread
    /// (the lead's error in) (mm; none where a flank lies along the
    /// radial). Held to the maximum-material limit; the simple
    /// `pitch_diameter` to both.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub functional_pitch_diameter: Option<Real>,
}

/// The simulation's result (`report.json`'s `thread_verification`; the
/// section and chips, for drawing, are not in it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThreadCheck {
    /// Every thread block, in order.
    pub passes: Vec<SimulatedPass>,
    /// The finished profile at each start.
    pub starts: Vec<StartProfile>,
    /// The nominal area of the spaces in one lead of the section (mm^2).
    pub space_area: Real,
    /// The simulated chips' areas summed (mm^2).
    pub removed_area: Real,
    /// The programmed lead's error accumulated over the thread (mm).
    pub lead_error: Real,
    /// The loads summed over all passes: left edge, right edge (mm^2).
    pub flank_loads: [Real; 2],
    /// The tolerances checked.
    pub tolerances: ThreadTolerances,
    /// Each pass's chip as polygons `(z, r)` (for the pass-by-pass view).
    #[serde(skip)]
    pub chips: Vec<Vec<Vec<[Real; 2]>>>,
    /// The finished section over one lead (from `window.0`; empty when
    /// read back from a report).
    #[serde(skip, default = "no_section")]
    pub section: MultiPolygon<Real>,
    /// The lead's window of the section: its first z and the lead.
    #[serde(skip)]
    pub window: (Real, Real),
    /// What failed, in the order found (the run's verdict holds them).
    #[serde(skip)]
    pub failures: Vec<Finding>,
    /// The nominal thickness at the pitch line, root and tip diameters (mm).
    #[serde(default)]
    pub nominal: (Real, Real, Real),
    /// The nominal flank angle (deg; the flank towards -Z's where they
    /// differ).
    #[serde(default)]
    pub nominal_alpha_deg: Real,
    /// The nominal flank angles (deg): the space's flank towards -Z (the
    /// left), then +Z; curved flanks' (ZN, ZI) least-squares lines over
    /// the radii the flanks are measured at.
    #[serde(default)]
    pub nominal_flanks_deg: [Real; 2],
    /// The standard's limits the thread was held to (none: the
    /// tolerances about the nominal alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<crate::families::thread::ThreadLimits>,
    /// The wire the over-wires measurement takes: the profile's best
    /// (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wire: Option<Real>,
    /// The measurement over wires the limits of the pitch diameter allow
    /// with that wire: [least, most] (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub over_wires_limits: Option<[Real; 2]>,
    /// An internal thread: its section's surface is the lowest material
    /// (the nut's inside), the measurement over wires one between balls.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub internal: bool,
    /// The way the thread winds: its solid's helix.
    #[serde(default)]
    pub hand: Hand,
}

impl ThreadCheck {
    /// The check, or its first failure as an error.
    ///
    /// # Failures
    /// What the simulation found beyond a tolerance ([`VerifyError::Failed`],
    /// naming the block or the start and flank).
    pub fn verified(self) -> Result<Self, VerifyError> {
        match self.failures.first() {
            Some(f) => Err(VerifyError::Failed(
                f.message
                    .strip_prefix("verification failed: ")
                    .unwrap_or(&f.message)
                    .to_owned(),
            )),
            None => Ok(self),
        }
    }

    /// Each figure the simulation holds to its tolerance, the worst over
    /// the starts and passes, and what failed.
    pub fn findings(&self) -> (Vec<Figure>, Vec<Finding>) {
        let mut figures = self.start_figures();
        figures.extend(self.gauge_figures());
        figures.push(Figure::new(
            "the lead over the thread",
            self.lead_error,
            self.tolerances.position,
            "mm",
            String::new(),
        ));
        figures.extend(self.pass_figures());
        (figures, self.failures.clone())
    }

    /// The figures of the starts, each the worst start's: the flanks' form
    /// and angles, the diameters (a standard thread's from the middle of
    /// each band, within half the band; a worm's from the nominal), each
    /// start's place.
    fn start_figures(&self) -> Vec<Figure> {
        let t = &self.tolerances;
        let mut figures = Vec::new();
        let mut start_figure = |name: &str, f: Of<'_, StartProfile>, tol: Real, unit| {
            figures.extend(self.worst_start(name, f, tol, unit));
        };
        let larger = |l: Real, r: Real| if l.abs() >= r.abs() { l } else { r };
        start_figure(
            "flank form",
            &|s| larger(s.left_form, s.right_form),
            t.form,
            "mm",
        );
        let [alpha_l, alpha_r] = self.nominal_flanks_deg;
        start_figure(
            "flank angle",
            &|s| larger(s.left_angle_deg - alpha_l, s.right_angle_deg - alpha_r),
            t.flank_angle.to_degrees(),
            "deg",
        );
        let diameters: [(&str, Of<'_, StartProfile>, Real, Real); 3] = match &self.limits {
            Some(l) => [
                (
                    "pitch diameter",
                    &|s| s.pitch_diameter,
                    l.pitch_diameter.middle(),
                    0.5 * l.pitch_diameter.width(),
                ),
                (
                    "root diameter",
                    &|s| s.root_diameter,
                    l.root.middle(),
                    0.5 * l.root.width(),
                ),
                (
                    "crest diameter",
                    &|s| s.tip_diameter,
                    l.crest.middle(),
                    0.5 * l.crest.width(),
                ),
            ],
            None => [
                (
                    "thickness at the pitch line",
                    &|s| s.thickness,
                    self.nominal.0,
                    t.thickness,
                ),
                (
                    "root diameter",
                    &|s| s.root_diameter,
                    self.nominal.1,
                    t.diameter,
                ),
                (
                    "tip diameter",
                    &|s| s.tip_diameter,
                    self.nominal.2,
                    t.diameter,
                ),
            ],
        };
        for (name, f, from, tol) in diameters {
            start_figure(name, &|s| f(s) - from, tol, "mm");
        }
        start_figure(
            "each start's place",
            &|s| s.position_error,
            t.position,
            "mm",
        );
        figures
    }

    /// The figure `name` of the start where `f` is largest, against `tol`.
    fn worst_start(
        &self,
        name: &str,
        f: Of<'_, StartProfile>,
        tol: Real,
        unit: &str,
    ) -> Option<Figure> {
        let (v, s) = (self.starts.iter())
            .map(|s| (f(s), s.start))
            .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))?;
        Some(Figure::new(name, v, tol, unit, format!("start {}", s + 1)))
    }

    /// The figures as the gauges take them, each the worst start's: the GO
    /// gauge's functional pitch diameter (the simple one lies on the
    /// band's other side of it, so beyond half the band from the middle
    /// is beyond the maximum-material limit), and the reading over wires
    /// (between balls) within what the band allows.
    fn gauge_figures(&self) -> Vec<Figure> {
        let mut figures = Vec::new();
        if let Some(l) = &self.limits {
            let (middle, half) = (l.pitch_diameter.middle(), 0.5 * l.pitch_diameter.width());
            if self
                .starts
                .iter()
                .all(|s| s.functional_pitch_diameter.is_some())
            {
                figures.extend(self.worst_start(
                    "functional pitch diameter (GO gauge)",
                    &|s| s.functional_pitch_diameter.unwrap_or(middle) - middle,
                    half,
                    "mm",
                ));
            }
        }
        if let Some([lo, hi]) = self.over_wires_limits {
            if self.starts.iter().all(|s| s.over_wires.is_some()) {
                let middle = 0.5 * (lo + hi);
                let name = if self.internal {
                    "between balls"
                } else {
                    "over wires"
                };
                figures.extend(self.worst_start(
                    name,
                    &|s| s.over_wires.unwrap_or(middle) - middle,
                    0.5 * (hi - lo),
                    "mm",
                ));
            }
        }
        figures
    }

    /// The figures of the passes, each the worst pass's, at its block: the
    /// cut beyond the nominal space, the lead where an edge meets the face
    /// and leaves the far end.
    fn pass_figures(&self) -> Vec<Figure> {
        let t = &self.tolerances;
        let pass = |f: &dyn Fn(&SimulatedPass) -> Real| {
            (self.passes.iter())
                .max_by(|a, b| f(a).total_cmp(&f(b)))
                .map(|p| (f(p), p.name.clone(), p.block))
        };
        let rows: [(&str, Of<'_, SimulatedPass>, Real, &str); 3] = [
            ("cut beyond the nominal space", &|p| p.gouge, t.form, "mm"),
            (
                "the lead where a pass's edge meets the face",
                &|p| 100.0 * p.face_lead_error,
                100.0 * t.lead,
                "%",
            ),
            (
                "the lead where a pass's edge leaves the far end",
                &|p| 100.0 * p.end_lead_error,
                100.0 * t.lead,
                "%",
            ),
        ];
        let mut figures = Vec::new();
        for (name, f, tol, unit) in rows {
            if let Some((v, place, block)) = pass(f) {
                let figure = Figure::new(name, v, tol, unit, place);
                figures.push(match block.checked_sub(1) {
                    Some(b) => figure.at_block(b),
                    None => figure,
                });
            }
        }
        figures
    }

    /// The finished thread's radius at `z` in the section at part angle 0
    /// (the section repeats with the lead): the highest material there,
    /// an internal thread's lowest.
    pub fn radius_at(&self, z: Real) -> Real {
        let (w0, lead) = self.window;
        let z = w0 + (z - w0).rem_euclid(lead);
        let r = if self.internal {
            vertical_top(&flipped(&self.section), z).map(|r| -r)
        } else {
            vertical_top(&self.section, z)
        };
        r.unwrap_or(0.0)
    }

    /// The check of an internal thread's external twin (simulated in rho =
    /// -r, [`ThreadRequest::mirrored`]) turned back: radii and diameters
    /// positive, the limits its own.
    pub(super) fn mirrored(mut self) -> Self {
        for s in &mut self.starts {
            s.root_diameter = -s.root_diameter;
            s.tip_diameter = -s.tip_diameter;
            s.pitch_diameter = -s.pitch_diameter;
            s.over_wires = s.over_wires.map(|m| -m);
            s.functional_pitch_diameter = s.functional_pitch_diameter.map(|d| -d);
        }
        self.nominal.1 = -self.nominal.1;
        self.nominal.2 = -self.nominal.2;
        self.limits = self.limits.as_ref().map(mirrored_limits);
        self.over_wires_limits = self.over_wires_limits.map(|[a, b]| [-b, -a]);
        for chip in &mut self.chips {
            for ring in chip {
                for p in ring {
                    p[1] = -p[1];
                }
            }
        }
        self.section = flipped(&self.section);
        self.internal = true;
        self
    }

    /// The finished section's outline over one lead from `window.0`, as
    /// `(z, r)` just either side of each of its corners (1 nm off, where
    /// a vertical ray meets edges, not corners): the outline is straight
    /// between them, so interpolating these is [`Self::radius_at`], and
    /// cheap.
    pub fn outline(&self) -> Vec<[Real; 2]> {
        const SIDE: Real = 1e-6;
        let (w0, lead) = self.window;
        let mut zs: Vec<Real> = edges(&self.section)
            .flat_map(|(a, _)| [a.x - SIDE, a.x + SIDE])
            .chain([w0 + SIDE, w0 + lead - SIDE])
            .filter(|z| *z > w0 && *z < w0 + lead)
            .collect();
        zs.sort_by(Real::total_cmp);
        zs.dedup_by(|a, b| (*a - *b).abs() < crate::tolerance::SAME_LENGTH);
        zs.iter().map(|&z| [z, self.radius_at(z)]).collect()
    }
}

/// A figure's value of a start or a pass.
type Of<'a, T> = &'a dyn Fn(&T) -> Real;
