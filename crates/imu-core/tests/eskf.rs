//! The error-state filter, written once for every Earth, tested where it lives: consistency by
//! Monte Carlo (average NEES of position, velocity and attitude inside the two-sided 95 %
//! chi-square bounds) on the flat Earth and on WGS-84, a mistuned filter outside them, and a
//! covariance still symmetric and positive definite after 10⁶ steps.
use imu_core::earth::{EarthModel, EarthMount, EarthTruth, FlatEarth, Geodetic, Wgs84};
use imu_core::fusion::gate::Gate;
use imu_core::fusion::{
    BASE_STATES, Eskf, EskfNoise, EskfState, FULL_STATES, GnssFix, InitialSigma, SensorErrorSigma,
};
use imu_core::sensor::{NoiseSource, SeededNormals};
use imu_core::strapdown::NavState;
use imu_core::{Enu, Ned, Rotation, Vec3};

const RATE_HZ: f64 = 100.0;
const GNSS_EVERY: usize = 100;
const POSITION_SIGMA_M: f64 = 1.0;
const VELOCITY_SIGMA_M_S: f64 = 0.1;

pub(crate) const NOISE: EskfNoise = EskfNoise {
    accel_psd: 2e-3,
    gyro_psd: 1e-4,
    accel_bias_psd: 1e-5,
    gyro_bias_psd: 1e-7,
};

pub(crate) const SIGMA: InitialSigma = InitialSigma {
    position_m: 2.0,
    velocity_m_s: 0.2,
    attitude_rad: [0.01, 0.01, 0.05],
    accel_bias_m_s2: 0.02,
    gyro_bias_rad_s: 2e-4,
};

/// An Earth with a vehicle on it: where it is at `t_s`, how fast, and what an ideal IMU on it
/// reads (level, its body axes on the navigation axes).
trait Case: EarthModel {
    fn earth() -> Self;
    /// Truth at `t_s`: position and velocity (attitude level, yaw 0).
    fn truth(t_s: f64) -> (Self::Position, Vec3<Self::Frame>);
    /// The ideal gyroscope and accelerometer readings (constant along the motion).
    fn ideal() -> ([f64; 3], [f64; 3]);
}

/// Driving north-east at a constant 11 m/s on the flat ENU Earth.
impl Case for FlatEarth<Enu> {
    fn earth() -> Self {
        FlatEarth::new(9.81)
    }
    fn truth(t_s: f64) -> (Vec3<Enu>, Vec3<Enu>) {
        let v = Vec3::new(10.0, 5.0, 0.0);
        (Vec3::new(3.0, -2.0, 1.0) + v * t_s, v)
    }
    fn ideal() -> ([f64; 3], [f64; 3]) {
        ([0.0; 3], [0.0, 0.0, 9.81])
    }
}

/// Standing at 45° N on the rotating WGS-84 Earth (NED): the gyroscopes read the Earth's rate.
impl Case for Wgs84<Ned> {
    fn earth() -> Self {
        Wgs84::default()
    }
    fn truth(_t_s: f64) -> (Geodetic, Vec3<Ned>) {
        (Geodetic::from_degrees(45.0, 7.0, 300.0), Vec3::zeros())
    }
    fn ideal() -> ([f64; 3], [f64; 3]) {
        let truth = EarthTruth {
            position: Self::truth(0.0).0,
            ..EarthTruth::default()
        };
        let r = EarthMount::default().read(&truth, Vec3::zeros());
        (r.gyro_rad_s.to_array(), r.accel_m_s2.to_array())
    }
}

pub(crate) fn chi2_quantile(k: f64, z: f64) -> f64 {
    // Wilson–Hilferty.
    let c = 2.0 / (9.0 * k);
    k * (1.0 - c + z * c.sqrt()).powi(3)
}

pub(crate) fn draw3(n: &mut SeededNormals, sigma: [f64; 3]) -> [f64; 3] {
    sigma.map(|s| s * n.standard_normal())
}

/// The filter's errors `(δp, δv, φ)` against the truth at `t_s` (navigation axes; position in
/// metres), with `C_true = (I + [φ×]) Ĉ`.
fn errors_of<E: Case>(earth: &E, nav: &NavState<E>, t_s: f64) -> [nalgebra::Vector3<f64>; 3] {
    let (p, v) = E::truth(t_s);
    let ep = earth.displacement_m(&E::coordinates(&nav.position), &E::coordinates(&p));
    let ev = v - nav.velocity_m_s;
    let ea = (Rotation::<imu_core::Body, E::Frame>::identity().quaternion()
        * nav.attitude.quaternion().inverse())
    .scaled_axis();
    [*ep.as_nalgebra(), *ev.as_nalgebra(), ea]
}

