//! `imukit calibrate`: a part calibrated from the log of a procedure, without equipment
//! ([`imu_core::calibration`]): the white noise learnt from the log's quiet blocks, the rests
//! found with it, the accelerometer fitted to gravity's magnitude at the rests, the gyroscope to
//! the rotations between them, the magnetometer (when the log has one) to an ellipsoid. A
//! sensor the log cannot calibrate is said and left out; the calibration file
//! ([`crate::io::calibration`]) holds the others.
use imu_core::calibration::accelerometer::{self, AccelCalibration};
use imu_core::calibration::gyroscope::{self, GyroCalibration, GyroInputs, rotation_residuals};
use imu_core::calibration::magnetometer::{self, MagCalibration};
use imu_core::calibration::{Correction, MAX_REST_RATE_RAD_S, Rest, rests};
use imu_core::stillness::{ReadingNoise, quiet_noise_below};

use crate::error::{Result, invalid};
use crate::io::Input;
use crate::io::columns::{ACCEL_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS};
use crate::io::read::{read_header, read_table_columns};
use crate::io::rows::TimeWindow;
use crate::io::table::Table;

/// Length of the blocks the noise and the rests are judged on, s.
pub const BLOCK_S: f64 = 0.25;

/// The shortest rest kept, after its first and last block are left out, s.
pub const MIN_REST_S: f64 = 1.0;

/// What a calibration found.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrateResult {
    /// The accelerometer's, when the log calibrates it.
    pub accelerometer: Option<AccelCalibration>,
    /// The gyroscope's, when the log calibrates it.
    pub gyroscope: Option<GyroCalibration>,
    /// The magnetometer's, when the log has one and calibrates it.
    pub magnetometer: Option<MagCalibration>,
    /// The rests found (sample ranges of the log, in the window).
    pub rests: Vec<Rest>,
    /// The white noise learnt from the quiet blocks, one reading's standard deviation.
    pub noise: Option<ReadingNoise>,
    /// What could not be calibrated and why, each naming the file.
    pub warnings: Vec<String>,
    /// What the calibration leaves of each residual, beside the raw readings'.
    pub residuals: Residuals,
}

impl CalibrateResult {
    /// The calibration file's text.
    #[must_use]
    pub fn to_toml(&self) -> String {
        crate::io::calibration::to_toml(
            self.accelerometer.as_ref(),
            self.gyroscope.as_ref(),
            self.magnetometer.as_ref(),
        )
    }
}

/// Calibrates the part whose procedure `source` logged, over `window`, with gravity
/// `gravity_m_s2`.
///
/// # Errors
/// A file that cannot be read, without accelerometer and gyroscope columns (or magnetometer
/// ones), times that do not increase, a window with too few rows, or a log that calibrates no
/// sensor (each reason said).
pub fn calibrate_log(
    source: &Input,
    gravity_m_s2: f64,
    window: TimeWindow,
) -> Result<CalibrateResult> {
    let file = source.path().display().to_string();
    let header = read_header(source)?;
    let has = |cols: &[&str; 3]| cols.iter().all(|c| header.iter().any(|h| h == c));
    let (inertial, mag) = (has(&ACCEL_COLUMNS) && has(&GYRO_COLUMNS), has(&MAG_COLUMNS));
    let mut names = vec!["t_s"];
    if inertial {
        names.extend(ACCEL_COLUMNS.iter().chain(&GYRO_COLUMNS));
    }
    if mag {
        names.extend(MAG_COLUMNS);
    }
    let table = read_table_columns(source, &names, "")?;
    let t0 = TimeWindow::first_time(&table, &file)?;
    let table = window.apply(table, t0, &file, 2)?;
    calibrate_table(&table, gravity_m_s2, &file)
}

/// [`calibrate_log`] of readings already in a table (`t_s` and the sensors' columns;
/// `source` names them in messages).
///
/// # Errors
/// As [`calibrate_log`].
pub fn calibrate_table(table: &Table, gravity_m_s2: f64, source: &str) -> Result<CalibrateResult> {
    let file = source;
    if !(gravity_m_s2.is_finite() && gravity_m_s2 > 0.0) {
        return Err(crate::error::refused(
            crate::error::RequestOption::Gravity,
            format!("{gravity_m_s2} is not a gravity (m/s², > 0)"),
        ));
    }
    let has = |cols: &[&str; 3]| cols.iter().all(|c| table.columns.iter().any(|h| h == c));
    let (inertial, mag) = (has(&ACCEL_COLUMNS) && has(&GYRO_COLUMNS), has(&MAG_COLUMNS));
    if !inertial && !mag {
        return Err(invalid(
            file,
            "has neither accelerometer and gyroscope columns (accel_*_m_s2, gyro_*_rad_s) nor \
             magnetometer ones (mag_*_ut) to calibrate",
        ));
    }
    let t = column(table, "t_s");
    if t.iter().any(|v| !v.is_finite()) || table.data.iter().any(|v| !v.is_finite()) {
        return Err(invalid(file, "holds a value that is not a finite number"));
    }
    if let Some(k) = (1..t.len()).find(|&k| t[k] <= t[k - 1]) {
        return Err(crate::io::rows::not_increasing(file, k + 2));
    }
    let mut result = CalibrateResult {
        accelerometer: None,
        gyroscope: None,
        magnetometer: None,
        rests: Vec::new(),
        noise: None,
        warnings: Vec::new(),
        residuals: Residuals::default(),
    };
    if inertial {
        inertial_fits(table, &t, gravity_m_s2, file, &mut result);
    }
    if mag {
        let m = triples(table, &MAG_COLUMNS);
        match magnetometer::calibrate(&m) {
            Ok(c) => result.magnetometer = Some(c),
            Err(e) => result
                .warnings
                .push(format!("{file}: the magnetometer is not calibrated: {e}")),
        }
    }
    if result.accelerometer.is_none() && result.magnetometer.is_none() {
        return Err(invalid(
            file,
            format!("calibrates no sensor: {}", result.warnings.join("; ")),
        ));
    }
    result.residuals = residuals(table, gravity_m_s2, &result);
    Ok(result)
}

