//! A loosely coupled error-state Kalman filter on any [`EarthModel`]: 15 error states —
//! position (metres of the navigation frame), velocity, attitude (a small rotation φ of the
//! navigation frame, `C_true = (I + [φ×]) Ĉ`), accelerometer bias, gyroscope bias — or 36 with
//! the sensors' scale-factor, misalignment and g-sensitivity errors of
//! [`super::sensor_errors`], either with the fixes' correlated errors of
//! [`super::fix_errors`] (18 or 39), around the strapdown of [`crate::strapdown::increments`]
//! (increments by the trapezoid of each interval's rate samples, coning and sculling, the
//! Earth's terms), with closed-loop correction after every update. Fixed-size matrices, no
//! heap.
//!
//! Error dynamics (Groves 2nd ed. §14.2, local-navigation frame, position error in metres):
//! `δṗ = δv`; `δv̇ = −[f^n×]φ − Ĉ δb_a − Ĉ n_a + G δp − [(2ω_ie + ω_en)×] δv`;
//! `φ̇ = −Ĉ δb_g − Ĉ n_g − [ω_in×]φ − (∂ω_in/∂p) δp − (∂ω_en/∂v) δv`; `δḃ = n_b` (random-walk
//! biases). The Earth's couplings (`G`, the gravity gradient's vertical term; the frame rate's
//! derivatives, which close the Schuler loop) come from [`EarthModel::couplings`] and vanish on
//! the flat Earth. `Φ = I + A`, `A = FΔt + (FΔt)²/2`, kept as its non-zero 3 × 3 blocks (the
//! rows below the attitude are zero); `Q_d = ½ (Φ G Q Gᵀ Φᵀ + G Q Gᵀ) Δt`.
//!
//! Updates: GNSS position and velocity at an antenna lever arm `l`
//! (`p_a = p + Ĉ l`, `v_a = v + Ĉ (ω̂ × l)`), with `H` from
//! `δp_a = δp − [(Ĉ l)×] φ` and `δv_a = δv − [(Ĉ(ω̂×l))×] φ + Ĉ [l×] δb_g`, the position
//! innovation the Earth's [`EarthModel::displacement_m`]; Joseph form, symmetrised; a
//! chi-square innovation gate (normalised innovation squared, NIS) rejects and counts
//! outliers. Ground-vehicle aiding: body-frame velocity (odometer forward speed,
//! non-holonomic zero lateral and vertical velocity) with `δv_b = Ĉᵀ δv + Ĉᵀ [v̂×] φ`; height
//! (barometer) on the frame's up axis; zero angular rate. Corrections are injected into the
//! position through [`EarthModel::offset`].
use crate::fusion::gate::Gate;
use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

use super::fix_errors::{self, FixErrorModel, has_fix_errors, has_sensor_errors};
use super::sensor_errors::{BASE_STATES, SensorErrorEstimate, SensorErrorSigma, SensorErrors};
use super::smoother::{EpochRecord, SmoothingLog};
use crate::earth::EarthModel;
use crate::math;
use crate::nav_frame::NavFrame;
use crate::rotation::Rotation;
use crate::strapdown::{Increments, NavState, StrapdownOptions};
use crate::vector::Vec3;

mod intake;
mod measurements;
mod models;
mod reset;
mod transition;

