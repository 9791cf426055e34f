"""3D strapdown and comparison from Python."""
import math
import warnings

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


EARTH_FLIGHT = {
    "rate_hz": 50.0, "duration_s": 300.0, "nav_frame": "NED", "earth": "wgs84",
    "origin": {"latitude_deg": 47.0, "longitude_deg": 8.0, "height_m": 500.0},
    "trajectory": {"type": "expression",
                   "position_m": ["3000*sin(0.03*t) + 20*t", "3000*(1 - cos(0.03*t))", "-100*sin(0.01*t)"],
                   "attitude": "tangent"},
    "imu": {"kind": "accel-gyro"},
}


def test_on_the_wgs84_earth_the_imu_senses_the_earth_and_the_earth_strapdown_undoes_it():
    rest = imukit.simulate({"nav_frame": "NED", "earth": "wgs84", "duration_s": 1.0,
                            "origin": {"latitude_deg": 45.0, "longitude_deg": 0.0, "height_m": 0.0},
                            "trajectory": {"type": "builtin", "name": "static"}})
    omega = 7.292115e-5
    np.testing.assert_allclose(rest.imu["gyro_x_rad_s"], omega * np.cos(np.pi / 4), rtol=1e-14)
    np.testing.assert_allclose(rest.imu["gyro_z_rad_s"], -omega * np.sin(np.pi / 4), rtol=1e-14)
    assert list(rest.truth.columns[-6:]) == ["lat_rad", "lon_rad", "height_m", "ecef_x_m", "ecef_y_m", "ecef_z_m"]

    sim = imukit.simulate(EARTH_FLIGHT)
    nav = imukit.strapdown(sim.imu, initial=sim.truth, nav_frame="NED", earth="wgs84")
    _, on_earth = imukit.compare(sim.truth, nav)
    assert on_earth["position_max_m"] < 1e-6
    np.testing.assert_allclose(nav["lat_rad"], sim.truth["lat_rad"], atol=1e-12)
    # The tables say they are on the WGS-84 Earth: a flat mechanization is refused, and runs
    # on the same numbers without their descriptions.
    with pytest.raises(imukit.ImuError, match="earth: flat contradicts"):
        imukit.strapdown(sim.imu, initial=sim.truth, earth="flat")
    plain = lambda t: imukit.Table(t.columns, t.values)  # noqa: E731
    flat = imukit.strapdown(plain(sim.imu), initial=plain(sim.truth), nav_frame="NED")
    _, on_flat = imukit.compare(plain(sim.truth), flat)
    assert on_flat["position_final_m"] > 1000.0  # the flat mechanization ignores the Earth

    # A start given by its parts: at rest, level, at 45° N, for an hour with the height held.
    imu = imukit.simulate({"nav_frame": "NED", "earth": "wgs84", "duration_s": 600.0, "rate_hz": 10.0,
                           "origin": {"latitude_deg": 45.0, "longitude_deg": 0.0, "height_m": 0.0},
                           "trajectory": {"type": "builtin", "name": "static"}}).imu
    still = imukit.strapdown(imu, nav_frame="NED", earth="wgs84", vertical="hold",
                             initial={"latitude_deg": 45.0, "longitude_deg": 0.0, "height_m": 0.0})
    assert np.max(np.abs(still["pos_x_m"])) < 1e-6 and np.max(np.abs(still["pos_y_m"])) < 1e-6
    # Without a start, the described origin is the start (as on the command line) …
    described = imukit.strapdown(imu, vertical="hold")
    np.testing.assert_array_equal(described.values, still.values)
    # … and a table that says nothing of its origin needs one.
    with pytest.raises(ImuError, match="lat_rad, lon_rad, height_m") as e:
        imukit.strapdown(imukit.Table(imu.columns, imu.values), nav_frame="NED", earth="wgs84")
    with pytest.raises(ImuError, match="unknown vertical channel") as e:
        imukit.strapdown(imu, earth="wgs84", vertical="float", initial={"latitude_deg": 0, "longitude_deg": 0, "height_m": 0})
    assert e.value.field == "vertical"
    with pytest.raises(ImuError, match="lon0_deg: missing"):
        imukit.strapdown(imu, earth="wgs84", initial={"latitude_deg": 0})


