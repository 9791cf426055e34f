//! A loosely coupled error-state Kalman filter on any [`EarthModel`]: 15 error states —
//! position (metres of the navigation frame), velocity, attitude (a small rotation φ of the
//! navigation frame, `C_true = (I + [φ×]) Ĉ`), accelerometer bias, gyroscope bias — or 36 with
//! the sensors' scale-factor, misalignment and g-sensitivity errors of
//! [`super::sensor_errors`], around the strapdown of [`crate::strapdown::increments`]
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
use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

use crate::earth::EarthModel;
use crate::frame::{Body, NavFrame};
use crate::math;
use crate::rotation::Rotation;
use crate::strapdown::{Increments, NavState, StrapdownOptions};
use crate::vector::Vec3;

use super::sensor_errors::{
    ACCEL_MATRIX, BASE_STATES, FULL_STATES, GYRO_ERRORS, SensorErrorEstimate, SensorErrorSigma,
    SensorErrors, d_gyro, d_matrix,
};
use super::smoother::{EpochRecord, SmoothingLog};

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

/// One GNSS fix as the filter takes it (see [`Eskf::update_gnss`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssFix<E: EarthModel> {
    /// Antenna position.
    pub position: E::Position,
    /// Antenna velocity, navigation frame, m/s (`None`: position only).
    pub velocity_m_s: Option<Vec3<E::Frame>>,
    /// Antenna lever arm, body frame, m.
    pub lever_arm_m: Vec3<Body>,
    /// Position one-sigma per navigation axis, m.
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

/// A 3 × `C` block of the transition.
type Block<const C: usize> = SMatrix<f64, 3, C>;

/// The error dynamics `F` by its non-zero 3 × 3 blocks (the rows below the attitude are
/// zero): on every Earth `δṗ = δv` (the identity), `F_vφ = −[Ĉf̂×]` and
/// `F_v,ba = F_φ,bg = −Ĉ`; a curved Earth adds its couplings, a 36-state filter its sensor
/// errors.
struct Dynamics {
    /// `F_vφ = −[Ĉf̂×]`.
    v_phi: Matrix3<f64>,
    /// `−Ĉ`, both `F_v,ba` and `F_φ,bg`.
    minus_c: Matrix3<f64>,
    earth: Option<EarthCouplings>,
    /// `F_v,ma = −Ĉ D_a` (3 × 9) and `F_φ,mg = −Ĉ D_g` (3 × 12).
    sensors: Option<(Block<9>, Block<12>)>,
}

/// The blocks of `F` that a curved Earth adds.
struct EarthCouplings {
    /// `F_vp`, the gravity gradient.
    v_p: Matrix3<f64>,
    /// `F_vv = −[(2ω_ie + ω_en)×]`.
    v_v: Matrix3<f64>,
    /// `F_φp = −∂ω_in/∂p`.
    phi_p: Matrix3<f64>,
    /// `F_φv = −∂ω_en/∂v`.
    phi_v: Matrix3<f64>,
    /// `F_φφ = −[ω_in×]`.
    phi_phi: Matrix3<f64>,
}

/// `A = FΔt + (FΔt)²/2`, by its non-zero blocks (named row_column): those of every Earth,
/// those a curved Earth adds and the sensor errors' columns. `Φ = I + A`.
struct Transition {
    p_v: Matrix3<f64>,
    p_phi: Matrix3<f64>,
    p_ba: Matrix3<f64>,
    v_phi: Matrix3<f64>,
    v_ba: Matrix3<f64>,
    v_bg: Matrix3<f64>,
    phi_bg: Matrix3<f64>,
    earth: Option<EarthTransition>,
    sensors: Option<SensorTransition>,
}

/// The blocks of `A` that are zero on the flat Earth.
struct EarthTransition {
    p_p: Matrix3<f64>,
    v_p: Matrix3<f64>,
    v_v: Matrix3<f64>,
    phi_p: Matrix3<f64>,
    phi_v: Matrix3<f64>,
    phi_phi: Matrix3<f64>,
    phi_ba: Matrix3<f64>,
}

/// The sensor errors' columns of `A` (36 states).
struct SensorTransition {
    p_ma: Block<9>,
    v_ma: Block<9>,
    /// Zero on the flat Earth.
    phi_ma: Option<Block<9>>,
    v_mg: Block<12>,
    phi_mg: Block<12>,
}

