//! A loosely coupled error-state Kalman filter: 15 error states — position, velocity, attitude
//! (a small rotation φ of the navigation frame, `C_true = (I + [φ×]) Ĉ`), accelerometer bias,
//! gyroscope bias — around a strapdown nominal state on the flat Earth (frame `N`, constant
//! gravity), with closed-loop correction after every update.
//!
//! Propagation per IMU interval `Δt` (rates `ω_m`, `f_m`, biases removed, averaged over the
//! interval): `q ← q ⊗ exp(ω̂ Δt)`, `v ← v + Ĉ_mid f̂ Δt + g Δt`, `p ← p + ½ (v₀ + v₁) Δt`.
//! Error dynamics (Groves 2nd ed. §14.2, flat Earth):
//! `δṗ = δv`, `δv̇ = −[f^n×] φ − Ĉ δb_a − Ĉ n_a`, `φ̇ = −Ĉ δb_g − Ĉ n_g`, `δḃ = n_b`
//! (random-walk biases). `Φ = I + F Δt + (F Δt)²/2`; `Q_d = ½ (Φ G Q Gᵀ Φᵀ + G Q Gᵀ) Δt`.
//! Updates: GNSS position and velocity at an antenna lever arm `l`
//! (`p_a = p + Ĉ l`, `v_a = v + Ĉ (ω̂ × l)`), with `H` from
//! `δp_a = δp − [(Ĉ l)×] φ` and `δv_a = δv − [(Ĉ(ω̂×l))×] φ + Ĉ [l×] δb_g`; Joseph form,
//! symmetrised; a chi-square innovation gate (normalised innovation squared, NIS) rejects and
//! counts outliers. Ground-vehicle aiding: body-frame velocity (odometer forward speed,
//! non-holonomic zero lateral and vertical velocity) with `δv_b = Ĉᵀ δv + Ĉᵀ [v̂×] φ`, and
//! height (barometer) on the frame's up axis.
use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

use crate::frame::{Body, NavFrame};
use crate::math;
use crate::rotation::Rotation;
use crate::vector::Vec3;

use super::sensor_errors::{
    ACCEL_MATRIX, BASE_STATES, FULL_STATES, GYRO_ERRORS, GyroJacobian, SensorErrorEstimate,
    SensorErrorSigma, SensorErrors, d_gyro, d_matrix,
};

/// The error covariance of `S` states.
pub(crate) type Cov<const S: usize> = SMatrix<f64, S, S>;
/// An error-state vector of `S` states.
pub(crate) type StateVec<const S: usize> = SVector<f64, S>;

/// Continuous-time noise of the IMU as the filter models it (per axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EskfNoise {
    /// White accelerometer noise, (m/s²)/√Hz (two-sided PSD √q of the continuous process).
    pub accel_psd: f64,
    /// White gyroscope noise, (rad/s)/√Hz.
    pub gyro_psd: f64,
    /// Accelerometer bias random walk, (m/s²)·√Hz… i.e. m/s³/√Hz.
    pub accel_bias_psd: f64,
    /// Gyroscope bias random walk, rad/s²/√Hz.
    pub gyro_bias_psd: f64,
}

/// One-sigma uncertainty of the initial state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialSigma {
    /// Position, m.
    pub position_m: f64,
    /// Velocity, m/s.
    pub velocity_m_s: f64,
    /// Attitude (roll, pitch about horizontal axes; yaw), rad.
    pub attitude_rad: [f64; 3],
    /// Accelerometer bias, m/s².
    pub accel_bias_m_s2: f64,
    /// Gyroscope bias, rad/s.
    pub gyro_bias_rad_s: f64,
}

/// The filter's estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EskfState<N> {
    /// Time, s.
    pub t_s: f64,
    /// Position, navigation frame, m.
    pub position_m: Vec3<N>,
    /// Velocity, navigation frame, m/s.
    pub velocity_m_s: Vec3<N>,
    /// Attitude `C_nb`.
    pub attitude: Rotation<Body, N>,
    /// Accelerometer bias, body frame, m/s².
    pub accel_bias_m_s2: [f64; 3],
    /// Gyroscope bias, body frame, rad/s.
    pub gyro_bias_rad_s: [f64; 3],
}

/// What an update did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateOutcome {
    /// Normalised innovation squared `yᵀ S⁻¹ y`.
    pub nis: f64,
    /// Whether it was applied (false: rejected by the gate).
    pub accepted: bool,
}