/// One run of `seconds`: the truth's biases and the filter's start drawn from the initial
/// one-sigmas times `draw_scale`, white noise on every reading, GNSS position and velocity at
/// 1 Hz; returns the NEES of position, velocity and attitude at the end.
fn run<E: Case>(seed: u64, run: u64, seconds: f64, draw_scale: f64) -> [f64; 3] {
    let earth = E::earth();
    let mut n = SeededNormals::for_run(seed, run);
    let s = draw_scale;
    let bias_a = draw3(&mut n, [SIGMA.accel_bias_m_s2 * s; 3]);
    let bias_g = draw3(&mut n, [SIGMA.gyro_bias_rad_s * s; 3]);
    let (p0, v0) = E::truth(0.0);
    let dp = draw3(&mut n, [SIGMA.position_m * s; 3]);
    let dv = draw3(&mut n, [SIGMA.velocity_m_s * s; 3]);
    let tilt = draw3(&mut n, SIGMA.attitude_rad.map(|a| a * s));
    let start = EskfState::<E> {
        nav: NavState {
            t_s: 0.0,
            // The estimate off by −δx: Ĉ = exp(−[φ×]) C_true.
            position: E::position(
                earth.offset(&E::coordinates(&p0), &Vec3::from_array(dp.map(|x| -x))),
            ),
            velocity_m_s: v0 - Vec3::from_array(dv),
            attitude: Rotation::assume_from_quaternion(nalgebra::UnitQuaternion::from_scaled_axis(
                -nalgebra::Vector3::from(tilt),
            )),
        },
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let mut f = Eskf::<E, BASE_STATES>::new(earth, &start, &SIGMA, NOISE).unwrap();
    let (w_ideal, a_ideal) = E::ideal();
    let (sigma_w, sigma_a) = (
        NOISE.gyro_psd * RATE_HZ.sqrt(),
        NOISE.accel_psd * RATE_HZ.sqrt(),
    );
    let samples = (seconds * RATE_HZ) as usize;
    for k in 0..=samples {
        let t = k as f64 / RATE_HZ;
        let w = draw3(&mut n, [sigma_w; 3]);
        let a = draw3(&mut n, [sigma_a; 3]);
        f.propagate(
            t,
            std::array::from_fn(|i| w_ideal[i] + bias_g[i] + w[i]),
            std::array::from_fn(|i| a_ideal[i] + bias_a[i] + a[i]),
        )
        .unwrap();
        if k > 0 && k % GNSS_EVERY == 0 {
            let (p, v) = E::truth(t);
            let ep = draw3(&mut n, [POSITION_SIGMA_M; 3]);
            let ev = draw3(&mut n, [VELOCITY_SIGMA_M_S; 3]);
            let fix = GnssFix::<E> {
                position: E::position(earth.offset(&E::coordinates(&p), &Vec3::from_array(ep))),
                velocity_m_s: Some(v + Vec3::from_array(ev)),
                lever_arm_m: Vec3::zeros(),
                position_sigma_m: [POSITION_SIGMA_M; 3],
                velocity_sigma_m_s: [VELOCITY_SIGMA_M_S; 3],
                age_s: 0.0,
            };
            f.update(&fix, Gate::Off).unwrap();
        }
    }
    let t_end = samples as f64 / RATE_HZ;
    let e = errors_of(f.earth(), &f.state().nav, t_end);
    std::array::from_fn(|k| {
        let block = nalgebra::Matrix3::from_fn(|r, c| f.covariance(3 * k + r, 3 * k + c));
        (e[k].transpose() * block.try_inverse().unwrap() * e[k])[(0, 0)]
    })
}

/// Average NEES over `runs` runs, and the 95 % bounds of an average of `runs` χ²(3) draws.
fn average_nees<E: Case>(runs: u64, draw_scale: f64) -> ([f64; 3], (f64, f64)) {
    let mut sums = [0.0; 3];
    for r in 0..runs {
        let nees = run::<E>(7, r, 60.0, draw_scale);
        for k in 0..3 {
            sums[k] += nees[k];
        }
    }
    let dof = 3.0 * runs as f64;
    let bounds = (
        chi2_quantile(dof, -1.959_964) / runs as f64,
        chi2_quantile(dof, 1.959_964) / runs as f64,
    );
    (sums.map(|s| s / runs as f64), bounds)
}

fn consistent<E: Case>(name: &str) {
    let (nees, (lo, hi)) = average_nees::<E>(50, 1.0);
    eprintln!("{name}: average NEES {nees:?}, 95 % bounds [{lo:.3}, {hi:.3}]");
    for (what, v) in ["position", "velocity", "attitude"].iter().zip(nees) {
        assert!(
            lo <= v && v <= hi,
            "{name} {what}: average NEES {v} outside [{lo}, {hi}]"
        );
    }
    // A filter told a start three times better than it is: its attitude NEES leaves the bounds.
    let (nees, _) = average_nees::<E>(50, 3.0);
    eprintln!("{name}, start three times worse than told: average NEES {nees:?}");
    assert!(nees[2] > hi, "{name}: a mistuned filter passed ({nees:?})");
}

#[test]
fn the_filter_is_consistent_on_the_flat_earth_and_a_mistuned_one_is_not() {
    consistent::<FlatEarth<Enu>>("flat ENU");
}

#[test]
fn the_filter_is_consistent_on_wgs84_and_a_mistuned_one_is_not() {
    consistent::<Wgs84<Ned>>("WGS-84 NED");
}

/// A million IMU steps with a fix every second, every step propagating the covariance: it
/// stays exactly symmetric (Joseph form, symmetrised) and positive definite (its Cholesky
/// factor exists, its smallest eigenvalue is positive).
fn long_run<E: Case, const S: usize>(name: &str) {
    let earth = E::earth();
    let (p0, v0) = E::truth(0.0);
    let start = EskfState::<E> {
        nav: NavState {
            t_s: 0.0,
            position: p0,
            velocity_m_s: v0,
            attitude: Rotation::identity(),
        },
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let mut f = Eskf::<E, S>::new(earth, &start, &SIGMA, NOISE).unwrap();
    if S == FULL_STATES {
        f = f
            .with_sensor_error_sigma(&SensorErrorSigma {
                accel_scale_factor: 1e-3,
                accel_misalignment: 1e-3,
                gyro_scale_factor: 1e-3,
                gyro_misalignment: 1e-3,
                gyro_g_sensitivity: 1e-5,
            })
            .unwrap();
    }
    let (w, a) = E::ideal();
    let mut n = SeededNormals::new(3);
    for k in 0..=1_000_000usize {
        let t = k as f64 / RATE_HZ;
        f.propagate(t, w, a).unwrap();
        if k > 0 && k % GNSS_EVERY == 0 {
            let (p, v) = E::truth(t);
            let ep = draw3(&mut n, [POSITION_SIGMA_M; 3]);
            let fix = GnssFix::<E> {
                position: E::position(earth.offset(&E::coordinates(&p), &Vec3::from_array(ep))),
                velocity_m_s: Some(v),
                lever_arm_m: Vec3::new(0.5, -0.2, 0.3),
                position_sigma_m: [POSITION_SIGMA_M; 3],
                velocity_sigma_m_s: [VELOCITY_SIGMA_M_S; 3],
                age_s: 0.0,
            };
            f.update(&fix, Gate::Off).unwrap();
        }
    }
    let p = nalgebra::DMatrix::from_fn(S, S, |i, j| f.covariance(i, j));
    assert_eq!(p, p.transpose(), "{name}: not symmetric");
    let min = p.clone().symmetric_eigenvalues().min();
    eprintln!("{name}: smallest eigenvalue after 10⁶ steps {min:e}");
    assert!(min > 0.0, "{name}: smallest eigenvalue {min:e}");
    assert!(p.cholesky().is_some(), "{name}: no Cholesky factor");
}

#[test]
fn the_covariance_stays_symmetric_and_positive_definite_for_a_million_steps() {
    long_run::<FlatEarth<Enu>, BASE_STATES>("flat, 15 states");
    long_run::<Wgs84<Ned>, BASE_STATES>("WGS-84, 15 states");
    long_run::<FlatEarth<Enu>, FULL_STATES>("flat, 36 states");
}

/// A reset to a fix: the reference point moves to the fix less the lever arm, the velocity to
/// the fix's, the heading along it; their variances are the fix's and their correlations with
/// every other state are gone; tilt and its covariance are kept, the bias estimates too, but
/// their uncertainty returns to at least its initial value, uncorrelated.
#[test]
fn a_reset_puts_the_filter_on_the_fix_with_the_fix_s_uncertainty() {
    let earth = FlatEarth::<Enu>::new(9.81);
    let start = EskfState::<FlatEarth<Enu>> {
        nav: NavState {
            t_s: 0.0,
            position: Vec3::new(0.0, 0.0, 0.0),
            velocity_m_s: Vec3::zeros(),
            attitude: Rotation::identity(),
        },
        accel_bias_m_s2: [0.01, 0.0, 0.0],
        gyro_bias_rad_s: [0.0; 3],
    };
    let mut f = Eskf::<FlatEarth<Enu>, BASE_STATES>::new(earth, &start, &SIGMA, NOISE).unwrap();
    // A second at rest, fixes of the standstill every 0.1 s: the vertical accelerometer bias
    // is learnt (its variance falls below the initial one).
    let standstill = GnssFix::<FlatEarth<Enu>> {
        position: Vec3::new(0.0, 0.0, 0.0),
        velocity_m_s: Some(Vec3::zeros()),
        lever_arm_m: Vec3::zeros(),
        position_sigma_m: [0.5; 3],
        velocity_sigma_m_s: [0.01; 3],
        age_s: 0.0,
    };
    for k in 0..=100 {
        f.propagate(k as f64 / RATE_HZ, [0.0; 3], [0.0, 0.0, 9.81])
            .unwrap();
        if k % 10 == 0 {
            f.update(&standstill, Gate::ChiSquare(1e6)).unwrap();
        }
    }
    let bias_before: Vec<f64> = (9..15).map(|k| f.covariance(k, k)).collect();
    let initial = [SIGMA.accel_bias_m_s2.powi(2); 3]
        .into_iter()
        .chain([SIGMA.gyro_bias_rad_s.powi(2); 3])
        .collect::<Vec<_>>();
    assert!(bias_before[2] < 0.5 * initial[2], "{bias_before:?}");
    let tilt_before = f.covariance(6, 6);
    // A fix 40 m north-east with a velocity due north, the antenna 1 m ahead of the reference
    // point (the body's x axis points east at identity attitude in ENU).
    let fix = GnssFix::<FlatEarth<Enu>> {
        position: Vec3::new(30.0, 40.0, 0.0),
        velocity_m_s: Some(Vec3::new(0.0, 5.0, 0.0)),
        lever_arm_m: Vec3::new(1.0, 0.0, 0.0),
        position_sigma_m: [1.5, 1.5, 3.0],
        velocity_sigma_m_s: [0.1, 0.1, 0.2],
        age_s: 0.0,
    };
    let biases = (f.state().accel_bias_m_s2, f.state().gyro_bias_rad_s);
    let counts = f.update_counts();
    f.reset_to_gnss(&fix, Some(0.02)).unwrap();
    let s = f.state();
    // The reference point is the antenna less the lever arm, turned by the attitude after the
    // reset (forward now north, the tilt the updates left): about 1 m south of the fix.
    let p = s.nav.position.to_array();
    let arm = s.nav.attitude.apply(Vec3::new(1.0, 0.0, 0.0)).to_array();
    for k in 0..3 {
        let want = [30.0, 40.0, 0.0][k] - arm[k];
        assert!((p[k] - want).abs() < 1e-12, "{p:?}");
    }
    assert!((p[1] - 39.0).abs() < 1e-5, "{p:?}");
    // The fix's velocity, less the lever arm's turning with the rate the estimated gyroscope
    // bias leaves (under 1e-6 m/s here).
    let v = s.nav.velocity_m_s.to_array();
    assert!(
        v[0].abs() < 1e-12 && (v[1] - 5.0).abs() < 1e-6 && v[2].abs() < 1e-6,
        "{v:?}"
    );
    // Heading along the velocity: the body's forward axis, seen from above, now points north.
    let forward = s.nav.attitude.apply(Vec3::new(1.0, 0.0, 0.0)).to_array();
    assert!(
        forward[0].abs() < 1e-12 && (forward[1] - 1.0).abs() < 1e-5,
        "{forward:?}"
    );
    assert_eq!(
        (s.accel_bias_m_s2, s.gyro_bias_rad_s),
        biases,
        "bias estimates kept"
    );
    let expected = [1.5, 1.5, 3.0, 0.1, 0.1, 0.2];
    for (k, sigma) in expected.iter().enumerate() {
        assert!((f.covariance(k, k) - sigma * sigma).abs() < 1e-15, "{k}");
        for j in 0..BASE_STATES {
            if j != k {
                assert_eq!(f.covariance(k, j), 0.0, "({k}, {j})");
            }
        }
    }
    assert!((f.covariance(8, 8) - 0.02 * 0.02).abs() < 1e-18);
    assert_eq!(f.covariance(6, 6), tilt_before, "tilt kept");
    for k in 0..6 {
        let want = bias_before[k].max(initial[k]);
        assert_eq!(f.covariance(9 + k, 9 + k), want, "bias {k}");
        for j in (0..BASE_STATES).filter(|&j| j != 9 + k) {
            assert_eq!(f.covariance(9 + k, j), 0.0, "bias {k} with {j}");
        }
    }
    assert_eq!(
        f.update_counts(),
        counts,
        "a reset is neither an update nor a rejection"
    );
    // A heading asked for without a horizontal velocity is refused.
    let still = GnssFix {
        velocity_m_s: None,
        ..fix
    };
    assert!(f.reset_to_gnss(&still, Some(0.02)).is_err());
    assert!(f.reset_to_gnss(&still, None).is_ok());
}