pub(crate) use intake::Intake;
pub use measurements::{BodyVelocity, GnssFix, Height, Measurement, ModelRows, ZeroRate};
pub(crate) use models::{initial_covariance, kalman_update, process_noise, set_sensor_variances};
use transition::{Dynamics, EarthCouplings, Transition};

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
pub struct EskfState<E: EarthModel> {
    /// Time, attitude `C_nb`, velocity and position.
    pub nav: NavState<E>,
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

/// A 3 × `C` block of the transition.
type Block<const C: usize> = SMatrix<f64, 3, C>;

/// The error-state filter of `S` states on the Earth `E`: [`BASE_STATES`] (15, the default) or
/// [`FULL_STATES`](super::FULL_STATES) (36, with the sensors' scale-factor, misalignment and g-sensitivity errors,
/// see [`super::sensor_errors`]), either plus [`super::FIX_ERROR_STATES`] (18 or 39, with the
/// fixes' correlated errors, see [`super::fix_errors`]); any other `S` does not compile.
#[derive(Clone, Copy, Debug)]
pub struct Eskf<E: EarthModel, const S: usize = BASE_STATES> {
    mechanization: Increments<E>,
    nav: NavState<E>,
    ba: Vector3<f64>,
    bg: Vector3<f64>,
    errors: SensorErrors,
    cov: Cov<S>,
    noise: EskfNoise,
    intake: Intake,
    updates: usize,
    rejected: usize,
    smoothing: Option<SmoothingLog<S>>,
    /// The fixes' correlated error as modelled (18 and 39 states; `None`: those states stay
    /// zero) and its estimate `b̂`, navigation axes, m.
    fix_error: Option<FixErrorModel>,
    fix_error_m: Vector3<f64>,
    /// The biases' initial variances (accelerometer, then gyroscope), which a reset restores.
    initial_bias_variance: [f64; 6],
}

impl<E: EarthModel, const S: usize> Eskf<E, S> {
    /// A filter on `earth` at `initial` with `sigma` initial uncertainty (position in metres
    /// on each navigation axis; the sensor errors of a 36-state filter start at zero, known
    /// exactly until [`Self::with_sensor_error_sigma`]).
    ///
    /// # Errors
    /// Non-finite state, one outside the frame's domain (beyond ±89.9° on WGS-84), gravity
    /// that is not finite or points up, sigmas or noise that are negative or not finite.
    pub fn new(
        earth: E,
        initial: &EskfState<E>,
        sigma: &InitialSigma,
        noise: EskfNoise,
    ) -> Result<Self, EskfError> {
        let cov = initial_covariance(sigma, &noise)?;
        let finite = initial
            .accel_bias_m_s2
            .iter()
            .chain(&initial.gyro_bias_rad_s)
            .all(|v| v.is_finite());
        let c = E::coordinates(&initial.nav.position);
        let g = -<E::Frame as NavFrame>::Z_UP
            * earth.terms(&c, &initial.nav.velocity_m_s).gravity_m_s2.z();
        non_negative("gravity_m_s2", g)?;
        let mechanization = Increments::new(earth, &initial.nav, StrapdownOptions::default())
            .map_err(|_| EskfError::NotFinite { index: 0 })?;
        if !finite {
            return Err(EskfError::NotFinite { index: 0 });
        }
        Ok(Self {
            mechanization,
            nav: initial.nav,
            ba: Vector3::from(initial.accel_bias_m_s2),
            bg: Vector3::from(initial.gyro_bias_rad_s),
            errors: SensorErrors::new(),
            cov,
            noise,
            intake: Intake::new(),
            updates: 0,
            rejected: 0,
            smoothing: None,
            fix_error: None,
            fix_error_m: Vector3::zeros(),
            initial_bias_variance: core::array::from_fn(|k| cov[(9 + k, 9 + k)]),
        })
    }

    /// Keeps what a forward–backward smoother needs ([`super::smoother`]): an
    /// [`EpochRecord`] at every time the state is corrected and at least every `max_gap_s` of
    /// propagation, taken with [`Self::take_epoch`] after each call. Set after the covariance
    /// is complete (after [`Self::with_sensor_error_sigma`]).
    ///
    /// # Errors
    /// A gap that is not finite and positive.
    pub fn with_smoothing(mut self, max_gap_s: f64) -> Result<Self, EskfError> {
        if !(max_gap_s.is_finite() && max_gap_s > 0.0) {
            return Err(EskfError::BadParameter {
                field: "smoothing gap",
            });
        }
        self.smoothing = Some(SmoothingLog::new(max_gap_s, self.nav.t_s, &self.cov));
        Ok(self)
    }

    /// The next finished epoch of a filter kept for smoothing ([`Self::with_smoothing`]).
    pub fn take_epoch(&mut self) -> Option<EpochRecord<S>> {
        self.smoothing.as_mut().and_then(SmoothingLog::take)
    }

