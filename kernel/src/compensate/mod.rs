//! Measured part in, corrected target out: the groundwork of `pilgrim
//! compensate`.
//!
//! A shop measures the finished part (a mandrel's diameters along z on a
//! measuring bench or a CMM); the measured minus the nominal is the error
//! the process left (wheel wear, deflection, heat), which the replay of
//! the program does not model. Fitted smoothly within the measurement's
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

pub use fit::{fit_error, within_limit, ErrorFit};
pub use measure::{read_measured, Measured, MeasuredSpec, MIN_POINTS};

/// What a measurement of a family's finished part holds and what it is
/// held against, as the family's verification gives it
/// (`Verifier::nominal`): a quantity along a coordinate.
#[derive(Debug, Clone, PartialEq)]
pub struct Nominal {
    /// The coordinate's column (`z_mm`).
    pub coordinate: &'static str,
    /// The columns the quantity may be read from, each with the factor
    /// that makes the quantity of it (`r_mm` 1, `d_mm` 0.5).
    pub values: &'static [(&'static str, Real)],
    /// The quantity's name in messages and files (`radius`).
    pub quantity: &'static str,
    /// The nominal quantity along the coordinate.
    pub profile: Profile,
    /// The part's extent along the coordinate that is measured.
    pub range: (Real, Real),
}

impl Nominal {
    /// The measurement's spec: a stretch of at most a quarter of the range
    /// left without a measured place.
    pub fn spec(&self) -> MeasuredSpec<'static> {
        MeasuredSpec {
            coordinate: self.coordinate,
            values: self.values,
            range: self.range,
            max_gap: 0.25 * (self.range.1 - self.range.0),
        }
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
    #[error("the correction {correction:.4} mm at {at} is beyond its limit of {limit} mm: {why}")]
    TooLarge {
        /// Where (`z = 120.000 mm`).
        at: String,
        /// The correction there (mm).
        correction: f64,
        /// The limit (mm).
        limit: f64,
        /// What to look at.
        why: String,
    },
    /// The fit could not be made.
    #[error("the measured error could not be fitted: {0}")]
    Fit(String),
}
