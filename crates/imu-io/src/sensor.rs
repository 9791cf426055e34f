//! The core's sensor types with their bias-instability filters on the heap, so a filter may be
//! as long as MATLAB's (its Allan example uses `fractalcoef(500)`: 501 coefficients).
//!
//! The core (`imu_core::sensor`) holds at most
//! [`MAX_FILTER_COEFFICIENTS`](imu_core::sensor::MAX_FILTER_COEFFICIENTS) coefficients inline and
//! never allocates; its types are generic over a [`FilterBuffer`]. This crate supplies
//! [`HeapBuffer`] and names the types it uses with it. Filters of up to 33 coefficients keep
//! their memory inline even here; longer ones allocate it once per run and axis.
use imu_core::sensor::FilterBuffer;

/// Most numerator or denominator coefficients a bias-instability filter may have: 4096 (order
/// 4095). The cost per sample grows with the length (one multiply-add per coefficient and
/// axis), so the bound also bounds the work; a 1/f floor of any length is the flicker model.
pub const MAX_FILTER_COEFFICIENTS: usize = 4096;

/// Filter coefficients or memory in a `Vec`, at most [`MAX_FILTER_COEFFICIENTS`] values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HeapBuffer(Vec<f64>);

impl FilterBuffer for HeapBuffer {
    const CAPACITY: usize = MAX_FILTER_COEFFICIENTS;

    fn zeros(len: usize) -> Option<Self> {
        (len <= MAX_FILTER_COEFFICIENTS).then(|| Self(vec![0.0; len]))
    }

    fn as_slice(&self) -> &[f64] {
        &self.0
    }

    fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.0
    }
}

/// One triad's parameters ([`imu_core::sensor::SensorParams`]), filters of any length.
pub type SensorParams = imu_core::sensor::SensorParams<HeapBuffer>;
/// The bias-instability generator ([`imu_core::sensor::BiasInstabilityModel`]).
pub type BiasInstabilityModel = imu_core::sensor::BiasInstabilityModel<HeapBuffer>;
/// MATLAB's `Numerator`/`Denominator` ([`imu_core::sensor::FilterCoefficients`]).
pub type FilterCoefficients = imu_core::sensor::FilterCoefficients<HeapBuffer>;
/// A validated IMU in navigation frame `N` ([`imu_core::sensor::ImuModel`]).
pub type ImuModel<N> = imu_core::sensor::ImuModel<N, HeapBuffer>;
/// What drifts in an IMU ([`imu_core::sensor::ImuState`]).
pub type ImuState = imu_core::sensor::ImuState<HeapBuffer>;
/// A signal chain whose filters are on the heap ([`HeapBuffer`]: long averages and FIR filters).
pub type Chain = imu_core::signal::Chain<HeapBuffer>;
/// The memory of a [`Chain`].
pub type ChainState = imu_core::signal::ChainState<HeapBuffer>;
