//! Error-state (indirect) Kalman orientation filters with the structure, tunables and defaults
//! of MATLAB's `imufilter` (accelerometer + gyroscope, 9 error states) and `ahrsfilter`
//! (+ magnetometer, 12 error states), after Roetenberg et al., "Compensation of magnetic
//! disturbances improves inertial and magnetic sensing of human body segment orientation",
//! IEEE TNSRE 13(3), 2005, which MATLAB cites.
//!
//! The equations below are derived here for imukit's conventions (NED internally, `q = q_nb`,
//! errors defined as estimate − truth); MATLAB's own implementation was not available to check
//! them against, so outputs agree with MATLAB's in behaviour and tuning, not to the last digit.
//!
//! **State.** The orientation `q`, gyroscope offset `b̂`, linear acceleration `â` (body frame,
//! m/s²), and for the AHRS the magnetic disturbance `d̂` (µT) and the Earth field `m_n` (NED,
//! with no east component). The error state is `x = [θ, δb, δa, δd]`, where the true attitude
//! is `C_nb = Ĉ_nb (I + [θ×])`.
//!
//! **Predict** (every sample): `q ← q ⊗ exp((ω − b̂) Δt)`, with `Δt` the sample's own interval
//! when it carries one ([`FilterInput::interval_s`]), else `1/SampleRate` (MATLAB's fixed
//! rate). Every `DecimationFactor` samples the filter corrects; the block's duration `κ` is the
//! sum of its samples' intervals, else MATLAB's `DecimationFactor/SampleRate`:
//!
//! * priors `â⁻ = ν â`, `d̂⁻ = σ d̂` (`ν` LinearAccelerationDecayFactor, `σ`
//!   MagneticDisturbanceDecayFactor);
//! * gravity from the orientation `g = Ĉ_nbᵀ (0, 0, g)` and from the accelerometer
//!   `y_a + â⁻` (`y_a = −f_b`, MATLAB's sign); `z_a = g − (y_a + â⁻) = −[g×] θ − δa`;
//! * AHRS: the field from the orientation `m = Ĉ_nbᵀ m_n` and from the magnetometer
//!   `y_m − d̂⁻`; `z_m = m − (y_m − d̂⁻) = −[m×] θ + δd`. A disturbance-corrected reading
//!   longer than twice ExpectedMagneticFieldStrength is treated as jamming: that update uses the
//!   accelerometer only (as MATLAB does);
//! * `K = P⁻Hᵀ(HP⁻Hᵀ + R)⁻¹`, `x = K z`, `P⁺ = P⁻ − K(P⁻Hᵀ)ᵀ` (= `P⁻ − KHP⁻`), with
//!   `R_a = (λ + ξ + κ²(β + η)) I` and `R_m = (μ + δ + κ²(β + η)) I` (λ AccelerometerNoise,
//!   ξ LinearAccelerationNoise, β GyroscopeDriftNoise, η GyroscopeNoise, μ MagnetometerNoise,
//!   δ MagneticDisturbanceNoise);
//! * `q ← q ⊗ exp(θ)`, `b̂ ← b̂ − δb`, `â ← â⁻ − δa`, `d̂ ← d̂⁻ − δd`, and
//!   `m_n ← (|h|, 0, v)` for `(h, v)` the horizontal and vertical parts of `Ĉ_nb (y_m − d̂)`.
//!
//! **Covariance between corrections** (MATLAB's block form: only the diagonal blocks of `P⁺`
//! are carried; `θ` absorbs the offset error over `κ`, formed at each correction with that
//! block's `κ`, so a gap in the data widens the attitude's uncertainty by the time it lasted):
//! `P⁻_θθ = P⁺_θθ + κ²(P⁺_bb + β + η)`, `P⁻_θb = κ(P⁺_bb + β)`, `P⁻_bb = P⁺_bb + β`,
//! `P⁻_aa = ν²P⁺_aa + ξ`, `P⁻_dd = σ²P⁺_dd + δ`; the first prior is InitialProcessNoise.
//!
//! **Start.** The first sample sets the orientation: the e-compass for the AHRS, roll and pitch
//! from the accelerometer with zero yaw for the IMU filter (so its yaw is relative to the
//! initial heading, as MATLAB's).
use core::marker::PhantomData;

use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

