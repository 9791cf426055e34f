//! Whether the IMU stands still, from its readings alone: the rest at the start of a log that a
//! filter can use to calibrate its gyroscopes.
//!
//! The readings are cut into blocks of `window` samples. A block is still when, on each of the
//! six axes, (a) its sample variance is within what the sensor's white noise allows —
//! `s² ≤ σ²·χ²_{W−1, 1−p}/(W−1)` — and (b) its mean has not moved from the mean of the still
//! blocks before it by more than the noise allows, `|x̄ − x̄_ref| ≤ z_p·σ·√(1/W + 1/N_ref)`.
//! Both tests are on differences, so a constant bias (a consumer gyroscope's 20 °/s) does not
//! matter; a vehicle that vibrates more than the sensor's noise, or starts to move, fails one of
//! them. `p` is small ([`FALSE_ALARM`]) because many blocks and axes are tested: a still log
//! is rarely cut short, and motion is found within a block of its start.

use crate::math;

/// Probability that one axis of one still block fails a test by chance.
pub const FALSE_ALARM: f64 = 1e-6;

/// The normal quantile two-sided at [`FALSE_ALARM`] (`z` with `P(|N| > z) = 1e-6`).
const Z_FALSE_ALARM: f64 = 4.891_638_475_699_412;

/// The white noise of the readings the test expects, one sample's standard deviation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadingNoise {
    /// Accelerometer, m/s² per sample.
    pub accel: f64,
    /// Gyroscope, rad/s per sample.
    pub gyro: f64,
}

/// The number of samples from the first that are still, a whole number of blocks of `window`
/// samples with the last still block left out (motion may start inside it unseen); 0 when fewer
/// than two blocks are still or the noise is not positive. `accel` and `gyro` are the three
/// axes' readings, all of one length.
#[must_use]
pub fn initial_rest(
    accel: [&[f64]; 3],
    gyro: [&[f64]; 3],
    noise: ReadingNoise,
    window: usize,
) -> usize {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let n = accel
        .iter()
        .chain(gyro.iter())
        .map(|a| a.len())
        .min()
        .unwrap_or(0);
    if window < 2
        || n < 2 * window
        || !(noise.accel > 0.0 && noise.gyro > 0.0)
        || !(noise.accel.is_finite() && noise.gyro.is_finite())
    {
        return 0;
    }
    let Ok(chi) = ChiSquared::new((window - 1) as f64) else {
        return 0;
    };
    let variance_limit = chi.inverse_cdf(1.0 - FALSE_ALARM) / (window - 1) as f64;
    let axes: [(&[f64], f64); 6] = [
        (accel[0], noise.accel),
        (accel[1], noise.accel),
        (accel[2], noise.accel),
        (gyro[0], noise.gyro),
        (gyro[1], noise.gyro),
        (gyro[2], noise.gyro),
    ];
    let mut reference = [0.0; 6];
    let mut still = 0usize;
    let w = window as f64;
    for block in 0..n / window {
        let range = block * window..(block + 1) * window;
        let mut ok = true;
        let mut means = [0.0; 6];
        for (k, (x, sigma)) in axes.iter().enumerate() {
            let part = &x[range.clone()];
            let mean = part.iter().sum::<f64>() / w;
            let var = part.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (w - 1.0);
            means[k] = mean;
            if var.partial_cmp(&(sigma * sigma * variance_limit))
                == Some(core::cmp::Ordering::Greater)
                || var.is_nan()
            {
                ok = false;
                break;
            }
            if still > 0 {
                let n_ref = (still * window) as f64;
                let allowed = Z_FALSE_ALARM * sigma * math::sqrt(1.0 / w + 1.0 / n_ref);
                let shift = math::abs(mean - reference[k]);
                if shift.is_nan() || shift > allowed {
                    ok = false;
                    break;
                }
            }
        }
        if !ok {
            break;
        }
        // The reference is the mean of every still block so far.
        let s = still as f64;
        for (r, m) in reference.iter_mut().zip(means) {
            *r = (*r * s + m) / (s + 1.0);
        }
        still += 1;
    }
    if still < 2 { 0 } else { (still - 1) * window }
}
