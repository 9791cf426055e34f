//! What the filter measures, one model per aid behind one trait, [`Measurement`], and one
//! update that takes any of them, [`Eskf::update`]: a GNSS fix ([`GnssFix`]), a body-frame
//! velocity ([`BodyVelocity`]: an odometer, the non-holonomic constraints, a zero-velocity
//! update), a height ([`Height`], a barometer), a zero angular rate ([`ZeroRate`]). Each model
//! gives the rows `H` of the error state it sees, the innovation `y` and the measurement
//! variances `r` at the filter's nominal state; rows with `H = 0`, `y = 0`, `r = 1` are inert,
//! so that a model of `M` rows can leave some out.
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use super::{Eskf, EskfError, UpdateOutcome, skew, sq};
use crate::earth::EarthModel;
use crate::frame::Body;
use crate::fusion::fix_errors::{self, has_fix_errors, has_sensor_errors};
use crate::fusion::gate::Gate;
use crate::fusion::sensor_errors::{ACCEL_MATRIX, GYRO_ERRORS, d_gyro, d_matrix};
use crate::nav_frame::NavFrame;
use crate::vector::Vec3;

/// A measurement model's rows at the nominal state: `H` (`M` × `S`), the innovation `y` and the
/// measurement variances `r`.
pub type ModelRows<const M: usize, const S: usize> =
    (SMatrix<f64, M, S>, SVector<f64, M>, SVector<f64, M>);

/// A measurement of `M` rows the filter on the Earth `E` takes through [`Eskf::update`]. The
/// models are the filter's own ([`GnssFix`], [`BodyVelocity`], [`Height`], [`ZeroRate`]): the
/// trait is sealed, since a model reads the filter's nominal state and sensor-error terms.
pub trait Measurement<E: EarthModel, const M: usize>: sealed::Sealed {
    /// `(H, y, r)` at the filter's nominal state: the model (`M` × `S`), the innovation and
    /// the measurement variances.
    ///
    /// # Errors
    /// A value that is not finite, a sigma that is not positive (named), no IMU sample yet.
    #[doc(hidden)]
    fn model<const S: usize>(
        &self,
        filter: &Eskf<E, S>,
        index: usize,
    ) -> Result<ModelRows<M, S>, EskfError>;
}

mod sealed {
    pub trait Sealed {}
    impl<E: crate::earth::EarthModel> Sealed for super::GnssFix<E> {}
    impl Sealed for super::BodyVelocity {}
    impl Sealed for super::Height {}
    impl Sealed for super::ZeroRate {}
}

impl<E: EarthModel, const S: usize> Eskf<E, S> {
    /// Takes `measurement`: the pending covariance step (which also decays the fixes' error
    /// estimate to now), the measurement's model at the nominal state, its normalised
    /// innovation squared against `gate` (a chi-square quantile for as many degrees of freedom
    /// as the measurement has rows, see [`crate::fusion::gate`], or [`Gate::Off`]; rejected
    /// and counted above it), then the Joseph-form correction, injected into the nominal
    /// state.
    ///
    /// # Errors
    /// Non-finite input, sigmas that are not positive, no IMU sample yet (a zero rate), or a
    /// covariance that can no longer be inverted (divergence).
    pub fn update<const M: usize>(
        &mut self,
        measurement: &impl Measurement<E, M>,
        gate: Gate,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        self.step_covariance();
        let (h, y, r) = measurement.model(self, index)?;
        self.correct(&h, &y, &r, gate, index)
    }
}

/// One GNSS fix, valid `age_s = τ` before the filter's time (latency compensation): the
/// antenna, at lever arm `l`, is predicted back with the current acceleration
/// `a = Ĉf̂ + g`, `p_a = p + Ĉl − τ (v + Ĉ(ω̂×l)) + ½τ² a` and `v_a = v + Ĉ(ω̂×l) − τ a`, so
/// `δp_a = δp − τ δv − [(Ĉl)×] φ` and
/// `δv_a = δv − [(Ĉ(ω̂×l))×] φ + τ [(Ĉf̂)×] φ + τ Ĉ δb_a + Ĉ [l×] δb_g` (the change of the
/// lever-arm terms over `τ` is neglected), the position innovation the Earth's
/// [`EarthModel::displacement_m`]. With the sensor errors the velocity rows also see them
/// through the lever arm (`Ĉ [l×] D_g δm_g`) and the latency (`τ Ĉ D_a δm_a`); with the fix
/// errors the position rows see the fix's error `b` (`H = I` on `δb`, its estimate taken off).
/// Six rows, the velocity's inert without a velocity.
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

