//! The IMU's scale-factor, misalignment and g-sensitivity errors as filter states: the
//! accelerometers read `f_m = (I + M_a) f + b_a + n_a` and the gyroscopes
//! `ω_m = (I + M_g) ω + b_g + k ∘ f + n_g` (body frame), each `M` a 3 × 3 matrix whose diagonal
//! holds the scale-factor errors and whose off-diagonal entries the misalignment (cross-axis
//! sensitivity), fractions — MATLAB's `AxesMisalignment` in percent is `100 (I + M)` — and
//! `k` the gyroscopes' g-sensitivity per axis, (rad/s)/(m/s²) (MATLAB's `AccelerationBias`).
//!
//! With these 21 states (`M_a` row-major, then `M_g` row-major and `k`, after the 15 of
//! [`super::eskf`]) the filters have 36. The nominal readings are corrected by
//! `f̂ = (I + M̂_a)⁻¹ (f_m − b̂_a)` and `ω̂ = (I + M̂_g)⁻¹ (ω_m − b̂_g − k̂ ∘ f̂)`, so
//! `f̂ ≈ f + δM_a f + δb_a`, `ω̂ ≈ ω + δM_g ω + δb_g + δk ∘ f`, and the error dynamics gain
//! `δv̇ = … − Ĉ D_a δm_a` and `φ̇ = … − Ĉ D_g δm_g`, where `D_a = D(f̂)` (3 × 9) is
//! `∂(M x)/∂vec(M)` at `x = f̂` — row `r` holds `xᵀ` in columns `3r … 3r + 2` — and
//! `D_g = [D(ω̂) | diag(f̂)]` (3 × 12). The errors are constant (no process noise): a filter
//! told a part's tolerances learns them in the turns and speed changes instead of taking them
//! for noise (Groves 2nd ed. §4.4 and §14.2.7).
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Number of error states without the sensor matrices: position, velocity, attitude,
/// accelerometer bias, gyroscope bias.
pub const BASE_STATES: usize = 15;
/// Number of error states with them: [`BASE_STATES`] + 9 (accelerometer matrix) + 9
/// (gyroscope matrix) + 3 (g-sensitivity).
pub const FULL_STATES: usize = 36;
/// First state of the accelerometer's matrix `M_a` (row-major).
pub(crate) const ACCEL_MATRIX: usize = 15;
/// First of the gyroscope's 12 error states: `M_g` (row-major), then `k`.
pub(crate) const GYRO_ERRORS: usize = 24;

/// The gyroscope error states' Jacobian `D_g` (3 × 12).
pub(crate) type GyroJacobian = SMatrix<f64, 3, 12>;

/// One-sigma of the sensor errors at the start (fractions, 0.01 is 1 %; g-sensitivity in
/// (rad/s)/(m/s²)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorErrorSigma {
    /// Accelerometer scale-factor error (diagonal of `M_a`).
    pub accel_scale_factor: f64,
    /// Accelerometer misalignment / cross-axis sensitivity (off-diagonal of `M_a`).
    pub accel_misalignment: f64,
    /// Gyroscope scale-factor error (diagonal of `M_g`).
    pub gyro_scale_factor: f64,
    /// Gyroscope misalignment / cross-axis sensitivity (off-diagonal of `M_g`).
    pub gyro_misalignment: f64,
    /// Gyroscope g-sensitivity `k`, (rad/s)/(m/s²).
    pub gyro_g_sensitivity: f64,
}

impl SensorErrorSigma {
    /// The initial variances of the 21 sensor error states, in state order; `None` when a
    /// sigma is negative or not finite.
    pub(crate) fn variances(&self) -> Option<[f64; FULL_STATES - BASE_STATES]> {
        let all = [
            self.accel_scale_factor,
            self.accel_misalignment,
            self.gyro_scale_factor,
            self.gyro_misalignment,
            self.gyro_g_sensitivity,
        ];
        if !all.iter().all(|s| s.is_finite() && *s >= 0.0) {
            return None;
        }
        Some(core::array::from_fn(|k| {
            let (triad, entry) = (k / 9, k % 9);
            let diagonal = entry % 4 == 0;
            let s = match (triad, diagonal) {
                (2, _) => self.gyro_g_sensitivity,
                (0, true) => self.accel_scale_factor,
                (0, false) => self.accel_misalignment,
                (_, true) => self.gyro_scale_factor,
                (_, false) => self.gyro_misalignment,
            };
            s * s
        }))
    }
}

/// The filter's estimate of the sensor errors: zero in a 15-state filter.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorErrorEstimate {
    /// Accelerometer `M_a` (row-major `[row][column]`, fractions).
    pub accel: [[f64; 3]; 3],
    /// Gyroscope `M_g`.
    pub gyro: [[f64; 3]; 3],
    /// Gyroscope g-sensitivity `k`, (rad/s)/(m/s²).
    pub gyro_g_sensitivity: [f64; 3],
}

