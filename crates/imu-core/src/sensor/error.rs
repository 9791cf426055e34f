use core::fmt;

/// An invalid sensor parameter; `field` is the parameter's name in parameter files.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamError {
    /// NaN (or infinity where not allowed).
    NotFinite {
        /// Parameter name.
        field: &'static str,
        /// Axis or coefficient index.
        index: usize,
    },
    /// Must be ≥ 0.
    Negative {
        /// Parameter name.
        field: &'static str,
        /// Axis index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// Must be > 0.
    NotPositive {
        /// Parameter name.
        field: &'static str,
        /// The value.
        value: f64,
    },
    /// Outside its allowed interval.
    OutOfRange {
        /// Parameter name.
        field: &'static str,
        /// Axis index.
        index: usize,
        /// The value.
        value: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Valid alone, but not a finite number once scaled to the sample rate (or, for a bias
    /// instability model, its filter is not).
    Overflow {
        /// Parameter name.
        field: &'static str,
        /// Axis index.
        index: usize,
    },
    /// Filter coefficients: empty, or a zero leading denominator coefficient.
    BadFilter {
        /// What is wrong.
        reason: &'static str,
    },
    /// More filter coefficients than the storage holds (see `FilterBuffer::CAPACITY`).
    TooManyCoefficients {
        /// The longer list's length.
        len: usize,
        /// Most coefficients held.
        max: usize,
    },
}

impl ParamError {
    /// The parameter's name (`noise_density`, `bias_instability_coefficients`, …).
    #[must_use]
    pub fn field(&self) -> &'static str {
        match *self {
            Self::NotFinite { field, .. }
            | Self::Overflow { field, .. }
            | Self::Negative { field, .. }
            | Self::NotPositive { field, .. }
            | Self::OutOfRange { field, .. } => field,
            Self::BadFilter { .. } | Self::TooManyCoefficients { .. } => {
                "bias_instability_coefficients"
            }
        }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NotFinite { field, index } => {
                write!(f, "{field}[{index}] is not a finite number")
            }
            Self::Negative {
                field,
                index,
                value,
            } => write!(f, "{field}[{index}] must be ≥ 0, got {value}"),
            Self::NotPositive { field, value } => write!(f, "{field} must be > 0, got {value}"),
            Self::OutOfRange {
                field,
                index,
                value,
                min,
                max,
            } => {
                write!(f, "{field}[{index}] must be in [{min}, {max}], got {value}")
            }
            Self::Overflow { field, index } => write!(
                f,
                "{field}[{index}] is too large: at this sample rate the model is not finite"
            ),
            Self::BadFilter { reason } => write!(f, "bias_instability_coefficients: {reason}"),
            Self::TooManyCoefficients { len, max } => write!(
                f,
                "bias_instability_coefficients: {len} coefficients, at most {max} taken (a 1/f floor is \
                 the flicker model, at most 16 sections)"
            ),
        }
    }
}

impl core::error::Error for ParamError {}
