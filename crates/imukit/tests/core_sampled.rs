//! Sampled input (finite differences) against the exact truth of the MATLAB trajectory tool's tilted circle.
use imu_core::kinematics::KinematicsError;
use imu_core::kinematics::sampled::{SampledAttitude, SampledOptions, truth_from_samples};
use imu_core::{Enu, EulerZyx, Truth};
use imukit::motion::analytic::{AnalyticOptions, Motion, Scalar, truth_from_motion};

/// The MATLAB trajectory tool's tilted circle (f = 1 Hz) with its explicit Euler angles (the example of its error study).
struct TiltedCircle;
impl Motion for TiltedCircle {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        let w = t * (2.0 * std::f64::consts::PI);
        [w.cos() * 0.8, w.sin() * 0.8, w.cos() * 0.3]
    }
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        let pi = std::f64::consts::PI;
        let w = t * (2.0 * pi);
        let pitch = ((w.sin() * (3.0 * 2f64.sqrt()))
            / ((t * (4.0 * pi)).cos() * -9.0 + 137.0).sqrt())
        .asin();
        Some([w + pi / 2.0, pitch, D::from(0.0)])
    }
}

fn exact(t: &[f64]) -> Vec<Truth<Enu>> {
    let mut out = vec![Truth::default(); t.len()];
    truth_from_motion(&TiltedCircle, t, AnalyticOptions::default(), &mut out).unwrap();
    out
}

fn grid(rate_hz: f64) -> Vec<f64> {
    let n = rate_hz.round() as usize;
    (0..=n).map(|k| k as f64 / rate_hz).collect()
}

/// Largest error of each quantity relative to its largest exact magnitude:
/// [v, a, ω, α].
fn relative_errors(est: &[Truth<Enu>], ex: &[Truth<Enu>]) -> [f64; 4] {
    type Pick = fn(&Truth<Enu>) -> [f64; 3];
    let pick: [Pick; 4] = [
        |s| s.velocity_m_s.to_array(),
        |s| s.acceleration_m_s2.to_array(),
        |s| s.omega_b_rad_s.to_array(),
        |s| s.alpha_b_rad_s2.to_array(),
    ];
    pick.map(|f| {
        let scale = ex.iter().flat_map(f).fold(0.0_f64, |m, v| m.max(v.abs()));
        let err = est.iter().zip(ex).flat_map(|(a, b)| {
            let (a, b) = (f(a), f(b));
            [
                (a[0] - b[0]).abs(),
                (a[1] - b[1]).abs(),
                (a[2] - b[2]).abs(),
            ]
        });
        err.fold(0.0_f64, f64::max) / scale
    })
}

fn sampled(t: &[f64], ex: &[Truth<Enu>], attitude: &str, order: usize) -> Vec<Truth<Enu>> {
    let pos: Vec<_> = ex.iter().map(|s| s.position_m.to_array()).collect();
    let euler: Vec<_> = ex.iter().map(|s| s.euler).collect();
    let quat: Vec<_> = ex.iter().map(|s| s.attitude.to_wxyz()).collect();
    let att = match attitude {
        "euler" => SampledAttitude::Euler(&euler),
        _ => SampledAttitude::Quaternion(&quat),
    };
    let mut out = vec![Truth::default(); t.len()];
    let opts = SampledOptions {
        order,
        ..SampledOptions::default()
    };
    truth_from_samples(t, &pos, att, opts, &mut out).unwrap();
    out
}

#[test]
fn default_order_is_below_1e_8_relative_on_the_tilted_circle_at_200_hz() {
    let t = grid(200.0);
    let ex = exact(&t);
    for attitude in ["euler", "quaternion"] {
        let errs = relative_errors(&sampled(&t, &ex, attitude, 6), &ex);
        for (name, e) in ["v", "a", "omega", "alpha"].iter().zip(errs) {
            assert!(e < 1e-8, "{attitude}: {name} relative error {e:e}");
        }
    }
}

