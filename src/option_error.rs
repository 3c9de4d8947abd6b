//! [`OptionError`]: an option value no run can use, shared by the option structs' `validate`
//! methods (the run's options, the size controls, the feature rule, the improvers).

use thiserror::Error;

/// An option value no run can use: the option's name, the value given and what it must be,
/// as data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum OptionError {
    /// A number outside its range.
    #[error("{option} must be {range}, got {value}")]
    OutOfRange {
        /// the option, as the user knows it ("hmin", "feature angle", ...)
        option: &'static str,
        /// the value given
        value: f64,
        /// the range it must be in ("a positive size", "in (0, 1]", ...)
        range: &'static str,
    },
    /// A count below its least value.
    #[error("{option} must be at least {min}, got {value}")]
    TooFew {
        /// the option
        option: &'static str,
        /// the value given
        value: usize,
        /// its least value
        min: usize,
    },
    /// A lower bound above its upper bound.
    #[error("{low} {low_value} is larger than {high} {high_value}")]
    Crossed {
        /// the lower bound's option
        low: &'static str,
        /// its value
        low_value: f64,
        /// the upper bound's option
        high: &'static str,
        /// its value
        high_value: f64,
    },
    /// A value that does not parse.
    #[error("{option}: expected {expected}, got {value:?}")]
    Unparsed {
        /// the option
        option: &'static str,
        /// the text given
        value: String,
        /// what it must be
        expected: &'static str,
    },
}
