//! Profiles: the "digital array" `(z_i, x_i)` of a 2-D curve (docs/math.md §2.1, §3.2).
//!
//! A [`Profile`] is a curve `x(z)` sampled at strictly increasing `z`: the
//! radius of a body of revolution along its axis, a groove's depth along the
//! roll angle, a table of measurements. It may carry analytic first and
//! second derivatives (generators know them); otherwise derivatives are
//! estimated from the samples by three-point formulas.
//!
//! ```
//! use pilgrim_kernel::Profile;
//! let p = Profile::new(vec![0.0, 1.0, 2.0, 3.0], vec![1.0, 2.0, 5.0, 10.0]).unwrap();
//! assert_eq!(p.divided_differences(), vec![1.0, 3.0, 5.0]);
//! assert_eq!(p.second_derivatives()[1], 2.0); // x = z^2 + 1 exactly
//! ```

mod builder;
mod dxf;
mod ellipse;
mod helicoid;
mod law;
mod simplify;
mod smooth;
mod spline;
mod stations;
mod table;
mod workbook;

pub use builder::{Bulge, ProfileBuilder};
pub use dxf::{profile_from_dxf, DxfError, DxfOptions};
pub use ellipse::EllipseSection;
pub use helicoid::FlankForm;
pub use law::{uniform_grid, MandrelLaw};
pub use simplify::{simplify_polyline, Polyline};
pub use smooth::Smoothing;
pub use spline::Swing;
pub use stations::{aimed, polyline_through, station_sources, CornerForm};

pub use table::{
    read_table, read_table_bytes, read_table_str, Table, TableError, TableFormat, MAX_CELLS,
};

use crate::input::InputError;
use crate::math::{fixed, Real};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// The fewest points a profile may have.
pub const MIN_POINTS: usize = 3;

/// The most nodes a generator or resampling will make (10 million: 80 MB per
/// array). A step that would need more is refused rather than exhausting
/// memory on a mistyped value.
pub const MAX_NODES: usize = 10_000_000;

/// Checks a node count a generator is about to make.
pub(crate) fn check_node_count(what: &str, count: Real, step: Real) -> Result<usize, InputError> {
    if count.is_finite() && count <= MAX_NODES as Real {
        Ok(count as usize)
    } else {
        Err(InputError::out_of_range(
            what,
            step,
            format!("a step giving at most {MAX_NODES} nodes (this one gives {count:.3e})"),
        ))
    }
}

/// Errors of profiles, their generators, equidistants and envelopes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProfileError {
    /// The run's time limit passed while this was being done.
    #[error(transparent)]
    OverTime(#[from] crate::budget::OverTime),
    /// A rejected number or array.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The tool is rounder than the profile: its radius exceeds the
    /// profile's radius of curvature where the profile is concave seen from
    /// the tool (docs/math.md §2.2). Every such place is listed.
    #[error("tool radius {tool_radius} mm exceeds the profile's radius of curvature at {} place(s): {}",
        violations.len(), list_violations(violations))]
    CurvatureBelowTool {
        /// The tool's radius (mm).
        tool_radius: Real,
        /// Each violating node.
        violations: Vec<CurvatureViolation>,
    },
    /// Two chained segments do not meet.
    #[error(
        "segment {segment} starts at x = {x_start} but the profile is at x = {x_end} (z = {z})"
    )]
    Discontinuous {
        /// Index of the segment that does not meet the previous one.
        segment: usize,
        /// Where they should meet.
        z: Real,
        /// The previous segment's end.
        x_end: Real,
        /// This segment's start.
        x_start: Real,
    },
    /// An arc whose radius is too small for its chord, or which would not be
    /// a function of z.
    #[error(
        "segment {segment}: an arc of radius {radius} cannot join points {chord} mm apart as x(z)"
    )]
    BadArc {
        /// Index of the segment.
        segment: usize,
        /// The radius given.
        radius: Real,
        /// The chord between its ends.
        chord: Real,
    },
    /// A query outside the profile's z range.
    #[error("{what} at z = {} is outside the profile's range [{}, {}]", fixed(*z, 4), fixed(*z_min, 4), fixed(*z_max, 4))]
    OutsideProfile {
        /// What was asked.
        what: String,
        /// The z asked for.
        z: Real,
        /// First z of the profile.
        z_min: Real,
        /// Last z of the profile.
        z_max: Real,
    },
}

/// A node where the tool's radius exceeds the profile's radius of curvature.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurvatureViolation {
    /// Index of the node.
    pub index: usize,
    /// Its z (mm).
    pub z: Real,
    /// The profile's radius of curvature there (mm).
    pub rho: Real,
    /// What of the drawing the profile takes there ([`Source`]), where
    /// the profile says.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
}

fn list_violations(v: &[CurvatureViolation]) -> String {
    const SHOWN: usize = 12;
    let mut s: Vec<String> = v
        .iter()
        .take(SHOWN)
        .map(|c| match c.rho {
            // A kink: no fillet to judge, a corner the tool cannot enter.
            0.0 => format!(
                "z = {} (a corner: a fillet of at least the tool's radius grinds it{})",
                fixed(c.z, 4),
                from_source(c)
            ),
            rho => format!(
                "z = {} (rho = {}{})",
                fixed(c.z, 4),
                fixed(rho, 4),
                from_source(c)
            ),
        })
        .collect();
    if v.len() > SHOWN {
        s.push(format!("... and {} more", v.len() - SHOWN));
    }
    s.join(", ")
}

/// `; the nominal's <source>` where a violation's source is known.
fn from_source(c: &CurvatureViolation) -> String {
    (c.source.as_ref()).map_or(String::new(), |s| format!("; the nominal's {s}"))
}

