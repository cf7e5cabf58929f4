//! The cut simulated pass by pass (issue 13 §2): the axis program, as
//! written, replayed in the worm's axial section. Every thread block cuts
//! the section at one place: the cutter's tip at the block's X, at the Z
//! where the helix it cuts crosses the section at part angle 0 (its start
//! Z shifted by the start angle's share of the lead). The cutter's section
//! (nose radii included) is subtracted from the blank's with a polygon
//! boolean crate (`geo`, whose `BooleanOps` is the `i_overlay` engine), not
//! hand-written clipping. From the simulation alone: each pass's chip
//! area and its share on each flank, any cut beyond the nominal space
//! (named by block), and the finished profile against the nominal ZA
//! axial profile: flank angles and form, thickness at the pitch line,
//! root and tip diameters, each start's position.
//!
//! An internal thread is cut as its external twin in rho = -r
//! ([`ThreadRequest::mirrored`]): its space opens towards the axis, so in
//! rho it opens outwards as an external thread's, and the results are
//! turned back (diameters positive, the measurement over wires one between
//! balls).
//!
//! The section is periodic along the axis with the lead: one lead is
//! simulated, from the middle of the thread before start 0's space, the
//! cutter placed with its copies one lead either side. What the model
//! leaves out: the servo's lag (the same on every pass at one spindle
//! speed, so it shifts the whole thread, not one pass), the approach and
//! run-out (checked to cover the thread's length), the cutter's clearance
//! angles and the lead angle's effect on the section (a ZA worm is cut with
//! the cutter in the axial plane), deflection and wear.

use super::{ThreadCutter, WormSizes};
use crate::families::thread::{Hand, ThreadSection};
use crate::machine::MachineKinematics;
use crate::math::Real;
use crate::program::{block_name, AxisProgram};
use crate::replay::{as_written, replay, VerifyError};
use crate::toolpath::Motion;
use crate::transform::ToolFrame;
use crate::verdict::{Figure, Finding};
use geo::{Area, BooleanOps, Coord, LineString, MultiPolygon, Polygon};
use serde::{Deserialize, Serialize};

/// How far (mm) inside its ends a radial band is read, where the flanks
/// are defined on both sides: a nanometre.
const INSIDE: Real = 1e-6;

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
    fn mirrored(&self) -> Self {
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
    fn start_shift(&self, k: u32) -> Real {
        self.place_shift.get(k as usize).copied().unwrap_or(0.0)
    }

    /// Start `k`'s section as the cut aims at it: the section aimed at its
    /// pitch diameter moved by its correction (its space moved radially,
    /// [`ThreadSection::aimed`]).
    fn start_section(&self, k: u32) -> ThreadSection {
        let w = &self.section;
        match self.pitch_shift.get(k as usize) {
            Some(&d) if d != 0.0 => w.aimed(w.pitch_diameter + d),
            _ => w.clone(),
        }
    }
}

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
        let t = &self.tolerances;
        let worst = |f: &dyn Fn(&StartProfile) -> Real| {
            self.starts
                .iter()
                .map(|s| (f(s), s.start))
                .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
        };
        let mut figures = Vec::new();
        let mut start_figure = |name: &str, f: &dyn Fn(&StartProfile) -> Real, tol: Real, unit| {
            if let Some((v, s)) = worst(f) {
                figures.push(Figure::new(name, v, tol, unit, format!("start {}", s + 1)));
            }
        };
        start_figure(
            "flank form",
            &|s| {
                if s.left_form.abs() >= s.right_form.abs() {
                    s.left_form
                } else {
                    s.right_form
                }
            },
            t.form,
            "mm",
        );
        let [alpha_l, alpha_r] = self.nominal_flanks_deg;
        start_figure(
            "flank angle",
            &|s| {
                let (l, r) = (s.left_angle_deg - alpha_l, s.right_angle_deg - alpha_r);
                if l.abs() >= r.abs() {
                    l
                } else {
                    r
                }
            },
            t.flank_angle.to_degrees(),
            "deg",
        );
        match &self.limits {
            // A standard thread: each diameter from the middle of its band,
            // within half the band.
            Some(l) => {
                for (name, f, band) in [
                    (
                        "pitch diameter",
                        &(|s: &StartProfile| s.pitch_diameter) as &dyn Fn(&StartProfile) -> Real,
                        l.pitch_diameter,
                    ),
                    ("root diameter", &|s| s.root_diameter, l.root),
                    ("crest diameter", &|s| s.tip_diameter, l.crest),
                ] {
                    start_figure(name, &|s| f(s) - band.middle(), 0.5 * band.width(), "mm");
                }
            }
            None => {
                start_figure(
                    "thickness at the pitch line",
                    &|s| s.thickness - self.nominal.0,
                    t.thickness,
                    "mm",
                );
                start_figure(
                    "root diameter",
                    &|s| s.root_diameter - self.nominal.1,
                    t.diameter,
                    "mm",
                );
                start_figure(
                    "tip diameter",
                    &|s| s.tip_diameter - self.nominal.2,
                    t.diameter,
                    "mm",
                );
            }
        }
        start_figure(
            "each start's place",
            &|s| s.position_error,
            t.position,
            "mm",
        );
        figures.push(Figure::new(
            "the lead over the thread",
            self.lead_error,
            t.position,
            "mm",
            String::new(),
        ));
        let pass = |f: &dyn Fn(&SimulatedPass) -> Real| {
            self.passes
                .iter()
                .max_by(|a, b| f(a).total_cmp(&f(b)))
                .map(|p| (f(p), p.name.clone(), p.block))
        };
        for (name, f, tol, unit) in [
            (
                "cut beyond the nominal space",
                &(|p: &SimulatedPass| p.gouge) as &dyn Fn(&SimulatedPass) -> Real,
                t.form,
                "mm",
            ),
            (
                "the lead where a pass's edge meets the face",
                &|p: &SimulatedPass| 100.0 * p.face_lead_error,
                100.0 * t.lead,
                "%",
            ),
            (
                "the lead where a pass's edge leaves the far end",
                &|p: &SimulatedPass| 100.0 * p.end_lead_error,
                100.0 * t.lead,
                "%",
            ),
        ] {
            if let Some((v, place, block)) = pass(f) {
                let figure = Figure::new(name, v, tol, unit, place);
                figures.push(match block.checked_sub(1) {
                    Some(b) => figure.at_block(b),
                    None => figure,
                });
            }
        }
        (figures, self.failures.clone())
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
    fn mirrored(mut self) -> Self {
        for s in &mut self.starts {
            s.root_diameter = -s.root_diameter;
            s.tip_diameter = -s.tip_diameter;
            s.pitch_diameter = -s.pitch_diameter;
            s.over_wires = s.over_wires.map(|m| -m);
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

/// `m` mirrored across the axis (r to -r).
fn flipped(m: &MultiPolygon<Real>) -> MultiPolygon<Real> {
    use geo::MapCoords;
    m.map_coords(|c| Coord { x: c.x, y: -c.y })
}

/// The section of a check read back from a report, which does not hold it.
fn no_section() -> MultiPolygon<Real> {
    MultiPolygon::new(Vec::new())
}

/// A polygon of `(z, r)` points.
pub(super) fn poly(points: &[[Real; 2]]) -> Polygon<Real> {
    Polygon::new(
        LineString::from(points.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>()),
        vec![],
    )
}

/// The rectangle `[z0, z1] x [r0, r1]`.
pub(super) fn rect(z0: Real, z1: Real, r0: Real, r1: Real) -> Polygon<Real> {
    poly(&[[z0, r0], [z1, r0], [z1, r1], [z0, r1]])
}

/// Every edge of a multipolygon's rings.
fn edges(m: &MultiPolygon<Real>) -> impl Iterator<Item = (Coord<Real>, Coord<Real>)> + '_ {
    m.0.iter()
        .flat_map(|p| std::iter::once(p.exterior()).chain(p.interiors()))
        .flat_map(|ring| ring.lines().map(|l| (l.start, l.end)))
}

/// The z where the material's boundary crosses the radius `r`, sorted.
fn crossings_at(m: &MultiPolygon<Real>, r: Real) -> Vec<Real> {
    let mut out: Vec<Real> = edges(m)
        .filter(|(a, b)| (a.y <= r) != (b.y <= r))
        .map(|(a, b)| a.x + (r - a.y) / (b.y - a.y) * (b.x - a.x))
        .collect();
    out.sort_by(Real::total_cmp);
    out
}

/// The highest material at `z`.
fn vertical_top(m: &MultiPolygon<Real>, z: Real) -> Option<Real> {
    edges(m)
        .filter(|(a, b)| (a.x <= z) != (b.x <= z))
        .map(|(a, b)| a.y + (z - a.x) / (b.x - a.x) * (b.y - a.y))
        .max_by(Real::total_cmp)
}

/// The space around `c` at radius `r`: the material's boundary just left
/// and just right of it, if `c` is in a space there.
fn space_edges(m: &MultiPolygon<Real>, r: Real, c: Real) -> Option<(Real, Real)> {
    let x = crossings_at(m, r);
    let i = x.iter().position(|z| *z > c)?;
    // Crossings alternate into and out of material from the left: an even
    // count to the left of c means c is outside the material.
    (i % 2 == 0 && i > 0).then(|| (x[i - 1], x[i]))
}

fn segment_distance(p: [Real; 2], a: [Real; 2], b: [Real; 2]) -> Real {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p[0] - a[0] - t * dx).powi(2) + (p[1] - a[1] - t * dy).powi(2)).sqrt()
}