use super::ecompass::{ecompass_ned, tilt};
use super::{
    Estimate, FilterInput, OrientError, OrientationFilter, check_finite, gravity_reading, positive,
    to_frame,
};
use crate::ideal::AccelSign;
use crate::nav_frame::NavFrame;

/// Error states: orientation, gyroscope offset, linear acceleration, magnetic disturbance.
const STATES: usize = 12;

/// The tunables of MATLAB's `imufilter`/`ahrsfilter` (its property names in the field docs),
/// SI units; [`Default`] is MATLAB's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanParams {
    /// SampleRate, Hz (100).
    pub sample_rate_hz: f64,
    /// DecimationFactor: one correction and one output per this many samples (1).
    pub decimation: usize,
    /// AccelerometerNoise λ, (m/s²)² (0.00019247).
    pub accelerometer_noise: f64,
    /// GyroscopeNoise η, (rad/s)² (9.1385e-5).
    pub gyroscope_noise: f64,
    /// GyroscopeDriftNoise β, (rad/s)² (3.0462e-13).
    pub gyroscope_drift_noise: f64,
    /// LinearAccelerationNoise ξ, (m/s²)² (0.0096236).
    pub linear_acceleration_noise: f64,
    /// LinearAccelerationDecayFactor ν, in [0, 1) (0.5).
    pub linear_acceleration_decay: f64,
    /// InitialProcessNoise, the diagonal of the first error covariance: orientation (rad²),
    /// gyroscope offset ((rad/s)²), linear acceleration ((m/s²)²), magnetic disturbance (µT²)
    /// — 6.0923e-6, 7.6154e-5, 0.0096236, 0.6 on each axis.
    pub initial_process_noise: [f64; STATES],
    /// MagnetometerNoise μ, µT² (0.1).
    pub magnetometer_noise: f64,
    /// MagneticDisturbanceNoise δ, µT² (0.5).
    pub magnetic_disturbance_noise: f64,
    /// MagneticDisturbanceDecayFactor σ, in [0, 1] (0.5).
    pub magnetic_disturbance_decay: f64,
    /// ExpectedMagneticFieldStrength, µT (50).
    pub expected_magnetic_field_ut: f64,
    /// Gravity, m/s² (9.81).
    pub gravity_m_s2: f64,
    /// Sign of the accelerometer readings fed in (MATLAB's by default, as these filters mirror
    /// MATLAB's).
    pub accel_sign: AccelSign,
}

impl Default for KalmanParams {
    fn default() -> Self {
        let mut ipn = [0.0; STATES];
        for (k, v) in [6.092_348_396e-6, 7.615_435_494_7e-5, 0.009_623_61, 0.6]
            .into_iter()
            .enumerate()
        {
            ipn[3 * k..3 * k + 3].fill(v);
        }
        Self {
            sample_rate_hz: 100.0,
            decimation: 1,
            accelerometer_noise: 0.000_192_47,
            gyroscope_noise: 9.1385e-5,
            gyroscope_drift_noise: 3.0462e-13,
            linear_acceleration_noise: 0.009_623_6,
            linear_acceleration_decay: 0.5,
            initial_process_noise: ipn,
            magnetometer_noise: 0.1,
            magnetic_disturbance_noise: 0.5,
            magnetic_disturbance_decay: 0.5,
            expected_magnetic_field_ut: 50.0,
            gravity_m_s2: crate::frame::DEFAULT_GRAVITY_M_S2,
            accel_sign: AccelSign::Matlab,
        }
    }
}

impl KalmanParams {
    /// Checks every field's range, naming the first that is out of it.
    ///
    /// # Errors
    /// [`OrientError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), OrientError> {
        positive("SampleRate", self.sample_rate_hz, false)?;
        if self.decimation == 0 {
            return Err(OrientError::InvalidParameter {
                field: "DecimationFactor",
                value: 0.0,
                expected: "a whole number ≥ 1",
            });
        }
        positive("AccelerometerNoise", self.accelerometer_noise, false)?;
        positive("GyroscopeNoise", self.gyroscope_noise, false)?;
        positive("GyroscopeDriftNoise", self.gyroscope_drift_noise, false)?;
        positive(
            "LinearAccelerationNoise",
            self.linear_acceleration_noise,
            false,
        )?;
        positive("MagnetometerNoise", self.magnetometer_noise, false)?;
        positive(
            "MagneticDisturbanceNoise",
            self.magnetic_disturbance_noise,
            false,
        )?;
        positive(
            "ExpectedMagneticFieldStrength",
            self.expected_magnetic_field_ut,
            false,
        )?;
        positive("gravity", self.gravity_m_s2, false)?;
        for (field, v) in [
            (
                "LinearAccelerationDecayFactor",
                self.linear_acceleration_decay,
            ),
            (
                "MagneticDisturbanceDecayFactor",
                self.magnetic_disturbance_decay,
            ),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(OrientError::InvalidParameter {
                    field,
                    value: v,
                    expected: "in [0, 1]",
                });
            }
        }
        for v in self.initial_process_noise {
            positive("InitialProcessNoise", v, false)?;
        }
        Ok(())
    }
}