/// How a profile without analytic derivatives is interpolated between its
/// nodes: a stated choice, since a table's curve between rows is not in
/// the table (a groove moves by microns between the choices).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Interpolation {
    /// Cubic Hermite, each node's slope that of the parabola through it
    /// and its two neighbours: C1, exact for parabolas, but it overshoots
    /// beside a flat run (a node ending a constant stretch takes a slope
    /// from the node beyond it).
    #[default]
    Parabolic,
    /// Monotone cubic Hermite (Fritsch–Carlson, as PCHIP): C1, each
    /// node's slope the weighted harmonic mean of its two sides, zero
    /// where they differ in sign or one is zero: no overshoot, monotone
    /// stretches stay monotone and a constant stretch stays exactly flat.
    Monotone,
    /// Straight lines between nodes: C0, with a kink at every node.
    Linear,
    /// The natural cubic spline: C2, its second derivative zero at both
    /// ends; smooth through a drawing's stations, but it may swing beyond
    /// them beside a flat run ([`Profile::swing`]).
    Natural,
}

impl Interpolation {
    /// The interpolation named `name` (one of [`Self::NAMES`], or
    /// `pchip` for `monotone`), or `None`.
    pub fn named(name: &str) -> Option<Self> {
        match name.trim().to_ascii_lowercase().as_str() {
            "parabolic" => Some(Self::Parabolic),
            "monotone" | "pchip" => Some(Self::Monotone),
            "linear" => Some(Self::Linear),
            "natural" => Some(Self::Natural),
            _ => None,
        }
    }

    /// Its name, as [`Self::named`] reads it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Parabolic => "parabolic",
            Self::Monotone => "monotone",
            Self::Linear => "linear",
            Self::Natural => "natural",
        }
    }

    /// The interpolations' names, as a message lists them.
    pub const NAMES: &'static str = "parabolic, monotone, linear, natural";
}

/// A curve `x(z)` sampled at strictly increasing `z`. See the [module docs](self).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    z: Vec<Real>,
    x: Vec<Real>,
    /// How it is interpolated between nodes without analytic derivatives.
    #[serde(default)]
    interpolation: Interpolation,
    /// Analytic dx/dz at the nodes, when known.
    dx: Option<Vec<Real>>,
    /// Analytic d2x/dz2 at the nodes, when known (may be infinite at a kink).
    d2x: Option<Vec<Real>>,
    /// The estimated slopes, made on first use (evaluating point by point
    /// must not estimate them again each time: that is O(nodes) a call).
    #[serde(skip)]
    estimated: SlopeCache,
    /// The stretches a drawing tolerances on their own ([`Band`]), in z
    /// order; none where the whole profile holds one tolerance.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    bands: Vec<Band>,
    /// What of a drawing each stretch comes from ([`Source`]), in z order;
    /// none for a profile from samples.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    sources: Vec<Source>,
}

/// What a profile says of a stretch of z ([`Band`], [`Source`]).
trait Stretch: Clone {
    /// Where it starts and ends (z, mm).
    fn span(&self) -> (Real, Real);
    /// The same over `from` to `to`.
    fn spanning(&self, from: Real, to: Real) -> Self;
}

/// [`Stretch`] for a struct with `from` and `to`.
macro_rules! stretch {
    ($($t:ty),*) => {$(
        impl Stretch for $t {
            fn span(&self) -> (Real, Real) {
                (self.from, self.to)
            }
            fn spanning(&self, from: Real, to: Real) -> Self {
                Self { from, to, ..self.clone() }
            }
        }
    )*};
}
stretch!(Band, Source);

/// `items` sorted by where they start.
fn sorted<T: Stretch>(mut items: Vec<T>) -> Vec<T> {
    items.sort_by(|a, b| a.span().0.total_cmp(&b.span().0));
    items
}

/// Those of `items` over `from` to `to`, cut to it.
fn clipped<T: Stretch>(items: &[T], from: Real, to: Real) -> Vec<T> {
    (items.iter())
        .filter(|s| s.span().1 >= from && s.span().0 <= to)
        .map(|s| s.spanning(s.span().0.max(from), s.span().1.min(to)))
        .collect()
}

/// What of a drawing a stretch of a profile comes from (a station, an
/// element of a chain, a DXF entity), as messages name it: where the
/// nominal itself cannot be ground, a message names it there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Source {
    /// Where it starts (z, mm).
    pub from: Real,
    /// Where it ends (z, mm).
    pub to: Real,
    /// Its index in what built the profile (a station's, a segment's).
    pub index: usize,
    /// As messages name it ("station 7 (z = 360 mm, x = 9.135 mm)").
    pub label: String,
}

/// A stretch of a profile a drawing gives its own tolerance (a station's
/// or an element's fit or limits): the profile there is aimed at the
/// band's middle, and a verification judges the stretch against its
/// half-width instead of the general tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Band {
    /// Where it starts (z, mm).
    pub from: Real,
    /// Where it ends (z, mm; `from` for a single station).
    pub to: Real,
    /// Half the band's width on the radius (mm): the profile is its
    /// middle.
    pub half: Real,
    /// Where the drawing gives it, as a message names it ("stations 1 to
    /// 2 (z = 0 to 60 mm), d 18 h4: 0/-0.005 mm").
    pub source: String,
}

/// A profile's estimated node slopes, computed once; not part of what the
/// profile is (equal profiles are equal whether or not it is filled).
#[derive(Debug, Clone, Default)]
struct SlopeCache(std::sync::OnceLock<Vec<Real>>);

impl PartialEq for SlopeCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Validates an abscissa array: finite, long enough, strictly increasing.
pub(crate) fn check_abscissa(what: &str, z: &[Real]) -> Result<(), InputError> {
    if z.len() < MIN_POINTS {
        return Err(InputError::TooFew {
            what: what.to_owned(),
            got: z.len(),
            min: MIN_POINTS,
        });
    }
    crate::math::all_finite(what, z)?;
    if let Some(i) = (1..z.len()).find(|&i| z[i] <= z[i - 1]) {
        return Err(InputError::NotIncreasing {
            what: what.to_owned(),
            index: i,
            prev: z[i - 1],
            value: z[i],
        });
    }
    Ok(())
}