/// How far the middles of the threads' crests either side of a space
/// stand from its centre (the root's middle): before it (towards -Z), then
/// after it. Below the crest the thread is wider, so a line there stays in
/// the thread (a buttress's too).
fn thread_middle(t: &ThreadSection) -> [Real; 2] {
    let reach = t.reach(t.crest_diameter / 2.0);
    let half = (t.pitch - reach[0] - reach[1]) / 2.0;
    [reach[0] + half, reach[1] + half]
}

/// The nominal spaces of one lead's window (and one either side), each an
/// outline from the root to above the crest: a trapezoid, or curved
/// flanks in chords of [`NOMINAL_CHORDS`] along the depth; each start's
/// moved radially by its correction ([`ThreadRequest::pitch_shift`]).
fn nominal_spaces(req: &ThreadRequest, c0: Real) -> Vec<Vec<[Real; 2]>> {
    let t = &req.section;
    let n = if t.form.is_axial() { 1 } else { NOMINAL_CHORDS };
    (-1..=i64::from(t.starts))
        .map(|k| {
            // The place's start (start_place is its own inverse), its
            // space moved by its corrections.
            let start = t.hand.start_place(k, t.starts);
            let c = c0 + k as Real * t.pitch + req.start_shift(start);
            let s = req.start_section(start);
            let (root, top) = (s.root_diameter / 2.0, s.crest_diameter / 2.0 + 2.0);
            let radii: Vec<Real> = (0..=n)
                .map(|i| root + (top - root) * i as Real / n as Real)
                .collect();
            let reach: Vec<[Real; 2]> = radii.iter().map(|&r| s.reach(r)).collect();
            // From the -Z flank's root corner along the root, up the +Z
            // flank, back down the -Z flank.
            let up = radii.iter().zip(&reach).map(|(&r, e)| [c + e[1], r]);
            let down = radii.iter().zip(&reach).rev().map(|(&r, e)| [c - e[0], r]);
            let mut outline: Vec<[Real; 2]> = up.chain(down).collect();
            outline.rotate_right(1);
            outline
        })
        .collect()
}

/// The chords of a curved nominal flank: 64 over a worm's depth of 11 mm
/// and 2 above it leave 0.2 mm each, within 0.02 um of a ZI flank's curve
/// (its axial angle turns 3 degrees over the depth).
const NOMINAL_CHORDS: usize = 64;

