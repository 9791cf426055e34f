//! The sensor error model: each deterministic step against its formula (noise off), chunked =
//! one-shot runs, the fast paths bit for bit the plain one, both profiles in both frames.
use imu_core::sensor::{
    Environment, GyroAccelerationInput, ImuModel, ImuState, InlineBuffer, NoNoise, NoiseSource,
    NoiseType, ParamError, SeededNormals, SensorModel, SensorSet, SensorState, Temperatures,
};

/// The core's own storage for filters, named once so struct literals need no annotation.
type SensorParams = imu_core::sensor::SensorParams<InlineBuffer>;
type FilterCoefficients = imu_core::sensor::FilterCoefficients<InlineBuffer>;
use imu_core::{AccelSign, Body, Enu, EulerZyx, ImuMount, NavFrame, Ned, Rotation, Truth, Vec3};

const U: [f64; 3] = [1.25, -0.5, 9.81];
const TOL: f64 = 1e-12;

fn one(params: &SensorParams, u: [f64; 3], env: &Environment) -> [f64; 3] {
    let model = SensorModel::new(params, 100.0).unwrap();
    model.measure(u, env, &mut SensorState::default(), &mut NoNoise)
}

fn close(a: [f64; 3], b: [f64; 3]) {
    for k in 0..3 {
        assert!(
            (a[k] - b[k]).abs() <= TOL * b[k].abs().max(1.0),
            "{a:?} vs {b:?}"
        );
    }
}

fn matvec(m: [[f64; 3]; 3], u: [f64; 3]) -> [f64; 3] {
    core::array::from_fn(|i| (m[i][0] * u[0] + m[i][1] * u[1] + m[i][2] * u[2]) / 100.0)
}

#[test]
fn ideal_parameters_pass_the_input_through() {
    assert_eq!(one(&SensorParams::default(), U, &Environment::default()), U);
}

#[test]
fn misalignment_in_all_three_forms() {
    let env = Environment::default();
    let scalar = SensorParams::misalignment_from_scalar(2.0);
    assert_eq!(
        scalar,
        [[100.0, 2.0, 2.0], [2.0, 100.0, 2.0], [2.0, 2.0, 100.0]]
    );
    let vector = SensorParams::misalignment_from_vector([1.0, 2.0, 3.0]);
    assert_eq!(
        vector,
        [[100.0, 2.0, 3.0], [1.0, 100.0, 3.0], [1.0, 2.0, 100.0]]
    );
    let full = [[101.0, 0.5, -0.3], [0.2, 99.0, 0.1], [-0.4, 0.6, 100.5]];
    for m in [scalar, vector, full] {
        let p = SensorParams {
            axes_misalignment_pct: m,
            ..SensorParams::default()
        };
        close(one(&p, U, &env), matvec(m, U));
    }
}

#[test]
fn constant_bias_adds() {
    let p = SensorParams {
        constant_bias: [0.1, -0.2, 0.3],
        ..SensorParams::default()
    };
    close(
        one(&p, U, &Environment::default()),
        [U[0] + 0.1, U[1] - 0.2, U[2] + 0.3],
    );
}

#[test]
fn temperature_bias_and_scale_follow_the_25_degree_reference() {
    let p = SensorParams {
        temperature_bias: [0.01, 0.02, -0.03],
        temperature_scale_factor_pct: [0.02, 0.5, 1.0],
        constant_bias: [0.1, 0.0, 0.0],
        ..SensorParams::default()
    };
    let env = Environment {
        temperature_c: 40.0,
        ..Environment::default()
    };
    let expected: [f64; 3] = core::array::from_fn(|i| {
        (1.0 + 15.0 * p.temperature_scale_factor_pct[i] / 100.0)
            * (U[i] + p.constant_bias[i] + 15.0 * p.temperature_bias[i])
    });
    close(one(&p, U, &env), expected);
    // At 25 °C both vanish.
    close(
        one(&p, U, &Environment::default()),
        [U[0] + 0.1, U[1], U[2]],
    );
}

#[test]
fn acceleration_bias_multiplies_the_environment_acceleration() {
    let p = SensorParams {
        acceleration_bias: [1e-3, 2e-3, 3e-3],
        ..SensorParams::default()
    };
    let env = Environment {
        temperature_c: 25.0,
        acceleration_m_s2: [1.0, 2.0, -9.81],
    };
    close(one(&p, [0.0; 3], &env), [1e-3, 4e-3, -3e-3 * 9.81]);
}