fn check_same_len(what: &str, a: usize, b: usize) -> Result<(), InputError> {
    if a != b {
        return Err(InputError::LengthMismatch {
            what: what.to_owned(),
            left: a,
            right: b,
        });
    }
    Ok(())
}

impl Profile {
    /// A profile from its samples.
    ///
    /// # Failures
    /// Fewer than [`MIN_POINTS`] points, arrays of different lengths, a
    /// non-finite value, or z not strictly increasing: each names the index.
    pub fn new(z: Vec<Real>, x: Vec<Real>) -> Result<Self, ProfileError> {
        check_same_len("profile z and x", z.len(), x.len())?;
        check_abscissa("profile z", &z)?;
        crate::math::all_finite("profile x", &x)?;
        Ok(Self {
            z,
            x,
            interpolation: Interpolation::default(),
            dx: None,
            d2x: None,
            estimated: SlopeCache::default(),
            bands: Vec::new(),
            sources: Vec::new(),
        })
    }

    /// A profile with analytic first and second derivatives at its nodes.
    /// Second derivatives may be infinite (a kink: `+inf` where the slope
    /// jumps up, `-inf` where it jumps down), never NaN.
    ///
    /// # Failures
    /// As [`Profile::new`], and for derivatives of the wrong length or NaN.
    pub fn with_derivatives(
        z: Vec<Real>,
        x: Vec<Real>,
        dx: Vec<Real>,
        d2x: Vec<Real>,
    ) -> Result<Self, ProfileError> {
        let mut p = Self::new(z, x)?;
        check_same_len("profile z and dx/dz", p.z.len(), dx.len())?;
        check_same_len("profile z and d2x/dz2", p.z.len(), d2x.len())?;
        crate::math::all_finite("profile dx/dz", &dx)?;
        if let Some(i) = d2x.iter().position(|v| v.is_nan()) {
            return Err(InputError::NonFinite {
                what: "profile d2x/dz2".into(),
                index: Some(i),
                value: d2x[i],
            }
            .into());
        }
        p.dx = Some(dx);
        p.d2x = Some(d2x);
        Ok(p)
    }

    /// The profile interpolated between its nodes by `interpolation`
    /// (analytic derivatives, if it has them, still rule).
    pub fn with_interpolation(mut self, interpolation: Interpolation) -> Self {
        self.interpolation = interpolation;
        self.estimated = SlopeCache::default();
        self
    }

    /// The profile with its own tolerance `bands` ([`Band`]), sorted by
    /// where they start.
    pub fn with_bands(mut self, bands: Vec<Band>) -> Self {
        self.bands = sorted(bands);
        self
    }

    /// The stretches a drawing tolerances on their own.
    pub fn bands(&self) -> &[Band] {
        &self.bands
    }

    /// The profile with what of a drawing each stretch comes from
    /// ([`Source`]), sorted by where they start.
    pub fn with_sources(mut self, sources: Vec<Source>) -> Self {
        self.sources = sorted(sources);
        self
    }

    /// What of a drawing each stretch comes from.
    pub fn sources(&self) -> &[Source] {
        &self.sources
    }

    /// What of a drawing the profile takes at `z` (the first stretch
    /// holding it), if it says.
    pub fn source_at(&self, z: Real) -> Option<&Source> {
        self.sources.iter().find(|s| z >= s.from && z <= s.to)
    }

    /// How the profile is interpolated between its nodes.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// Number of nodes (at least [`MIN_POINTS`]).
    pub fn len(&self) -> usize {
        self.z.len()
    }

    /// Always `false`: a profile has at least [`MIN_POINTS`] nodes.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The abscissae (mm).
    pub fn z(&self) -> &[Real] {
        &self.z
    }

    /// The ordinates (mm).
    pub fn x(&self) -> &[Real] {
        &self.x
    }

    /// First and last z.
    pub fn z_range(&self) -> (Real, Real) {
        (self.z[0], self.z[self.z.len() - 1])
    }

    /// Whether the derivatives are analytic (given by a generator).
    pub fn has_analytic_derivatives(&self) -> bool {
        self.dx.is_some()
    }

    /// Drops the analytic derivatives, so that estimates are used.
    pub fn without_derivatives(mut self) -> Self {
        self.dx = None;
        self.d2x = None;
        self
    }

    /// First divided differences `(x_{i+1} - x_i) / (z_{i+1} - z_i)`, one per
    /// interval (`len() - 1` values).
    pub fn divided_differences(&self) -> Vec<Real> {
        self.z
            .windows(2)
            .zip(self.x.windows(2))
            .map(|(z, x)| (x[1] - x[0]) / (z[1] - z[0]))
            .collect()
    }

    /// Second divided differences times two, `2 x[z_{i-1}, z_i, z_{i+1}]`:
    /// the second derivative of the parabola through three neighbours, one
    /// per interior node (`len() - 2` values).
    pub fn second_divided_differences(&self) -> Vec<Real> {
        let d = self.divided_differences();
        (1..self.len() - 1)
            .map(|i| 2.0 * (d[i] - d[i - 1]) / (self.z[i + 1] - self.z[i - 1]))
            .collect()
    }