/// The accelerometer's and the gyroscope's fits from the rests of `table` (times `t`).
fn inertial_fits(table: &Table, t: &[f64], g: f64, file: &str, result: &mut CalibrateResult) {
    let accel = triples(table, &ACCEL_COLUMNS);
    let gyro = triples(table, &GYRO_COLUMNS);
    let span = t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0);
    let rate = (t.len().saturating_sub(1)) as f64 / span.max(f64::MIN_POSITIVE);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let window = ((BLOCK_S * rate).round() as usize).max(5);
    let mut blocks = vec![[0.0; 3]; accel.len() / window + 1];
    let Some(quiet) = quiet_noise_below(&accel, &gyro, window, g, MAX_REST_RATE_RAD_S, &mut blocks)
    else {
        result.warnings.push(format!(
            "{file}: the accelerometer and gyroscope are not calibrated: fewer than {} quiet \
             blocks of {window} samples (the part must stand still between its turns)",
            imu_core::stillness::MIN_QUIET_BLOCKS
        ));
        return;
    };
    result.noise = Some(quiet.noise);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let min_blocks = (MIN_REST_S / BLOCK_S).ceil() as usize;
    rests(&accel, &gyro, window, quiet.noise, min_blocks, |r| {
        result.rests.push(r);
    });
    let means: Vec<[f64; 3]> = result.rests.iter().map(|r| r.mean(&accel)).collect();
    let shortest = result.rests.iter().map(Rest::len).min().unwrap_or(1) as f64;
    let a = match accelerometer::calibrate(&means, g, quiet.noise.accel / shortest.sqrt()) {
        Ok(a) => a,
        Err(e) => {
            result.warnings.push(format!(
                "{file}: the accelerometer and gyroscope are not calibrated: {e}"
            ));
            return;
        }
    };
    result.accelerometer = Some(a);
    match gyroscope::calibrate(&GyroInputs {
        t_s: t,
        gyro: &gyro,
        rests: &result.rests,
        accel_means: &means,
        accel: &a,
        noise: quiet.noise,
    }) {
        Ok(c) => result.gyroscope = Some(c),
        Err(e) => result
            .warnings
            .push(format!("{file}: the gyroscope is not calibrated: {e}")),
    }
}

fn column(table: &Table, name: &str) -> Vec<f64> {
    table.column(name).unwrap_or_default()
}

fn triples(table: &Table, names: &[&str; 3]) -> Vec<[f64; 3]> {
    let [x, y, z] = names.map(|n| column(table, n));
    x.iter()
        .zip(&y)
        .zip(&z)
        .map(|((a, b), c)| [*a, *b, *c])
        .collect()
}

/// What a calibration leaves of each sensor's residual, beside what the raw readings have: the
/// figure of `imukit calibrate --plot` and Python's `Calibration.residuals`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Residuals {
    /// The middle of each rest, s.
    pub rest_t_s: Vec<f64>,
    /// `|ā| − g` at each rest, raw and calibrated, m/s².
    pub accel_raw_m_s2: Vec<f64>,
    /// The same, calibrated.
    pub accel_m_s2: Vec<f64>,
    /// The end of each rotation (the start of the rest it turns into), s.
    pub rotation_t_s: Vec<f64>,
    /// The angle by which the integrated rate misses the next rest's gravity direction, raw
    /// (accelerometer calibrated, gyroscope not) and calibrated, rad.
    pub gyro_raw_rad: Vec<f64>,
    /// The same, calibrated.
    pub gyro_rad: Vec<f64>,
    /// Every magnetometer reading's time, s (at most [`MAX_MAG_POINTS`], evenly picked).
    pub mag_t_s: Vec<f64>,
    /// `|m|` over its mean, less one, raw; calibrated, `|C(m − b)|/B − 1`.
    pub mag_raw: Vec<f64>,
    /// The same, calibrated.
    pub mag: Vec<f64>,
}

