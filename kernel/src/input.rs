//! The validation error every module shares: a rejected input value.
//!
//! A leaf: it depends on nothing in the kernel, and every module may use
//! it. Each module has its own error enum naming the offending value and
//! its place (index, row, axis, block); [`crate::error::Error`] gathers them all.

use std::fmt;

/// A rejected input value: what it is, where it stands and why.
///
/// Produced by every constructor that validates numbers; each variant names
/// the value (`what`, e.g. `"profile x"` or `"wheel rounding radius"`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InputError {
    /// A value is NaN or infinite.
    #[error("{} = {value} is not a finite number", Place(what, *index))]
    NonFinite {
        /// What the value is.
        what: String,
        /// Its index in an array, if it came from one.
        index: Option<usize>,
        /// The value itself.
        value: f64,
    },
    /// A value that must be strictly positive is zero or negative.
    #[error("{what} must be > 0, got {value}")]
    NotPositive {
        /// What the value is.
        what: String,
        /// The value itself.
        value: f64,
    },
    /// An array is too short for the operation.
    #[error("{what} needs at least {min} points, got {got}")]
    TooFew {
        /// What the array is.
        what: String,
        /// Its length.
        got: usize,
        /// The least length accepted.
        min: usize,
    },
    /// An abscissa that must increase strictly does not.
    #[error("{what}: values must increase strictly, but [{index}] = {value} follows [{}] = {prev}", index - 1)]
    NotIncreasing {
        /// What the array is.
        what: String,
        /// Index of the offending value.
        index: usize,
        /// The value before it.
        prev: f64,
        /// The offending value.
        value: f64,
    },
    /// Two arrays that must have equal lengths do not.
    #[error("{what}: lengths differ ({left} vs {right})")]
    LengthMismatch {
        /// What the arrays are.
        what: String,
        /// Length of the first.
        left: usize,
        /// Length of the second.
        right: usize,
    },
    /// A value outside the range an operation accepts.
    #[error("{what} = {value} is out of range: {expected}")]
    OutOfRange {
        /// What the value is.
        what: String,
        /// The value itself.
        value: f64,
        /// The accepted range, in words.
        expected: String,
    },
    /// A name or text refused for what it holds ([`crate::names`]).
    #[error("{what} {value} {reason}")]
    BadText {
        /// What the text is (`tool name`, `machine description`).
        what: String,
        /// The text as quoted in messages (escaped, cut short).
        value: String,
        /// What is wrong with it.
        reason: String,
    },
}

impl InputError {
    /// Shorthand for [`InputError::OutOfRange`].
    pub fn out_of_range(what: impl Into<String>, value: f64, expected: impl Into<String>) -> Self {
        Self::OutOfRange {
            what: what.into(),
            value,
            expected: expected.into(),
        }
    }
}

/// `name` or `name[index]`, for messages.
struct Place<'a>(&'a str, Option<usize>);

impl fmt::Display for Place<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.1 {
            Some(i) => write!(f, "{}[{i}]", self.0),
            None => f.write_str(self.0),
        }
    }
}