def test_gyrocompassing_finds_north_with_a_navigation_grade_imu_only():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[3] / "examples" / "gyrocompass.py"
    spec = importlib.util.spec_from_file_location("gyrocompass", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    # HG9900: bias 0.003 °/h and angle random walk against the 10.6 °/h horizontal Earth rate at
    # 45°: a few hundredths of a degree after ten minutes (well within 0.1° for any seed).
    for seed in (1, 2, 3):
        assert abs(module.run("hg9900", seed=seed)) < 0.1
    # HG1700 (1 °/h bias): degrees off, as bias / (Ω cos φ) = 5.4° predicts.
    assert 2.0 < abs(module.run("hg1700")) < 15.0


def test_a_scenario_with_a_gnss_receiver_returns_its_fixes():
    scenario = {"rate_hz": 100.0, "duration_s": 20.0, "trajectory": {"type": "builtin", "name": "figure8"},
                "gnss": {"rate_hz": 10.0, "horizontal_accuracy_m": 0.0, "vertical_accuracy_m": 0.0,
                         "velocity_accuracy_m_s": 0.0, "latency_s": 0.1}}
    sim = imukit.simulate(scenario)
    assert list(sim.gnss.columns) == ["t_s", "pos_x_m", "pos_y_m", "pos_z_m", "vel_x_m_s", "vel_y_m_s", "vel_z_m_s"]
    # Exact fixes of every 10th sample, stamped 0.1 s late (the last one falls after the run).
    np.testing.assert_allclose(sim.gnss["t_s"], sim.truth["t_s"][:-10:10] + 0.1, atol=1e-12)
    np.testing.assert_allclose(sim.gnss["pos_x_m"], sim.truth["pos_x_m"][:-10:10], atol=1e-12)
    noisy = imukit.simulate({**scenario, "gnss": {"rate_hz": 10.0}}, run=3)
    again = imukit.simulate({**scenario, "gnss": {"rate_hz": 10.0}}, run=3)
    np.testing.assert_array_equal(noisy.gnss.values, again.gnss.values)
    assert imukit.simulate({k: v for k, v in scenario.items() if k != "gnss"}).gnss is None
    with pytest.raises(ImuError, match="gnss.rate_hz") as e:
        imukit.simulate({**scenario, "gnss": {"rate_hz": 7.0}})
    assert e.value.field == "gnss.rate_hz"


def test_fuse_keeps_a_car_within_its_stated_uncertainty_through_a_gnss_outage():
    scenario = {
        "rate_hz": 100.0, "duration_s": 120.0, "nav_frame": "ENU",
        "trajectory": {"type": "expression", "position_m": ["60*sin(0.16*t)", "60*(1 - cos(0.16*t))", "2*sin(0.1*t)"],
                       "attitude": "tangent"},
        "imu": {"kind": "accel-gyro", "preset": "stim300", "seed": 4},
        "gnss": {"rate_hz": 5.0, "decay_factor": 0.0, "horizontal_accuracy_m": 1.0, "vertical_accuracy_m": 2.0,
                 "outages": [{"start_s": 60.0, "duration_s": 30.0}]},
    }
    sim = imukit.simulate(scenario)
    nav = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario)
    assert list(nav.columns[14:17]) == ["pos_x_sigma_m", "pos_y_sigma_m", "pos_z_sigma_m"]
    errors, summary = imukit.compare(sim.truth, nav)
    # With fixes: well inside the fixes' own metre; the stated one-sigma grows through the
    # outage and the error stays within 3σ of it (per axis) at its end.
    t = nav["t_s"]
    k = int(np.argmin(np.abs(t - 89.99)))
    for axis in "xy":
        assert abs(errors[f"pos_err_{axis}_m"][k]) < 3 * nav[f"pos_{axis}_sigma_m"][k]
    assert nav["pos_x_sigma_m"][k] > 3 * nav["pos_x_sigma_m"][int(np.argmin(np.abs(t - 59.0)))]
    assert summary["position_final_m"] < 1.0
    with pytest.raises(ImuError, match="no \\[gnss\\] receiver"):
        imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario={k: v for k, v in scenario.items() if k != "gnss"})