#[test]
fn order_two_is_matlab_gradient_whose_acceleration_does_not_converge_at_the_ends() {
    // gradient(gradient(x)) uses first-order one-sided differences at the ends, so the end
    // samples' acceleration keeps an O(1) error whatever the rate, while the interior is O(h²).
    for rate in [200.0, 400.0] {
        let t = grid(rate);
        let ex = exact(&t);
        let est = sampled(&t, &ex, "euler", 2);
        let all = relative_errors(&est, &ex);
        let n = t.len();
        let interior = relative_errors(&est[3..n - 3], &ex[3..n - 3]);
        assert!(
            all[1] > 0.4,
            "end acceleration error {:e} at {rate} Hz",
            all[1]
        );
        assert!(
            interior[1] < 4e-4,
            "interior acceleration error {:e} at {rate} Hz",
            interior[1]
        );
    }
}

fn observed_orders(order: usize, rates: [f64; 3], trim: usize) -> Vec<[f64; 4]> {
    let errs: Vec<[f64; 4]> = rates
        .iter()
        .map(|&r| {
            let t = grid(r);
            let ex = exact(&t);
            let est = sampled(&t, &ex, "quaternion", order);
            let n = t.len();
            relative_errors(&est[trim..n - trim], &ex[trim..n - trim])
        })
        .collect();
    (0..2)
        .map(|k| core::array::from_fn(|q| (errs[k][q] / errs[k + 1][q]).log2()))
        .collect()
}

#[test]
fn error_falls_at_the_stencil_order_as_the_rate_doubles() {
    // Rates chosen above the pre-asymptotic range and below the rounding floor of each order.
    // Order 2 (MATLAB gradient) is checked away from its non-convergent ends.
    for (order, rates, trim) in [
        (2, [100.0, 200.0, 400.0], 3),
        (4, [50.0, 100.0, 200.0], 0),
        (6, [25.0, 50.0, 100.0], 0),
    ] {
        for (k, obs) in observed_orders(order, rates, trim).iter().enumerate() {
            for (q, &o) in obs.iter().enumerate() {
                assert!(
                    o > order as f64 - 0.5 && o < order as f64 + 2.5,
                    "order {order}, quantity {q} (v, a, ω, α), {}→{} Hz: observed order {o:.2}",
                    rates[k],
                    rates[k + 1]
                );
            }
        }
    }
}

#[test]
fn bad_sampled_input_is_refused_with_its_index() {
    let t = grid(50.0);
    let ex = exact(&t);
    let pos: Vec<_> = ex.iter().map(|s| s.position_m.to_array()).collect();
    let mut out = vec![Truth::<Enu>::default(); t.len()];
    let opts = SampledOptions::default();

    let mut bad = pos.clone();
    bad[7][1] = f64::NAN;
    assert_eq!(
        truth_from_samples(&t, &bad, SampledAttitude::Tangent, opts, &mut out),
        Err(KinematicsError::NotFinite {
            field: "position_m",
            index: 7
        })
    );

    let mut tt = t.clone();
    tt[5] = tt[4];
    assert!(matches!(
        truth_from_samples(&tt, &pos, SampledAttitude::Tangent, opts, &mut out),
        Err(KinematicsError::TimeNotIncreasing { index: 5, .. })
    ));

    let short = &t[..9];
    assert_eq!(
        truth_from_samples(
            short,
            &pos[..9],
            SampledAttitude::Tangent,
            opts,
            &mut out[..9]
        ),
        Err(KinematicsError::TooFewSamples { needed: 10, got: 9 })
    );

    let mut euler: Vec<_> = ex.iter().map(|s| s.euler).collect();
    euler[3] = EulerZyx::new(0.0, std::f64::consts::FRAC_PI_2, 0.0);
    assert!(matches!(
        truth_from_samples(&t, &pos, SampledAttitude::Euler(&euler), opts, &mut out),
        Err(KinematicsError::GimbalLock { index: 3, .. })
    ));

    assert!(matches!(
        truth_from_samples(&t, &pos[1..], SampledAttitude::Tangent, opts, &mut out),
        Err(KinematicsError::LengthMismatch {
            field: "position_m",
            ..
        })
    ));
}

