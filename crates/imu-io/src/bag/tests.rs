//! Bags written and read back: every topic, the table a reader picks, the clocks, damaged files.
use std::collections::BTreeMap;
use std::path::Path;

use super::decode::rotate;
use super::*;
use crate::asl::stamp_ns;
use crate::columns::{ACCEL_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS};
use crate::description::Description;
use crate::input::{Clock, Input, Selection};
use crate::table::Table;

fn write_bag(path: &Path, tables: &[&Table], description: &Description) {
    super::writer::write_bag_file(path, tables, description, &BagOptions::default());
}

fn readings(rows: usize, mag: bool) -> Table {
    let mut columns = vec!["t_s"];
    columns.extend(ACCEL_COLUMNS);
    columns.extend(GYRO_COLUMNS);
    if mag {
        columns.extend(MAG_COLUMNS);
    }
    let mut t = Table::new(&columns);
    for k in 0..rows {
        let x = k as f64;
        let mut row = vec![
            x * 0.01,
            0.1 + x,
            -9.8,
            1e-3 * x,
            0.3,
            -0.2,
            1.0 / (x + 3.0),
        ];
        if mag {
            row.extend([20.0 + x, -3.5, 41.25]);
        }
        t.push_row(&row);
    }
    t
}

#[test]
fn readings_come_back_bit_for_bit_and_stamps_to_the_nanosecond() {
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("run.mcap");
    let imu = readings(250, true);
    write_bag(&path, &[&imu], &Description::default());
    assert_eq!(&std::fs::read(&path).expect("read")[..8], b"\x89MCAP0\r\n");
    let contents = read(&path).expect("read");
    let names: Vec<&str> = contents.topics.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["/imu", "/imu/mag"]);
    let back = contents
        .table(&[])
        .expect("the IMU topic, its magnetometer merged");
    assert_eq!(back.columns, imu.columns);
    let w = imu.columns.len();
    for (a, b) in imu.data.chunks(w).zip(back.data.chunks(w)) {
        assert_eq!(stamp_ns(a[0]), stamp_ns(b[0]));
        assert_eq!(a[1..7], b[1..7], "accelerometer and gyroscope bit for bit");
        for (x, y) in a[7..].iter().zip(&b[7..]) {
            assert!((x - y).abs() <= 1e-15 * x.abs(), "{x} {y}");
        }
    }
    // The magnetometer alone, when named.
    let named = |topic: &str| {
        Input::new(&path).with_selection(Selection {
            topics: vec![topic.into()],
            clock: Clock::Header,
        })
    };
    let mag = read_table(named("/imu/mag"), &[]).expect("named");
    assert_eq!(mag.columns, ["t_s", "mag_x_ut", "mag_y_ut", "mag_z_ut"]);
    let e = read_table(named("/nope"), &[]).unwrap_err().to_string();
    assert!(
        e.contains("no topic /nope") && e.contains("/imu (sensor_msgs/msg/Imu, 250 messages)"),
        "{e}"
    );
    // The path alone is read as it is, whatever another reader named.
    assert_eq!(
        read_table(&path, &[]).expect("the IMU").columns,
        imu.columns
    );
}

#[test]
fn a_truth_and_fixes_come_back_and_a_reader_picks_by_columns() {
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("run.mcap");
    let mut truth = Table::new(&[
        "t_s",
        "pos_x_m",
        "pos_y_m",
        "pos_z_m",
        "vel_x_m_s",
        "vel_y_m_s",
        "vel_z_m_s",
        "q_w",
        "q_x",
        "q_y",
        "q_z",
    ]);
    let (c, s) = (0.6_f64.cos(), 0.6_f64.sin());
    truth.push_row(&[0.0, 1.0, 2.0, 3.0, 4.0, -5.0, 0.5, c, 0.0, 0.0, s]);
    truth.push_row(&[0.5, 1.5, 2.0, 3.0, 4.0, -5.0, 0.5, c, s, 0.0, 0.0]);
    let mut fixes = Table::new(&[
        "t_s",
        "lat_rad",
        "lon_rad",
        "height_m",
        "vel_n_m_s",
        "vel_e_m_s",
        "vel_d_m_s",
    ]);
    fixes.push_row(&[0.0, 0.8, -0.1, 120.0, 3.0, 4.0, -0.5]);
    let imu = readings(3, false);
    write_bag(&path, &[&imu, &truth, &fixes], &Description::default());
    let contents = read(&path).expect("read");
    let t = contents.table(&["q_w"]).expect("the truth");
    assert_eq!(t.columns, truth.columns);
    for (a, b) in truth.data.iter().zip(&t.data) {
        assert!((a - b).abs() < 1e-14, "{a} {b}");
    }
    let f = contents
        .table(&["lat_rad", "vel_n_m_s"])
        .expect("the fixes");
    assert_eq!(f.columns, fixes.columns);
    for (a, b) in fixes.data.iter().zip(&f.data) {
        assert!((a - b).abs() < 1e-14, "{a} {b}");
    }
    // Several fit a reader that asks for nothing: the IMU's readings.
    assert_eq!(contents.table(&[]).expect("readings").columns, imu.columns);
    let e = contents.table(&["t_s"]).unwrap_err().to_string();
    assert!(
        e.contains("several topics fit") && e.contains("/ground_truth"),
        "{e}"
    );
    let f = contents.table_as(&[], Role::Fixes).expect("the fixes");
    assert_eq!(f.columns, fixes.columns);
    let e = contents.table(&["mag_x_ut"]).unwrap_err().to_string();
    assert!(e.contains("no topic gives the columns mag_x_ut"), "{e}");
}

