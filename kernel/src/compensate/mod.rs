//! Measured part in, corrected target out: the groundwork of `pilgrim
//! compensate`.
//!
//! A shop measures the finished part (a mandrel's diameters along z on a
//! measuring bench or a CMM); the measured minus the part the replay of
//! its program predicted ([`PREDICTED`]) is the error the process left
//! (wheel wear, deflection, heat), which the replay does not model.
//! Fitted smoothly within the measurement's
//! stated uncertainty ([`fit_error`]), the error shifts the target the
//! next run aims at against it ([`ErrorFit::correction`]), bounded.
//!
//! - [`read_measured`]: a table's coordinate and value columns (named,
//!   with their units), every row inside the part, dense enough;
//! - [`fit_error`]: a cubic smoothing spline (de Boor's, the `csaps`
//!   crate) whose residual is the measurement's uncertainty;
//! - [`ErrorFit::correction`]: the target's shift, `-gain` times the fit;
//!   [`within_limit`] refuses one that exceeds its limit, naming where.

mod fit;
mod measure;

use crate::math::Real;
use crate::profile::Profile;

pub use fit::{fit_error, fit_mean, within_limit, ErrorFit};
pub use measure::{read_measured, Measured, MeasuredSpec, MIN_POINTS};

/// The table a run's verification leaves in its report (`report.json`'s
/// `tables`) with the part its replay predicts, as its deviation from the
/// run's target (the nominal, moved by the run's correction where it was
/// corrected), shaped as the correction's table: the coordinate's column
/// ([`Nominal::coordinate`]) and a column per quantity named by its
/// [`Quantity::key`], in the quantity's own measure (a mandrel's `z_mm`
/// and `dr_mm`, its finish's highest generatrix, what a two-point
/// instrument's anvils touch; a thread's each start's simulated pitch
/// diameter as one value, `dd2_1_mm`, ...). `compensate` fits what the
/// replay does not model: the measured minus the target and this.
pub const PREDICTED: &str = "predicted_deviation";

/// What a measurement of a family's finished part holds and what it is
/// held against, as the family's verification gives it
/// (`Verifier::nominal`): quantities along one coordinate.
#[derive(Debug, Clone, PartialEq)]
pub struct Nominal {
    /// The coordinate's column (`z_mm`, `theta_deg`).
    pub coordinate: &'static str,
    /// The part's extent along the coordinate that is measured.
    pub range: (Real, Real),
    /// What may be measured: at least one of them in a measurement.
    pub quantities: Vec<Quantity>,
}

/// One quantity a measurement may hold (a mandrel's radius, a groove's
/// depth, a thread start's pitch diameter) and its nominal.
#[derive(Debug, Clone, PartialEq)]
pub struct Quantity {
    /// Its name in messages and files (`radius`, `start 2's pitch
    /// diameter`).
    pub name: String,
    /// The columns it may be read from, each with the factor that makes
    /// the quantity of it (`r_mm` 1, `d_mm` 0.5).
    pub values: &'static [(&'static str, Real)],
    /// The rows that measure it, where a column tells (`("start", 2.0)`);
    /// `None`: every row.
    pub select: Option<(&'static str, Real)>,
    /// The nominal along the coordinate.
    pub nominal: Profile,
    /// Whether it is corrected along the coordinate (fitted by a
    /// smoothing spline), or by one value (the measured rows' mean: a
    /// thread start's passes move as one).
    pub along: bool,
    /// Its correction's column in the correction's table (`dr_mm`), the
    /// target's shift in the quantity's own measure.
    pub key: String,
    /// How far the finished part may stray from the nominal in it (mm),
    /// where the family holds it to one tolerance: the part a corrected
    /// run predicts (the measured error repeating, less the correction)
    /// is judged against it. `None`: not judged so (a thread's limits).
    pub tolerance: Option<Real>,
}

impl Nominal {
    /// The measurement's spec for quantity `q`: along the coordinate, at
    /// least [`MIN_POINTS`] places and no stretch longer than a quarter of
    /// the range without one; as one value, a row at least.
    pub fn spec(&self, q: &Quantity) -> MeasuredSpec<'static> {
        let (from, to) = self.range;
        MeasuredSpec {
            coordinate: self.coordinate,
            values: q.values,
            select: q.select,
            range: self.range,
            max_gap: if q.along {
                Some(0.25 * (to - from))
            } else {
                None
            },
        }
    }

    /// The coordinate's name and unit, as its column spells them
    /// (`z_mm`: `z`, `mm`).
    pub fn names(&self) -> (&'static str, &'static str) {
        self.coordinate
            .rsplit_once('_')
            .unwrap_or((self.coordinate, ""))
    }
}

