//! The accelerometer from its rests: at each rest `k` the calibrated mean reading has gravity's
//! magnitude, `|A(ā_k − b)| = g`. Nine unknowns — `A` upper triangular (scale on the diagonal,
//! three misalignments above it, the frame fixed by the accelerometer's own x axis and xy
//! plane, as in Tedaldi et al.) and the bias `b` — found by least squares over the residuals
//! `|A(ā_k − b)| − g`; with few rests the scale-and-bias model (`A` diagonal, six unknowns).
use nalgebra::{Matrix3, SVector, Vector3};

use super::solve::{Normal, least_squares};
use super::{CalibrationError, Correction};
use crate::math;

/// Rests from which the full model (misalignment too) is fitted; below, scale and bias only.
pub const FULL_MODEL_RESTS: usize = 12;

/// Rests the scale-and-bias model needs at least.
pub const MIN_RESTS: usize = 7;

/// The accelerometer's calibration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelCalibration {
    /// `u = A(y − b)`, m/s².
    pub correction: Correction,
    /// Standard deviation of each entry of `A` (zero where the model fixes it).
    pub matrix_sigma: [[f64; 3]; 3],
    /// Standard deviation of `b`, m/s²: the fit's, and the bias's wander over the procedure
    /// (the rests' scatter beyond their white noise).
    pub bias_sigma: [f64; 3],
    /// The wander of the bias over the procedure, m/s²: the rests' scatter beyond their white
    /// noise (zero when the white noise explains it).
    pub wander_m_s2: f64,
    /// Whether the misalignments were fitted (else `A` is diagonal).
    pub full: bool,
    /// RMS of `|A(ā_k − b)| − g` over the rests, m/s².
    pub residual_rms_m_s2: f64,
    /// The rests fitted.
    pub rests: usize,
}

/// Where the unknowns sit: `A`'s entries (row, column) then `b`.
const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
const DIAGONAL: [(usize, usize); 3] = [(0, 0), (1, 1), (2, 2)];

/// Calibrates from the mean readings of the rests, `means` (m/s²), and gravity `gravity_m_s2`;
/// `mean_noise_m_s2` is the white noise of one rest's mean (the sensor's over the square root of
/// the rest's length), the least scatter the uncertainties assume (0: the residuals' alone).
///
/// # Errors
/// Fewer than [`MIN_RESTS`] rests, or rests that do not determine the terms.
pub fn calibrate(
    means: &[[f64; 3]],
    gravity_m_s2: f64,
    mean_noise_m_s2: f64,
) -> Result<AccelCalibration, CalibrationError> {
    if means.len() < MIN_RESTS {
        return Err(CalibrationError::TooFewRests {
            found: means.len(),
            needed: MIN_RESTS,
        });
    }
    if !(gravity_m_s2.is_finite() && gravity_m_s2 > 0.0)
        || means.iter().flatten().any(|v| !v.is_finite())
    {
        return Err(CalibrationError::Degenerate(
            "a reading or gravity is not finite",
        ));
    }
    if means.len() >= FULL_MODEL_RESTS {
        fit::<9>(means, gravity_m_s2, mean_noise_m_s2, &UPPER)
    } else {
        fit::<6>(means, gravity_m_s2, mean_noise_m_s2, &DIAGONAL)
    }
}

/// The fit with `A`'s free entries `entries` (P − 3 of them) and the bias.
fn fit<const P: usize>(
    means: &[[f64; 3]],
    g: f64,
    floor: f64,
    entries: &[(usize, usize)],
) -> Result<AccelCalibration, CalibrationError> {
    let unpack = |p: &SVector<f64, P>| {
        let mut a = Matrix3::zeros();
        for (k, &(i, j)) in entries.iter().enumerate() {
            a[(i, j)] = p[k];
        }
        let n = entries.len();
        (a, Vector3::new(p[n], p[n + 1], p[n + 2]))
    };
    // Start: unit scale, the bias that centres the readings' mean magnitude on g.
    let mean_norm = means
        .iter()
        .map(|m| math::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]))
        .sum::<f64>()
        / means.len() as f64;
    let mut start = SVector::<f64, P>::zeros();
    for (k, &(i, j)) in entries.iter().enumerate() {
        if i == j {
            start[k] = g / mean_norm;
        }
    }
    let solution = least_squares(start, |p, normal: &mut Normal<P>| {
        let (a, b) = unpack(p);
        for m in means {
            let v = Vector3::from(*m) - b;
            let w = a * v;
            let norm = w.norm();
            if norm.is_nan() || norm <= 0.0 {
                return false;
            }
            let mut j = SVector::<f64, P>::zeros();
            for (k, &(r, c)) in entries.iter().enumerate() {
                j[k] = w[r] * v[c] / norm;
            }
            // ∂|w|/∂b = −(wᵀA)/|w|.
            let db = -(a.transpose() * w) / norm;
            let n = entries.len();
            for i in 0..3 {
                j[n + i] = db[i];
            }
            normal.add(norm - g, &j);
        }
        true
    })
    .ok_or(CalibrationError::Degenerate(
        "the magnitudes cannot be evaluated",
    ))?;
    let covariance = solution
        .covariance_at_least(floor)
        .ok_or(CalibrationError::Degenerate(
            "the rests do not span the directions the terms need",
        ))?;
    let sigma = solution.sigma(floor);
    let (a, b) = unpack(&solution.params);
    if a.iter().chain(b.iter()).any(|v| !v.is_finite()) || covariance.iter().any(|v| !v.is_finite())
    {
        return Err(CalibrationError::Degenerate("the fit did not converge"));
    }
    let mut matrix_sigma = [[0.0; 3]; 3];
    for (k, &(i, j)) in entries.iter().enumerate() {
        matrix_sigma[i][j] = sigma[k];
    }
    let n = entries.len();
    // A bias that wanders during the procedure (bias instability) scatters the rests beyond
    // their white noise; the procedure's mean bias is then uncertain by that wander too.
    let scatter = solution.normal.cost / (solution.normal.count - P) as f64;
    let wander = (scatter - floor * floor).max(0.0);
    let with_wander = |s: f64| math::sqrt(s * s + wander);
    Ok(AccelCalibration {
        correction: Correction::of(&a, &b),
        matrix_sigma,
        bias_sigma: [
            with_wander(sigma[n]),
            with_wander(sigma[n + 1]),
            with_wander(sigma[n + 2]),
        ],
        wander_m_s2: math::sqrt(wander),
        full: P == 9,
        residual_rms_m_s2: math::sqrt(solution.normal.cost / means.len() as f64),
        rests: means.len(),
    })
}

