"""3D strapdown and comparison from Python."""
import numpy as np
import pytest

import imukit
from imukit import ImuError

HELIX = {
    "rate_hz": 400.0, "duration_s": 10.0,
    "trajectory": {"type": "expression", "position_m": ["5*cos(0.5*t)", "5*sin(0.5*t)", "0.3*t"],
                   "yaw_rad": "0.5*t + pi/2", "pitch_rad": "0.05", "roll_rad": "0.4*sin(1.7*t)"},
}


def test_simulate_strapdown_compare_round_trip():
    sim = imukit.simulate(HELIX)
    nav = imukit.strapdown(sim.imu, initial=sim.truth)
    errors, summary = imukit.compare(sim.truth, nav)
    assert summary["position_final_m"] < 1e-3 and summary["attitude_final_rad"] < 1e-5
    assert errors["pos_err_m"][-1] == pytest.approx(summary["position_final_m"])
    rk4 = imukit.strapdown(sim.imu, initial=sim.truth, scheme="rk4")
    _, fine = imukit.compare(sim.truth, rk4)
    assert fine["position_final_m"] < 1e-6
    with pytest.raises(ImuError, match="unknown scheme"):
        imukit.strapdown(sim.imu, scheme="euler")
    bare = imukit.strapdown(sim.imu, initial=sim.truth, coning=False, sculling=False)
    _, worse = imukit.compare(sim.truth, bare)
    assert worse["position_final_m"] > 10 * summary["position_final_m"]


def test_initial_state_from_a_dict_and_errors():
    imu = imukit.simulate({"rate_hz": 100.0, "duration_s": 60.0, "trajectory": {"type": "builtin", "name": "static"}}).imu
    nav = imukit.strapdown(imu, initial={"position_m": [1, 2, 3], "euler_rad": [0.5, 0, 0]})
    np.testing.assert_array_equal(nav["pos_x_m"], 1.0)
    np.testing.assert_allclose(nav["yaw_rad"], 0.5, atol=1e-15)
    with pytest.raises(ImuError, match="nav_frame"):
        imukit.strapdown(imu, nav_frame="XYZ")
    with pytest.raises(TypeError):
        imukit.strapdown(imu.values)


def test_body_rates_reproduce_matlabs_rotating_platform():
    fs = 100
    t = np.arange(600) / fs
    w = np.zeros((600, 3))
    w[:400, 2] = np.pi / 2
    w[400:, 2] = np.pi
    truth = imukit.truth_from_body_rates(t, np.zeros((600, 3)), w, nav_frame="NED")
    yaw = np.where(t <= 4, np.pi / 2 * t, 2 * np.pi + np.pi * (t - 4))
    np.testing.assert_allclose(truth["yaw_rad"], yaw, atol=1e-11)
    imu = imukit.ideal_imu(truth, nav_frame="NED", kind="accel-mag")
    np.testing.assert_allclose(imu["accel_z_m_s2"], -9.81, atol=1e-12)
    with pytest.raises(ValueError, match="omega_body_rad_s has 5 rows"):
        imukit.truth_from_body_rates(t, np.zeros((600, 3)), np.zeros((5, 3)))


def test_waypoints_pass_through_their_positions():
    knots = np.array([0.0, 2.0, 3.5, 6.0])
    p = np.array([[0, 0, 0], [10, 1, 0.5], [12, 6, 1], [5, 9, 1.5]], dtype=float)
    truth = imukit.truth_from_waypoints(knots, knots, p)
    np.testing.assert_allclose(np.column_stack([truth[f"pos_{a}_m"] for a in "xyz"]), p, atol=1e-12)
    with pytest.raises(ImuError, match="at least 2 waypoints"):
        imukit.truth_from_waypoints([0.0], [0.0], [[0, 0, 0]])