/// The prior error covariance, in MATLAB's block form.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Prior {
    tt: Matrix3<f64>,
    tb: Matrix3<f64>,
    bb: Matrix3<f64>,
    aa: Matrix3<f64>,
    dd: Matrix3<f64>,
}

impl Prior {
    /// The prior of a correction from the last one's posterior blocks, over a block of `kappa`
    /// seconds (MATLAB's block form; `θ` absorbs the offset error over `κ`).
    fn propagated(posterior: &[Matrix3<f64>; 4], kappa: f64, p: &KalmanParams) -> Self {
        let [tt, bb, aa, dd] = *posterior;
        let beta = p.gyroscope_drift_noise;
        Self {
            tt: tt
                + (bb + Matrix3::from_diagonal_element(beta + p.gyroscope_noise)) * (kappa * kappa),
            tb: (bb + Matrix3::from_diagonal_element(beta)) * kappa,
            bb: bb + Matrix3::from_diagonal_element(beta),
            aa: aa * (p.linear_acceleration_decay * p.linear_acceleration_decay)
                + Matrix3::from_diagonal_element(p.linear_acceleration_noise),
            dd: dd * (p.magnetic_disturbance_decay * p.magnetic_disturbance_decay)
                + Matrix3::from_diagonal_element(p.magnetic_disturbance_noise),
        }
    }
}

/// What the filter carries between samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanState {
    started: bool,
    q: UnitQuaternion<f64>,
    gyro_offset: Vector3<f64>,
    linear_accel: Vector3<f64>,
    mag_disturbance: Vector3<f64>,
    mag_nav: Vector3<f64>,
    prior: Prior,
    in_block: usize,
    /// The diagonal blocks of the last correction's `P⁺` (θθ, bb, aa, dd), propagated over the
    /// next block once its duration is known (`None` before the first correction).
    posterior: Option<[Matrix3<f64>; 4]>,
    /// The time the current decimation block has spanned, s, when its samples carried their
    /// intervals (`None`: MATLAB's fixed `DecimationFactor / SampleRate`).
    block_s: Option<f64>,
}

impl KalmanState {
    fn new(p: &KalmanParams) -> Self {
        let d = |k: usize| {
            let v = &p.initial_process_noise[3 * k..3 * k + 3];
            Matrix3::from_diagonal(&Vector3::new(v[0], v[1], v[2]))
        };
        Self {
            started: false,
            q: UnitQuaternion::identity(),
            gyro_offset: Vector3::zeros(),
            linear_accel: Vector3::zeros(),
            mag_disturbance: Vector3::zeros(),
            mag_nav: Vector3::zeros(),
            prior: Prior {
                tt: d(0),
                tb: Matrix3::zeros(),
                bb: d(1),
                aa: d(2),
                dd: d(3),
            },
            in_block: 0,
            posterior: None,
            block_s: None,
        }
    }

    /// The gyroscope offset estimate, rad/s.
    #[must_use]
    pub fn gyroscope_offset(&self) -> [f64; 3] {
        self.gyro_offset.into()
    }

    /// The linear acceleration estimate (body frame, gravity-reading sign), m/s².
    #[must_use]
    pub fn linear_acceleration(&self) -> [f64; 3] {
        self.linear_accel.into()
    }

    /// The magnetic disturbance estimate (body frame), µT.
    #[must_use]
    pub fn magnetic_disturbance(&self) -> [f64; 3] {
        self.mag_disturbance.into()
    }
}