def test_fuse_with_an_odometer_and_the_vehicle_constraints_holds_the_car_through_the_outage():
    # The same car and outage with a 10 Hz odometer and the non-holonomic constraints: the error
    # at the outage's end is far below the GNSS-only filter's, like imukit fuse --odometer --nhc.
    scenario = {
        "rate_hz": 100.0, "duration_s": 120.0, "nav_frame": "ENU",
        "trajectory": {"type": "expression", "position_m": ["60*sin(0.16*t)", "60*(1 - cos(0.16*t))", "2*sin(0.1*t)"],
                       "attitude": "tangent"},
        "imu": {"kind": "accel-gyro", "preset": "icm-42688-p", "seed": 4},
        "gnss": {"rate_hz": 5.0, "decay_factor": 0.0, "outages": [{"start_s": 60.0, "duration_s": 30.0}]},
        "odometer": {"rate_hz": 10.0, "noise_m_s": 0.05},
    }
    sim = imukit.simulate(scenario)
    k = int(np.argmin(np.abs(sim.truth["t_s"] - 89.99)))

    def horizontal_error(nav):
        return math.hypot(nav["pos_x_m"][k] - sim.truth["pos_x_m"][k], nav["pos_y_m"][k] - sim.truth["pos_y_m"][k])

    alone = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario)
    wheels = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario, odometer=sim.odometer,
                         nhc_sigma_m_s=0.05)
    assert wheels["pos_x_sigma_m"][k] < 0.5 * alone["pos_x_sigma_m"][k]
    assert horizontal_error(wheels) < 3 * math.hypot(wheels["pos_x_sigma_m"][k], wheels["pos_y_sigma_m"][k])
    with pytest.raises(ImuError, match="nhc_sigma_m_s") as e:
        imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario, nhc_sigma_m_s=0.0)
    assert e.value.field == "nhc_sigma_m_s"
    with pytest.raises(ImuError, match="no \\[baro\\]"):
        imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario, baro=sim.odometer)


