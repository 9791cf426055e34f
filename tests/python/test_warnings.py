"""Silent slips are spoken of: readings clipped at a part's range (per axis, as a share of the
samples), figures implausible for their unit (with the likely slip and its SI value), angles in
degrees where radians are read, and sampling too coarse for the motion. The numbers stay as asked."""
import math
import subprocess
import warnings

import numpy as np
import pytest

import imukit
from imukit import ImuWarning

from test_cli_vs_python import imukit_bin

FIGURE8 = {"trajectory": {"type": "builtin", "name": "figure8"}}


def caught(scenario):
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        sim = imukit.simulate(scenario)
    return sim, [str(x.message) for x in w if issubclass(x.category, ImuWarning)]


def test_saturation_is_reported_per_axis_as_the_share_of_samples_clipped():
    scenario = {**FIGURE8, "rate_hz": 200.0, "duration_s": 2.0,
                "imu": {"kind": "accel-gyro", "accelerometer": {"measurement_range_m_s2": 50.0}}}
    sim, notes = caught(scenario)
    accel = np.column_stack([sim.imu[f"accel_{a}_m_s2"] for a in "xyz"])
    share = 100.0 * (np.abs(accel) >= 50.0).mean(axis=0)
    assert share.max() > 0
    [note] = [n for n in notes if "accelerometer saturated" in n]
    expected = ", ".join(f"{a} {s:.1f} %" for a, s in zip("xyz", share) if s > 0)
    assert f"measurement range ±50 m/s²: clipped readings {expected} (of {len(sim.imu)} samples)" in note
    # A range the motion stays within says nothing.
    _, quiet = caught({**scenario, "imu": {"kind": "accel-gyro"}})
    assert not [n for n in quiet if "saturated" in n]


def test_a_noise_density_in_degrees_per_root_hour_pasted_as_si_is_named():
    scenario = {"trajectory": {"type": "builtin", "name": "static"}, "duration_s": 1.0,
                "imu": {"gyroscope": {"noise_density_rad_s_per_rt_hz": 0.15}}}
    sim, notes = caught(scenario)
    [note] = notes
    si = 0.15 * math.pi / 180 / 60
    assert note.startswith("imu.gyroscope.noise_density: 0.15 rad/s/√Hz is more than any gyroscope")
    assert f"as °/√h it is {si:.4e} rad/s/√Hz".replace("e-05", "e-5") in note
    # The numbers are as asked: a 1.49 rad/s noise at 100 Hz (0.15·√100).
    assert np.std(sim.imu["gyro_x_rad_s"]) == pytest.approx(0.15 * 10, rel=0.1)


def test_degrees_where_radians_are_read_and_a_coarse_rate_are_named():
    scenario = {"rate_hz": 100.0, "duration_s": 1.0,
                "trajectory": {"type": "body-rates", "euler0_rad": [90, 0, 0],
                               "acceleration_body_m_s2": ["0", "0", "0"],
                               "angular_velocity_body_rad_s": ["0", "0", "0.1"]}}
    _, notes = caught(scenario)
    assert notes == ["trajectory.euler0_rad: 90 rad is more than a full turn; if it is in degrees, "
                     f"it is {math.radians(90):.6f} rad"]
    _, coarse = caught({**FIGURE8, "rate_hz": 0.5, "duration_s": 20.0})
    assert len(coarse) == 1 and coarse[0].startswith("rate_hz = 0.5 is coarse for this motion")
    _, fine = caught({**FIGURE8, "rate_hz": 2000.0, "duration_s": 1.0})
    assert fine == []


def test_the_command_line_prints_the_same_warnings(tmp_path):
    scenario = tmp_path / "s.toml"
    scenario.write_text('rate_hz = 200.0\nduration_s = 10.0\n[trajectory]\ntype = "builtin"\nname = "figure8"\n'
                        '[imu]\npreset = "mpu-6050"\nseed = 3\n')
    done = subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(tmp_path / "o.csv"), "--quiet"],
                          capture_output=True, text=True)
    assert done.returncode == 0
    lines = done.stderr.splitlines()
    assert any(line.startswith("imukit: warning: the accelerometer saturated at its measurement range")
               for line in lines), done.stderr
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        imukit.simulate(scenario)
    assert sorted(f"imukit: warning: {x.message}" for x in w) == sorted(lines)
