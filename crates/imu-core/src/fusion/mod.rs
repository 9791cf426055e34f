//! Fusion of the IMU with aiding sensors: [`eskf`], a loosely coupled error-state Kalman filter
//! (15 states, fixed-size matrices, no heap) on the flat-Earth mechanization.
pub mod eskf;

pub use eskf::{Eskf, EskfError, EskfNoise, EskfState, GnssFix, InitialSigma, UpdateOutcome};