def test_fuse_of_a_consumer_imu_finds_the_rest_and_the_sensor_error_states_itself():
    # The example road with an MPU-6050 (±20 °/s turn-on bias, 2 % cross-axis sensitivity).
    # Plain fuse finds the 20 s wait in the readings and, the part's 2 % being above 0.1 %,
    # estimates its scale factors, misalignment and g-sensitivity: it holds the car through the
    # tunnel within its stated uncertainty, as told of both (imukit fuse --rest-s 20
    # --sensor-errors). Told of neither, the 15-state filter loses the fixes (it is reset to
    # them, and says so).
    from pathlib import Path
    import tomllib
    path = Path(__file__).resolve().parents[3] / "examples" / "car_tunnel.toml"
    scenario = tomllib.loads(path.read_text())
    scenario["imu"]["preset"] = "mpu-6050"
    sim = imukit.simulate(scenario)
    with pytest.warns(imukit.ImuWarning, match="lost the fixes"):
        lost = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario, rest_s=0.0, sensor_errors=False)
    assert lost["gnss_resets"][-1] > 0
    with warnings.catch_warnings():
        warnings.simplefilter("error", imukit.ImuWarning)
        plain = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario)
    assert plain["gnss_resets"][-1] == 0
    assert "gyro_g_sensitivity_z_rad_s_per_m_s2" in plain.columns
    for axis in "xyz":
        error = np.abs(plain[f"pos_{axis}_m"] - sim.truth[f"pos_{axis}_m"])
        assert np.all(error <= 3 * plain[f"pos_{axis}_sigma_m"]), axis
    with warnings.catch_warnings():
        warnings.simplefilter("error", imukit.ImuWarning)
        nav = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario, rest_s=20.0, sensor_errors=True)
    assert nav["gnss_resets"][-1] == 0
    assert "gyro_g_sensitivity_z_rad_s_per_m_s2" in nav.columns
    assert "accel_misalignment_zx_sigma" in nav.columns
    k = int(np.argmin(np.abs(nav["t_s"] - 149.99)))
    error = math.hypot(nav["pos_x_m"][k] - sim.truth["pos_x_m"][k], nav["pos_y_m"][k] - sim.truth["pos_y_m"][k])
    assert error < 3 * math.hypot(nav["pos_x_sigma_m"][k], nav["pos_y_sigma_m"][k])
    # After the rest the z gyroscope's reading at rest is known: its bias plus its g-sensitivity
    # times gravity (the two are told apart only on the road).
    i = int(np.argmin(np.abs(nav["t_s"] - 19.99)))
    at_rest = nav["gyro_bias_z_rad_s"][i] + 9.81 * nav["gyro_g_sensitivity_z_rad_s_per_m_s2"][i]
    assert abs(at_rest - (0.349066 + 9.81 * 0.000177974)) < 1e-4
    with pytest.raises(ImuError, match="rest_s") as e:
        imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario, rest_s=-1.0)
    assert e.value.field == "rest_s"


def test_fuse_aligns_from_gnss_without_truth():
    # A car from rest: without initial=, align="gnss" starts the filter at the first fix at
    # 3 m/s or more (the estimate begins there), heading along its velocity.
    scenario = {
        "rate_hz": 100.0, "nav_frame": "NED",
        "trajectory": {"type": "waypoints", "time_s": [0, 10, 20, 30],
                       "position_m": [[0, 0, 0], [60, 10, 0], [160, 60, 0], [220, 160, 0]],
                       "velocity_m_s": [[0, 0, 0], [0, 0, 0]]},
        "imu": {"kind": "accel-gyro", "preset": "stim300", "seed": 2},
        "gnss": {"rate_hz": 5.0, "decay_factor": 0.0},
    }
    sim = imukit.simulate(scenario)
    nav = imukit.fuse(sim.imu, sim.gnss, scenario=scenario, align="gnss")
    speed = np.hypot(sim.gnss["vel_x_m_s"], sim.gnss["vel_y_m_s"])
    assert nav["t_s"][0] == pytest.approx(sim.gnss["t_s"][np.argmax(speed >= 3.0)])
    k = int(np.searchsorted(sim.truth["t_s"], nav["t_s"][-1] - 1e-9))
    yaw_error = (nav["yaw_rad"][-1] - sim.truth["yaw_rad"][k] + math.pi) % (2 * math.pi) - math.pi
    assert abs(yaw_error) < 3 * nav["att_z_sigma_rad"][-1]
    with pytest.raises(ImuError, match="north") as e:
        imukit.fuse(sim.imu, sim.gnss, scenario=scenario, align="static")
    assert e.value.field == "align"
    with pytest.raises(ImuError, match="not both"):
        imukit.fuse(sim.imu, sim.gnss, scenario=scenario, initial=sim.truth, align="gnss")


