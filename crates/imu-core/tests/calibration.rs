//! Calibration from a procedure against the part that made it: a part with known bias, scale
//! and misalignment set down in K orientations, turned between them about fixed axes (exact
//! rates), read with and without white noise. Without noise every term comes back exact; with
//! noise within its stated uncertainty. The accelerometer's calibrated frame is fixed by its
//! own x axis and xy plane, so the truth is `U` of `M_a⁻¹ = QU` (QR, positive diagonal) and the
//! gyroscope's `QᵀM_g⁻¹`. The ellipsoid fit returns a sphere's hard and soft iron.
use imu_core::calibration::{Rest, accelerometer, gyroscope, magnetometer, rests};
use imu_core::sensor::{NoiseSource, SeededNormals};
use imu_core::stillness::{ReadingNoise, quiet_noise};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

const RATE_HZ: f64 = 100.0;
const REST_S: f64 = 4.0;
const TURN_S: f64 = 2.0;
const G: f64 = 9.81;

/// Orientations spread over the sphere of gravity directions, with turns about all axes.
fn orientations(k: usize) -> Vec<UnitQuaternion<f64>> {
    (0..k)
        .map(|i| {
            let i = i as f64;
            // A golden-angle spiral of the up direction, and a yaw that keeps changing.
            let z = 1.0 - 2.0 * (i + 0.5) / k as f64;
            let phi = i * 2.399_963_229_728_653;
            let up = Vector3::new(
                (1.0 - z * z).sqrt() * phi.cos(),
                (1.0 - z * z).sqrt() * phi.sin(),
                z,
            );
            UnitQuaternion::rotation_between(&Vector3::z(), &up).unwrap_or_else(|| {
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
            }) * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.7 * i)
        })
        .collect()
}

struct Procedure {
    t: Vec<f64>,
    /// True specific force and rate, body axes.
    f: Vec<[f64; 3]>,
    w: Vec<[f64; 3]>,
}

/// Rest, turn, rest, …: `q` is body → level frame (z up), the specific force `qᵀ(0, 0, g)`; a
/// turn from `q_a` to `q_b` about the body axis of `q_a⁻¹q_b`, angle by the quintic smoothstep.
fn procedure(q: &[UnitQuaternion<f64>]) -> Procedure {
    let (nr, nt) = ((REST_S * RATE_HZ) as usize, (TURN_S * RATE_HZ) as usize);
    let mut p = Procedure {
        t: Vec::new(),
        f: Vec::new(),
        w: Vec::new(),
    };
    let mut push = |att: &UnitQuaternion<f64>, w: Vector3<f64>| {
        p.t.push(p.t.len() as f64 / RATE_HZ);
        p.f.push((att.inverse() * Vector3::new(0.0, 0.0, G)).into());
        p.w.push(w.into());
    };
    for (k, qa) in q.iter().enumerate() {
        for _ in 0..nr {
            push(qa, Vector3::zeros());
        }
        let Some(qb) = q.get(k + 1) else { break };
        let rel = qa.inverse() * qb;
        let (axis, angle) = rel.axis_angle().unwrap();
        for j in 0..nt {
            let s = j as f64 / nt as f64;
            let (pos, vel) = (
                s * s * s * (10.0 - 15.0 * s + 6.0 * s * s),
                30.0 * s * s * (1.0 - s) * (1.0 - s) / TURN_S,
            );
            let att = qa * UnitQuaternion::from_axis_angle(&axis, angle * pos);
            push(&att, axis.into_inner() * angle * vel);
        }
    }
    p
}

struct Part {
    ma: Matrix3<f64>,
    ba: Vector3<f64>,
    mg: Matrix3<f64>,
    bg: Vector3<f64>,
}

fn part() -> Part {
    Part {
        ma: Matrix3::new(
            1.02, 0.01, -0.004, -0.006, 0.985, 0.008, 0.003, -0.012, 1.01,
        ),
        ba: Vector3::new(0.15, -0.2, 0.3),
        mg: Matrix3::new(
            0.99, -0.015, 0.006, 0.01, 1.03, -0.004, -0.007, 0.009, 0.995,
        ),
        bg: Vector3::new(0.01, -0.02, 0.005),
    }
}