#[test]
fn saturation_clips_at_the_range() {
    let p = SensorParams {
        measurement_range: 5.0,
        ..SensorParams::default()
    };
    assert_eq!(
        one(&p, [7.0, -7.0, 4.5], &Environment::default()),
        [5.0, -5.0, 4.5]
    );
}

#[test]
fn quantisation_rounds_half_away_from_zero_after_saturation() {
    let r = 0.25;
    let p = SensorParams {
        resolution: r,
        measurement_range: 1.3,
        ..SensorParams::default()
    };
    // 0.625 = 2.5 steps → 3 steps; −0.625 → −3 steps; 1.4 saturates to 1.3 then rounds to 1.25.
    assert_eq!(
        one(&p, [0.625, -0.625, 1.4], &Environment::default()),
        [0.75, -0.75, 1.25]
    );
}

#[test]
fn parameters_are_validated_with_the_field_named() {
    let bad = |p: SensorParams| SensorModel::new(&p, 100.0).unwrap_err();
    let d = SensorParams::default();
    assert_eq!(
        bad(SensorParams {
            noise_density: [0.1, -1.0, 0.0],
            ..d.clone()
        }),
        ParamError::Negative {
            field: "noise_density",
            index: 1,
            value: -1.0
        }
    );
    assert_eq!(
        bad(SensorParams {
            measurement_range: 0.0,
            ..d.clone()
        }),
        ParamError::NotPositive {
            field: "measurement_range",
            value: 0.0
        }
    );
    assert!(matches!(
        bad(SensorParams {
            measurement_range: f64::NAN,
            ..d.clone()
        }),
        ParamError::NotPositive { .. }
    ));
    assert_eq!(
        bad(SensorParams {
            constant_bias: [0.0, 0.0, f64::NAN],
            ..d.clone()
        }),
        ParamError::NotFinite {
            field: "constant_bias",
            index: 2
        }
    );
    assert!(matches!(
        bad(SensorParams {
            temperature_scale_factor_pct: [0.0, 101.0, 0.0],
            ..d.clone()
        }),
        ParamError::OutOfRange { index: 1, .. }
    ));
    assert!(matches!(
        bad(SensorParams {
            resolution: -1.0,
            ..d.clone()
        }),
        ParamError::Negative {
            field: "resolution",
            ..
        }
    ));
    assert!(FilterCoefficients::new(&[1.0], &[0.0, 1.0]).is_err());
    assert!(FilterCoefficients::new(&[], &[1.0]).is_err());
    assert!(SensorModel::new(&d, 0.0).is_err());
    let msg = bad(SensorParams {
        random_walk: [-2.0, 0.0, 0.0],
        ..d.clone()
    })
    .to_string();
    assert_eq!(msg, "random_walk[0] must be ≥ 0, got -2");
    // Infinite range is allowed.
    assert!(
        SensorModel::new(
            &SensorParams {
                measurement_range: f64::INFINITY,
                ..d.clone()
            },
            100.0
        )
        .is_ok()
    );
}

/// Accelerometer, gyroscope and magnetometer, each with `p`, at 100 Hz.
fn all_three<N: NavFrame>(mount: ImuMount<N>, p: &SensorParams) -> ImuModel<N> {
    ImuModel::<N>::new(
        mount,
        SensorSet {
            gyroscope: true,
            magnetometer: true,
        },
        GyroAccelerationInput::BodySpecificForce,
        [p, p, p],
        100.0,
    )
    .unwrap()
}

fn full_params() -> SensorParams {
    SensorParams {
        measurement_range: 50.0,
        resolution: 1e-4,
        constant_bias: [0.1, 0.2, 0.3],
        axes_misalignment_pct: SensorParams::misalignment_from_scalar(1.0),
        noise_density: [1e-3; 3],
        bias_instability: [1e-3; 3],
        random_walk: [1e-4; 3],
        temperature_bias: [1e-3; 3],
        temperature_scale_factor_pct: [0.01; 3],
        acceleration_bias: [1e-4; 3],
        ..SensorParams::default()
    }
}

#[test]
fn a_run_split_into_chunks_equals_one_call() {
    let p = full_params();
    let imu = all_three::<Enu>(ImuMount::default(), &p);
    let truth = Truth::<Enu>::default();
    let temps = Temperatures::uniform(30.0);
    let run = |chunks: &[usize]| {
        let mut state = ImuState::default();
        let mut noise = SeededNormals::new(77);
        let mut out = Vec::new();
        for &len in chunks {
            // Each chunk continues from the state and stream the previous one left.
            let (mut s, mut nz) = (state, noise.clone());
            for _ in 0..len {
                out.push(imu.measure(&truth, &temps, &mut s, &mut nz));
            }
            state = s;
            noise = nz;
        }
        out
    };
    assert_eq!(run(&[1000]), run(&[1, 333, 500, 166]));
}

