"""Binary outputs: ``imukit simulate`` writes Parquet, ``.npy`` or ``.npz`` when the output's
extension says so — the CSV contract's column names, float64 (Parquet also carries the scenario
and navigation frame in its metadata) — and pyarrow, pandas, polars, NumPy and ``imukit.read``
read them back bit for bit equal to the CSV output; the commands read what NumPy saves."""
import json
import subprocess

import numpy as np
import pyarrow.parquet as pq
import pandas as pd
import polars as pl
import pytest

import imukit
from test_cli_vs_python import ROOT, imukit_bin


def test_parquet_outputs_read_back_everywhere_with_their_metadata(tmp_path):
    scenario = ROOT / "examples" / "expression.toml"
    for ext in ("csv", "parquet"):
        subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(tmp_path / f"imu.{ext}"),
                        "--truth", str(tmp_path / f"truth.{ext}")], check=True, capture_output=True)
    for name in ("imu", "truth"):
        csv = imukit.read(tmp_path / f"{name}.csv")
        parquet = tmp_path / f"{name}.parquet"
        table = pq.read_table(parquet)
        assert table.schema.names == list(csv.columns)
        assert all(str(t) == "double" for t in table.schema.types)
        meta = {k.decode(): v.decode() for k, v in table.schema.metadata.items()}
        assert meta["imukit.nav_frame"] == "ENU"
        assert meta["imukit.scenario"] == scenario.read_text()
        # Snappy over byte-stream-split float64 pages (every column).
        chunks = pq.ParquetFile(parquet).metadata.row_group(0)
        for c in range(chunks.num_columns):
            assert chunks.column(c).compression == "SNAPPY"
            assert "BYTE_STREAM_SPLIT" in chunks.column(c).encodings, chunks.column(c).encodings
        # Bit for bit: float64 in, float64 out, against the CSV's shortest round-trip text.
        assert np.array_equal(table.to_pandas().to_numpy(), csv.values)
        assert np.array_equal(pd.read_parquet(parquet).to_numpy(), csv.values)
        assert np.array_equal(pl.read_parquet(parquet).to_numpy(), csv.values)
        ours = imukit.read(parquet)
        assert ours.columns == csv.columns and np.array_equal(ours.values, csv.values)


def test_a_csv_table_says_what_it_holds_in_a_line_pandas_and_numpy_skip(tmp_path):
    scenario = ROOT / "examples" / "schuler.toml"
    text = scenario.read_text().replace("duration_s = 5400.0", "duration_s = 2.0")
    (tmp_path / "s.toml").write_text(text)
    subprocess.run([imukit_bin(), "simulate", str(tmp_path / "s.toml"), "--out", str(tmp_path / "imu.csv"),
                    "--truth", str(tmp_path / "truth.parquet")], check=True, capture_output=True)
    first = (tmp_path / "imu.csv").read_text().splitlines()[0]
    assert first.startswith("# imukit: ")
    described = json.loads(first[len("# imukit: "):])
    assert described["kind"] == "readings" and described["nav_frame"] == "NED"
    assert described["body_frame"] == "FRD" and described["earth"] == "wgs84"
    assert (described["origin_latitude_deg"], described["origin_longitude_deg"]) == (45.0, 7.0)
    assert described["scenario"] == text
    assert "[gyroscope]" in described["sensor"]
    # The same entries in the Parquet file's metadata, as text.
    meta = {k.decode(): v.decode() for k, v in pq.read_metadata(tmp_path / "truth.parquet").metadata.items()}
    assert meta["imukit.kind"] == "truth" and meta["imukit.origin_height_m"] == "300"
    # The readers the documentation names skip it and read the numbers bit for bit.
    ours = imukit.read(tmp_path / "imu.csv")
    frame = pd.read_csv(tmp_path / "imu.csv", comment="#", float_precision="round_trip")
    assert list(frame.columns) == list(ours.columns)
    assert np.array_equal(frame.to_numpy(), ours.values)
    array = np.genfromtxt(tmp_path / "imu.csv", delimiter=",", names=True, skip_header=1)
    assert list(array.dtype.names) == list(ours.columns)
    assert np.array_equal(array["gyro_z_rad_s"], ours.values[:, ours.columns.index("gyro_z_rad_s")])


