//! The EuRoC/TUM-VI ASL layout read by its header: a simulated run written as a EuRoC sequence
//! (`imu0/data.csv`, `state_groundtruth_estimate0/data.csv`, stamps in integer nanoseconds since
//! the epoch) reads back with every reading bit for bit and every stamp to the nanosecond, and
//! integrates to the numbers of the run itself.
use std::fmt::Write as _;
use std::path::Path;

use imukit::ScenarioSpec;
use imukit::io::asl::{seconds_after, time_origin_ns};
use imukit::io::read::read_table;
use imukit::run::compare::compare;
use imukit::run::navigate::{InitialState, NavSetup, integrate};

/// EuRoC MH_01_easy's first IMU stamp, ns.
const FIRST_NS: i64 = 1_403_636_579_758_555_392;

const IMU_HEADER: &str = "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],\
    w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]";
const TRUTH_HEADER: &str = "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], \
    q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], \
    b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], \
    b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]";

fn simulation() -> imukit::Simulation {
    let text = "rate_hz = 200.0\nduration_s = 20.0\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"3*cos(0.4*t)\", \"3*sin(0.4*t)\", \"0.2*sin(0.3*t)\"]\n\
         yaw_rad = \"0.4*t + pi/2\"\npitch_rad = \"0.05\"\nroll_rad = \"0.3*sin(1.1*t)\"\n[imu]\n";
    ScenarioSpec::from_toml(text, "t")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate()
        .unwrap()
}

/// Stamps of the simulation's times: EuRoC's first stamp plus each time to the nanosecond,
/// with a few microseconds of jitter (a real logger's).
fn stamps(t: &[f64]) -> Vec<i64> {
    t.iter()
        .enumerate()
        .map(|(k, &t)| FIRST_NS + (t * 1e9).round() as i64 + [0, 3_001, -2_517, 811][k % 4])
        .collect()
}

fn columns(table: &imukit::Table, names: &[&str]) -> Vec<Vec<f64>> {
    names.iter().map(|n| table.column(n).unwrap()).collect()
}