/// One GNSS fix as the filter takes it (see [`Eskf::update_gnss_fix`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssFix<N> {
    /// Antenna position, navigation frame, m.
    pub position_m: Vec3<N>,
    /// Antenna velocity, navigation frame, m/s (`None`: position only).
    pub velocity_m_s: Option<Vec3<N>>,
    /// Antenna lever arm, body frame, m.
    pub lever_arm_m: Vec3<Body>,
    /// Position one-sigma per axis, m.
    pub position_sigma_m: [f64; 3],
    /// Velocity one-sigma per axis, m/s.
    pub velocity_sigma_m_s: [f64; 3],
    /// How long before the filter's current time the fix was valid, s (≥ 0): the receiver's
    /// latency plus the wait for the next IMU sample.
    pub age_s: f64,
}

/// Why the filter refused input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EskfError {
    /// A value that is not finite, at IMU sample `index` (or update `index`).
    NotFinite {
        /// Sample or update index.
        index: usize,
    },
    /// Times that do not increase.
    TimeNotIncreasing {
        /// Sample index.
        index: usize,
    },
    /// The innovation covariance could not be inverted or the covariance lost its positive
    /// definiteness: the filter diverged.
    Diverged {
        /// Update index.
        index: usize,
    },
    /// A noise or initial sigma out of range.
    BadParameter {
        /// Which.
        field: &'static str,
    },
}

impl core::fmt::Display for EskfError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::NotFinite { index } => write!(f, "sample {index} is not a finite number"),
            Self::TimeNotIncreasing { index } => {
                write!(f, "time at sample {index} does not increase")
            }
            Self::Diverged { index } => write!(
                f,
                "the filter diverged at update {index} (its covariance is no longer positive definite)"
            ),
            Self::BadParameter { field } => write!(f, "{field} must be a finite number ≥ 0"),
        }
    }
}

impl core::error::Error for EskfError {}

pub(crate) fn sq(x: f64) -> f64 {
    x * x
}

