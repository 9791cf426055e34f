//! Vibration rectified by the sensing element's nonlinearity: a sine of amplitude `A` on an
//! axis with second-order nonlinearity `K₂` reads a mean bias `K₂A²/2`, with scale-factor
//! asymmetry `ε` a bias `εA/π`, and a gyroscope with g²-sensitivity `k` under acceleration
//! `A·sin` a bias `kA²/2` — each against its closed form, with noise off and with noise (the
//! tolerance from the mean's standard error); the element taken out of a model for a chain reads
//! the same as the model that keeps it; ranges refused by field.
use core::f64::consts::PI;

use imu_core::sensor::{
    Environment, GyroAccelerationInput, ImuModel, ImuState, InlineBuffer, NoNoise, ParamError,
    SeededNormals, SensorModel, SensorSet, SensorState, Temperatures,
};
use imu_core::{AccelSign, ImuMount, Ned, Vec3};

type SensorParams = imu_core::sensor::SensorParams<InlineBuffer>;

/// Internal rate of the sines, Hz, and their frequency (not a divisor of the rate).
const RATE_HZ: f64 = 8000.0;
const F_HZ: f64 = 1130.0;
/// 10 s: a whole number of the sine's periods (11 300).
const SAMPLES: usize = 80_000;

fn sine(k: usize, amplitude: f64) -> f64 {
    amplitude * (2.0 * PI * F_HZ * k as f64 / RATE_HZ).sin()
}

/// The mean reading of each axis over the samples, the input `input(k)` and acceleration
/// `acceleration(k)`, noise from `seed` when given.
fn mean_reading(
    p: &SensorParams,
    input: impl Fn(usize) -> [f64; 3],
    acceleration: impl Fn(usize) -> [f64; 3],
    seed: Option<u64>,
) -> [f64; 3] {
    let model = SensorModel::new(p, RATE_HZ).unwrap();
    let mut state = SensorState::default();
    let mut noise = seed.map(SeededNormals::new);
    let mut sum = [0.0; 3];
    for k in 0..SAMPLES {
        let env = Environment {
            temperature_c: 25.0,
            acceleration_m_s2: acceleration(k),
        };
        let y = match &mut noise {
            Some(n) => model.measure(input(k), &env, &mut state, n),
            None => model.measure(input(k), &env, &mut state, &mut NoNoise),
        };
        for i in 0..3 {
            sum[i] += y[i];
        }
    }
    sum.map(|s| s / SAMPLES as f64)
}

#[test]
fn second_order_nonlinearity_rectifies_a_sine_into_k2_a_squared_over_two() {
    // 2 g of vibration on x, gravity on z, 1e-3 /(m/s²) (about 10 mg/g²) on x and z.
    let (a, g) = (19.62, 9.81);
    let p = SensorParams {
        scale_factor_nonlinearity: [1e-3, 0.0, 2e-3],
        ..SensorParams::default()
    };
    let input = |k| [sine(k, a), 0.0, g];
    let mean = mean_reading(&p, input, |_| [0.0; 3], None);
    let expected = [1e-3 * a * a / 2.0, 0.0, g + 2e-3 * g * g];
    for i in 0..3 {
        assert!(
            (mean[i] - expected[i]).abs() <= 1e-9 * expected[i].abs().max(1.0),
            "axis {i}: {} vs {}",
            mean[i],
            expected[i]
        );
    }
    // With a part's white noise (0.01 m/s² a sample): within 4 standard errors of the mean,
    // which is far inside the 1 % the rectified bias (0.19 m/s²) is asked to hold.
    let noisy = SensorParams {
        noise_density: [0.01 / (RATE_HZ / 2.0).sqrt(); 3],
        ..p
    };
    let mean = mean_reading(&noisy, input, |_| [0.0; 3], Some(7));
    let standard_error = 0.01 / (SAMPLES as f64).sqrt();
    assert!(
        (mean[0] - expected[0]).abs() < 4.0 * standard_error,
        "{} vs {}",
        mean[0],
        expected[0]
    );
    assert!(4.0 * standard_error < 0.01 * expected[0]);
}