/// Replays `program` (as written) on `machine` and simulates the cut of
/// `cutter` (tracked at `tool`) in the worm's axial section; see the
/// module's docs.
///
/// # Failures
/// The replay failing; a thread block that tapers (X changes), whose lead
/// is not the worm's within the position tolerance over the thread, or
/// that does not run over the whole thread; a move other than a thread
/// that crosses the blank; any cut deeper than the form tolerance beyond
/// the nominal space (named by block); the finished profile beyond a
/// tolerance (named by start and flank). Each a [`VerifyError::Failed`].
pub fn simulate(
    program: &AxisProgram,
    machine: &dyn MachineKinematics,
    tool: &ToolFrame,
    cutter: &ThreadCutter,
    req: &ThreadRequest,
) -> Result<ThreadCheck, VerifyError> {
    // An internal thread is simulated as its external twin in rho = -r
    // (see `mirrored`), and its results turned back.
    let inside = req.section.internal;
    let rho = req.section.opening();
    let twin;
    let req = if inside {
        twin = req.mirrored();
        &twin
    } else {
        req
    };
    let w = &req.section;
    let tol = &req.tolerances;
    let fail = |m: String| VerifyError::Failed(m);
    let (written, _) = as_written(program);
    let poses = replay(&written, machine, tool)?;
    let at = |i: usize| (rho * poses[6 * i], poses[6 * i + 2]);
    let lead = w.lead();
    let (px, z1) = (w.pitch, w.starts);
    let (r_a, r_f) = (w.crest_diameter / 2.0, w.root_diameter / 2.0);
    let r_core = r_f - (2.0f64).min(r_f.abs() / 2.0);
    let c0 = req.space_centre;
    // The window starts in the middle of the crest before start 0's
    // space.
    let w0 = c0 - thread_middle(w)[0];
    let mut material = MultiPolygon::new(vec![rect(w0, w0 + lead, r_core, r_a)]);
    let spaces = nominal_spaces(req, c0);
    let nominal = MultiPolygon::new(spaces.iter().map(|s| poly(s)).collect());
    let mut passes = Vec::new();
    let mut chips = Vec::new();
    let mut lead_error: Real = 0.0;
    let x_axis = written.axes.iter().position(|a| a.name == "X");
    // The carriage's servo (docs/math.md §4.2): the machine's time constant and
    // the spindle's speed as written.
    let servo = machine
        .info()
        .constants
        .get("servo_time_constant")
        .copied()
        .filter(|t| *t > 0.0)
        .ok_or_else(|| {
            fail(format!(
                "machine {} states no servo_time_constant (s): the lead where the thread starts and ends cannot be checked",
                machine.info().name
            ))
        })?;
    // What fails is found and the simulation goes on, so that a failed run
    // shows every pass and the profile it leaves.
    let mut failures: Vec<Finding> = Vec::new();
    let mut found = |i: usize, m: String| {
        failures
            .push(Finding::new("verification", fail(m).to_string()).at(i, block_name(&written, i)));
    };
    let mut ticker = crate::budget::Ticker::new("the thread's simulation", 16);
    let speeds: Vec<Real> = crate::program::spindle_speeds(&written).collect();
    for i in 1..written.blocks.len() {
        ticker.tick()?;
        let (b, rpm) = (&written.blocks[i], speeds[i]);
        let name = || block_name(&written, i);
        let ((r0, z0), (r1, z1e)) = (at(i - 1), at(i));
        let Motion::Thread { lead: l, start_deg } = b.motion else {
            // Any other move must keep clear of the blank, but for the
            // retract straight out of the groove a thread block just cut.
            let low = r0.min(r1);
            let out_of_groove = matches!(written.blocks[i - 1].motion, Motion::Thread { .. })
                && z0 == z1e
                && r1 >= r0;
            if low < r_a - crate::tolerance::SAME_LENGTH && !out_of_groove {
                // The cutter's profile reaches its height above the tip; what
                // holds it is the collision check's.
                let half = cutter.width_at((r_a - low).min(cutter.height)) / 2.0;
                let (lo, hi) = (z0.min(z1e), z0.max(z1e));
                if hi > -req.length - half && lo < half {
                    found(i, format!(
                        "{}: a move that is not a thread block crosses the blank (tip at diameter {:.3}, z from {:.3} to {:.3}; the worm runs from z = {:.3} to 0 at diameter {:.3})",
                        name(), diameter(low), z0, z1e, -req.length, diameter(r_a)
                    ));
                }
            }
            continue;
        };
        if (r1 - r0).abs() > crate::tolerance::SAME_LENGTH {
            found(
                i,
                format!(
                    "{}: a thread block that changes X (from {:.4} to {:.4}) cuts a taper, not a worm",
                    name(),
                    diameter(r0),
                    diameter(r1)
                ),
            );
            continue;
        }
        let err_len = (l - lead).abs() * req.length / lead;
        lead_error = lead_error.max(err_len);
        if err_len > tol.position {
            found(i, format!(
                "{}: lead {l} mm is not the worm's {lead:.6} mm: {err_len:.4} mm out over the thread's {} mm (tolerance {} mm)",
                name(), req.length, tol.position
            ));
        }
        if z0.min(z1e) > -req.length || z0.max(z1e) < 0.0 {
            found(
                i,
                format!(
                    "{}: the thread block runs from z = {z0:.3} to {z1e:.3}, not over the whole thread (z from {:.3} to 0)",
                    name(),
                    -req.length
                ),
            );
            continue;
        }
        // The spindle turns as M3 (the lint refuses any other word): a
        // block towards -Z cuts a right-hand helix, towards +Z a left.
        let dir = (z1e - z0).signum();
        let cuts = if dir < 0.0 { Hand::Right } else { Hand::Left };
        if cuts != w.hand {
            found(i, format!(
                "{}: a thread block towards {} with the spindle in M3 cuts a {}-hand helix, and the thread is {}-handed (cut it towards {})",
                name(),
                if dir < 0.0 { "-Z (the chuck)" } else { "+Z (the tailstock)" },
                cuts.name(),
                w.hand.name(),
                if dir < 0.0 { "+Z" } else { "-Z" },
            ));
            // Simulated still: the axial section at angle 0 is cut the
            // same, and a failed run shows every pass.
        }
        let z_sec = z0 - dir * l * start_deg / 360.0;
        let k_raw = ((z_sec - c0) / px).round();
        let start = w.hand.start_place(k_raw as i64, z1);
        let offset = z_sec - (c0 + k_raw * px);
        let zw = w0 + (z_sec - w0).rem_euclid(lead);
        let section = cutter.section(r_a + 1.0 - r1);
        let placed = |dz: Real| -> Polygon<Real> {
            poly(
                &section
                    .iter()
                    .map(|p| [p[0] + zw + dz, p[1] + r1])
                    .collect::<Vec<_>>(),
            )
        };
        let cutter_mp = MultiPolygon::new(vec![placed(-lead), placed(0.0), placed(lead)]);
        let chip = material.intersection(&cutter_mp);
        let chip_area = chip.unsigned_area();
        // The chip's thickness: the farthest its outline stands inside the
        // cutter's (the depth of the cut, normal to the edge that takes it).
        let thickness = chip
            .0
            .iter()
            .flat_map(|p| p.exterior().coords())
            .map(|c| {
                [-lead, 0.0, lead]
                    .iter()
                    .map(|dz| {
                        let n = section.len();
                        (0..n)
                            .map(|j| {
                                let at = |q: [Real; 2]| [q[0] + zw + dz, q[1] + r1];
                                segment_distance(
                                    [c.x, c.y],
                                    at(section[j]),
                                    at(section[(j + 1) % n]),
                                )
                            })
                            .fold(Real::INFINITY, Real::min)
                    })
                    .fold(Real::INFINITY, Real::min)
            })
            .fold(0.0, Real::max);
        let left_side = MultiPolygon::new(
            [-lead, 0.0, lead]
                .iter()
                .map(|dz| rect(zw + dz - lead / 2.0, zw + dz, r_core - 1.0, r_a + 2.0))
                .collect(),
        );
        let left_area = chip.intersection(&left_side).unsigned_area();
        let beyond = chip.difference(&nominal);
        let mut gouge: Real = 0.0;
        let mut worst = [0.0; 2];
        if beyond.unsigned_area() > crate::tolerance::NO_AREA {
            for (p, _) in edges(&beyond) {
                let q = [p.x, p.y];
                let d = spaces
                    .iter()
                    .map(|s| {
                        (0..s.len())
                            .map(|j| segment_distance(q, s[j], s[(j + 1) % s.len()]))
                            .fold(Real::INFINITY, Real::min)
                    })
                    .fold(Real::INFINITY, Real::min);
                if d > gouge {
                    gouge = d;
                    worst = q;
                }
            }
        }
        let x = x_axis.map(|k| b.values[k]).unwrap_or(diameter(r1));
        if gouge > tol.form {
            found(i, format!(
                "{}: the cutter cuts {:.4} mm beyond the nominal thread space (at z = {:.3} in the section, diameter {:.3}; X{x:.3}, offset {offset:.4} mm from start {}'s space; tolerance {} mm)",
                name(), gouge, worst[0], diameter(worst[1]), start + 1, tol.form
            ));
        }
        // Where the cutting edges at the blank's radius meet the thread's
        // near end and leave its far end: the servo's lead error there.
        let [left, right] = cutter.extent_at(r_a - r1);
        let (approach_mm, runout_mm) = if dir < 0.0 {
            (z0 - left, -req.length - (z1e + right))
        } else {
            (-req.length - (z0 + right), z1e - left)
        };
        let v = l * rpm / 60.0;
        let face_lead_error = super::approach_error(servo, v, approach_mm);
        let end_lead_error = super::runout_error(servo, v, runout_mm);
        for (what, e, length, minimum) in [
            (
                "where the leading cutting edge meets the worm's face",
                face_lead_error,
                approach_mm,
                super::approach_length(servo, v, tol.lead),
            ),
            (
                "where the trailing cutting edge leaves the thread's far end",
                end_lead_error,
                runout_mm,
                super::runout_length(servo, v) * (1.0 - tol.lead),
            ),
        ] {
            if e > tol.lead {
                found(i, format!(
                    "{}: the lead is {:.2}% off {what} ({:.3} mm from the block's {}; at least {:.3} mm keeps it within the allowed {}%)",
                    name(),
                    100.0 * e,
                    length,
                    if length == approach_mm { "start" } else { "end" },
                    minimum,
                    100.0 * tol.lead
                ));
            }
        }
        chips.push(
            chip.0
                .iter()
                .map(|p| p.exterior().coords().map(|c| [c.x, c.y]).collect())
                .collect(),
        );
        material = material.difference(&cutter_mp);
        passes.push(SimulatedPass {
            block: i + 1,
            name: name(),
            start,
            x,
            offset,
            chip_area,
            left_area,
            right_area: chip_area - left_area,
            gouge,
            thickness,
            approach_mm,
            face_lead_error,
            runout_mm,
            end_lead_error,
        });
    }
    if passes.is_empty() {
        return Err(VerifyError::NoCuttingPass);
    }
    let (starts, unmeasured) = measure(&material, req, cutter);
    let nominal_flanks = nominal_flanks_deg(w, &flank_radii(w, req.flank_margin, cutter));
    failures.extend(unmeasured);
    let check = ThreadCheck {
        failures,
        nominal: (
            w.pitch - w.space_at_pitch,
            w.root_diameter,
            w.crest_diameter,
        ),
        nominal_alpha_deg: nominal_flanks[0],
        nominal_flanks_deg: nominal_flanks,
        limits: req.limits.clone(),
        wire: req.limits.as_ref().and(w.best_wire()),
        over_wires_limits: req.limits.as_ref().and_then(|l| {
            let wire = w.best_wire()?;
            let m = |d: Real| w.over_wires(wire, d);
            let (a, b) = (m(l.pitch_diameter.min)?, m(l.pitch_diameter.max)?);
            Some([a.min(b), a.max(b)])
        }),
        removed_area: passes.iter().map(|p| p.chip_area).sum(),
        flank_loads: [
            passes.iter().map(|p| p.left_area).sum(),
            passes.iter().map(|p| p.right_area).sum(),
        ],
        passes,
        starts,
        space_area: Real::from(z1) * w.space_area(),
        lead_error,
        tolerances: *tol,
        chips,
        section: material,
        window: (w0, lead),
        internal: false,
        hand: w.hand,
    };
    Ok(if inside { check.mirrored() } else { check })
}