#[test]
fn many_samples_at_once_are_each_samples_reading_bit_for_bit() {
    use imu_core::sensor::{ImuReading, MEASURE_BLOCK};
    let p = full_params();
    // A moving truth, so that every reading differs, and a temperature that changes with time.
    let truth: Vec<Truth<Ned>> = (0..3 * MEASURE_BLOCK + 5)
        .map(|k| {
            let t = 0.01 * k as f64;
            let e = EulerZyx::new(0.3 * t, 0.1 * t.sin(), -0.2 * t);
            Truth {
                t_s: t,
                attitude: Rotation::from_euler(e),
                euler: e,
                acceleration_m_s2: Vec3::new(t, -0.5 * t, 0.2),
                omega_b_rad_s: Vec3::new(0.1, -0.2 * t, 0.3),
                ..Truth::default()
            }
        })
        .collect();
    let temperatures = |s: &Truth<Ned>| Temperatures::uniform(20.0 + s.t_s);
    for (gyroscope, magnetometer) in [(true, true), (true, false), (false, false)] {
        let imu = ImuModel::<Ned>::new(
            ImuMount::default(),
            SensorSet {
                gyroscope,
                magnetometer,
            },
            GyroAccelerationInput::BodySpecificForce,
            [&p, &p, &p],
            100.0,
        )
        .unwrap();
        // Lengths around a block, and an output shorter than the truth.
        for (n, out_len) in [
            (0, 0),
            (1, 1),
            (MEASURE_BLOCK, MEASURE_BLOCK),
            (truth.len(), truth.len()),
            (truth.len(), 11),
        ] {
            let (mut state_one, mut noise_one) = (ImuState::default(), SeededNormals::new(5));
            let one_by_one: Vec<ImuReading> = truth[..out_len.min(n)]
                .iter()
                .map(|s| imu.measure(s, &temperatures(s), &mut state_one, &mut noise_one))
                .collect();
            let (mut state, mut noise) = (ImuState::default(), SeededNormals::new(5));
            let mut many = vec![ImuReading::default(); out_len];
            imu.measure_many(&truth[..n], temperatures, &mut state, &mut noise, &mut many);
            let bits = |r: &[ImuReading]| {
                r.iter()
                    .flat_map(|r| [r.accel_m_s2, r.gyro_rad_s, r.mag_ut].concat())
                    .map(f64::to_bits)
                    .collect::<Vec<_>>()
            };
            let case = format!(
                "gyroscope {gyroscope}, magnetometer {magnetometer}, {n} samples into {out_len}"
            );
            assert_eq!(bits(&many), bits(&one_by_one), "{case}");
            // The same state and the same place in the stream afterwards.
            assert_eq!(state, state_one, "{case}");
            assert_eq!(
                noise.standard_normal().to_bits(),
                noise_one.standard_normal().to_bits(),
                "{case}"
            );
        }
    }
}

// The only test in this file that switches the AVX2 copy (`imu_core::cpu`): the others may run
// meanwhile and see either copy, which give the same numbers (that is what this checks).
#[test]
fn the_models_avx2_copy_gives_the_baselines_readings_bit_for_bit() {
    use imu_core::sensor::ImuReading;
    let p = full_params();
    let truth: Vec<Truth<Ned>> = (0..2000)
        .map(|k| {
            let t = 0.01 * k as f64;
            let e = EulerZyx::new(0.3 * t, 0.4 * (3.0 * t).sin(), -0.2 * t.cos());
            Truth {
                t_s: t,
                attitude: Rotation::from_euler(e),
                euler: e,
                acceleration_m_s2: Vec3::new((7.0 * t).sin(), -0.5 * t, 0.2),
                omega_b_rad_s: Vec3::new(0.1 * t.cos(), -0.2 * t, 0.3),
                alpha_b_rad_s2: Vec3::new(0.01, (2.0 * t).sin(), -0.02),
                ..Truth::default()
            }
        })
        .collect();
    let imu = all_three::<Ned>(
        ImuMount {
            lever_arm_m: Vec3::new(0.1, -0.05, 0.02),
            ..ImuMount::default()
        },
        &p,
    );
    let run = |avx2: bool| {
        imu_core::cpu::allow_avx2(avx2);
        let (mut state, mut noise) = (ImuState::default(), SeededNormals::new(9));
        let mut readings = vec![ImuReading::default(); truth.len()];
        imu.measure_many(
            &truth,
            |s| Temperatures::uniform(15.0 + s.t_s),
            &mut state,
            &mut noise,
            &mut readings,
        );
        let bits: Vec<u64> = readings
            .iter()
            .flat_map(|r| [r.accel_m_s2, r.gyro_rad_s, r.mag_ut].concat())
            .map(f64::to_bits)
            .collect();
        (bits, state, noise.standard_normal().to_bits())
    };
    let (baseline, avx2) = (run(false), run(true));
    if !imu_core::cpu::avx2_in_use() {
        eprintln!("this CPU runs no AVX2 copy: both runs were the baseline's");
    }
    assert_eq!(avx2.0.len(), 2000 * 9);
    assert!(avx2.0 == baseline.0, "the readings differ");
    assert_eq!(avx2.1, baseline.1, "the states afterwards differ");
    assert_eq!(avx2.2, baseline.2, "the streams' places afterwards differ");
}

