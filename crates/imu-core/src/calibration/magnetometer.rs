//! Hard and soft iron from a magnetometer turned through all directions: the readings `m` of a
//! constant field lie on an ellipsoid `(m − b)ᵀ E (m − b) = 1`; the calibration `C(m − b)`,
//! `C = E^{1/2}/det(E)^{1/6}` (symmetric, determinant 1), puts them on a sphere whose radius
//! `B = det(E)^{−1/6}` is the field's strength.
//!
//! The fit is the algebraic one (the ten-term quadric by least squares under a unit norm, as in
//! T. Ozyagcilar, "Calibrating an eCompass in the presence of hard- and soft-iron
//! interference", NXP AN4246, and MATLAB's `magcal` with a symmetric matrix): the readings,
//! centred on their mean `c` and scaled by their RMS distance `s` from it (for conditioning),
//! give rows `[x², y², z², 2yz, 2xz, 2xy, 2x, 2y, 2z, 1]`; the eigenvector of the smallest
//! eigenvalue of `DᵀD` is the quadric `xᵀQx + 2lᵀx + d = 0` (its sign taken so that `Q` is
//! positive definite); the centre is `x₀ = −Q⁻¹l`, `E_x = Q/(x₀ᵀQx₀ − d)`, and back in the
//! readings' units `b = c + s x₀`, `E = E_x/s²`. The fit error stated beside it is
//! `√(mean((|C(m − b)|² − B²)²))/(2B²)`, to first order the RMS of `|C(m − b)|/B − 1`.
//!
//! Uncertainties come from the geometric residuals `|G(m − b)| − 1`, `G = C/B`, linearised at
//! the fit (`s²(JᵀJ)⁻¹` over `b` and `G`'s six entries), carried to `C` and `B` by the
//! derivative of `G ↦ (G/det(G)^{1/3}, 1/det(G)^{1/3})`.
use nalgebra::{Matrix3, SMatrix, SVector, SymmetricEigen, Vector3};

use super::solve::{Normal, Solution};
use super::{CalibrationError, Correction};
use crate::math;

/// Readings the fit needs at least (nine unknowns and a margin).
pub const MIN_READINGS: usize = 12;

/// The magnetometer's calibration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagCalibration {
    /// `C(m − b)`: `b` the hard iron (µT), `C` the soft-iron correction (symmetric,
    /// determinant 1).
    pub correction: Correction,
    /// Standard deviation of each entry of `C`.
    pub matrix_sigma: [[f64; 3]; 3],
    /// Standard deviation of `b`, µT.
    pub bias_sigma: [f64; 3],
    /// The field's strength `B`, µT, and its standard deviation.
    pub field_ut: f64,
    /// Standard deviation of `B`, µT.
    pub field_sigma_ut: f64,
    /// The fit error (a fraction; see the module documentation).
    pub fit_error: f64,
    /// The readings fitted.
    pub readings: usize,
}

/// The ellipsoid through readings `mag` (µT).
///
/// # Errors
/// Fewer than [`MIN_READINGS`] readings, a non-finite one, or readings that do not lie on an
/// ellipsoid (too few directions: a flat turn gives a cylinder, not an ellipsoid).
pub fn calibrate(mag: &[[f64; 3]]) -> Result<MagCalibration, CalibrationError> {
    if mag.len() < MIN_READINGS {
        return Err(CalibrationError::TooFewReadings {
            found: mag.len(),
            needed: MIN_READINGS,
        });
    }
    if mag.iter().flatten().any(|v| !v.is_finite()) {
        return Err(CalibrationError::Degenerate("a reading is not finite"));
    }
    let (b, e) = ellipsoid(mag)?;
    let eigen = SymmetricEigen::new(e);
    let root = eigen.eigenvectors
        * Matrix3::from_diagonal(&eigen.eigenvalues.map(math::sqrt))
        * eigen.eigenvectors.transpose();
    let g = (root + root.transpose()) * 0.5;
    let (c, field) = normalised(&g).ok_or(CalibrationError::Degenerate("not an ellipsoid"))?;
    let n = mag.len() as f64;
    let fit_error = math::sqrt(
        mag.iter()
            .map(|m| {
                let r = (c * (Vector3::from(*m) - b)).norm_squared() - field * field;
                r * r
            })
            .sum::<f64>()
            / n,
    ) / (2.0 * field * field);
    let (bias_sigma, matrix_sigma, field_sigma) = uncertainty(mag, &b, &g);
    Ok(MagCalibration {
        correction: Correction::of(&c, &b),
        matrix_sigma,
        bias_sigma,
        field_ut: field,
        field_sigma_ut: field_sigma,
        fit_error,
        readings: mag.len(),
    })
}

