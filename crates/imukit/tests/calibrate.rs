//! `imukit calibrate` on simulated procedures: a part of each grade (a consumer, an industrial
//! and a tactical preset's noise), its bias and misalignment drawn anew for each of 50 seeded
//! runs, set down in 18 positions (`type = "positions"`); every estimated term lies within its
//! stated 3σ in at least 95 % of the runs, and the calibrated readings at the rests read gravity
//! to within the part's noise. The procedure itself: rests at rest, the positions' attitudes, the
//! count refused by key. A magnetometer turned through all directions comes back with its hard
//! and soft iron.
use imu_core::sensor::{NoiseSource, SeededNormals};
use imukit::calibrate::calibrate_table;
use imukit::{Scenario, ScenarioSpec};
use nalgebra::{Matrix3, Vector3};

fn scenario(text: &str) -> Scenario {
    ScenarioSpec::from_toml(text, "procedure")
        .unwrap()
        .resolve(std::path::Path::new("."))
        .unwrap()
}

fn matrix_text(m: &Matrix3<f64>) -> String {
    let row = |i: usize| format!("[{}, {}, {}]", m[(i, 0)], m[(i, 1)], m[(i, 2)]);
    format!("[{}, {}, {}]", row(0), row(1), row(2))
}

/// A drawn part: misalignment (percent, `100·I` plus the errors) and bias of each sensor.
struct Part {
    ma: Matrix3<f64>,
    ba: Vector3<f64>,
    mg: Matrix3<f64>,
    bg: Vector3<f64>,
}

/// The part of run `run`: scale and misalignment errors of σ `m` (a fraction), biases of σ
/// `sa` (m/s²) and `sg` (rad/s).
fn draw(run: u64, m: f64, sa: f64, sg: f64) -> Part {
    let mut n = SeededNormals::new(1000 + run);
    let mat = |n: &mut SeededNormals| {
        Matrix3::identity() + Matrix3::from_fn(|_, _| m * n.standard_normal())
    };
    let ma = mat(&mut n);
    let mg = mat(&mut n);
    let ba = Vector3::from_fn(|_, _| sa * n.standard_normal());
    let bg = Vector3::from_fn(|_, _| sg * n.standard_normal());
    Part { ma, ba, mg, bg }
}

/// The truth in the calibrated frame: `U` of `M_a⁻¹ = QU`, and `QᵀM_g⁻¹`.
fn truth(p: &Part) -> (Matrix3<f64>, Matrix3<f64>) {
    let qr = p.ma.try_inverse().unwrap().qr();
    let (mut q, mut u) = (qr.q(), qr.r());
    for i in 0..3 {
        if u[(i, i)] < 0.0 {
            u.row_mut(i).neg_mut();
            q.column_mut(i).neg_mut();
        }
    }
    (u, q.transpose() * p.mg.try_inverse().unwrap())
}

