//! The aids of a fusion besides GNSS — odometer readings, barometer readings, the
//! non-holonomic constraints and a rest at the start (zero velocity and zero angular rate) —
//! read, checked and applied at their times, the same way on every Earth.
use crate::error::{Data, RequestOption, Result, invalid, refused};
use imu_core::earth::EarthModel;
use imu_core::fusion::gate::{Gate, gate_99_9};
use imu_core::fusion::{BodyVelocity, Eskf, Height, ZeroRate};

use crate::io::table::Table;
use crate::run::fuse::{
    AidTables, FuseSetup, NHC_RATE_HZ, OdometerModel, REST_VELOCITY_SIGMA_M_S,
    STANCE_VELOCITY_SIGMA_M_S, filter_refusal,
};

/// The smallest one-sigma the filter is told for an aid (exact simulated readings still need a
/// little trust in the model), in the aid's unit.
const MIN_SIGMA: f64 = 1e-3;

/// The least one-sigma of a zero-rate update, rad/s (for noiseless gyroscopes).
const MIN_RATE_SIGMA: f64 = 1e-9;

/// Times and values of an aid table, checked: finite, increasing, inside `[t0, t1]`.
pub(crate) fn aid_series(
    table: &Table,
    what: Data,
    value: &str,
    (t0, t1): (f64, f64),
) -> Result<(Vec<f64>, Vec<f64>)> {
    let (Some(t), Some(v)) = (table.column("t_s"), table.column(value)) else {
        return Err(invalid(
            what,
            format!("missing column(s): needs t_s and {value}"),
        ));
    };
    for (k, (&tk, &vk)) in t.iter().zip(&v).enumerate() {
        if !tk.is_finite() || !vk.is_finite() || (k > 0 && tk <= t[k - 1]) {
            return Err(invalid(
                what,
                format!(
                    "row {}: times must be finite and increase, values finite",
                    k + 2
                ),
            ));
        }
        if tk < t0 || tk > t1 {
            return Err(invalid(
                what,
                format!(
                    "row {}: time {tk} s is outside the IMU's span [{t0}, {t1}] s",
                    k + 2
                ),
            ));
        }
    }
    Ok((t, v))
}

/// The aids of one fusion: readings, models and where each stream has got to.
pub(crate) struct AidStreams {
    odometer: (Vec<f64>, Vec<f64>),
    baro: (Vec<f64>, Vec<f64>),
    odometer_model: OdometerModel,
    baro_sigma_m: f64,
    nhc_sigma_m_s: Option<f64>,
    gate_on: bool,
    /// The end of the rest at the start, s, and one sample's gyroscope noise, rad/s.
    rest: (f64, f64),
    /// Per IMU sample, whether it is a stance (zero-velocity updates on the move).
    stance: Vec<bool>,
    /// The gyroscope's bias as the rest at the start shows it, rad/s.
    stance_bias: [f64; 3],
    next: (usize, usize),
    next_nhc_t: f64,
}

impl AidStreams {
    /// The aid tables given, checked against the IMU's span, with the models of `setup` (an
    /// aid table without its model is refused, not ignored).
    ///
    /// # Errors
    /// A table without its columns or model, times that do not increase or fall outside the
    /// span, a constraint sigma that is not positive, a rest that is negative or not finite.
    pub(crate) fn new(
        aids: AidTables<'_>,
        setup: &FuseSetup,
        span: (f64, f64),
        samples: usize,
    ) -> Result<Self> {
        let odometer = match (aids.odometer, setup.aiding.odometer) {
            (Some(table), Some(_)) => aid_series(table, Data::Odometer, "speed_m_s", span)?,
            (Some(_), None) => {
                return Err(invalid(
                    Data::Odometer,
                    "given, but the scenario has no [odometer]: the filter takes its accuracy from it",
                ));
            }
            (None, _) => (Vec::new(), Vec::new()),
        };
        let baro = match (aids.baro, setup.aiding.baro_sigma_m) {
            (Some(table), Some(_)) => aid_series(table, Data::Barometer, "baro_height_m", span)?,
            (Some(_), None) => {
                return Err(invalid(
                    Data::Barometer,
                    "given, but the scenario has no [baro]: the filter takes its accuracy from it",
                ));
            }
            (None, _) => (Vec::new(), Vec::new()),
        };
        let nhc = setup.aiding.nhc_sigma_m_s;
        if let Some(c) = nhc
            && !(c.is_finite() && c > 0.0)
        {
            return Err(refused(
                RequestOption::NhcSigma,
                format!("must be a finite number > 0 (m/s), got {c}"),
            ));
        }
        if !(setup.rest_s.is_finite() && setup.rest_s >= 0.0) {
            return Err(refused(
                RequestOption::RestS,
                format!("must be a finite number ≥ 0 (s), got {}", setup.rest_s),
            ));
        }
        // One sample's white gyroscope noise: √q over the IMU's interval.
        let interval_s = (span.1 - span.0) / samples.saturating_sub(1).max(1) as f64;
        let gyro_sample_sigma = (setup.noise.gyro_psd / interval_s.sqrt()).max(MIN_RATE_SIGMA);
        Ok(Self {
            odometer,
            baro,
            odometer_model: setup.aiding.odometer.unwrap_or(OdometerModel {
                noise_m_s: 0.0,
                scale_factor_error: 0.0,
            }),
            baro_sigma_m: setup.aiding.baro_sigma_m.unwrap_or(1.0).max(MIN_SIGMA),
            nhc_sigma_m_s: nhc,
            gate_on: setup.gate.is_on(),
            rest: (span.0 + setup.rest_s, gyro_sample_sigma),
            stance: Vec::new(),
            stance_bias: [0.0; 3],
            next: (0, 0),
            next_nhc_t: span.0,
        })
    }