    /// dx/dz at every node: analytic if known, else the derivative of the
    /// parabola through the node and its neighbours (one-sided at the ends).
    ///
    /// # Tolerance
    /// The estimate's error is at most `h_i h_{i+1} max|x'''| / 6` inside
    /// and `h (h + h') max|x'''| / 6` at the ends, for steps `h`.
    pub fn slopes(&self) -> Cow<'_, [Real]> {
        if let Some(d) = &self.dx {
            return Cow::Borrowed(d);
        }
        Cow::Borrowed(self.estimated.0.get_or_init(|| self.estimate_slopes()))
    }

    /// The node slopes the interpolation uses ([`Self::slopes`]).
    fn estimate_slopes(&self) -> Vec<Real> {
        match self.interpolation {
            Interpolation::Parabolic => self.parabolic_slopes(),
            Interpolation::Monotone => self.monotone_slopes(),
            Interpolation::Natural => spline::natural_slopes(&self.z, &self.x),
            Interpolation::Linear => {
                // Each node the mean of its two sides (the kinks' slopes
                // are not used by the interpolation itself).
                let d = self.divided_differences();
                let n = self.len();
                (0..n)
                    .map(|i| match i {
                        0 => d[0],
                        _ if i == n - 1 => d[n - 2],
                        _ => 0.5 * (d[i - 1] + d[i]),
                    })
                    .collect()
            }
        }
    }

    /// Fritsch–Carlson slopes (PCHIP): inside, the weighted harmonic mean
    /// of the two sides' differences, zero where they differ in sign or
    /// one is zero; at the ends the three-point estimate, kept to the
    /// first difference's sign and to three times it.
    fn monotone_slopes(&self) -> Vec<Real> {
        let (z, n) = (&self.z, self.len());
        let d = self.divided_differences();
        let h: Vec<Real> = z.windows(2).map(|w| w[1] - w[0]).collect();
        let mut out = vec![0.0; n];
        for i in 1..n - 1 {
            if d[i - 1] * d[i] > 0.0 {
                let (w1, w2) = (2.0 * h[i] + h[i - 1], h[i] + 2.0 * h[i - 1]);
                out[i] = (w1 + w2) / (w1 / d[i - 1] + w2 / d[i]);
            }
        }
        let end = |h0: Real, h1: Real, d0: Real, d1: Real| {
            let m = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
            if m * d0 <= 0.0 {
                0.0
            } else if d0 * d1 < 0.0 && m.abs() > 3.0 * d0.abs() {
                3.0 * d0
            } else {
                m
            }
        };
        out[0] = end(h[0], h[1], d[0], d[1]);
        out[n - 1] = end(h[n - 2], h[n - 3], d[n - 2], d[n - 3]);
        out
    }

    /// The three-point (parabola) estimate of the slopes.
    fn parabolic_slopes(&self) -> Vec<Real> {
        let (z, x) = (&self.z, &self.x);
        let n = z.len();
        let mut out = vec![0.0; n];
        // Derivative at node k of the parabola through nodes a, b, c.
        let parabola = |k: usize, a: usize, b: usize, c: usize| -> Real {
            let (za, zb, zc, zk) = (z[a], z[b], z[c], z[k]);
            x[a] * ((zk - zb) + (zk - zc)) / ((za - zb) * (za - zc))
                + x[b] * ((zk - za) + (zk - zc)) / ((zb - za) * (zb - zc))
                + x[c] * ((zk - za) + (zk - zb)) / ((zc - za) * (zc - zb))
        };
        out[0] = parabola(0, 0, 1, 2);
        for i in 1..n - 1 {
            out[i] = parabola(i, i - 1, i, i + 1);
        }
        out[n - 1] = parabola(n - 1, n - 3, n - 2, n - 1);
        out
    }

    /// d2x/dz2 at every node: analytic if known, else the second divided
    /// difference of the node's neighbourhood (the nearest one at the ends).
    pub fn second_derivatives(&self) -> Cow<'_, [Real]> {
        if let Some(d) = &self.d2x {
            return Cow::Borrowed(d);
        }
        let mut d2 = self.second_divided_differences();
        let (first, last) = (d2[0], d2[d2.len() - 1]);
        d2.insert(0, first);
        d2.push(last);
        Cow::Owned(d2)
    }

    /// Tangent angle `gamma_i = atan(dx/dz)` at every node (rad).
    pub fn tangent_angles(&self) -> Vec<Real> {
        self.slopes().iter().map(|s| s.atan()).collect()
    }

    /// Signed curvature `x'' / (1 + x'^2)^(3/2)` at every node (1/mm):
    /// positive where the profile is concave seen from +x (its centre of
    /// curvature on the +x side).
    pub fn curvature(&self) -> Vec<Real> {
        let (d1, d2) = (self.slopes(), self.second_derivatives());
        d1.iter()
            .zip(d2.iter())
            .map(|(a, b)| curvature_of(*a, *b))
            .collect()
    }

    /// Radius of curvature `1 / |curvature|` at every node (mm; infinite on
    /// straight parts, 0 at a kink).
    pub fn curvature_radius(&self) -> Vec<Real> {
        self.curvature().iter().map(|k| 1.0 / k.abs()).collect()
    }

    /// Cumulative arc length from the first node, by chords (mm).
    ///
    /// # Tolerance
    /// A chord is shorter than its arc by about `h^3 kappa^2 / 24` per step.
    pub fn arc_length(&self) -> Vec<Real> {
        let mut s = Vec::with_capacity(self.len());
        let mut acc = 0.0;
        s.push(0.0);
        for i in 1..self.len() {
            acc += (self.z[i] - self.z[i - 1]).hypot(self.x[i] - self.x[i - 1]);
            s.push(acc);
        }
        s
    }

    /// x at any z of the range, by cubic Hermite interpolation with the
    /// node slopes of [`Self::slopes`] (linear beside a kink, where a node's
    /// slope is ambiguous); the slopes are estimated once per profile.
    ///
    /// # Failures
    /// z outside the profile's range, or not finite.
    pub fn eval(&self, z: Real) -> Result<Real, ProfileError> {
        self.check_inside(std::slice::from_ref(&z))?;
        Ok(self.value_at(&self.slopes(), z))
    }

    /// x, dx/dz and d2x/dz2 at any z of the range, of the curve
    /// [`Self::eval`] reads: the cubic Hermite's own derivatives on its
    /// interval (at a node, those of the interval it begins), a straight
    /// interval's slope and zero beside a kink or on a linear profile.
    ///
    /// # Failures
    /// z outside the profile's range, or not finite.
    pub fn jet(&self, z: Real) -> Result<[Real; 3], ProfileError> {
        self.check_inside(std::slice::from_ref(&z))?;
        Ok(self.jet_in(self.interval(z), z))
    }

    /// [`Self::jet`] on the interval `i`.
    fn jet_in(&self, i: usize, z: Real) -> [Real; 3] {
        let (z0, z1, x0, x1) = (self.z[i], self.z[i + 1], self.x[i], self.x[i + 1]);
        let h = z1 - z0;
        let kinked =
            (self.d2x.as_deref()).is_some_and(|d2| d2[i].is_infinite() || d2[i + 1].is_infinite());
        if kinked || (self.interpolation == Interpolation::Linear && self.dx.is_none()) {
            let t = ((z - z0) / h).clamp(0.0, 1.0);
            return [x0 + t * (x1 - x0), (x1 - x0) / h, 0.0];
        }
        let s = self.slopes();
        let u = ((z - z0) / h).clamp(0.0, 1.0);
        let (m0, m1) = (h * s[i], h * s[i + 1]);
        // x(u) = x0 + a u + b u^2 + c u^3 (as in `spline::largest_swing`).
        let (a, b, c) = (
            m0,
            3.0 * (x1 - x0) - 2.0 * m0 - m1,
            m0 + m1 - 2.0 * (x1 - x0),
        );
        [
            x0 + u * (a + u * (b + u * c)),
            (a + u * (2.0 * b + 3.0 * c * u)) / h,
            (2.0 * b + 6.0 * c * u) / (h * h),
        ]
    }

    /// The profile over `[from, to]` only: its nodes inside, and the curve
    /// [`Self::eval`] reads at the two ends, with its derivatives there
    /// ([`Self::jet`]: at a kink, the side inside the range): a ground
    /// stretch of a whole part's outline.
    ///
    /// # Failures
    /// `from` or `to` outside the range or not finite; fewer than
    /// [`MIN_POINTS`] nodes between them.
    pub fn between(&self, from: Real, to: Real) -> Result<Profile, ProfileError> {
        let (d1, d2) = (self.slopes(), self.second_derivatives());
        let mut out: [Vec<Real>; 4] = Default::default();
        let mut push = |v: [Real; 4]| out.iter_mut().zip(v).for_each(|(c, v)| c.push(v));
        let [x, s, k] = self.jet(from)?;
        push([from, x, s, k]);
        for i in (0..self.len()).filter(|&i| self.z[i] > from && self.z[i] < to) {
            push([self.z[i], self.x[i], d1[i], d2[i]]);
        }
        // At `to`, the interval ending there.
        self.check_inside(std::slice::from_ref(&to))?;
        let mut i = self.interval(to);
        if i > 0 && self.z[i] == to {
            i -= 1;
        }
        let [x, s, k] = self.jet_in(i, to);
        push([to, x, s, k]);
        let [z, x, d1, d2] = out;
        // The bands and sources over the stretch kept, cut to it.
        Ok(Profile::with_derivatives(z, x, d1, d2)?
            .with_interpolation(self.interpolation)
            .with_bands(clipped(&self.bands, from, to))
            .with_sources(clipped(&self.sources, from, to)))
    }

    /// Where the profile between two nodes goes furthest beyond the
    /// range of those two nodes' values (a drawing's stations: the
    /// interpolation's own swing, which the drawing does not give), or
    /// `None` where it stays within them everywhere (a linear or monotone
    /// profile always does).
    pub fn swing(&self) -> Option<Swing> {
        if self.interpolation == Interpolation::Linear && self.dx.is_none() {
            return None;
        }
        // An interval beside a kink is straight (see `value_at`).
        let straight = |i: usize| {
            (self.d2x.as_deref()).is_some_and(|d2| d2[i].is_infinite() || d2[i + 1].is_infinite())
        };
        spline::largest_swing(&self.z, &self.x, &self.slopes(), &straight)
    }

    /// x at many z (as [`Self::eval`]).
    ///
    /// # Failures
    /// A z outside the profile's range, or not finite (the first one).
    pub fn eval_many(&self, zs: &[Real]) -> Result<Vec<Real>, ProfileError> {
        self.check_inside(zs)?;
        let slopes = self.slopes();
        Ok(zs.iter().map(|&z| self.value_at(&slopes, z)).collect())
    }

    /// Every z of `zs` finite and inside the range, or the first that is
    /// not.
    fn check_inside(&self, zs: &[Real]) -> Result<(), ProfileError> {
        let (lo, hi) = self.z_range();
        if let Some(&z) = zs.iter().find(|z| !(lo..=hi).contains(*z)) {
            crate::math::finite("profile query z", z)?;
            return Err(ProfileError::OutsideProfile {
                what: "profile value".into(),
                z,
                z_min: lo,
                z_max: hi,
            });
        }
        Ok(())
    }

    /// The interval `z` lies in: the last node at or below it, at most the
    /// last interval's (the first for a z below the range). Guessed as if
    /// the nodes were evenly spaced and checked, two neighbours tried, then
    /// sought by bisection: a table at an even step (the groove's, a
    /// correction's grid) is evaluated millions of times a run.
    fn interval(&self, z: Real) -> usize {
        let zs = &self.z;
        let last = zs.len() - 2;
        let fits = |i: usize| (i == 0 || zs[i] <= z) && (i == last || zs[i + 1] > z);
        let span = zs[last + 1] - zs[0];
        let guess = ((z - zs[0]) / span * (last + 1) as Real).floor();
        let mut i = if guess.is_nan() || guess < 0.0 {
            0
        } else {
            (guess as usize).min(last)
        };
        for _ in 0..3 {
            if fits(i) {
                return i;
            }
            if i > 0 && zs[i] > z {
                i -= 1;
            } else {
                i = (i + 1).min(last);
            }
        }
        crate::math::floor_index(zs, z).unwrap_or(0).min(last)
    }

    /// x at `z` (inside the range) with the node `slopes`.
    fn value_at(&self, slopes: &[Real], z: Real) -> Real {
        let i = self.interval(z);
        let linear = |i: usize| {
            let t = ((z - self.z[i]) / (self.z[i + 1] - self.z[i])).clamp(0.0, 1.0);
            self.x[i] + t * (self.x[i + 1] - self.x[i])
        };
        if self.interpolation == Interpolation::Linear && self.dx.is_none() {
            return linear(i);
        }
        // Beside a kink (marked by an infinite second derivative) the
        // node's slope is only the mean of its two sides: interpolate
        // that interval linearly rather than bend it.
        match self.d2x.as_deref() {
            Some(d2) if d2[i].is_infinite() || d2[i + 1].is_infinite() => linear(i),
            _ => hermite_in(&self.z, &self.x, slopes, i, z),
        }
    }

    /// The profile with `dx` added where `z_from <= z <= z_to` (a stock
    /// allowance over a stretch: a blank). Where the raise begins and ends
    /// the profile steps between two neighbouring nodes: those nodes are
    /// kinks, so the step is a straight line (a cubic through it would
    /// overshoot the raised stretch by a tenth of the step), the same line
    /// a polyline of the nodes has; elsewhere the profile keeps its slopes.
    ///
    /// # Failures
    /// A `dx` or bound that is not finite.
    pub fn raised(&self, z_from: Real, z_to: Real, dx: Real) -> Result<Profile, ProfileError> {
        crate::math::finite("raise from z", z_from)?;
        crate::math::finite("raise to z", z_to)?;
        crate::math::finite("raise by", dx)?;
        let inside = |z: &Real| (z_from..=z_to).contains(z);
        let x: Vec<Real> = self
            .z()
            .iter()
            .zip(self.x())
            .map(|(z, x)| if inside(z) { x + dx } else { *x })
            .collect();
        let slopes = self.slopes().into_owned();
        let mut d2x = self.second_derivatives().into_owned();
        let n = self.z.len();
        for i in 0..n - 1 {
            if inside(&self.z[i]) != inside(&self.z[i + 1]) && dx != 0.0 {
                // The step up (or down) between nodes i and i + 1.
                let up = (x[i + 1] - x[i]) / (self.z[i + 1] - self.z[i]) > slopes[i];
                d2x[i] = if up {
                    Real::INFINITY
                } else {
                    Real::NEG_INFINITY
                };
                d2x[i + 1] = -d2x[i];
            }
        }
        Profile::with_derivatives(self.z().to_vec(), x, slopes, d2x)
    }

    /// The profile moved by `d` along x: each node's x plus `d` at its z
    /// (held at `d`'s end values beyond its range), its slopes and second
    /// derivatives with `d`'s (central differences over 1e-3 of z; a kink
    /// stays one). A target corrected by a measured error (`pilgrim
    /// compensate`): a correction that bends the target more than a
    /// wheel's rounding can follow is then refused by the curvature check
    /// of the wheel's path ([`crate::offset::equidistant`]), named by z.
    ///
    /// # Failures
    /// `d` failing to evaluate.
    pub fn offset_by(&self, d: &Profile) -> Result<Profile, ProfileError> {
        let (lo, hi) = d.z_range();
        let at = |z: Real| d.eval(z.clamp(lo, hi));
        let mut x = Vec::with_capacity(self.len());
        let mut slopes = self.slopes().into_owned();
        let mut d2x = self.second_derivatives().into_owned();
        let h = 1e-3;
        for (i, &z) in self.z.iter().enumerate() {
            let (before, here, after) = (at(z - h)?, at(z)?, at(z + h)?);
            x.push(self.x[i] + here);
            slopes[i] += (after - before) / (2.0 * h);
            d2x[i] += (after - 2.0 * here + before) / (h * h);
        }
        Profile::with_derivatives(self.z.clone(), x, slopes, d2x)
    }

    /// The profile resampled at a uniform step of z from its first to its
    /// last z (the last step may be shorter), by cubic Hermite
    /// interpolation. Analytic derivatives are not carried over.
    ///
    /// # Failures
    /// A step that is not positive and finite, or one so small that the
    /// result would exceed [`MAX_NODES`] nodes.
    pub fn resample_uniform(&self, step: Real) -> Result<Profile, ProfileError> {
        self.resample_by(&self.z.clone(), step)
    }

    /// The profile resampled at a uniform step of a monotone parameter `t`
    /// given at the nodes (for example [`Self::arc_length`]): z and x are
    /// both interpolated in `t` (cubic Hermite).
    ///
    /// # Failures
    /// `t` of the wrong length, not finite or not strictly increasing; a bad
    /// step; a parameter under which the resampled z would not increase.
    pub fn resample_by(&self, t: &[Real], step: Real) -> Result<Profile, ProfileError> {
        check_same_len("resampling parameter and profile", t.len(), self.len())?;
        check_abscissa("resampling parameter", t)?;
        crate::math::positive("resampling step", step)?;
        let ts = law::uniform_grid(t[0], t[t.len() - 1], step)?;
        let tz = Profile::new(t.to_vec(), self.z.clone())?;
        let tx = Profile::new(t.to_vec(), self.x.clone())?;
        let (sz, sx) = (tz.slopes(), tx.slopes());
        let z = ts.iter().map(|&tk| hermite(t, &self.z, &sz, tk)).collect();
        let x = ts.iter().map(|&tk| hermite(t, &self.x, &sx, tk)).collect();
        Profile::new(z, x)
    }

    /// Pointwise minimum of this profile and `other`, on this profile's nodes
    /// (where `other` covers them; elsewhere this profile's value). Useful
    /// for "the current surface": the stock left and the wheel's envelope.
    pub fn min_with(&self, other: &Profile) -> Profile {
        let (lo, hi) = other.z_range();
        let slopes = other.slopes();
        let x = self
            .z
            .iter()
            .zip(&self.x)
            .map(|(&z, &x)| {
                if (lo..=hi).contains(&z) {
                    x.min(hermite(&other.z, &other.x, &slopes, z))
                } else {
                    x
                }
            })
            .collect();
        Profile {
            z: self.z.clone(),
            x,
            interpolation: self.interpolation,
            dx: None,
            d2x: None,
            estimated: SlopeCache::default(),
            bands: Vec::new(),
            sources: Vec::new(),
        }
    }
}

