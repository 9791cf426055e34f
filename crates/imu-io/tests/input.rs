//! How a file is read travels with it as one argument ([`imu_io::Input`]): a column map given to
//! one reader changes nothing that another reader of the same file sees, also at the same time
//! on another thread.
use std::path::Path;

use imu_io::Input;
use imu_io::column_map::ColumnMap;
use imu_io::read::{read_header, read_table};

const MAP: &str = r#"
time = { column = "Timestamp", unit = "ms" }
accel = { columns = ["AccX", "AccY", "AccZ"], unit = "g" }
"#;

/// A vendor's log: milliseconds and g.
fn vendor_log(path: &Path, rows: usize) {
    let mut text = String::from("Timestamp,AccX,AccY,AccZ\n");
    for k in 0..rows {
        text.push_str(&format!("{},0,0,1\n", 10 * k));
    }
    std::fs::write(path, text).expect("written");
}

#[test]
fn a_map_given_on_one_thread_changes_nothing_another_reads() {
    let dir = tempfile::tempdir().expect("a folder");
    let path = dir.path().join("log.csv");
    vendor_log(&path, 200);
    let map = ColumnMap::from_toml(MAP, "map.toml").expect("a map");
    let mapped = Input::new(&path).with_map(map);
    std::thread::scope(|s| {
        let through_map = s.spawn(|| {
            for _ in 0..50 {
                let t = read_table(&mapped).expect("read through the map");
                assert_eq!(
                    t.columns,
                    ["t_s", "accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]
                );
                let z = t.column("accel_z_m_s2").expect("z");
                // 1 g in m/s² (the map's unit, standard gravity), ms in s.
                assert!(z.iter().all(|v| (v - 9.806_65).abs() < 1e-12), "{}", z[0]);
                assert_eq!(t.column("t_s").expect("t")[1], 0.01);
            }
        });
        let plain = s.spawn(|| {
            for _ in 0..50 {
                assert_eq!(
                    read_header(&path).expect("the header"),
                    ["Timestamp", "AccX", "AccY", "AccZ"]
                );
                let t = read_table(&path).expect("read as it is");
                assert_eq!(t.column("AccZ").expect("z")[0], 1.0);
                assert_eq!(t.column("Timestamp").expect("t")[1], 10.0);
            }
        });
        through_map.join().expect("the mapped reader");
        plain.join().expect("the plain reader");
    });
    // And after both: the path alone is still the file as it is.
    assert_eq!(read_header(&path).expect("header")[0], "Timestamp");
}
