//! The gyroscope from the rotations between rests (Tedaldi et al.): the bias is the mean
//! reading at rest; the matrix `A` (scale and misalignment, full, into the accelerometer's
//! calibrated frame) is the one whose rate `A(y − b)`, integrated over each rotation, turns the
//! gravity direction measured at one rest into the one measured at the next: residuals
//! `u_{k+1} − R_kᵀ u_k`, `R_k` the attitude change over the rotation. The attitude is
//! integrated by the classical Runge–Kutta scheme on `q̇ = ½ q ⊗ ω`, the rate mid-interval from
//! the cubic through four samples, so the integration's own error (fourth order) stays below a
//! navigation-grade accelerometer's noise. Rotations about the vertical alone do not move
//! gravity and teach nothing: the procedure must tilt the part.
use nalgebra::{Matrix3, Quaternion, SMatrix, SVector, UnitQuaternion, Vector3};

use super::accelerometer::{AccelCalibration, Influence};
use super::solve::{Normal, least_squares};
use super::{CalibrationError, Correction, Rest};
use crate::math;
use crate::stillness::ReadingNoise;

/// Rotations (rests less one) the fit needs at least: nine unknowns, two equations each.
pub const MIN_ROTATIONS: usize = 5;

/// The gyroscope's calibration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroCalibration {
    /// `ω = A(y − b)`, rad/s, in the accelerometer's calibrated frame.
    pub correction: Correction,
    /// Standard deviation of each entry of `A`.
    pub matrix_sigma: [[f64; 3]; 3],
    /// Standard deviation of `b`, rad/s: the scatter of the rests' means over their number, and
    /// the bias's wander over the procedure (that scatter beyond the white noise).
    pub bias_sigma: [f64; 3],
    /// RMS of the gravity direction's residual components after the rotations, rad.
    pub residual_rms_rad: f64,
    /// The rotations fitted.
    pub rotations: usize,
}

/// What the gyroscope's fit takes: its readings and the accelerometer's calibration of the
/// same procedure.
#[derive(Clone, Copy, Debug)]
pub struct GyroInputs<'a> {
    /// Sample times, s.
    pub t_s: &'a [f64],
    /// Gyroscope readings, rad/s.
    pub gyro: &'a [[f64; 3]],
    /// The rests, in order.
    pub rests: &'a [Rest],
    /// The accelerometer's mean reading at each rest, m/s².
    pub accel_means: &'a [[f64; 3]],
    /// The accelerometer's calibration from those means.
    pub accel: &'a AccelCalibration,
    /// White noise of one reading, accelerometer (m/s²) and gyroscope (rad/s).
    pub noise: ReadingNoise,
}

