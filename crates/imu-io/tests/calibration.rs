//! A part's calibration applied as readings are read (`--calibration FILE`): one axis asked
//! for reads the other two to correct it, a whole table is corrected, a sensor the file does
//! not calibrate is read as it is, and a calibrated sensor without all its columns is refused.
use imu_core::calibration::Correction;
use imu_io::calibration::CalibrationFile;

#[test]
fn readings_are_read_corrected_one_axis_asked_for_or_all() {
    let dir = tempfile::Builder::new()
        .prefix("imukit-calibration-")
        .tempdir()
        .unwrap();
    let path = dir.path().join("imu.csv");
    std::fs::write(
        &path,
        "t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s\n\
         0,0.1,0.2,9.9,0.01,0.02,0.03\n0.01,0.3,-0.1,9.7,-0.01,0.0,0.05\n",
    )
    .unwrap();
    let gyro = Correction {
        matrix: [[1.0, 0.1, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]],
        bias: [0.01, 0.0, 0.0],
    };
    let file = CalibrationFile {
        corrections: [None, Some(gyro), None],
    };
    let input = imu_io::input::Input::new(&path).with_calibration(file.clone());
    // One axis asked for: its other two are read to correct it.
    let x = imu_io::read::read_columns(input.clone(), &["gyro_x_rad_s"], "").unwrap();
    assert_eq!(x.get("gyro_x_rad_s"), [0.0 + 0.1 * 0.02, -0.02].as_slice());
    let whole = imu_io::read::read_table(input).unwrap();
    let col = |n: &str| whole.column(n).unwrap().to_vec();
    assert_eq!(col("gyro_y_rad_s"), vec![0.04, 0.0]);
    assert_eq!(
        col("accel_z_m_s2"),
        vec![9.9, 9.7],
        "a sensor not in the file is read as it is"
    );
    // A calibrated sensor without all its columns is refused by name.
    std::fs::write(&path, "t_s,gyro_x_rad_s\n0,1\n").unwrap();
    let e = imu_io::read::read_columns(
        imu_io::input::Input::new(&path).with_calibration(file),
        &["gyro_x_rad_s"],
        "",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("gyro_y_rad_s") && e.contains("corrects"), "{e}");
}

#[test]
fn a_correction_that_overflows_a_reading_is_refused_by_row_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("imu.csv");
    std::fs::write(
        &path,
        "t_s,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s\n0,0,0,0\n0.01,1e10,0,0\n",
    )
    .unwrap();
    let file = CalibrationFile {
        corrections: [
            None,
            Some(Correction {
                matrix: [[1e300, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                bias: [0.0; 3],
            }),
            None,
        ],
    };
    let input = imu_io::input::Input::new(&path).with_calibration(file);
    let e = imu_io::read::read_columns(input.clone(), &["t_s", "gyro_y_rad_s"], "")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("row 3")
            && e.contains("gyro_x_rad_s")
            && e.contains("corrected by the calibration"),
        "{e}"
    );
    let mut table = imu_io::read::read_table(imu_io::input::Input::new(&path)).unwrap();
    let e = input
        .calibration()
        .unwrap()
        .apply_to_table(&mut table, "imu.csv")
        .unwrap_err()
        .to_string();
    assert!(e.contains("imu.csv, row 3, column gyro_x_rad_s"), "{e}");
}
