use std::fmt;

/// Everything that can go wrong in this crate.
///
/// Each message names the parameter or the part of a saved state that is
/// wrong, gives the value it had and says what was expected, so that it can
/// be shown to a user as it is.
///
/// ```
/// use mosaic_learn::{LearnError, ModelConfig};
///
/// let err = ModelConfig::ridge(3, 1).lambda(0.0).build().unwrap_err();
/// assert!(matches!(err, LearnError::InvalidParameter { name: "Lambda", .. }));
/// assert!(err.to_string().contains("Lambda is 0"));
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum LearnError {
    /// A scalar parameter is out of its range.
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What was expected, in words.
        expected: &'static str,
    },
    /// A size (inputs, outputs, features) is zero or too large to allocate.
    Size {
        /// Name of the size.
        name: &'static str,
        /// The value given.
        value: usize,
        /// What was expected, in words.
        expected: &'static str,
    },
    /// A buffer does not hold a whole number of rows of the expected width.
    NotWholeRows {
        /// Name of the buffer ("x", "y", "output").
        name: &'static str,
        /// Number of values in it.
        len: usize,
        /// Values per row.
        width: usize,
    },
    /// A buffer has the wrong number of values.
    Length {
        /// Name of the buffer.
        name: &'static str,
        /// Number of values given.
        len: usize,
        /// Number of values expected.
        expected: usize,
    },
    /// Two buffers that must describe the same rows do not.
    RowMismatch {
        /// Name of the first buffer.
        a: &'static str,
        /// Its number of rows.
        a_rows: usize,
        /// Name of the second buffer.
        b: &'static str,
        /// Its number of rows.
        b_rows: usize,
    },
    /// A saved state has the wrong number of values (in total or in a section).
    StateLength {
        /// Name of the section, or "state" for the whole.
        section: &'static str,
        /// Number of values given.
        len: usize,
        /// Number of values expected.
        expected: usize,
    },
    /// A saved state holds a value that is NaN, infinite or out of range.
    StateValue {
        /// Name of the section.
        section: &'static str,
        /// Index of the bad value in the section.
        index: usize,
        /// The bad value.
        value: f64,
        /// What was expected, in words.
        expected: &'static str,
    },
    /// A saved scatter matrix is not symmetric.
    NotSymmetric {
        /// Row of the first asymmetric pair.
        row: usize,
        /// Column of the first asymmetric pair.
        col: usize,
    },
    /// A saved scatter matrix plus λI is not positive definite.
    NotPositiveDefinite,
    /// Saved weights disagree with the ones the saved normal equations give.
    Inconsistent {
        /// Name of the section ("weights" or "intercept").
        section: &'static str,
        /// Largest absolute difference found.
        difference: f64,
        /// Tolerance it exceeded.
        tolerance: f64,
    },
}

impl fmt::Display for LearnError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LearnError::InvalidParameter {
                name,
                value,
                expected,
            } => write!(f, "{name} is {value}; expected {expected}"),
            LearnError::Size {
                name,
                value,
                expected,
            } => write!(f, "{name} is {value}; expected {expected}"),
            LearnError::NotWholeRows { name, len, width } => write!(
                f,
                "{name} has {len} values, which is not a whole number of rows of {width}; expected a multiple of {width}"
            ),
            LearnError::Length {
                name,
                len,
                expected,
            } => write!(f, "{name} has {len} values; expected {expected}"),
            LearnError::RowMismatch {
                a,
                a_rows,
                b,
                b_rows,
            } => write!(
                f,
                "{a} has {a_rows} rows but {b} has {b_rows}; they must describe the same samples"
            ),
            LearnError::StateLength {
                section,
                len,
                expected,
            } => write!(
                f,
                "saved state: {section} has {len} values; expected {expected} for this model's dimensions"
            ),
            LearnError::StateValue {
                section,
                index,
                value,
                expected,
            } => write!(
                f,
                "saved state: {section}[{index}] is {value}; expected {expected}"
            ),
            LearnError::NotSymmetric { row, col } => write!(
                f,
                "saved state: scatter[{row}][{col}] differs from scatter[{col}][{row}]; the scatter matrix must be symmetric"
            ),
            LearnError::NotPositiveDefinite => f.write_str(
                "saved state: scatter + λI is not positive definite (a scatter matrix is a sum of outer products); the state is corrupt",
            ),
            LearnError::Inconsistent {
                section,
                difference,
                tolerance,
            } => write!(
                f,
                "saved state: {section} differ by up to {difference:e} from what the saved normal equations give (tolerance {tolerance:e}); the file was edited or is corrupt"
            ),
        }
    }
}

impl std::error::Error for LearnError {}