/// A diameter of the section from a radius of the simulation's, which is
/// negative for an internal thread's twin.
fn diameter(r: Real) -> Real {
    2.0 * r.abs()
}

/// A thread's limits in rho = -r, or back (its own inverse): each band
/// negated, least first.
fn mirrored_limits(
    l: &crate::families::thread::ThreadLimits,
) -> crate::families::thread::ThreadLimits {
    let band = |b: &crate::families::thread::Limits| crate::families::thread::Limits {
        min: -b.max,
        max: -b.min,
    };
    crate::families::thread::ThreadLimits {
        pitch_diameter: band(&l.pitch_diameter),
        crest: band(&l.crest),
        root: band(&l.root),
        source: l.source.clone(),
    }
}

/// The worm's material for the process's rules ([`crate::process`]): the
/// blank, a cylinder of the tip's radius over the thread's length, which
/// a tool moving otherwise than along the thread meets as the part turns
/// under it (the envelope of the section over a turn); and each thread
/// block's chip, the last at each start finishing it.
#[derive(Debug, Clone)]
pub struct ThreadStock {
    /// +1, or -1 for an internal thread: radii are taken as rho = -r, so
    /// that the material lies below the crest as an external thread's.
    rho: Real,
    tip_radius: Real,
    /// The material's far side in rho: a nut's outside (none: the axis,
    /// which no tool reaches).
    far: Real,
    length: Real,
    /// The cutter's outline about its tip's centre, sampled every 0.1 mm.
    outline: Vec<[Real; 2]>,
    passes: Vec<crate::process::PassStock>,
}

impl ThreadStock {
    /// The material of the worm of `req` that `check` simulated, cut by
    /// `cutter`.
    pub fn new(check: &ThreadCheck, req: &ThreadRequest, cutter: &ThreadCutter) -> Self {
        let section = cutter.section(cutter.height);
        let mut outline = Vec::new();
        for j in 0..section.len() {
            let (a, b) = (section[j], section[(j + 1) % section.len()]);
            let n = ((a[0] - b[0]).hypot(a[1] - b[1]) / 0.1).ceil().max(1.0) as usize;
            outline.extend((0..n).map(|i| {
                let t = i as Real / n as Real;
                [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
            }));
        }
        let last_of_start = |k: usize| {
            check.passes[k + 1..]
                .iter()
                .all(|p| p.start != check.passes[k].start)
        };
        let passes = check
            .passes
            .iter()
            .enumerate()
            .map(|(k, p)| crate::process::PassStock {
                name: p.name.clone(),
                first_block: p.block - 1,
                cut: p.thickness,
                ridge: 0.0,
                finishes: last_of_start(k),
            })
            .collect();
        let rho = req.section.opening();
        Self {
            rho,
            tip_radius: rho * req.section.crest_diameter / 2.0,
            far: req
                .outside_diameter
                .filter(|_| req.section.internal)
                .map_or(Real::NEG_INFINITY, |d| -d / 2.0),
            length: req.length,
            outline,
            passes,
        }
    }
}

impl crate::process::Stock for ThreadStock {
    fn tool_depth(&self, _: usize, pose: &[Real]) -> Real {
        let (z, r) = (pose[2], self.rho * pose[0].hypot(pose[1]));
        // Into the blank, the outline's points over it; off it, the
        // nearest's distance.
        self.outline
            .iter()
            .map(|p| {
                let (pz, pr) = (z + p[0], r + p[1]);
                let dz = (pz - 0.0).max(-self.length - pz).max(0.0);
                // Beyond the crest, or beyond a nut's outside.
                let dr = (pr - self.tip_radius).max(self.far - pr);
                if dz == 0.0 {
                    -dr
                } else {
                    -dz.hypot(dr.max(0.0))
                }
            })
            .fold(Real::NEG_INFINITY, Real::max)
    }

    fn passes(&self) -> Vec<crate::process::PassStock> {
        self.passes.clone()
    }
}

/// The diameter where the space round `c` is as wide as the basic
/// section's at its pitch diameter, between the radii `band` (from the cut
/// root, where it stands above the band's start; bisection on the space's
/// width, which grows towards the crest; 0 if it is not within the band).
fn pitch_diameter(m: &MultiPolygon<Real>, t: &ThreadSection, c: Real, band: (Real, Real)) -> Real {
    let width = |r: Real| space_edges(m, r, c).map(|(a, b)| b - a);
    let (mut lo, mut hi) = band;
    // Where the cut's root stands above the band's start (the passes'
    // depths rounded to the program's digit), the band starts at it.
    if width(lo).is_none() {
        if let Some(root) = vertical_top(m, c) {
            lo = lo.max(root + INSIDE);
        }
    }
    let (Some(w_lo), Some(w_hi)) = (width(lo), width(hi)) else {
        return 0.0;
    };
    let want = t.space_at_pitch;
    if !(w_lo <= want && want <= w_hi) {
        return 0.0;
    }
    // 50 halvings take a band of millimetres below 1e-12 mm.
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        match width(mid) {
            Some(w) if w < want => lo = mid,
            Some(_) => hi = mid,
            None => return 0.0,
        }
    }
    lo + hi
}

