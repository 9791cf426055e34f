"""Planar dead reckoning from Python: the exercise's rules, the default scheme, files."""
import math

import numpy as np
import pytest

import imukit
from imukit import ImuError


def test_exercise_scheme_three_sample_case():
    nav = imukit.planar_dead_reckon([0, 1, 2], [0, 1, 1], [0, 0.5, 0.2], [0, 0.1, 0.2], scheme="exercise")
    x1 = 100 + math.cos(0.1) * 1.5 + math.sin(0.1) * 0.6
    y1 = 100 - math.sin(0.1) * 1.5 + math.cos(0.1) * 0.6
    assert abs(nav["pos_x_m"][1] - x1) < 1e-13 and abs(nav["pos_y_m"][1] - y1) < 1e-13
    assert nav["yaw_rad"][2] == pytest.approx(0.3, abs=1e-15)


def test_default_scheme_recovers_the_cart_and_files_round_trip(tmp_path):
    sim = imukit.simulate({"trajectory": {"type": "builtin", "name": "cart"}})
    imu, truth = sim.imu, sim.truth
    nav = imukit.planar_dead_reckon(imu["t_s"], imu["accel_x_m_s2"], imu["accel_y_m_s2"], imu["gyro_z_rad_s"])
    err = np.hypot(nav["pos_x_m"] - truth["pos_x_m"], nav["pos_y_m"] - truth["pos_y_m"])
    assert err.max() < 0.4
    dat = tmp_path / "inertial_data.dat"
    np.savetxt(dat, np.column_stack([imu["t_s"], imu["accel_x_m_s2"], imu["accel_y_m_s2"], imu["gyro_z_rad_s"]]))
    back = imukit.read_planar(dat)
    np.testing.assert_array_equal(back["gyro_z_rad_s"], imu["gyro_z_rad_s"])


def test_bad_planar_input():
    with pytest.raises(ImuError, match="does not increase"):
        imukit.planar_dead_reckon([0, 1, 1], [0, 0, 0], [0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="accel_y_m_s2 has 2 rows, expected 3"):
        imukit.planar_dead_reckon([0, 1, 2], [0, 0, 0], [0, 0], [0, 0, 0])
    with pytest.raises(ImuError, match="unknown scheme"):
        imukit.planar_dead_reckon([0, 1], [0, 0], [0, 0], [0, 0], scheme="euler")
