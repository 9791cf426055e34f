//! Where filters keep their coefficients and memory: on the stack in the core, on the heap in
//! a crate that has one.
use core::fmt;

/// Largest number of numerator or denominator coefficients of the bias-instability filter that
/// [`InlineBuffer`], the core's own storage, holds (order up to 7): the core has no heap. A crate
/// with a heap supplies a [`FilterBuffer`] of its own to take longer filters (MATLAB takes any
/// length; the library crate `imukit` takes thousands).
pub const MAX_FILTER_COEFFICIENTS: usize = 8;

/// Where a filter (a bias-instability filter, a signal chain's section) keeps its coefficients
/// and its memory: a list of `f64` of fixed length, at most [`Self::CAPACITY`] long.
///
/// The sensor types ([`SensorParams`](crate::sensor::SensorParams), [`SensorModel`](crate::sensor::SensorModel),
/// [`SensorState`](crate::sensor::SensorState), [`ImuModel`](crate::sensor::ImuModel),
/// [`ImuState`](crate::sensor::ImuState)) are generic over it, [`InlineBuffer`] by default. In
/// expressions Rust does not apply that default by itself: name the type once
/// (`let p: SensorParams = SensorParams { .. }`) and the rest follows.
pub trait FilterBuffer: Clone + fmt::Debug + PartialEq + Default {
    /// Most values one buffer holds (≥ 2).
    const CAPACITY: usize;
    /// A buffer of `len` zeros; `None` beyond [`Self::CAPACITY`].
    fn zeros(len: usize) -> Option<Self>;
    /// The values.
    fn as_slice(&self) -> &[f64];
    /// The values, to write.
    fn as_mut_slice(&mut self) -> &mut [f64];
    /// A buffer holding a copy of `values`; `None` beyond [`Self::CAPACITY`].
    fn from_slice(values: &[f64]) -> Option<Self> {
        let mut b = Self::zeros(values.len())?;
        b.as_mut_slice().copy_from_slice(values);
        Some(b)
    }
}

/// The core's filter storage: up to [`MAX_FILTER_COEFFICIENTS`] values, inline.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InlineBuffer {
    values: [f64; MAX_FILTER_COEFFICIENTS],
    len: usize,
}

impl FilterBuffer for InlineBuffer {
    const CAPACITY: usize = MAX_FILTER_COEFFICIENTS;

    fn zeros(len: usize) -> Option<Self> {
        (len <= MAX_FILTER_COEFFICIENTS).then_some(Self {
            values: [0.0; MAX_FILTER_COEFFICIENTS],
            len,
        })
    }

    fn as_slice(&self) -> &[f64] {
        &self.values[..self.len]
    }

    fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.values[..self.len]
    }
}