/// How the accelerometer's terms move with each rest's mean reading: the derivative
/// `∂θ/∂ā_k` (nine terms: `A`'s upper triangle row by row, then `b`; zero rows for the terms a
/// scale-and-bias fit leaves out), `−N⁻¹ J_kᵀ ∂r_k/∂ā_k` at the fit (`N = JᵀJ`), which carries
/// the rests' noise into what is calibrated with the result (the gyroscope's fit).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Influence {
    inverse: nalgebra::SMatrix<f64, 9, 9>,
    a: Matrix3<f64>,
    b: Vector3<f64>,
    full: bool,
}

impl Influence {
    /// The influence of the rests `means` on the calibration `cal` made from them.
    pub(crate) fn of(means: &[[f64; 3]], cal: &AccelCalibration) -> Option<Self> {
        let a = Matrix3::from_fn(|i, j| cal.correction.matrix[i][j]);
        let b = Vector3::from(cal.correction.bias);
        let mut normal = nalgebra::SMatrix::<f64, 9, 9>::zeros();
        let mut s = Self {
            inverse: normal,
            a,
            b,
            full: cal.full,
        };
        for m in means {
            let (j, _) = s.rows(m)?;
            normal += j * j.transpose();
        }
        // Terms the model fixes: a unit diagonal keeps the matrix invertible, and their
        // Jacobian entries are zero, so they get no influence.
        for k in 0..9 {
            if normal[(k, k)] == 0.0 {
                normal[(k, k)] = 1.0;
            }
        }
        s.inverse = normal.try_inverse()?;
        Some(s)
    }

    /// The residual's Jacobian row by the terms (`J_kᵀ`) and by the mean (`∂r_k/∂ā_k`).
    fn rows(&self, m: &[f64; 3]) -> Option<(SVector<f64, 9>, Vector3<f64>)> {
        let v = Vector3::from(*m) - self.b;
        let w = self.a * v;
        let norm = w.norm();
        if norm.is_nan() || norm <= 0.0 {
            return None;
        }
        let mut j = SVector::<f64, 9>::zeros();
        for (k, &(r, c)) in UPPER.iter().enumerate() {
            if self.full || r == c {
                j[k] = w[r] * v[c] / norm;
            }
        }
        let d = self.a.transpose() * w / norm;
        for i in 0..3 {
            j[6 + i] = -d[i];
        }
        Some((j, d))
    }

    /// `∂θ/∂ā_k` of the rest with mean `m`.
    pub(crate) fn of_rest(&self, m: &[f64; 3]) -> nalgebra::SMatrix<f64, 9, 3> {
        self.rows(m).map_or(nalgebra::SMatrix::zeros(), |(j, d)| {
            -(self.inverse * j) * d.transpose()
        })
    }

    /// `∂u/∂θ` of the calibrated mean `u = A(m − b)` (3 × 9).
    pub(crate) fn value_by_terms(&self, m: &[f64; 3]) -> nalgebra::SMatrix<f64, 3, 9> {
        let v = Vector3::from(*m) - self.b;
        let mut t = nalgebra::SMatrix::<f64, 3, 9>::zeros();
        for (k, &(r, c)) in UPPER.iter().enumerate() {
            if self.full || r == c {
                t[(r, k)] = v[c];
            }
        }
        t.fixed_view_mut::<3, 3>(0, 6).copy_from(&(-self.a));
        t
    }

    /// `A`.
    pub(crate) fn matrix(&self) -> &Matrix3<f64> {
        &self.a
    }
}
