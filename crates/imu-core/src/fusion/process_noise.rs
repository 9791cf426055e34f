//! The filter's model of a sensor triad from the part's error figures: the continuous PSDs of
//! the white noise and of the bias drift that the simulator's discrete noise has, so that a
//! filter tuned from a part's description is as sure of itself as that part deserves.
use crate::fusion::EskfNoise;
use crate::math;
use crate::sensor::{BiasInstabilityModel, FilterBuffer, NoiseType, SensorParams};

/// The Allan floor of flicker noise per unit bias instability, `√(2 ln 2/π)` (IEEE Std 952).
pub use crate::allan::BIAS_INSTABILITY_FACTOR as FLICKER_FLOOR;

/// The continuous PSDs `(√q_white, √q_drift)` of one triad sampled at `rate_hz` (worst axis),
/// each from the discrete noise the simulator draws:
/// - white: `σ_d = N √β` per sample (`β = fs` single-sided, `fs/2` double-sided), so
///   `√q = σ_d/√fs`; quantisation to a step `r` adds white noise of variance `r²/12` per sample
///   (Widrow's model);
/// - random walk `K/√β` per sample: `√q = K √(fs/β)`;
/// - bias instability `B`: MATLAB's filter (short memory) joins the white noise at its
///   low-frequency gain, `q += (B·|Σb/Σa|)²/fs`; Gauss–Markov (time `T`) joins the drift as a
///   random walk of the same variance growth, `q += 2B²/T`; flicker joins it as the random walk
///   whose Allan deviation `√(qτ/3)` equals the floor `0.664·B` at the floor's geometric centre
///   `√(τ_min τ_max)`.
#[must_use]
pub fn triad_psd<B: FilterBuffer>(p: &SensorParams<B>, rate_hz: f64) -> (f64, f64) {
    let beta = match p.noise_type {
        NoiseType::SingleSided => rate_hz,
        NoiseType::DoubleSided => rate_hz / 2.0,
    };
    let max = |v: [f64; 3]| v.iter().fold(0.0_f64, |a, b| a.max(math::abs(*b)));
    let (n, k, b) = (
        max(p.noise_density),
        max(p.random_walk),
        max(p.bias_instability),
    );
    let mut white =
        math::sqrt(n * n * beta / rate_hz + p.resolution * p.resolution / (12.0 * rate_hz));
    let walk = k * math::sqrt(rate_hz / beta);
    let mut drift_q = walk * walk;
    match &p.bias_instability_model {
        BiasInstabilityModel::Filter(c) => {
            let gain = c.numerator().iter().sum::<f64>() / c.denominator().iter().sum::<f64>();
            let g = b * math::abs(gain);
            white = math::sqrt(white * white + g * g / rate_hz);
        }
        BiasInstabilityModel::Flicker {
            tau_min_s,
            tau_max_s,
        } => {
            let tau_c = math::sqrt(tau_min_s * tau_max_s);
            let floor = FLICKER_FLOOR * b;
            drift_q += 3.0 * floor * floor / tau_c;
        }
        BiasInstabilityModel::GaussMarkov { correlation_time_s } => {
            drift_q += 2.0 * b * b / correlation_time_s;
        }
    }
    (white, math::sqrt(drift_q))
}

/// The filter's noise for an IMU of accelerometer `accel` and gyroscope `gyro` sampled at
/// `rate_hz` ([`triad_psd`] of each).
#[must_use]
pub fn eskf_noise<B: FilterBuffer>(
    accel: &SensorParams<B>,
    gyro: &SensorParams<B>,
    rate_hz: f64,
) -> EskfNoise {
    let (accel_psd, accel_bias_psd) = triad_psd(accel, rate_hz);
    let (gyro_psd, gyro_bias_psd) = triad_psd(gyro, rate_hz);
    EskfNoise {
        accel_psd,
        gyro_psd,
        accel_bias_psd,
        gyro_bias_psd,
    }
}
