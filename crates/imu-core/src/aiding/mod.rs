//! Aiding sensors: what a navigator fuses with the IMU. [`gnss`]: a GNSS receiver's position and
//! velocity errors (MATLAB gpsSensor's model, and a Gauss–Markov alternative); [`baro`]: a
//! barometric altimeter and a wheel odometer.
pub mod baro;
pub mod gnss;

pub use baro::SimpleAid;
pub use gnss::{GnssError, GnssModel, GnssParams, GnssState, PositionNoise};