/// MATLAB's `imufilter` (no magnetometer) or `ahrsfilter` (with one) in NED or ENU.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanFilter<N: NavFrame> {
    params: KalmanParams,
    magnetometer: bool,
    state: KalmanState,
    frame: PhantomData<N>,
}

impl<N: NavFrame> KalmanFilter<N> {
    /// The accelerometer-gyroscope filter (`imufilter`).
    ///
    /// # Errors
    /// [`OrientError::InvalidParameter`] naming the field.
    pub fn imu(params: KalmanParams) -> Result<Self, OrientError> {
        Self::new(params, false)
    }

    /// The accelerometer-gyroscope-magnetometer filter (`ahrsfilter`).
    ///
    /// # Errors
    /// [`OrientError::InvalidParameter`] naming the field.
    pub fn ahrs(params: KalmanParams) -> Result<Self, OrientError> {
        Self::new(params, true)
    }

    fn new(params: KalmanParams, magnetometer: bool) -> Result<Self, OrientError> {
        params.validate()?;
        Ok(Self {
            params,
            magnetometer,
            state: KalmanState::new(&params),
            frame: PhantomData,
        })
    }

    /// The parameters.
    #[must_use]
    pub fn params(&self) -> &KalmanParams {
        &self.params
    }

    /// The carried state (gyroscope offset and the other estimates).
    #[must_use]
    pub fn state(&self) -> &KalmanState {
        &self.state
    }

    /// One correction on `s` (a copy of the state), with the gravity reading `y_a` and the
    /// magnetometer reading `y_m`.
    fn correct(
        &self,
        s: &mut KalmanState,
        y_a: &Vector3<f64>,
        y_m: &Vector3<f64>,
    ) -> Result<(), OrientError> {
        let p = &self.params;
        // The block's duration κ: MATLAB's fixed one, or the time its samples spanned.
        let kappa = s
            .block_s
            .take()
            .unwrap_or(p.decimation as f64 / p.sample_rate_hz);
        let gyro_term = kappa * kappa * (p.gyroscope_drift_noise + p.gyroscope_noise);
        if let Some(posterior) = s.posterior.take() {
            s.prior = Prior::propagated(&posterior, kappa, p);
        }
        let mut cov = SMatrix::<f64, STATES, STATES>::zeros();
        let pr = &s.prior;
        cov.fixed_view_mut::<3, 3>(0, 0).copy_from(&pr.tt);
        cov.fixed_view_mut::<3, 3>(0, 3).copy_from(&pr.tb);
        cov.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&pr.tb.transpose());
        cov.fixed_view_mut::<3, 3>(3, 3).copy_from(&pr.bb);
        cov.fixed_view_mut::<3, 3>(6, 6).copy_from(&pr.aa);
        if self.magnetometer {
            cov.fixed_view_mut::<3, 3>(9, 9).copy_from(&pr.dd);
        }
        let a_prior = s.linear_accel * p.linear_acceleration_decay;
        let d_prior = s.mag_disturbance * p.magnetic_disturbance_decay;
        let nav_to_body = s.q.inverse();
        let g = nav_to_body * Vector3::new(0.0, 0.0, p.gravity_m_s2);
        let z_a = g - (y_a + a_prior);
        let mut h_a = SMatrix::<f64, 3, STATES>::zeros();
        h_a.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(-g.cross_matrix()));
        h_a.fixed_view_mut::<3, 3>(0, 6)
            .copy_from(&(-Matrix3::identity()));
        let r_a = p.accelerometer_noise + p.linear_acceleration_noise + gyro_term;
        let m_meas = y_m - d_prior;
        let use_mag = self.magnetometer
            && m_meas.norm_squared()
                <= 4.0 * p.expected_magnetic_field_ut * p.expected_magnetic_field_ut;
        let (x, posterior) = if use_mag {
            let m = nav_to_body * s.mag_nav;
            let z_m = m - m_meas;
            let mut h = SMatrix::<f64, 6, STATES>::zeros();
            h.fixed_view_mut::<3, STATES>(0, 0).copy_from(&h_a);
            h.fixed_view_mut::<3, 3>(3, 0)
                .copy_from(&(-m.cross_matrix()));
            h.fixed_view_mut::<3, 3>(3, 9)
                .copy_from(&Matrix3::identity());
            let r_m = p.magnetometer_noise + p.magnetic_disturbance_noise + gyro_term;
            let z = SVector::<f64, 6>::from_iterator(z_a.iter().chain(z_m.iter()).copied());
            let r = SVector::<f64, 6>::from_iterator([r_a, r_a, r_a, r_m, r_m, r_m]);
            update(&cov, &h, &z, &r)?
        } else {
            update(&cov, &h_a, &z_a, &Vector3::repeat(r_a))?
        };
        let theta = Vector3::new(x[0], x[1], x[2]);
        s.q *= UnitQuaternion::from_scaled_axis(theta);
        s.gyro_offset -= Vector3::new(x[3], x[4], x[5]);
        s.linear_accel = a_prior - Vector3::new(x[6], x[7], x[8]);
        if self.magnetometer {
            s.mag_disturbance = d_prior - Vector3::new(x[9], x[10], x[11]);
        }
        if use_mag {
            s.mag_nav = horizontal_north(&(s.q * (y_m - s.mag_disturbance)));
        }
        s.posterior = Some(posterior);
        Ok(())
    }
}