#[test]
fn tangent_from_samples_matches_exact_tangent() {
    struct Tangent;
    impl Motion for Tangent {
        fn position<D: Scalar>(&self, t: D) -> [D; 3] {
            TiltedCircle.position(t)
        }
        fn euler<D: Scalar>(&self, _t: D) -> Option<[D; 3]> {
            None
        }
    }
    let t = grid(200.0);
    let mut ex = vec![Truth::<Enu>::default(); t.len()];
    truth_from_motion(&Tangent, &t, AnalyticOptions::default(), &mut ex).unwrap();
    let pos: Vec<_> = ex.iter().map(|s| s.position_m.to_array()).collect();
    let mut out = vec![Truth::<Enu>::default(); t.len()];
    truth_from_samples(
        &t,
        &pos,
        SampledAttitude::Tangent,
        SampledOptions::default(),
        &mut out,
    )
    .unwrap();
    let errs = relative_errors(&out, &ex);
    // Angles are differenced after being computed from differenced velocities: one order of
    // differentiation more, so a looser but still tight bound.
    assert!(errs.iter().all(|&e| e < 1e-6), "{errs:?}");
    // The exact tangent attitude reproduces the tool's explicit angles on this circle.
    let seed = exact(&t);
    for (a, b) in ex.iter().zip(&seed) {
        assert!((a.euler.pitch_rad - b.euler.pitch_rad).abs() < 1e-12);
        let dyaw = a.euler.yaw_rad - b.euler.yaw_rad;
        assert!(
            (dyaw - (dyaw / std::f64::consts::TAU).round() * std::f64::consts::TAU).abs() < 1e-12
        );
    }
}

#[test]
fn truth_in_ranges_equals_the_whole_call_bit_for_bit() {
    use imu_core::kinematics::sampled::truth_range;
    // Three turns of the tilted circle at 200 Hz: the yaw wraps several times, across chunk
    // boundaries too.
    let t: Vec<f64> = (0..=600).map(|k| k as f64 / 200.0).collect();
    let ex = exact(&t);
    let pos: Vec<[f64; 3]> = ex.iter().map(|s| s.position_m.to_array()).collect();
    let wrap = |a: f64| {
        (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    let euler: Vec<EulerZyx> = ex
        .iter()
        .map(|s| EulerZyx::new(wrap(s.euler.yaw_rad), s.euler.pitch_rad, s.euler.roll_rad))
        .collect();
    let quat: Vec<[f64; 4]> = ex.iter().map(|s| s.attitude.to_wxyz()).collect();
    let options = SampledOptions::default();
    for attitude in [
        SampledAttitude::Euler(&euler),
        SampledAttitude::Quaternion(&quat),
    ] {
        let mut whole = vec![Truth::<Enu>::default(); t.len()];
        truth_from_samples(&t, &pos, attitude, options, &mut whole).unwrap();
        for chunk in [1, 7, 64, 601] {
            let mut buffer = vec![Truth::<Enu>::default(); chunk];
            let (mut start, mut previous) = (0, None);
            while start < t.len() {
                let len = chunk.min(t.len() - start);
                truth_range(
                    &t,
                    &pos,
                    attitude,
                    options,
                    start,
                    previous,
                    &mut buffer[..len],
                )
                .unwrap();
                assert!(
                    buffer[..len] == whole[start..start + len],
                    "chunk {chunk} at {start}"
                );
                previous = Some(buffer[len - 1].euler.yaw_rad);
                start += len;
            }
        }
    }
    let mut out = vec![Truth::<Enu>::default(); 10];
    assert_eq!(
        truth_range(
            &t,
            &pos,
            SampledAttitude::Tangent,
            options,
            0,
            None,
            &mut out
        ),
        Err(KinematicsError::NeedsWholeSeries)
    );
    assert!(matches!(
        truth_range(
            &t,
            &pos,
            SampledAttitude::Euler(&euler),
            options,
            595,
            None,
            &mut out
        ),
        Err(KinematicsError::LengthMismatch { .. })
    ));
}
