//! The measurement models and the covariance pieces every filter shares: the initial
//! covariance, the process noise, each aid's linearisation, and the Kalman update.
use nalgebra::{SMatrix, SVector, Vector3};

use super::{Cov, EskfError, EskfNoise, InitialSigma, StateVec, non_negative, skew, sq};
use crate::fusion::fix_errors::{self, has_fix_errors, has_sensor_errors, is_state_count};
use crate::fusion::gate::Gate;
use crate::fusion::sensor_errors::{
    ACCEL_MATRIX, GYRO_ERRORS, SensorErrorSigma, SensorErrors, d_gyro, d_matrix,
};

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
    if has_sensor_errors(S) {
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
/// (`Ĉ [l×] D_g δm_g`) and the latency (`τ Ĉ D_a δm_a`); with the fix errors the position
/// rows see the fix's error `b` (`H = I` on `δb`, the estimate `fix_error_m` taken off).
#[allow(clippy::too_many_arguments)]
pub(crate) fn gnss_model<const S: usize>(
    lin: &Linearisation,
    delta_p: Vector3<f64>,
    fix_error_m: &Vector3<f64>,
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
    let z_p = delta_p - (cl - (lin.v + cwl) * age_s + accel * (0.5 * age_s * age_s)) - fix_error_m;
    let mut finite = z_p.iter().all(|v| v.is_finite());
    let mut h = SMatrix::<f64, 6, S>::zeros();
    let mut y = SVector::<f64, 6>::zeros();
    let mut r = SVector::<f64, 6>::repeat(1.0);
    h.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&nalgebra::Matrix3::identity());
    h.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(nalgebra::Matrix3::identity() * -age_s));
    h.fixed_view_mut::<3, 3>(0, 6).copy_from(&(-skew(&cl)));
    if has_fix_errors(S) {
        h.fixed_view_mut::<3, 3>(0, fix_errors::first::<S>())
            .copy_from(&nalgebra::Matrix3::identity());
    }
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
        if has_sensor_errors(S) {
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