/// Readings `M x + b + σ n`.
fn read(
    x: &[[f64; 3]],
    m: &Matrix3<f64>,
    b: &Vector3<f64>,
    sigma: f64,
    noise: &mut SeededNormals,
) -> Vec<[f64; 3]> {
    x.iter()
        .map(|v| {
            let n = Vector3::from_fn(|_, _| noise.standard_normal());
            (m * Vector3::from(*v) + b + n * sigma).into()
        })
        .collect()
}

struct Truth {
    a: Matrix3<f64>,
    g: Matrix3<f64>,
}

fn truth(p: &Part) -> Truth {
    let qr = p.ma.try_inverse().unwrap().qr();
    let (mut q, mut u) = (qr.q(), qr.r());
    for i in 0..3 {
        if u[(i, i)] < 0.0 {
            u.row_mut(i).neg_mut();
            q.column_mut(i).neg_mut();
        }
    }
    Truth {
        a: u,
        g: q.transpose() * p.mg.try_inverse().unwrap(),
    }
}

/// Rests, accelerometer and gyroscope calibration of one procedure read with noise `sa`, `sg`.
fn calibrate(
    k: usize,
    sa: f64,
    sg: f64,
    seed: u64,
) -> (
    Vec<Rest>,
    accelerometer::AccelCalibration,
    gyroscope::GyroCalibration,
) {
    let p = part();
    let proc = procedure(&orientations(k));
    let mut noise = SeededNormals::new(seed);
    let accel = read(&proc.f, &p.ma, &p.ba, sa, &mut noise);
    let gyro = read(&proc.w, &p.mg, &p.bg, sg, &mut noise);
    let window = 25;
    let learnt = if sa > 0.0 {
        let mut blocks = vec![[0.0; 3]; accel.len() / window];
        quiet_noise(&accel, &gyro, window, G, &mut blocks)
            .unwrap()
            .noise
    } else {
        ReadingNoise {
            accel: 1e-9,
            gyro: 1e-9,
        }
    };
    let mut found = Vec::new();
    rests(&accel, &gyro, window, learnt, 2, |r| found.push(r));
    let means: Vec<[f64; 3]> = found.iter().map(|r| r.mean(&accel)).collect();
    let shortest = found.iter().map(Rest::len).min().unwrap() as f64;
    let a = accelerometer::calibrate(&means, G, learnt.accel / shortest.sqrt()).unwrap();
    let g = gyroscope::calibrate(&gyroscope::GyroInputs {
        t_s: &proc.t,
        gyro: &gyro,
        rests: &found,
        accel_means: &means,
        accel: &a,
        noise: learnt,
    })
    .unwrap();
    (found, a, g)
}

#[test]
fn without_noise_every_term_comes_back_exact() {
    let p = part();
    let t = truth(&p);
    let (found, a, g) = calibrate(16, 0.0, 0.0, 1);
    assert_eq!(found.len(), 16, "{found:?}");
    assert!(a.full);
    for i in 0..3 {
        assert!((a.correction.bias[i] - p.ba[i]).abs() < 1e-9, "{a:?}");
        assert!((g.correction.bias[i] - p.bg[i]).abs() < 1e-12, "{g:?}");
        for j in 0..3 {
            assert!(
                (a.correction.matrix[i][j] - t.a[(i, j)]).abs() < 1e-9,
                "{a:?}"
            );
            assert!(
                (g.correction.matrix[i][j] - t.g[(i, j)]).abs() < 1e-7,
                "{g:?} vs {}",
                t.g
            );
        }
    }
    assert!(a.residual_rms_m_s2 < 1e-9 && g.residual_rms_rad < 1e-7);
}

