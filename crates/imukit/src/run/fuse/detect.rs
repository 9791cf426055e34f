//! The detectors a fusion runs on the readings: the rest at the start (the gyroscope biases
//! are learnt there) and the stances of a foot-mounted IMU (zero-velocity updates). Both test
//! the readings against their white noise: the noise the log itself shows in its quiet
//! stretches ([`imu_core::stillness::quiet_noise`]) when it has enough of them, else the
//! part's; the stances against gravity as this accelerometer reads it at rest (its bias
//! included), not nominal gravity.
use imu_core::stillness::{QuietStretches, ReadingNoise};

use super::FuseSetup;

/// One-sigma of the zero-velocity update at a stance on the move, m/s (OpenShoe's figure).
pub const STANCE_VELOCITY_SIGMA_M_S: f64 = 0.01;

/// Window of the stance detector, s (Skog et al. use 3 to 5 samples at 100 Hz and more).
pub const STANCE_WINDOW_S: f64 = 0.05;

/// A share of stance samples below which a front end warns that `--zupt` found implausibly
/// few: a walking foot stands for about a third of the time or more.
pub const FEW_STANCES: f64 = 0.05;

/// False-alarm probability of the stance detector per sample.
pub const STANCE_FALSE_ALARM: f64 = 1e-3;

/// Block length over which the log's quiet stretches are found, s: a foot's stance holds a few
/// such blocks, a hand's pause one or two.
pub const QUIET_WINDOW_S: f64 = 0.1;

/// What the detectors test the readings against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detection {
    /// The readings' mean interval, s.
    pub interval_s: f64,
    /// Their white noise per sample: the log's own when learnt, else the part's.
    pub noise: ReadingNoise,
    /// Gravity as the accelerometer reads it at rest, m/s² (the setup's gravity when nothing
    /// was learnt).
    pub gravity_m_s2: f64,
    /// The part's white noise per sample (what the setup says).
    pub part_noise: ReadingNoise,
    /// Whether `noise` and `gravity_m_s2` were learnt from the log.
    pub learnt: bool,
}

impl Detection {
    /// The detection for readings `f`, `w` at times `t` under `setup`; `None` for fewer than
    /// three samples or times that do not advance.
    #[must_use]
    pub fn of(t: &[f64], f: &[[f64; 3]], w: &[[f64; 3]], setup: &FuseSetup) -> Option<Self> {
        let n = t.len();
        if n < 3 {
            return None;
        }
        let interval_s = (t[n - 1] - t[0]) / (n - 1) as f64;
        if interval_s.is_nan() || interval_s <= 0.0 {
            return None;
        }
        let per_sample = |psd: f64| psd / interval_s.sqrt();
        let part_noise = ReadingNoise {
            accel: per_sample(setup.noise.accel_psd),
            gyro: per_sample(setup.noise.gyro_psd),
        };
        let learnt = learnt_noise(f, w, interval_s, setup.gravity_m_s2);
        Some(Self {
            interval_s,
            noise: learnt.map_or(part_noise, |q| q.noise),
            gravity_m_s2: learnt.map_or(setup.gravity_m_s2, |q| q.gravity_reading_m_s2),
            part_noise,
            learnt: learnt.is_some(),
        })
    }
}

/// The white noise and gravity reading of readings `f`, `w` (sampled every `interval_s`) from
/// their quiet stretches, in blocks of [`QUIET_WINDOW_S`]; `None` when the log has too few.
#[must_use]
pub fn learnt_noise(
    f: &[[f64; 3]],
    w: &[[f64; 3]],
    interval_s: f64,
    gravity_m_s2: f64,
) -> Option<QuietStretches> {
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let window = ((QUIET_WINDOW_S / interval_s).round() as usize).max(3);
    let mut blocks = vec![[0.0; 3]; f.len().min(w.len()) / window];
    imu_core::stillness::quiet_noise(f, w, window, gravity_m_s2, &mut blocks)
}

