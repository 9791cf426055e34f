//! Fusion of the IMU with aiding sensors: [`eskf`], a loosely coupled error-state Kalman filter
//! (15 states, or 36 with the sensors' scale-factor, misalignment and g-sensitivity errors of
//! [`sensor_errors`], either with three more for the fixes' correlated errors of [`fix_errors`];
//! fixed-size matrices, no heap) on any [`crate::earth::EarthModel`], and
//! [`smoother`], its forward–backward (RTS) smoothing, [`align`], where it starts without a
//! reference attitude, [`gate`], its innovation gate, and
//! [`process_noise`], its model of a part from the part's figures.
pub mod align;
pub mod eskf;
pub mod fix_errors;
pub mod gate;
pub mod process_noise;
pub mod sensor_errors;
pub mod smoother;

pub use eskf::{
    BodyVelocity, Eskf, EskfError, EskfNoise, EskfState, GnssFix, Height, InitialSigma,
    Measurement, UpdateOutcome, ZeroRate, corrected_state,
};
pub use fix_errors::{FIX_ERROR_STATES, FixErrorModel, has_fix_errors, has_sensor_errors};
pub use sensor_errors::{BASE_STATES, FULL_STATES, SensorErrorEstimate, SensorErrorSigma};