fn write_asl(path: &Path, header: &str, stamps: &[i64], values: &[Vec<f64>], extra: usize) {
    let mut text = format!("{header}\r\n");
    for (k, s) in stamps.iter().enumerate() {
        write!(text, "{s}").unwrap();
        for v in values {
            write!(text, ",{}", v[k]).unwrap();
        }
        for _ in 0..extra {
            text.push_str(",0.0");
        }
        text.push_str("\r\n");
    }
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

#[test]
fn a_euroc_sequence_reads_back_exactly_and_navigates_as_the_run() {
    let sim = simulation();
    let dir = tempfile::tempdir().unwrap();
    let (imu_path, truth_path) = (
        dir.path().join("mav0/imu0/data.csv"),
        dir.path().join("mav0/state_groundtruth_estimate0/data.csv"),
    );
    let t = sim.imu.column("t_s").unwrap();
    let ns = stamps(&t);
    let imu_names = [
        "gyro_x_rad_s",
        "gyro_y_rad_s",
        "gyro_z_rad_s",
        "accel_x_m_s2",
        "accel_y_m_s2",
        "accel_z_m_s2",
    ];
    write_asl(
        &imu_path,
        IMU_HEADER,
        &ns,
        &columns(&sim.imu, &imu_names),
        0,
    );
    let truth_names = [
        "pos_x_m",
        "pos_y_m",
        "pos_z_m",
        "q_w",
        "q_x",
        "q_y",
        "q_z",
        "vel_x_m_s",
        "vel_y_m_s",
        "vel_z_m_s",
    ];
    // The ground truth starts 0.5 s later, as EuRoC's does, so it sets the same origin only if
    // the rule is the day's and not the file's.
    let late = 100;
    let truth_values: Vec<Vec<f64>> = columns(&sim.truth, &truth_names)
        .into_iter()
        .map(|c| c[late..].to_vec())
        .collect();
    write_asl(&truth_path, TRUTH_HEADER, &ns[late..], &truth_values, 6);

    let imu = read_table(&imu_path).unwrap();
    assert_eq!(imu.columns[0], "t_s");
    assert_eq!(imu.columns[1..], imu_names);
    // Readings bit for bit; stamps to the nanosecond.
    assert_eq!(columns(&imu, &imu_names), columns(&sim.imu, &imu_names));
    let origin = time_origin_ns(FIRST_NS);
    let back: Vec<i64> = imu
        .column("t_s")
        .unwrap()
        .iter()
        .map(|t| (t * 1e9).round() as i64 + origin)
        .collect();
    assert_eq!(back, ns);
    let truth = read_table(&truth_path).unwrap();
    assert_eq!(
        truth.column("t_s").unwrap()[0],
        seconds_after(ns[late], origin)
    );
    assert_eq!(truth.columns[11], "b_w_RS_S_x");

    // The sequence navigates as the run: from the ground truth's first row, over the IMU rows
    // from there on. The stamps' jitter is what separates the two: each reading is dated up to
    // δ = 3 µs off, so the velocity is off by at most |f|·δ (the Δv of each interval telescopes)
    // and the position by |f|·δ·T over the T = 19.5 s, with |f| ≤ 9.9 m/s² here: 5.8e-4 m.
    let from = |table: &imukit::Table, first: usize| {
        let mut cut =
            imukit::Table::new(&table.columns.iter().map(String::as_str).collect::<Vec<_>>());
        let w = table.columns.len();
        for r in first..table.rows() {
            cut.push_row(&table.data[r * w..(r + 1) * w]);
        }
        cut
    };
    let setup = NavSetup {
        scheme: imukit::run::navigate::NavScheme::Rk4 { substeps: 4 },
        ..NavSetup::default()
    };
    let nav = integrate(
        &from(&imu, late),
        &InitialState::from_table(&truth).unwrap(),
        &setup,
    )
    .unwrap();
    let errors = compare(&truth, &nav).unwrap();
    let own = integrate(
        &from(&sim.imu, late),
        &InitialState::from_table(&from(&sim.truth, late)).unwrap(),
        &setup,
    )
    .unwrap();
    let own_errors = compare(&from(&sim.truth, late), &own).unwrap();
    let worst = |e: &imukit::run::compare::Comparison| e.summary.position.unwrap().max();
    assert!(worst(&own_errors) < 1e-9, "{:e} m", worst(&own_errors));
    assert!(
        worst(&errors) < 9.9 * 3.0e-6 * 19.5,
        "{:e} m",
        worst(&errors)
    );
}

#[test]
fn a_sequence_that_crosses_midnight_keeps_one_time_origin() {
    let dir = tempfile::tempdir().unwrap();
    let (imu_path, truth_path) = (
        dir.path().join("mav0/imu0/data.csv"),
        dir.path().join("mav0/state_groundtruth_estimate0/data.csv"),
    );
    // The IMU starts 0.2 s before a UTC midnight, the ground truth 0.5 s after it.
    let midnight = time_origin_ns(FIRST_NS) + imukit::io::asl::DAY_NS;
    let imu_ns: Vec<i64> = (0..200)
        .map(|k| midnight - 200_000_000 + k * 5_000_000)
        .collect();
    let truth_ns: Vec<i64> = (0..10)
        .map(|k| midnight + 500_000_000 + k * 5_000_000)
        .collect();
    let zeros = |n: usize, columns: usize| vec![vec![0.0; n]; columns];
    write_asl(&imu_path, IMU_HEADER, &imu_ns, &zeros(imu_ns.len(), 6), 0);
    let mut truth_values = zeros(truth_ns.len(), 10);
    truth_values[3] = vec![1.0; truth_ns.len()]; // q_w
    write_asl(&truth_path, TRUTH_HEADER, &truth_ns, &truth_values, 6);
    let imu = read_table(&imu_path).unwrap();
    let truth = read_table(&truth_path).unwrap();
    let origin = midnight - imukit::io::asl::DAY_NS;
    // Both count from the midnight before the sequence's first stamp: 0.7 s apart, as recorded.
    assert_eq!(
        imu.column("t_s").unwrap()[0],
        seconds_after(imu_ns[0], origin)
    );
    assert_eq!(
        truth.column("t_s").unwrap()[0],
        seconds_after(truth_ns[0], origin)
    );
    assert!((truth.column("t_s").unwrap()[0] - imu.column("t_s").unwrap()[0] - 0.7).abs() < 1e-9);
    // A file alone (outside a sequence's mav0 folder) counts from its own midnight.
    let alone = dir.path().join("alone.csv");
    std::fs::copy(&truth_path, &alone).unwrap();
    assert_eq!(read_table(&alone).unwrap().column("t_s").unwrap()[0], 0.5);
}
