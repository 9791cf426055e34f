//! Float functions that work with either `std` or `libm` (through `num_traits::Float`).
use num_traits::Float;

#[inline]
pub(crate) fn sin(x: f64) -> f64 {
    Float::sin(x)
}
#[inline]
pub(crate) fn cos(x: f64) -> f64 {
    Float::cos(x)
}
#[inline]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    Float::atan2(y, x)
}
#[inline]
pub(crate) fn sqrt(x: f64) -> f64 {
    Float::sqrt(x)
}
#[inline]
pub(crate) fn abs(x: f64) -> f64 {
    Float::abs(x)
}
#[inline]
pub(crate) fn round(x: f64) -> f64 {
    Float::round(x)
}

/// Adds the multiple of 2π to `angle` that brings it closest to `reference` (angle unwrapping).
#[inline]
pub(crate) fn unwrap_near(angle: f64, reference: f64) -> f64 {
    let two_pi = 2.0 * core::f64::consts::PI;
    angle + two_pi * round((reference - angle) / two_pi)
}

#[inline]
pub(crate) fn exp(x: f64) -> f64 {
    Float::exp(x)
}
#[inline]
pub(crate) fn ln(x: f64) -> f64 {
    Float::ln(x)
}
#[inline]
pub(crate) fn powf(x: f64, y: f64) -> f64 {
    Float::powf(x, y)
}
#[inline]
pub(crate) fn ceil(x: f64) -> f64 {
    Float::ceil(x)
}