    /// Ends the smoother's record: the pending covariance step taken, the last epochs closed
    /// (then taken with [`Self::take_epoch`]).
    pub fn finish_smoothing(&mut self) {
        self.step_covariance();
        let (t, cov) = (self.nav.t_s, self.cov);
        if let Some(log) = self.smoothing.as_mut() {
            log.finish(t, &cov);
        }
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

    /// The fixes' correlated position error ([`super::fix_errors`]): a filter of 18 or 39
    /// states estimates it from `model`, starting at zero with the model's initial one-sigma.
    /// Set before [`Self::with_smoothing`].
    ///
    /// # Errors
    /// A filter without those states, or a model that is not valid
    /// ([`FixErrorModel::is_valid`]).
    pub fn with_fix_errors(mut self, model: FixErrorModel) -> Result<Self, EskfError> {
        if !has_fix_errors(S) {
            return Err(EskfError::BadParameter {
                field: "fix error model (only a filter of 18 or 39 states has the fix errors)",
            });
        }
        if !model.is_valid() {
            return Err(EskfError::BadParameter {
                field: "fix error model",
            });
        }
        let b = fix_errors::first::<S>();
        for k in 0..3 {
            self.cov.row_mut(b + k).fill(0.0);
            self.cov.column_mut(b + k).fill(0.0);
            self.cov[(b + k, b + k)] = sq(model.initial_sigma_m[k]);
        }
        self.fix_error = Some(model);
        Ok(self)
    }

    /// Scales the fixes' correlated error by `factor` in variance (its stationary one-sigma, its
    /// estimate's one-sigma and its correlations by `√factor`; the estimate itself kept): what
    /// an adaptive filter does when the fixes' innovations show a receiver worse or better than
    /// modelled. Rows and columns scaled alike keep the covariance positive definite. Nothing
    /// without the fix-error states.
    ///
    /// # Errors
    /// A factor that is not finite and positive.
    pub fn scale_fix_errors(&mut self, factor: f64) -> Result<(), EskfError> {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(EskfError::BadParameter {
                field: "fix error scale",
            });
        }
        if self.fix_error.is_none() {
            return Ok(());
        }
        self.step_covariance();
        let root = math::sqrt(factor);
        if let Some(model) = self.fix_error.as_mut() {
            model.sigma_m = model.sigma_m.map(|s| s * root);
        }
        let b = fix_errors::first::<S>();
        let before = self.cov;
        for k in b..S {
            self.cov.row_mut(k).scale_mut(root);
            self.cov.column_mut(k).scale_mut(root);
        }
        // To the smoother a transition of no duration, `Φ = diag(1, …, √factor)`.
        let (t, after) = (self.nav.t_s, self.cov);
        if let Some(log) = self.smoothing.as_mut() {
            let mut phi = Cov::<S>::identity();
            for k in b..S {
                phi[(k, k)] = root;
            }
            log.step(&before, &phi, 0.0, &after, t);
        }
        Ok(())
    }

    /// The estimated error of the fixes, navigation axes, m (zero without the fix-error
    /// states).
    #[must_use]
    pub fn fix_error_m(&self) -> [f64; 3] {
        self.fix_error_m.into()
    }

    /// The Earth the filter runs on.
    #[must_use]
    pub fn earth(&self) -> &E {
        self.mechanization.earth()
    }

    /// The estimated sensor errors (zero in a 15-state filter).
    #[must_use]
    pub fn sensor_errors(&self) -> SensorErrorEstimate {
        self.errors.estimate()
    }

    /// The current estimate.
    #[must_use]
    pub fn state(&self) -> EskfState<E> {
        EskfState {
            nav: self.nav,
            accel_bias_m_s2: self.ba.into(),
            gyro_bias_rad_s: self.bg.into(),
        }
    }

    /// One-sigma of the error states: position (3, m on the navigation axes), velocity (3),
    /// attitude (3, navigation axes), accelerometer bias (3), gyroscope bias (3), with 36 or 39
    /// states the sensor errors `M_a`, `M_g` (9 each, row-major) and `k` (3), and with 18 or
    /// 39 the fixes' errors (3, navigation axes) last.
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

