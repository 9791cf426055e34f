//! The workloads the criterion benches in `benches/` time, shared with the `workload` example,
//! which runs one of them a fixed number of times: a fixed amount of work is what a profiler or
//! an instruction count needs (criterion runs for a time, not for a count).
//!
//! Instruction counts do not move with the machine's load, which shifts wall-clock figures by
//! tens of percent on a shared machine:
//! `valgrind --tool=callgrind target/release/examples/workload fusion/propagate_covariance_20hz 10`.
use imu_core::earth::{EarthModel, FlatEarth, Geodetic, Wgs84};
use imu_core::fusion::{Eskf, EskfNoise, EskfState, FULL_STATES, InitialSigma, SensorErrorSigma};
use imu_core::strapdown::{NavState, StrapdownOptions, strapdown_increments, strapdown_rates};
use imu_core::{Enu, Ned, Rotation, Vec3};

/// Samples at 1 kHz for the strapdown benches, a slow turn and a level accelerometer: rates
/// (gyro rad/s, specific force m/s², body) and the same as Δθ/Δv increments over 1 ms.
pub struct StrapdownInput {
    /// Times, s.
    pub t_s: Vec<f64>,
    /// Gyro, rad/s.
    pub gyro_rad_s: Vec<[f64; 3]>,
    /// Specific force, m/s².
    pub accel_m_s2: Vec<[f64; 3]>,
    /// Angle increments, rad.
    pub dtheta_rad: Vec<[f64; 3]>,
    /// Velocity increments, m/s.
    pub dv_m_s: Vec<[f64; 3]>,
}

/// The start on WGS-84 (45° N, 7° E, 300 m).
#[must_use]
pub fn earth_start() -> NavState<Wgs84<Ned>> {
    NavState {
        position: Geodetic::from_degrees(45.0, 7.0, 300.0),
        ..NavState::default()
    }
}

impl StrapdownInput {
    /// `n` samples.
    #[must_use]
    pub fn new(n: usize) -> Self {
        let t_s: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let gyro_rad_s: Vec<[f64; 3]> = t_s
            .iter()
            .map(|s| [0.3 * s.sin(), 0.2, -0.1 * s.cos()])
            .collect();
        let accel_m_s2: Vec<[f64; 3]> = t_s.iter().map(|s| [0.5 * s.cos(), 0.1, 9.81]).collect();
        let increments = |x: &[[f64; 3]]| x.iter().map(|w| w.map(|x| x * 1e-3)).collect();
        Self {
            dtheta_rad: increments(&gyro_rad_s),
            dv_m_s: increments(&accel_m_s2),
            t_s,
            gyro_rad_s,
            accel_m_s2,
        }
    }

    /// The flat strapdown on the rates, into `out`.
    ///
    /// # Panics
    /// Never: the samples are valid.
    pub fn rates_flat(&self, out: &mut [NavState<FlatEarth<Enu>>]) {
        let flat = FlatEarth::new(9.81);
        let (t, w, f) = (&self.t_s, &self.gyro_rad_s, &self.accel_m_s2);
        strapdown_rates(
            flat,
            t,
            w,
            f,
            None,
            NavState::default(),
            StrapdownOptions::default(),
            out,
        )
        .expect("valid");
    }

    /// The strapdown on the increments on `earth` from `start`, into `out`.
    ///
    /// # Panics
    /// Never: the samples are valid.
    pub fn increments<E: EarthModel>(&self, earth: E, start: NavState<E>, out: &mut [NavState<E>]) {
        let (t, dth, dv) = (&self.t_s, &self.dtheta_rad, &self.dv_m_s);
        strapdown_increments(
            earth,
            t,
            dth,
            dv,
            None,
            start,
            StrapdownOptions::default(),
            out,
        )
        .expect("valid");
    }
}

/// An Earth to run the filter on and a position near its origin, `offset_m` north-east of it.
pub trait BenchEarth: EarthModel {
    /// The Earth.
    fn make() -> Self;
    /// A position `offset_m` north-east of the start.
    fn at(offset_m: f64) -> Self::Position;
}

impl BenchEarth for FlatEarth<Enu> {
    fn make() -> Self {
        FlatEarth::new(9.81)
    }
    fn at(offset_m: f64) -> Vec3<Enu> {
        Vec3::new(offset_m, offset_m, 0.0)
    }
}

impl BenchEarth for Wgs84<Ned> {
    fn make() -> Self {
        Wgs84::default()
    }
    fn at(offset_m: f64) -> Geodetic {
        Geodetic::from_degrees(
            45.0 + offset_m / 111_000.0,
            7.0 + offset_m / 78_800.0,
            300.0,
        )
    }
}

/// A filter of `S` states at 10 m/s, level, with a consumer part's noise.
///
/// # Panics
/// Never: the settings are valid.
#[must_use]
pub fn filter<E: BenchEarth, const S: usize>() -> Eskf<E, S> {
    let start = EskfState::<E> {
        nav: NavState {
            t_s: 0.0,
            position: E::at(0.0),
            velocity_m_s: Vec3::new(10.0, 0.0, 0.0),
            attitude: Rotation::identity(),
        },
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let sigma = InitialSigma {
        position_m: 1.0,
        velocity_m_s: 0.1,
        attitude_rad: [0.01, 0.01, 0.05],
        accel_bias_m_s2: 0.01,
        gyro_bias_rad_s: 1e-4,
    };
    let noise = EskfNoise {
        accel_psd: 3e-3,
        gyro_psd: 2e-4,
        accel_bias_psd: 2e-4,
        gyro_bias_psd: 2e-6,
    };
    let f = Eskf::new(E::make(), &start, &sigma, noise).expect("valid");
    if S == FULL_STATES {
        f.with_sensor_error_sigma(&SensorErrorSigma {
            accel_scale_factor: 1e-3,
            accel_misalignment: 1e-3,
            gyro_scale_factor: 1e-3,
            gyro_misalignment: 1e-3,
            gyro_g_sensitivity: 1e-5,
        })
        .expect("valid")
    } else {
        f
    }
}

/// `n` samples at 100 Hz through a filter of `S` states, the covariance every `interval_s`.
///
/// # Panics
/// Never: the samples are valid.
#[must_use]
pub fn propagate<E: BenchEarth, const S: usize>(n: usize, interval_s: f64) -> Eskf<E, S> {
    let mut f = filter::<E, S>()
        .with_covariance_interval(interval_s)
        .expect("valid");
    let up = -<E::Frame as imu_core::NavFrame>::Z_UP;
    for k in 0..n {
        let t = k as f64 * 0.01;
        f.propagate(t, [0.01, -0.02, 0.1 * t.sin()], [0.2, 1.0, -up * 9.81])
            .expect("valid");
    }
    f
}