/// `D(x)`: the 3 × 9 Jacobian of `M x` with respect to `M` row-major.
pub(crate) fn d_matrix(x: &Vector3<f64>) -> SMatrix<f64, 3, 9> {
    let mut d = SMatrix::<f64, 3, 9>::zeros();
    for r in 0..3 {
        for c in 0..3 {
            d[(r, 3 * r + c)] = x[c];
        }
    }
    d
}

/// `D_g = [D(ω) | diag(f)]`: the 3 × 12 Jacobian of the gyroscope errors `M_g ω + k ∘ f`.
pub(crate) fn d_gyro(w: &Vector3<f64>, f: &Vector3<f64>) -> GyroJacobian {
    let mut d = GyroJacobian::zeros();
    d.fixed_view_mut::<3, 9>(0, 0).copy_from(&d_matrix(w));
    for r in 0..3 {
        d[(r, 9 + r)] = f[r];
    }
    d
}

/// The nominal sensor errors, the inverses `(I + M̂)⁻¹` and the sums the covariance step needs
/// since its last step: `∫ Ĉ D_a dt` and `∫ Ĉ D_g dt`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SensorErrors {
    accel: Matrix3<f64>,
    gyro: Matrix3<f64>,
    g_sensitivity: Vector3<f64>,
    accel_inv: Matrix3<f64>,
    gyro_inv: Matrix3<f64>,
    pending_accel: SMatrix<f64, 3, 9>,
    pending_gyro: GyroJacobian,
}

impl SensorErrors {
    /// Perfect sensors.
    pub(crate) fn new() -> Self {
        Self {
            accel: Matrix3::zeros(),
            gyro: Matrix3::zeros(),
            g_sensitivity: Vector3::zeros(),
            accel_inv: Matrix3::identity(),
            gyro_inv: Matrix3::identity(),
            pending_accel: SMatrix::zeros(),
            pending_gyro: GyroJacobian::zeros(),
        }
    }

    /// The estimate.
    pub(crate) fn estimate(&self) -> SensorErrorEstimate {
        let rows = |m: &Matrix3<f64>| core::array::from_fn(|r| core::array::from_fn(|c| m[(r, c)]));
        SensorErrorEstimate {
            accel: rows(&self.accel),
            gyro: rows(&self.gyro),
            gyro_g_sensitivity: self.g_sensitivity.into(),
        }
    }

    /// Body rate and specific force with the errors removed, from readings whose biases are
    /// already removed: `f̂ = (I + M̂_a)⁻¹ f`, `ω̂ = (I + M̂_g)⁻¹ (ω − k̂ ∘ f̂)` in a filter of
    /// [`FULL_STATES`]; a filter of `S` = 15 states takes the readings as they are.
    pub(crate) fn correct<const S: usize>(
        &self,
        gyro: Vector3<f64>,
        accel: Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        if S < FULL_STATES {
            return (gyro, accel);
        }
        let f = self.accel_inv * accel;
        (
            self.gyro_inv * (gyro - self.g_sensitivity.component_mul(&f)),
            f,
        )
    }

    /// What the gyroscopes read, bias aside, of a body turning at `w` under specific force
    /// `f`: `(I + M̂_g) ω + k̂ ∘ f`.
    pub(crate) fn gyro_reading(&self, w: &Vector3<f64>, f: &Vector3<f64>) -> Vector3<f64> {
        w + self.gyro * w + self.g_sensitivity.component_mul(f)
    }

    /// Adds an interval `dt` with attitude `c`, corrected rate `w` and specific force `f`.
    pub(crate) fn accumulate(
        &mut self,
        dt: f64,
        c: &Matrix3<f64>,
        w: &Vector3<f64>,
        f: &Vector3<f64>,
    ) {
        self.pending_accel += c * d_matrix(f) * dt;
        self.pending_gyro += c * d_gyro(w, f) * dt;
    }

    /// The interval's means `Ĉ D_a` and `Ĉ D_g` over `dt`, cleared.
    pub(crate) fn take_pending(&mut self, dt: f64) -> (SMatrix<f64, 3, 9>, GyroJacobian) {
        let out = (self.pending_accel / dt, self.pending_gyro / dt);
        self.pending_accel = SMatrix::zeros();
        self.pending_gyro = GyroJacobian::zeros();
        out
    }

    /// Closed loop: the corrections (states [`ACCEL_MATRIX`]… of `dx`) into the nominal
    /// errors; `false` when `I + M̂` could no longer be inverted.
    pub(crate) fn inject<const S: usize>(&mut self, dx: &SVector<f64, S>) -> bool {
        if S < FULL_STATES {
            return true;
        }
        for k in 0..9 {
            self.accel[(k / 3, k % 3)] += dx[ACCEL_MATRIX + k];
            self.gyro[(k / 3, k % 3)] += dx[GYRO_ERRORS + k];
        }
        for r in 0..3 {
            self.g_sensitivity[r] += dx[GYRO_ERRORS + 9 + r];
        }
        match (
            (Matrix3::identity() + self.accel).try_inverse(),
            (Matrix3::identity() + self.gyro).try_inverse(),
        ) {
            (Some(a), Some(g)) => {
                self.accel_inv = a;
                self.gyro_inv = g;
                true
            }
            _ => false,
        }
    }
}
