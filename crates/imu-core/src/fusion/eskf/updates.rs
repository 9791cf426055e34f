//! The measurement updates: GNSS position and velocity (and the reset to a fix), body-frame
//! velocity (odometer, non-holonomic constraints, zero velocity), height, zero rate.
use crate::fusion::gate::Gate;
use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

use super::{
    Eskf, EskfError, GnssFix, Linearisation, StateVec, UpdateOutcome, body_velocity_model,
    gnss_model, sq, zero_rate_model,
};
use crate::earth::EarthModel;
use crate::fusion::fix_errors::{self, has_fix_errors};
use crate::math;
use crate::nav_frame::NavFrame;

impl<E: EarthModel, const S: usize> Eskf<E, S> {
    /// A GNSS position (and, when given, velocity) fix valid `fix.age_s = τ` before the
    /// filter's time (latency compensation): the antenna is predicted back with the current
    /// acceleration `a = Ĉf̂ + g`, `p_a = p + Ĉl − τ (v + Ĉ(ω̂×l)) + ½τ² a` and
    /// `v_a = v + Ĉ(ω̂×l) − τ a`, so `δp_a = δp − τ δv − [(Ĉl)×] φ` and
    /// `δv_a = δv − [(Ĉ(ω̂×l))×] φ + τ [(Ĉf̂)×] φ + τ Ĉ δb_a + Ĉ [l×] δb_g` (the change of the
    /// lever-arm terms over `τ` is neglected). Rejected (and counted) when its NIS exceeds
    /// `gate` (a chi-square quantile for 3 or 6 degrees of freedom, or [`Gate::Off`]).
    ///
    /// # Errors
    /// Non-finite input, sigmas that are not positive, an age that is negative or not finite,
    /// or a covariance that can no longer be inverted (divergence).
    pub fn update_gnss(
        &mut self,
        fix: &GnssFix<E>,
        gate: Gate,
    ) -> Result<UpdateOutcome, EskfError> {
        let index = self.updates + self.rejected;
        if !(fix.age_s.is_finite() && fix.age_s >= 0.0) {
            return Err(EskfError::NotFinite { index });
        }
        // The pending covariance step first: it also decays the fix-error estimate to now.
        self.step_covariance();
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
            &self.fix_error_m,
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
    /// the next reset. Tilt and sensor errors are kept with their covariance. With the fix
    /// errors ([`super::super::fix_errors`]) the position becomes the fix less its estimated
    /// error, and its error that error's plus the fix's white part (correlated with the rest as
    /// the fix error is). The reset is
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
            .copy_from(&(to_antenna - c * lever - self.fix_error_m));
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
        if has_fix_errors(S) {
            // The position is now the fix less its estimated error: its error is the fix
            // error's plus the fix's white part, `δp = δb + v`.
            let b = fix_errors::first::<S>();
            for k in 0..3 {
                let row = self.cov.row(b + k).into_owned();
                self.cov.row_mut(k).copy_from(&row);
                self.cov.column_mut(k).copy_from(&row.transpose());
            }
            for k in 0..3 {
                for j in 0..3 {
                    self.cov[(k, j)] = self.cov[(b + k, b + j)];
                }
                self.cov[(k, k)] += sq(fix.position_sigma_m[k]);
            }
        }
        let mut set = |k: usize, variance: f64| {
            self.cov.row_mut(k).fill(0.0);
            self.cov.column_mut(k).fill(0.0);
            self.cov[(k, k)] = variance;
        };
        if !has_fix_errors(S) {
            for k in 0..3 {
                set(k, fix.position_sigma_m[k] * fix.position_sigma_m[k]);
            }
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
        gate: Gate,
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
        gate: Gate,
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
        gate: Gate,
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
        gate: Gate,
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
        gate: Gate,
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
        gate: Gate,
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
}