/// The most magnetometer readings [`Residuals`] keeps.
pub const MAX_MAG_POINTS: usize = 5000;

/// The residuals of `result` on the readings `table` it was made from.
#[must_use]
pub fn residuals(table: &Table, gravity_m_s2: f64, result: &CalibrateResult) -> Residuals {
    let t = column(table, "t_s");
    let mut r = Residuals::default();
    if let Some(a) = &result.accelerometer {
        let accel = triples(table, &ACCEL_COLUMNS);
        let means: Vec<[f64; 3]> = result.rests.iter().map(|x| x.mean(&accel)).collect();
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        for (x, m) in result.rests.iter().zip(&means) {
            r.rest_t_s.push(0.5 * (t[x.start] + t[x.end - 1]));
            r.accel_raw_m_s2.push(norm(*m) - gravity_m_s2);
            r.accel_m_s2
                .push(norm(a.correction.apply(*m)) - gravity_m_s2);
        }
        if let Some(g) = &result.gyroscope {
            let gyro = triples(table, &GYRO_COLUMNS);
            let at = |k: usize| t[result.rests[k + 1].start];
            rotation_residuals(
                &t,
                &gyro,
                &result.rests,
                &means,
                &a.correction,
                &Correction::identity(),
                |k, e| {
                    r.rotation_t_s.push(at(k));
                    r.gyro_raw_rad.push(e);
                },
            );
            rotation_residuals(
                &t,
                &gyro,
                &result.rests,
                &means,
                &a.correction,
                &g.correction,
                |_, e| {
                    r.gyro_rad.push(e);
                },
            );
        }
    }
    if let Some(m) = &result.magnetometer {
        let mag = triples(table, &MAG_COLUMNS);
        let step = mag.len().div_ceil(MAX_MAG_POINTS).max(1);
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let mean = mag.iter().map(|v| norm(*v)).sum::<f64>() / mag.len().max(1) as f64;
        for (k, v) in mag.iter().enumerate().step_by(step) {
            r.mag_t_s.push(t[k]);
            r.mag_raw.push(norm(*v) / mean - 1.0);
            r.mag.push(norm(m.correction.apply(*v)) / m.field_ut - 1.0);
        }
    }
    r
}

/// The summary printed after a calibration: each sensor's terms with their uncertainties.
#[must_use]
pub fn summary(r: &CalibrateResult) -> Vec<String> {
    let mut lines = Vec::new();
    if let Some(n) = r.noise {
        lines.push(format!(
            "{} rests found; white noise learnt from the quiet blocks: accelerometer {:.3e} m/s², \
             gyroscope {:.3e} rad/s a sample",
            r.rests.len(),
            n.accel,
            n.gyro
        ));
    }
    let matrix = |m: [[f64; 3]; 3], s: [[f64; 3]; 3]| -> Vec<String> {
        (0..3)
            .map(|i| {
                format!(
                    "    [{}]",
                    (0..3)
                        .map(|j| format!("{:.6} ± {:.1e}", m[i][j], s[i][j]))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })
            .collect()
    };
    let bias = |b: [f64; 3], s: [f64; 3], unit: &str| {
        format!(
            "  bias [{}] {unit}",
            (0..3)
                .map(|i| format!("{:.6e} ± {:.1e}", b[i], s[i]))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    if let Some(a) = &r.accelerometer {
        lines.push(format!(
            "accelerometer ({} rests, {}): residual of |a| − g {:.3e} m/s² RMS; matrix:",
            a.rests,
            if a.full {
                "scale, misalignment and bias"
            } else {
                "scale and bias only: fewer than 12 rests"
            },
            a.residual_rms_m_s2
        ));
        lines.extend(matrix(a.correction.matrix, a.matrix_sigma));
        lines.push(bias(a.correction.bias, a.bias_sigma, "m/s²"));
    }
    if let Some(g) = &r.gyroscope {
        lines.push(format!(
            "gyroscope ({} rotations): residual of the gravity direction {:.3e} rad RMS; matrix:",
            g.rotations, g.residual_rms_rad
        ));
        lines.extend(matrix(g.correction.matrix, g.matrix_sigma));
        lines.push(bias(g.correction.bias, g.bias_sigma, "rad/s"));
    }
    if let Some(m) = &r.magnetometer {
        lines.push(format!(
            "magnetometer ({} readings): field {:.3} ± {:.1e} µT, fit error {:.3} %; soft iron:",
            m.readings,
            m.field_ut,
            m.field_sigma_ut,
            100.0 * m.fit_error
        ));
        lines.extend(matrix(m.correction.matrix, m.matrix_sigma));
        lines.push(bias(m.correction.bias, m.bias_sigma, "µT (hard iron)"));
    }
    lines.extend(r.warnings.iter().map(|w| format!("warning: {w}")));
    lines
}
