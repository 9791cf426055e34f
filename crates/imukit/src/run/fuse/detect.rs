//! The detectors a fusion runs on the readings: the rest at the start (the gyroscope biases
//! are learnt there) and the stances of a foot-mounted IMU (zero-velocity updates), each with
//! the part's white noise ([`imu_core::stillness`]).
use super::FuseSetup;

/// One-sigma of the zero-velocity update at a stance on the move, m/s (OpenShoe's figure).
pub const STANCE_VELOCITY_SIGMA_M_S: f64 = 0.01;

/// Window of the stance detector, s (Skog et al. use 3 to 5 samples at 100 Hz and more).
pub const STANCE_WINDOW_S: f64 = 0.05;

/// False-alarm probability of the stance detector per sample.
pub const STANCE_FALSE_ALARM: f64 = 1e-3;

/// The samples of readings `f`, `w` (specific force and rate, times `t`) that are stances
/// ([`FuseSetup::zupt`]), as the fusion finds them.
pub fn stance_samples(t: &[f64], f: &[[f64; 3]], w: &[[f64; 3]], setup: &FuseSetup) -> Vec<bool> {
    use imu_core::stillness::{detect_stance, shoe_threshold};
    let mut stance = vec![false; t.len()];
    let Some((interval, noise)) = reading_noise(t, setup) else {
        return stance;
    };
    // The rest's mean rate is the bias the detector's zero-rate test must not see.
    let rest = t.partition_point(|&x| x < t[0] + setup.rest_s);
    let bias = if rest > 0 {
        [0, 1, 2].map(|k| w[..rest].iter().map(|x| x[k]).sum::<f64>() / rest as f64)
    } else {
        [0.0; 3]
    };
    let gyro: Vec<[f64; 3]> = w
        .iter()
        .map(|x| [x[0] - bias[0], x[1] - bias[1], x[2] - bias[2]])
        .collect();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let window = ((STANCE_WINDOW_S / interval).round() as usize).max(3);
    detect_stance(
        f,
        &gyro,
        setup.gravity_m_s2,
        noise,
        window,
        shoe_threshold(window, STANCE_FALSE_ALARM),
        &mut stance,
    );
    stance
}

/// Block length of the rest detector, s.
pub const REST_WINDOW_S: f64 = 0.5;

/// A start faster than this, m/s, is not at rest: no rest is looked for.
pub const REST_START_SPEED_M_S: f64 = 0.1;

/// The rest at the start of readings `f`, `w` at times `t`, s ([`imu_core::stillness`] with the
/// part's white noise per sample and blocks of [`REST_WINDOW_S`]).
pub(super) fn detected_rest_s(t: &[f64], f: &[[f64; 3]], w: &[[f64; 3]], setup: &FuseSetup) -> f64 {
    let Some((interval, noise)) = reading_noise(t, setup) else {
        return 0.0;
    };
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let window = ((REST_WINDOW_S / interval).round() as usize).max(2);
    let still = imu_core::stillness::initial_rest(f, w, noise, window);
    if still == 0 { 0.0 } else { t[still] - t[0] }
}

/// The mean interval of the times `t` and the part's white noise over one such interval, the
/// stillness tests' noise; `None` for fewer than three samples or times that do not advance.
fn reading_noise(t: &[f64], setup: &FuseSetup) -> Option<(f64, imu_core::stillness::ReadingNoise)> {
    let n = t.len();
    if n < 3 {
        return None;
    }
    let interval = (t[n - 1] - t[0]) / (n - 1) as f64;
    if interval.is_nan() || interval <= 0.0 {
        return None;
    }
    let per_sample = |psd: f64| psd / interval.sqrt();
    Some((
        interval,
        imu_core::stillness::ReadingNoise {
            accel: per_sample(setup.noise.accel_psd),
            gyro: per_sample(setup.noise.gyro_psd),
        },
    ))
}
