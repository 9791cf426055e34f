use super::*;

#[cfg(unix)]
#[test]
fn folders_inside_an_output_folder_are_made_through_no_link() {
    let dir = tempfile::tempdir().unwrap();
    let (out, elsewhere) = (dir.path().join("seq"), dir.path().join("elsewhere"));
    std::fs::create_dir_all(&out).unwrap();
    std::fs::create_dir_all(&elsewhere).unwrap();
    std::os::unix::fs::symlink(&elsewhere, out.join("mav0")).unwrap();
    let e = create_folder_within(&out, Path::new("mav0/imu0"), "--out")
        .unwrap_err()
        .to_string();
    assert!(e.contains("--out") && e.contains("mav0 is a link"), "{e}");
    assert!(!elsewhere.join("imu0").exists());
    // Without the link the folders are made, and made again without complaint.
    std::fs::remove_file(out.join("mav0")).unwrap();
    for _ in 0..2 {
        let made = create_folder_within(&out, Path::new("mav0/imu0"), "--out").unwrap();
        assert_eq!(made, out.join("mav0/imu0"));
        assert!(made.is_dir());
    }
    // The output folder itself may be a link the user named.
    let named = dir.path().join("named");
    std::os::unix::fs::symlink(&elsewhere, &named).unwrap();
    create_folder_within(&named, Path::new("mav0"), "--out").unwrap();
    assert!(elsewhere.join("mav0").is_dir());
    std::fs::write(out.join("file"), "x").unwrap();
    let e = create_folder_within(&out, Path::new("file/x"), "--out")
        .unwrap_err()
        .to_string();
    assert!(e.contains("is a file where a folder goes"), "{e}");
}

#[test]
fn an_output_in_a_missing_folder_is_refused_naming_the_file_and_its_folder() {
    let dir = tempfile::tempdir().expect("a folder");
    let path = dir.path().join("nosuch").join("out.csv");
    let Err(e) = AtomicFile::create(&path) else {
        panic!("a missing folder was accepted")
    };
    let message = e.to_string();
    assert!(message.contains("out.csv"), "{message}");
    assert!(message.contains("nosuch does not exist"), "{message}");
    assert!(!message.contains(PARTIAL), "{message}");
    assert!(!dir.path().join("nosuch").exists());
}

/// A build without Parquet refuses a `.parquet` output by name and leaves nothing.
#[cfg(not(feature = "parquet"))]
#[test]
fn without_parquet_a_parquet_output_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.parquet");
    let table = Table {
        columns: vec!["t_s".into()],
        data: vec![0.0, 1.0],
    };
    let e = table.write(&path).unwrap_err().to_string();
    assert!(e.contains("`parquet` feature is off"), "{e}");
    assert!(!path.exists());
}