impl<E: EarthModel> Measurement<E, 6> for GnssFix<E> {
    fn model<const S: usize>(
        &self,
        filter: &Eskf<E, S>,
        index: usize,
    ) -> Result<ModelRows<6, S>, EskfError> {
        let age_s = self.age_s;
        if !(age_s.is_finite() && age_s >= 0.0) {
            return Err(EskfError::NotFinite { index });
        }
        let (w_last, f_last) = filter.intake.last();
        let (w_body, f_body) = filter
            .errors
            .correct::<S>(w_last - filter.bg, f_last - filter.ba);
        let earth = filter.mechanization.earth();
        let coords = E::coordinates(&filter.nav.position);
        let delta_p = *earth
            .displacement_m(&coords, &E::coordinates(&self.position))
            .as_nalgebra();
        let g = *earth
            .terms(&coords, &filter.nav.velocity_m_s)
            .gravity_m_s2
            .as_nalgebra();
        let (c, v, l) = (
            filter.c_nb(),
            *filter.nav.velocity_m_s.as_nalgebra(),
            *self.lever_arm_m.as_nalgebra(),
        );
        let cl = c * l;
        let cwl = c * w_body.cross(&l);
        let cf = c * f_body;
        let accel = cf + g;
        let z_p =
            delta_p - (cl - (v + cwl) * age_s + accel * (0.5 * age_s * age_s)) - filter.fix_error_m;
        let mut finite = z_p.iter().all(|v| v.is_finite());
        let mut h = SMatrix::<f64, 6, S>::zeros();
        let mut y = SVector::<f64, 6>::zeros();
        let mut r = SVector::<f64, 6>::repeat(1.0);
        h.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&Matrix3::identity());
        h.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(Matrix3::identity() * -age_s));
        h.fixed_view_mut::<3, 3>(0, 6).copy_from(&(-skew(&cl)));
        if has_fix_errors(S) {
            h.fixed_view_mut::<3, 3>(0, fix_errors::first::<S>())
                .copy_from(&Matrix3::identity());
        }
        y.fixed_rows_mut::<3>(0).copy_from(&z_p);
        for i in 0..3 {
            r[i] = sq(self.position_sigma_m[i]);
        }
        if let Some(vm) = self.velocity_m_s {
            let z_v = *vm.as_nalgebra() - (v + cwl - accel * age_s);
            finite &= z_v.iter().all(|v| v.is_finite());
            h.fixed_view_mut::<3, 3>(3, 3)
                .copy_from(&Matrix3::identity());
            h.fixed_view_mut::<3, 3>(3, 6)
                .copy_from(&(-skew(&cwl) + skew(&cf) * age_s));
            h.fixed_view_mut::<3, 3>(3, 9).copy_from(&(c * age_s));
            h.fixed_view_mut::<3, 3>(3, 12).copy_from(&(c * skew(&l)));
            if has_sensor_errors(S) {
                h.fixed_view_mut::<3, 9>(3, ACCEL_MATRIX)
                    .copy_from(&(c * d_matrix(&f_body) * age_s));
                h.fixed_view_mut::<3, 12>(3, GYRO_ERRORS)
                    .copy_from(&(c * skew(&l) * d_gyro(&w_body, &f_body)));
            }
            y.fixed_rows_mut::<3>(3).copy_from(&z_v);
            for i in 0..3 {
                r[3 + i] = sq(self.velocity_sigma_m_s[i]);
            }
        }
        let all_sigma = self
            .position_sigma_m
            .iter()
            .chain(&self.velocity_sigma_m_s)
            .all(|s| s.is_finite() && *s > 0.0);
        if !(finite && all_sigma) {
            return Err(EskfError::NotFinite { index });
        }
        Ok((h, y, r))
    }
}

