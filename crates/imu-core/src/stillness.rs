//! Whether the IMU stands still, from its readings alone: the rest at the start of a log that a
//! filter can use to calibrate its gyroscopes ([`initial_rest`]), and the stance phases of a
//! foot-mounted IMU ([`detect_stance`], the SHOE detector) where zero-velocity updates apply.
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
/// than two blocks are still or the noise is not positive. `accel` and `gyro` are rows of
/// readings (the shorter sets the length).
#[must_use]
pub fn initial_rest(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    noise: ReadingNoise,
    window: usize,
) -> usize {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let n = accel.len().min(gyro.len());
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
    // Axis k of the six: the accelerometer's 0–2, the gyroscope's 3–5.
    let axes: [(&[[f64; 3]], usize, f64); 6] = [
        (accel, 0, noise.accel),
        (accel, 1, noise.accel),
        (accel, 2, noise.accel),
        (gyro, 0, noise.gyro),
        (gyro, 1, noise.gyro),
        (gyro, 2, noise.gyro),
    ];
    let mut reference = [0.0; 6];
    let mut still = 0usize;
    let w = window as f64;
    for block in 0..n / window {
        let range = block * window..(block + 1) * window;
        let mut ok = true;
        let mut means = [0.0; 6];
        for (k, &(rows, axis, sigma)) in axes.iter().enumerate() {
            let part = &rows[range.clone()];
            let mean = part.iter().map(|r| r[axis]).sum::<f64>() / w;
            let var = part
                .iter()
                .map(|r| (r[axis] - mean) * (r[axis] - mean))
                .sum::<f64>()
                / (w - 1.0);
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

/// The stance hypothesis' statistic of Skog et al.'s SHOE detector ("Zero-velocity detection —
/// an algorithm evaluation", IEEE Trans. Biomed. Eng. 57(11), 2010) over one window of
/// specific forces `accel` (m/s², body axes, either sign) and bias-free body rates `gyro`
/// (rad/s): `T = (1/W) Σ ( |a_k − g ā/|ā||²/σ_a² + |ω_k|²/σ_ω² )`, `W` the window's length. A
/// still sensor gives `T` about `6 − 3/W` (χ² of `6W − 3` degrees of freedom over `W`).
/// `None` for an empty window or a zero mean acceleration.
#[must_use]
pub fn shoe_statistic(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    gravity_m_s2: f64,
    noise: ReadingNoise,
) -> Option<f64> {
    let w = accel.len().min(gyro.len());
    if w == 0 {
        return None;
    }
    let mut mean = [0.0; 3];
    for a in &accel[..w] {
        for k in 0..3 {
            mean[k] += a[k] / w as f64;
        }
    }
    let norm = math::sqrt(mean.iter().map(|m| m * m).sum::<f64>());
    if norm.is_nan() || norm <= 0.0 {
        return None;
    }
    let g_dir = mean.map(|m| gravity_m_s2 * m / norm);
    let (va, vg) = (noise.accel * noise.accel, noise.gyro * noise.gyro);
    let sum: f64 = accel[..w]
        .iter()
        .zip(&gyro[..w])
        .map(|(a, g)| {
            let da: f64 = (0..3).map(|k| (a[k] - g_dir[k]) * (a[k] - g_dir[k])).sum();
            let dg: f64 = g.iter().map(|x| x * x).sum();
            da / va + dg / vg
        })
        .sum();
    Some(sum / w as f64)
}

/// The SHOE threshold at false-alarm probability `p` for windows of `window` samples: the
/// `1 − p` quantile of χ² with `6·window − 3` degrees of freedom, over `window`.
#[must_use]
pub fn shoe_threshold(window: usize, p: f64) -> f64 {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let dof = (6 * window).saturating_sub(3).max(1) as f64;
    ChiSquared::new(dof).map_or(f64::INFINITY, |c| c.inverse_cdf(1.0 - p) / window as f64)
}

/// Marks each sample whose centred window of `window` samples passes the SHOE test against
/// `threshold` ([`shoe_statistic`], [`shoe_threshold`]) as stance, in `stance` (the length of
/// the readings; samples whose window would run off either end take the nearest full window).
pub fn detect_stance(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    gravity_m_s2: f64,
    noise: ReadingNoise,
    window: usize,
    threshold: f64,
    stance: &mut [bool],
) {
    let n = accel.len().min(gyro.len()).min(stance.len());
    let window = window.max(1);
    if n < window {
        stance[..n].fill(false);
        return;
    }
    for (i, s) in stance[..n].iter_mut().enumerate() {
        let start = i.saturating_sub(window / 2).min(n - window);
        let range = start..start + window;
        *s = shoe_statistic(&accel[range.clone()], &gyro[range], gravity_m_s2, noise)
            .is_some_and(|t| t < threshold);
    }
}