fn profiles_case<N: NavFrame>() {
    // A static IMU, yawed and tilted, noise off: MATLAB call shape and truth path agree with the
    // formulas in both accelerometer signs and both g-sensitivity inputs.
    let e = EulerZyx::new(0.4, 0.1, -0.2);
    let att = Rotation::<Body, N>::from_euler(e);
    let g_n = N::gravity(9.81);
    let f_b = att.inverse().apply(-g_n).to_array();
    let m_b = att
        .inverse()
        .apply(N::default_magnetic_field_ut())
        .to_array();
    let gyro = SensorParams {
        acceleration_bias: [0.01, 0.02, 0.03],
        ..SensorParams::default()
    };
    let ideal = SensorParams::default();
    for (sign, input) in [
        (
            AccelSign::SpecificForce,
            GyroAccelerationInput::BodySpecificForce,
        ),
        (AccelSign::Matlab, GyroAccelerationInput::NavAcceleration),
    ] {
        let mount = ImuMount::<N> {
            accel_sign: sign,
            ..ImuMount::default()
        };
        let imu = ImuModel::new(
            mount,
            SensorSet {
                gyroscope: true,
                magnetometer: true,
            },
            input,
            [&ideal, &gyro, &ideal],
            100.0,
        )
        .unwrap();
        let k = if sign == AccelSign::Matlab { -1.0 } else { 1.0 };
        let r = imu.measure_nav(
            Vec3::zeros(),
            Vec3::zeros(),
            &att,
            &Temperatures::default(),
            &mut ImuState::default(),
            &mut NoNoise,
        );
        close(r.accel_m_s2, f_b.map(|c| k * c));
        close(r.mag_ut, m_b);
        let g_sens = match input {
            GyroAccelerationInput::BodySpecificForce => {
                [0.01 * f_b[0], 0.02 * f_b[1], 0.03 * f_b[2]]
            }
            GyroAccelerationInput::NavAcceleration => [0.0; 3], // at rest the nav acceleration is zero
        };
        close(r.gyro_rad_s, g_sens);
        let truth = Truth::<N> {
            attitude: att,
            euler: e,
            ..Truth::default()
        };
        let r2 = imu.measure(
            &truth,
            &Temperatures::default(),
            &mut ImuState::default(),
            &mut NoNoise,
        );
        close(r2.accel_m_s2, r.accel_m_s2);
        close(r2.gyro_rad_s, r.gyro_rad_s);
    }
}

#[test]
fn both_profiles_and_frames_follow_the_formulas_enu() {
    profiles_case::<Enu>();
}

#[test]
fn both_profiles_and_frames_follow_the_formulas_ned() {
    profiles_case::<Ned>();
}