/// Signed curvature of a graph from its first and second derivatives.
#[inline]
pub fn curvature_of(d1: Real, d2: Real) -> Real {
    let t = 1.0 + d1 * d1;
    d2 / (t * t.sqrt())
}

/// Cubic Hermite interpolation of nodes `(t, v)` with slopes `s` at `tq`
/// (clamped to the range).
pub(crate) fn hermite(t: &[Real], v: &[Real], s: &[Real], tq: Real) -> Real {
    let n = t.len();
    let i = crate::math::floor_index(t, tq).unwrap_or(0).min(n - 2);
    hermite_in(t, v, s, i, tq)
}

/// [`hermite`] on the interval `i` (`t[i] <= tq <= t[i + 1]`, clamped).
fn hermite_in(t: &[Real], v: &[Real], s: &[Real], i: usize, tq: Real) -> Real {
    let h = t[i + 1] - t[i];
    let u = ((tq - t[i]) / h).clamp(0.0, 1.0);
    let (u2, u3) = (u * u, u * u * u);
    let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
    let h10 = u3 - 2.0 * u2 + u;
    let h01 = -2.0 * u3 + 3.0 * u2;
    let h11 = u3 - u2;
    h00 * v[i] + h10 * h * s[i] + h01 * v[i + 1] + h11 * h * s[i + 1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    /// The interval guessed from an even step is the one bisection finds,
    /// for even, nearly even and uneven nodes, inside, at and beyond the
    /// ends.
    #[test]
    fn interval_agrees_with_bisection() {
        let tables: Vec<Vec<Real>> = vec![
            (0..=400).map(|i| -1.2 + 2.4 * i as Real / 400.0).collect(),
            (0..=50).map(|i| (i as Real).powi(2) * 0.01).collect(),
            (0..=30)
                .map(|i| i as Real + 0.3 * ((i * 7) % 5) as Real / 5.0)
                .collect(),
            vec![0.0, 1.0, 5.0],
        ];
        for z in tables {
            let p = Profile::new(z.clone(), z.iter().map(|v| v.sin()).collect()).unwrap();
            let (lo, hi) = p.z_range();
            let last = z.len() - 2;
            let mut at: Vec<Real> = z.clone();
            at.extend((0..=1000).map(|k| lo - 0.1 + (hi - lo + 0.2) * k as Real / 1000.0));
            for q in at {
                let want = crate::math::floor_index(&z, q).unwrap_or(0).min(last);
                assert_eq!(p.interval(q), want, "z = {q}");
            }
        }
    }

    /// A profile moved by a narrow dip bends as the dip does: its second
    /// derivatives are the dip's too, so a wheel rounder than the dip is
    /// refused by the equidistant's curvature check, naming where, rather
    /// than folding its path.
    #[test]
    fn an_offset_bends_the_profile_by_its_own_curvature() {
        let z: Vec<Real> = (0..=100).map(|i| i as Real).collect();
        let line = Profile::with_derivatives(
            z.clone(),
            vec![20.0; z.len()],
            vec![0.0; z.len()],
            vec![0.0; z.len()],
        )
        .unwrap();
        // A dip 0.06 mm deep, sigma 0.8 mm, at z = 50: x'' = 0.06 / 0.64
        // at its bottom.
        let dz: Vec<Real> = (0..=400).map(|i| 40.0 + 0.05 * i as Real).collect();
        let dip = |z: Real| -0.06 * (-0.5 * ((z - 50.0) / 0.8).powi(2)).exp();
        let d = Profile::new(dz.clone(), dz.iter().map(|&z| dip(z)).collect()).unwrap();
        let moved = line.offset_by(&d).unwrap();
        assert_near!(moved.second_derivatives()[50], 0.06 / 0.64, 1e-3);
        let e = crate::offset::equidistant(&moved, 20.0, crate::offset::Side::Outside)
            .unwrap_err()
            .to_string();
        assert!(e.contains("z = 50"), "{e}");
    }

    fn cubic() -> Profile {
        // x = z^3 - z on a non-uniform grid.
        let z: Vec<Real> = (0..40)
            .map(|i| -2.0 + 0.1 * i as Real + 0.002 * (i % 3) as Real)
            .collect();
        let x = z.iter().map(|z| z * z * z - z).collect();
        Profile::new(z, x).unwrap()
    }

    #[test]
    fn estimated_derivatives_within_documented_bound() {
        let p = cubic();
        let s = p.slopes();
        for (i, &z) in p.z().iter().enumerate() {
            // |x'''| = 6; steps about 0.1: the bound is h h' 6 / 6 (interior), h(h+h') at the ends.
            let h = 0.104;
            let bound = if i == 0 || i == p.len() - 1 {
                2.0 * h * h
            } else {
                h * h
            };
            assert_near!(s[i], 3.0 * z * z - 1.0, bound, "node {i}");
        }
        let d2 = p.second_derivatives();
        for i in 1..p.len() - 1 {
            assert_near!(d2[i], 6.0 * p.z()[i], 0.7, "node {i}");
        }
    }

    #[test]
    fn curvature_of_a_circle() {
        let r = 5.0;
        let z: Vec<Real> = (0..201).map(|i| -3.0 + 0.03 * i as Real).collect();
        let x: Vec<Real> = z.iter().map(|z| -(r * r - z * z).sqrt()).collect();
        let p = Profile::new(z, x).unwrap();
        for (i, k) in p.curvature().iter().enumerate().skip(1).take(198) {
            assert_near!(*k, 1.0 / r, 1e-4, "node {i}");
        }
        assert_near!(p.curvature_radius()[100], r, 1e-3);
        // Arc length of the arc from -3 to 3 on a circle of radius 5.
        let s = p.arc_length();
        // Chords fall short by about h^3 kappa^2 / 24 per step: 200 steps of up to 0.0375.
        assert_near!(
            s[200],
            2.0 * r * (3.0_f64 / r).asin(),
            200.0 * 0.0375_f64.powi(3) / 25.0 / 24.0
        );
    }

    #[test]
    fn resampling_keeps_the_curve() {
        let p = cubic();
        let r = p.resample_uniform(0.013).unwrap();
        let (a, b) = r.z_range();
        assert_eq!((a, b), p.z_range());
        for (z, x) in r.z().iter().zip(r.x()) {
            assert_near!(*x, z * z * z - z, 2e-3, "z = {z}");
        }
        let s = p.arc_length();
        let r = p.resample_by(&s, 0.05).unwrap();
        let rs = r.arc_length();
        for w in rs.windows(2).take(rs.len() - 2) {
            assert_near!(w[1] - w[0], 0.05, 5e-3);
        }
    }

    #[test]
    fn min_with_takes_the_lower_surface_where_both_exist() {
        let stock = Profile::new(vec![0.0, 1.0, 2.0, 3.0, 4.0], vec![5.0; 5]).unwrap();
        let cut = Profile::new(vec![1.5, 2.0, 2.5, 3.0], vec![4.0, 6.0, 4.5, 4.5]).unwrap();
        let m = stock.min_with(&cut);
        assert_eq!(m.z(), stock.z());
        assert_eq!(m.x(), [5.0, 5.0, 5.0, 4.5, 5.0]);
    }

    #[test]
    fn evaluation_beside_a_kink_follows_the_segments() {
        use crate::profile::ProfileBuilder;
        // A cylinder, then a cone going down: a convex kink at z = 10.
        let p = ProfileBuilder::start(0.0, 5.0)
            .cylinder(10.0)
            .line_to(20.0, 3.0)
            .build(0.01, 4.0)
            .unwrap();
        for z in [7.5, 9.0, 9.99, 10.0, 10.01, 11.0, 12.5] {
            let exact = if z <= 10.0 {
                5.0
            } else {
                5.0 - 0.2 * (z - 10.0)
            };
            assert_near!(p.eval(z).unwrap(), exact, 1e-12, "z = {z}");
        }
    }

    /// Beside a flat run the parabolic slopes bulge between its rows; the
    /// monotone ones keep it flat and never overshoot the nodes; linear
    /// runs straight.
    #[test]
    fn interpolations_between_rows() {
        let z: Vec<Real> = (0..8).map(|i| i as Real).collect();
        let x = vec![5.0, 4.0, 2.5, 1.0, 1.0, 1.0, 1.5, 3.0];
        let p = Profile::new(z.clone(), x.clone()).unwrap();
        let flat = |p: &Profile| -> Real {
            (0..=100)
                .map(|i| (p.eval(3.0 + 2.0 * i as Real / 100.0).unwrap() - 1.0).abs())
                .fold(0.0, Real::max)
        };
        assert!(flat(&p) > 0.01, "{}", flat(&p));
        let m = p.clone().with_interpolation(Interpolation::Monotone);
        assert_eq!(flat(&m), 0.0);
        for w in 0..7 {
            let (lo, hi) = (x[w].min(x[w + 1]), x[w].max(x[w + 1]));
            for i in 0..=20 {
                let v = m.eval(w as Real + i as Real / 20.0).unwrap();
                assert!(v >= lo - 1e-12 && v <= hi + 1e-12, "{w} {i}: {v}");
            }
        }
        let l = p.with_interpolation(Interpolation::Linear);
        assert_eq!(l.eval(1.5).unwrap(), 3.25);
        assert_eq!(Interpolation::named("PCHIP"), Some(Interpolation::Monotone));
        assert_eq!(Interpolation::named("spline"), None);
    }

    #[test]
    fn bad_profiles_are_named() {
        let e = Profile::new(vec![0.0, 1.0], vec![0.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("at least 3"), "{e}");
        let e = Profile::new(vec![0.0, 1.0, 1.0], vec![0.0, 1.0, 2.0]).unwrap_err();
        assert!(e.to_string().contains("[2] = 1 follows [1] = 1"), "{e}");
        let e = Profile::new(vec![0.0, 1.0, 2.0], vec![0.0, f64::INFINITY, 2.0]).unwrap_err();
        assert!(e.to_string().contains("profile x[1] = inf"), "{e}");
        let e = Profile::new(vec![0.0, 1.0, 2.0], vec![0.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("lengths differ"), "{e}");
        let p = cubic();
        assert!(p.eval(5.0).is_err());
        assert!(p.resample_uniform(0.0).is_err());
        assert!(p.resample_uniform(1e-12).is_err());
        assert!(p.resample_uniform(1e-7).is_err()); // 39 million nodes
    }
}
