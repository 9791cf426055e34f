//! The samples taken between two covariance steps, and the means the step uses.
use nalgebra::Vector3;

use super::EskfError;

/// An IMU interval: its length, s, and the mean body rate and specific force of its two samples.
pub(crate) type Interval = (f64, Vector3<f64>, Vector3<f64>);

/// What both filters keep between IMU samples: the last sample, and the covariance schedule —
/// its interval and, since its last step, the time and the sums `∫ Ĉ f̂ dt`, `∫ Ĉ dt`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Intake {
    last: Option<(Vector3<f64>, Vector3<f64>)>,
    interval_s: f64,
    pending: (f64, Vector3<f64>, nalgebra::Matrix3<f64>),
    samples: usize,
}

impl Intake {
    pub(crate) fn new() -> Self {
        Self {
            last: None,
            interval_s: 0.0,
            pending: (0.0, Vector3::zeros(), nalgebra::Matrix3::zeros()),
            samples: 0,
        }
    }

    /// The covariance interval, s (finite, ≥ 0; 0: every sample).
    pub(crate) fn set_interval(&mut self, interval_s: f64) -> Result<(), EskfError> {
        if !(interval_s.is_finite() && interval_s >= 0.0) {
            return Err(EskfError::BadParameter {
                field: "covariance interval",
            });
        }
        self.interval_s = interval_s;
        Ok(())
    }

    /// Samples taken so far (the next one's index).
    pub(crate) fn samples(&self) -> usize {
        self.samples
    }

    /// The last sample's body rate and specific force, as measured.
    pub(crate) fn last(&self) -> (Vector3<f64>, Vector3<f64>) {
        self.last.unwrap_or((Vector3::zeros(), Vector3::zeros()))
    }

    /// The last sample's body rate and specific force as measured, `None` before the first.
    pub(crate) fn last_sample(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        self.last
    }

    /// Takes sample `(t_s, gyro, accel)` after the one at `t_prev_s`: `None` for the first,
    /// else the interval and the two samples' mean rate and specific force.
    ///
    /// # Errors
    /// Non-finite values or a time that does not increase (the sample's index named).
    pub(crate) fn take(
        &mut self,
        t_prev_s: f64,
        t_s: f64,
        gyro_rad_s: [f64; 3],
        accel_m_s2: [f64; 3],
    ) -> Result<Option<Interval>, EskfError> {
        let index = self.samples;
        let finite = [t_s]
            .iter()
            .chain(&gyro_rad_s)
            .chain(&accel_m_s2)
            .all(|v| v.is_finite());
        if !finite {
            return Err(EskfError::NotFinite { index });
        }
        let (w1, f1) = (Vector3::from(gyro_rad_s), Vector3::from(accel_m_s2));
        let previous = self.last.replace((w1, f1));
        let Some((w0, f0)) = previous else {
            self.samples += 1;
            return Ok(None);
        };
        let dt = t_s - t_prev_s;
        if dt.is_nan() || dt <= 0.0 {
            self.last = previous;
            return Err(EskfError::TimeNotIncreasing { index });
        }
        self.samples += 1;
        Ok(Some((dt, 0.5 * (w0 + w1), 0.5 * (f0 + f1))))
    }

    /// Adds an interval `dt` with attitude `c` and specific force `f` (bias-corrected, body) to
    /// the pending covariance step; true when the step is due.
    pub(crate) fn accumulate(
        &mut self,
        dt: f64,
        c: &nalgebra::Matrix3<f64>,
        f: &Vector3<f64>,
    ) -> bool {
        self.pending.0 += dt;
        self.pending.1 += c * f * dt;
        self.pending.2 += c * dt;
        self.pending.0 >= self.interval_s * (1.0 - 1e-9)
    }

    /// The pending interval (its length, mean `Ĉf̂` and mean `Ĉ`), cleared; `None` when empty.
    pub(crate) fn take_pending(&mut self) -> Option<(f64, Vector3<f64>, nalgebra::Matrix3<f64>)> {
        let (dt, cf, cdt) = self.pending;
        if dt <= 0.0 {
            return None;
        }
        self.pending = (0.0, Vector3::zeros(), nalgebra::Matrix3::zeros());
        Some((dt, cf / dt, cdt / dt))
    }
}
