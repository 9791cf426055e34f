//! Binary tables read within limits and written only as readers take them: `.npz` archives whose
//! members lie about their sizes, repeat, fail their CRC or expand like a bomb; `.npy` headers
//! that disagree with the file; Parquet files with damaged metadata or a column twice; column
//! names no format could carry back. Each is refused with an error naming the file and what is
//! wrong, before anything large is allocated, and never with a panic.
use std::io::Write;
use std::path::{Path, PathBuf};

use imu_io::Table;
use imu_io::read::read_table;

fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("imukit-binary-{name}-"))
        .tempdir()
        .unwrap()
}

fn small_table(rows: usize) -> Table {
    let mut t = Table::new(&["t_s", "accel_x_m_s2", "gyro_z_rad_s"]);
    for k in 0..rows {
        let x = k as f64;
        t.push_row(&[x / 100.0, (x * 0.1).sin(), 1e-3 * x]);
    }
    t
}

fn refused(path: &Path) -> String {
    read_table(path).unwrap_err().to_string()
}

/// A version 1 `.npy` file: the header `dict` padded as NumPy pads it, then `data`.
fn npy_file(dict: &str, data: &[u8]) -> Vec<u8> {
    let mut header = dict.as_bytes().to_vec();
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(b' ');
    }
    header.push(b'\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&u16::try_from(header.len()).unwrap().to_le_bytes());
    out.extend_from_slice(&header);
    out.extend_from_slice(data);
    out
}

/// One `.npy` member (a float64 column) as NumPy writes it.
fn npy_column(values: &[f64]) -> Vec<u8> {
    let dict = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({},), }}",
        values.len()
    );
    let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    npy_file(&dict, &data)
}

