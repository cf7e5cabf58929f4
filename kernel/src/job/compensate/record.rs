//! What `compensation.json` records: each quantity's measured places,
//! fit and correction, and the corrected run's line of descent.

use serde::Serialize;

/// One measured place as `compensation.json` lists it.
#[derive(Debug, Clone, Serialize)]
pub struct Place {
    /// The coordinate.
    pub at: f64,
    /// The quantity measured (the rows there averaged).
    pub measured: f64,
    /// How far the rows there differ (several angular positions: out of
    /// round), the largest less the least: averaged, not corrected.
    pub spread: f64,
    /// The nominal there.
    pub nominal: f64,
    /// Measured minus nominal: the part's error.
    pub error: f64,
    /// The part the run's replay predicted there (none where its
    /// verification predicts none: its target taken for it).
    pub predicted: Option<f64>,
    /// What the replay does not model, which is fitted: the measured minus
    /// the prediction, plus the run's own correction where it was
    /// corrected.
    pub unmodelled: f64,
    /// The fit there.
    pub fitted: f64,
    /// The correction there: the corrected target minus the nominal (as
    /// `correction.csv` has it), the run's own correction replaced.
    pub correction: f64,
    /// The error from the nominal expected after it, the same unmodelled
    /// error repeating: the corrected run's predicted part plus the
    /// measured minus the first prediction (where both runs predict; else
    /// the error plus the correction).
    pub expected_after: f64,
}

/// One quantity's measurement, fit and correction.
#[derive(Debug, Clone, Serialize)]
pub struct QuantityRecord {
    /// The quantity (`radius`, `depth`, `start 2's pitch diameter`).
    pub name: String,
    /// The value's column read.
    pub column: String,
    /// The correction's column in `correction.csv`.
    pub key: String,
    /// Corrected along the coordinate (a smoothing spline), or by one
    /// value (the measured errors' mean).
    pub along: bool,
    /// The smoothing parameter found (along the coordinate).
    pub smooth: f64,
    /// The fit's residual, RMS (mm). As one value: how far the error
    /// varies along the part beyond its mean, which the correction leaves.
    pub rms_residual_mm: f64,
    /// The largest measured error (mm).
    pub max_error_mm: f64,
    /// The largest spread of the rows at one place (mm): out of round,
    /// averaged, not corrected.
    pub max_spread_mm: f64,
    /// The largest correction, an earlier one kept included (mm).
    pub max_correction_mm: f64,
    /// The largest error expected after the correction, the same error
    /// repeating (mm).
    pub max_expected_after_mm: f64,
    /// Every measured place.
    pub places: Vec<Place>,
}

/// `compensation.json`: see the module's docs.
#[derive(Debug, Clone, Serialize)]
pub struct Compensation {
    /// The run corrected (as given).
    pub run: String,
    /// The measurement's file.
    pub measured_file: String,
    /// The coordinate's column.
    pub coordinate: &'static str,
    /// The uncertainty the fit was held to (mm).
    pub uncertainty_mm: f64,
    /// The gain.
    pub gain: f64,
    /// The largest correction accepted (mm).
    pub limit_mm: f64,
    /// The quantities measured.
    pub quantities: Vec<QuantityRecord>,
    /// The quantities the part may be measured by that the measurement
    /// does not hold: not corrected (an earlier correction kept).
    pub not_measured: Vec<String>,
    /// How the program changed.
    pub program: super::ProgramChange,
    /// Where the corrected run comes from.
    pub lineage: Lineage,
}

/// A corrected run's line of descent: how many corrections it carries,
/// the run it corrected and every measurement applied along the line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Lineage {
    /// How many corrections the run's target carries (1: the first
    /// corrected run of a run that had none).
    pub generation: u32,
    /// The run corrected (as given).
    pub parent: String,
    /// The measurement's content digest ([`Table::digest`]).
    pub measurement_sha256: String,
    /// Every measurement's digest applied along the line, oldest first,
    /// this one last.
    pub applied: Vec<String>,
    /// The gain.
    pub gain: f64,
    /// The correction's limit (mm).
    pub limit_mm: f64,
}

impl Compensation {
    /// What was measured and corrected, in a line per quantity.
    pub fn summary(&self) -> String {
        let mut s: Vec<String> = self
            .quantities
            .iter()
            .map(|q| {
                let spread = if q.max_spread_mm > 0.0 {
                    format!(
                        " (the rows at one place differ by up to {:.4} mm: out of round, averaged, not corrected)",
                        q.max_spread_mm
                    )
                } else {
                    String::new()
                };
                format!(
                    "{}: {} places{spread}, the error up to {:.4} mm {} (RMS residual {:.4} mm), the target moved by up to {:.4} mm, {:.4} mm expected after",
                    q.name,
                    q.places.len(),
                    q.max_error_mm,
                    if q.along {
                        format!("fitted within {} mm", self.uncertainty_mm)
                    } else {
                        "corrected by its mean".to_owned()
                    },
                    q.rms_residual_mm,
                    q.max_correction_mm,
                    q.max_expected_after_mm
                )
            })
            .collect();
        if !self.not_measured.is_empty() {
            s.push(format!("not measured: {}", self.not_measured.join(", ")));
        }
        s.join("; ")
    }
}

/// The largest value of `v` in size.
pub(super) fn largest(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |a: f64, x| a.max(x.abs()))
}
