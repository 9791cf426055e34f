//! The filter's aiding updates besides GNSS, written once for every Earth and tested where they
//! live: an odometer, the non-holonomic constraints and a zero-velocity update each move the
//! estimate and shrink the covariance exactly as the scalar Kalman update does on the body axes
//! they measure (and leave the others alone); the gate rejects what lies beyond its quantile,
//! and the quantiles are the chi-square distribution's.
use imu_core::earth::{EarthModel, FlatEarth, Geodetic, Wgs84};
use imu_core::fusion::gate::{CHI2_99_9, Gate, gate_99_9};
use imu_core::fusion::{BASE_STATES, BodyVelocity, Eskf, EskfNoise, EskfState, InitialSigma};
use imu_core::strapdown::NavState;
use imu_core::{Body, Enu, EulerZyx, Ned, Rotation, Vec3};

/// The prior velocity one-sigma, m/s.
const SIGMA_V: f64 = 0.3;

fn filter<E: EarthModel>(earth: E, position: E::Position) -> Eskf<E, BASE_STATES> {
    let start = EskfState {
        nav: NavState {
            t_s: 0.0,
            // Pitched, rolled and turned: body and frame axes differ.
            attitude: Rotation::<Body, E::Frame>::from_euler(EulerZyx::new(0.8, 0.2, -0.3)),
            // At rest in the estimate: the attitude's error does not enter a body velocity.
            velocity_m_s: Vec3::zeros(),
            position,
        },
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let sigma = InitialSigma {
        position_m: 1.0,
        velocity_m_s: SIGMA_V,
        attitude_rad: [0.01, 0.01, 0.05],
        accel_bias_m_s2: 0.01,
        gyro_bias_rad_s: 1e-4,
    };
    let noise = EskfNoise {
        accel_psd: 1e-3,
        gyro_psd: 1e-4,
        accel_bias_psd: 1e-5,
        gyro_bias_psd: 1e-7,
    };
    Eskf::new(earth, &start, &sigma, noise).unwrap()
}

/// The body axis `k` in the navigation frame.
fn body_axis<E: EarthModel>(f: &Eskf<E, BASE_STATES>, k: usize) -> nalgebra::Vector3<f64> {
    let mut e = [0.0; 3];
    e[k] = 1.0;
    *f.state()
        .nav
        .attitude
        .apply(Vec3::from_array(e))
        .as_nalgebra()
}

/// The velocity estimate along body axis `k` and its variance.
fn along<E: EarthModel>(f: &Eskf<E, BASE_STATES>, k: usize) -> (f64, f64) {
    let u = body_axis(f, k);
    let p = nalgebra::Matrix3::from_fn(|r, c| f.covariance(3 + r, 3 + c));
    (
        u.dot(f.state().nav.velocity_m_s.as_nalgebra()),
        (u.transpose() * p * u)[(0, 0)],
    )
}

/// The scalar Kalman update of a prior `N(0, σ₀²)` by a measurement `z` of variance `σ²`.
fn scalar_update(z: f64, sigma: f64) -> (f64, f64) {
    let (p, r) = (SIGMA_V * SIGMA_V, sigma * sigma);
    (p / (p + r) * z, p * r / (p + r))
}

fn close(a: (f64, f64), b: (f64, f64), what: &str) {
    assert!(
        (a.0 - b.0).abs() < 1e-12 && (a.1 / b.1 - 1.0).abs() < 1e-9,
        "{what}: {a:?} against {b:?}"
    );
}

fn updates_are_scalar_kalman_updates<E: EarthModel + Copy>(earth: E, position: E::Position) {
    // An odometer alone: forward only.
    let mut f = filter(earth, position);
    let outcome = f
        .update(&BodyVelocity::odometer(0.5, 0.1, None), Gate::Off)
        .unwrap();
    assert!(outcome.accepted);
    close(along(&f, 0), scalar_update(0.5, 0.1), "odometer, forward");
    close(along(&f, 1), (0.0, SIGMA_V * SIGMA_V), "odometer, lateral");
    close(along(&f, 2), (0.0, SIGMA_V * SIGMA_V), "odometer, vertical");
    // With the constraints: forward as before, lateral and vertical held to 0 ± 0.05.
    let mut f = filter(earth, position);
    f.update(&BodyVelocity::odometer(0.5, 0.1, Some(0.05)), Gate::Off)
        .unwrap();
    close(
        along(&f, 0),
        scalar_update(0.5, 0.1),
        "odometer + NHC, forward",
    );
    close(
        along(&f, 1),
        scalar_update(0.0, 0.05),
        "odometer + NHC, lateral",
    );
    close(
        along(&f, 2),
        scalar_update(0.0, 0.05),
        "odometer + NHC, vertical",
    );
    // The constraints alone leave the forward axis.
    let mut f = filter(earth, position);
    f.update(&BodyVelocity::nonholonomic(0.05), Gate::Off)
        .unwrap();
    close(along(&f, 0), (0.0, SIGMA_V * SIGMA_V), "NHC, forward");
    close(along(&f, 1), scalar_update(0.0, 0.05), "NHC, lateral");
    // A zero-velocity update: every axis.
    let mut f = filter(earth, position);
    f.update(&BodyVelocity::zero(0.01), Gate::Off).unwrap();
    for k in 0..3 {
        close(along(&f, k), scalar_update(0.0, 0.01), "zero velocity");
    }
    // The gate: NIS z²/(σ₀² + σ²) against the one-row quantile.
    let limit = (CHI2_99_9[0] * (SIGMA_V * SIGMA_V + 0.01)).sqrt();
    let mut f = filter(earth, position);
    assert!(
        f.update(
            &BodyVelocity::odometer(0.99 * limit, 0.1, None),
            gate_99_9(1)
        )
        .unwrap()
        .accepted
    );
    let mut f = filter(earth, position);
    let outcome = f
        .update(
            &BodyVelocity::odometer(1.01 * limit, 0.1, None),
            gate_99_9(1),
        )
        .unwrap();
    assert!(!outcome.accepted);
    assert!((outcome.nis / (1.01 * 1.01 * CHI2_99_9[0]) - 1.0).abs() < 1e-9);
    close(along(&f, 0), (0.0, SIGMA_V * SIGMA_V), "a rejected reading");
}

#[test]
fn aiding_updates_are_the_scalar_kalman_update_on_the_body_axes_they_measure() {
    updates_are_scalar_kalman_updates(FlatEarth::<Enu>::new(9.81), Vec3::new(1.0, 2.0, 3.0));
    updates_are_scalar_kalman_updates(
        Wgs84::<Ned>::default(),
        Geodetic::from_degrees(48.0, 11.0, 520.0),
    );
    updates_are_scalar_kalman_updates(
        Wgs84::<Enu>::default(),
        Geodetic::from_degrees(-12.0, -77.0, 150.0),
    );
}

/// The chi-square distribution function `P(k/2, x/2)` by its series,
/// `e^{−y} Σ yᵃ⁺ⁿ / Γ(a + n + 1)`, with `Γ` of integers and half-integers exact.
fn chi_square_cdf(x: f64, k: usize) -> f64 {
    let a = k as f64 / 2.0;
    let y = x / 2.0;
    // Γ(a + 1) for a = k/2.
    let mut gamma = if k.is_multiple_of(2) {
        1.0
    } else {
        std::f64::consts::PI.sqrt() / 2.0
    };
    let mut s = if k.is_multiple_of(2) { 1.0 } else { 1.5 };
    while s <= a {
        gamma *= s;
        s += 1.0;
    }
    let mut term = y.powf(a) / gamma;
    let mut sum = 0.0;
    for n in 1..400 {
        sum += term;
        term *= y / (a + n as f64);
    }
    (-y).exp() * sum
}

#[test]
fn the_gates_are_the_chi_square_quantiles() {
    for (k, q) in CHI2_99_9.iter().enumerate() {
        let p = chi_square_cdf(*q, k + 1);
        assert!((p - 0.999).abs() < 1e-13, "{} rows: P = {p}", k + 1);
    }
    assert_eq!(gate_99_9(7), Gate::Off);
    assert_eq!(gate_99_9(1), Gate::ChiSquare(CHI2_99_9[0]));
}

/// A foot that rolls while it stands turns about the point it rests on: its rate is not zero,
/// though its velocity is. Rocking in pitch in place (0.3 rad/s at most, 0.5 Hz) for 20 s with a
/// gyroscope bias of 0.01 rad/s on that axis, the filter takes zero velocity and zero rate at
/// every sample. Told the rate is zero within one sample's noise, it takes the roll for a bias:
/// its bias estimate follows the rocking and its pitch stands still while the foot rocks, errors
/// far beyond its own three sigma. Told the one-sigma the rate itself gives
/// (`ZeroRate::rolling`, the bias a rest measured taken off the rate), its pitch and bias stay
/// within five sigma at worst over the run, the bias learnt where the rocking turns back (not
/// three: the roll is not white, consecutive samples' rates are alike, which a one-sigma per
/// sample does not know).
#[test]
fn a_rolling_stance_is_not_taken_for_a_gyroscope_bias() {
    use imu_core::fusion::ZeroRate;
    let (fs, g, bias, sigma): (f64, f64, f64, f64) = (100.0, 9.81, 0.01, 0.002);
    let (amplitude, hz) = (0.3 / (2.0 * std::f64::consts::PI * 0.5), 0.5);
    let run = |rolling: bool| {
        let start = EskfState {
            nav: NavState {
                t_s: 0.0,
                attitude: Rotation::<Body, Enu>::from_euler(EulerZyx::new(0.0, 0.0, 0.0)),
                velocity_m_s: Vec3::zeros(),
                position: Vec3::zeros(),
            },
            accel_bias_m_s2: [0.0; 3],
            gyro_bias_rad_s: [0.0; 3],
        };
        let initial = InitialSigma {
            position_m: 0.01,
            velocity_m_s: 0.01,
            attitude_rad: [0.01, 0.01, 0.01],
            accel_bias_m_s2: 0.05,
            gyro_bias_rad_s: 0.05,
        };
        let noise = EskfNoise {
            accel_psd: 0.002,
            gyro_psd: sigma / fs.sqrt(),
            accel_bias_psd: 1e-4,
            gyro_bias_psd: 1e-5,
        };
        let mut f =
            Eskf::<_, BASE_STATES>::new(FlatEarth::<Enu>::new(g), &start, &initial, noise).unwrap();
        let (mut worst_pitch, mut worst_bias) = (0.0_f64, 0.0_f64);
        for i in 0..(20.0 * fs) as usize {
            let t = i as f64 / fs;
            let x = 2.0 * std::f64::consts::PI * hz * t;
            let (pitch, rate) = (
                amplitude * x.sin(),
                amplitude * 2.0 * std::f64::consts::PI * hz * x.cos(),
            );
            // The body pitched by `pitch` about y: gravity's reaction in body axes.
            let accel = [-g * pitch.sin(), 0.0, g * pitch.cos()];
            let gyro = [0.0, rate + bias, 0.0];
            f.propagate(t, gyro, accel).unwrap();
            f.update(&BodyVelocity::zero(0.01), Gate::Off).unwrap();
            let zero_rate = if rolling {
                // The rate with the bias a rest before the walk measured taken off.
                ZeroRate::rolling(sigma, [0.0, gyro[1] - bias, 0.0])
            } else {
                ZeroRate { sigma_rad_s: sigma }
            };
            f.update(&zero_rate, Gate::Off).unwrap();
            let estimate = f.state();
            let pitch_error = estimate.nav.attitude.to_euler().pitch_rad - pitch;
            let bias_error = estimate.gyro_bias_rad_s[1] - bias;
            worst_pitch = worst_pitch.max(pitch_error.abs() / f.covariance(7, 7).sqrt());
            worst_bias = worst_bias.max(bias_error.abs() / f.covariance(13, 13).sqrt());
        }
        (worst_pitch, worst_bias)
    };
    let (pitch_fixed, bias_fixed) = run(false);
    let (pitch_rolling, bias_rolling) = run(true);
    eprintln!(
        "largest error in its own sigmas, pitch and y bias: white-noise zero rate {pitch_fixed:.0}, \
         {bias_fixed:.0}; rolling {pitch_rolling:.2}, {bias_rolling:.2}"
    );
    assert!(pitch_fixed > 10.0 && bias_fixed > 10.0);
    assert!(pitch_rolling < 5.0 && bias_rolling < 5.0);
}