/// `x`, plus `y` when there is one.
#[inline(always)]
fn plus<T: core::ops::Add<Output = T>>(x: T, y: Option<T>) -> T {
    match y {
        Some(y) => x + y,
        None => x,
    }
}

impl Transition {
    /// `A_ij = F_ij Δt + (Σ_k F_ik F_kj) Δt²/2`, each sum over the present products in the
    /// order of `k` (δp, δv, φ; F's first block row is the identity at δv, so its products
    /// are taken without multiplying).
    #[inline(always)]
    fn new(f: &Dynamics, dt: f64) -> Self {
        let h = 0.5 * dt * dt;
        let (x, mc) = (&f.v_phi, &f.minus_c);
        let e = f.earth.as_ref();
        Self {
            p_v: plus(Matrix3::identity() * dt, e.map(|e| e.v_v * h)),
            p_phi: x * h,
            p_ba: mc * h,
            v_phi: plus(x * dt, e.map(|e| (e.v_v * x + x * e.phi_phi) * h)),
            v_ba: plus(mc * dt, e.map(|e| (e.v_v * mc) * h)),
            v_bg: (x * mc) * h,
            phi_bg: plus(mc * dt, e.map(|e| (e.phi_phi * mc) * h)),
            earth: e.map(|e| EarthTransition {
                p_p: e.v_p * h,
                v_p: e.v_p * dt + (e.v_v * e.v_p + x * e.phi_p) * h,
                v_v: e.v_v * dt + (e.v_p + e.v_v * e.v_v + x * e.phi_v) * h,
                phi_p: e.phi_p * dt + (e.phi_v * e.v_p + e.phi_phi * e.phi_p) * h,
                phi_v: e.phi_v * dt + (e.phi_p + e.phi_v * e.v_v + e.phi_phi * e.phi_v) * h,
                phi_phi: e.phi_phi * dt + (e.phi_v * x + e.phi_phi * e.phi_phi) * h,
                phi_ba: (e.phi_v * mc) * h,
            }),
            sensors: f.sensors.as_ref().map(|(va, pg)| SensorTransition {
                p_ma: va * h,
                v_ma: plus(va * dt, e.map(|e| (e.v_v * va) * h)),
                phi_ma: e.map(|e| (e.phi_v * va) * h),
                v_mg: (x * pg) * h,
                phi_mg: plus(pg * dt, e.map(|e| (e.phi_phi * pg) * h)),
            }),
        }
    }

    /// `A · m` (rows below the attitude zero), each block row the sum of its blocks'
    /// products in column order, formed apart and copied in (built in the product itself,
    /// every call also paid a copy of the whole matrix).
    fn times<const S: usize>(&self, m: &Cov<S>) -> Cov<S> {
        let row = |k: usize| m.fixed_view::<3, S>(3 * k, 0);
        let accel = || m.fixed_view::<9, S>(ACCEL_MATRIX, 0);
        let gyro = || m.fixed_view::<12, S>(GYRO_ERRORS, 0);
        let (e, s) = (self.earth.as_ref(), self.sensors.as_ref());
        // Each row starts from its first present term (no zero added), then the rest in
        // column order.
        let (mut r0, mut r1, mut r2) = match e {
            Some(e) => (
                e.p_p * row(0) + self.p_v * row(1),
                e.v_p * row(0) + e.v_v * row(1) + self.v_phi * row(2),
                e.phi_p * row(0)
                    + e.phi_v * row(1)
                    + e.phi_phi * row(2)
                    + e.phi_ba * row(3)
                    + self.phi_bg * row(4),
            ),
            None => (self.p_v * row(1), self.v_phi * row(2), self.phi_bg * row(4)),
        };
        r0 += self.p_phi * row(2);
        r0 += self.p_ba * row(3);
        r1 += self.v_ba * row(3);
        r1 += self.v_bg * row(4);
        if let Some(s) = s {
            r0 += s.p_ma * accel();
            r1 += s.v_ma * accel();
            r1 += s.v_mg * gyro();
            if let Some(phi_ma) = &s.phi_ma {
                r2 += phi_ma * accel();
            }
            r2 += s.phi_mg * gyro();
        }
        let mut out = Cov::<S>::zeros();
        out.fixed_view_mut::<3, S>(0, 0).copy_from(&r0);
        out.fixed_view_mut::<3, S>(3, 0).copy_from(&r1);
        out.fixed_view_mut::<3, S>(6, 0).copy_from(&r2);
        out
    }
}

