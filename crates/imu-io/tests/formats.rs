//! Tables as Parquet, NumPy `.npy` and `.npz`: written by the output's extension and read back
//! bit for bit (Parquet's metadata kept), a value that is not finite refused before any file is
//! made, a file of the wrong kind refused saying what it holds and where.
use imu_io::Table;
use imu_io::conventions::NavFrameName;
use imu_io::description::Description;
use imu_io::parquet::{read_metadata, read_table};
use imu_io::schema::TableKind;

/// A fresh folder under the system's temporary folder, removed with its files when dropped.
fn dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("imukit-formats-{name}-"))
        .tempdir()
        .unwrap()
}

#[test]
fn parquet_tables_round_trip_bit_for_bit_across_row_groups() {
    let d = dir("round-trip");
    let d = d.path();
    let n = imu_io::parquet::ROW_GROUP + 1234;
    let mut t = Table::new(&["t_s", "x", "y"]);
    for i in 0..n {
        let x = i as f64;
        t.push_row(&[x * 0.01, (x * 0.37).sin() * 1e-300, 1.0 / (x + 0.3)]);
    }
    let path = d.join("t.parquet");
    t.write(&path).unwrap();
    let back = read_table(&path).unwrap();
    assert_eq!(back.columns, t.columns);
    assert_eq!(back.data.len(), t.data.len());
    assert!(
        back.data
            .iter()
            .zip(&t.data)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    );
    // The table readers of every command take it as they take CSV.
    let picked = imu_io::read::read_table_columns(&path, &["y", "t_s"], "").unwrap();
    assert_eq!(picked.column("y").unwrap()[7], t.column("y").unwrap()[7]);
    let e = imu_io::read::read_table_columns(&path, &["z"], "")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.parquet") && e.contains("missing column(s) z"),
        "{e}"
    );
    // What the table holds goes into its metadata, one key per entry, and comes back.
    let described = Description {
        nav_frame: Some(NavFrameName::NED),
        scenario: Some("rate_hz = 10.0\n".into()),
        ..Description::of_kind(TableKind::Truth)
    };
    imu_io::parquet::write_table(&t, &d.join("m.parquet"), &described).unwrap();
    let metadata = read_metadata(&d.join("m.parquet")).unwrap();
    for (k, v) in [
        ("imukit.kind", "truth"),
        ("imukit.nav_frame", "NED"),
        ("imukit.body_frame", "FRD"),
        ("imukit.scenario", "rate_hz = 10.0\n"),
    ] {
        assert!(metadata.contains(&(k.to_string(), v.to_string())), "{k}");
    }
    assert_eq!(
        Description::read(&d.join("m.parquet")).unwrap(),
        Some(described)
    );
}

#[test]
fn a_value_that_is_not_finite_is_refused_and_no_file_is_left() {
    let d = dir("finite");
    let d = d.path();
    let mut t = Table::new(&["t_s", "x"]);
    t.push_row(&[0.0, 1.0]);
    t.push_row(&[0.1, f64::NAN]);
    let path = d.join("bad.parquet");
    let e = t.write(&path).unwrap_err().to_string();
    // Rows counted from 1 (a Parquet file has no header row).
    assert!(e.contains("row 2") && e.contains("column x"), "{e}");
    assert!(!path.exists());
    assert!(
        std::fs::read_dir(d).unwrap().next().is_none(),
        "a partial file was left"
    );
    // Not a Parquet file at all.
    std::fs::write(&path, b"t_s,x\n0,1\n").unwrap();
    let e = read_table(&path).unwrap_err().to_string();
    assert!(e.contains("bad.parquet") && e.contains("Parquet"), "{e}");
}

/// A table of `n` rows whose values use every bit of a float64 (tiny, huge, negative zero).
fn awkward_table(n: usize) -> Table {
    let mut t = Table::new(&["t_s", "x", "y"]);
    for i in 0..n {
        let x = i as f64;
        t.push_row(&[x * 0.01, (x * 0.37).sin() * 1e-300, -1.0 / (x + 0.3)]);
    }
    t.push_row(&[1e300, -0.0, f64::MIN_POSITIVE]);
    t
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn npy_tables_round_trip_bit_for_bit_and_read_like_csv() {
    let d = dir("npy");
    let d = d.path();
    let t = awkward_table(10_000);
    let path = d.join("t.npy");
    t.write(&path).unwrap();
    // The file is the NumPy format: magic, then a header naming the fields and the row count.
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let header = String::from_utf8_lossy(&bytes[10..200]);
    assert!(
        header.contains("('t_s', '<f8')") && header.contains("(10001,)"),
        "{header}"
    );
    // Records follow the header, 8 bytes a field.
    assert_eq!(bytes.len() % 64, (t.data.len() * 8) % 64);
    let back = imu_io::read::read_table(&path).unwrap();
    assert_eq!(back.columns, t.columns);
    assert!(same_bits(&back.data, &t.data));
    let picked = imu_io::read::read_table_columns(&path, &["y", "t_s"], "").unwrap();
    assert!(same_bits(
        &picked.column("y").unwrap(),
        &t.column("y").unwrap()
    ));
    let e = imu_io::read::read_table_columns(&path, &["z"], "")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.npy") && e.contains("missing column(s) z"),
        "{e}"
    );
}