#[test]
fn with_noise_each_term_lies_within_its_stated_uncertainty() {
    let p = part();
    let t = truth(&p);
    // A consumer part's white noise: 0.02 m/s² and 0.002 rad/s a sample.
    let (mut inside, mut total, mut z2) = (0, 0, 0.0);
    for seed in 0..10 {
        let (found, a, g) = calibrate(16, 0.02, 0.002, seed);
        assert_eq!(found.len(), 16);
        let mut count = |est: f64, truth: f64, sigma: f64| {
            assert!(sigma > 0.0);
            total += 1;
            z2 += ((est - truth) / sigma).powi(2);
            if (est - truth).abs() <= 3.0 * sigma {
                inside += 1;
            }
        };
        for i in 0..3 {
            count(a.correction.bias[i], p.ba[i], a.bias_sigma[i]);
            count(g.correction.bias[i], p.bg[i], g.bias_sigma[i]);
            for j in 0..3 {
                if j >= i {
                    count(a.correction.matrix[i][j], t.a[(i, j)], a.matrix_sigma[i][j]);
                }
                count(g.correction.matrix[i][j], t.g[(i, j)], g.matrix_sigma[i][j]);
            }
        }
        // The residual at the noise: the magnitude's scatter is σ/√n of a rest's mean.
        let n = found[0].len() as f64;
        assert!(
            a.residual_rms_m_s2 < 3.0 * 0.02 / n.sqrt(),
            "{}",
            a.residual_rms_m_s2
        );
    }
    assert!(
        inside as f64 >= 0.95 * total as f64,
        "{inside} of {total} terms within 3σ"
    );
    // Neither too small nor inflated: the errors' RMS in units of their σ is about 1 (the
    // 210 terms of ten runs are correlated within a run, hence the wide band).
    let rms = (z2 / total as f64).sqrt();
    assert!((0.6..1.5).contains(&rms), "RMS of error/σ {rms}");
}

#[test]
fn few_rests_fit_scale_and_bias_and_too_few_are_refused() {
    let (found, a, _) = calibrate(8, 0.0, 0.0, 1);
    assert_eq!(found.len(), 8);
    assert!(!a.full);
    assert_eq!(a.correction.matrix[0][1], 0.0);
    let e = accelerometer::calibrate(&[[0.0, 0.0, 9.81]; 5], G, 0.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "5 static intervals found, the fit needs at least 7: set the part down in more orientations, longer"
    );
}

#[test]
fn a_sphere_seen_through_hard_and_soft_iron_is_fitted_back() {
    // Directions on a spiral, a 48 µT field, soft iron S (symmetric) and hard iron h.
    let s = Matrix3::new(1.1, 0.05, -0.02, 0.05, 0.95, 0.03, -0.02, 0.03, 1.02);
    let h = Vector3::new(12.0, -30.0, 5.0);
    let mut noise = SeededNormals::new(3);
    let n = 400;
    let readings: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let phi = i as f64 * 2.399_963_229_728_653;
            let u = Vector3::new(
                (1.0 - z * z).sqrt() * phi.cos(),
                (1.0 - z * z).sqrt() * phi.sin(),
                z,
            );
            let e = Vector3::from_fn(|_, _| noise.standard_normal()) * 0.1;
            (s * u * 48.0 + h + e).into()
        })
        .collect();
    let c = magnetometer::calibrate(&readings).unwrap();
    // C = S⁻¹ scaled to determinant 1, B = 48·det(S)^{1/3}.
    let expected = s.try_inverse().unwrap() * s.determinant().cbrt();
    let field = 48.0 * s.determinant().cbrt();
    for i in 0..3 {
        assert!(
            (c.correction.bias[i] - h[i]).abs() < 4.0 * c.bias_sigma[i],
            "{c:?}"
        );
        for j in 0..3 {
            assert!(
                (c.correction.matrix[i][j] - expected[(i, j)]).abs() < 4.0 * c.matrix_sigma[i][j],
                "{c:?} vs {expected}"
            );
        }
    }
    assert!((c.field_ut - field).abs() < 4.0 * c.field_sigma_ut);
    // 0.1 µT of noise on 48 µT: a fit error of about 0.1/48/√3.
    assert!(
        c.fit_error > 0.0005 && c.fit_error < 0.003,
        "{}",
        c.fit_error
    );
    assert!(Matrix3::from_fn(|i, j| c.correction.matrix[i][j]).determinant() - 1.0 < 1e-12);
    // A flat turn (all readings in one plane) is not an ellipsoid.
    let flat: Vec<[f64; 3]> = readings.iter().map(|m| [m[0], m[1], 5.0]).collect();
    assert!(magnetometer::calibrate(&flat).is_err());
}
