//! The transition over one covariance step, kept as its non-zero 3 × 3 blocks: the dynamics
//! every Earth has, the couplings a curved one adds, and the sensor errors' columns.
use nalgebra::Matrix3;

use super::{Block, Cov};
use crate::fusion::sensor_errors::{ACCEL_MATRIX, GYRO_ERRORS};

/// The error dynamics `F` by its non-zero 3 × 3 blocks (the rows below the attitude are
/// zero): on every Earth `δṗ = δv` (the identity), `F_vφ = −[Ĉf̂×]` and
/// `F_v,ba = F_φ,bg = −Ĉ`; a curved Earth adds its couplings, a 36-state filter its sensor
/// errors.
pub(super) struct Dynamics {
    /// `F_vφ = −[Ĉf̂×]`.
    pub(super) v_phi: Matrix3<f64>,
    /// `−Ĉ`, both `F_v,ba` and `F_φ,bg`.
    pub(super) minus_c: Matrix3<f64>,
    pub(super) earth: Option<EarthCouplings>,
    /// `F_v,ma = −Ĉ D_a` (3 × 9) and `F_φ,mg = −Ĉ D_g` (3 × 12).
    pub(super) sensors: Option<(Block<9>, Block<12>)>,
}

/// The blocks of `F` that a curved Earth adds.
pub(super) struct EarthCouplings {
    /// `F_vp`, the gravity gradient.
    pub(super) v_p: Matrix3<f64>,
    /// `F_vv = −[(2ω_ie + ω_en)×]`.
    pub(super) v_v: Matrix3<f64>,
    /// `F_φp = −∂ω_in/∂p`.
    pub(super) phi_p: Matrix3<f64>,
    /// `F_φv = −∂ω_en/∂v`.
    pub(super) phi_v: Matrix3<f64>,
    /// `F_φφ = −[ω_in×]`.
    pub(super) phi_phi: Matrix3<f64>,
}

/// `A = FΔt + (FΔt)²/2`, by its non-zero blocks (named row_column): those of every Earth,
/// those a curved Earth adds and the sensor errors' columns. `Φ = I + A`.
pub(super) struct Transition {
    p_v: Matrix3<f64>,
    p_phi: Matrix3<f64>,
    p_ba: Matrix3<f64>,
    v_phi: Matrix3<f64>,
    v_ba: Matrix3<f64>,
    v_bg: Matrix3<f64>,
    phi_bg: Matrix3<f64>,
    earth: Option<EarthTransition>,
    sensors: Option<SensorTransition>,
}

/// The blocks of `A` that are zero on the flat Earth.
pub(super) struct EarthTransition {
    p_p: Matrix3<f64>,
    v_p: Matrix3<f64>,
    v_v: Matrix3<f64>,
    phi_p: Matrix3<f64>,
    phi_v: Matrix3<f64>,
    phi_phi: Matrix3<f64>,
    phi_ba: Matrix3<f64>,
}

/// The sensor errors' columns of `A` (36 states).
pub(super) struct SensorTransition {
    p_ma: Block<9>,
    v_ma: Block<9>,
    /// Zero on the flat Earth.
    phi_ma: Option<Block<9>>,
    v_mg: Block<12>,
    phi_mg: Block<12>,
}

/// `x`, plus `y` when there is one.
#[inline(always)]
pub(super) fn plus<T: core::ops::Add<Output = T>>(x: T, y: Option<T>) -> T {
    match y {
        Some(y) => x + y,
        None => x,
    }
}

