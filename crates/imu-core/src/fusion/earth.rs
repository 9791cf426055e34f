//! The error-state filter on the WGS-84 Earth: the same 15 error states as [`super::eskf`] —
//! position (local NED metres), velocity (NED), attitude (a small rotation φ of the NED frame,
//! `C_true = (I + [φ×]) Ĉ`), accelerometer and gyroscope biases (FRD body) — around the
//! Earth mechanization of [`crate::strapdown::earth`] (Earth rate, transport rate, Coriolis,
//! normal gravity; increments by the trapezoid of each interval's rate samples, coning and
//! sculling corrections).
//!
//! Error dynamics (Groves 2nd ed. §14.2.4, local-navigation frame, with the position error in
//! metres): `δṗ = δv`; `δv̇ = −[f^n×]φ − Ĉ δb_a − [(2ω_ie + ω_en)×] δv + δg`, the gravity
//! model's error `δg = (0, 0, 2γ/R δp_D)` (the vertical channel's instability); `φ̇ = −[ω_in×]φ − Ĉ δb_g − δω_in`, where
//! `δω_in = ∂ω_en/∂v δv + ∂ω_ie/∂φ δp_N/(R_N + h)` — the tilt a velocity error makes through the
//! transport rate closes the Schuler loop (`ω² = γ/R`, 84 minutes; tested against the closed
//! form). `Φ = I + FΔt + (FΔt)²/2` (dense),
//! `Q_d = ½(Φ Q Φᵀ + Q)Δt`. GNSS updates as the flat filter's, their position innovation in NED
//! metres: `((φ_m − φ̂)(R_N + h), (λ_m − λ̂)(R_E + h) cos φ, −(h_m − ĥ))`. Corrections are
//! injected into latitude, longitude and height through the same radii.
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::eskf::{
    Cov, EskfError, EskfNoise, InitialSigma, Intake, Linearisation, StateVec, UpdateOutcome,
    body_velocity_model, gnss_model, initial_covariance, kalman_update, process_noise,
    set_sensor_variances, skew, sq, zero_rate_model,
};
use super::sensor_errors::{
    ACCEL_MATRIX, BASE_STATES, FULL_STATES, GYRO_ERRORS, SensorErrorEstimate, SensorErrorSigma,
    SensorErrors,
};
use crate::earth::rates::{earth_rate_ned, transport_rate_ned};
use crate::earth::wgs84::OMEGA_IE_RAD_S;
use crate::earth::{Geodetic, GravityModel};
use crate::frame::{Body, Ned};
use crate::math;
use crate::rotation::Rotation;
use crate::strapdown::earth::{EarthIncrements, EarthNavState, EarthOptions, VerticalChannel};
use crate::vector::Vec3;

/// The Earth filter's estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthEskfState {
    /// Time, attitude `C_nb` (FRD body to local NED), NED velocity and geodetic position.
    pub nav: EarthNavState,
    /// Accelerometer bias, FRD body, m/s².
    pub accel_bias_m_s2: [f64; 3],
    /// Gyroscope bias, FRD body, rad/s.
    pub gyro_bias_rad_s: [f64; 3],
}

/// One GNSS fix on the Earth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthGnssFix {
    /// Antenna position.
    pub position: Geodetic,
    /// Antenna ground velocity, NED, m/s (`None`: position only).
    pub velocity_m_s: Option<Vec3<Ned>>,
    /// Antenna lever arm, FRD body, m.
    pub lever_arm_m: Vec3<Body>,
    /// Position one-sigma north, east, down, m.
    pub position_sigma_m: [f64; 3],
    /// Velocity one-sigma per axis, m/s.
    pub velocity_sigma_m_s: [f64; 3],
    /// How long before the filter's time the fix was valid, s (≥ 0).
    pub age_s: f64,
}

/// The error-state filter on the WGS-84 Earth, of `S` states as [`super::Eskf`]: 15 (the
/// default) or 36 with the sensors' scale-factor, misalignment and g-sensitivity errors.
#[derive(Clone, Copy, Debug)]
pub struct EarthEskf<const S: usize = BASE_STATES> {
    mechanization: EarthIncrements,
    nav: EarthNavState,
    ba: Vector3<f64>,
    bg: Vector3<f64>,
    errors: SensorErrors,
    cov: Cov<S>,
    noise: EskfNoise,
    gravity: GravityModel,
    intake: Intake,
    updates: usize,
    rejected: usize,
}

