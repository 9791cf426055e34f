//! The covariance pieces of the filter: the initial covariance, the process noise and the
//! Kalman update every measurement goes through.
use nalgebra::{SMatrix, SVector};

use super::{Cov, EskfError, EskfNoise, InitialSigma, StateVec, non_negative, sq};
use crate::fusion::fix_errors::{has_sensor_errors, is_state_count};
use crate::fusion::gate::Gate;
use crate::fusion::sensor_errors::{ACCEL_MATRIX, SensorErrorSigma};

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
            is_state_count(S),
            "the filters have 15, 18, 36 or 39 error states"
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

/// Sets the initial variances of the sensor errors in `cov` (36 or 39 states).
///
/// # Errors
/// A covariance without the sensor errors, or a sigma that is negative or not finite.
pub(crate) fn set_sensor_variances<const S: usize>(
    cov: &mut Cov<S>,
    sigma: &SensorErrorSigma,
) -> Result<(), EskfError> {
    if !has_sensor_errors(S) {
        return Err(EskfError::BadParameter {
            field: "sensor error sigma (only a filter of 36 or 39 states has the sensor errors)",
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
    gate: Gate,
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
    if gate.rejects(nis) {
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