impl Transition {
    /// `A_ij = F_ij Δt + (Σ_k F_ik F_kj) Δt²/2`, each sum over the present products in the
    /// order of `k` (δp, δv, φ; F's first block row is the identity at δv, so its products
    /// are taken without multiplying).
    #[inline(always)]
    pub(super) fn new(f: &Dynamics, dt: f64) -> Self {
        let h = 0.5 * dt * dt;
        let (x, mc) = (&f.v_phi, &f.minus_c);
        let e = f.earth.as_ref();
        Self {
            p_v: plus(Matrix3::identity() * dt, e.map(|e| e.v_v * h)),
            p_phi: x * h,
            p_ba: mc * h,
            v_phi: plus(x * dt, e.map(|e| (e.v_v * x + x * e.phi_phi) * h)),
            v_ba: plus(mc * dt, e.map(|e| (e.v_v * mc) * h)),
            v_bg: (x * mc) * h,
            phi_bg: plus(mc * dt, e.map(|e| (e.phi_phi * mc) * h)),
            earth: e.map(|e| EarthTransition {
                p_p: e.v_p * h,
                v_p: e.v_p * dt + (e.v_v * e.v_p + x * e.phi_p) * h,
                v_v: e.v_v * dt + (e.v_p + e.v_v * e.v_v + x * e.phi_v) * h,
                phi_p: e.phi_p * dt + (e.phi_v * e.v_p + e.phi_phi * e.phi_p) * h,
                phi_v: e.phi_v * dt + (e.phi_p + e.phi_v * e.v_v + e.phi_phi * e.phi_v) * h,
                phi_phi: e.phi_phi * dt + (e.phi_v * x + e.phi_phi * e.phi_phi) * h,
                phi_ba: (e.phi_v * mc) * h,
            }),
            sensors: f.sensors.as_ref().map(|(va, pg)| SensorTransition {
                p_ma: va * h,
                v_ma: plus(va * dt, e.map(|e| (e.v_v * va) * h)),
                phi_ma: e.map(|e| (e.phi_v * va) * h),
                v_mg: (x * pg) * h,
                phi_mg: plus(pg * dt, e.map(|e| (e.phi_phi * pg) * h)),
            }),
        }
    }

    /// `A · m` (rows below the attitude zero), each block row the sum of its blocks'
    /// products in column order, formed apart and copied in (built in the product itself,
    /// every call also paid a copy of the whole matrix).
    pub(super) fn times<const S: usize>(&self, m: &Cov<S>) -> Cov<S> {
        let row = |k: usize| m.fixed_view::<3, S>(3 * k, 0);
        let accel = || m.fixed_view::<9, S>(ACCEL_MATRIX, 0);
        let gyro = || m.fixed_view::<12, S>(GYRO_ERRORS, 0);
        let (e, s) = (self.earth.as_ref(), self.sensors.as_ref());
        // Each row starts from its first present term (no zero added), then the rest in
        // column order.
        let (mut r0, mut r1, mut r2) = match e {
            Some(e) => (
                e.p_p * row(0) + self.p_v * row(1),
                e.v_p * row(0) + e.v_v * row(1) + self.v_phi * row(2),
                e.phi_p * row(0)
                    + e.phi_v * row(1)
                    + e.phi_phi * row(2)
                    + e.phi_ba * row(3)
                    + self.phi_bg * row(4),
            ),
            None => (self.p_v * row(1), self.v_phi * row(2), self.phi_bg * row(4)),
        };
        r0 += self.p_phi * row(2);
        r0 += self.p_ba * row(3);
        r1 += self.v_ba * row(3);
        r1 += self.v_bg * row(4);
        if let Some(s) = s {
            r0 += s.p_ma * accel();
            r1 += s.v_ma * accel();
            r1 += s.v_mg * gyro();
            if let Some(phi_ma) = &s.phi_ma {
                r2 += phi_ma * accel();
            }
            r2 += s.phi_mg * gyro();
        }
        let mut out = Cov::<S>::zeros();
        out.fixed_view_mut::<3, S>(0, 0).copy_from(&r0);
        out.fixed_view_mut::<3, S>(3, 0).copy_from(&r1);
        out.fixed_view_mut::<3, S>(6, 0).copy_from(&r2);
        out
    }
}
