//! Sensor error models: MATLAB `imuSensor` parity, then beyond (docs/models.md §2).
//!
//! Per sensor and sample, with `u` the ideal input in the sensor frame:
//! 1. bulk `B = (M/100)·u + ConstantBias` (AxesMisalignment `M` in percent);
//! 2. drift `D` = bias instability (`filter(Num, Den, BiasInstability·n)`, persistent state) +
//!    white (`NoiseDensity·√β·n`) + random walk (`x_k = x_{k−1} + RandomWalk/√β·n`), with
//!    bandwidth `β = fs/2` (double-sided) or `fs` (single-sided, the default);
//! 3. environment `E = (T − 25)·TemperatureBias (+ AccelerationBias ⊙ a` for the gyroscope);
//! 4. scale `y = (1 + (T − 25)·TemperatureScaleFactor/100) ⊙ (B + D + E)`;
//! 5. saturation at ±MeasurementRange; 6. quantisation `Resolution·round(y/Resolution)`, half
//!    away from zero.
//!
//! Nine standard normals are drawn per sensor and sample, always, in the order bias instability
//! (x, y, z), white (x, y, z), random walk (x, y, z); sensors in the order accelerometer,
//! gyroscope, magnetometer. Parameters ([`SensorParams`]) are plain data; [`SensorModel`] is the
//! validated model; [`SensorState`] holds what drifts, so one model serves many runs.
mod error;
mod imu;
pub mod increments;
mod model;
mod noise;
mod params;

pub use error::ParamError;
pub use imu::{
    GyroAccelerationInput, ImuModel, ImuParamError, ImuReading, ImuState, MEASURE_BLOCK,
    SensingElement, SensorSet, Temperatures,
};
pub use model::MAX_FLICKER_SECTIONS;
pub use model::{Environment, Nonlinearity, SensorModel, SensorState};
pub use noise::{NoNoise, NoiseSource, SeededNormals};
pub use params::{
    BiasInstabilityModel, FilterBuffer, FilterCoefficients, InlineBuffer, MAX_FILTER_COEFFICIENTS,
    NoiseType, SensorParams,
};
