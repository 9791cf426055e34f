//! imukit's robust filter through what throws other filters: a 720 °/s spin for 3 s, a magnet
//! next to the sensor at rest, and 5 s of shaking. Truth in closed form (constant rates, a
//! sinusoidal acceleration), readings with a gyroscope bias of about 1 °/s and white noise.
use imu_core::orientation::{FilterInput, OrientationFilter, RobustFilter, RobustParams};
use imu_core::{Body, Ned, Rotation};
use nalgebra::{UnitQuaternion, Vector3};
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

const FS: f64 = 100.0;

struct Sample {
    t: f64,
    q: UnitQuaternion<f64>,
    input: FilterInput,
    disturbed: bool,
    shaking: bool,
    resting: bool,
}

fn run() -> Vec<Sample> {
    let bias = Vector3::new(0.01, -0.02, 0.015);
    let field_ned = Vector3::new(20.0, 0.0, 45.0);
    let g = 9.81;
    let spin = Vector3::new(1.0, 1.0, 0.0).normalize() * 720f64.to_radians();
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
    let mut n = |s: f64| {
        let z: f64 = StandardNormal.sample(&mut rng);
        s * z
    };
    let q0 = UnitQuaternion::from_euler_angles(0.0, 0.0, 30f64.to_radians());
    let mut q = q0;
    let mut out = Vec::new();
    for k in 0..(45.0 * FS) as usize {
        let t = k as f64 / FS;
        let spinning = (10.0..13.0).contains(&t);
        let rate = if spinning { spin } else { Vector3::zeros() };
        if k > 0 {
            q *= UnitQuaternion::from_scaled_axis(rate / FS);
        }
        let shaking = (30.0..35.0).contains(&t);
        let a_lin = if shaking {
            Vector3::new(3.0 * (2.0 * std::f64::consts::PI * 2.0 * t).sin(), 0.0, 0.0)
        } else {
            Vector3::zeros()
        };
        let disturbed = (25.0..30.0).contains(&t);
        let f_b = q.inverse() * (a_lin - Vector3::new(0.0, 0.0, g));
        let mut m_b = q.inverse() * field_ned;
        if disturbed {
            m_b += Vector3::new(25.0, -15.0, 10.0);
        }
        out.push(Sample {
            t,
            q,
            input: FilterInput {
                accel_m_s2: [f_b.x + n(0.02), f_b.y + n(0.02), f_b.z + n(0.02)],
                gyro_rad_s: [
                    rate.x + bias.x + n(0.002),
                    rate.y + bias.y + n(0.002),
                    rate.z + bias.z + n(0.002),
                ],
                mag_ut: [m_b.x + n(0.1), m_b.y + n(0.1), m_b.z + n(0.1)],
                interval_s: None,
            },
            disturbed,
            shaking,
            resting: !spinning && !shaking && t > 2.0,
        });
    }
    out
}

#[test]
fn the_bias_stays_sane_the_tilt_holds_and_the_flags_fire() {
    let true_bias = Vector3::new(0.01, -0.02, 0.015);
    let mut f = RobustFilter::new(RobustParams {
        sample_rate_hz: FS,
        magnetometer: true,
        ..RobustParams::default()
    })
    .unwrap();
    let (mut worst_tilt, mut worst_heading, mut worst_bias) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut rejected_shaking, mut shaking, mut rejected_still) = (0, 0, 0);
    let (mut flagged, mut disturbed, mut rest_seen) = (0, 0, 0);
    for s in run() {
        let est = OrientationFilter::<Ned>::update(&mut f, &s.input)
            .unwrap()
            .unwrap();
        let status = f.status();
        let truth = Rotation::<Body, Ned>::assume_from_quaternion(s.q);
        let error = est.orientation.quaternion().inverse() * truth.quaternion();
        // Tilt: the angle between the estimated and true down directions in body axes.
        let down = |r: &UnitQuaternion<f64>| r.inverse() * Vector3::z();
        let tilt = down(est.orientation.quaternion()).angle(&down(truth.quaternion()));
        let bias = Vector3::from(status.gyro_bias_rad_s);
        worst_bias = worst_bias.max(bias.norm() / true_bias.norm());
        if s.t > 1.0 {
            worst_tilt = worst_tilt.max(tilt);
            worst_heading = worst_heading.max(error.angle());
        }
        if s.shaking {
            shaking += 1;
            rejected_shaking += usize::from(status.accel_rejected);
        } else if s.resting {
            rejected_still += usize::from(status.accel_rejected);
        }
        if s.disturbed {
            disturbed += 1;
            flagged += usize::from(status.mag_disturbed);
        } else if s.resting {
            assert!(
                !status.mag_disturbed || s.t < 30.5,
                "flagged undisturbed at {}",
                s.t
            );
        }
        rest_seen += usize::from(status.at_rest && s.resting);
    }
    let end_bias = Vector3::from(f.status().gyro_bias_rad_s);
    eprintln!(
        "worst tilt {:.3}°, worst attitude {:.3}°, bias at most {worst_bias:.2}× the true, \
         at the end {:?} (true {:?}); accel rejected {rejected_shaking}/{shaking} shaking, \
         {rejected_still} still; magnet flagged {flagged}/{disturbed}; at rest {rest_seen}",
        worst_tilt.to_degrees(),
        worst_heading.to_degrees(),
        end_bias,
        true_bias
    );
    assert!(
        worst_bias <= 3.0,
        "bias estimate {worst_bias}× the true one"
    );
    assert!(
        (end_bias - true_bias).norm() < 0.2 * true_bias.norm(),
        "{end_bias:?}"
    );
    assert!(
        worst_tilt.to_degrees() <= 2.0,
        "tilt error {}°",
        worst_tilt.to_degrees()
    );
    assert!(
        worst_heading.to_degrees() <= 3.0,
        "attitude error {}°",
        worst_heading.to_degrees()
    );
    // Shaking back and forth at 2 Hz averages out in the low-pass: not a sustained acceleration.
    assert_eq!(rejected_shaking, 0, "{shaking} shaking samples");
    assert_eq!(rejected_still, 0);
    assert!(flagged * 10 >= disturbed * 9, "{flagged}/{disturbed}");
    assert!(rest_seen > 2000);
}

#[test]
fn bad_settings_are_refused_by_name() {
    let e = RobustFilter::new(RobustParams {
        tau_accel_s: -1.0,
        ..RobustParams::default()
    })
    .unwrap_err();
    assert!(e.to_string().contains("AccelerometerTimeConstant"), "{e}");
}
