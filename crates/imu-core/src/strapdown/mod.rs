//! Dead reckoning and strapdown navigation from IMU data, written once for every Earth
//! ([`crate::earth::EarthModel`]: the flat Earth, WGS-84, or one of your own).
//!
//! [`planar`]: a cart in a plane with two accelerometers and a yaw gyro (the planar cart
//! exercise), with the exercise's own update rules kept verbatim and a consistent second-order
//! default.
//! [`increments`]: 3D strapdown on Δθ/Δv increments with coning and sculling (second order),
//! and on rate samples turned into increments by the trapezoid;
//! [`rk4`]: a fourth-order alternative for rate samples.
//!
//! Both integrate the navigation equations of the Earth model in its local-level frame `n`:
//! `q̇_nb = ½ q_nb ⊗ (0, ω_ib^b) − ½ (0, ω_in^n) ⊗ q_nb`,
//! `v̇ = C_nb f^b + g^n − (2 ω_ie^n + ω_en^n) × v`, and the position coordinates' rate; on the
//! flat Earth the frame rates vanish and gravity is constant. The height is found as
//! [`VerticalChannel`] says.
mod equations;
pub mod increments;
pub mod planar;
pub mod rk4;

use crate::earth::EarthModel;
use crate::frame::Body;
use crate::rotation::Rotation;
use crate::vector::Vec3;

pub use increments::{Increments, RateIncrements, strapdown_increments, strapdown_rates};
pub use rk4::{Rk4, strapdown_rates_rk4};

/// The navigation state on the Earth `E`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavState<E: EarthModel> {
    /// Time, s.
    pub t_s: f64,
    /// Attitude `C_nb`.
    pub attitude: Rotation<Body, E::Frame>,
    /// Velocity over the ground in the navigation frame, m/s.
    pub velocity_m_s: Vec3<E::Frame>,
    /// Position (metres of the frame on the flat Earth, geodetic on WGS-84).
    pub position: E::Position,
}

impl<E: EarthModel> Default for NavState<E> {
    fn default() -> Self {
        Self {
            t_s: 0.0,
            attitude: Rotation::identity(),
            velocity_m_s: Vec3::zeros(),
            position: E::Position::default(),
        }
    }
}

/// How the height is found: the inertial vertical channel of a round Earth is unstable (a
/// height error `δh` makes gravity too small by `2γ/R·δh`, so errors grow as `cosh(t/τ)`,
/// `τ = √(R/2g) ≈ 570 s`); on the flat Earth it is neutral.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum VerticalChannel {
    /// Integrated freely, as physics says (the default).
    #[default]
    Free,
    /// Held at the initial height with zero vertical velocity (ships, cars on flat ground,
    /// studies of the horizontal channels).
    Hold,
    /// Damped by a barometric altitude with Widnall and Sinha's third-order loop, its three
    /// poles at `−1/time_constant_s`: `ḣ = v_up − k₁ δh`, `v̇_up −= k₂ δh + b`, `ḃ = k₃ δh`
    /// (`δh = h − h_baro`, `b` the loop's acceleration correction), `k₁ = 3/τ`,
    /// `k₂ = 3/τ² + 2γ/R`, `k₃ = 1/τ³`: the height error then obeys
    /// `s³ + k₁ s² + (k₂ − 2γ/R) s + k₃ = (s + 1/τ)³`.
    Baro {
        /// Loop time constant, s (> 0; 100 s is usual).
        time_constant_s: f64,
    },
}

/// Options of the strapdown algorithms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrapdownOptions {
    /// Apply the two-sample coning correction (increments scheme).
    pub coning: bool,
    /// Apply the rotation and two-sample sculling terms to the velocity increment (increments
    /// scheme).
    pub sculling: bool,
    /// The vertical channel.
    pub vertical: VerticalChannel,
}

impl Default for StrapdownOptions {
    fn default() -> Self {
        Self {
            coning: true,
            sculling: true,
            vertical: VerticalChannel::Free,
        }
    }
}

/// Why a strapdown step was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StrapdownError {
    /// A NaN or infinite input at sample `index`.
    NotFinite {
        /// Sample index.
        index: usize,
    },
    /// Times must increase strictly.
    TimeNotIncreasing {
        /// Sample index.
        index: usize,
    },
    /// The position left the navigation frame's domain: on WGS-84, the latitude left ±89.9°,
    /// where the local NED frame is not used.
    NearPole {
        /// Sample index.
        index: usize,
    },
    /// An option out of its range.
    BadOption {
        /// Which option and its range.
        field: &'static str,
    },
    /// Input slices of different lengths, or an output slice too short.
    LengthMismatch {
        /// Which slice.
        field: &'static str,
        /// Needed length.
        expected: usize,
        /// Its length.
        got: usize,
    },
}

impl core::fmt::Display for StrapdownError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::NotFinite { index } => {
                write!(f, "sample {index} has a value that is not a finite number")
            }
            Self::TimeNotIncreasing { index } => {
                write!(
                    f,
                    "time at sample {index} does not increase after sample {}",
                    index.saturating_sub(1)
                )
            }
            Self::NearPole { index } => write!(
                f,
                "at sample {index} the latitude is beyond ±89.9°, where the local NED frame is \
                 not used (the transport rate grows without bound near the poles)"
            ),
            Self::BadOption { field } => write!(f, "{field}"),
            Self::LengthMismatch {
                field,
                expected,
                got,
            } => write!(f, "{field} has length {got}, expected {expected}"),
        }
    }
}

impl core::error::Error for StrapdownError {}

/// Checks that every `(field, length)` equals `n`.
pub(crate) fn check_lengths(
    n: usize,
    lengths: &[(&'static str, usize)],
) -> Result<(), StrapdownError> {
    match lengths.iter().find(|(_, got)| *got != n) {
        Some(&(field, got)) => Err(StrapdownError::LengthMismatch {
            field,
            expected: n,
            got,
        }),
        None => Ok(()),
    }
}

/// The barometric heights the vertical channel needs: required (of length `n`) for the baro
/// loop, ignored otherwise.
pub(crate) fn check_baro<'a>(
    n: usize,
    baro: Option<&'a [f64]>,
    options: &StrapdownOptions,
) -> Result<Option<&'a [f64]>, StrapdownError> {
    match (options.vertical, baro) {
        (VerticalChannel::Baro { .. }, None) => Err(StrapdownError::BadOption {
            field: "the baro vertical channel needs a barometric height per sample",
        }),
        (VerticalChannel::Baro { .. }, Some(b)) => {
            check_lengths(n, &[("baro_height_m", b.len())])?;
            Ok(Some(b))
        }
        _ => Ok(None),
    }
}