pub(crate) fn skew(v: &Vector3<f64>) -> nalgebra::Matrix3<f64> {
    nalgebra::Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The non-zero blocks of `A = FΔt + (FΔt)²/2` (rows/columns in blocks of 3: δp, δv, φ, δb_a,
/// δb_g, then the sensor errors δm_a (9) and δm_g (12), see [`super::sensor_errors`]):
/// `F₀₁ = I`, `F₁₂ = −[f^n×]`, `F₁₃ = −Ĉ`, `F₂₄ = −Ĉ`, `F₁₅ = −Ĉ D_a`, `F₂₆ = −Ĉ D_g`, and `F²`
/// adds `(0,2) = −[f^n×]`, `(0,3) = −Ĉ`, `(1,4) = [f^n×]Ĉ`, `(0,5) = −Ĉ D_a`,
/// `(1,6) = [f^n×] Ĉ D_g`.
struct Transition {
    a01: nalgebra::Matrix3<f64>,
    a02: nalgebra::Matrix3<f64>,
    a03: nalgebra::Matrix3<f64>,
    a12: nalgebra::Matrix3<f64>,
    a13: nalgebra::Matrix3<f64>,
    a14: nalgebra::Matrix3<f64>,
    a24: nalgebra::Matrix3<f64>,
    /// `(a05, a15, a16, a26)` with the sensor errors.
    sensor: Option<SensorBlocks>,
}

/// The transition's sensor-error blocks `a05`, `a15` (3 × 9) and `a16`, `a26` (3 × 12).
type SensorBlocks = (
    SMatrix<f64, 3, 9>,
    SMatrix<f64, 3, 9>,
    GyroJacobian,
    GyroJacobian,
);

impl Transition {
    fn new(
        fx: &nalgebra::Matrix3<f64>,
        c: &nalgebra::Matrix3<f64>,
        sensor: Option<(SMatrix<f64, 3, 9>, GyroJacobian)>,
        dt: f64,
    ) -> Self {
        let h = 0.5 * dt * dt;
        Self {
            a01: nalgebra::Matrix3::identity() * dt,
            a02: -fx * h,
            a03: -c * h,
            a12: -fx * dt,
            a13: -c * dt,
            a14: fx * c * h,
            a24: -c * dt,
            sensor: sensor.map(|(cda, cdg)| (-cda * h, -cda * dt, fx * cdg * h, -cdg * dt)),
        }
    }

    /// `A · m`, block row by block row (rows 3–4 and the sensor rows of A are zero).
    fn times<const S: usize>(&self, m: &Cov<S>) -> Cov<S> {
        let row = |k: usize| m.fixed_view::<3, S>(3 * k, 0);
        let mut r0 = self.a01 * row(1) + self.a02 * row(2) + self.a03 * row(3);
        let mut r1 = self.a12 * row(2) + self.a13 * row(3) + self.a14 * row(4);
        let mut r2 = self.a24 * row(4);
        if let Some((a05, a15, a16, a26)) = &self.sensor {
            let accel = m.fixed_view::<9, S>(ACCEL_MATRIX, 0);
            let gyro = m.fixed_view::<12, S>(GYRO_ERRORS, 0);
            r0 += a05 * accel;
            r1 += a15 * accel + a16 * gyro;
            r2 += a26 * gyro;
        }
        let mut out = Cov::<S>::zeros();
        out.fixed_view_mut::<3, S>(0, 0).copy_from(&r0);
        out.fixed_view_mut::<3, S>(3, 0).copy_from(&r1);
        out.fixed_view_mut::<3, S>(6, 0).copy_from(&r2);
        out
    }
}

/// The error-state filter of `S` states: [`BASE_STATES`] (15, the default) or [`FULL_STATES`]
/// (36, with the sensors' scale-factor, misalignment and g-sensitivity errors, see
/// [`super::sensor_errors`]); any other `S` does not compile.
#[derive(Clone, Copy, Debug)]
pub struct Eskf<N: NavFrame, const S: usize = BASE_STATES> {
    t: f64,
    p: Vector3<f64>,
    v: Vector3<f64>,
    q: UnitQuaternion<f64>,
    ba: Vector3<f64>,
    bg: Vector3<f64>,
    errors: SensorErrors,
    cov: Cov<S>,
    noise: EskfNoise,
    g: Vector3<f64>,
    intake: Intake,
    updates: usize,
    rejected: usize,
    frame: core::marker::PhantomData<N>,
}

impl<N: NavFrame, const S: usize> Eskf<N, S> {
    /// A filter at `initial` (biases zero unless given) with `sigma` initial uncertainty (the
    /// sensor errors of a 36-state filter start at zero, known exactly until
    /// [`Self::with_sensor_error_sigma`]).
    ///
    /// # Errors
    /// Non-finite state, negative or non-finite sigmas or noise.
    pub fn new(
        initial: &EskfState<N>,
        sigma: &InitialSigma,
        noise: EskfNoise,
        gravity_m_s2: f64,
    ) -> Result<Self, EskfError> {
        let cov = initial_covariance(sigma, &noise)?;
        non_negative("gravity_m_s2", gravity_m_s2)?;
        let finite = [initial.t_s]
            .iter()
            .chain(initial.position_m.as_nalgebra().iter())
            .chain(initial.velocity_m_s.as_nalgebra().iter())
            .chain(&initial.accel_bias_m_s2)
            .chain(&initial.gyro_bias_rad_s)
            .all(|v| v.is_finite());
        if !finite {
            return Err(EskfError::NotFinite { index: 0 });
        }
        Ok(Self {
            t: initial.t_s,
            p: *initial.position_m.as_nalgebra(),
            v: *initial.velocity_m_s.as_nalgebra(),
            q: *initial.attitude.quaternion(),
            ba: Vector3::from(initial.accel_bias_m_s2),
            bg: Vector3::from(initial.gyro_bias_rad_s),
            errors: SensorErrors::new(),
            cov,
            noise,
            g: *N::gravity(gravity_m_s2).as_nalgebra(),
            intake: Intake::new(),
            updates: 0,
            rejected: 0,
            frame: core::marker::PhantomData,
        })
    }

    /// Propagates the covariance once per `interval_s` (or at the next update, whichever comes
    /// first) instead of at every IMU sample: the nominal state still follows every sample, and
    /// the interval's error dynamics use its mean specific force and attitude (the transition
    /// of `F` at the mean over `Δt`). The covariance (and [`Self::sigmas`]) then lags the state
    /// by less than `interval_s`; at 100 Hz an interval of 0.05 s makes propagation about four
    /// times faster. 0 (the default) steps it with every sample.
    ///
    /// # Errors
    /// An interval that is negative or not finite.
    pub fn with_covariance_interval(mut self, interval_s: f64) -> Result<Self, EskfError> {
        self.intake.set_interval(interval_s)?;
        Ok(self)
    }

    /// The initial one-sigma of the sensor errors (36 states; see [`super::sensor_errors`]).
    ///
    /// # Errors
    /// A 15-state filter, or a sigma that is negative or not finite.
    pub fn with_sensor_error_sigma(mut self, sigma: &SensorErrorSigma) -> Result<Self, EskfError> {
        set_sensor_variances(&mut self.cov, sigma)?;
        Ok(self)
    }

    /// The estimated sensor errors (zero in a 15-state filter).
    #[must_use]
    pub fn sensor_errors(&self) -> SensorErrorEstimate {
        self.errors.estimate()
    }

    /// The current estimate.
    #[must_use]
    pub fn state(&self) -> EskfState<N> {
        EskfState {
            t_s: self.t,
            position_m: Vec3::from_nalgebra(self.p),
            velocity_m_s: Vec3::from_nalgebra(self.v),
            attitude: Rotation::assume_from_quaternion(self.q),
            accel_bias_m_s2: self.ba.into(),
            gyro_bias_rad_s: self.bg.into(),
        }
    }

    /// One-sigma of the error states: position (3), velocity (3), attitude (3, navigation
    /// axes), accelerometer bias (3), gyroscope bias (3), and with 36 states the sensor
    /// errors `M_a`, `M_g` (9 each, row-major) and `k` (3).
    #[must_use]
    pub fn sigmas(&self) -> [f64; S] {
        core::array::from_fn(|i| math::sqrt(self.cov[(i, i)].max(0.0)))
    }

    /// The error covariance entry `(i, j)` (`S × S`).
    #[must_use]
    pub fn covariance(&self, i: usize, j: usize) -> f64 {
        self.cov[(i, j)]
    }

    /// Updates applied and rejected by the gate.
    #[must_use]
    pub fn update_counts(&self) -> (usize, usize) {
        (self.updates, self.rejected)
    }

    /// Takes IMU sample `(t_s, gyro, accel)` (body, rad/s and specific force m/s²): the first
    /// sets the start time, each later one propagates over the interval.
    ///
    /// # Errors
    /// Non-finite values or a time that does not increase.
    pub fn propagate(
        &mut self,
        t_s: f64,
        gyro_rad_s: [f64; 3],
        accel_m_s2: [f64; 3],
    ) -> Result<(), EskfError> {
        let Some((dt, w, f)) = self.intake.take(self.t, t_s, gyro_rad_s, accel_m_s2)? else {
            self.t = t_s;
            return Ok(());
        };
        let (w, f) = self.errors.correct::<S>(w - self.bg, f - self.ba);
        // Nominal state.
        let half = self.q * UnitQuaternion::from_scaled_axis(w * (0.5 * dt));
        let q1 = self.q * UnitQuaternion::from_scaled_axis(w * dt);
        let v0 = self.v;
        self.v += (half * f + self.g) * dt;
        self.p += 0.5 * (v0 + self.v) * dt;
        let c = half.to_rotation_matrix().into_inner();
        self.q = q1;
        self.t = t_s;
        if S == FULL_STATES {
            self.errors.accumulate(dt, &c, &w, &f);
        }
        if self.intake.accumulate(dt, &c, &f) {
            self.step_covariance();
        }
        Ok(())
    }

    /// One covariance step over the pending interval (nothing when none is pending): `Φ = I + A`,
    /// `A = FΔt + (FΔt)²/2` with the interval's mean `Ĉf̂` and `Ĉ`, kept as its seven non-zero
    /// 3 × 3 blocks; `Φ P Φᵀ = P + AP + (AP)ᵀ + A(AP)ᵀ` (P symmetric).
    fn step_covariance(&mut self) {
        let Some((dt, cf, c)) = self.intake.take_pending() else {
            return;
        };
        let sensor = (S == FULL_STATES).then(|| self.errors.take_pending(dt));
        let a = Transition::new(&skew(&cf), &c, sensor, dt);
        let ap = a.times(&self.cov);
        // G Q Gᵀ: velocity and attitude noise through Ĉ (isotropic: C q Cᵀ = q I), biases;
        // Q_d = ½ (Φ Q Φᵀ + Q) Δt.
        let qc = Cov::<S>::from_diagonal(&process_noise(&self.noise));
        let aq = a.times(&qc);
        let qd = (qc * 2.0 + aq + aq.transpose() + a.times(&aq.transpose())) * (0.5 * dt);
        self.cov += ap + ap.transpose() + a.times(&ap.transpose()) + qd;
        self.cov = (self.cov + self.cov.transpose()) * 0.5;
    }

    /// A GNSS position (and, when given, velocity) fix at the current time: `position_m` of the
    /// antenna at `lever_arm_m` (body) with one-sigma `position_sigma_m` per axis, and the
    /// antenna velocity with `velocity_sigma_m_s`. Rejected (and counted) when its NIS exceeds
    /// `gate` (a chi-square quantile for 3 or 6 degrees of freedom; `f64::INFINITY` turns the
    /// gate off).
    ///
    /// # Errors
    /// Non-finite input, or a covariance that can no longer be inverted (divergence).
    pub fn update_gnss(
        &mut self,
        position_m: Vec3<N>,
        velocity_m_s: Option<Vec3<N>>,
        lever_arm_m: Vec3<Body>,
        position_sigma_m: [f64; 3],
        velocity_sigma_m_s: [f64; 3],
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let fix = GnssFix {
            position_m,
            velocity_m_s,
            lever_arm_m,
            position_sigma_m,
            velocity_sigma_m_s,
            age_s: 0.0,
        };
        self.update_gnss_fix(&fix, gate)
    }

    /// [`Self::update_gnss`] for a fix valid `fix.age_s = τ` before the filter's time (latency
    /// compensation): the antenna is predicted back with the current acceleration
    /// `a = Ĉf̂ + g`, `p_a = p + Ĉl − τ (v + Ĉ(ω̂×l)) + ½τ² a` and `v_a = v + Ĉ(ω̂×l) − τ a`, so
    /// `δp_a = δp − τ δv − [(Ĉl)×] φ` and
    /// `δv_a = δv − [(Ĉ(ω̂×l))×] φ + τ [(Ĉf̂)×] φ + τ Ĉ δb_a + Ĉ [l×] δb_g` (the change of the
    /// lever-arm terms over `τ` is neglected).
    ///
    /// # Errors
    /// As [`Self::update_gnss`]; an age that is negative or not finite.
    pub fn update_gnss_fix(
        &mut self,
        fix: &GnssFix<N>,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let GnssFix {
            position_m,
            velocity_m_s,
            lever_arm_m,
            position_sigma_m,
            velocity_sigma_m_s,
            age_s,
        } = *fix;
        let index = self.updates + self.rejected;
        if !(age_s.is_finite() && age_s >= 0.0) {
            return Err(EskfError::NotFinite { index });
        }
        let (w_last, f_last) = self.intake.last();
        let (w_body, f_body) = self.errors.correct::<S>(w_last - self.bg, f_last - self.ba);
        let lin = Linearisation {
            c: self.q.to_rotation_matrix().into_inner(),
            v: self.v,
            w_body,
            f_body,
            g: self.g,
        };
        let delta_p = *position_m.as_nalgebra() - self.p;
        let (h, y, r) = gnss_model(
            &lin,
            delta_p,
            velocity_m_s.map(|v| *v.as_nalgebra()),
            *lever_arm_m.as_nalgebra(),
            [position_sigma_m, velocity_sigma_m_s],
            age_s,
            index,
        )?;
        self.correct(&h, &y, &r, gate, index)
    }

    /// A body-frame velocity measurement: `measured_m_s[i]`, when given, is the velocity of the
    /// reference point along body axis `i` with one-sigma `sigma_m_s[i]` — a wheel odometer's
    /// forward speed on x, and for a ground vehicle that neither slips sideways nor leaves the
    /// road the non-holonomic constraints, 0 on y and z. With `v_b = Ĉᵀ v`,
    /// `δv_b = Ĉᵀ δv + Ĉᵀ [v̂×] φ`. Gated like [`Self::update_gnss`] (`gate` for as many degrees
    /// of freedom as rows given).
    ///
    /// # Errors
    /// Non-finite input or sigmas that are not positive, or a covariance that can no longer be
    /// inverted (divergence).
    pub fn update_body_velocity(
        &mut self,
        measured_m_s: [Option<f64>; 3],
        sigma_m_s: [f64; 3],
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        let c = self.q.to_rotation_matrix().into_inner();
        let (h, y, r) = body_velocity_model(&c, &self.v, measured_m_s, sigma_m_s, index)?;
        self.correct(&h, &y, &r, gate, index)
    }

    /// A height measurement (a barometer): `height_m` of the reference point, up (`N::Z_UP`
    /// times the frame's z), one-sigma `sigma_m`. Gated with `gate` (one degree of freedom).
    ///
    /// # Errors
    /// Non-finite input, a sigma that is not positive, or divergence.
    pub fn update_height(
        &mut self,
        height_m: f64,
        sigma_m: f64,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        if !(height_m.is_finite() && sigma_m.is_finite() && sigma_m > 0.0) {
            return Err(EskfError::NotFinite { index });
        }
        let mut h = SMatrix::<f64, 1, S>::zeros();
        h[(0, 2)] = N::Z_UP;
        let y = SVector::<f64, 1>::new(height_m - N::Z_UP * self.p.z);
        let r = SVector::<f64, 1>::new(sq(sigma_m));
        self.correct(&h, &y, &r, gate, index)
    }

    /// The Kalman correction shared by every update: innovation `y` with model `H` and
    /// measurement variances `r` (rows with `H = 0`, `y = 0`, `r = 1` are inert); NIS against
    /// `gate` (rejected and counted above it); Joseph-form covariance, symmetrised; closed-loop
    /// injection of `δx` into the nominal state, and reset.
    /// A zero-angular-rate update (the vehicle stands still): the last gyroscope sample is
    /// what the gyroscopes read of a body at rest on the flat Earth, `b_g` (and the
    /// g-sensitivity's `k ∘ f`) plus noise of one-sigma `sigma_rad_s` per axis (one sample's
    /// white noise): `y = ω_m − b̂_g − k̂ ∘ f̂`, `H = I` on the gyroscope bias (and `diag(f̂)` on
    /// `k`). Gated with `gate` (three degrees of freedom).
    ///
    /// # Errors
    /// A sigma that is not positive, no sample taken yet, or divergence.
    pub fn update_zero_rate(
        &mut self,
        sigma_rad_s: f64,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        let (h, y, r) = zero_rate_model(
            self.intake.last_sample(),
            &self.bg,
            &self.ba,
            &self.errors,
            &Vector3::zeros(),
            sigma_rad_s,
            index,
        )?;
        self.correct(&h, &y, &r, gate, index)
    }

    fn correct<const M: usize>(
        &mut self,
        h: &SMatrix<f64, M, S>,
        y: &SVector<f64, M>,
        r: &SVector<f64, M>,
        gate: f64,
        index: usize,
    ) -> Result<UpdateOutcome, EskfError> {
        self.step_covariance();
        let (nis, dx) = kalman_update(&mut self.cov, h, y, r, gate, index)?;
        let Some(dx) = dx else {
            self.rejected += 1;
            return Ok(UpdateOutcome {
                nis,
                accepted: false,
            });
        };
        // Closed loop: inject and reset.
        self.p += dx.fixed_rows::<3>(0);
        self.v += dx.fixed_rows::<3>(3);
        let phi: Vector3<f64> = dx.fixed_rows::<3>(6).into();
        self.q = UnitQuaternion::from_scaled_axis(phi) * self.q;
        self.ba += dx.fixed_rows::<3>(9);
        self.bg += dx.fixed_rows::<3>(12);
        if !self.errors.inject(&dx) {
            return Err(EskfError::Diverged { index });
        }
        self.updates += 1;
        Ok(UpdateOutcome {
            nis,
            accepted: true,
        })
    }
}

/// `v` when it is a finite number ≥ 0, else a refusal naming `field`.
fn non_negative(field: &'static str, v: f64) -> Result<f64, EskfError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(EskfError::BadParameter { field })
    }
}

/// The initial covariance (diagonal, from `sigma`) after checking `sigma` and `noise`, for
/// both filters.
///
/// # Errors
/// A sigma or noise density that is negative or not finite, named.
pub(crate) fn initial_covariance<const S: usize>(
    sigma: &InitialSigma,
    noise: &EskfNoise,
) -> Result<Cov<S>, EskfError> {
    const {
        assert!(
            S == BASE_STATES || S == FULL_STATES,
            "the filters have 15 or 36 error states"
        );
    }
    non_negative("accel_psd", noise.accel_psd)?;
    non_negative("gyro_psd", noise.gyro_psd)?;
    non_negative("accel_bias_psd", noise.accel_bias_psd)?;
    non_negative("gyro_bias_psd", noise.gyro_bias_psd)?;
    let mut diag = StateVec::<S>::zeros();
    for i in 0..3 {
        diag[i] = sq(non_negative("position sigma", sigma.position_m)?);
        diag[3 + i] = sq(non_negative("velocity sigma", sigma.velocity_m_s)?);
        diag[6 + i] = sq(non_negative("attitude sigma", sigma.attitude_rad[i])?);
        diag[9 + i] = sq(non_negative(
            "accelerometer bias sigma",
            sigma.accel_bias_m_s2,
        )?);
        diag[12 + i] = sq(non_negative("gyroscope bias sigma", sigma.gyro_bias_rad_s)?);
    }
    Ok(Cov::<S>::from_diagonal(&diag))
}

/// Sets the initial variances of the sensor errors in `cov` (36 states).
///
/// # Errors
/// A 15-state covariance, or a sigma that is negative or not finite.
pub(crate) fn set_sensor_variances<const S: usize>(
    cov: &mut Cov<S>,
    sigma: &SensorErrorSigma,
) -> Result<(), EskfError> {
    if S != FULL_STATES {
        return Err(EskfError::BadParameter {
            field: "sensor error sigma (only a filter of 36 states has the sensor errors)",
        });
    }
    let variances = sigma.variances().ok_or(EskfError::BadParameter {
        field: "sensor error sigma",
    })?;
    for (k, v) in variances.iter().enumerate() {
        cov[(ACCEL_MATRIX + k, ACCEL_MATRIX + k)] = *v;
    }
    Ok(())
}

/// The diagonal of the continuous process noise `G Q Gᵀ`: velocity and attitude white noise,
/// bias random walks; none on position and the sensor matrices.
pub(crate) fn process_noise<const S: usize>(noise: &EskfNoise) -> StateVec<S> {
    let mut q = StateVec::<S>::zeros();
    for i in 0..3 {
        q[3 + i] = sq(noise.accel_psd);
        q[6 + i] = sq(noise.gyro_psd);
        q[9 + i] = sq(noise.accel_bias_psd);
        q[12 + i] = sq(noise.gyro_bias_psd);
    }
    q
}

/// The zero-angular-rate model shared by the filters: `sample` (the last raw gyroscope and
/// accelerometer readings, `None` before the first) of a body turning at `w_true` (body axes:
/// 0 on the flat Earth, the Earth rate on WGS-84) with biases `b̂_g`, `b̂_a` and sensor errors
/// `errors`: `y = ω_m − b̂_g − ((I + M̂_g) ω + k̂ ∘ f̂)`, `H = [I on δb_g, D_g on δm_g]`,
/// `R = σ² I`.
///
/// # Errors
/// No sample, a sigma that is not positive.
pub(crate) fn zero_rate_model<const S: usize>(
    sample: Option<(Vector3<f64>, Vector3<f64>)>,
    bg: &Vector3<f64>,
    ba: &Vector3<f64>,
    errors: &SensorErrors,
    w_true: &Vector3<f64>,
    sigma_rad_s: f64,
    index: usize,
) -> Result<Rows<3, S>, EskfError> {
    let Some((w_m, f_m)) = sample else {
        return Err(EskfError::NotFinite { index });
    };
    let (_, f) = errors.correct::<S>(Vector3::zeros(), f_m - ba);
    if !(sigma_rad_s.is_finite() && sigma_rad_s > 0.0) {
        return Err(EskfError::BadParameter {
            field: "zero-rate sigma",
        });
    }
    let mut h = SMatrix::<f64, 3, S>::zeros();
    h.fixed_view_mut::<3, 3>(0, 12)
        .copy_from(&nalgebra::Matrix3::identity());
    if S == FULL_STATES {
        h.fixed_view_mut::<3, 12>(0, GYRO_ERRORS)
            .copy_from(&d_gyro(w_true, &f));
    }
    let y = w_m - bg - errors.gyro_reading(w_true, &f);
    Ok((h, y, SVector::<f64, 3>::repeat(sq(sigma_rad_s))))
}

/// What a measurement model needs of the nominal state: `Ĉ` (body to navigation), the
/// velocity, the bias-corrected body rate and specific force of the last sample, and gravity.
pub(crate) struct Linearisation {
    pub(crate) c: nalgebra::Matrix3<f64>,
    pub(crate) v: Vector3<f64>,
    pub(crate) w_body: Vector3<f64>,
    pub(crate) f_body: Vector3<f64>,
    pub(crate) g: Vector3<f64>,
}

/// A measurement model of `M` rows: `H` (M × S), innovation `y` and variances `r`.
pub(crate) type Rows<const M: usize, const S: usize> =
    (SMatrix<f64, M, S>, SVector<f64, M>, SVector<f64, M>);

/// The GNSS measurement model shared by the flat and the Earth filters: `delta_p` is the fix's
/// position minus the nominal position in local navigation-frame metres; the antenna at lever
/// arm `l`, the fix valid `age_s` earlier (see [`Eskf::update_gnss_fix`]); `sigmas` are the
/// position and velocity one-sigmas. Returns `(H, y, r)` with unused velocity rows inert. With
/// the sensor errors the velocity rows also see them through the lever arm
/// (`Ĉ [l×] D_g δm_g`) and the latency (`τ Ĉ D_a δm_a`).
pub(crate) fn gnss_model<const S: usize>(
    lin: &Linearisation,
    delta_p: Vector3<f64>,
    velocity_m_s: Option<Vector3<f64>>,
    l: Vector3<f64>,
    sigmas: [[f64; 3]; 2],
    age_s: f64,
    index: usize,
) -> Result<Rows<6, S>, EskfError> {
    let c = lin.c;
    let cl = c * l;
    let cwl = c * lin.w_body.cross(&l);
    let cf = c * lin.f_body;
    let accel = cf + lin.g;
    let z_p = delta_p - (cl - (lin.v + cwl) * age_s + accel * (0.5 * age_s * age_s));
    let mut finite = z_p.iter().all(|v| v.is_finite());
    let mut h = SMatrix::<f64, 6, S>::zeros();
    let mut y = SVector::<f64, 6>::zeros();
    let mut r = SVector::<f64, 6>::repeat(1.0);
    h.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&nalgebra::Matrix3::identity());
    h.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(nalgebra::Matrix3::identity() * -age_s));
    h.fixed_view_mut::<3, 3>(0, 6).copy_from(&(-skew(&cl)));
    y.fixed_rows_mut::<3>(0).copy_from(&z_p);
    for i in 0..3 {
        r[i] = sq(sigmas[0][i]);
    }
    if let Some(vm) = velocity_m_s {
        let z_v = vm - (lin.v + cwl - accel * age_s);
        finite &= z_v.iter().all(|v| v.is_finite());
        h.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&nalgebra::Matrix3::identity());
        h.fixed_view_mut::<3, 3>(3, 6)
            .copy_from(&(-skew(&cwl) + skew(&cf) * age_s));
        h.fixed_view_mut::<3, 3>(3, 9).copy_from(&(c * age_s));
        h.fixed_view_mut::<3, 3>(3, 12).copy_from(&(c * skew(&l)));
        if S == FULL_STATES {
            h.fixed_view_mut::<3, 9>(3, ACCEL_MATRIX)
                .copy_from(&(c * d_matrix(&lin.f_body) * age_s));
            h.fixed_view_mut::<3, 12>(3, GYRO_ERRORS)
                .copy_from(&(c * skew(&l) * d_gyro(&lin.w_body, &lin.f_body)));
        }
        y.fixed_rows_mut::<3>(3).copy_from(&z_v);
        for i in 0..3 {
            r[3 + i] = sq(sigmas[1][i]);
        }
    }
    let all_sigma = sigmas[0]
        .iter()
        .chain(&sigmas[1])
        .all(|s| s.is_finite() && *s > 0.0);
    if !(finite && all_sigma && age_s.is_finite() && age_s >= 0.0) {
        return Err(EskfError::NotFinite { index });
    }
    Ok((h, y, r))
}

