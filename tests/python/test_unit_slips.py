"""Readings that look like a unit slip are warned about, naming the unit, and a table is never
written under a name that promises another format."""
import subprocess
import warnings

import numpy as np
import pytest

import imukit
from imukit import ImuError, ImuWarning

from test_cli_vs_python import imukit_bin

SCENARIO = {"rate_hz": 100.0, "duration_s": 5.0, "trajectory": {"type": "builtin", "name": "platform-turn"}}


@pytest.fixture(scope="module")
def sim():
    return imukit.simulate(SCENARIO)


def vendor(tmp_path, sim, accel_scale, gyro_scale, time_scale):
    """The run as a vendor's CSV whose units are those scales of SI."""
    import pandas as pd
    df = pd.DataFrame({"Time": sim.imu["t_s"] * time_scale})
    for ax in "xyz":
        df[f"A{ax}"] = sim.imu[f"accel_{ax}_m_s2"] * accel_scale
        df[f"G{ax}"] = sim.imu[f"gyro_{ax}_rad_s"] * gyro_scale
    path = tmp_path / "log.csv"
    df.to_csv(path, index=False)
    return path


def map_of(accel_unit="m/s^2", gyro_unit="rad/s", time_unit="s"):
    return {"time": {"column": "Time", "unit": time_unit},
            "accel": {"columns": ["Ax", "Ay", "Az"], "unit": accel_unit},
            "gyro": {"columns": ["Gx", "Gy", "Gz"], "unit": gyro_unit}}


@pytest.mark.parametrize("scales, needle", [
    ((1 / 9.80665, 1.0, 1.0), "accelerations in g read as m/s²"),
    ((1e3 / 9.80665, 1.0, 1.0), "accelerations in mg read as m/s²"),
    ((1.0, 1.0, 1e3), "time stamps in milliseconds read as seconds"),
])
def test_a_unit_declared_wrong_is_warned_about_and_declared_right_is_not(tmp_path, sim, scales, needle):
    path = vendor(tmp_path, sim, *scales)
    with pytest.warns(ImuWarning, match=needle):
        imukit.read(path, map=map_of())
    right = map_of(accel_unit="g" if scales[0] < 0.5 else ("mg" if scales[0] > 10 else "m/s^2"),
                   time_unit="ms" if scales[2] > 10 else "s")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImuWarning)
        table = imukit.read(path, map=right)
    np.testing.assert_allclose(table["accel_z_m_s2"], sim.imu["accel_z_m_s2"], rtol=1e-12)
    # The command line says the same on standard error, and still runs.
    done = subprocess.run([imukit_bin(), "orient", str(path), "--map", str(write_map(tmp_path, map_of())),
                           "--out", str(tmp_path / "o.csv")], capture_output=True, text=True)
    assert done.returncode == 0 and "warning" in done.stderr and needle in done.stderr, done.stderr


def test_rates_in_degrees_read_as_radians_are_named(tmp_path):
    spin = imukit.simulate({"rate_hz": 200.0, "duration_s": 2.0, "trajectory": {
        "type": "body-rates", "acceleration_body_m_s2": [0, 0, 0], "angular_velocity_body_rad_s": [0, 0, 1.0]}})
    path = vendor(tmp_path, spin, 1.0, 180 / np.pi, 1.0)
    with pytest.warns(ImuWarning, match=r"rates in °/s read as rad/s"):
        imukit.read(path, map=map_of())


def write_map(tmp_path, m):
    lines = [f'[time]\ncolumn = "{m["time"]["column"]}"\nunit = "{m["time"]["unit"]}"']
    for sensor in ("accel", "gyro"):
        cols = ", ".join(f'"{c}"' for c in m[sensor]["columns"])
        lines.append(f'[{sensor}]\ncolumns = [{cols}]\nunit = "{m[sensor]["unit"]}"')
    path = tmp_path / "map.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("name, needle", [
    ("x.mat", ".mat is not a table format imukit writes"),
    ("x.h5", ".h5 is not a table format"),
    ("x.xlsx", ".xlsx is not a table format"),
    ("x.db3", "name it .mcap"),
    ("x.bag", "name it .mcap"),
])
def test_a_table_is_not_written_under_a_name_that_promises_another_format(tmp_path, sim, name, needle):
    with pytest.raises(ImuError, match=needle):
        sim.imu.write(tmp_path / name)
    assert not (tmp_path / name).exists()
    imu = tmp_path / "imu.csv"
    sim.imu.write(imu)
    done = subprocess.run([imukit_bin(), "integrate", str(imu), "--out", str(tmp_path / name)],
                          capture_output=True, text=True)
    assert done.returncode == 65 and needle in done.stderr and "--out" in done.stderr, done.stderr
    assert not (tmp_path / name).exists()


def test_a_vendors_header_is_pointed_at_a_column_map(tmp_path, sim):
    path = vendor(tmp_path, sim, 1.0, 1.0, 1.0)
    done = subprocess.run([imukit_bin(), "integrate", str(path), "--out", str(tmp_path / "n.csv")],
                          capture_output=True, text=True)
    assert done.returncode == 65, done.stderr
    assert "--map FILE" in done.stderr, done.stderr
    # A reader that names the missing columns names the header's too.
    done = subprocess.run([imukit_bin(), "allan", str(path), "--column", "gyro_x_rad_s", "--out", str(tmp_path / "a.csv")],
                          capture_output=True, text=True)
    assert done.returncode == 65 and "--map FILE" in done.stderr, done.stderr
    # An imukit table that lacks a column is told which, without a map suggested.
    truth = tmp_path / "truth.csv"
    imukit.Table(["t_s", "pos_x_m"], [[0.0, 1.0]]).write(truth)
    sim.imu.write(tmp_path / "imu.csv")
    done = subprocess.run([imukit_bin(), "integrate", str(tmp_path / "imu.csv"), "--init", str(truth),
                           "--out", str(tmp_path / "n.csv")], capture_output=True, text=True)
    assert done.returncode == 65 and "--map" not in done.stderr, done.stderr
    assert "; the initial state comes from a truth CSV" in done.stderr, done.stderr


def test_options_that_would_be_ignored_are_refused(tmp_path, sim):
    csv, parquet = tmp_path / "imu.csv", tmp_path / "imu.parquet"
    sim.imu.write(csv)
    sim.imu.write(parquet)
    map_path = write_map(tmp_path, map_of())
    for args, needle in [
        (["integrate", str(parquet), "--map", str(map_path)], "--map: reads a vendor's CSV"),
        (["integrate", str(csv), "--topic", "/imu"], "--topic: chooses what to read from a ROS bag"),
        (["allan", str(csv), "--receive-time"], "--receive-time: chooses what to read from a ROS bag"),
    ]:
        done = subprocess.run([imukit_bin(), *args, "--out", str(tmp_path / "o.csv")], capture_output=True, text=True)
        assert done.returncode == 65 and needle in done.stderr, (args, done.stderr)
        assert not (tmp_path / "o.csv").exists()
