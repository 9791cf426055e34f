//! The reset to a GNSS fix, which a filter that has lost its fixes takes instead of giving up.
use nalgebra::{UnitQuaternion, Vector3};

use super::{Eskf, EskfError, GnssFix, StateVec, sq};
use crate::earth::EarthModel;
use crate::fusion::fix_errors::{self, has_fix_errors};
use crate::math;

impl<E: EarthModel, const S: usize> Eskf<E, S> {
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
}