/// A body-velocity measurement's model, shared by the filters: rows `i` with a measurement;
/// `v_b = Ĉᵀ v`, so `δv_b = Ĉᵀ δv + Ĉᵀ [v̂×] φ` (see [`Eskf::update_body_velocity`]).
///
/// # Errors
/// A measurement that is not finite or a sigma that is not positive.
pub(crate) fn body_velocity_model<const S: usize>(
    c: &nalgebra::Matrix3<f64>,
    v: &Vector3<f64>,
    measured_m_s: [Option<f64>; 3],
    sigma_m_s: [f64; 3],
    index: usize,
) -> Result<Rows<3, S>, EskfError> {
    let ct = c.transpose();
    let predicted = ct * v;
    let h_phi = ct * skew(v);
    let mut h = SMatrix::<f64, 3, S>::zeros();
    let mut y = SVector::<f64, 3>::zeros();
    let mut r = SVector::<f64, 3>::repeat(1.0);
    for i in 0..3 {
        let Some(z) = measured_m_s[i] else { continue };
        if !(z.is_finite() && sigma_m_s[i].is_finite() && sigma_m_s[i] > 0.0) {
            return Err(EskfError::NotFinite { index });
        }
        h.fixed_view_mut::<1, 3>(i, 3).copy_from(&ct.row(i));
        h.fixed_view_mut::<1, 3>(i, 6).copy_from(&h_phi.row(i));
        y[i] = z - predicted[i];
        r[i] = sq(sigma_m_s[i]);
    }
    Ok((h, y, r))
}

