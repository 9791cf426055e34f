//! Tables as Parquet: written by the output's extension and read back bit for bit, metadata
//! kept, a value that is not finite refused before any file is made, a file of the wrong kind
//! refused naming its column.
use imukit::Table;
use imukit::io::parquet::{read_metadata, read_table};

fn dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("imukit-formats-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn parquet_tables_round_trip_bit_for_bit_across_row_groups() {
    let d = dir("round-trip");
    let n = imukit::io::parquet::ROW_GROUP + 1234;
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
    let picked = imukit::io::table::read_table_columns(&path, &["y", "t_s"], "").unwrap();
    assert_eq!(picked.column("y").unwrap()[7], t.column("y").unwrap()[7]);
    let e = imukit::io::table::read_table_columns(&path, &["z"], "")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.parquet") && e.contains("missing column(s) z"),
        "{e}"
    );
    imukit::io::parquet::write_table(&t, &d.join("m.parquet"), &[("k".into(), "v".into())])
        .unwrap();
    assert!(
        read_metadata(&d.join("m.parquet"))
            .unwrap()
            .contains(&("k".to_string(), "v".to_string()))
    );
}

#[test]
fn a_value_that_is_not_finite_is_refused_and_no_file_is_left() {
    let d = dir("finite");
    let mut t = Table::new(&["t_s", "x"]);
    t.push_row(&[0.0, 1.0]);
    t.push_row(&[0.1, f64::NAN]);
    let path = d.join("bad.parquet");
    let e = t.write(&path).unwrap_err().to_string();
    // Rows counted from 1 (a Parquet file has no header row).
    assert!(e.contains("row 2") && e.contains("column x"), "{e}");
    assert!(!path.exists());
    assert!(
        std::fs::read_dir(&d).unwrap().next().is_none(),
        "a partial file was left"
    );
    // Not a Parquet file at all.
    std::fs::write(&path, b"t_s,x\n0,1\n").unwrap();
    let e = read_table(&path).unwrap_err().to_string();
    assert!(e.contains("bad.parquet") && e.contains("Parquet"), "{e}");
}