#[test]
fn fixes_keep_their_accuracy_through_the_covariance() {
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("fixes.mcap");
    let mut fixes = Table::new(&[
        "t_s",
        "lat_rad",
        "lon_rad",
        "height_m",
        "horizontal_accuracy_m",
        "vertical_accuracy_m",
    ]);
    fixes.push_row(&[1.0, 0.8, -0.1, 120.0, 1.5, 3.0]);
    fixes.push_row(&[2.0, 0.8, -0.1, 121.0, 0.02, 0.05]);
    write_bag(&path, &[&fixes], &Description::default());
    let back = read_table(&path, &[]).expect("the fixes, positions only");
    assert_eq!(back.columns, fixes.columns);
    for (a, b) in fixes.data.iter().zip(&back.data) {
        assert!((a - b).abs() <= 1e-15 * a.abs().max(1.0), "{a} {b}");
    }
}

/// An MCAP file of the magic, a header and one metadata record whose key declares `key_len`
/// bytes, then the data end and footer.
fn mcap_with_metadata_key(key_len: u32) -> Vec<u8> {
    fn record(out: &mut Vec<u8>, op: u8, body: &[u8]) {
        out.push(op);
        out.extend_from_slice(&(body.len() as u64).to_le_bytes());
        out.extend_from_slice(body);
    }
    let string = |s: &[u8]| [&(s.len() as u32).to_le_bytes()[..], s].concat();
    let mut out = b"\x89MCAP0\r\n".to_vec();
    record(&mut out, 0x01, &[string(b"ros2"), string(b"x")].concat());
    let mut map = key_len.to_le_bytes().to_vec();
    map.extend_from_slice(b"abc");
    let body = [string(b"m"), (map.len() as u32).to_le_bytes().to_vec(), map].concat();
    record(&mut out, 0x0C, &body);
    record(&mut out, 0x0F, &0u32.to_le_bytes());
    record(&mut out, 0x02, &[0u8; 20]);
    out.extend_from_slice(b"\x89MCAP0\r\n");
    out
}

#[test]
fn a_length_that_does_not_fit_its_record_is_refused_before_anything_is_reserved() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("m.mcap");
    std::fs::write(&p, mcap_with_metadata_key(0xFFFF_0003)).unwrap();
    let e = read(&p).unwrap_err().to_string();
    assert!(
        e.contains("m.mcap") && e.contains("a key of the metadata declares 4294901763 bytes"),
        "{e}"
    );
    // The same record with a key that fits is read (no messages: no topic).
    std::fs::write(&p, mcap_with_metadata_key(3)).unwrap();
    let e = read(&p).map(|_| ()).map_err(|e| e.to_string());
    assert!(
        e.as_ref()
            .map_or_else(|m| !m.contains("declares"), |()| true),
        "{e:?}"
    );
    // Each kind of field is walked.
    assert!(storage::mcap_lengths_fit(0x04, &[0, 0, 0, 0, 9, 0, 0, 0]).is_err());
    assert!(storage::mcap_lengths_fit(0x01, &[1, 0, 0, 0, b'a', 0, 0, 0, 0]).is_ok());
    let mut chunk = vec![0u8; 16];
    chunk.extend_from_slice(&(u64::MAX).to_le_bytes());
    let e = storage::mcap_lengths_fit(0x06, &chunk).unwrap_err();
    assert!(e.contains("once decompressed"), "{e}");
}

