use core::fmt;

/// Why truth kinematics could not be computed. Indices are 0-based sample indices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KinematicsError {
    /// A NaN or infinite value in an input (or a non-finite result of an analytic motion).
    NotFinite {
        /// The quantity, e.g. `"position_m"`.
        field: &'static str,
        /// Sample index.
        index: usize,
    },
    /// Sample times must increase strictly.
    TimeNotIncreasing {
        /// Index of the offending sample.
        index: usize,
        /// The time before it, s.
        previous_s: f64,
        /// Its time, s.
        t_s: f64,
    },
    /// The finite-difference stencil needs more samples than were given.
    TooFewSamples {
        /// Samples needed for the chosen order.
        needed: usize,
        /// Samples given.
        got: usize,
    },
    /// Input slices of different lengths.
    LengthMismatch {
        /// The slice whose length is wrong.
        field: &'static str,
        /// Expected length (that of the times).
        expected: usize,
        /// Its length.
        got: usize,
    },
    /// Finite-difference order not supported (2, 4, 6 or 8).
    UnsupportedOrder {
        /// The order asked for.
        order: usize,
    },
    /// Pitch at ±90°: z-y-x Euler rates are singular there.
    GimbalLock {
        /// Sample index.
        index: usize,
        /// The pitch found, rad.
        pitch_rad: f64,
    },
    /// A zero-norm quaternion.
    ZeroQuaternion {
        /// Sample index.
        index: usize,
    },
    /// Tangent attitude with a vertical velocity: yaw undefined, pitch at ±90°.
    VerticalTangent {
        /// Sample index.
        index: usize,
    },
    /// A range of samples asked for with the tangent attitude, which needs the whole series.
    NeedsWholeSeries,
}

impl KinematicsError {
    /// The sample index the error refers to, when it refers to one.
    #[must_use]
    pub fn index(&self) -> Option<usize> {
        match *self {
            Self::NotFinite { index, .. }
            | Self::TimeNotIncreasing { index, .. }
            | Self::GimbalLock { index, .. }
            | Self::ZeroQuaternion { index }
            | Self::VerticalTangent { index } => Some(index),
            Self::TooFewSamples { .. }
            | Self::LengthMismatch { .. }
            | Self::UnsupportedOrder { .. }
            | Self::NeedsWholeSeries => None,
        }
    }
}

impl fmt::Display for KinematicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NotFinite { field, index } => {
                write!(f, "{field} at sample {index} is not a finite number")
            }
            Self::TimeNotIncreasing {
                index,
                previous_s,
                t_s,
            } => write!(
                f,
                "time at sample {index} ({t_s} s) does not increase after sample {} ({previous_s} s)",
                index - 1
            ),
            Self::TooFewSamples { needed, got } => write!(
                f,
                "too few samples for the finite-difference stencil: need at least {needed}, got {got}"
            ),
            Self::LengthMismatch {
                field,
                expected,
                got,
            } => {
                write!(
                    f,
                    "{field} has {got} samples, expected {expected} (one per time)"
                )
            }
            Self::UnsupportedOrder { order } => write!(
                f,
                "finite-difference order {order} is not supported (use 2, 4, 6 or 8)"
            ),
            Self::GimbalLock { index, pitch_rad } => write!(
                f,
                "pitch at sample {index} is {pitch_rad} rad (±90°): z-y-x Euler angles are singular \
                 there (gimbal lock); give the attitude as quaternions instead"
            ),
            Self::ZeroQuaternion { index } => {
                write!(f, "quaternion at sample {index} has zero norm")
            }
            Self::VerticalTangent { index } => write!(
                f,
                "velocity at sample {index} is vertical: tangent attitude has no yaw there (gimbal \
                 lock); give the attitude explicitly"
            ),
            Self::NeedsWholeSeries => write!(
                f,
                "the tangent attitude needs the whole series, not a range of samples"
            ),
        }
    }
}

impl core::error::Error for KinematicsError {}