def test_fuse_on_the_wgs84_earth_takes_geodetic_fixes():
    scenario = {
        "rate_hz": 100.0, "duration_s": 60.0, "nav_frame": "ENU", "earth": "wgs84",
        "origin": {"latitude_deg": 45.0, "longitude_deg": 7.0, "height_m": 300.0},
        "trajectory": {"type": "expression", "position_m": ["60*sin(0.16*t)", "60*(1 - cos(0.16*t))", "0"],
                       "attitude": "tangent"},
        "imu": {"kind": "accel-gyro", "preset": "stim300", "seed": 1},
        "gnss": {"rate_hz": 5.0, "decay_factor": 0.0, "horizontal_accuracy_m": 1.0},
    }
    sim = imukit.simulate(scenario)
    assert "lat_rad" in sim.gnss.columns
    nav = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario)
    assert list(nav.columns[-4:]) == ["lat_rad", "lon_rad", "height_m", "gnss_resets"]
    errors, summary = imukit.compare(sim.truth, nav)
    assert summary["position_rms_m"] < 1.0
    # The geodetic output and the tangent-plane one describe the same place (1 m ≈ 1.6e-7 rad).
    k = -1
    north = (nav["lat_rad"][k] - sim.truth["lat_rad"][k]) * 6.37e6
    assert abs(north - errors["pos_err_y_m"][k]) < 0.01


def test_a_scenario_with_a_barometer_and_an_odometer_returns_their_readings():
    sim = imukit.simulate({"rate_hz": 100.0, "duration_s": 20.0, "nav_frame": "NED",
                           "trajectory": {"type": "expression", "position_m": ["10*t", "0", "-50"], "attitude": "tangent"},
                           "baro": {"bias_m": 2.0, "noise_m": 0.0}, "odometer": {"scale_factor_error": 0.01, "noise_m_s": 0.0}})
    np.testing.assert_allclose(sim.baro["baro_height_m"], 52.0, atol=1e-9)
    np.testing.assert_allclose(sim.odometer["speed_m_s"], 10.1, atol=1e-9)
    assert sim.gnss is None


def test_barometer_readings_damp_the_vertical_channel_of_earth_navigation():
    scenario = {"rate_hz": 10.0, "duration_s": 1200.0, "nav_frame": "NED", "earth": "wgs84",
                "origin": {"latitude_deg": 45.0, "longitude_deg": 7.0, "height_m": 300.0},
                "trajectory": {"type": "builtin", "name": "static"},
                "imu": {"kind": "accel-gyro", "accelerometer": {"ConstantBias": [0.0, 0.0, 0.001]}},
                "baro": {"noise_m": 0.5}}
    sim = imukit.simulate(scenario)
    damped = imukit.strapdown(sim.imu, initial=sim.truth, nav_frame="NED", earth="wgs84", vertical="baro",
                              baro=sim.baro)
    free = imukit.strapdown(sim.imu, initial=sim.truth, nav_frame="NED", earth="wgs84", vertical="free")
    assert abs(damped["height_m"][-1] - 300.0) < 2.0
    assert abs(free["height_m"][-1] - 300.0) > 700.0
    with pytest.raises(ImuError, match="needs t_s and baro_height_m"):
        imukit.strapdown(sim.imu, initial=sim.truth, nav_frame="NED", earth="wgs84", vertical="baro",
                         baro=sim.truth)


def test_barometer_readings_without_the_baro_channel_are_refused_as_by_the_command_line():
    scenario = {"rate_hz": 10.0, "duration_s": 5.0, "earth": "wgs84",
                "origin": {"latitude_deg": 45.0, "longitude_deg": 7.0, "height_m": 300.0},
                "trajectory": {"type": "builtin", "name": "static"}, "baro": {"noise_m": 0.1}}
    sim = imukit.simulate(scenario)
    for vertical in ("free", "hold"):
        with pytest.raises(ImuError, match="barometer readings feed the baro-damped vertical channel") as e:
            imukit.strapdown(sim.imu, initial=sim.truth, earth="wgs84", vertical=vertical, baro=sim.baro)
        assert e.value.field == "baro"
    nav = imukit.strapdown(sim.imu, initial=sim.truth, earth="wgs84", vertical="baro", baro=sim.baro)
    assert len(nav) == len(sim.imu)