impl<const S: usize> EarthEskf<S> {
    /// A filter at `initial` (biases zero) with `sigma` initial uncertainty (position in
    /// metres on each NED axis), the IMU `noise` and `gravity`.
    ///
    /// # Errors
    /// Non-finite state, a latitude beyond ±89.9°, sigmas or noise that are negative or not
    /// finite.
    pub fn new(
        initial: &EarthNavState,
        sigma: &InitialSigma,
        noise: EskfNoise,
        gravity: GravityModel,
    ) -> Result<Self, EskfError> {
        let options = EarthOptions {
            gravity,
            vertical: VerticalChannel::Free,
            ..EarthOptions::default()
        };
        let mechanization = EarthIncrements::new(initial, options)
            .map_err(|_| EskfError::NotFinite { index: 0 })?;
        let cov = initial_covariance(sigma, &noise)?;
        Ok(Self {
            mechanization,
            nav: *initial,
            ba: Vector3::zeros(),
            bg: Vector3::zeros(),
            errors: SensorErrors::new(),
            cov,
            noise,
            gravity,
            intake: Intake::new(),
            updates: 0,
            rejected: 0,
        })
    }

    /// As [`super::Eskf::with_covariance_interval`].
    ///
    /// # Errors
    /// An interval that is negative or not finite.
    pub fn with_covariance_interval(mut self, interval_s: f64) -> Result<Self, EskfError> {
        self.intake.set_interval(interval_s)?;
        Ok(self)
    }

    /// As [`super::Eskf::with_sensor_error_sigma`].
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
    pub fn state(&self) -> EarthEskfState {
        EarthEskfState {
            nav: self.nav,
            accel_bias_m_s2: self.ba.into(),
            gyro_bias_rad_s: self.bg.into(),
        }
    }

    /// One-sigma of the error states: position north, east, down (m), velocity (NED),
    /// attitude (NED axes), accelerometer bias, gyroscope bias (FRD), and with 36 states the
    /// sensor errors.
    #[must_use]
    pub fn sigmas(&self) -> [f64; S] {
        core::array::from_fn(|i| math::sqrt(self.cov[(i, i)].max(0.0)))
    }

    /// The error covariance entry `(i, j)`.
    #[must_use]
    pub fn covariance(&self, i: usize, j: usize) -> f64 {
        self.cov[(i, j)]
    }

    /// Updates applied and rejected by the gate.
    #[must_use]
    pub fn update_counts(&self) -> (usize, usize) {
        (self.updates, self.rejected)
    }