    /// `Ĉ` as a matrix.
    fn c_nb(&self) -> Matrix3<f64> {
        self.nav
            .attitude
            .quaternion()
            .to_rotation_matrix()
            .into_inner()
    }

    /// Takes IMU sample `(t_s, gyro, accel)` (body, rad/s and specific force m/s²): the first
    /// sets the start time, each later one advances the mechanization over the interval with
    /// the trapezoid of the two samples, biases removed.
    ///
    /// # Errors
    /// Non-finite values, a time that does not increase, a position leaving the frame's domain.
    pub fn propagate(
        &mut self,
        t_s: f64,
        gyro_rad_s: [f64; 3],
        accel_m_s2: [f64; 3],
    ) -> Result<(), EskfError> {
        let index = self.intake.samples();
        let Some((dt, w, f)) = self
            .intake
            .take(self.nav.t_s, t_s, gyro_rad_s, accel_m_s2)?
        else {
            self.nav.t_s = t_s;
            return self
                .mechanization
                .reset(&self.nav)
                .map_err(|_| EskfError::NotFinite { index });
        };
        let (w, f) = self.errors.correct::<S>(w - self.bg, f - self.ba);
        let c0 = self.c_nb();
        self.nav = self
            .mechanization
            .step(t_s, (w * dt).into(), (f * dt).into())
            .map_err(|_| EskfError::NotFinite { index })?;
        let c = (c0 + self.c_nb()) * 0.5;
        if has_sensor_errors(S) {
            self.errors.accumulate(dt, &c, &w, &f);
        }
        if self.intake.accumulate(dt, &c, &f) {
            self.step_covariance();
        }
        Ok(())
    }

    /// One covariance step over the pending interval (nothing when none is pending), with the
    /// interval's mean `Ĉf̂` and `Ĉ` and the Earth's couplings at the current state:
    /// `Φ P Φᵀ = P + AP + (AP)ᵀ + A(AP)ᵀ` (P symmetric).
    fn step_covariance(&mut self) {
        let Some((dt, cf, c)) = self.intake.take_pending() else {
            return;
        };
        let earth = self.mechanization.earth();
        let coords = E::coordinates(&self.nav.position);
        let v = self.nav.velocity_m_s;
        let couplings = earth.couplings(&coords, &v).map(|k| {
            let t = earth.terms(&coords, &v);
            let (w_ie, w_en) = (
                *t.earth_rate_rad_s.as_nalgebra(),
                *t.transport_rate_rad_s.as_nalgebra(),
            );
            let m = |a: [[f64; 3]; 3]| Matrix3::from_fn(|i, j| a[i][j]);
            EarthCouplings {
                v_p: m(k.gravity_gradient),
                v_v: -skew(&(2.0 * w_ie + w_en)),
                phi_p: -m(k.rate_by_position),
                phi_v: -m(k.rate_by_velocity),
                phi_phi: -skew(&(w_ie + w_en)),
            }
        });
        let sensors = has_sensor_errors(S).then(|| {
            let (cda, cdg) = self.errors.take_pending(dt);
            (-cda, -cdg)
        });
        let f = Dynamics {
            v_phi: -skew(&cf),
            minus_c: -c,
            earth: couplings,
            sensors,
        };
        let a = Transition::new(&f, dt);
        let before = self.smoothing.is_some().then_some(self.cov);
        let ap = a.times(&self.cov);
        // G Q Gᵀ: velocity and attitude noise through Ĉ (isotropic: C q Cᵀ = q I), biases;
        // Q_d = ½ (Φ Q Φᵀ + Q) Δt.
        let qc = Cov::<S>::from_diagonal(&process_noise(&self.noise));
        let aq = a.times(&qc);
        let qd = (qc * 2.0 + aq + aq.transpose() + a.times(&aq.transpose())) * (0.5 * dt);
        self.cov += ap + ap.transpose() + a.times(&ap.transpose()) + qd;
        self.cov = (self.cov + self.cov.transpose()) * 0.5;
        let mut phi = before
            .is_some()
            .then(|| Cov::<S>::identity() + a.times(&Cov::<S>::identity()));
        if let Some(model) = &self.fix_error {
            let (decay, q) = model.step(dt);
            fix_errors::decay_covariance(&mut self.cov, phi.as_mut(), decay, &q);
            self.fix_error_m *= decay;
        }
        if let (Some(log), Some(before), Some(phi)) = (self.smoothing.as_mut(), before, phi) {
            log.step(&before, &phi, dt, &self.cov, self.nav.t_s);
        }
    }