/// The Kalman correction shared by the filters: innovation `y`, model `H`, measurement
/// variances `r` (rows with `H = 0`, `y = 0`, `r = 1` are inert); the NIS against `gate`
/// (`None` correction above it); otherwise the Joseph-form covariance, symmetrised, and the
/// error-state correction `δx` to inject.
///
/// # Errors
/// An innovation covariance that cannot be inverted, or a covariance that loses its positive
/// diagonal: divergence at update `index`.
pub(crate) fn kalman_update<const M: usize, const S: usize>(
    cov: &mut Cov<S>,
    h: &SMatrix<f64, M, S>,
    y: &SVector<f64, M>,
    r: &SVector<f64, M>,
    gate: f64,
    index: usize,
) -> Result<(f64, Option<StateVec<S>>), EskfError> {
    let rm = SMatrix::<f64, M, M>::from_diagonal(r);
    let s = h * *cov * h.transpose() + rm;
    let Some(s_inv) = s.try_inverse() else {
        return Err(EskfError::Diverged { index });
    };
    let nis = (y.transpose() * s_inv * y)[(0, 0)];
    if !nis.is_finite() || nis < 0.0 {
        return Err(EskfError::Diverged { index });
    }
    if nis > gate {
        return Ok((nis, None));
    }
    let pht = *cov * h.transpose();
    let k = pht * s_inv;
    let dx = k * y;
    // Joseph form `(I − KH) P (I − KH)ᵀ + K R Kᵀ`, multiplied out in an order that keeps every
    // product thin (S × M or M × S): `A = P − K (HP)`, then `A − (A Hᵀ) Kᵀ`.
    let a = *cov - k * pht.transpose();
    *cov = a - (a * h.transpose()) * k.transpose() + k * rm * k.transpose();
    *cov = (*cov + cov.transpose()) * 0.5;
    if (0..S).any(|i| cov[(i, i)].is_nan() || cov[(i, i)] < 0.0) {
        return Err(EskfError::Diverged { index });
    }
    Ok((nis, Some(dx)))
}

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
