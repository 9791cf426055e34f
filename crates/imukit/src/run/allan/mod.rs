//! Allan deviation of IMU columns and noise identification, shared by the CLI and Python.
use imu_core::allan::{
    NoiseFit, allan_deviation, deviation_interval, fit_noise, octave_cluster_sizes,
};

use crate::error::{Result, invalid};
use crate::io::table::Table;

mod log;
pub use log::{AllanLog, allan_of_log};

/// One column's noise terms and its curve's 95 % confidence band.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnNoise {
    /// The column.
    pub column: String,
    /// The fitted terms.
    pub fit: NoiseFit,
    /// Lower end of each deviation's 95 % interval, at the table's τ.
    pub lower: Vec<f64>,
    /// Upper end.
    pub upper: Vec<f64>,
    /// The column's mean over the record: at rest a gyroscope's turn-on bias (with the Earth
    /// rate's share on its axis, up to 7.3e-5 rad/s), an accelerometer's bias plus gravity's
    /// share.
    pub mean: f64,
    /// The mean's one-sigma: the deviation of averages over the curve's longest τ (the scatter
    /// the slow terms leave in an average, an upper estimate for the whole record's).
    pub mean_sigma: f64,
    /// Stretches where the column moves instead of resting ([`moving_stretches`]), s from the
    /// first sample.
    pub moving: Vec<(f64, f64)>,
    /// Whether the column reads a constant but for rounding (its shortest-τ deviation within
    /// [`CONSTANT_TO`] of its mean): no noise to identify, its terms all zero.
    pub constant: bool,
}

/// A column whose deviation at the shortest τ is at most this fraction of its mean reads a
/// constant (a simulated ideal sensor, a stuck channel): eleven digits below the value, far
/// above a double's rounding and far below any sensor's noise.
pub const CONSTANT_TO: f64 = 1e-11;

/// Length of the blocks [`moving_stretches`] compares, s.
pub const MOTION_BLOCK_S: f64 = 1.0;

/// How many robust spreads a block's mean must stand off the log's median to count as motion.
pub const MOTION_SPREADS: f64 = 10.0;

/// The stretches of `x` (sampled at `sample_rate_hz`) that move: blocks of [`MOTION_BLOCK_S`]
/// whose mean stands more than [`MOTION_SPREADS`] robust spreads (1.4826 × the median absolute
/// deviation of the block means) off the blocks' median; a static log's block means scatter by
/// its noise alone, so a turn or a push stands out. Adjacent moving blocks are one stretch.
/// Empty for fewer than eight blocks.
#[must_use]
pub fn moving_stretches(x: &[f64], sample_rate_hz: f64) -> Vec<(f64, f64)> {
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let block = ((MOTION_BLOCK_S * sample_rate_hz).round() as usize).max(1);
    let means: Vec<f64> = x
        .chunks_exact(block)
        .map(|c| c.iter().sum::<f64>() / block as f64)
        .collect();
    if means.len() < 8 {
        return Vec::new();
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let centre = median(&mut means.clone());
    let spread = 1.4826 * median(&mut means.iter().map(|m| (m - centre).abs()).collect());
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (k, m) in means.iter().enumerate() {
        if (m - centre).abs() <= MOTION_SPREADS * spread {
            continue;
        }
        let (from, to) = (
            (k * block) as f64 / sample_rate_hz,
            ((k + 1) * block) as f64 / sample_rate_hz,
        );
        match out.last_mut() {
            Some(last) if last.1 >= from => last.1 = to,
            _ => out.push((from, to)),
        }
    }
    out
}

/// Allan deviations of several rate columns at octave-spaced τ.
#[derive(Clone, Debug, PartialEq)]
pub struct AllanResult {
    /// `tau_s` then `adev_<column>` per column.
    pub table: Table,
    /// Noise terms per column, in column order (empty for curves read back from a file, whose
    /// record length is not known).
    pub noise: Vec<ColumnNoise>,
    /// Samples per column.
    pub samples: usize,
    /// Their rate, Hz.
    pub sample_rate_hz: f64,
}

/// Overlapping Allan deviation of each `(name, samples)` at octave cluster sizes, sampled at
/// `sample_rate_hz`, with the noise terms fitted to each curve (`imu_core::allan::fit`).
///
/// # Errors
/// Fewer than 3 samples, non-finite samples (column and index named), a bad rate, a deviation
/// that overflows (values too large to square).
pub fn allan(columns: &[(String, Vec<f64>)], sample_rate_hz: f64) -> Result<AllanResult> {
    let n = columns.first().map_or(0, |(_, v)| v.len());
    let mut m = vec![0usize; 64];
    let count = octave_cluster_sizes(n, &mut m);
    m.truncate(count);
    if count == 0 {
        return Err(invalid(
            "allan",
            format!("need at least 3 samples, got {n}"),
        ));
    }
    let tau: Vec<f64> = m.iter().map(|&k| k as f64 / sample_rate_hz).collect();
    let mut names = vec!["tau_s".to_string()];
    let mut curves = Vec::new();
    let mut noise = Vec::new();
    let mut theta = vec![0.0; n];
    for (name, x) in columns {
        let mut adev = vec![0.0; count];
        allan_deviation(x, sample_rate_hz, &m, &mut theta, &mut adev).map_err(|source| {
            crate::Error::Allan {
                context: name.clone(),
                source,
            }
        })?;
        if let Some(k) = adev.iter().position(|a| !a.is_finite()) {
            let peak = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            return Err(invalid(
                name.clone(),
                format!(
                    "the Allan deviation at τ = {} s overflows (values up to {peak:e}): the column \
                     is not a rate of this magnitude; nothing was written",
                    tau[k]
                ),
            ));
        }
        // A column constant but for rounding has no noise to identify: its curve is fitted
        // as the flat zero it is, and the column is warned about.
        let mean = x.iter().sum::<f64>() / n as f64;
        let constant = adev[0] <= CONSTANT_TO * mean.abs();
        let zeros = vec![0.0; adev.len()];
        let fitted = if constant { &zeros } else { &adev };
        let fit =
            fit_noise(&tau, fitted, &m, n).map_err(|e| invalid(name.clone(), e.to_string()))?;
        let (lower, upper) = adev
            .iter()
            .zip(&fit.edf)
            .map(|(a, nu)| deviation_interval(*a, *nu))
            .unzip();
        noise.push(ColumnNoise {
            column: name.clone(),
            fit,
            lower,
            upper,
            mean,
            mean_sigma: adev[count - 1],
            moving: moving_stretches(x, sample_rate_hz),
            constant,
        });
        names.push(format!("adev_{name}"));
        curves.push(adev);
    }
    let mut data = Vec::with_capacity(count * names.len());
    for (k, t) in tau.iter().enumerate() {
        data.push(*t);
        data.extend(curves.iter().map(|c| c[k]));
    }
    Ok(AllanResult {
        table: Table {
            columns: names,
            data,
        },
        noise,
        samples: n,
        sample_rate_hz,
    })
}

/// The mean sample rate of increasing times `t_s`, Hz.
///
/// # Errors
/// Fewer than 2 samples or times that do not increase.
pub fn mean_rate(t_s: &[f64]) -> Result<f64> {
    if t_s.len() < 2 || t_s[t_s.len() - 1] <= t_s[0] {
        return Err(invalid(
            "t_s",
            "need at least 2 increasing times to find the sample rate",
        ));
    }
    Ok((t_s.len() - 1) as f64 / (t_s[t_s.len() - 1] - t_s[0]))
}