#[test]
fn matlab_spec_sheet_accelerometer_example_deterministic_part() {
    // MATLAB imuSensor page: MeasurementRange 19.62, Resolution 0.00059875, ConstantBias 0.4905,
    // AxesMisalignment 2, NoiseDensity 0.003924 (off here), TemperatureBias
    // [0.34335 0.34335 0.5886], TemperatureScaleFactor 0.02; at 35 °C, level at rest, NED.
    let p = SensorParams {
        measurement_range: 19.62,
        resolution: 0.00059875,
        constant_bias: [0.4905; 3],
        axes_misalignment_pct: SensorParams::misalignment_from_scalar(2.0),
        temperature_bias: [0.34335, 0.34335, 0.5886],
        temperature_scale_factor_pct: [0.02; 3],
        noise_type: NoiseType::DoubleSided,
        ..SensorParams::default()
    };
    let mount = ImuMount::<Ned> {
        accel_sign: AccelSign::Matlab,
        ..ImuMount::default()
    };
    let imu = ImuModel::new(
        mount,
        SensorSet {
            gyroscope: false,
            magnetometer: false,
        },
        GyroAccelerationInput::NavAcceleration,
        [&p, &SensorParams::default(), &SensorParams::default()],
        100.0,
    )
    .unwrap();
    let r = imu.measure_nav(
        Vec3::zeros(),
        Vec3::zeros(),
        &Rotation::identity(),
        &Temperatures::uniform(35.0),
        &mut ImuState::default(),
        &mut NoNoise,
    );
    let u = [0.0, 0.0, 9.81]; // MATLAB: gravity minus acceleration, NED
    let expected: [f64; 3] = core::array::from_fn(|i| {
        let m = SensorParams::misalignment_from_scalar(2.0)[i];
        let bulk = (m[0] * u[0] + m[1] * u[1] + m[2] * u[2]) / 100.0 + 0.4905;
        let y = (1.0 + 10.0 * 0.02 / 100.0) * (bulk + 10.0 * p.temperature_bias[i]);
        let y = y.clamp(-19.62, 19.62);
        0.00059875 * (y / 0.00059875).round()
    });
    close(r.accel_m_s2, expected);
    assert_eq!(r.gyro_rad_s, [0.0; 3]);
}