    /// The Kalman correction shared by every update: the pending covariance step, innovation
    /// `y` with model `H` and measurement variances `r` (rows with `H = 0`, `y = 0`, `r = 1`
    /// are inert); NIS against `gate` (rejected and counted above it); Joseph-form covariance,
    /// symmetrised; closed-loop injection of `δx` into the nominal state, and reset.
    fn correct<const M: usize>(
        &mut self,
        h: &SMatrix<f64, M, S>,
        y: &SVector<f64, M>,
        r: &SVector<f64, M>,
        gate: Gate,
        index: usize,
    ) -> Result<UpdateOutcome, EskfError> {
        self.step_covariance();
        let prior = self.smoothing.is_some().then_some(self.cov);
        let (nis, dx) = kalman_update(&mut self.cov, h, y, r, gate, index)?;
        let Some(dx) = dx else {
            self.rejected += 1;
            return Ok(UpdateOutcome {
                nis,
                accepted: false,
            });
        };
        if let (Some(log), Some(prior)) = (self.smoothing.as_mut(), prior) {
            log.correction(self.nav.t_s, &prior, &dx, false);
        }
        self.inject(&dx, index)?;
        self.updates += 1;
        Ok(UpdateOutcome {
            nis,
            accepted: true,
        })
    }

    /// Closed loop: the error estimate into the nominal state (the position through
    /// [`EarthModel::offset`]), and the mechanization restarted from it (its coning and
    /// sculling memory kept).
    fn inject(&mut self, dx: &StateVec<S>, index: usize) -> Result<(), EskfError> {
        let corrected = corrected_state(self.mechanization.earth(), &self.state(), dx.as_slice());
        self.nav = corrected.nav;
        self.ba = Vector3::from(corrected.accel_bias_m_s2);
        self.bg = Vector3::from(corrected.gyro_bias_rad_s);
        if !self.errors.inject(dx) {
            return Err(EskfError::Diverged { index });
        }
        if has_fix_errors(S) {
            self.fix_error_m += dx.fixed_rows::<3>(fix_errors::first::<S>());
        }
        self.mechanization
            .reset(&self.nav)
            .map_err(|_| EskfError::Diverged { index })
    }
}

/// `state` with the error estimate `dx` (at least the 15 navigation and bias states) put into
/// it, as the filter's closed loop does: position through [`EarthModel::offset`], attitude by
/// the small rotation `φ` on the left, velocity and biases added. How a smoothed correction
/// ([`super::smoother`]) is applied to a filtered state.
#[must_use]
pub fn corrected_state<E: EarthModel>(earth: &E, state: &EskfState<E>, dx: &[f64]) -> EskfState<E> {
    let d = |k: usize| dx.get(k).copied().unwrap_or(0.0);
    let coords = E::coordinates(&state.nav.position);
    let position = E::position(earth.offset(&coords, &Vec3::new(d(0), d(1), d(2))));
    let phi = Vector3::new(d(6), d(7), d(8));
    let q = UnitQuaternion::from_scaled_axis(phi) * *state.nav.attitude.quaternion();
    EskfState {
        nav: NavState {
            t_s: state.nav.t_s,
            attitude: Rotation::assume_from_quaternion(q),
            velocity_m_s: Vec3::from_nalgebra(
                *state.nav.velocity_m_s.as_nalgebra() + Vector3::new(d(3), d(4), d(5)),
            ),
            position,
        },
        accel_bias_m_s2: core::array::from_fn(|k| state.accel_bias_m_s2[k] + d(9 + k)),
        gyro_bias_rad_s: core::array::from_fn(|k| state.gyro_bias_rad_s[k] + d(12 + k)),
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