/// A body-frame velocity: `measured_m_s[i]`, when given, is the velocity of the reference
/// point along body axis `i` with one-sigma `sigma_m_s[i]` — a wheel odometer's forward speed
/// on x, and for a ground vehicle that neither slips sideways nor leaves the road the
/// non-holonomic constraints, 0 on the other two. With `v_b = Ĉᵀ v`,
/// `δv_b = Ĉᵀ δv + Ĉᵀ [v̂×] φ`. Three rows, those without a measurement inert.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyVelocity {
    /// The velocity along each body axis, m/s (`None`: not measured).
    pub measured_m_s: [Option<f64>; 3],
    /// Its one-sigma per axis, m/s (read only where measured).
    pub sigma_m_s: [f64; 3],
}

impl BodyVelocity {
    /// A wheel odometer's forward speed `speed_m_s` (body x) with one-sigma `sigma_m_s`, and
    /// with `constraint_sigma_m_s` the non-holonomic constraints at the same time (no lateral
    /// or vertical body velocity).
    #[must_use]
    pub fn odometer(speed_m_s: f64, sigma_m_s: f64, constraint_sigma_m_s: Option<f64>) -> Self {
        match constraint_sigma_m_s {
            Some(c) => Self {
                measured_m_s: [Some(speed_m_s), Some(0.0), Some(0.0)],
                sigma_m_s: [sigma_m_s, c, c],
            },
            None => Self {
                measured_m_s: [Some(speed_m_s), None, None],
                sigma_m_s: [sigma_m_s, 1.0, 1.0],
            },
        }
    }

    /// The non-holonomic constraints alone: no lateral or vertical body velocity, within
    /// `sigma_m_s`.
    #[must_use]
    pub fn nonholonomic(sigma_m_s: f64) -> Self {
        Self {
            measured_m_s: [None, Some(0.0), Some(0.0)],
            sigma_m_s: [1.0, sigma_m_s, sigma_m_s],
        }
    }

    /// A zero-velocity update (the vehicle, or the foot, stands still): every body axis's
    /// velocity 0 within `sigma_m_s`.
    #[must_use]
    pub fn zero(sigma_m_s: f64) -> Self {
        Self {
            measured_m_s: [Some(0.0); 3],
            sigma_m_s: [sigma_m_s; 3],
        }
    }

    /// How many axes are measured: the degrees of freedom of its gate.
    #[must_use]
    pub fn rows(&self) -> usize {
        self.measured_m_s.iter().flatten().count()
    }
}

impl<E: EarthModel> Measurement<E, 3> for BodyVelocity {
    fn model<const S: usize>(
        &self,
        filter: &Eskf<E, S>,
        index: usize,
    ) -> Result<ModelRows<3, S>, EskfError> {
        let v = *filter.nav.velocity_m_s.as_nalgebra();
        let ct = filter.c_nb().transpose();
        let predicted = ct * v;
        let h_phi = ct * skew(&v);
        let mut h = SMatrix::<f64, 3, S>::zeros();
        let mut y = SVector::<f64, 3>::zeros();
        let mut r = SVector::<f64, 3>::repeat(1.0);
        for i in 0..3 {
            let Some(z) = self.measured_m_s[i] else {
                continue;
            };
            let sigma = self.sigma_m_s[i];
            if !(z.is_finite() && sigma.is_finite() && sigma > 0.0) {
                return Err(EskfError::NotFinite { index });
            }
            h.fixed_view_mut::<1, 3>(i, 3).copy_from(&ct.row(i));
            h.fixed_view_mut::<1, 3>(i, 6).copy_from(&h_phi.row(i));
            y[i] = z - predicted[i];
            r[i] = sq(sigma);
        }
        Ok((h, y, r))
    }
}

/// A height (a barometer): `height_m` of the reference point above the Earth's reference
/// surface (the frame's up axis on the flat Earth, the ellipsoid on WGS-84), one-sigma
/// `sigma_m`. One row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Height {
    /// The height, m.
    pub height_m: f64,
    /// Its one-sigma, m.
    pub sigma_m: f64,
}