#[test]
fn quantisation_carry_keeps_the_sum_of_readings_within_one_lsb_of_the_sum_of_inputs() {
    let r = 0.01;
    let u = [0.0031, -0.0047, 0.0199];
    for carry in [false, true] {
        let p = SensorParams {
            resolution: r,
            quantization_carry: carry,
            ..SensorParams::default()
        };
        let model = SensorModel::new(&p, 100.0).unwrap();
        let mut state = SensorState::default();
        let n = 1000;
        let mut sums = [0.0; 3];
        for _ in 0..n {
            let y = model.measure(u, &Environment::default(), &mut state, &mut NoNoise);
            for k in 0..3 {
                assert!(
                    ((y[k] / r) - (y[k] / r).round()).abs() < 1e-9,
                    "on the grid"
                );
                sums[k] += y[k];
            }
        }
        for k in 0..3 {
            let err = (sums[k] - n as f64 * u[k]).abs();
            if carry {
                assert!(err <= r + 1e-9, "axis {k}: {err}");
            } else {
                // Plain rounding: 0.0031 → 0, −0.0047 → 0, 0.0199 → 0.02, every sample.
                let plain = (u[k] / r).round() * r;
                assert!((sums[k] - n as f64 * plain).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn increments_integrate_each_interval() {
    use imu_core::sensor::increments::trapezoid;
    // Linear in time: exact. ω(t) = 0.5 + 2t on [0, 1] at 10 Hz: Δθ_k = 0.5·Δt + (t_k² − t_{k−1}²).
    let t: Vec<f64> = (0..11).map(|k| k as f64 * 0.1).collect();
    let x: Vec<[f64; 3]> = t.iter().map(|&s| [0.5 + 2.0 * s, -1.0, 3.0 * s]).collect();
    let mut d = vec![[9.9; 3]; t.len()];
    trapezoid(&t, &x, &mut d);
    assert_eq!(d[0], [0.0; 3]);
    for k in 1..t.len() {
        let exact = 0.5 * 0.1 + (t[k] * t[k] - t[k - 1] * t[k - 1]);
        assert!(
            (d[k][0] - exact).abs() < 1e-15 && (d[k][1] + 0.1).abs() < 1e-15,
            "{k}"
        );
    }
    // Smooth signal: the summed increments converge to the integral at second order.
    let err = |n: usize| {
        let t: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
        let x: Vec<[f64; 3]> = t.iter().map(|&s| [s.sin(), 0.0, 0.0]).collect();
        let mut d = vec![[0.0; 3]; t.len()];
        trapezoid(&t, &x, &mut d);
        (d.iter().map(|v| v[0]).sum::<f64>() - (1.0 - 1f64.cos())).abs()
    };
    let order = (err(50) / err(100)).log2();
    assert!((order - 2.0).abs() < 0.05, "{order}");
}

/// The seven steps written plainly, axis by axis, with the general transposed-direct-form-II
/// recursion and the library `round`: the optimised model must give the same bits.
fn transcribed(
    p: &SensorParams,
    rate: f64,
    u: &[[f64; 3]],
    env: &Environment,
    seed: u64,
) -> Vec<[f64; 3]> {
    let imu_core::sensor::BiasInstabilityModel::Filter(c) = &p.bias_instability_model else {
        unreachable!("filter models only")
    };
    let (num, den) = (c.numerator(), c.denominator());
    let n = num.len().max(den.len());
    let coeff = |v: &[f64], k: usize| v.get(k).map_or(0.0, |x| x / den[0]);
    let root = match p.noise_type {
        NoiseType::SingleSided => rate,
        NoiseType::DoubleSided => rate / 2.0,
    }
    .sqrt();
    let mut z = [[0.0; 8]; 3];
    let mut rw = [0.0; 3];
    let mut residual = [0.0; 3];
    let mut noise = SeededNormals::new(seed);
    let quantise = |y: f64| {
        if p.resolution > 0.0 {
            p.resolution * (y / p.resolution).round()
        } else {
            y
        }
    };
    u.iter()
        .map(|u| {
            let draws: Vec<f64> = (0..9).map(|_| noise.standard_normal()).collect();
            let dt_c = env.temperature_c - 25.0;
            core::array::from_fn(|i| {
                let m = p.axes_misalignment_pct[i].map(|v| v / 100.0);
                let bulk = m[0] * u[0] + m[1] * u[1] + m[2] * u[2] + p.constant_bias[i];
                let x = p.bias_instability[i] * draws[i];
                let y = coeff(num, 0) * x + if n > 1 { z[i][0] } else { 0.0 };
                for k in 1..n {
                    let next = if k + 1 < n { z[i][k] } else { 0.0 };
                    z[i][k - 1] = coeff(num, k) * x + next - coeff(den, k) * y;
                }
                rw[i] += p.random_walk[i] / root * draws[6 + i];
                let drift = y + p.noise_density[i] * root * draws[3 + i] + rw[i];
                let environment = dt_c * p.temperature_bias[i]
                    + p.acceleration_bias[i] * env.acceleration_m_s2[i];
                let y = (1.0 + dt_c * (p.temperature_scale_factor_pct[i] / 100.0))
                    * (bulk + drift + environment);
                let y = y.clamp(-p.measurement_range, p.measurement_range);
                if p.quantization_carry && p.resolution > 0.0 {
                    let carried = y + residual[i];
                    let q = quantise(carried);
                    residual[i] = carried - q;
                    q
                } else {
                    quantise(y)
                }
            })
        })
        .collect()
}

#[test]
fn the_model_gives_the_bits_of_the_seven_steps_written_plainly() {
    let third = FilterCoefficients::new(&[0.5, 0.25, 0.125], &[2.0, -0.4, 0.1, 0.05]).unwrap();
    let filters = [
        imu_core::sensor::BiasInstabilityModel::default(),
        imu_core::sensor::BiasInstabilityModel::Filter(third),
    ];
    let env = Environment {
        temperature_c: 31.5,
        acceleration_m_s2: [0.3, -9.7, 1.1],
    };
    // Inputs that swing past the range (saturation) and land on quantisation halves.
    let u: Vec<[f64; 3]> = (0..5000)
        .map(|k| {
            let t = k as f64 * 0.01;
            [
                60.0 * t.sin(),
                0.00015 * (k % 7) as f64,
                -3.0 + 0.5 * (3.0 * t).cos(),
            ]
        })
        .collect();
    for (f, filter) in filters.into_iter().enumerate() {
        for carry in [false, true] {
            for noise_type in [NoiseType::SingleSided, NoiseType::DoubleSided] {
                let p = SensorParams {
                    bias_instability_model: filter.clone(),
                    quantization_carry: carry,
                    noise_type,
                    ..full_params()
                };
                let model = SensorModel::new(&p, 200.0).unwrap();
                let mut state = SensorState::default();
                let mut noise = SeededNormals::new(5);
                let want = transcribed(&p, 200.0, &u, &env, 5);
                for (k, (u, want)) in u.iter().zip(&want).enumerate() {
                    let got = model.measure(*u, &env, &mut state, &mut noise);
                    assert_eq!(
                        got.map(f64::to_bits),
                        want.map(f64::to_bits),
                        "filter {f}, carry {carry}, {noise_type:?}, sample {k}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }
}