#[test]
fn scale_factor_asymmetry_rectifies_a_sine_into_epsilon_a_over_pi() {
    let a = 19.62;
    let p = SensorParams {
        scale_factor_asymmetry_pct: [2.0, -1.0, 0.0],
        ..SensorParams::default()
    };
    let mean = mean_reading(&p, |k| [sine(k, a), sine(k, a), 3.0], |_| [0.0; 3], None);
    // The sampled mean of |sin| is 2/π to within the sampling's ripple (about 1e-5 here).
    for (i, eps) in [(0, 0.02), (1, -0.01)] {
        let expected = eps * a / PI;
        assert!(
            (mean[i] / expected - 1.0).abs() < 1e-3,
            "axis {i}: {} vs {expected}",
            mean[i]
        );
    }
    // A positive input reads (1 + ε/2)·u, a negative one (1 − ε/2)·u.
    let model = SensorModel::new(&p, RATE_HZ).unwrap();
    let env = Environment::default();
    let y = model.measure(
        [2.0, -2.0, 3.0],
        &env,
        &mut SensorState::default(),
        &mut NoNoise,
    );
    assert!((y[0] - 2.0 * 1.01).abs() < 1e-15);
    assert!((y[1] - -2.0 * 1.005).abs() < 1e-15);
    assert_eq!(y[2], 3.0);
}

#[test]
fn gyroscope_g_squared_sensitivity_rectifies_acceleration_into_k_a_squared_over_two() {
    let a = 49.05; // 5 g
    let p = SensorParams {
        acceleration_squared_bias: [0.0, 3e-6, 0.0],
        ..SensorParams::default()
    };
    let mean = mean_reading(&p, |_| [0.0; 3], |k| [0.0, sine(k, a), 0.0], None);
    let expected = 3e-6 * a * a / 2.0;
    assert!((mean[1] / expected - 1.0).abs() < 1e-9, "{mean:?}");
    assert_eq!(mean[0], 0.0);
}

#[test]
fn the_element_taken_out_for_a_chain_reads_as_the_model_that_keeps_it() {
    let accel = SensorParams {
        scale_factor_nonlinearity: [1e-3, -2e-3, 5e-4],
        scale_factor_asymmetry_pct: [0.5, 0.0, -0.3],
        constant_bias: [0.01, 0.0, -0.02],
        ..SensorParams::default()
    };
    let gyro = SensorParams {
        acceleration_squared_bias: [1e-6, 2e-6, -3e-6],
        scale_factor_nonlinearity: [1e-2; 3],
        ..SensorParams::default()
    };
    let mag = SensorParams::default();
    let sensors = SensorSet {
        gyroscope: true,
        magnetometer: true,
    };
    for sign in [AccelSign::SpecificForce, AccelSign::Matlab] {
        let mount = ImuMount::<Ned> {
            accel_sign: sign,
            ..ImuMount::default()
        };
        let whole = ImuModel::new(
            mount,
            sensors,
            GyroAccelerationInput::BodySpecificForce,
            [&accel, &gyro, &mag],
            100.0,
        )
        .unwrap();
        let mut linear = whole.clone();
        let element = linear.take_sensing_element().expect("the parts have terms");
        assert!(linear.clone().take_sensing_element().is_none());
        let (f, w, m) = ([3.0, -12.0, -9.81], [0.2, -0.1, 0.05], [20.0, 1.0, 40.0]);
        let temperatures = Temperatures::uniform(25.0);
        let read = |model: &ImuModel<Ned>, [f, w, m]: [[f64; 3]; 3]| {
            model.measure_ideal(
                Vec3::from_array(f),
                Vec3::from_array(w),
                Vec3::from_array(m),
                Vec3::from_array([0.0; 3]),
                &temperatures,
                &mut ImuState::default(),
                &mut NoNoise,
            )
        };
        let direct = read(&whole, [f, w, m]);
        let split = read(&linear, element.apply([f, w, m], [0.0; 3]));
        for (a, b) in [
            (direct.accel_m_s2, split.accel_m_s2),
            (direct.gyro_rad_s, split.gyro_rad_s),
            (direct.mag_ut, split.mag_ut),
        ] {
            for i in 0..3 {
                assert!(
                    (a[i] - b[i]).abs() <= 1e-14 * a[i].abs().max(1.0),
                    "{sign:?}"
                );
            }
        }
    }
}

#[test]
fn an_asymmetry_beyond_the_scale_or_a_nan_term_is_refused_by_field() {
    let asymmetric = SensorParams {
        scale_factor_asymmetry_pct: [0.0, 150.0, 0.0],
        ..SensorParams::default()
    };
    assert!(matches!(
        asymmetric.validate(),
        Err(ParamError::OutOfRange {
            field: "scale_factor_asymmetry_pct",
            index: 1,
            ..
        })
    ));
    let nan = SensorParams {
        scale_factor_nonlinearity: [0.0, 0.0, f64::NAN],
        ..SensorParams::default()
    };
    assert!(matches!(
        nan.validate(),
        Err(ParamError::NotFinite {
            field: "scale_factor_nonlinearity",
            index: 2
        })
    ));
    let g2 = SensorParams {
        acceleration_squared_bias: [f64::INFINITY, 0.0, 0.0],
        ..SensorParams::default()
    };
    assert!(g2.validate().is_err());
}