/// Errors reading a measurement and turning it into a correction; each
/// names the file, and the row and column or the place along the part.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CompensateError {
    /// The table could not be read, or a column or cell is wrong.
    #[error(transparent)]
    Table(#[from] crate::profile::TableError),
    /// None of the columns a value may come from is in the table.
    #[error("{file}: no column {wanted} (columns: {available})")]
    NoValueColumn {
        /// The file.
        file: String,
        /// The columns accepted, in words.
        wanted: String,
        /// The columns there are.
        available: String,
    },
    /// A row measured outside the part.
    #[error("{file}, row {row}, column {column}: {value} is outside the part ({from} to {to})")]
    Outside {
        /// The file.
        file: String,
        /// The row (from 1, as the spreadsheet numbers it).
        row: usize,
        /// The coordinate's column.
        column: String,
        /// Its value.
        value: f64,
        /// The part's start along the coordinate.
        from: f64,
        /// Its end.
        to: f64,
    },
    /// Too few places measured, or a stretch of the part without any.
    #[error("{file}: {what}")]
    TooSparse {
        /// The file.
        file: String,
        /// What is missing.
        what: String,
    },
    /// The correction asked for is beyond its limit somewhere.
    #[error("the correction {correction:.4} mm {at} is beyond its limit of {limit} mm: {why}")]
    TooLarge {
        /// Of what and where (`of the radius at z = 120.000 mm`).
        at: String,
        /// The correction there (mm).
        correction: f64,
        /// The limit (mm).
        limit: f64,
        /// What to look at.
        why: String,
    },
    /// A measurement holds none of the quantities the part may be
    /// measured by.
    #[error("{file}: it measures none of {wanted} (columns: {available})")]
    Nothing {
        /// The file.
        file: String,
        /// The quantities and their columns, in words.
        wanted: String,
        /// The columns there are.
        available: String,
    },
    /// A measurement that contradicts itself: rows at one place, or two
    /// columns of one quantity, further apart than its uncertainty allows.
    #[error("{file}: {what}")]
    Inconsistent {
        /// The file.
        file: String,
        /// Where and what, both sides named.
        what: String,
    },
    /// A `--columns` key that is none of the family's measured columns.
    #[error("--columns: '{key}' is none of the family's columns ({known}); map each as NAME=COLUMN, e.g. z=\"Position Z [mm]\"")]
    ColumnKey {
        /// The key given.
        key: String,
        /// The family's columns.
        known: String,
    },
    /// An option bounding the correction out of its range.
    #[error("{what} is {value}; it must be {range}")]
    Option {
        /// The option, in words and by its flag.
        what: String,
        /// Its value.
        value: f64,
        /// What it must be.
        range: String,
    },
    /// A family that takes no correction: its script declares no
    /// `correction` parameter.
    #[error("{script}: the family takes no correction: its script declares no `correction` parameter (a table's name)")]
    NoCorrection {
        /// The family's script.
        script: String,
    },
    /// A family whose verification takes no measurement of its part.
    #[error("{script}: the family's verification takes no measurement of its part")]
    NotMeasured {
        /// The family's script.
        script: String,
    },
    /// A measurement applied already in the line of corrections that made
    /// the run.
    #[error("{file}: this measurement was applied already, in the line of corrections that made {run} (its compensation.json): measure the part its corrected program made, and correct by that")]
    AppliedAlready {
        /// The measurement.
        file: String,
        /// The run corrected.
        run: String,
    },
    /// The fit could not be made.
    #[error("the measured error could not be fitted: {0}")]
    Fit(String),
    /// The job refused the corrected target (a wheel that cannot follow
    /// it, named where).
    #[error("the target corrected by {file} is refused: {why} (the correction bends the part more than the process can follow: look at the measurement, or state its uncertainty, --uncertainty, for a smoother fit)")]
    Corrected {
        /// The measurement's file.
        file: String,
        /// The job's refusal.
        why: String,
    },
}