#[test]
fn a_bad_npy_file_is_refused_saying_what_and_where() {
    let d = dir("npy-bad");
    let d = d.path();
    let t = awkward_table(100);
    let good = d.join("good.npy");
    t.write(&good).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let err = |name: &str, content: &[u8]| {
        let p = d.join(name);
        std::fs::write(&p, content).unwrap();
        imu_io::read::read_table(&p).unwrap_err().to_string()
    };
    // Cut short, or longer than its header says: what the header gives against what the file
    // holds, before a row is read.
    let e = err("short.npy", &bytes[..bytes.len() - 12]);
    assert!(
        e.contains("short.npy")
            && e.contains("header gives 101 rows")
            && e.contains("(100 whole rows): truncated"),
        "{e}"
    );
    let mut long = bytes.clone();
    long.extend_from_slice(&[0; 8]);
    let e = err("long.npy", &long);
    assert!(
        e.contains("header gives 101 rows") && !e.contains("truncated"),
        "{e}"
    );
    // Not a NumPy file.
    let e = err("text.npy", b"t_s,x\n0,1\n");
    assert!(e.contains("not a NumPy .npy file"), "{e}");
    // A header longer than NumPy reads is refused before it is read (v2: 4-byte length).
    let mut long = b"\x93NUMPY\x02\x00".to_vec();
    long.extend_from_slice(&u32::MAX.to_le_bytes());
    let e = err("long.npy", &long);
    assert!(e.contains("header of 4294967295 bytes"), "{e}");
    // A value that is not finite: its row and column.
    let mut nan = bytes.clone();
    let data_start = bytes.len() - t.data.len() * 8;
    let k = 4 * 3 + 1; // row 5, column x
    nan[data_start + 8 * k..data_start + 8 * k + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    let e = err("nan.npy", &nan);
    assert!(
        e.contains("nan.npy") && e.contains("row 5") && e.contains("column x"),
        "{e}"
    );
    // A plain 2-D array has no column names.
    let mut plain = bytes.clone();
    let h = String::from_utf8_lossy(&bytes[10..data_start]).into_owned();
    let descr_end = h.find("], 'fortran_order'").unwrap() + 1;
    let swapped = format!(
        "{{'descr': '<f8',{}",
        " ".repeat(descr_end - "{'descr': '<f8',".len() + 1)
    ) + &h[descr_end + 1..];
    plain[10..data_start].copy_from_slice(swapped.as_bytes());
    let e = err("plain.npy", &plain);
    assert!(e.contains("not a table") && e.contains("structured"), "{e}");
    // Nothing that is not finite is written.
    let mut bad = Table::new(&["t_s", "x"]);
    bad.push_row(&[0.0, f64::INFINITY]);
    let path = d.join("inf.npy");
    let e = bad.write(&path).unwrap_err().to_string();
    assert!(e.contains("row 1") && e.contains("column x"), "{e}");
    assert!(!path.exists());
}

#[test]
fn npz_archives_round_trip_bit_for_bit_across_blocks() {
    let d = dir("npz");
    let d = d.path();
    // 40 columns × 60 000 rows: more than one block of rows goes through the temporary file.
    let names: Vec<String> = (0..40).map(|k| format!("c{k}")).collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut t = Table::new(&refs);
    let mut row = vec![0.0; 40];
    for i in 0..60_000 {
        for (k, v) in row.iter_mut().enumerate() {
            *v = ((i * 40 + k) as f64 * 0.731).sin() * 10f64.powi(k as i32 - 20);
        }
        t.push_row(&row);
    }
    let path = d.join("t.npz");
    t.write(&path).unwrap();
    let back = imu_io::read::read_table(&path).unwrap();
    assert_eq!(back.columns, t.columns);
    assert!(same_bits(&back.data, &t.data));
    let picked = imu_io::read::read_table_columns(&path, &["c39", "c0"], "").unwrap();
    assert!(same_bits(
        &picked.column("c39").unwrap(),
        &t.column("c39").unwrap()
    ));
    // Only the archive is left in the folder: the block file had no name.
    let left: Vec<_> = std::fs::read_dir(d).unwrap().collect();
    assert_eq!(left.len(), 1, "{left:?}");
}

#[test]
fn a_bad_npz_archive_is_refused_saying_what_and_where() {
    let d = dir("npz-bad");
    let d = d.path();
    let mut t = Table::new(&["t_s", "x"]);
    for i in 0..50 {
        t.push_row(&[i as f64 * 0.1, (i as f64).sqrt()]);
    }
    let good = d.join("good.npz");
    t.write(&good).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let err = |name: &str, content: &[u8]| {
        let p = d.join(name);
        std::fs::write(&p, content).unwrap();
        imu_io::read::read_table(&p).unwrap_err().to_string()
    };
    let e = err("cut.npz", &bytes[..bytes.len() / 2]);
    assert!(e.contains("cut.npz") && e.contains(".npz"), "{e}");
    let e = err("text.npz", b"t_s,x\n0,1\n");
    assert!(e.contains("text.npz") && e.contains(".npz"), "{e}");
    // A value that is not finite: the row and column (rows from 1).
    let mut nan = t.clone();
    let k = nan.data.len() - 1;
    nan.data[k] = f64::NAN;
    let e = nan.write(&d.join("nan.npz")).unwrap_err().to_string();
    assert!(e.contains("row 50") && e.contains("column x"), "{e}");
    assert!(!d.join("nan.npz").exists());
    // Archives made elsewhere (as numpy.savez makes them): a NaN, columns of unequal length, a
    // member that is not float64.
    let npz = |name: &str, members: &[(&str, Vec<f64>)], extra: Option<(&str, Vec<i64>)>| {
        use npyz::WriterBuilder;
        use std::io::Write;
        let p = d.join(name);
        let mut zip = zip::ZipWriter::new(std::fs::File::create(&p).unwrap());
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        for (member, values) in members {
            let mut buf = Vec::new();
            let mut w = npyz::WriteOptions::new()
                .default_dtype()
                .shape(&[values.len() as u64])
                .writer(&mut buf)
                .begin_nd()
                .unwrap();
            w.extend(values.iter().copied()).unwrap();
            w.finish().unwrap();
            zip.start_file(format!("{member}.npy"), options).unwrap();
            zip.write_all(&buf).unwrap();
        }
        if let Some((member, values)) = extra {
            let mut buf = Vec::new();
            let mut w = npyz::WriteOptions::new()
                .default_dtype()
                .shape(&[values.len() as u64])
                .writer(&mut buf)
                .begin_nd()
                .unwrap();
            w.extend(values).unwrap();
            w.finish().unwrap();
            zip.start_file(format!("{member}.npy"), options).unwrap();
            zip.write_all(&buf).unwrap();
        }
        zip.finish().unwrap();
        imu_io::read::read_table(&p).unwrap_err().to_string()
    };
    let e = npz(
        "nan2.npz",
        &[
            ("t_s", vec![0.0, 0.1, 0.2]),
            ("x", vec![1.0, f64::NAN, 3.0]),
        ],
        None,
    );
    assert!(
        e.contains("nan2.npz") && e.contains("row 2") && e.contains("column x"),
        "{e}"
    );
    let e = npz(
        "short.npz",
        &[("t_s", vec![0.0, 0.1, 0.2]), ("x", vec![1.0, 2.0])],
        None,
    );
    assert!(
        e.contains("member x.npy") && e.contains("2 values, but column t_s has 3"),
        "{e}"
    );
    let e = npz(
        "ints.npz",
        &[("t_s", vec![0.0, 0.1])],
        Some(("count", vec![1, 2])),
    );
    assert!(
        e.contains("member count.npy") && e.contains("<i8") && e.contains("float64"),
        "{e}"
    );
}

#[test]
fn a_table_is_written_only_under_a_name_whose_format_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let table = Table {
        columns: vec!["t_s".into()],
        data: vec![0.0, 1.0],
    };
    for (name, needle) in [
        ("err.xlsx", ".xlsx is not a table format imukit writes"),
        ("x.mat", ".mat is not a table format"),
        ("x.h5", ".h5 is not a table format"),
        ("x.db3", "name it .mcap"),
        ("x.bag", "name it .mcap"),
        ("x.nmea", ".nmea is not a table format"),
    ] {
        let path = dir.path().join(name);
        let e = table.write(&path).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains(needle), "{name}: {e}");
        assert!(!path.exists(), "{name} was written");
        assert!(imu_io::output::check_table_outputs(&[("--out", &path)]).is_err());
    }
    for name in [
        "t.csv",
        "t.CSV",
        "t.txt",
        "t.parquet",
        "t.npy",
        "t.npz",
        "noext",
    ] {
        let path = dir.path().join(name);
        imu_io::output::check_table_outputs(&[("--out", &path)]).unwrap();
        if cfg!(not(feature = "parquet")) && name.ends_with(".parquet") {
            // A build without Parquet refuses the file by name and leaves nothing.
            let e = table.write(&path).unwrap_err().to_string();
            assert!(e.contains("`parquet` feature is off"), "{e}");
            assert!(!path.exists());
            continue;
        }
        table.write(&path).unwrap();
        assert_eq!(
            imu_io::read::read_table(&path).unwrap().data,
            table.data,
            "{name}"
        );
    }
}