    /// The stance samples, by IMU sample index ([`super::fuse::FuseSetup::zupt`]), and the
    /// gyroscope's bias as the rest at the start shows it (rad/s).
    pub(crate) fn set_stance(&mut self, stance: Vec<bool>, bias_rad_s: [f64; 3]) {
        self.stance = stance;
        self.stance_bias = bias_rad_s;
    }

    /// Skips the readings before the filter's first sample at `t_first`.
    pub(crate) fn start_at(&mut self, t_first: f64) {
        self.next = (
            self.odometer.0.partition_point(|&x| x < t_first),
            self.baro.0.partition_point(|&x| x < t_first),
        );
        self.next_nhc_t = t_first;
    }

    /// The χ² 99.9 % gate for `rows` rows (none when the fusion's gate is off).
    fn gate(&self, rows: usize) -> Gate {
        if self.gate_on {
            gate_99_9(rows)
        } else {
            Gate::Off
        }
    }

    /// Every aid reading up to IMU sample `i` at `t_s` (its gyroscope reading `gyro_rad_s`):
    /// zero velocity and rate at the rest and the stances, odometer speeds (with the constraints
    /// when they are on), the constraints alone at [`NHC_RATE_HZ`] without an odometer, heights.
    ///
    /// # Errors
    /// The filter's refusal, naming the aid and its row ([`filter_refusal`]).
    pub(crate) fn apply<E: EarthModel, const S: usize>(
        &mut self,
        filter: &mut Eskf<E, S>,
        t_s: f64,
        i: usize,
        gyro_rad_s: [f64; 3],
    ) -> Result<()> {
        if t_s >= self.rest.0 && self.stance.get(i).copied().unwrap_or(false) {
            // A stance on the move: the detector is the gate, and the foot is still only to
            // about a centimetre a second. It rolls, so its rate is not the bias; the bias taken
            // off is the rest's, a fixed number (the filter's own estimate would let the update
            // pull the estimate towards the roll and then trust it more).
            let rate = [0, 1, 2].map(|k| gyro_rad_s[k] - self.stance_bias[k]);
            filter
                .update(&BodyVelocity::zero(STANCE_VELOCITY_SIGMA_M_S), Gate::Off)
                .map_err(|e| filter_refusal("IMU (stance, zero velocity) data", i, e))?;
            filter
                .update(&ZeroRate::rolling(self.rest.1, rate), Gate::Off)
                .map_err(|e| filter_refusal("IMU (stance, zero rate) data", i, e))?;
        } else if t_s < self.rest.0 {
            filter
                .update(&BodyVelocity::zero(REST_VELOCITY_SIGMA_M_S), self.gate(3))
                .map_err(|e| filter_refusal("IMU (at rest, zero velocity) data", i, e))?;
            filter
                .update(
                    &ZeroRate {
                        sigma_rad_s: self.rest.1,
                    },
                    self.gate(3),
                )
                .map_err(|e| filter_refusal("IMU (at rest, zero rate) data", i, e))?;
        }
        let (odo_t, odo_v) = (&self.odometer.0, &self.odometer.1);
        while self.next.0 < odo_t.len() && odo_t[self.next.0] <= t_s {
            let k = self.next.0;
            let speed = odo_v[k];
            let m = self.odometer_model;
            let sigma = m
                .noise_m_s
                .hypot(m.scale_factor_error * speed)
                .max(MIN_SIGMA);
            let odometer = BodyVelocity::odometer(speed, sigma, self.nhc_sigma_m_s);
            filter
                .update(&odometer, self.gate(odometer.rows()))
                .map_err(|e| filter_refusal(Data::Odometer, k, e))?;
            self.next.0 += 1;
        }
        if let Some(c) = self.nhc_sigma_m_s
            && odo_t.is_empty()
            && t_s >= self.next_nhc_t
        {
            filter
                .update(&BodyVelocity::nonholonomic(c), self.gate(2))
                .map_err(|e| filter_refusal("constraint data", i, e))?;
            self.next_nhc_t = t_s + 1.0 / NHC_RATE_HZ;
        }
        let (baro_t, baro_h) = (&self.baro.0, &self.baro.1);
        while self.next.1 < baro_t.len() && baro_t[self.next.1] <= t_s {
            let k = self.next.1;
            filter
                .update(
                    &Height {
                        height_m: baro_h[k],
                        sigma_m: self.baro_sigma_m,
                    },
                    self.gate(1),
                )
                .map_err(|e| filter_refusal(Data::Barometer, k, e))?;
            self.next.1 += 1;
        }
        Ok(())
    }
}