def test_tables_write_parquet_and_the_commands_read_it(tmp_path):
    sim = imukit.simulate(ROOT / "examples" / "expression.toml")
    sim.truth.write(tmp_path / "truth.parquet")
    sim.imu.write(tmp_path / "imu.parquet")
    back = imukit.read(tmp_path / "truth.parquet")
    assert np.array_equal(back.values, sim.truth.values)
    sim.truth.write(tmp_path / "truth.csv")
    sim.imu.write(tmp_path / "imu.csv")
    # A command reads Parquet inputs as it reads CSV ones, and writes what its --out names: the
    # same numbers either way.
    for ext in ("csv", "parquet"):
        run = subprocess.run([imukit_bin(), "integrate", str(tmp_path / f"imu.{ext}"), "--init",
                              str(tmp_path / f"truth.{ext}"), "--out", str(tmp_path / f"nav.{ext}")],
                             capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        run = subprocess.run([imukit_bin(), "compare", str(tmp_path / f"truth.{ext}"), str(tmp_path / f"nav.{ext}"),
                              "--out", str(tmp_path / f"err.{ext}")], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
    for name in ("nav", "err"):
        a, b = imukit.read(tmp_path / f"{name}.csv"), imukit.read(tmp_path / f"{name}.parquet")
        assert a.columns == b.columns and np.array_equal(a.values, b.values), name
    # A Parquet file with a column that is not numbers is refused, naming it.
    import pyarrow as pa
    pq.write_table(pa.table({"t_s": [0.0, 1.0], "label": ["a", "b"]}), tmp_path / "bad.parquet")
    with pytest.raises(imukit.ImuError, match="column label is Utf8"):
        imukit.read(tmp_path / "bad.parquet")


def test_numpy_outputs_read_back_bit_for_bit_in_numpy_and_pandas(tmp_path):
    scenario = ROOT / "examples" / "expression.toml"
    for ext in ("csv", "npy", "npz"):
        subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(tmp_path / f"imu.{ext}"),
                        "--truth", str(tmp_path / f"truth.{ext}")], check=True, capture_output=True)
    for name in ("imu", "truth"):
        csv = imukit.read(tmp_path / f"{name}.csv")
        # .npy: one structured array, a float64 field per column, named as in the CSV.
        records = np.load(tmp_path / f"{name}.npy")
        assert records.dtype.names == csv.columns
        assert all(records.dtype[n] == np.dtype("<f8") for n in csv.columns)
        assert records.shape == (csv.values.shape[0],)
        for k, n in enumerate(csv.columns):
            assert np.array_equal(records[n], csv.values[:, k]), n
        assert np.array_equal(pd.DataFrame(records).to_numpy(), csv.values)
        # .npz: one one-dimensional float64 array per column, as numpy.savez writes them.
        with np.load(tmp_path / f"{name}.npz") as archive:
            assert tuple(archive.files) == csv.columns
            assert np.array_equal(pd.DataFrame(dict(archive)).to_numpy(), csv.values)
        for ext in ("npy", "npz"):
            ours = imukit.read(tmp_path / f"{name}.{ext}")
            assert ours.columns == csv.columns and np.array_equal(ours.values, csv.values)