/// The samples of readings `f`, `w` (specific force and rate, times `t`) that are stances
/// ([`FuseSetup::zupt`]), as the fusion finds them.
#[must_use]
pub fn stance_samples(t: &[f64], f: &[[f64; 3]], w: &[[f64; 3]], setup: &FuseSetup) -> Vec<bool> {
    Detection::of(t, f, w, setup)
        .map_or_else(|| vec![false; t.len()], |d| stances(t, f, w, setup, &d))
}

/// [`stance_samples`] under `detection`.
pub(super) fn stances(
    t: &[f64],
    f: &[[f64; 3]],
    w: &[[f64; 3]],
    setup: &FuseSetup,
    detection: &Detection,
) -> Vec<bool> {
    stances_with_threshold(t, f, w, setup, detection).0
}

/// The threshold the stance detector used: the noise's alone ([`shoe_threshold`] at
/// [`STANCE_FALSE_ALARM`]), or, when higher, the one learnt from the log's populations of the
/// statistic ([`imu_core::stillness::stance_threshold`]: a real foot rolls while it stands, far
/// above its sensor's noise, and a walk's rests are a population of their own).
///
/// [`shoe_threshold`]: imu_core::stillness::shoe_threshold
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StanceThreshold {
    /// The threshold used.
    pub used: f64,
    /// The noise's threshold.
    pub noise: f64,
    /// Whether the log's populations of the statistic set it.
    pub learnt: bool,
}

/// [`stances`] and the threshold they used.
pub(super) fn stances_with_threshold(
    t: &[f64],
    f: &[[f64; 3]],
    w: &[[f64; 3]],
    setup: &FuseSetup,
    detection: &Detection,
) -> (Vec<bool>, StanceThreshold) {
    use imu_core::stillness::{shoe_statistics, shoe_threshold, stance_threshold};
    // The rest's mean rate is the bias the detector's zero-rate test must not see.
    let bias = rest_rate(t, w, setup.rest_s);
    let gyro: Vec<[f64; 3]> = w
        .iter()
        .map(|x| [x[0] - bias[0], x[1] - bias[1], x[2] - bias[2]])
        .collect();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let window = ((STANCE_WINDOW_S / detection.interval_s).round() as usize).max(3);
    let mut statistic = vec![f64::INFINITY; t.len()];
    shoe_statistics(
        f,
        &gyro,
        detection.gravity_m_s2,
        detection.noise,
        window,
        &mut statistic,
    );
    let noise = shoe_threshold(window, STANCE_FALSE_ALARM);
    let threshold = match stance_threshold(&statistic) {
        Some(split) if split > noise => StanceThreshold {
            used: split,
            noise,
            learnt: true,
        },
        _ => StanceThreshold {
            used: noise,
            noise,
            learnt: false,
        },
    };
    let stance = statistic.iter().map(|s| *s < threshold.used).collect();
    (stance, threshold)
}

/// The mean rate over the rest at the start (`rest_s` from the first of the times `t`), rad/s:
/// the gyroscope's bias as the rest shows it (zero without a rest).
#[must_use]
pub fn rest_rate(t: &[f64], w: &[[f64; 3]], rest_s: f64) -> [f64; 3] {
    let Some(&t0) = t.first() else {
        return [0.0; 3];
    };
    let rest = t.partition_point(|&x| x < t0 + rest_s).min(w.len());
    if rest == 0 {
        return [0.0; 3];
    }
    #[allow(clippy::cast_precision_loss)]
    [0, 1, 2].map(|k| w[..rest].iter().map(|x| x[k]).sum::<f64>() / rest as f64)
}

/// The shortest first stance taken as the rest at the start of a walk, s.
pub const FIRST_STANCE_MIN_S: f64 = 1.0;

