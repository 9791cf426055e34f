use std::io::Read;

use super::*;

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
        assert!(check_table_outputs(&[("--out", &path)]).is_err());
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
        check_table_outputs(&[("--out", &path)]).unwrap();
        if cfg!(not(feature = "parquet")) && name.ends_with(".parquet") {
            // A build without Parquet refuses the file by name and leaves nothing.
            let e = table.write(&path).unwrap_err().to_string();
            assert!(e.contains("`parquet` feature is off"), "{e}");
            assert!(!path.exists());
            continue;
        }
        table.write(&path).unwrap();
        assert_eq!(
            crate::read::read_table(&path).unwrap().data,
            table.data,
            "{name}"
        );
    }
}

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

#[test]
fn an_output_file_holds_what_was_written_and_hands_each_step_to_the_disk() {
    // Past several steps, then back to the start (as an archive rewrites its header) and
    // on from the end: the file is exactly what was written, and the part handed to the
    // disk follows the writes (`handed` is where the last hand-over ended).
    let dir = tempfile::tempdir().expect("a folder");
    let path = dir.path().join("out.bin");
    let mut out = OutputFile::new(File::create(&path).expect("a file"));
    let step = usize::try_from(WRITEBACK_STEP).expect("a step fits");
    let block: Vec<u8> = (0..step / 3 + 7).map(|i| (i % 251) as u8).collect();
    let mut want = Vec::new();
    let mut handed = Vec::new();
    for _ in 0..10 {
        out.write_all(&block).expect("written");
        want.extend_from_slice(&block);
        handed.push((out.position, out.handed));
    }
    // Handed over a step at a time, at the end of a write, never further behind than a step.
    let step = WRITEBACK_STEP;
    assert!(
        handed
            .iter()
            .all(|&(at, h)| h % (block.len() as u64) == 0 && at - h < step),
        "{handed:?}"
    );
    let handed: Vec<u64> = handed.into_iter().map(|(_, h)| h).collect();
    assert!(
        handed.contains(&0) && handed.iter().any(|&h| h >= 2 * step),
        "{handed:?}"
    );
    out.seek(SeekFrom::Start(0)).expect("seek");
    out.write_all(b"head").expect("written");
    want[..4].copy_from_slice(b"head");
    assert_eq!(out.handed, 4, "handed from the rewritten place on");
    out.seek(SeekFrom::End(0)).expect("seek");
    out.write_all(b"tail").expect("written");
    want.extend_from_slice(b"tail");
    out.flush().expect("flushed");
    out.get_ref().sync_all().expect("synced");
    drop(out);
    let mut back = Vec::new();
    File::open(&path)
        .expect("opened")
        .read_to_end(&mut back)
        .expect("read");
    assert!(
        back == want,
        "{} bytes back, {} written",
        back.len(),
        want.len()
    );
}