def test_commands_read_numpy_files_made_by_numpy(tmp_path):
    sim = imukit.simulate(ROOT / "examples" / "expression.toml")
    sim.truth.write(tmp_path / "truth.csv")
    sim.imu.write(tmp_path / "imu.csv")
    # As a NumPy user would save them: savez, savez_compressed, a structured array.
    np.savez(tmp_path / "imu.npz", **sim.imu.to_dict())
    np.savez_compressed(tmp_path / "truth.npz", **sim.truth.to_dict())
    np.save(tmp_path / "truth.npy", np.rec.fromarrays([sim.truth[c] for c in sim.truth.columns],
                                                      names=list(sim.truth.columns)))
    outs = {}
    for imu, truth in (("imu.csv", "truth.csv"), ("imu.npz", "truth.npz"), ("imu.npz", "truth.npy")):
        out = tmp_path / f"nav-{imu}-{truth}.npy"
        run = subprocess.run([imukit_bin(), "integrate", str(tmp_path / imu), "--init", str(tmp_path / truth),
                              "--out", str(out)], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        outs[(imu, truth)] = imukit.read(out)
    first, *rest = outs.values()
    for other in rest:
        assert other.columns == first.columns and np.array_equal(other.values, first.values)
    # A plain 2-D array has no column names: refused, saying so.
    np.save(tmp_path / "plain.npy", sim.imu.values)
    with pytest.raises(imukit.ImuError, match="not a table"):
        imukit.read(tmp_path / "plain.npy")
    # Unknown extensions are refused with the formats read.
    with pytest.raises(imukit.ImuError, match=r"\.npy, \.npz"):
        imukit.read(tmp_path / "imu.xlsx")


def test_kalibr_imu_yaml_reads_with_kalibrs_parser_and_carries_the_presets_figures():
    """`imukit presets NAME --format kalibr`: PyYAML (what Kalibr reads it with) gives floats, the
    densities are the preset's (single-sided, as Kalibr's), the topic and rate are the options'."""
    yaml = pytest.importorskip("yaml")
    out = subprocess.run([imukit_bin(), "presets", "stim300", "--format", "kalibr",
                          "--rate-hz", "125", "--topic", "/imu0"],
                         check=True, capture_output=True, text=True).stdout
    d = yaml.safe_load(out)
    assert d["rostopic"] == "/imu0" and d["update_rate"] == 125.0
    part = imukit.preset_params("stim300")
    for sensor, key in (("gyroscope", "noise_density_rad_s_per_rt_hz"),
                        ("accelerometer", "noise_density_m_s2_per_rt_hz")):
        assert isinstance(d[f"{sensor}_noise_density"], float)
        assert d[f"{sensor}_noise_density"] == pytest.approx(part[sensor][key], rel=5e-7)
        assert isinstance(d[f"{sensor}_random_walk"], float) and d[f"{sensor}_random_walk"] > 0
    assert imukit.kalibr_yaml("stim300", rate_hz=125.0, topic="/imu0") == out
    with pytest.raises(imukit.ImuError, match="rate_hz"):
        imukit.kalibr_yaml("stim300", rate_hz=0.0)


def test_a_matlab_parameter_file_becomes_kalibrs_single_sided_figures(tmp_path):
    """`imukit presets --params FILE --format kalibr`: a MATLAB ``loadparams`` file is double-sided,
    so Kalibr's density is N/√2 and its random walk K·√2."""
    yaml = pytest.importorskip("yaml")
    part = tmp_path / "part.json"
    part.write_text(json.dumps({"MyPart": {
        "Accelerometer": {"NoiseDensity": 2e-3, "RandomWalk": 4e-4},
        "Gyroscope": {"NoiseDensity": 1e-3, "RandomWalk": 2e-5}}}))
    out = subprocess.run([imukit_bin(), "presets", "--params", str(part), "--format", "kalibr"],
                         check=True, capture_output=True, text=True).stdout
    d = yaml.safe_load(out)
    assert d["gyroscope_noise_density"] == pytest.approx(1e-3 / 2**0.5, rel=5e-7)
    assert d["gyroscope_random_walk"] == pytest.approx(2e-5 * 2**0.5, rel=5e-7)
    assert d["accelerometer_noise_density"] == pytest.approx(2e-3 / 2**0.5, rel=5e-7)
    assert "from MyPart" in out and "double-sided densities turned single-sided" in out


EUROC_IMU = ("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
             "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]")


def test_a_euroc_imu_file_is_read_by_its_header_with_stamps_to_the_nanosecond(tmp_path):
    first = 1403636579758555392  # EuRoC MH_01_easy's first IMU stamp
    stamps = first + np.array([0, 5_000_213, 9_999_871, 15_000_000, 20_000_001, 25_000_000], dtype=np.int64)
    readings = np.random.default_rng(3).normal(size=(stamps.size, 6)) + [0, 0, 0, 0, 0, 9.81]
    path = tmp_path / "mav0" / "imu0" / "data.csv"
    path.parent.mkdir(parents=True)
    with open(path, "w") as f:
        f.write(EUROC_IMU + "\n")
        for s, row in zip(stamps, readings):
            f.write(",".join([str(s)] + [repr(float(v)) for v in row]) + "\n")
    table = imukit.read(path)
    assert list(table) == ["t_s", "gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s",
                           "accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]
    np.testing.assert_array_equal(np.column_stack([table[c] for c in list(table)[1:]]), readings)
    origin = first // 86_400_000_000_000 * 86_400_000_000_000
    np.testing.assert_array_equal(np.round(table["t_s"] * 1e9).astype(np.int64) + origin, stamps)
    out = tmp_path / "o.csv"
    done = subprocess.run([imukit_bin(), "orient", str(path), "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert len(imukit.read(out)) == stamps.size


VENDOR_MAP = """time = { column = "Timestamp", unit = "ms" }
accel = { columns = ["AccX", "AccY", "AccZ"], unit = "g" }
gyro = { columns = ["GyrX", "GyrY", "GyrZ"], unit = "deg/s" }
mag = { columns = ["MagX", "MagY", "MagZ"], unit = "mG" }
axes = ["x", "-y", "-z"]
"""


def vendor_log(tmp_path):
    """A simulated run as a vendor writes it (pandas): epoch milliseconds, g, deg/s and
    milligauss, the y and z axes flipped, a temperature column; and its map."""
    sim = imukit.simulate({"rate_hz": 100.0, "duration_s": 5.0,
                           "trajectory": {"type": "builtin", "name": "platform-turn"}})
    imu = sim.imu.to_pandas()
    g, deg = 9.80665, np.pi / 180
    flip = {"x": 1.0, "y": -1.0, "z": -1.0}
    log = pd.DataFrame({"Timestamp": np.round(imu.t_s * 1e3).astype(np.int64) + 1_700_000_000_000})
    for ax in "xyz":
        log[f"Acc{ax.upper()}"] = flip[ax] * imu[f"accel_{ax}_m_s2"] / g
    for ax in "xyz":
        log[f"Gyr{ax.upper()}"] = flip[ax] * imu[f"gyro_{ax}_rad_s"] / deg
    for ax in "xyz":
        log[f"Mag{ax.upper()}"] = flip[ax] * imu[f"mag_{ax}_ut"] * 10.0
    log["Temp"] = 25.0
    path, map_path = tmp_path / "vendor.csv", tmp_path / "vendor.map.toml"
    log.to_csv(path, index=False)
    map_path.write_text(VENDOR_MAP)
    return sim, path, map_path


def test_a_vendor_csv_reads_through_its_column_map_in_si_and_body_axes(tmp_path):
    sim, path, map_path = vendor_log(tmp_path)
    table = imukit.read(path, map=map_path)
    assert list(table)[:10] == list(sim.imu)[:10] and list(table)[-1] == "Temp"
    for column in list(sim.imu)[1:]:
        np.testing.assert_allclose(table[column], sim.imu[column], rtol=1e-14, atol=1e-14, err_msg=column)
    # Integer milliseconds since 1970, kept exactly: seconds from that day's midnight.
    ms = np.round((table["t_s"] - table["t_s"][0]) * 1e3)
    np.testing.assert_array_equal(ms, np.round(sim.imu["t_s"] * 1e3))
    as_dict = imukit.read(path, map={
        "time": {"column": "Timestamp", "unit": "ms"},
        "accel": {"columns": ["AccX", "AccY", "AccZ"], "unit": "g"},
        "gyro": {"columns": ["GyrX", "GyrY", "GyrZ"], "unit": "deg/s"},
        "mag": {"columns": ["MagX", "MagY", "MagZ"], "unit": "mG"},
        "axes": ["x", "-y", "-z"]})
    for column in table:
        np.testing.assert_array_equal(as_dict[column], table[column])


def test_commands_take_a_column_map_and_refuse_a_bad_one_by_name(tmp_path):
    sim, path, map_path = vendor_log(tmp_path)
    plain = tmp_path / "plain.csv"
    sim.imu.write(plain)
    outs = {}
    # The plain file says its frame (the built-in scenario's NED); the vendor's is told.
    for name, extra in [("vendor", [str(path), "--map", str(map_path), "--nav-frame", "NED"]), ("plain", [str(plain)])]:
        out = tmp_path / f"{name}_orient.csv"
        done = subprocess.run([imukit_bin(), "orient", *extra, "--filter", "ahrsfilter", "--out", str(out)],
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        outs[name] = imukit.read(out)
    for column in ("q_w", "q_x", "q_y", "q_z"):
        np.testing.assert_allclose(outs["vendor"][column], outs["plain"][column], atol=1e-9)
    bad = tmp_path / "bad.toml"
    for text, expected in [
        (VENDOR_MAP.replace('"GyrZ"', '"GyroZ"'), 'names column "GyroZ", which the header does not have'),
        (VENDOR_MAP.replace('"deg/s"', '"furlong/s"'), 'gyro.unit: "furlong/s" is not a unit of rad/s'),
    ]:
        bad.write_text(text)
        out = tmp_path / "never.csv"
        done = subprocess.run([imukit_bin(), "orient", str(path), "--map", str(bad), "--out", str(out)],
                              capture_output=True, text=True)
        assert done.returncode == 65 and expected in done.stderr, done.stderr
        assert not out.exists()


def test_simulate_writes_a_euroc_sequence_that_reads_back_bit_for_bit(tmp_path):
    scenario = ROOT / "examples" / "matlab_orientation.toml"
    seq, imu_csv, truth_csv = tmp_path / "seq", tmp_path / "imu.csv", tmp_path / "truth.csv"
    for extra in (["--layout", "euroc", "--out", str(seq)], ["--out", str(imu_csv), "--truth", str(truth_csv)]):
        done = subprocess.run([imukit_bin(), "simulate", str(scenario), *extra], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
    with open(seq / "mav0" / "imu0" / "data.csv") as f:
        assert f.readline().startswith("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1]")
    imu, plain = imukit.read(seq / "mav0" / "imu0" / "data.csv"), imukit.read(imu_csv)
    # The readings bit for bit (the magnetometer has no column in the layout); times to the ns.
    assert sorted(imu) == sorted(c for c in plain if not c.startswith("mag_"))
    for column in imu:
        if column != "t_s":
            np.testing.assert_array_equal(imu[column], plain[column], err_msg=column)
    np.testing.assert_array_equal(np.round(imu["t_s"] * 1e9), np.round(plain["t_s"] * 1e9))
    truth, plain_truth = imukit.read(seq / "mav0" / "state_groundtruth_estimate0" / "data.csv"), imukit.read(truth_csv)
    for column in ("pos_x_m", "pos_z_m", "q_w", "q_z", "vel_y_m_s"):
        np.testing.assert_array_equal(truth[column], plain_truth[column], err_msg=column)
    done = subprocess.run([imukit_bin(), "simulate", str(scenario), "--layout", "euroc", "--out", str(tmp_path / "s2"),
                           "--truth", str(tmp_path / "t.csv")], capture_output=True, text=True)
    assert done.returncode == 65 and "--truth: a EuRoC sequence keeps its ground truth" in done.stderr, done.stderr


def test_a_map_gives_a_receivers_columns_to_imukits_by_name(tmp_path):
    """A map's `columns` table (here a dict): the receiver's names become imukit's, as they are;
    a name imukit does not read is refused by key."""
    path = tmp_path / "receiver.csv"
    path.write_text("gps_time,e,n,u,pos_std_1,pos_std_2,pos_std_3\n0.0,1.0,2.0,3.0,0.5,0.6,0.7\n"
                    "0.2,1.5,2.5,3.5,0.5,0.6,0.7\n")
    columns = {"pos_x_m": "e", "pos_y_m": "n", "pos_z_m": "u", "pos_x_sigma_m": "pos_std_1",
               "pos_y_sigma_m": "pos_std_2", "pos_z_sigma_m": "pos_std_3"}
    fixes = imukit.read(path, map={"time": {"column": "gps_time", "unit": "s"}, "columns": columns})
    assert list(fixes["pos_y_m"]) == [2.0, 2.5] and list(fixes["pos_z_sigma_m"]) == [0.7, 0.7]
    assert list(fixes["t_s"]) == [0.0, 0.2]
    with pytest.raises(imukit.ImuError, match="columns.pos_x_sigma"):
        imukit.read(path, map={"time": {"column": "gps_time", "unit": "s"}, "columns": {"pos_x_sigma": "e"}})