#[test]
fn a_ros1_chunk_declaring_gigabytes_is_refused_before_it_is_decompressed() {
    fn field(name: &[u8], value: &[u8]) -> Vec<u8> {
        let f = [name, b"=", value].concat();
        [(f.len() as u32).to_le_bytes().to_vec(), f].concat()
    }
    let header = [
        field(b"op", &[0x05]),
        field(b"compression", b"bz2"),
        field(b"size", &u32::MAX.to_le_bytes()),
    ]
    .concat();
    let mut bag = b"#ROSBAG V2.0\n".to_vec();
    bag.extend_from_slice(&(header.len() as u32).to_le_bytes());
    bag.extend_from_slice(&header);
    bag.extend_from_slice(&4u32.to_le_bytes());
    bag.extend_from_slice(b"BZh9");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("b.bag");
    std::fs::write(&p, &bag).unwrap();
    let e = read(&p).unwrap_err().to_string();
    assert!(
        e.contains("b.bag") && e.contains("at byte 13") && e.contains("4294967295 bytes"),
        "{e}"
    );
    // A record longer than the file is refused as such.
    bag.truncate(bag.len() - 2);
    std::fs::write(&p, &bag).unwrap();
    let e = read(&p).unwrap_err().to_string();
    assert!(e.contains("past the file's end"), "{e}");
}

#[test]
fn a_sqlite_bag_whose_messages_are_a_view_is_refused_and_no_side_file_is_left() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("v.db3");
    {
        let db = rusqlite::Connection::open(&p).unwrap();
        db.execute_batch(
            "PRAGMA journal_mode=WAL;
             CREATE TABLE topics (id INTEGER, name TEXT, type TEXT, serialization_format TEXT);
             CREATE VIEW messages AS WITH RECURSIVE n(id) AS (SELECT 1 UNION ALL SELECT id + 1 FROM n)
               SELECT 1 AS topic_id, x'00' AS data, id AS timestamp, id FROM n;",
        )
        .unwrap();
    }
    for side in ["v.db3-shm", "v.db3-wal"] {
        let _ = std::fs::remove_file(dir.path().join(side));
    }
    let e = read(&p).unwrap_err().to_string();
    assert!(
        e.contains("v.db3") && e.contains("its messages is a view"),
        "{e}"
    );
    let left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, ["v.db3"]);
}

#[test]
fn a_truncated_bag_is_refused_by_name() {
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("run.mcap");
    write_bag(&path, &[&readings(2000, true)], &Description::default());
    let bytes = std::fs::read(&path).expect("read");
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).expect("written");
    let e = read(&cut).unwrap_err().to_string();
    assert!(
        e.starts_with(&cut.display().to_string()) && e.contains("MCAP"),
        "{e}"
    );
    std::fs::write(&cut, b"not a bag at all").expect("written");
    assert!(read(&cut).is_err());
}

#[test]
fn a_description_rides_in_the_channels() {
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("run.mcap");
    let d = Description {
        nav_frame: Some(crate::conventions::NavFrameName::NED),
        ..Description::default()
    };
    write_bag(&path, &[&readings(3, false)], &d);
    let back = read(&path).expect("read").description.expect("described");
    assert_eq!(back.nav_frame, d.nav_frame);
}

/// Two topics of one bag described in different frames are not read as one run.
#[test]
fn topics_described_in_two_frames_are_refused() {
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("mixed.mcap");
    let file = std::io::BufWriter::new(std::fs::File::create(&path).expect("file"));
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .create(file)
        .expect("writer");
    let kind = ros::MessageType::Imu;
    let schema = w
        .add_schema(kind.name(), "ros2msg", kind.schema().as_bytes())
        .expect("schema");
    for (k, (topic, frame)) in [("/imu", "ENU"), ("/imu2", "NED")].into_iter().enumerate() {
        let meta = BTreeMap::from([("imukit.nav_frame".to_string(), frame.to_string())]);
        let channel = w.add_channel(schema, topic, "cdr", &meta).expect("channel");
        let m = ros::Imu {
            header: ros::Header {
                stamp: ros::Time::from_ns(1_000 + k as i64).expect("stamp"),
                frame_id: "imu_link".into(),
            },
            orientation: ros::Quaternion::default(),
            orientation_covariance: ros::UNKNOWN_COVARIANCE,
            angular_velocity: ros::Vector3::default(),
            angular_velocity_covariance: [0.0; 9],
            linear_acceleration: ros::Vector3::of([0.0, 0.0, 9.8]),
            linear_acceleration_covariance: [0.0; 9],
        };
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: 1,
            log_time: 1_000 + k as u64,
            publish_time: 1_000 + k as u64,
        };
        w.write_to_known_channel(&header, &ros::encode(&m))
            .expect("message");
    }
    w.finish().expect("finished");
    drop(w);
    let e = read(&path).map(|_| ()).expect_err("refused").to_string();
    assert!(
        e.contains("topic /imu2 is described with nav_frame NED, not ENU (topic /imu's)"),
        "{e}"
    );
}

#[test]
fn a_vector_turns_as_the_quaternion_says() {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let v = rotate([h, 0.0, 0.0, h], [1.0, 0.0, 0.0]);
    assert!((v[0]).abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15 && v[2].abs() < 1e-15);
}