/// The rest at the start of a foot-mounted log (`--zupt`), s: its first stance, when that
/// begins at the first sample and lasts at least [`FIRST_STANCE_MIN_S`]; 0 otherwise. A person
/// standing sways, so the foot reads rates well above its sensor's white noise, which the rest
/// detector ([`detected_rest_s`]) refuses and the stance detector, with its threshold learnt
/// from the walk, does not. The stances are found here without a gyroscope bias (the rest that
/// would give it is what is sought); a consumer gyroscope's bias adds little to the statistic
/// next to the learnt threshold.
pub(super) fn first_stance_s(
    t: &[f64],
    f: &[[f64; 3]],
    w: &[[f64; 3]],
    setup: &FuseSetup,
    detection: &Detection,
) -> f64 {
    let unbiased = FuseSetup {
        rest_s: 0.0,
        ..*setup
    };
    let (stance, _) = stances_with_threshold(t, f, w, &unbiased, detection);
    let end = stance.iter().position(|s| !s).unwrap_or(stance.len());
    // The last stance sample before the foot moves: the window straddles the motion's start.
    let last = end.saturating_sub(1);
    if end == 0 || last >= t.len() || t[last] - t[0] < FIRST_STANCE_MIN_S {
        0.0
    } else {
        t[last] - t[0]
    }
}

/// The longest a walking foot goes without standing, s: a stride at any walking pace is
/// shorter, and the foot stands in each.
pub const MAX_STANCE_GAP_S: f64 = 2.0;

/// The longest stretch of samples at times `t` with no stance in `stance`, after the rest at the
/// start (`rest_s` from the first sample) and before the last stance: `(start, length)`, s from
/// the first sample. `None` with fewer than two stances after the rest.
#[must_use]
pub fn longest_without_stance(t: &[f64], stance: &[bool], rest_s: f64) -> Option<(f64, f64)> {
    let t0 = *t.first()?;
    let mut previous: Option<f64> = None;
    let mut longest: Option<(f64, f64)> = None;
    for (ti, _) in t
        .iter()
        .zip(stance)
        .filter(|(ti, s)| **s && **ti - t0 >= rest_s)
    {
        if let Some(p) = previous
            && longest.is_none_or(|(_, l)| ti - p > l)
        {
            longest = Some((p - t0, ti - p));
        }
        previous = Some(*ti);
    }
    longest
}

/// What a run says when its foot went longer than [`MAX_STANCE_GAP_S`] without a stance
/// (`what` the IMU's name; `None` otherwise): the estimate runs free-inertial there, and its
/// one-sigma, from the part's white noise alone, understates what it does.
#[must_use]
pub fn stance_gap_message(what: &str, gap: Option<(f64, f64)>) -> Option<String> {
    let (start, length) = gap.filter(|(_, l)| *l > MAX_STANCE_GAP_S)?;
    Some(format!(
        "{what}: --zupt found no stance for {length:.1} s (from t = {start:.1} s after the first \
         sample; a walking foot stands at least every {MAX_STANCE_GAP_S} s): the estimate is free \
         inertial there and drifts beyond its one-sigma (is the sensor on a foot? does the foot \
         stand still at each step?)"
    ))
}

/// Block length of the rest detector, s.
pub const REST_WINDOW_S: f64 = 0.5;

/// A start faster than this, m/s, is not at rest: no rest is looked for.
pub const REST_START_SPEED_M_S: f64 = 0.1;

/// The rest at the start of readings `f`, `w` at times `t`, s ([`imu_core::stillness`] with
/// the detection's white noise per sample and blocks of [`REST_WINDOW_S`]).
pub(super) fn detected_rest_s(
    t: &[f64],
    f: &[[f64; 3]],
    w: &[[f64; 3]],
    detection: &Detection,
) -> f64 {
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let window = ((REST_WINDOW_S / detection.interval_s).round() as usize).max(2);
    let still = imu_core::stillness::initial_rest(f, w, detection.noise, window);
    if still == 0 { 0.0 } else { t[still] - t[0] }
}