def test_smoothing_on_the_wgs84_earth_brings_an_outage_back_to_the_fixes():
    # A circle on WGS-84 with a 20 s GNSS outage: the smoothed estimate (same columns) is closer
    # to the truth through the outage than the filter's, and the CLI's --smooth gives the same.
    scenario = {
        "rate_hz": 100.0, "duration_s": 60.0, "nav_frame": "NED", "earth": "wgs84",
        "origin": {"latitude_deg": 45.0, "longitude_deg": 7.0, "height_m": 300.0},
        "trajectory": {"type": "expression", "position_m": ["60*sin(0.16*t)", "60*(1 - cos(0.16*t))", "0"],
                       "attitude": "tangent"},
        "imu": {"kind": "accel-gyro", "preset": "stim300", "seed": 2},
        "gnss": {"rate_hz": 5.0, "decay_factor": 0.0, "horizontal_accuracy_m": 1.0,
                 "outages": [{"start_s": 25.0, "duration_s": 20.0}]},
    }
    sim = imukit.simulate(scenario)
    filtered = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario)
    smoothed = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario, smooth=True)
    assert list(smoothed.columns) == list(filtered.columns)
    outage = (sim.truth["t_s"] > 25.0) & (sim.truth["t_s"] < 45.0)
    def rms(nav):
        e, _ = imukit.compare(sim.truth, nav)
        return float(np.sqrt(np.mean(e["pos_err_m"][outage] ** 2)))
    assert rms(smoothed) < 0.5 * rms(filtered), (rms(smoothed), rms(filtered))
    # Smoothed one-sigma no larger than the filter's anywhere (it uses more data).
    assert np.all(smoothed["pos_x_sigma_m"] <= filtered["pos_x_sigma_m"] * (1 + 1e-9) + 1e-12)


def test_a_noisy_walk_is_fused_from_its_readings_alone():
    # No scenario, no part, no start: the noise learnt from the log, levelled over the rest,
    # heading zero at the origin; a lap of a 10 m circle (62.8 m) with an IMU three times
    # noisier than any preset and a 0.03 g accelerometer bias closes within 0.5 %.
    scenario = {
        "rate_hz": 100.0, "duration_s": 60.0, "nav_frame": "ENU",
        "trajectory": {"type": "walk", "cadence_hz": 0.9, "stride_m": 2 * math.pi * 10 / 45,
                       "radius_m": 10.0, "start_s": 10.0},
        "imu": {"kind": "accel-gyro", "preset": "icm-42688-p", "seed": 2,
                "accelerometer": {"noise_density_m_s2_per_rt_hz": 0.011768,
                                  "constant_bias_m_s2": [0.3, -0.2, 0.25]},
                "gyroscope": {"noise_density_rad_s_per_rt_hz": 0.00036652}},
    }
    sim = imukit.simulate(scenario)
    nav = imukit.fuse(sim.imu, None, zupt=True)
    end = np.array([nav[f"pos_{a}_m"][-1] for a in "xyz"])
    # Begins where the rest ends: the foot stands 10 s and through its first stride's stance
    # (0.6 of a stride at 0.9 strides a second).
    moves = 10.0 + 0.6 / 0.9
    assert moves - 0.6 < nav["t_s"][0] <= moves
    assert np.linalg.norm(end) < 0.005 * 2 * math.pi * 10
    with pytest.raises(ValueError, match="not both"):
        imukit.fuse(sim.imu, None, scenario=scenario, imu_model="stim300")


def test_a_walk_without_fixes_is_navigated_by_its_stances():
    # examples/walk.toml: 754 m around a circle and back; no GNSS at all, zero-velocity updates.
    from pathlib import Path
    path = Path(__file__).resolve().parents[3] / "examples" / "walk.toml"
    sim = imukit.simulate(str(path))
    nav = imukit.fuse(sim.imu, None, initial=sim.truth, scenario=str(path), zupt=True, rest_s=10.0)
    end = np.array([nav[f"pos_{a}_m"][-1] for a in "xyz"])
    start = np.array([sim.truth[f"pos_{a}_m"][0] for a in "xyz"])
    assert np.linalg.norm(end - start) < 0.01 * 754.0
