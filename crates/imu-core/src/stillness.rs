//! Whether the IMU stands still, from its readings alone: the rest at the start of a log that a
//! filter can use to calibrate its gyroscopes ([`initial_rest`]), and the stance phases of a
//! foot-mounted IMU ([`detect_stance`], the SHOE detector) where zero-velocity updates apply.
//! Both need the sensor's white noise; [`quiet_noise`] learns it from the log's quiet stretches
//! when no data sheet is trusted.
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

/// The SHOE statistic of each sample's centred window of `window` samples, in `statistic` (the
/// length of the readings; samples whose window would run off either end take the nearest full
/// window; `f64::INFINITY` where the statistic is undefined, a zero mean acceleration).
pub fn shoe_statistics(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    gravity_m_s2: f64,
    noise: ReadingNoise,
    window: usize,
    statistic: &mut [f64],
) {
    let n = accel.len().min(gyro.len()).min(statistic.len());
    let window = window.max(1);
    if n < window {
        statistic[..n].fill(f64::INFINITY);
        return;
    }
    for (i, s) in statistic[..n].iter_mut().enumerate() {
        let range = centred_window(i, n, window);
        *s = shoe_statistic(&accel[range.clone()], &gyro[range], gravity_m_s2, noise)
            .unwrap_or(f64::INFINITY);
    }
}

/// The window of `window` samples centred on sample `i` of `n` (`window ≤ n`), the nearest
/// full window where it would run off either end.
fn centred_window(i: usize, n: usize, window: usize) -> core::ops::Range<usize> {
    let start = i.saturating_sub(window / 2).min(n - window);
    start..start + window
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
        let range = centred_window(i, n, window);
        *s = shoe_statistic(&accel[range.clone()], &gyro[range], gravity_m_s2, noise)
            .is_some_and(|t| t < threshold);
    }
}

/// Bins of the histogram [`two_population_threshold`] splits.
pub const POPULATION_BINS: usize = 256;

/// The least share of the samples each population must hold for a split to count.
pub const MIN_POPULATION_SHARE: f64 = 0.05;

/// The least distance between the two populations' mean logarithms, decades: a walking foot's
/// stances and swings lie three to six decades apart in the SHOE statistic.
pub const MIN_POPULATION_SEPARATION: f64 = 1.0;

/// The least share of the statistics' variance the split between the stances and the swings
/// above a walk's rests must explain (Otsu's effectiveness, between-class over total variance)
/// for [`stance_threshold`] to take it: one normal population split in two gives about 0.64
/// and a uniform one 0.75, two populations decades apart nearly 1 (a simulated foot that
/// stands still has swings alone above its split, and they are not split again).
pub const MIN_SPLIT_EFFECTIVENESS: f64 = 0.8;

/// One population of a split: its mean and standard deviation of the decimal logarithm and its
/// number of statistics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Population {
    /// Mean of `log10` of its statistics.
    pub mean_log: f64,
    /// Standard deviation of `log10` of its statistics.
    pub sd_log: f64,
    /// How many statistics it holds.
    pub count: usize,
}

/// Otsu's split of the logarithms of some statistics into two populations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PopulationSplit {
    /// The threshold between them (the statistic, not its logarithm).
    pub threshold: f64,
    /// The population below it.
    pub lower: Population,
    /// The population above it.
    pub upper: Population,
    /// The share of the logarithms' variance the split explains.
    pub effectiveness: f64,
}