impl<E: EarthModel> Measurement<E, 1> for Height {
    fn model<const S: usize>(
        &self,
        filter: &Eskf<E, S>,
        index: usize,
    ) -> Result<ModelRows<1, S>, EskfError> {
        if !(self.height_m.is_finite() && self.sigma_m.is_finite() && self.sigma_m > 0.0) {
            return Err(EskfError::NotFinite { index });
        }
        let coords = E::coordinates(&filter.nav.position);
        let (height_now, _) = filter.mechanization.earth().height_m(&coords);
        let mut h = SMatrix::<f64, 1, S>::zeros();
        h[(0, 2)] = <E::Frame as NavFrame>::Z_UP;
        let y = SVector::<f64, 1>::new(self.height_m - height_now);
        Ok((h, y, SVector::<f64, 1>::new(sq(self.sigma_m))))
    }
}

/// A zero angular rate (the vehicle stands still): the last gyroscope sample reads the Earth's
/// rate in body axes, `Ĉᵀ ω_ie` (nothing on the flat Earth), plus `b_g` (and the
/// g-sensitivity's `k ∘ f`) and noise of one-sigma `sigma_rad_s` per axis (one sample's white
/// noise): `y = ω_m − b̂_g − ((I + M̂_g) ω + k̂ ∘ f̂)`, `H = I` on the gyroscope bias (and the
/// sensor errors' Jacobian `D_g` on `δm_g`). Three rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZeroRate {
    /// The gyroscope's one-sigma per sample and axis, rad/s.
    pub sigma_rad_s: f64,
}

impl ZeroRate {
    /// A zero rate at a stance that may roll: a walking foot rolls from heel to toe while it
    /// stands, so the rate `rate_rad_s` it reads there (the bias taken off) is not the bias's
    /// noise but a turn the foot makes. Its size bounds how far the true rate is from zero: the
    /// one-sigma is `√(σ² + |ω|²)` with `σ` one sample's white noise, as tight as a rest's where
    /// the foot is still, loose where it rolls. Told `σ` alone, the update takes the roll for a
    /// bias and turns the attitude away.
    #[must_use]
    pub fn rolling(sigma_rad_s: f64, rate_rad_s: [f64; 3]) -> Self {
        let rate_squared: f64 = rate_rad_s.iter().map(|x| x * x).sum();
        Self {
            sigma_rad_s: crate::math::sqrt(sigma_rad_s * sigma_rad_s + rate_squared),
        }
    }
}

impl<E: EarthModel> Measurement<E, 3> for ZeroRate {
    fn model<const S: usize>(
        &self,
        filter: &Eskf<E, S>,
        index: usize,
    ) -> Result<ModelRows<3, S>, EskfError> {
        let w_true = if E::ROTATING {
            let coords = E::coordinates(&filter.nav.position);
            let t = filter
                .mechanization
                .earth()
                .terms(&coords, &filter.nav.velocity_m_s);
            filter.c_nb().transpose() * t.earth_rate_rad_s.as_nalgebra()
        } else {
            Vector3::zeros()
        };
        let Some((w_m, f_m)) = filter.intake.last_sample() else {
            return Err(EskfError::NotFinite { index });
        };
        let (_, f) = filter
            .errors
            .correct::<S>(Vector3::zeros(), f_m - filter.ba);
        if !(self.sigma_rad_s.is_finite() && self.sigma_rad_s > 0.0) {
            return Err(EskfError::BadParameter {
                field: "zero-rate sigma",
            });
        }
        let mut h = SMatrix::<f64, 3, S>::zeros();
        h.fixed_view_mut::<3, 3>(0, 12)
            .copy_from(&Matrix3::identity());
        if has_sensor_errors(S) {
            h.fixed_view_mut::<3, 12>(0, GYRO_ERRORS)
                .copy_from(&d_gyro(&w_true, &f));
        }
        let y = w_m - filter.bg - filter.errors.gyro_reading(&w_true, &f);
        Ok((h, y, SVector::<f64, 3>::repeat(sq(self.sigma_rad_s))))
    }
}