/// The measurement over two wires of diameter `wire` laid in spaces whose
/// flanks are the lines `left` and `right` (`z = a + b r`), opposite each
/// other: each wire's centre where the space is as wide as the wire
/// reaches across it, touching both flanks.
fn over_wires(t: &ThreadSection, wire: Real, left: [Real; 2], right: [Real; 2]) -> Real {
    // A wire touching a flank at `a` from the radial has its centre
    // wire / 2 / cos(a) from it along the axis.
    let (a_l, a_r) = ((-left[1]).atan(), right[1].atan());
    let across = 0.5 * wire * (1.0 / a_l.cos() + 1.0 / a_r.cos());
    let r_centre = (across - (right[0] - left[0])) / (right[1] - left[1]);
    2.0 * r_centre + t.opening() * wire
}

/// The least-squares slope `b` of `z = a + b r`.
fn slope(samples: &[(Real, Real)]) -> Real {
    line(samples)[1]
}

/// The least-squares line `z = a + b r`: `[a, b]`.
fn line(samples: &[(Real, Real)]) -> [Real; 2] {
    let n = samples.len() as Real;
    let (mr, mz) = samples
        .iter()
        .fold((0.0, 0.0), |(a, b), (r, z)| (a + r / n, b + z / n));
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (r, z) in samples {
        sxy += (r - mr) * (z - mz);
        sxx += (r - mr) * (r - mr);
    }
    let b = sxy / sxx;
    [mz - b * mr, b]
}

/// The radii the flanks of section `w` are measured at: 21, `margin`
/// clear of the root's fillet and the tip's edge.
fn flank_radii(w: &ThreadSection, margin: Real, cutter: &ThreadCutter) -> Vec<Real> {
    let r_lo = w.root_diameter / 2.0 + 2.0 * cutter.nose_radius + margin;
    let r_hi = w.crest_diameter / 2.0 - margin;
    (0..21)
        .map(|j| r_lo + (r_hi - r_lo) * j as Real / 20.0)
        .collect()
}

/// The nominal flanks' angles the measured ones are held to (deg, the
/// flank towards -Z first): straight flanks' own; curved flanks' (ZN, ZI)
/// least-squares lines over the `radii` they are measured at, as the
/// measured angles are taken.
fn nominal_flanks_deg(w: &ThreadSection, radii: &[Real]) -> [Real; 2] {
    if w.form.is_axial() {
        return w.flanks.map(Real::to_degrees);
    }
    let side = |k: usize, sign: Real| -> Vec<(Real, Real)> {
        radii.iter().map(|&r| (r, sign * w.reach(r)[k])).collect()
    };
    [
        (-slope(&side(0, -1.0))).atan().to_degrees(),
        slope(&side(1, 1.0)).atan().to_degrees(),
    ]
}