/// The algebraic fit: the centre `b` and `E` of `(m − b)ᵀE(m − b) = 1`.
fn ellipsoid(mag: &[[f64; 3]]) -> Result<(Vector3<f64>, Matrix3<f64>), CalibrationError> {
    let n = mag.len() as f64;
    let centre = mag
        .iter()
        .fold(Vector3::zeros(), |a, m| a + Vector3::from(*m))
        / n;
    let scale = math::sqrt(
        mag.iter()
            .map(|m| (Vector3::from(*m) - centre).norm_squared())
            .sum::<f64>()
            / n,
    );
    if scale.is_nan() || scale <= 0.0 {
        return Err(CalibrationError::Degenerate("the readings do not move"));
    }
    let mut dtd = SMatrix::<f64, 10, 10>::zeros();
    for m in mag {
        let x = (Vector3::from(*m) - centre) / scale;
        let row = SVector::<f64, 10>::from_row_slice(&[
            x.x * x.x,
            x.y * x.y,
            x.z * x.z,
            2.0 * x.y * x.z,
            2.0 * x.x * x.z,
            2.0 * x.x * x.y,
            2.0 * x.x,
            2.0 * x.y,
            2.0 * x.z,
            1.0,
        ]);
        dtd += row * row.transpose();
    }
    let eigen = SymmetricEigen::new(dtd);
    let smallest = eigen.eigenvalues.imin();
    let mut v = eigen.eigenvectors.column(smallest).into_owned();
    let quadric =
        |v: &SVector<f64, 10>| Matrix3::new(v[0], v[5], v[4], v[5], v[1], v[3], v[4], v[3], v[2]);
    if quadric(&v).trace() < 0.0 {
        v = -v;
    }
    let q = quadric(&v);
    let not_ellipsoid = CalibrationError::Degenerate(
        "the readings do not lie on an ellipsoid: turn the magnetometer through all directions",
    );
    if SymmetricEigen::new(q).eigenvalues.min() <= 0.0 {
        return Err(not_ellipsoid);
    }
    let l = Vector3::new(v[6], v[7], v[8]);
    let x0 = -q.try_inverse().ok_or(not_ellipsoid)? * l;
    let k = (x0.transpose() * q * x0)[0] - v[9];
    if k.is_nan() || k <= 0.0 {
        return Err(not_ellipsoid);
    }
    Ok((centre + x0 * scale, q / (k * scale * scale)))
}

/// `G ↦ (G/det(G)^{1/3}, det(G)^{−1/3})`.
fn normalised(g: &Matrix3<f64>) -> Option<(Matrix3<f64>, f64)> {
    let det = g.determinant();
    if !(det > 0.0 && det.is_finite()) {
        return None;
    }
    let field = 1.0 / math::cbrt(det);
    Some((g * field, field))
}

/// `G`'s six distinct entries, row by row of its upper triangle.
const SYMMETRIC: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

fn symmetric(p: &SVector<f64, 6>) -> Matrix3<f64> {
    let mut g = Matrix3::zeros();
    for (k, &(i, j)) in SYMMETRIC.iter().enumerate() {
        g[(i, j)] = p[k];
        g[(j, i)] = p[k];
    }
    g
}

/// Standard deviations of `b`, of `C`'s entries and of `B` (see the module documentation).
fn uncertainty(
    mag: &[[f64; 3]],
    b: &Vector3<f64>,
    g: &Matrix3<f64>,
) -> ([f64; 3], [[f64; 3]; 3], f64) {
    let mut normal = Normal::<9>::zero();
    for m in mag {
        let v = Vector3::from(*m) - b;
        let w = g * v;
        let norm = w.norm();
        let mut j = SVector::<f64, 9>::zeros();
        let db = -(g * w) / norm;
        for i in 0..3 {
            j[i] = db[i];
        }
        for (k, &(r, c)) in SYMMETRIC.iter().enumerate() {
            j[3 + k] = if r == c {
                w[r] * v[r] / norm
            } else {
                (w[r] * v[c] + w[c] * v[r]) / norm
            };
        }
        normal.add(norm - 1.0, &j);
    }
    let params = SVector::<f64, 9>::from_fn(|i, _| if i < 3 { b[i] } else { g[SYMMETRIC[i - 3]] });
    let Some(cov) = (Solution { params, normal }).covariance() else {
        return ([0.0; 3], [[0.0; 3]; 3], 0.0);
    };
    let sd = |v: f64| math::sqrt(v.max(0.0));
    // The derivative of (C's entries, B) by G's six entries, by central differences.
    let p0 = SVector::<f64, 6>::from_fn(|k, _| g[SYMMETRIC[k]]);
    let mut jac = SMatrix::<f64, 10, 6>::zeros();
    for k in 0..6 {
        let h = 1e-6 * p0[k].abs().max(1e-6 * p0.amax());
        let at = |d: f64| {
            let mut p = p0;
            p[k] += d;
            normalised(&symmetric(&p)).map(|(c, f)| {
                SVector::<f64, 10>::from_fn(|i, _| if i < 9 { c[(i / 3, i % 3)] } else { f })
            })
        };
        let (Some(up), Some(down)) = (at(h), at(-h)) else {
            return ([0.0; 3], [[0.0; 3]; 3], 0.0);
        };
        jac.set_column(k, &((up - down) / (2.0 * h)));
    }
    let cov_g = cov.fixed_view::<6, 6>(3, 3).into_owned();
    let derived = jac * cov_g * jac.transpose();
    (
        core::array::from_fn(|i| sd(cov[(i, i)])),
        core::array::from_fn(|i| core::array::from_fn(|j| sd(derived[(3 * i + j, 3 * i + j)]))),
        sd(derived[(9, 9)]),
    )
}