/// Otsu's split (the one that maximises the variance between the two classes) of the histogram
/// of the decimal logarithms of the finite positive `statistics` above `above`, in
/// [`POPULATION_BINS`] bins; `None` unless it separates two populations: each at least
/// [`MIN_POPULATION_SHARE`] of the statistics split, their mean logarithms at least
/// [`MIN_POPULATION_SEPARATION`] decades apart.
#[must_use]
pub fn population_split(statistics: &[f64], above: f64) -> Option<PopulationSplit> {
    let logs = || {
        statistics
            .iter()
            .filter(move |t| t.is_finite() && **t > 0.0 && **t > above)
            .map(|t| num_traits::Float::log10(*t))
    };
    let (lo, hi) = logs().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    if hi.partial_cmp(&lo) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let width = (hi - lo) / POPULATION_BINS as f64;
    let mut count = [0usize; POPULATION_BINS];
    let mut sum = [0.0; POPULATION_BINS];
    let mut squares = [0.0; POPULATION_BINS];
    for x in logs() {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let k = (((x - lo) / width) as usize).min(POPULATION_BINS - 1);
        count[k] += 1;
        sum[k] += x;
        squares[k] += x * x;
    }
    let total: usize = count.iter().sum();
    let total_sum: f64 = sum.iter().sum();
    let (mut n0, mut s0) = (0usize, 0.0);
    // (between-class variance × total², bins in the lower class)
    let mut best: Option<(f64, usize)> = None;
    for k in 0..POPULATION_BINS - 1 {
        n0 += count[k];
        s0 += sum[k];
        let n1 = total - n0;
        if n0 == 0 || n1 == 0 {
            continue;
        }
        let (m0, m1) = (s0 / n0 as f64, (total_sum - s0) / n1 as f64);
        let between = n0 as f64 * n1 as f64 * (m1 - m0) * (m1 - m0);
        if best.is_none_or(|b| between > b.0) {
            best = Some((between, k + 1));
        }
    }
    let (between, bins) = best?;
    let class = |range: core::ops::Range<usize>| {
        let n: usize = count[range.clone()].iter().sum();
        let s: f64 = sum[range.clone()].iter().sum();
        let q: f64 = squares[range].iter().sum();
        let mean = s / n as f64;
        Population {
            mean_log: mean,
            sd_log: math::sqrt((q / n as f64 - mean * mean).max(0.0)),
            count: n,
        }
    };
    let (lower, upper) = (class(0..bins), class(bins..POPULATION_BINS));
    let n = total as f64;
    let mean = total_sum / n;
    let variance = squares.iter().sum::<f64>() / n - mean * mean;
    let effectiveness = between / (n * n) / variance;
    let share = lower.count as f64 / n;
    if !(MIN_POPULATION_SHARE..=1.0 - MIN_POPULATION_SHARE).contains(&share)
        || upper.mean_log - lower.mean_log < MIN_POPULATION_SEPARATION
    {
        return None;
    }
    // The split lies at the upper edge of the last bin of the lower population.
    Some(PopulationSplit {
        threshold: num_traits::Float::powf(10.0, lo + bins as f64 * width),
        lower,
        upper,
        effectiveness,
    })
}

/// The threshold that splits a detector's statistics into two populations, learnt from the
/// statistics themselves ([`population_split`] of all of them).
///
/// A real foot does not stand still: it rolls from heel to toe, so its stances read rates far
/// above its gyroscope's noise while the sensor does not move, and a threshold from the noise
/// alone ([`shoe_threshold`]) finds few of them. Its stances and swings still form two
/// populations decades apart, which the split separates. `None` for a log all at rest or all in
/// motion (no second population).
#[must_use]
pub fn two_population_threshold(statistics: &[f64]) -> Option<f64> {
    population_split(statistics, 0.0).map(|s| s.threshold)
}

/// The stance detector's threshold learnt from a walk's SHOE statistics; `None` without two
/// populations ([`population_split`]).
///
/// A walk with long rests has three populations: the rests, at the noise; the stances, where
/// the foot rolls from heel to toe at rates far above the noise; the swings. The split of all
/// of them then falls between the rests and the stances and misses the rolling stances; when
/// the statistics above the split hold two populations of their own (split explaining at least
/// [`MIN_SPLIT_EFFECTIVENESS`] of their variance), the stances are the lower of those. The
/// threshold is then the stances' mean plus one standard deviation (of the logarithm), at most
/// their split from the swings: a stance's upper tail is the foot striking the ground and
/// pushing off, when it moves, and a zero-velocity update there pulls the estimate off. With
/// two populations only, the split between them.
#[must_use]
pub fn stance_threshold(statistics: &[f64]) -> Option<f64> {
    let split = population_split(statistics, 0.0)?;
    let above = population_split(statistics, split.threshold)
        .filter(|s| s.effectiveness >= MIN_SPLIT_EFFECTIVENESS);
    match above {
        Some(stances) => {
            let edge = num_traits::Float::powf(10.0, stances.lower.mean_log + stances.lower.sd_log);
            Some(edge.min(stances.threshold))
        }
        None => Some(split.threshold),
    }
}