/// For each of the 21 terms (accelerometer bias and upper triangle, gyroscope bias and matrix)
/// the share of `runs` procedures with the noise of `preset` (whose accelerometer's bias
/// instability is `instability`, m/s²) in which it lies within its stated 3σ.
fn coverage(preset: &str, runs: u64, m: f64, sa: f64, sg: f64, instability: f64) -> Vec<f64> {
    let mut inside = [0usize; 21];
    for run in 0..runs {
        let p = draw(run, m, sa, sg);
        let text = format!(
            "rate_hz = 100\n[trajectory]\ntype = \"positions\"\ncount = 18\nrest_s = 4\nturn_s = 2\n\
             [imu]\nkind = \"accel-gyro\"\npreset = \"{preset}\"\nseed = {run}\n\
             [imu.accelerometer]\nconstant_bias_m_s2 = [{}, {}, {}]\naxes_misalignment_pct = {}\n\
             temperature_bias_m_s2_per_c = 0\ntemperature_scale_factor_pct_per_c = 0\n\
             [imu.gyroscope]\nconstant_bias_rad_s = [{}, {}, {}]\naxes_misalignment_pct = {}\n\
             acceleration_bias_rad_s_per_m_s2 = 0\ntemperature_bias_rad_s_per_c = 0\n\
             temperature_scale_factor_pct_per_c = 0\n",
            p.ba[0],
            p.ba[1],
            p.ba[2],
            matrix_text(&(p.ma * 100.0)),
            p.bg[0],
            p.bg[1],
            p.bg[2],
            matrix_text(&(p.mg * 100.0)),
        );
        let sim = scenario(&text).simulate().unwrap();
        let r = calibrate_table(&sim.imu, 9.81, "procedure").unwrap();
        assert_eq!(
            r.rests.len(),
            18,
            "{preset} run {run}: {:?} {:?}",
            r.rests,
            r.noise
        );
        let (a, g) = (r.accelerometer.unwrap(), r.gyroscope.unwrap());
        assert!(a.full);
        let (ta, tg) = truth(&p);
        let mut term = 0;
        let mut count = |est: f64, truth: f64, sigma: f64| {
            if (est - truth).abs() <= 3.0 * sigma {
                inside[term] += 1;
            }
            term += 1;
        };
        for i in 0..3 {
            count(a.correction.bias[i], p.ba[i], a.bias_sigma[i]);
            count(g.correction.bias[i], p.bg[i], g.bias_sigma[i]);
            for j in 0..3 {
                if j >= i {
                    count(a.correction.matrix[i][j], ta[(i, j)], a.matrix_sigma[i][j]);
                }
                count(g.correction.matrix[i][j], tg[(i, j)], g.matrix_sigma[i][j]);
            }
        }
        // The calibrated rests read gravity to within the part's noise: a rest's mean has the
        // white noise over √n and the bias's wander (its instability), so the magnitudes' RMS
        // residual is about their sum (well under 3×).
        let noise = r.noise.unwrap().accel;
        let n = r.rests.iter().map(|x| x.len()).min().unwrap() as f64;
        let expected = (noise * noise / n + instability * instability).sqrt();
        assert!(
            a.residual_rms_m_s2 < 3.0 * expected,
            "{preset} run {run}: residual {} against the part's {expected}",
            a.residual_rms_m_s2,
        );
    }
    inside.iter().map(|&k| k as f64 / runs as f64).collect()
}

#[test]
fn every_term_lies_within_its_stated_3_sigma_in_95_percent_of_runs_for_each_grade() {
    // Each preset's accelerometer bias instability: the MPU-6050's data sheet gives none.
    for (preset, m, sa, sg, instability) in [
        ("mpu-6050", 0.02, 0.5, 0.2, 0.0),
        ("mti-1", 0.002, 0.02, 0.002, 0.000442883),
        ("stim300", 0.0005, 0.005, 1e-4, 0.000738139),
    ] {
        let shares = coverage(preset, 50, m, sa, sg, instability);
        let worst = shares.iter().copied().fold(1.0, f64::min);
        assert!(
            worst >= 0.95,
            "{preset}: within 3σ in {shares:?} of the runs, term by term"
        );
    }
}