/// A stored zip archive of `members` written by hand, so that its directory can say what a
/// hostile file says: each member's sizes in the central directory are `declared(k, real)`
/// (a zip64 extra field carries them when they do not fit 32 bits) and its CRC `crc(k, real)`.
fn hand_zip(
    members: &[(&str, Vec<u8>)],
    declared: impl Fn(usize, u64) -> u64,
    crc: impl Fn(usize, u32) -> u32,
) -> Vec<u8> {
    let mut out = Vec::new();
    let mut central = Vec::new();
    for (k, (name, data)) in members.iter().enumerate() {
        let offset = out.len() as u32;
        let real_crc = crc32(data);
        let size = declared(k, data.len() as u64);
        let wide = size >= u64::from(u32::MAX);
        let short = if wide { u32::MAX } else { size as u32 };
        let c = crc(k, real_crc);
        // Local header (sizes as in the directory).
        out.extend_from_slice(&0x0403_4b50_u32.to_le_bytes());
        out.extend_from_slice(&[45, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
        out.extend_from_slice(&c.to_le_bytes());
        out.extend_from_slice(&short.to_le_bytes());
        out.extend_from_slice(&short.to_le_bytes());
        out.extend_from_slice(&(name.len() as u16).to_le_bytes());
        let extra: Vec<u8> = if wide {
            let mut e = vec![1, 0, 16, 0];
            e.extend_from_slice(&size.to_le_bytes());
            e.extend_from_slice(&size.to_le_bytes());
            e
        } else {
            Vec::new()
        };
        out.extend_from_slice(&(extra.len() as u16).to_le_bytes());
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(&extra);
        out.extend_from_slice(data);
        // Its central directory record.
        central.extend_from_slice(&0x0201_4b50_u32.to_le_bytes());
        central.extend_from_slice(&[45, 3, 45, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
        central.extend_from_slice(&c.to_le_bytes());
        central.extend_from_slice(&short.to_le_bytes());
        central.extend_from_slice(&short.to_le_bytes());
        central.extend_from_slice(&(name.len() as u16).to_le_bytes());
        central.extend_from_slice(&(extra.len() as u16).to_le_bytes());
        central.extend_from_slice(&[0; 6]);
        central.extend_from_slice(&0x81a4_0000_u32.to_le_bytes());
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name.as_bytes());
        central.extend_from_slice(&extra);
    }
    let start = out.len() as u32;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50_u32.to_le_bytes());
    out.extend_from_slice(&[0, 0, 0, 0]);
    let n = members.len() as u16;
    out.extend_from_slice(&n.to_le_bytes());
    out.extend_from_slice(&n.to_le_bytes());
    out.extend_from_slice(&(central.len() as u32).to_le_bytes());
    out.extend_from_slice(&start.to_le_bytes());
    out.extend_from_slice(&[0, 0]);
    out
}

fn crc32(data: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in data {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn npz_members_that_lie_repeat_or_fail_their_crc_are_refused_before_anything_is_allocated() {
    let d = scratch("npz");
    let d = d.path();
    let t: Vec<f64> = (0..50).map(|k| f64::from(k) / 10.0).collect();
    let x: Vec<f64> = (0..50).map(|k| f64::from(k).sin()).collect();
    let members = [("t_s.npy", npy_column(&t)), ("x.npy", npy_column(&x))];
    let write = |name: &str, bytes: Vec<u8>| {
        let p = d.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    // The honest archive reads (the hand-made zip is a valid one).
    let good = write("good.npz", hand_zip(&members, |_, n| n, |_, c| c));
    let back = read_table(&good).unwrap();
    assert_eq!(back.column("x").unwrap(), x);

    // A member declaring 2⁶² bytes in a file of a few hundred: refused by its sizes (this was
    // an abort, "memory allocation of 2305843009213693952 bytes failed").
    let huge = write(
        "huge.npz",
        hand_zip(&members, |k, n| if k == 1 { 1 << 62 } else { n }, |_, c| c),
    );
    let e = refused(&huge);
    assert!(
        e.contains("huge.npz") && (e.contains("declares") || e.contains("invalid")),
        "{e}"
    );

    // A member twice (the last used to win): NumPy refuses it, so does imukit.
    let twice = [
        ("t_s.npy", npy_column(&t)),
        ("x.npy", npy_column(&x)),
        ("t_s.npy", npy_column(&x)),
    ];
    let e = refused(&write("twice.npz", hand_zip(&twice, |_, n| n, |_, c| c)));
    assert!(
        e.contains("twice.npz") && e.contains("appears twice"),
        "{e}"
    );

    // A wrong CRC-32 (a damaged member) is found when the member ends.
    let e = refused(&write(
        "crc.npz",
        hand_zip(&members, |_, n| n, |k, c| if k == 1 { c ^ 1 } else { c }),
    ));
    assert!(e.contains("crc.npz") && e.contains("member x.npy"), "{e}");

    // Values after the ones the header gives.
    let mut long = npy_column(&x);
    long.extend_from_slice(&[0; 8]);
    let e = refused(&write(
        "long.npz",
        hand_zip(
            &[("t_s.npy", npy_column(&t)), ("x.npy", long)],
            |_, n| n,
            |_, c| c,
        ),
    ));
    assert!(e.contains("more bytes than its 50 values"), "{e}");
}

#[test]
fn an_npz_bomb_is_refused_by_its_ratio_and_a_constant_column_is_not() {
    let d = scratch("bomb");
    let d = d.path();
    let deflated = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .large_file(true);
    let archive = |name: &str, columns: &[(&str, &[f64])]| -> PathBuf {
        let p = d.join(name);
        let mut z = zip::ZipWriter::new(std::fs::File::create(&p).unwrap());
        for (c, v) in columns {
            z.start_file(format!("{c}.npy"), deflated).unwrap();
            z.write_all(&npy_column(v)).unwrap();
        }
        z.finish().unwrap();
        p
    };
    // 2 × 48 MiB of zeros: 96 MiB of values from about 100 kB.
    let zeros = vec![0.0; 6 << 20];
    let bomb = archive("bomb.npz", &[("t_s", &zeros), ("x", &zeros)]);
    assert!(std::fs::metadata(&bomb).unwrap().len() < 1 << 20);
    let e = refused(&bomb);
    assert!(
        e.contains("bomb.npz") && e.contains("more than 100 times"),
        "{e}"
    );
    // A table of measurements with a constant column deflates far less as a whole: read.
    let t: Vec<f64> = (0..200_000).map(|k| f64::from(k) * 0.01).collect();
    let noise: Vec<f64> = (0..200_000).map(|k| (f64::from(k) * 1.7).sin()).collect();
    let fine = archive(
        "fine.npz",
        &[
            ("t_s", &t),
            ("gyro_x_rad_s", &zeros[..200_000]),
            ("accel_x_m_s2", &noise),
        ],
    );
    let back = read_table(&fine).unwrap();
    assert_eq!(back.rows(), 200_000);
    assert_eq!(back.column("accel_x_m_s2").unwrap(), noise);
}

#[test]
fn an_npy_header_that_disagrees_with_the_file_is_refused_before_rows_are_read() {
    let d = scratch("npy");
    let d = d.path();
    let good = d.join("good.npy");
    small_table(10).write(&good).unwrap();
    let mut bytes = std::fs::read(&good).unwrap();
    // A header giving 2⁶⁰ rows over two rows of data.
    let dict = "{'descr': [('t_s', '<f8'), ('x', '<f8')], 'fortran_order': False, \
                'shape': (1152921504606846976,), }";
    let changed = npy_file(dict, &[0; 32]);
    let p = d.join("huge.npy");
    std::fs::write(&p, &changed).unwrap();
    let e = refused(&p);
    assert!(
        e.contains("huge.npy") && e.contains("header gives 1152921504606846976 rows"),
        "{e}"
    );
    bytes.truncate(bytes.len() - 1);
    std::fs::write(&p, &bytes).unwrap();
    assert!(refused(&p).contains("truncated"));
}

/// `path`'s Parquet file with its footer rewritten by `edit` (each column chunk's metadata).
fn parquet_with_metadata(
    good: &Path,
    path: &Path,
    edit: impl Fn(
        parquet::file::metadata::ColumnChunkMetaDataBuilder,
    ) -> parquet::file::metadata::ColumnChunkMetaDataBuilder,
) {
    use parquet::file::metadata::{ParquetMetaDataReader, ParquetMetaDataWriter};
    let bytes = std::fs::read(good).unwrap();
    let metadata = ParquetMetaDataReader::new()
        .parse_and_finish(&std::fs::File::open(good).unwrap())
        .unwrap();
    let footer = u32::from_le_bytes(bytes[bytes.len() - 8..bytes.len() - 4].try_into().unwrap());
    let body = &bytes[..bytes.len() - 8 - footer as usize];
    let groups = metadata
        .row_groups()
        .iter()
        .map(|g| {
            let columns = g
                .columns()
                .iter()
                .map(|c| edit(c.clone().into_builder()).build().unwrap())
                .collect();
            g.clone()
                .into_builder()
                .set_column_metadata(columns)
                .build()
                .unwrap()
        })
        .collect();
    let edited = metadata.into_builder().set_row_groups(groups).build();
    let mut out = body.to_vec();
    ParquetMetaDataWriter::new(&mut out, &edited)
        .finish()
        .unwrap();
    std::fs::write(path, out).unwrap();
}

#[test]
fn damaged_parquet_metadata_is_refused_naming_the_file_never_a_panic() {
    let d = scratch("parquet");
    let d = d.path();
    let good = d.join("good.parquet");
    small_table(1000).write(&good).unwrap();
    let cases: [(&str, fn(_) -> _, &str); 4] = [
        (
            "negative_size.parquet",
            |c: parquet::file::metadata::ColumnChunkMetaDataBuilder| {
                c.set_total_compressed_size(-5)
            },
            "outside the file",
        ),
        (
            "negative_offset.parquet",
            |c: parquet::file::metadata::ColumnChunkMetaDataBuilder| c.set_data_page_offset(-9),
            "outside the file",
        ),
        (
            "values.parquet",
            |c: parquet::file::metadata::ColumnChunkMetaDataBuilder| c.set_num_values(-1),
            "values in 1000 rows",
        ),
        // Snappy pages said to be uncompressed (this panicked in the parquet crate's
        // split-bytes decoder, "index out of bounds").
        (
            "codec.parquet",
            |c: parquet::file::metadata::ColumnChunkMetaDataBuilder| {
                c.set_compression(parquet::basic::Compression::UNCOMPRESSED)
            },
            "said to be uncompressed",
        ),
    ];
    for (name, edit, want) in cases {
        let p = d.join(name);
        parquet_with_metadata(&good, &p, edit);
        let e = refused(&p);
        assert!(e.contains(name) && e.contains(want), "{name}: {e}");
        // The row reader (what the commands stream with) refuses it too.
        let rows = imu_io::read::CsvRows::open(&p, &["t_s"], "").and_then(|mut r| {
            let mut out = [0.0];
            while r.next_row(&mut out)?.is_some() {}
            Ok(())
        });
        assert!(rows.is_err(), "{name}");
    }
}

#[test]
fn a_page_whose_header_says_dictionary_without_a_dictionary_is_an_error_not_a_panic() {
    // The metadata is sound; the first data page's header says its values are dictionary
    // indices (RLE_DICTIONARY) where they are split bytes. The parquet crate panics there
    // ("Decoder for dict should have been set"): the reader's containment turns it into an
    // error naming the file.
    let d = scratch("dictionary");
    let d = d.path();
    let good = d.join("good.parquet");
    small_table(1000).write(&good).unwrap();
    let mut bytes = std::fs::read(&good).unwrap();
    let metadata = parquet::file::metadata::ParquetMetaDataReader::new()
        .parse_and_finish(&std::fs::File::open(&good).unwrap())
        .unwrap();
    let start = usize::try_from(metadata.row_group(0).column(0).data_page_offset()).unwrap();
    // In the page header (Thrift compact): the data page header's field 2, an i32 (0x15), holding
    // BYTE_STREAM_SPLIT (9, zigzag 0x12) becomes RLE_DICTIONARY (8, zigzag 0x10).
    let at = bytes[start..start + 48]
        .windows(2)
        .position(|w| w == [0x15, 0x12])
        .expect("the encoding in the page header")
        + start;
    bytes[at + 1] = 0x10;
    let p = d.join("dictionary.parquet");
    std::fs::write(&p, &bytes).unwrap();
    let e = refused(&p);
    assert!(
        e.contains("dictionary.parquet") && e.contains("damaged file"),
        "{e}"
    );
    let rows = imu_io::read::CsvRows::open(&p, &["t_s"], "").and_then(|mut r| {
        let mut out = [0.0];
        while r.next_row(&mut out)?.is_some() {}
        Ok(())
    });
    let e = rows.unwrap_err().to_string();
    assert!(e.contains("dictionary.parquet"), "{e}");
}

#[test]
fn a_column_named_twice_is_refused_in_every_format_read() {
    let d = scratch("twice");
    let d = d.path();
    // Written by another tool (arrow here), as imukit never writes one.
    let p = d.join("twice.parquet");
    let schema = std::sync::Arc::new(arrow_schema::Schema::new(vec![
        arrow_schema::Field::new("t_s", arrow_schema::DataType::Float64, false),
        arrow_schema::Field::new("x", arrow_schema::DataType::Float64, false),
        arrow_schema::Field::new("t_s", arrow_schema::DataType::Float64, false),
    ]));
    let column = || {
        std::sync::Arc::new(arrow_array::Float64Array::from(vec![0.0, 0.01, 0.02]))
            as arrow_array::ArrayRef
    };
    let batch =
        arrow_array::RecordBatch::try_new(schema.clone(), vec![column(), column(), column()])
            .unwrap();
    let mut w =
        parquet::arrow::ArrowWriter::try_new(std::fs::File::create(&p).unwrap(), schema, None)
            .unwrap();
    w.write(&batch).unwrap();
    w.close().unwrap();
    let e = refused(&p);
    assert!(
        e.contains("twice.parquet") && e.contains("column t_s appears twice"),
        "{e}"
    );
    assert!(imu_io::read::read_header(&p).is_err());
    let csv = d.join("twice.csv");
    std::fs::write(&csv, "t_s,x,t_s\n0,1,2\n").unwrap();
    assert!(refused(&csv).contains("appears twice"));
}

#[test]
fn column_names_no_format_could_read_back_are_refused_before_a_byte_is_written() {
    let d = scratch("names");
    let d = d.path();
    let long = "x".repeat(100_000);
    for (columns, want) in [
        (vec!["t_s", "a,b"], "holds ','"),
        (vec!["t_s", "x", "t_s"], "the name of column 1 too"),
        (vec!["t_s", long.as_str()], "a name of 100000 bytes"),
        (vec!["t_s", ""], "needs a name"),
        (vec!["t_s", " x"], "a space"),
        (vec!["#t", "x"], "starting with #"),
        (vec!["t_s", "a\nb"], "holds '\\n'"),
        (vec!["t_s", "it's"], "holds '\\''"),
        (vec!["t_s", "a/b"], "holds '/'"),
    ] {
        let mut t = Table::new(&columns);
        t.push_row(&vec![1.0; columns.len()]);
        for ext in ["csv", "parquet", "npy", "npz"] {
            let p = d.join(format!("o.{ext}"));
            let e = t.write(&p).unwrap_err().to_string();
            assert!(
                e.contains(&format!("o.{ext}")) && e.contains(want),
                "{ext}: {e}"
            );
            assert_eq!(
                std::fs::read_dir(d).unwrap().count(),
                0,
                "{ext}: a file was left"
            );
        }
    }
}

#[test]
fn a_table_too_wide_for_a_npy_header_is_refused_and_written_in_the_formats_that_take_it() {
    let d = scratch("wide");
    let d = d.path();
    let names: Vec<String> = (0..2000).map(|k| format!("column_{k:04}_m")).collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut t = Table::new(&refs);
    t.push_row(&vec![0.5; 2000]);
    t.push_row(&vec![1.5; 2000]);
    let e = t.write(&d.join("wide.npy")).unwrap_err().to_string();
    assert!(
        e.contains("wide.npy") && e.contains("2000 columns") && e.contains(".parquet"),
        "{e}"
    );
    assert!(!d.join("wide.npy").exists());
    for ext in ["csv", "parquet", "npz"] {
        let p = d.join(format!("wide.{ext}"));
        t.write(&p).unwrap();
        assert_eq!(read_table(&p).unwrap(), t, "{ext}");
    }
    // The widest table a .npy file takes reads back.
    let fits: Vec<&str> = refs[..300].to_vec();
    let mut narrow = Table::new(&fits);
    narrow.push_row(&vec![2.0; 300]);
    narrow.write(&d.join("narrow.npy")).unwrap();
    assert_eq!(read_table(d.join("narrow.npy")).unwrap(), narrow);
}