    /// Takes IMU sample `(t_s, gyro, accel)` (FRD body, rad/s and specific force m/s²): the
    /// first sets the start, each later one advances the mechanization over the interval with
    /// the trapezoid of the two samples, biases removed.
    ///
    /// # Errors
    /// Non-finite values, a time that does not increase, a latitude beyond ±89.9°.
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
            return Ok(());
        };
        let (w, f) = self.errors.correct::<S>(w - self.bg, f - self.ba);
        let c0 = self
            .nav
            .attitude
            .quaternion()
            .to_rotation_matrix()
            .into_inner();
        self.nav = self
            .mechanization
            .step(t_s, (w * dt).into(), (f * dt).into(), 0.0)
            .map_err(|_| EskfError::NotFinite { index })?;
        let c1 = self
            .nav
            .attitude
            .quaternion()
            .to_rotation_matrix()
            .into_inner();
        let c = (c0 + c1) * 0.5;
        if S == FULL_STATES {
            self.errors.accumulate(dt, &c, &w, &f);
        }
        if self.intake.accumulate(dt, &c, &f) {
            self.step_covariance();
        }
        Ok(())
    }

    /// One covariance step over the pending interval with the dense transition of the Earth
    /// error dynamics at the current position and velocity.
    fn step_covariance(&mut self) {
        let Some((dt, f_n, c)) = self.intake.take_pending() else {
            return;
        };
        let p = &self.nav.position;
        let v = self.nav.velocity_m_s;
        let (r_n, r_e) = p.radii_m();
        let (rho_n, rho_e) = (r_n + p.height_m, r_e + p.height_m);
        let gamma = self.gravity.magnitude_m_s2(p);
        let r = math::sqrt(r_n * r_e) + p.height_m;
        let w_ie = *earth_rate_ned(p).as_nalgebra();
        let w_en = *transport_rate_ned(p, v).as_nalgebra();
        let (sin_l, cos_l) = (math::sin(p.latitude_rad), math::cos(p.latitude_rad));
        let tan_l = sin_l / cos_l;
        let mut f = Cov::<S>::zeros();
        f.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&Matrix3::identity());
        // The gravity model's error: vertical only (the horizontal Schuler feedback comes from
        // the tilt the transport rate's error makes, below; a horizontal gradient here as well
        // would double it).
        f[(5, 2)] = 2.0 * gamma / r;
        f.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(-skew(&(2.0 * w_ie + w_en))));
        f.fixed_view_mut::<3, 3>(3, 6).copy_from(&(-skew(&f_n)));
        f.fixed_view_mut::<3, 3>(3, 9).copy_from(&(-c));
        // −∂ω_ie/∂φ · δp_N/(R_N + h).
        f[(6, 0)] = OMEGA_IE_RAD_S * sin_l / rho_n;
        f[(8, 0)] = OMEGA_IE_RAD_S * cos_l / rho_n;
        // −∂ω_en/∂v.
        f[(6, 4)] = -1.0 / rho_e;
        f[(7, 3)] = 1.0 / rho_n;
        f[(8, 4)] = tan_l / rho_e;
        f.fixed_view_mut::<3, 3>(6, 6)
            .copy_from(&(-skew(&(w_ie + w_en))));
        f.fixed_view_mut::<3, 3>(6, 12).copy_from(&(-c));
        if S == FULL_STATES {
            let (cda, cdg) = self.errors.take_pending(dt);
            f.fixed_view_mut::<3, 9>(3, ACCEL_MATRIX).copy_from(&(-cda));
            f.fixed_view_mut::<3, 12>(6, GYRO_ERRORS).copy_from(&(-cdg));
        }
        let a = f * dt;
        let phi = Cov::<S>::identity() + a + a * a * 0.5;
        let qc = Cov::<S>::from_diagonal(&process_noise::<S>(&self.noise));
        let qd = (phi * qc * phi.transpose() + qc) * (0.5 * dt);
        self.cov = phi * self.cov * phi.transpose() + qd;
        self.cov = (self.cov + self.cov.transpose()) * 0.5;
    }

    /// A GNSS fix (see [`EarthGnssFix`]), gated with `gate` as the flat filter's.
    ///
    /// # Errors
    /// Non-finite input, sigmas that are not positive, an age that is negative, divergence.
    pub fn update_gnss(
        &mut self,
        fix: &EarthGnssFix,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        let p = &self.nav.position;
        let (r_n, r_e) = p.radii_m();
        let m = &fix.position;
        let (w_last, f_last) = self.intake.last();
        let (w_body, f_body) = self.errors.correct::<S>(w_last - self.bg, f_last - self.ba);
        let delta_p = Vector3::new(
            (m.latitude_rad - p.latitude_rad) * (r_n + p.height_m),
            wrap_pi(m.longitude_rad - p.longitude_rad)
                * (r_e + p.height_m)
                * math::cos(p.latitude_rad),
            -(m.height_m - p.height_m),
        );
        let lin = Linearisation {
            c: self
                .nav
                .attitude
                .quaternion()
                .to_rotation_matrix()
                .into_inner(),
            v: *self.nav.velocity_m_s.as_nalgebra(),
            w_body,
            f_body,
            g: Vector3::new(0.0, 0.0, self.gravity.magnitude_m_s2(p)),
        };
        let (h, y, r) = gnss_model(
            &lin,
            delta_p,
            fix.velocity_m_s.map(|v| *v.as_nalgebra()),
            *fix.lever_arm_m.as_nalgebra(),
            [fix.position_sigma_m, fix.velocity_sigma_m_s],
            fix.age_s,
            index,
        )?;
        self.correct(&h, &y, &r, gate, index)
    }

    /// Body-frame velocity (odometer forward speed, non-holonomic constraints), as
    /// [`super::Eskf::update_body_velocity`] (FRD body axes: x forward, y right, z down).
    ///
    /// # Errors
    /// As [`super::Eskf::update_body_velocity`].
    pub fn update_body_velocity(
        &mut self,
        measured_m_s: [Option<f64>; 3],
        sigma_m_s: [f64; 3],
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        let c = self
            .nav
            .attitude
            .quaternion()
            .to_rotation_matrix()
            .into_inner();
        let v = *self.nav.velocity_m_s.as_nalgebra();
        let (h, y, r) = body_velocity_model(&c, &v, measured_m_s, sigma_m_s, index)?;
        self.correct(&h, &y, &r, gate, index)
    }

    /// A height above the ellipsoid (a barometer on the Earth), one-sigma `sigma_m`: `δh = −δp_D`.
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
        let mut h = nalgebra::SMatrix::<f64, 1, S>::zeros();
        h[(0, 2)] = -1.0;
        let y = nalgebra::SVector::<f64, 1>::new(height_m - self.nav.position.height_m);
        let r = nalgebra::SVector::<f64, 1>::new(sq(sigma_m));
        self.correct(&h, &y, &r, gate, index)
    }

    /// A zero-angular-rate update (the vehicle stands still on the Earth): the last gyroscope
    /// sample reads the Earth rate in body axes, `Ĉᵀ ω_ie`, through the sensor errors, within
    /// one-sigma `sigma_rad_s` per axis (see [`super::Eskf::update_zero_rate`]).
    ///
    /// # Errors
    /// A sigma that is not positive, no sample taken yet, or divergence.
    pub fn update_zero_rate(
        &mut self,
        sigma_rad_s: f64,
        gate: f64,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        let c = self
            .nav
            .attitude
            .quaternion()
            .to_rotation_matrix()
            .into_inner();
        let w_ie_body = c.transpose() * *earth_rate_ned(&self.nav.position).as_nalgebra();
        let (h, y, r) = zero_rate_model(
            self.intake.last_sample(),
            &self.bg,
            &self.ba,
            &self.errors,
            &w_ie_body,
            sigma_rad_s,
            index,
        )?;
        self.correct(&h, &y, &r, gate, index)
    }

    /// The correction shared by the updates: pending covariance stepped, Kalman update, the
    /// closed-loop injection, counts.
    fn correct<const M: usize>(
        &mut self,
        h: &nalgebra::SMatrix<f64, M, S>,
        y: &nalgebra::SVector<f64, M>,
        r: &nalgebra::SVector<f64, M>,
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
        self.inject(&dx, index)?;
        self.updates += 1;
        Ok(UpdateOutcome {
            nis,
            accepted: true,
        })
    }

    /// Closed loop: the error estimate into the nominal state (position through the radii),
    /// and the mechanization restarted from it (its coning and sculling memory kept).
    fn inject(&mut self, dx: &StateVec<S>, index: usize) -> Result<(), EskfError> {
        let p = self.nav.position;
        let (r_n, r_e) = p.radii_m();
        let position = Geodetic {
            latitude_rad: p.latitude_rad + dx[0] / (r_n + p.height_m),
            longitude_rad: p.longitude_rad
                + dx[1] / ((r_e + p.height_m) * math::cos(p.latitude_rad)),
            height_m: p.height_m - dx[2],
        };
        let phi = Vector3::new(dx[6], dx[7], dx[8]);
        let q = UnitQuaternion::from_scaled_axis(phi) * *self.nav.attitude.quaternion();
        self.nav = EarthNavState {
            t_s: self.nav.t_s,
            attitude: Rotation::assume_from_quaternion(q),
            velocity_m_s: Vec3::from_nalgebra(
                *self.nav.velocity_m_s.as_nalgebra() + Vector3::new(dx[3], dx[4], dx[5]),
            ),
            position,
        };
        self.ba += Vector3::new(dx[9], dx[10], dx[11]);
        self.bg += Vector3::new(dx[12], dx[13], dx[14]);
        if !self.errors.inject(dx) {
            return Err(EskfError::Diverged { index });
        }
        self.mechanization
            .reset(&self.nav)
            .map_err(|_| EskfError::Diverged { index })
    }
}

/// An angle difference wrapped to (−π, π].
fn wrap_pi(a: f64) -> f64 {
    let two_pi = 2.0 * core::f64::consts::PI;
    let d = a - two_pi * math::round(a / two_pi);
    if d <= -core::f64::consts::PI {
        d + two_pi
    } else {
        d
    }
}