#[test]
fn the_procedure_rests_in_its_positions_and_refuses_a_count_out_of_range() {
    let sim = scenario(
        "rate_hz = 50\n[trajectory]\ntype = \"positions\"\ncount = 6\nrest_s = 2\nturn_s = 1\n\
         [imu]\nkind = \"accel-gyro\"\n",
    )
    .simulate()
    .unwrap();
    let t = sim.truth.column("t_s").unwrap();
    // 6 rests of 2 s and 5 turns of 1 s.
    assert!(
        (t.last().unwrap() - 17.0).abs() < 1e-9,
        "{}",
        t.last().unwrap()
    );
    let rate = |name: &str| sim.truth.column(name).unwrap();
    let (wx, wy, wz) = (
        rate("omega_x_rad_s"),
        rate("omega_y_rad_s"),
        rate("omega_z_rad_s"),
    );
    let (pitch, roll) = (rate("pitch_rad"), rate("roll_rad"));
    for (k, (p, r)) in [
        (0.0, 0.0),
        (0.0, 90.0),
        (0.0, 180.0),
        (0.0, -90.0),
        (70.0, 0.0),
        (-70.0, 0.0),
    ]
    .iter()
    .enumerate()
    {
        // The middle of rest k: still, at the table's pitch and roll.
        let i = ((3.0 * k as f64 + 1.0) * 50.0) as usize;
        assert!(wx[i].abs() + wy[i].abs() + wz[i].abs() < 1e-12, "rest {k}");
        assert!(
            (pitch[i].to_degrees() - p).abs() < 1e-9,
            "rest {k}: pitch {}",
            pitch[i]
        );
        let dr = (roll[i].to_degrees() - r).rem_euclid(360.0);
        assert!(dr.min(360.0 - dr) < 1e-9, "rest {k}: roll {}", roll[i]);
    }
    // A turn moves: its middle turns.
    let mid = (2.5 * 50.0) as usize;
    assert!(wx[mid].abs() + wy[mid].abs() + wz[mid].abs() > 0.1);
    let e = ScenarioSpec::from_toml(
        "rate_hz = 50\n[trajectory]\ntype = \"positions\"\ncount = 30\n[imu]\nkind = \"accel-gyro\"\n",
        "s",
    )
    .and_then(|s| s.resolve(std::path::Path::new(".")))
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("trajectory.count: must be 6 to 24 positions, got 30"),
        "{e}"
    );
}

#[test]
fn a_magnetometer_turned_through_all_directions_gives_back_its_hard_and_soft_iron() {
    // A tumble (yaw, pitch and roll at unrelated rates) of a magnetometer with hard iron h and
    // soft iron S (the readings S·m + h).
    let text = "rate_hz = 50\nduration_s = 120\n[trajectory]\ntype = \"expression\"\n\
                position_m = [0, 0, 0]\nyaw_rad = \"0.31*t\"\npitch_rad = \"1.2*sin(0.173*t)\"\n\
                roll_rad = \"0.57*t\"\n[imu]\nkind = \"accel-gyro-mag\"\nseed = 3\n\
                [imu.magnetometer]\nconstant_bias_ut = [12, -30, 5]\n\
                axes_misalignment_pct = [[110, 5, -2], [5, 95, 3], [-2, 3, 102]]\n\
                noise_density_ut_per_rt_hz = 0.02\n";
    let sim = scenario(text).simulate().unwrap();
    let r = calibrate_table(&sim.imu, 9.81, "tumble").unwrap();
    let m = r.magnetometer.unwrap();
    let s: Matrix3<f64> = Matrix3::new(1.10, 0.05, -0.02, 0.05, 0.95, 0.03, -0.02, 0.03, 1.02);
    let expected = s.try_inverse().unwrap() * s.determinant().cbrt();
    for i in 0..3 {
        let h = [12.0, -30.0, 5.0][i];
        assert!(
            (m.correction.bias[i] - h).abs() < 4.0 * m.bias_sigma[i],
            "{m:?}"
        );
        for j in 0..3 {
            assert!(
                (m.correction.matrix[i][j] - expected[(i, j)]).abs() < 4.0 * m.matrix_sigma[i][j],
                "{m:?} vs {expected}"
            );
        }
    }
    // The field's strength: the scenario's field (ENU default) through S, volume kept.
    let field = <imu_core::Enu as imu_core::NavFrame>::default_magnetic_field_ut().norm()
        * s.determinant().cbrt();
    assert!(
        (m.field_ut - field).abs() < 4.0 * m.field_sigma_ut,
        "{} vs {field}",
        m.field_ut
    );
}