/// The Kalman update: the error estimate `x` and the diagonal 3×3 blocks of `P⁺` (all that is
/// carried) for prior `cov`, observation `h`, innovation `z`, noise `r`. `P⁺ = P⁻ − K (P⁻Hᵀ)ᵀ`
/// (`P⁻` is symmetric), evaluated only on the diagonal blocks.
fn update<const M: usize>(
    cov: &SMatrix<f64, STATES, STATES>,
    h: &SMatrix<f64, M, STATES>,
    z: &SVector<f64, M>,
    r: &SVector<f64, M>,
) -> Result<(SVector<f64, STATES>, [Matrix3<f64>; 4]), OrientError> {
    let pht = cov * h.transpose();
    let innovation = h * pht + SMatrix::<f64, M, M>::from_diagonal(r);
    let inverse = innovation.try_inverse().ok_or(OrientError::Singular)?;
    let gain = pht * inverse;
    let x = gain * z;
    // Each block symmetrised: rounding must not let the carried covariance drift away from a
    // symmetric matrix over millions of updates.
    let block = |k: usize| {
        let r = 3 * k;
        let b = cov.fixed_view::<3, 3>(r, r)
            - gain.fixed_view::<3, M>(r, 0) * pht.fixed_view::<3, M>(r, 0).transpose();
        (b + b.transpose()) * 0.5
    };
    Ok((x, [block(0), block(1), block(2), block(3)]))
}

/// The field `v` (NED) turned about the vertical to have no east component.
fn horizontal_north(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(crate::math::sqrt(v.x * v.x + v.y * v.y), 0.0, v.z)
}

impl<N: NavFrame> OrientationFilter<N> for KalmanFilter<N> {
    fn update(&mut self, input: &FilterInput) -> Result<Option<Estimate<N>>, OrientError> {
        check_finite(input, true, self.magnetometer)?;
        let p = &self.params;
        let y_a = gravity_reading(input.accel_m_s2, p.accel_sign);
        let y_m = Vector3::from(input.mag_ut);
        let w = Vector3::from(input.gyro_rad_s);
        let mut s = self.state;
        if let Some(dt) = input.interval_s {
            s.block_s = Some(s.block_s.unwrap_or(0.0) + dt);
        }
        if s.started {
            let step = match input.interval_s {
                Some(dt) => (w - s.gyro_offset) * dt,
                None => (w - s.gyro_offset) / p.sample_rate_hz,
            };
            s.q *= UnitQuaternion::from_scaled_axis(step);
        } else {
            s.q = if self.magnetometer {
                ecompass_ned(&y_a, &y_m)?
            } else {
                tilt::<N>(&y_a)?
            };
            if self.magnetometer {
                s.mag_nav = horizontal_north(&(s.q * y_m));
            }
            s.started = true;
        }
        s.in_block += 1;
        if s.in_block < p.decimation {
            self.state = s;
            return Ok(None);
        }
        s.in_block = 0;
        self.correct(&mut s, &y_a, &y_m)?;
        self.state = s;
        Ok(Some(Estimate {
            orientation: to_frame(&s.q),
            angular_velocity_rad_s: (w - s.gyro_offset).into(),
        }))
    }

    fn reset(&mut self) {
        self.state = KalmanState::new(&self.params);
    }
}