/// The error-state filter of `S` states on the Earth `E`: [`BASE_STATES`] (15, the default) or
/// [`FULL_STATES`] (36, with the sensors' scale-factor, misalignment and g-sensitivity errors,
/// see [`super::sensor_errors`]); any other `S` does not compile.
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
    /// attitude (3, navigation axes), accelerometer bias (3), gyroscope bias (3), and with 36
    /// states the sensor errors `M_a`, `M_g` (9 each, row-major) and `k` (3).
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
        if S == FULL_STATES {
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
        let sensors = (S == FULL_STATES).then(|| {
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
        if let (Some(log), Some(before)) = (self.smoothing.as_mut(), before) {
            let phi = Cov::<S>::identity() + a.times(&Cov::<S>::identity());
            log.step(&before, &phi, dt, &self.cov, self.nav.t_s);
        }
    }

    /// A GNSS position (and, when given, velocity) fix valid `fix.age_s = τ` before the
    /// filter's time (latency compensation): the antenna is predicted back with the current
    /// acceleration `a = Ĉf̂ + g`, `p_a = p + Ĉl − τ (v + Ĉ(ω̂×l)) + ½τ² a` and
    /// `v_a = v + Ĉ(ω̂×l) − τ a`, so `δp_a = δp − τ δv − [(Ĉl)×] φ` and
    /// `δv_a = δv − [(Ĉ(ω̂×l))×] φ + τ [(Ĉf̂)×] φ + τ Ĉ δb_a + Ĉ [l×] δb_g` (the change of the
    /// lever-arm terms over `τ` is neglected). Rejected (and counted) when its NIS exceeds
    /// `gate` (a chi-square quantile for 3 or 6 degrees of freedom; `f64::INFINITY` turns the
    /// gate off).
    ///
    /// # Errors
    /// Non-finite input, sigmas that are not positive, an age that is negative or not finite,
    /// or a covariance that can no longer be inverted (divergence).
    pub fn update_gnss(&mut self, fix: &GnssFix<E>, gate: f64) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        if !(fix.age_s.is_finite() && fix.age_s >= 0.0) {
            return Err(EskfError::NotFinite { index });
        }
        let (w_last, f_last) = self.intake.last();
        let (w_body, f_body) = self.errors.correct::<S>(w_last - self.bg, f_last - self.ba);
        let earth = self.mechanization.earth();
        let coords = E::coordinates(&self.nav.position);
        let delta_p = earth.displacement_m(&coords, &E::coordinates(&fix.position));
        let lin = Linearisation {
            c: self.c_nb(),
            v: *self.nav.velocity_m_s.as_nalgebra(),
            w_body,
            f_body,
            g: *earth
                .terms(&coords, &self.nav.velocity_m_s)
                .gravity_m_s2
                .as_nalgebra(),
        };
        let (h, y, r) = gnss_model(
            &lin,
            *delta_p.as_nalgebra(),
            fix.velocity_m_s.map(|v| *v.as_nalgebra()),
            *fix.lever_arm_m.as_nalgebra(),
            [fix.position_sigma_m, fix.velocity_sigma_m_s],
            fix.age_s,
            index,
        )?;
        self.correct(&h, &y, &r, gate, index)
    }

    /// Resets the filter to `fix` when it has lost the fixes (they were rejected one after
    /// another), as production filters do instead of giving up: the nominal position of the
    /// reference point — and its velocity, when the fix has one — become the fix's (the lever
    /// arm taken off with the attitude after the reset), and their error covariance the fix's
    /// variances, uncorrelated with every other state. With `heading_sigma_rad` the heading too
    /// turns, so that the body's forward axis points along the fix's horizontal velocity (a
    /// vehicle moving nose first), its error variance that sigma squared. The biases return to
    /// their initial uncertainty, uncorrelated (at least; a larger one is kept): fixes rejected
    /// one after another say the filter was sure of something wrong, and a bias it was sure of
    /// is the likeliest — kept, a wrong gyroscope bias turns the heading away again and brings
    /// the next reset. Tilt and sensor errors are kept with their covariance. The reset is
    /// neither an update nor a rejection in [`Self::update_counts`].
    ///
    /// # Errors
    /// Non-finite input, sigmas that are not positive and finite, a heading asked for without a
    /// horizontal velocity, or a state the mechanization refuses.
    pub fn reset_to_gnss(
        &mut self,
        fix: &GnssFix<E>,
        heading_sigma_rad: Option<f64>,
    ) -> Result<(), EskfError> {
        let index = self.updates + self.rejected;
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let sigmas_ok = fix.position_sigma_m.iter().all(|&x| positive(x))
            && (fix.velocity_m_s.is_none() || fix.velocity_sigma_m_s.iter().all(|&x| positive(x)))
            && heading_sigma_rad.is_none_or(positive);
        if !sigmas_ok {
            return Err(EskfError::BadParameter {
                field: "reset sigma",
            });
        }
        self.step_covariance();
        let mut dx = StateVec::<S>::zeros();
        let mut c = self.c_nb();
        if heading_sigma_rad.is_some() {
            // The turn about the frame's z axis that takes the body's forward axis, seen from
            // above, onto the horizontal velocity (the same formula in ENU and NED); the lever
            // arm below is turned with it.
            let v = fix
                .velocity_m_s
                .map(|v| *v.as_nalgebra())
                .filter(|v| v.x * v.x + v.y * v.y > 0.0)
                .ok_or(EskfError::BadParameter {
                    field: "reset heading",
                })?;
            let b = c * Vector3::x();
            let turn = math::atan2(b.x * v.y - b.y * v.x, b.x * v.x + b.y * v.y);
            dx[8] = turn;
            c = UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, turn))
                .to_rotation_matrix()
                .into_inner()
                * c;
        }
        let lever = *fix.lever_arm_m.as_nalgebra();
        let earth = self.mechanization.earth();
        let coords = E::coordinates(&self.nav.position);
        let to_antenna = *earth
            .displacement_m(&coords, &E::coordinates(&fix.position))
            .as_nalgebra();
        dx.fixed_rows_mut::<3>(0)
            .copy_from(&(to_antenna - c * lever));
        if let Some(v) = fix.velocity_m_s {
            let (w_last, f_last) = self.intake.last();
            let (w_body, _) = self.errors.correct::<S>(w_last - self.bg, f_last - self.ba);
            let reference = *v.as_nalgebra() - c * w_body.cross(&lever);
            dx.fixed_rows_mut::<3>(3)
                .copy_from(&(reference - *self.nav.velocity_m_s.as_nalgebra()));
        }
        if !dx.iter().all(|x| x.is_finite()) {
            return Err(EskfError::NotFinite { index });
        }
        let (t, prior) = (self.nav.t_s, self.cov);
        if let Some(log) = self.smoothing.as_mut() {
            log.correction(t, &prior, &dx, true);
        }
        self.inject(&dx, index)?;
        let bias_variance: [f64; 6] =
            core::array::from_fn(|k| self.cov[(9 + k, 9 + k)].max(self.initial_bias_variance[k]));
        let mut set = |k: usize, variance: f64| {
            self.cov.row_mut(k).fill(0.0);
            self.cov.column_mut(k).fill(0.0);
            self.cov[(k, k)] = variance;
        };
        for k in 0..3 {
            set(k, fix.position_sigma_m[k] * fix.position_sigma_m[k]);
        }
        if fix.velocity_m_s.is_some() {
            for k in 0..3 {
                set(3 + k, fix.velocity_sigma_m_s[k] * fix.velocity_sigma_m_s[k]);
            }
        }
        if let Some(h) = heading_sigma_rad {
            set(8, h * h);
        }
        for (k, variance) in bias_variance.into_iter().enumerate() {
            set(9 + k, variance);
        }
        Ok(())
    }

    /// A body-frame velocity measurement: `measured_m_s[i]`, when given, is the velocity of the
    /// reference point along body axis `i` with one-sigma `sigma_m_s[i]` — a wheel odometer's
    /// forward speed on x, and for a ground vehicle that neither slips sideways nor leaves the
    /// road the non-holonomic constraints, 0 on the other two. With `v_b = Ĉᵀ v`,
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
        let v = *self.nav.velocity_m_s.as_nalgebra();
        let (h, y, r) = body_velocity_model(&self.c_nb(), &v, measured_m_s, sigma_m_s, index)?;
        self.correct(&h, &y, &r, gate, index)
    }

    /// A wheel odometer's forward speed `speed_m_s` (body x) with one-sigma `sigma_m_s`, and
    /// with `constraint_sigma_m_s` the non-holonomic constraints at the same time (no lateral
    /// or vertical body velocity): [`Self::update_body_velocity`] with one or three rows.
    ///
    /// # Errors
    /// As [`Self::update_body_velocity`].
    pub fn update_odometer(
        &mut self,
        speed_m_s: f64,
        sigma_m_s: f64,
        constraint_sigma_m_s: Option<f64>,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        match constraint_sigma_m_s {
            Some(c) => self.update_body_velocity(
                [Some(speed_m_s), Some(0.0), Some(0.0)],
                [sigma_m_s, c, c],
                gate,
            ),
            None => self.update_body_velocity(
                [Some(speed_m_s), None, None],
                [sigma_m_s, 1.0, 1.0],
                gate,
            ),
        }
    }

    /// The non-holonomic constraints alone: no lateral or vertical body velocity, within
    /// `sigma_m_s` (two rows).
    ///
    /// # Errors
    /// As [`Self::update_body_velocity`].
    pub fn update_nonholonomic(
        &mut self,
        sigma_m_s: f64,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        self.update_body_velocity(
            [None, Some(0.0), Some(0.0)],
            [1.0, sigma_m_s, sigma_m_s],
            gate,
        )
    }

    /// A zero-velocity update (the vehicle, or the foot, stands still): every body axis's
    /// velocity 0 within `sigma_m_s` (three rows).
    ///
    /// # Errors
    /// As [`Self::update_body_velocity`].
    pub fn update_zero_velocity(
        &mut self,
        sigma_m_s: f64,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        self.update_body_velocity([Some(0.0); 3], [sigma_m_s; 3], gate)
    }

    /// A height measurement (a barometer): `height_m` of the reference point above the Earth's
    /// reference surface (the frame's up axis on the flat Earth, the ellipsoid on WGS-84),
    /// one-sigma `sigma_m`. Gated with `gate` (one degree of freedom).
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
        let coords = E::coordinates(&self.nav.position);
        let (height_now, _) = self.mechanization.earth().height_m(&coords);
        let mut h = SMatrix::<f64, 1, S>::zeros();
        h[(0, 2)] = <E::Frame as NavFrame>::Z_UP;
        let y = SVector::<f64, 1>::new(height_m - height_now);
        let r = SVector::<f64, 1>::new(sq(sigma_m));
        self.correct(&h, &y, &r, gate, index)
    }

    /// A zero-angular-rate update (the vehicle stands still): the last gyroscope sample reads
    /// the Earth's rate in body axes, `Ĉᵀ ω_ie` (nothing on the flat Earth), plus `b_g` (and the
    /// g-sensitivity's `k ∘ f`) and noise of one-sigma `sigma_rad_s` per axis (one sample's
    /// white noise): `y = ω_m − b̂_g − ((I + M̂_g) ω + k̂ ∘ f̂)`, `H = I` on the gyroscope bias
    /// (and the sensor errors' Jacobian). Gated with `gate` (three degrees of freedom).
    ///
    /// # Errors
    /// A sigma that is not positive, no sample taken yet, or divergence.
    pub fn update_zero_rate(
        &mut self,
        sigma_rad_s: f64,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        let w_true = if E::ROTATING {
            let coords = E::coordinates(&self.nav.position);
            let t = self
                .mechanization
                .earth()
                .terms(&coords, &self.nav.velocity_m_s);
            self.c_nb().transpose() * t.earth_rate_rad_s.as_nalgebra()
        } else {
            Vector3::zeros()
        };
        let (h, y, r) = zero_rate_model(
            self.intake.last_sample(),
            &self.bg,
            &self.ba,
            &self.errors,
            &w_true,
            sigma_rad_s,
            index,
        )?;
        self.correct(&h, &y, &r, gate, index)
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
        gate: f64,
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
/// arm `l`, the fix valid `age_s` earlier (see [`Eskf::update_gnss`]); `sigmas` are the
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