/// The finished profile at every start, and what of it fails against the
/// nominal (a start whose space is not there is not measured further).
fn measure(
    m: &MultiPolygon<Real>,
    req: &ThreadRequest,
    cutter: &ThreadCutter,
) -> (Vec<StartProfile>, Vec<Finding>) {
    let (w, tol) = (&req.section, &req.tolerances);
    let mut failures = Vec::new();
    let fail = |m: String| Finding::new("verification", VerifyError::Failed(m).to_string());
    let (px, r_a, r1) = (w.pitch, w.crest_diameter / 2.0, w.pitch_diameter / 2.0);
    let c0 = req.space_centre;
    let mut out = Vec::new();
    'starts: for k in 0..w.starts {
        // The start's place in the window (modulo the lead).
        let c =
            c0 + Real::from(w.hand.start_place(i64::from(k), w.starts)) * px + req.start_shift(k);
        // The start's aimed space, moved by its correction, and the radii
        // its flanks are measured at.
        let aimed = req.start_section(k);
        let radii = flank_radii(&aimed, req.flank_margin, cutter);
        let nominal_angles = nominal_flanks_deg(&aimed, &radii);
        let space = |r: Real| {
            space_edges(m, r, c).ok_or_else(|| {
                fail(format!(
                    "start {}: no space cut at diameter {:.3} (the thread's space is not there)",
                    k + 1,
                    diameter(r)
                ))
            })
        };
        let (mut left, mut right) = (Vec::new(), Vec::new());
        let (mut left_form, mut right_form): (Real, Real) = (0.0, 0.0);
        let mut worst_at = [0.0; 2];
        for &r in &radii {
            let (zl, zr) = match space(r) {
                Ok(s) => s,
                Err(e) => {
                    failures.push(e);
                    continue 'starts;
                }
            };
            left.push((r, zl));
            right.push((r, zr));
            let reach = aimed.reach(r);
            let dl = (zl - (c - reach[0])) * w.flanks[0].cos();
            let dr = ((c + reach[1]) - zr) * w.flanks[1].cos();
            if dl.abs() > left_form.abs() {
                left_form = dl;
                worst_at[0] = r;
            }
            if dr.abs() > right_form.abs() {
                right_form = dr;
                worst_at[1] = r;
            }
        }
        let (zl, zr) = match space(r1) {
            Ok(s) => s,
            Err(e) => {
                failures.push(e);
                continue 'starts;
            }
        };
        // The space after the last start's is start 0's, one lead on.
        let next = if k + 1 == w.starts {
            space_edges(m, r1, c0).map(|(a, _)| a + w.lead())
        } else {
            space_edges(m, r1, c + px).map(|(a, _)| a)
        };
        let Some(next) = next else {
            failures.push(fail(format!(
                "start {}: no space after it at the pitch line",
                k + 1
            )));
            continue 'starts;
        };
        let p = StartProfile {
            start: k,
            // The pitch line's middle stands off the root's by half the
            // flanks' difference over the depth between them.
            position_error: 0.5 * (zl + zr) - c - {
                let reach = aimed.reach(r1);
                0.5 * (reach[1] - reach[0])
            },
            thickness: next - zr,
            left_angle_deg: (-slope(&left)).atan().to_degrees(),
            right_angle_deg: slope(&right).atan().to_degrees(),
            left_form,
            right_form,
            root_diameter: 2.0 * vertical_top(m, c).unwrap_or(0.0),
            // The thread's middle (the last start's at the window's end:
            // 1 um inside it).
            tip_diameter: 2.0 * vertical_top(m, c + thread_middle(w)[1] - 1e-3).unwrap_or(0.0),
            // Searched over the straight flanks: from where the nose's
            // arc meets them to the crest.
            pitch_diameter: pitch_diameter(
                m,
                w,
                c,
                (
                    aimed.root_diameter / 2.0
                        + cutter.nose_radius * (1.0 - w.flanks[0].min(w.flanks[1]).sin())
                        + INSIDE,
                    r_a - INSIDE,
                ),
            ),
            over_wires: req
                .limits
                .as_ref()
                .and(w.best_wire())
                .map(|wire| over_wires(w, wire, line(&left), line(&right))),
        };
        let s = k + 1;
        for (flank, form, r) in [
            ("left", p.left_form, worst_at[0]),
            ("right", p.right_form, worst_at[1]),
        ] {
            if form.abs() > tol.form {
                failures.push(fail(format!(
                    "start {s}, {flank} flank: {} {:.4} mm from the nominal flank at diameter {:.3} (tolerance {} mm)",
                    if form > 0.0 { "material left" } else { "cut too deep" },
                    form.abs(), diameter(r), tol.form
                )));
            }
        }
        for (flank, a, alpha) in [
            ("left", p.left_angle_deg, nominal_angles[0]),
            ("right", p.right_angle_deg, nominal_angles[1]),
        ] {
            if (a - alpha).abs() > tol.flank_angle.to_degrees() {
                failures.push(fail(format!(
                    "start {s}, {flank} flank: angle {a:.4} deg, nominal {alpha:.4} deg (tolerance {:.4} deg)",
                    tol.flank_angle.to_degrees()
                )));
            }
        }
        let thickness = w.pitch - w.space_at_pitch;
        if req.limits.is_none() && (p.thickness - thickness).abs() > tol.thickness {
            failures.push(fail(format!(
                "start {s}: axial thickness at the pitch line {:.4} mm, nominal {:.4} mm (tolerance {} mm)",
                p.thickness, thickness, tol.thickness
            )));
        }
        for (what, d, nominal) in [
            ("root diameter", p.root_diameter, w.root_diameter),
            ("tip diameter", p.tip_diameter, w.crest_diameter),
        ] {
            if req.limits.is_none() && (d - nominal).abs() > tol.diameter {
                failures.push(fail(format!(
                    "start {s}: {what} {:.4} mm, nominal {:.4} mm (tolerance {} mm)",
                    d.abs(),
                    nominal.abs(),
                    tol.diameter
                )));
            }
        }
        if let Some(l) = &req.limits {
            // A corrected start's pitch and root diameters are held to the
            // standard's band moved by its correction: the part is to come
            // out in the band when the measured error repeats.
            let by = aimed.pitch_diameter - w.pitch_diameter;
            for (what, v, d, by) in [
                ("pitch diameter", p.pitch_diameter, &l.pitch_diameter, by),
                ("root diameter", p.root_diameter, &l.root, by),
                ("crest diameter", p.tip_diameter, &l.crest, 0.0),
            ] {
                if !d.holds(v - by, 0.0) {
                    let (lo, hi) = (d.min + by, d.max + by);
                    let (lo, hi) = (lo.abs().min(hi.abs()), lo.abs().max(hi.abs()));
                    let corrected = if by == 0.0 {
                        String::new()
                    } else {
                        format!(
                            ", moved by {:+.4} mm for the correction",
                            by * w.pitch_diameter.signum()
                        )
                    };
                    failures.push(fail(format!(
                        "start {s}: {what} {:.4} mm, outside {lo:.4} to {hi:.4} mm ({}{corrected})",
                        v.abs(),
                        l.source
                    )));
                }
            }
        }
        if p.position_error.abs() > tol.position {
            failures.push(fail(format!(
                "start {s}: its space is {:.4} mm from its place (tolerance {} mm)",
                p.position_error, tol.position
            )));
        }
        out.push(p);
    }
    (out, failures)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::families::thread::{plan, FlankOrder, PlanSettings};
    use crate::families::thread::{standards, Hand, ThreadProfile};
    use crate::machine::{ChainMachine, Machine};
    use crate::program::{Block, ProgramAxis};

    /// An external M20 6g cut with a 60 degree cutter to the plan's depths,
    /// the section aimed `aim` mm below the basic pitch diameter: the
    /// lathe's program of plain thread blocks.
    fn cut_m20(aim: Real) -> Result<ThreadCheck, VerifyError> {
        let profile = standards::metric(20.0, 2.5, false, "6g", 1, Hand::Right).unwrap();
        cut(&profile, aim, FlankOrder::Alternating)
    }

    /// `profile` cut `aim` mm into the material from its basic pitch
    /// diameter (an external thread's smaller, an internal's larger) by a
    /// cutter of its own flanks and root space, the roughing passes on
    /// `order`'s flanks: the tip towards the axis from above an external
    /// thread, away from it from inside an internal thread's bore.
    fn cut(
        profile: &ThreadProfile,
        aim: Real,
        order: FlankOrder,
    ) -> Result<ThreadCheck, VerifyError> {
        cut_towards(profile, aim, order, -1.0)
    }

    /// [`cut`], the thread blocks towards -Z (`towards` -1, from 5 mm
    /// beyond the face) or +Z (+1, from 5 mm beyond the thread's far
    /// end), each start at its start angle.
    fn cut_towards(
        profile: &ThreadProfile,
        aim: Real,
        order: FlankOrder,
        towards: Real,
    ) -> Result<ThreadCheck, VerifyError> {
        cut_by(profile, aim, order, towards, |t| {
            ThreadCutter::new(t.root_space(), 0.15, t.flanks[0], t.flanks[1], 3.0).unwrap()
        })
    }

    /// [`cut_towards`] by the cutter `make` makes for the aimed section.
    fn cut_by(
        profile: &ThreadProfile,
        aim: Real,
        order: FlankOrder,
        towards: Real,
        make: fn(&ThreadSection) -> ThreadCutter,
    ) -> Result<ThreadCheck, VerifyError> {
        // The blank turned to the middle of the crest's band.
        let s = profile.section.opening();
        let t = &ThreadSection {
            crest_diameter: profile.limits.crest.middle(),
            ..profile
                .section
                .aimed(profile.section.pitch_diameter - s * aim)
        };
        let cutter = make(t);
        let settings = PlanSettings {
            roughing_passes: None,
            min_depth: 0.05,
            finish_depth: 0.03,
            finish_passes: 2,
            order,
            axial_step: 0.5,
            starts_by_depth: true,
        };
        let passes = plan(t, &cutter, &settings).unwrap();
        // A worm's long lead slower, and its deep space's edges further
        // out, S1 within the run-in before the face.
        let (length, rpm, run_in) = if t.lead() > 10.0 {
            (30.0, 60.0, 5.0 + t.depth())
        } else {
            (30.0, 300.0, 5.0)
        };
        let c0 = if towards < 0.0 {
            run_in
        } else {
            -length - run_in
        };
        let r_crest = t.crest_diameter / 2.0;
        let mut blocks = Vec::new();
        let block = |motion, x: Real, z: Real, feed: Real| Block {
            motion,
            values: vec![2.0 * x, z],
            feed,
            spindle: None,
            comment: None,
            keep: vec![],
            number: None,
        };
        let clear = r_crest + s;
        for p in &passes {
            let r = r_crest - s * p.cumulative;
            let zs = c0 + p.offset;
            let ze = if towards < 0.0 {
                -length - run_in
            } else {
                run_in
            };
            blocks.push(block(Motion::Rapid, clear, zs, 0.0));
            blocks.push(block(Motion::Rapid, r, zs, 0.0));
            blocks.push(block(
                Motion::Thread {
                    lead: t.lead(),
                    start_deg: 360.0 * Real::from(p.start) / Real::from(t.starts),
                },
                r,
                ze,
                t.lead() * rpm,
            ));
            blocks.push(block(Motion::Rapid, clear, ze, 0.0));
        }
        let axis = |n: &str| ProgramAxis {
            name: n.into(),
            unit: "mm".into(),
        };
        let program = AxisProgram {
            name: "THREAD".into(),
            number: 1,
            machine: "fanuc-0i-tc".into(),
            control: "fanuc".into(),
            tool_number: 1,
            tool_name: "thread insert 60".into(),
            spindle_rpm: rpm,
            decimals: None,
            axes: vec![axis("X"), axis("Z")],
            blocks,
            setup: Default::default(),
            cycles: Vec::new(),
        };
        let lathe = ChainMachine::new(Machine::from_info(fanuc_0i_tc::describe()).unwrap());
        let req = ThreadRequest {
            section: t.clone(),
            flank_margin: 0.1,
            length,
            space_centre: c0,
            tolerances: ThreadTolerances {
                form: 0.01,
                thickness: 1.0,
                diameter: 1.0,
                position: 0.01,
                flank_angle: 0.1f64.to_radians(),
                lead: 0.01,
            },
            limits: Some(profile.limits.clone()),
            part: "thread",
            outside_diameter: None,
            pitch_shift: Vec::new(),
            place_shift: Vec::new(),
        };
        simulate(&program, &lathe, &Default::default(), &cutter, &req)
    }

    /// A metric thread simulated from its program: cut to the basic
    /// profile its pitch diameter is the basic 18.376 mm and beyond 6g's
    /// upper limit (18.334), named; aimed into the band (0.1 mm down: the
    /// cutter's pitch line as much deeper) it measures 0.1 mm less and
    /// holds; its flanks at 30 degrees.
    #[test]
    fn a_metric_thread_is_held_to_its_pitch_diameter() {
        let basic = cut_m20(0.0).unwrap();
        let d2 = basic.starts[0].pitch_diameter;
        assert!((d2 - 18.376).abs() < 2e-3, "{d2}");
        assert!(basic
            .verified()
            .is_err_and(|e| e.to_string().contains("start 1: pitch diameter 18.37")
                && e.to_string().contains("(ISO 965-1 6g)")));
        let aimed = cut_m20(0.1).unwrap();
        let d2 = aimed.starts[0].pitch_diameter;
        assert!((d2 - 18.276).abs() < 2e-3, "{d2}");
        let held = aimed.verified().unwrap();
        for a in [
            held.starts[0].left_angle_deg,
            held.starts[0].right_angle_deg,
        ] {
            assert!((a - 30.0).abs() < 0.05, "{a}");
        }
        // Over wires: the best wire 0.57735 P (1.4434 mm) laid against the
        // cut flanks measures what the formula gives at the pitch
        // diameter measured, within 1 um, inside what 6g allows (M moves
        // with the pitch diameter one for one at 60 degrees).
        let wire = held.wire.unwrap();
        assert!((wire - 2.5 / 3f64.sqrt()).abs() < 1e-12, "{wire}");
        let m = held.starts[0].over_wires.unwrap();
        let section =
            crate::families::thread::standards::metric(20.0, 2.5, false, "6g", 1, Hand::Right)
                .unwrap()
                .section;
        let want = section.over_wires(wire, d2).unwrap();
        assert!((m - want).abs() < 1e-3, "M {m} vs {want}");
        let [lo, hi] = held.over_wires_limits.unwrap();
        assert!(
            lo < m && m < hi && (hi - lo - 0.17).abs() < 1e-9,
            "{lo} {m} {hi}"
        );
    }

    /// An internal M30x2 6H cut from inside its bore: its pitch diameter
    /// measured from the cut as a gauge takes it (the simulation in rho =
    /// -r, turned back), held to 6H's 28.701 to 28.925 mm; cut 0.05 mm
    /// short of the basic it is refused naming the limit; the major (the
    /// root) beyond its least, the minor (the bore) within its band; the
    /// measurement between balls inside what 6H allows.
    #[test]
    fn an_internal_thread_is_cut_and_held_from_inside_its_bore() {
        let nut = standards::metric(30.0, 2.0, true, "6H", 1, Hand::Right).unwrap();
        let check = cut(&nut, 0.1, FlankOrder::Alternating).unwrap();
        assert!(check.internal, "{:?}", check.failures);
        assert!(!check.starts.is_empty(), "{:?}", check.failures);
        let s = &check.starts[0];
        assert!((s.pitch_diameter - 28.801).abs() < 2e-3, "{s:?}");
        for a in [s.left_angle_deg, s.right_angle_deg] {
            assert!((a - 30.0).abs() < 0.05, "{a}");
        }
        let l = check.limits.clone().unwrap();
        assert!((l.pitch_diameter.min - 28.701).abs() < 1e-3, "{l:?}");
        assert!((l.pitch_diameter.max - 28.925).abs() < 1e-3, "{l:?}");
        assert!(s.root_diameter >= l.root.min, "{s:?} {l:?}");
        assert!(l.crest.holds(s.tip_diameter, 1e-9), "{s:?} {l:?}");
        // Between balls: the pitch diameter less the wires' reach.
        let wire = check.wire.unwrap();
        let m = s.over_wires.unwrap();
        let want = nut.section.over_wires(wire, s.pitch_diameter).unwrap();
        assert!(
            (m - want).abs() < 1e-3 && m < s.pitch_diameter,
            "M {m} vs {want}"
        );
        let [lo, hi] = check.over_wires_limits.unwrap();
        assert!(lo < m && m < hi, "{lo} {m} {hi}");
        // The section's surface is the nut's inside.
        assert!(
            (check.radius_at(check.window.0 + 0.25) - s.tip_diameter / 2.0).abs() < 0.05,
            "{}",
            check.radius_at(check.window.0 + 0.25)
        );
        let _ = check.clone().verified().unwrap();
        // Its part: a nut of 45 mm round the thread, closed, its volume
        // between the cylinders' at its root and at its crest.
        let solid = crate::families::thread::thread_solid(&check, 30.0, 0.01, Some(45.0)).unwrap();
        solid.check_closed().unwrap();
        let tube = |r: Real| std::f64::consts::PI * (22.5f64.powi(2) - r * r) * 30.0;
        let v = solid.volume();
        assert!(
            tube(s.root_diameter / 2.0) < v && v < tube(s.tip_diameter / 2.0),
            "{} < {v} < {}",
            tube(s.root_diameter / 2.0),
            tube(s.tip_diameter / 2.0)
        );
        let (lo, hi) = solid.bounds();
        assert!(
            (hi[0] - 22.5).abs() < 1e-9 && (lo[2] + 30.0).abs() < 1e-9,
            "{lo:?} {hi:?}"
        );
        assert!(crate::families::thread::thread_solid(&check, 30.0, 0.01, Some(28.0)).is_err());
        // Its STEP: the nut's faces close a solid of the mesh's volume
        // (the mesh's chords inside the helical surface by at most 0.01).
        let sweep =
            crate::families::thread::ThreadSweep::new(&check, 30.0, 2.5e-4, Some(45.0)).unwrap();
        let fit = crate::step::swept_step("nut", "a nut", &sweep, 1e-3).unwrap();
        assert!(
            (fit.volume - v).abs() < 0.01 * 30.0 * 100.0,
            "{} vs {v}",
            fit.volume
        );
        let short = cut(&nut, -0.05, FlankOrder::Alternating).unwrap();
        let e = short.verified().unwrap_err().to_string();
        assert!(
            e.contains("start 1: pitch diameter 28.65")
                && e.contains("outside 28.7010 to 28.9250 mm (ISO 965-1 6H)"),
            "{e}"
        );
    }

    /// A left hand, two starts (M20x5(P2.5)-6g-LH): cut towards +Z with
    /// the spindle in M3, each start at its angle, both starts' pitch
    /// diameters hold 6g, and each start is found where its angle puts it
    /// (start 2 a pitch towards -Z of start 1 in the section at angle 0).
    /// Cut towards -Z, each block is refused naming the hand it cuts. Its
    /// solid winds left: the section at +90 degrees is the one at 0
    /// shifted a quarter lead towards -Z.
    #[test]
    fn a_left_hand_is_cut_towards_the_tailstock() {
        let lh = standards::metric(20.0, 2.5, false, "6g", 2, Hand::Left).unwrap();
        let check = cut_towards(&lh, 0.1, FlankOrder::Alternating, 1.0).unwrap();
        assert_eq!(check.hand, Hand::Left);
        let check = check.verified().unwrap();
        assert_eq!(check.starts.len(), 2);
        for s in &check.starts {
            assert!((s.pitch_diameter - 18.276).abs() < 2e-3, "{s:?}");
            assert!(s.position_error.abs() < 1e-3, "{s:?}");
        }
        // Every pass cut the start its angle names, at its own space.
        for p in &check.passes {
            assert!(p.offset.abs() < 1.0, "{p:?}");
        }
        assert!(check.passes.iter().any(|p| p.start == 1));
        let wrong = cut_towards(&lh, 0.1, FlankOrder::Alternating, -1.0).unwrap();
        let e = wrong.verified().unwrap_err().to_string();
        assert!(
            e.contains("towards -Z (the chuck) with the spindle in M3 cuts a right-hand helix, and the thread is left-handed"),
            "{e}"
        );
        // The solid: a vertex at angle phi lies on the section at 0
        // shifted by -lead phi / 2 pi (a right hand's, +).
        let solid = crate::families::thread::thread_solid(&check, 30.0, 0.01, None).unwrap();
        solid.check_closed().unwrap();
        let (w0, lead) = check.window;
        let mut worst: Real = 0.0;
        for p in &solid.positions {
            let (r, phi) = (p[0].hypot(p[1]), p[1].atan2(p[0]));
            if r > 1.0 && p[2] < -1.0 && p[2] > -29.0 {
                let z = p[2] + lead * phi / std::f64::consts::TAU;
                worst = worst.max((check.radius_at(w0 + (z - w0).rem_euclid(lead)) - r).abs());
            }
        }
        assert!(worst < 0.02, "{worst}");
        let sweep = crate::families::thread::ThreadSweep::new(&check, 30.0, 2.5e-4, None).unwrap();
        use crate::step::Sections;
        let q = sweep.point(0, 0.5, 0.5);
        let phi = q[1].atan2(q[0]);
        let z = q[2] + lead * phi / std::f64::consts::TAU;
        let r = q[0].hypot(q[1]);
        assert!(
            (check.radius_at(w0 + (z - w0).rem_euclid(lead)) - r).abs() < 0.02,
            "{r}"
        );
    }

    /// A 7/45 buttress (1-8, its load flank the space's towards +Z), its
    /// roughing passes on the load flank: each flank holds its own angle,
    /// 45 and 7 degrees, and the pitch diameter its aim within its stated
    /// band.
    #[test]
    fn a_buttress_holds_its_two_flank_angles() {
        let stated = standards::StatedLimits {
            pitch_allowance: 0.0,
            pitch_tolerance: 0.1,
            crest_tolerance: 0.2,
            root_tolerance: 0.3,
        };
        let profile = standards::buttress(
            1.0,
            8.0,
            false,
            standards::LoadFlank::TowardsChuck,
            1,
            Hand::Right,
            stated,
        )
        .unwrap();
        let check = cut(&profile, 0.05, FlankOrder::Right)
            .unwrap()
            .verified()
            .unwrap();
        let s = &check.starts[0];
        assert!(
            (s.left_angle_deg - 45.0).abs() < 0.05,
            "{}",
            s.left_angle_deg
        );
        assert!(
            (s.right_angle_deg - 7.0).abs() < 0.05,
            "{}",
            s.right_angle_deg
        );
        let want = profile.section.pitch_diameter - 0.05;
        assert!(
            (s.pitch_diameter - want).abs() < 2e-3,
            "{} vs {want}",
            s.pitch_diameter
        );
        assert_eq!(check.nominal_flanks_deg.map(Real::round), [45.0, 7.0]);
        // The verdict's flank-angle figure takes each flank against its
        // own angle (it once took both against the left's 45 degrees,
        // and the 7 degree flank stood 38 degrees off).
        let (figures, _) = check.findings();
        let angle = figures.iter().find(|f| f.name == "flank angle").unwrap();
        assert!(angle.value.abs() < 0.05, "{angle:?}");
    }

    /// A ZI worm's flanks are curves in the axial section (its axial angle
    /// turns from 18.2 to 21.2 degrees over the depth): a straight cutter
    /// on their tangent at the pitch line leaves them tens of micrometres
    /// off, refused naming the flank's form; the form cutter ground to them
    /// cuts them within a micrometre, its angles those of the curve's
    /// line. A ZN worm's form cutter (its flanks nearly straight) leaves
    /// the ZI worm's curve as the straight one does.
    #[test]
    fn a_zi_worm_is_held_to_its_curved_flanks() {
        use crate::families::thread::{WormProfile, WormSizes};
        let worm = |profile| {
            WormSizes::with_profile(5.0, 2, 50.0, 0.2, 20f64.to_radians(), None, profile)
                .unwrap()
                .profile(0.05, 0.02)
        };
        let zi = worm(WormProfile::ZI);
        let form = |t: &ThreadSection| {
            ThreadCutter::ground_to(t.form, t.root_diameter / 2.0, 0.15, 13.0).unwrap()
        };
        let check = cut_by(&zi, 0.0, FlankOrder::Radial, -1.0, form).unwrap();
        let worst = check
            .starts
            .iter()
            .map(|s| s.left_form.abs().max(s.right_form.abs()))
            .fold(0.0, Real::max);
        assert!(worst < 1e-3, "{worst}");
        let nominal = check.nominal_flanks_deg;
        for s in &check.starts {
            assert!((s.left_angle_deg - nominal[0]).abs() < 5e-3, "{s:?}");
            assert!((s.right_angle_deg - nominal[1]).abs() < 5e-3, "{s:?}");
        }
        check.clone().verified().unwrap();
        // The curve's line over the measured band is steeper than its
        // tangent at the root, less steep than its tangent at the tip.
        let at = |r: Real| zi.section.form.axial_angle(r).unwrap().to_degrees();
        assert!(
            at(19.0) < nominal[1] && nominal[1] < at(30.0),
            "{nominal:?}"
        );
        // A straight cutter on the curve's tangent at the pitch line (the
        // space's width there, no side steps) leaves the curve either side.
        let straight = |t: &ThreadSection| {
            let a = t.flanks[0];
            let tip = t.space_at_pitch - (t.pitch_diameter - t.root_diameter) * a.tan();
            ThreadCutter::new(tip, 0.15, a, a, 13.0).unwrap()
        };
        let e = cut_by(&zi, 0.0, FlankOrder::Radial, -1.0, straight)
            .unwrap()
            .verified()
            .unwrap_err()
            .to_string();
        assert!(e.contains("flank: material left"), "{e}");
        // The ZN worm's cutter in the ZI worm's space cuts beyond it.
        let e = cut_by(&zi, 0.0, FlankOrder::Radial, -1.0, |_| {
            let a = 20f64.to_radians();
            let zn = WormSizes::with_profile(5.0, 2, 50.0, 0.2, a, None, WormProfile::ZN).unwrap();
            ThreadCutter::ground_to(zn.section().form, 19.0, 0.15, 13.0).unwrap()
        })
        .unwrap()
        .verified()
        .unwrap_err()
        .to_string();
        assert!(e.contains("start 1, left flank: material left"), "{e}");
    }
}