/// The sample variance of a block of rows pooled over its three axes (`3(W − 1)` degrees of
/// freedom); NaN for fewer than two rows.
pub(crate) fn pooled_variance(rows: &[[f64; 3]]) -> f64 {
    let w = rows.len() as f64;
    let mut sum = 0.0;
    for k in 0..3 {
        let mean = rows.iter().map(|r| r[k]).sum::<f64>() / w;
        sum += rows
            .iter()
            .map(|r| (r[k] - mean) * (r[k] - mean))
            .sum::<f64>();
    }
    sum / (3.0 * (w - 1.0))
}

/// The largest pooled variance of a still block of `window` rows, over the white noise's
/// (`χ²_{3(W−1)}` quantile at `1 − FALSE_ALARM`, over `3(W − 1)`); `None` for a window under 2.
pub(crate) fn quiet_variance_limit(window: usize) -> Option<f64> {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    if window < 2 {
        return None;
    }
    let dof = 3.0 * (window - 1) as f64;
    Some(ChiSquared::new(dof).ok()?.inverse_cdf(1.0 - FALSE_ALARM) / dof)
}

/// What the quiet stretches of a log say about its sensor ([`quiet_noise`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuietStretches {
    /// The white noise, one sample's standard deviation per axis (pooled over the axes).
    pub noise: ReadingNoise,
    /// The mean magnitude of the specific force there, m/s²: gravity as this accelerometer
    /// reads it (its bias included).
    pub gravity_reading_m_s2: f64,
    /// The quiet blocks found.
    pub quiet_blocks: usize,
    /// All blocks of the log.
    pub blocks: usize,
}

/// The least number of quiet blocks [`quiet_noise`] learns from.
pub const MIN_QUIET_BLOCKS: usize = 4;

/// How far a quiet block's mean specific force may be from gravity (a fraction): a consumer
/// accelerometer's bias of a few 0.01 g passes, a swing does not.
pub const QUIET_GRAVITY_TOLERANCE: f64 = 0.1;

/// The largest mean rate of a quiet block, rad/s (about 29 °/s: above a consumer gyroscope's
/// bias, below a foot's or a hand's swing).
pub const QUIET_MAX_RATE_RAD_S: f64 = 0.5;

/// The fixed point's iterations at most (it settles in a few).
const MAX_ITERATIONS: usize = 50;

/// The share of the blocks from whose variance [`quiet_noise`] starts (its 5th percentile):
/// a log whose quiet share is at least twice this starts from within its quiet population.
const START_QUANTILE: f64 = 0.05;

/// The white noise of readings `accel`, `gyro` learnt from the log itself: the readings cut
/// into blocks of `window` samples, each block's variance pooled over the three axes of each
/// sensor (`3(W − 1)` degrees of freedom), and the quiet population separated from the moving
/// one by a fixed point — start from the blocks' 5th percentile; call a block quiet when both
/// its variances are within the `1 − FALSE_ALARM` quantile of `σ² χ²_{3(W−1)}/(3(W−1))`;
/// `σ²` the mean of the quiet blocks' variances over the mean that quantile truncation leaves
/// (`P(χ²_{k+2} ≤ kc)/P(χ²_k ≤ kc)`); repeat until the quiet set no longer changes.
/// A motion's blocks, whose variance is far above the noise, never join; nor does a block
/// whose mean specific force is off `gravity_m_s2` by more than [`QUIET_GRAVITY_TOLERANCE`] or
/// whose mean rate exceeds [`QUIET_MAX_RATE_RAD_S`] (the crest of a slow swing is smooth but not
/// still). A log that is quiet throughout is one population. `blocks` is the caller's room for one row per block (at least
/// `n / window` rows; its contents are overwritten). `None` with fewer than
/// [`MIN_QUIET_BLOCKS`] quiet blocks, a `window` under 2, too little room, or a noise of zero
/// (readings quantised flat) or not finite.
#[must_use]
pub fn quiet_noise(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    window: usize,
    gravity_m_s2: f64,
    blocks: &mut [[f64; 3]],
) -> Option<QuietStretches> {
    quiet_noise_below(
        accel,
        gyro,
        window,
        gravity_m_s2,
        QUIET_MAX_RATE_RAD_S,
        blocks,
    )
}