/// Calibrates the gyroscope (see the module documentation). The uncertainty carries every
/// source the fit sees: the rests' accelerometer noise through the gravity directions and
/// through the accelerometer's own terms, the gyroscope's white noise integrated over each
/// rotation and the bias's uncertainty; it is never less than the residuals' own scatter
/// says.
///
/// # Errors
/// Fewer than [`MIN_ROTATIONS`] rotations, rests outside the readings, or rotations that do not
/// determine the terms.
pub fn calibrate(inputs: &GyroInputs<'_>) -> Result<GyroCalibration, CalibrationError> {
    let GyroInputs {
        t_s,
        gyro,
        rests,
        accel_means,
        ..
    } = *inputs;
    let n = t_s.len().min(gyro.len());
    if rests.len() != accel_means.len() || rests.iter().any(|r| r.is_empty() || r.end > n) {
        return Err(CalibrationError::Degenerate(
            "the rests and their gravity readings do not match the readings",
        ));
    }
    if rests.len() < MIN_ROTATIONS + 1 {
        return Err(CalibrationError::TooFewRests {
            found: rests.len(),
            needed: MIN_ROTATIONS + 1,
        });
    }
    let unit = |v: Vector3<f64>| {
        let n = v.norm();
        (n > 0.0 && n.is_finite()).then(|| v / n)
    };
    let calibrated = |k: usize| Vector3::from(inputs.accel.correction.apply(accel_means[k]));
    if (0..rests.len()).any(|k| unit(calibrated(k)).is_none()) {
        return Err(CalibrationError::Degenerate("a rest reads no gravity"));
    }
    let bias = rest_bias(gyro, rests, inputs.noise.gyro);
    let fit = Fit {
        inputs,
        bias: bias.0,
    };
    let start = SVector::<f64, 9>::from_row_slice(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    let solution = least_squares(start, |p, normal: &mut Normal<9>| {
        for k in 0..rests.len() - 1 {
            let Some((r, jac)) = fit.residual_and_jacobian(p, k) else {
                return false;
            };
            for c in 0..3 {
                normal.add(r[c], &jac.row(c).transpose());
            }
        }
        true
    })
    .ok_or(CalibrationError::Degenerate(
        "the rotations cannot be integrated",
    ))?;
    let inverse = solution
        .normal
        .jtj
        .try_inverse()
        .ok_or(CalibrationError::Degenerate(
            "the rotations do not turn the part about enough axes",
        ))?;
    let propagated = fit
        .propagated(&solution.params, &inverse, &bias.1)
        .ok_or(CalibrationError::Degenerate("the fit did not converge"))?;
    let scatter = solution.covariance().unwrap_or(SMatrix::zeros());
    let sigma = SVector::<f64, 9>::from_fn(|i, _| {
        math::sqrt(propagated[(i, i)].max(scatter[(i, i)]).max(0.0))
    });
    if solution
        .params
        .iter()
        .chain(sigma.iter())
        .any(|v| !v.is_finite())
    {
        return Err(CalibrationError::Degenerate("the fit did not converge"));
    }
    let a = Matrix3::from_row_slice(solution.params.as_slice());
    Ok(GyroCalibration {
        correction: Correction::of(&a, &bias.0),
        matrix_sigma: core::array::from_fn(|i| core::array::from_fn(|j| sigma[3 * i + j])),
        bias_sigma: bias.1.into(),
        residual_rms_rad: math::sqrt(solution.normal.cost / solution.normal.count as f64),
        rotations: rests.len() - 1,
    })
}

/// The fit's model: rotation `k`'s residual and its derivatives.
struct Fit<'a, 'b> {
    inputs: &'b GyroInputs<'a>,
    bias: Vector3<f64>,
}

/// Forward-difference step of the numerical derivatives (the terms are of order 1).
const H: f64 = 1e-7;

impl Fit<'_, '_> {
    fn direction(&self, k: usize) -> Vector3<f64> {
        let u = Vector3::from(
            self.inputs
                .accel
                .correction
                .apply(self.inputs.accel_means[k]),
        );
        u / u.norm()
    }

    /// The attitude change over rotation `k` under terms `p` and bias `b`.
    fn turn(&self, p: &SVector<f64, 9>, b: &Vector3<f64>, k: usize) -> UnitQuaternion<f64> {
        let i = self.inputs;
        let a = Matrix3::from_row_slice(p.as_slice());
        attitude_change(
            i.t_s,
            i.gyro,
            &a,
            b,
            i.rests[k].end - 1,
            i.rests[k + 1].start,
        )
    }

    /// `u_{k+1} − R_kᵀ u_k` under `p` and `b`.
    fn residual(&self, p: &SVector<f64, 9>, b: &Vector3<f64>, k: usize) -> Vector3<f64> {
        self.direction(k + 1) - self.turn(p, b, k).inverse() * self.direction(k)
    }

    /// Rotation `k`'s residual and its Jacobian by the terms (forward differences; each
    /// rotation integrates only its own samples).
    fn residual_and_jacobian(
        &self,
        p: &SVector<f64, 9>,
        k: usize,
    ) -> Option<(Vector3<f64>, Matrix3x9)> {
        let r = self.residual(p, &self.bias, k);
        let mut jac = Matrix3x9::zeros();
        for i in 0..9 {
            let mut q = *p;
            q[i] += H;
            jac.set_column(i, &((self.residual(&q, &self.bias, k) - r) / H));
        }
        (r.iter().chain(jac.iter()).all(|v| v.is_finite())).then_some((r, jac))
    }

    /// The terms' covariance from the noise of what the fit takes as given (see
    /// [`calibrate`]; a rest's accelerometer mean has its white noise and the bias's wander,
    /// [`AccelCalibration::wander_m_s2`]), by the implicit-function rule `dθ = −N⁻¹ Σ J_kᵀ dr_k`.
    fn propagated(
        &self,
        p: &SVector<f64, 9>,
        inverse: &SMatrix<f64, 9, 9>,
        bias_sigma: &Vector3<f64>,
    ) -> Option<SMatrix<f64, 9, 9>> {
        let i = self.inputs;
        let rests = i.rests;
        let k_last = rests.len() - 1;
        let influence = Influence::of(i.accel_means, i.accel)?;
        // ∂r_k/∂u of the direction's normalisation: (I − ûûᵀ)/|u|.
        let normalise = |k: usize| {
            let u = Vector3::from(i.accel.correction.apply(i.accel_means[k]));
            let d = u / u.norm();
            (Matrix3::identity() - d * d.transpose()) / u.norm()
        };
        // c_k = Σ over the residuals that hold u_k of J_rᵀ ∂r/∂u_k, and M_k = −N⁻¹ c_k.
        let jac = |k: usize| self.residual_and_jacobian(p, k).map(|(_, j)| j);
        let m_of = |k: usize| -> Option<SMatrix<f64, 9, 3>> {
            let mut c = SMatrix::<f64, 9, 3>::zeros();
            if k < k_last {
                let turn = self.turn(p, &self.bias, k).inverse().to_rotation_matrix();
                c -= jac(k)?.transpose() * turn.matrix() * normalise(k);
            }
            if k > 0 {
                c += jac(k - 1)?.transpose() * normalise(k);
            }
            Some(-inverse * c)
        };
        // W = Σ M_k T_k: how the accelerometer's terms reach the gyroscope's.
        let mut w = SMatrix::<f64, 9, 9>::zeros();
        for k in 0..rests.len() {
            w += m_of(k)? * influence.value_by_terms(&i.accel_means[k]);
        }
        let mut cov = SMatrix::<f64, 9, 9>::zeros();
        let mut bias_effect = SMatrix::<f64, 9, 3>::zeros();
        for k in 0..rests.len() {
            // A rest's mean: its own direction and, through the accelerometer's terms, all.
            let l = m_of(k)? * influence.matrix() + w * influence.of_rest(&i.accel_means[k]);
            let s2 = i.noise.accel * i.noise.accel / rests[k].len() as f64
                + i.accel.wander_m_s2 * i.accel.wander_m_s2;
            cov += l * l.transpose() * s2;
            if k < k_last {
                let j = jac(k)?;
                // The gyroscope's white noise integrated over the rotation: an angle error of
                // variance σ²·h·T per axis turns the prediction p by dφ × p.
                let (from, to) = (rests[k].end - 1, rests[k + 1].start);
                let span = i.t_s[to] - i.t_s[from];
                let h = span / (to - from) as f64;
                let predicted = self.turn(p, &self.bias, k).inverse() * self.direction(k);
                let cross = predicted.cross_matrix();
                let angle = i.noise.gyro * i.noise.gyro * h * span;
                let jn = inverse * j.transpose() * cross;
                cov += jn * jn.transpose() * angle;
                // The bias: ∂r_k/∂b by forward differences.
                let r0 = self.residual(p, &self.bias, k);
                let mut db = Matrix3::zeros();
                for c in 0..3 {
                    let mut b = self.bias;
                    b[c] += H;
                    db.set_column(c, &((self.residual(p, &b, k) - r0) / H));
                }
                bias_effect -= inverse * j.transpose() * db;
            }
        }
        let cb = Matrix3::from_diagonal(&bias_sigma.component_mul(bias_sigma));
        cov += bias_effect * cb * bias_effect.transpose();
        cov.iter().all(|v| v.is_finite()).then_some(cov)
    }
}

type Matrix3x9 = nalgebra::SMatrix<f64, 3, 9>;

/// The mean reading over the rests (each weighted by its length) and its standard deviation:
/// the scatter `s` of the rests' means over the square root of their number, and the bias's
/// wander over the procedure — what `s²` holds beyond the white noise `white` of a rest's mean
/// (`s² − σ²/n`) — so that a bias that drifts (bias instability) is not taken for a constant
/// known from the rests' average.
fn rest_bias(gyro: &[[f64; 3]], rests: &[Rest], white: f64) -> (Vector3<f64>, Vector3<f64>) {
    let total: usize = rests.iter().map(Rest::len).sum();
    let mut sum = Vector3::zeros();
    for r in rests {
        sum += Vector3::from(r.mean(gyro)) * r.len() as f64;
    }
    let mean = sum / total as f64;
    let k = rests.len() as f64;
    let spread = rests.iter().fold(Vector3::zeros(), |acc, r| {
        let d = Vector3::from(r.mean(gyro)) - mean;
        acc + d.component_mul(&d)
    }) / (k - 1.0);
    let mean_white2 = white * white * k / total as f64;
    (
        mean,
        spread.map(|v| math::sqrt(v / k + (v - mean_white2).max(0.0))),
    )
}

/// The attitude change from sample `from` to sample `to` (body then to body now: a vector
/// `v_to` in the body's axes at `to` is `q ⊗ v_to` at `from`), of the rate `A(y − b)`: the
/// classical Runge–Kutta scheme on `q̇ = ½ q ⊗ ω`, the mid-interval rate from the cubic through
/// the four samples around it (the line through two at the ends of the readings).
fn attitude_change(
    t_s: &[f64],
    gyro: &[[f64; 3]],
    a: &Matrix3<f64>,
    b: &Vector3<f64>,
    from: usize,
    to: usize,
) -> UnitQuaternion<f64> {
    let rate = |i: usize| a * (Vector3::from(gyro[i]) - b);
    let derivative = |q: &Quaternion<f64>, w: &Vector3<f64>| *q * Quaternion::from_imag(*w) * 0.5;
    let mut q = Quaternion::identity();
    for i in from..to {
        let h = t_s[i + 1] - t_s[i];
        let (w0, w1) = (rate(i), rate(i + 1));
        let mid = if i > 0 && i + 2 < t_s.len().min(gyro.len()) {
            (rate(i) * 9.0 + rate(i + 1) * 9.0 - rate(i - 1) - rate(i + 2)) / 16.0
        } else {
            (w0 + w1) * 0.5
        };
        let k1 = derivative(&q, &w0);
        let k2 = derivative(&(q + k1 * (h / 2.0)), &mid);
        let k3 = derivative(&(q + k2 * (h / 2.0)), &mid);
        let k4 = derivative(&(q + k3 * h), &w1);
        q += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        q /= q.norm();
    }
    UnitQuaternion::new_unchecked(q)
}

/// The angle, rad, by which each rotation `k` (from rest `k` to rest `k + 1`) misses the gravity
/// direction measured at rest `k + 1` when the readings are corrected by `accel` (the rests'
/// means `accel_means`) and `gyro`: what a calibration leaves, or, with [`Correction::identity`],
/// what the raw readings miss. Handed to `out` with `k`; rests outside the readings are skipped.
pub fn rotation_residuals(
    t_s: &[f64],
    gyro_readings: &[[f64; 3]],
    rests: &[Rest],
    accel_means: &[[f64; 3]],
    accel: &Correction,
    gyro: &Correction,
    mut out: impl FnMut(usize, f64),
) {
    let n = t_s.len().min(gyro_readings.len());
    let a = Matrix3::from_fn(|i, j| gyro.matrix[i][j]);
    let b = Vector3::from(gyro.bias);
    let unit = |k: usize| {
        let u = Vector3::from(accel.apply(accel_means[k]));
        u / u.norm()
    };
    for k in 0..rests.len().min(accel_means.len()).saturating_sub(1) {
        let (from, to) = (rests[k].end.saturating_sub(1), rests[k + 1].start);
        if rests[k].is_empty() || to >= n || from >= to {
            continue;
        }
        let q = attitude_change(t_s, gyro_readings, &a, &b, from, to);
        let predicted = q.inverse() * unit(k);
        out(k, predicted.angle(&unit(k + 1)));
    }
}
