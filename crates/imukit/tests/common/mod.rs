//! Motions and data shared by the integration tests.
#![allow(dead_code)]

use imu_core::{Enu, IdealReading, ImuMount, Truth};
use imukit::motion::analytic::{AnalyticOptions, Motion, Scalar, truth_from_motion};

/// A helix (radius 5 m, 0.5 rad/s, climbing 0.3 m/s) with yaw along it, a small pitch and a
/// sinusoidal roll.
pub struct RollingHelix;

impl Motion for RollingHelix {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        let a = t * 0.5;
        [a.cos() * 5.0, a.sin() * 5.0, t * 0.3]
    }
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        Some([
            t * 0.5 + std::f64::consts::FRAC_PI_2,
            D::from(0.05),
            (t * 1.7).sin() * 0.4,
        ])
    }
}

/// The helix sampled at `rate` Hz for `seconds`: times, exact truth (ENU), and the ideal gyroscope
/// and accelerometer readings at the reference point.
pub struct HelixData {
    pub t: Vec<f64>,
    pub truth: Vec<Truth<Enu>>,
    pub gyro: Vec<[f64; 3]>,
    pub accel: Vec<[f64; 3]>,
}

pub fn helix(rate: f64, seconds: f64) -> HelixData {
    let n = (rate * seconds) as usize;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 / rate).collect();
    let mut truth = vec![Truth::<Enu>::default(); t.len()];
    truth_from_motion(&RollingHelix, &t, AnalyticOptions::default(), &mut truth).unwrap();
    let mount = ImuMount::<Enu>::default();
    let r: Vec<IdealReading> = truth.iter().map(|s| mount.read(s)).collect();
    HelixData {
        gyro: r.iter().map(|x| x.gyro_rad_s.to_array()).collect(),
        accel: r.iter().map(|x| x.accel_m_s2.to_array()).collect(),
        t,
        truth,
    }
}

/// Wilson–Hilferty: the chi-square quantile with `k` degrees of freedom at standard normal `z`.
pub fn chi2_quantile(k: f64, z: f64) -> f64 {
    let c = 2.0 / (9.0 * k);
    k * (1.0 - c + z * c.sqrt()).powi(3)
}

/// The two-sided 95 % bounds of the average over `runs` runs of a NEES of three degrees of
/// freedom (χ² with 3 × runs degrees of freedom, over runs).
pub fn nees_bounds_95(runs: u64) -> (f64, f64) {
    #[allow(clippy::cast_precision_loss)]
    let n = runs as f64;
    (
        chi2_quantile(3.0 * n, -1.959_964) / n,
        chi2_quantile(3.0 * n, 1.959_964) / n,
    )
}