/// [`quiet_noise`] with the largest mean rate of a quiet block `max_rate_rad_s` instead of
/// [`QUIET_MAX_RATE_RAD_S`] (a calibration, whose rests hold still but whose gyroscope may read
/// a consumer part's bias of tens of degrees a second).
#[must_use]
pub fn quiet_noise_below(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    window: usize,
    gravity_m_s2: f64,
    max_rate_rad_s: f64,
    blocks: &mut [[f64; 3]],
) -> Option<QuietStretches> {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let n = accel.len().min(gyro.len());
    if window < 2 || n < MIN_QUIET_BLOCKS * window || blocks.len() < n / window {
        return None;
    }
    let stats = &mut blocks[..n / window];
    let w = window as f64;
    let dof = 3.0 * (w - 1.0);
    let chi = ChiSquared::new(dof).ok()?;
    let chi2 = ChiSquared::new(dof + 2.0).ok()?;
    let limit = quiet_variance_limit(window)?;
    let truncation = chi2.cdf(dof * limit) / chi.cdf(dof * limit);
    // Per block: accelerometer and gyroscope variances, and the mean specific force's norm.
    for (b, row) in stats.iter_mut().enumerate() {
        let range = b * window..(b + 1) * window;
        let (a, g) = (&accel[range.clone()], &gyro[range]);
        let norm_of_mean = |rows: &[[f64; 3]]| {
            let mean = [0, 1, 2].map(|k| rows.iter().map(|r| r[k]).sum::<f64>() / w);
            math::sqrt(mean.iter().map(|m| m * m).sum::<f64>())
        };
        let force = norm_of_mean(a);
        let still = math::abs(force - gravity_m_s2) <= QUIET_GRAVITY_TOLERANCE * gravity_m_s2
            && norm_of_mean(g) <= max_rate_rad_s;
        // A block that cannot be still gets an infinite variance: never quiet.
        *row = if still {
            [pooled_variance(a), pooled_variance(g), force]
        } else {
            [f64::INFINITY, f64::INFINITY, force]
        };
    }
    if stats.iter().flatten().any(|v| v.is_nan()) || !gravity_m_s2.is_finite() {
        return None;
    }
    let total = stats.len();
    // The blocks' q-quantile of column k (the rows are reordered, not changed).
    let mut quantile = |k: usize, q: f64| {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let at = ((q * total as f64) as usize).min(total - 1);
        stats.select_nth_unstable_by(at, |a, b| a[k].total_cmp(&b[k]));
        stats[at][k]
    };
    let start = [quantile(0, START_QUANTILE), quantile(1, START_QUANTILE)];
    // The quiet blocks' count and sums under the variances `sigma2`.
    let quiet_sums = |stats: &[[f64; 3]], sigma2: [f64; 2]| {
        stats
            .iter()
            .filter(|s| s[0] <= sigma2[0] * limit && s[1] <= sigma2[1] * limit)
            .fold((0usize, [0.0; 3]), |(c, sum), s| {
                (c + 1, [sum[0] + s[0], sum[1] + s[1], sum[2] + s[2]])
            })
    };
    let usable = |s: [f64; 2]| s.iter().all(|v| v.is_finite() && *v > 0.0);
    let mut sigma2 = start;
    let mut quiet = 0usize;
    for _ in 0..MAX_ITERATIONS {
        if !usable(sigma2) {
            return None;
        }
        let (count, sum) = quiet_sums(stats, sigma2);
        if count < MIN_QUIET_BLOCKS {
            return None;
        }
        let next = [0, 1].map(|k| sum[k] / count as f64 / truncation);
        let settled = count == quiet;
        quiet = count;
        sigma2 = next;
        if settled {
            break;
        }
    }
    let (count, sum) = quiet_sums(stats, sigma2);
    if count < MIN_QUIET_BLOCKS || !usable(sigma2) {
        return None;
    }
    Some(QuietStretches {
        noise: ReadingNoise {
            accel: math::sqrt(sigma2[0]),
            gyro: math::sqrt(sigma2[1]),
        },
        gravity_reading_m_s2: sum[2] / count as f64,
        quiet_blocks: count,
        blocks: total,
    })
}
