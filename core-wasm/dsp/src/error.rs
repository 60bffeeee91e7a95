use std::fmt;

/// Everything that can go wrong in this crate.
///
/// Each message names the bad parameter, gives the value it had and says what
/// was expected, so that it can be shown to a user as it is.
///
/// ```
/// use mosaic_dsp::{DspError, FilterBank};
///
/// let err = FilterBank::new(&[1.0], &[0.0, 1.0], 1).unwrap_err();
/// assert_eq!(err, DspError::ZeroLeadingDenominator);
/// assert!(err.to_string().contains("Denominator[0] must be non-zero"));
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum DspError {
    /// The numerator of a filter has no coefficient.
    EmptyNumerator,
    /// The denominator of a filter has no coefficient.
    EmptyDenominator,
    /// `Denominator[0]` is zero.
    ZeroLeadingDenominator,
    /// A coefficient or operand is NaN or infinite.
    NonFinite {
        /// Name of the list ("Numerator", "Denominator", "Operand").
        name: &'static str,
        /// Index of the bad value in that list.
        index: usize,
        /// The bad value.
        value: f64,
    },
    /// Dividing a coefficient by `Denominator[0]` overflowed to infinity.
    NormalisationOverflow {
        /// Name of the list ("Numerator" or "Denominator").
        name: &'static str,
        /// Index of the coefficient that overflowed.
        index: usize,
        /// The value of `Denominator[0]`.
        den0: f64,
    },
    /// `channels` is zero.
    ZeroChannels,
    /// An operand has a length that cannot be broadcast.
    OperandLength {
        /// Number of values given.
        len: usize,
        /// Number of channels of the kernel.
        channels: usize,
        /// Length of the input when a per-value operand is also accepted.
        per_value: Option<usize>,
    },
    /// The operation takes no operand but one was given.
    OperandNotUsed {
        /// Name of the operation.
        op: &'static str,
    },
    /// A list has the wrong number of values.
    WrongLength {
        /// Name of the list.
        name: &'static str,
        /// Number of values given.
        len: usize,
        /// Number of values expected.
        expected: usize,
    },
    /// A scalar parameter is out of its range.
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What was expected, in words.
        expected: &'static str,
    },
    /// The bounds of a clip are the wrong way round or NaN.
    ClipRange {
        /// Lower bound given.
        min: f64,
        /// Upper bound given.
        max: f64,
    },
    /// A buffer does not hold a whole number of events.
    NotWholeEvents {
        /// Name of the buffer ("input", "output", "data").
        name: &'static str,
        /// Number of values in it.
        len: usize,
        /// Number of channels of the kernel.
        channels: usize,
    },
    /// An output buffer does not have the length the input implies.
    OutputLength {
        /// Number of values given.
        len: usize,
        /// Number of values expected.
        expected: usize,
    },
    /// An output buffer is too short for what the call produces.
    TooShort {
        /// Name of the buffer.
        name: &'static str,
        /// Number of values it holds.
        len: usize,
        /// Number of values the call needs.
        needed: usize,
    },
    /// Input and output buffers have different lengths.
    LengthMismatch {
        /// Number of values in the input.
        input: usize,
        /// Number of values in the output.
        output: usize,
    },
}

impl fmt::Display for DspError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DspError::EmptyNumerator => f.write_str(
                "Numerator must have at least one coefficient (m0 … mP); got an empty list",
            ),
            DspError::EmptyDenominator => f.write_str(
                "Denominator must have at least one coefficient; got an empty list (use [1] for an FIR filter)",
            ),
            DspError::ZeroLeadingDenominator => f.write_str(
                "Denominator[0] must be non-zero (it is the a0 coefficient that the others are divided by); use [1, d1, …, dQ]",
            ),
            DspError::NonFinite { name, index, value } => write!(
                f,
                "{name}[{index}] is {value}; every value of {name} must be a finite number"
            ),
            DspError::NormalisationOverflow { name, index, den0 } => write!(
                f,
                "{name}[{index}] overflows to infinity when divided by Denominator[0] = {den0}; scale the coefficients so that Denominator[0] is 1"
            ),
            DspError::ZeroChannels => {
                f.write_str("channels must be at least 1; got 0")
            }
            DspError::OperandLength {
                len,
                channels,
                per_value,
            } => match per_value {
                Some(n) => write!(
                    f,
                    "Operand has {len} values; expected 1 (the same value for every channel), {channels} (one per channel) or {n} (one per input value)"
                ),
                None => write!(
                    f,
                    "Operand has {len} values; expected 1 (the same value for every channel) or {channels} (one per channel)"
                ),
            },
            DspError::OperandNotUsed { op } => write!(
                f,
                "operation '{op}' takes no operand; only 'add' and 'multiply' combine the input with an operand (call process instead)"
            ),
            DspError::WrongLength {
                name,
                len,
                expected,
            } => write!(f, "{name} has {len} values; expected {expected} (one per channel)"),
            DspError::InvalidParameter {
                name,
                value,
                expected,
            } => write!(f, "{name} is {value}; expected {expected}"),
            DspError::ClipRange { min, max } => write!(
                f,
                "Clip bounds are min = {min}, max = {max}; expected min <= max, and neither may be NaN (use -inf or inf for an open side)"
            ),
            DspError::NotWholeEvents {
                name,
                len,
                channels,
            } => write!(
                f,
                "{name} has {len} values, which is not a whole number of events of {channels} channels; expected a multiple of {channels}"
            ),
            DspError::OutputLength { len, expected } => write!(
                f,
                "output has {len} values; expected {expected} for this input (events × values per output event)"
            ),
            DspError::TooShort { name, len, needed } => write!(
                f,
                "{name} has room for {len} values but this call produces {needed}; make it longer"
            ),
            DspError::LengthMismatch { input, output } => write!(
                f,
                "output has {output} values but input has {input}; they must have the same length (events × channels)"
            ),
        }
    }
}

impl std::error::Error for DspError {}
