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
//! - [`ErrorFit::correction`]: the target's shift, `-gain` times the fit,
//!   refused where it exceeds its limit.

mod fit;
mod measure;

pub use fit::{fit_error, ErrorFit};
pub use measure::{read_measured, Measured, MeasuredSpec, MIN_POINTS};

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
