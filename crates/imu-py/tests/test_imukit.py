"""The Python face of imukit: closed-form values, sign anchors, MATLAB gradient parity, errors."""
import json
import math

import numpy as np
import pytest

import imukit
from imukit import ImuError

REL_TOL = 1e-9
G = 9.81


def rel_err(got, expected):
    scale = max(np.max(np.abs(expected)), 1.0)
    return float(np.max(np.abs(np.asarray(got) - np.asarray(expected))) / scale)


@pytest.mark.parametrize("nav_frame, z_up", [("ENU", 1.0), ("NED", -1.0)])
def test_level_circle_from_expressions_matches_closed_form(nav_frame, z_up):
    r, w = 3.0, 0.7
    t = np.arange(0, 400) * 0.01
    truth = imukit.truth_from_expressions(
        t, ["R*cos(w*t)", "R*sin(w*t)", "1.5"], attitude="tangent", constants={"R": r, "w": w}, nav_frame=nav_frame
    )
    assert rel_err(truth["vel_x_m_s"], -r * w * np.sin(w * t)) < REL_TOL
    assert rel_err(truth["acc_y_m_s2"], -r * w * w * np.sin(w * t)) < REL_TOL
    assert rel_err(truth["omega_z_rad_s"], np.full_like(t, w)) < REL_TOL
    assert rel_err(truth["yaw_rad"], w * t + math.pi / 2) < REL_TOL
    lever = [0.2, -0.1, 0.05]
    imu = imukit.ideal_imu(truth, lever_arm_m=lever, nav_frame=nav_frame)
    assert rel_err(imu["accel_x_m_s2"], np.full_like(t, -w * w * lever[0])) < REL_TOL
    assert rel_err(imu["accel_y_m_s2"], np.full_like(t, r * w * w - w * w * lever[1])) < REL_TOL
    assert rel_err(imu["accel_z_m_s2"], np.full_like(t, z_up * G)) < REL_TOL


@pytest.mark.parametrize("nav_frame, up", [("ENU", 1.0), ("NED", -1.0)])
def test_level_static_imu_reads_plus_g_up_and_the_opposite_in_matlab_mode(nav_frame, up):
    t = np.linspace(0, 1, 11)
    truth = imukit.truth_from_expressions(t, [0, 0, 0], attitude="level", nav_frame=nav_frame)
    sf = imukit.ideal_imu(truth, nav_frame=nav_frame)
    mat = imukit.ideal_imu(truth, nav_frame=nav_frame, accel_sign="matlab")
    assert np.all(sf["accel_z_m_s2"] == up * G)
    assert np.all(mat["accel_z_m_s2"] == -up * G)


def test_yaw_90_maps_body_x_to_north():
    c = imukit.euler_to_dcm([[math.pi / 2, 0.0, 0.0]])[0]
    np.testing.assert_allclose(c @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(c.T @ [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], atol=1e-15)


def test_conversions_round_trip():
    rng = np.random.default_rng(7)
    e = np.column_stack([rng.uniform(-3, 3, 50), rng.uniform(-1.5, 1.5, 50), rng.uniform(-3, 3, 50)])
    q = imukit.euler_to_quaternion(e)
    np.testing.assert_allclose(imukit.quaternion_to_euler(q), e, atol=1e-12)
    np.testing.assert_allclose(imukit.quaternion_to_dcm(q), imukit.euler_to_dcm(e), atol=1e-14)
    q2 = imukit.dcm_to_quaternion(imukit.euler_to_dcm(e))
    np.testing.assert_allclose(np.abs(np.sum(q * q2, axis=1)), 1.0, atol=1e-12)
    np.testing.assert_allclose(imukit.dcm_to_euler(imukit.euler_to_dcm(e)), e, atol=1e-12)
    for f in (imukit.quaternion_to_euler, imukit.quaternion_to_dcm):
        with pytest.raises(ImuError, match=r"quaternion\[1\] has zero norm"):
            f([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])


def matlab_gradient(x, t):
    """MATLAB gradient(x, t) along the first axis, written out (central inside, one-sided ends)."""
    g = np.empty_like(x)
    g[1:-1] = (x[2:] - x[:-2]) / (t[2:] - t[:-2])[:, None]
    g[0] = (x[1] - x[0]) / (t[1] - t[0])
    g[-1] = (x[-1] - x[-2]) / (t[-1] - t[-2])
    return g


def test_order_two_matches_matlab_gradient_to_rounding_on_uneven_times():
    t = np.cumsum(np.r_[0.0, 0.01 + 0.003 * np.sin(np.arange(60))])
    s = np.column_stack([np.cos(3 * t), np.sin(2 * t) * t, t**2])
    truth = imukit.truth_from_samples(t, s, attitude="level", order=2)
    v = np.column_stack([truth[f"vel_{a}_m_s"] for a in "xyz"])
    a = np.column_stack([truth[f"acc_{a}_m_s2"] for a in "xyz"])
    v_ref = matlab_gradient(s, t)
    a_ref = matlab_gradient(v_ref, t)
    np.testing.assert_allclose(v, v_ref, rtol=0, atol=1e-12 * np.max(np.abs(v_ref)))
    np.testing.assert_allclose(a, a_ref, rtol=0, atol=1e-11 * np.max(np.abs(a_ref)))
    # On even times it is also numpy.gradient.
    te = np.arange(40) * 0.01
    se = np.column_stack([np.cos(3 * te), te**3, te])
    tr = imukit.truth_from_samples(te, se, attitude="level", order=2)
    np.testing.assert_allclose(tr["vel_y_m_s"], np.gradient(se[:, 1], te, edge_order=1), rtol=0, atol=1e-12)


def test_tilted_circle_samples_at_default_order_are_within_1e8():
    t = np.arange(201) / 200.0
    kw = dict(constants={"f": 1.0})
    pos = ["0.8*cos(2*pi*f*t)", "0.8*sin(2*pi*f*t)", "0.3*cos(2*pi*f*t)"]
    pitch = "asin(3*sqrt(2)*sin(2*pi*f*t)/sqrt(137 - 9*cos(4*pi*f*t)))"
    exact = imukit.truth_from_expressions(t, pos, yaw_rad="2*pi*f*t + pi/2", pitch_rad=pitch, **kw)
    p = np.column_stack([exact[f"pos_{a}_m"] for a in "xyz"])
    e = np.column_stack([exact["yaw_rad"], exact["pitch_rad"], exact["roll_rad"]])
    sampled = imukit.truth_from_samples(t, p, euler_rad=e)
    for c in ["vel_x_m_s", "acc_z_m_s2", "omega_y_rad_s", "alpha_x_rad_s2", "alpha_z_rad_s2"]:
        assert rel_err(sampled[c], exact[c]) < 1e-8, c


def test_errors_are_imu_errors_that_say_what_and_where():
    t = np.linspace(0, 1, 20)
    with pytest.raises(ImuError, match=r"unknown function 'sine'.*column 5"):
        imukit.truth_from_expressions(t, ["0.8*sine(t)", "0", "0"])
    with pytest.raises(ImuError, match=r"unknown variable 'q'"):
        imukit.truth_from_expressions(t, ["q*t", "0", "0"])
    bad = np.column_stack([t, t, t])
    bad[5, 2] = np.nan
    with pytest.raises(ImuError, match=r"position_m at sample 5 is not a finite number"):
        imukit.truth_from_samples(t, bad, attitude="tangent")
    t2 = t.copy()
    t2[7] = t2[6]
    with pytest.raises(ImuError, match=r"sample 7.*does not increase"):
        imukit.truth_from_samples(t2, np.column_stack([t, t, t]), attitude="tangent")
    with pytest.raises(ImuError, match=r"too few samples.*need at least 10"):
        imukit.truth_from_samples(t[:5], np.zeros((5, 3)))
    with pytest.raises(ValueError, match=r"position_m must have shape \(N, 3\)"):
        imukit.truth_from_samples(t, np.zeros((20, 2)))
    with pytest.raises(ValueError, match=r"euler_rad has 19 rows, expected 20"):
        imukit.truth_from_samples(t, np.zeros((20, 3)), euler_rad=np.zeros((19, 3)))
    e = np.zeros((20, 3))
    e[3, 1] = math.pi / 2
    with pytest.raises(ImuError, match=r"gimbal lock"):
        imukit.truth_from_samples(t, np.zeros((20, 3)), euler_rad=e)
    with pytest.raises(ImuError, match=r"nav_frame"):
        imukit.truth_from_expressions(t, ["t", "0", "0"], nav_frame="NWU")
    with pytest.raises(ImuError, match=r"accel_sign"):
        imukit.ideal_imu(imukit.truth_from_expressions(t, ["t", "0", "0"]), accel_sign="up")
    with pytest.raises(ImuError, match=r"unknown built-in scenario \"nope\""):
        imukit.simulate({"trajectory": {"type": "builtin", "name": "nope"}})
    with pytest.raises(ImuError, match=r"no_such.toml"):
        imukit.simulate("no_such.toml")


def test_simulate_dict_and_builtins():
    assert "figure8" in imukit.builtin_scenarios()
    sim = imukit.simulate({"rate_hz": 100.0, "trajectory": {"type": "builtin", "name": "platform-turn"}})
    assert len(sim.imu) == 600
    np.testing.assert_allclose(sim.imu["gyro_z_rad_s"][100], math.pi / 2, atol=1e-12)
    assert "mag_x_ut" in sim.imu and "omega_z_rad_s" in sim.truth
    with pytest.raises(KeyError, match="no column 'nope'"):
        sim.truth["nope"]


def test_a_deeply_nested_formula_raises_instead_of_crashing_the_interpreter():
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ImuError, match="nested deeper than 64 levels") as e:
        imukit.truth_from_expressions(t, ["(" * 5000 + "t" + ")" * 5000, "0", "0"])
    assert e.value.field == "trajectory.position_m[0]"
    with pytest.raises(ImuError, match="more than 1000 operations deep"):
        imukit.truth_from_expressions(t, ["+".join(["t"] * 40_000), "0", "0"])


def test_a_run_too_long_for_memory_raises_before_allocating():
    with pytest.raises(ImuError, match="IMUKIT_MAX_MEMORY_GB") as e:
        imukit.simulate({"rate_hz": 1e8, "duration_s": 9.99, "trajectory": {"type": "builtin", "name": "static"}})
    assert e.value.field == "duration_s"


def test_a_dict_value_of_no_scenario_type_is_refused_naming_its_place():
    static = {"trajectory": {"type": "builtin", "name": "static"}}
    with pytest.raises(TypeError, match=r"^scenario\.imu\.lever_arm_m\[1\]: expected a number, .* got object$"):
        imukit.simulate({**static, "imu": {"lever_arm_m": [0.1, object(), 0.3]}})
    with pytest.raises(TypeError, match=r"^scenario\.imu: keys must be strings$"):
        imukit.simulate({**static, "imu": {1: 2}})
    # A value of the wrong kind for its key: the library names the key as the error's field.
    with pytest.raises(ImuError, match=r"imu\.lever_arm_m\[1\]: invalid type: string \"x\", expected f64") as e:
        imukit.simulate({**static, "imu": {"lever_arm_m": [0.1, "x", 0.3]}})
    assert e.value.field == "imu.lever_arm_m[1]"


def test_a_bad_trajectory_key_is_named_from_a_dict_and_from_a_json_file(tmp_path):
    # The trajectory's keys are read after its type, whatever their order: the key path goes
    # into the trajectory's lists, and a JSON file's message gives the line.
    bad = {"trajectory": {"position_m": ["t", "0", [1]], "yaw_rad": "0", "pitch_rad": "0",
                          "roll_rad": "0", "type": "expression"}}
    with pytest.raises(ImuError, match=r"position_m\[2\]: invalid type: sequence, expected a formula string of t, or a number$") as e:
        imukit.simulate(bad)
    assert e.value.field == "trajectory.position_m[2]"
    path = tmp_path / "bad.json"
    path.write_text('{"trajectory": {"type": "expression",\n "position_m": ["t", "0"]}}')
    with pytest.raises(ImuError, match=r"invalid length 2, expected an array of length 3 at line 2") as e:
        imukit.simulate(path)
    assert e.value.field == "trajectory.position_m"


def test_a_dict_nested_too_deep_is_refused_without_overflowing_the_stack():
    # 200 000 levels once overflowed the converter's stack and killed the interpreter.
    static = {"trajectory": {"type": "builtin", "name": "static"}}
    for wrap, inner in ((lambda d: {"a": d}, ".a"), (lambda d: [d], "[0]")):
        deep = 1.0
        for _ in range(200_000):
            deep = wrap(deep)
        with pytest.raises(ImuError, match="nested deeper than 64 levels") as e:
            imukit.simulate({**static, "imu": {"accelerometer": deep}})
        assert e.value.field == "scenario.imu.accelerometer" + inner * 63
    # The deepest a scenario needs reads as before.
    coefficients = {"Numerator": [1.0], "Denominator": [1.0, -0.5]}
    sim = imukit.simulate({**static, "duration_s": 0.1, "imu": {"accelerometer": {
        "BiasInstability": 0.01, "BiasInstabilityCoefficients": coefficients}}})
    assert sim.imu.values.shape[0] == 11


def test_negative_counts_and_seeds_are_refused_by_name():
    for call, field in [
        (lambda: imukit.simulate({"trajectory": {"type": "builtin", "name": "static"}}, run=-1), "run"),
        (lambda: imukit.ImuSensor(seed=-1), "seed"),
        (lambda: imukit.truth_from_samples(np.arange(10.0), np.zeros((10, 3)), order=-1), "order"),
        (lambda: imukit.ImuSensor(temperature=-300.0), "temperature"),
    ]:
        with pytest.raises(ImuError) as e:
            call()
        assert e.value.field == field


def test_wrong_lengths_and_empty_inputs_name_the_argument():
    sim = imukit.simulate({"rate_hz": 10.0, "duration_s": 1.0, "trajectory": {"type": "builtin", "name": "static"}})
    with pytest.raises(ValueError, match="lever_arm_m must have 3 numbers, got 2"):
        imukit.ideal_imu(sim.truth, lever_arm_m=[1.0, 2.0])
    with pytest.raises(ValueError, match="position0_m must have 2 numbers, got 3"):
        imukit.planar_dead_reckon(np.arange(3.0), np.zeros(3), np.zeros(3), np.zeros(3), position0_m=[0, 0, 0])
    with pytest.raises(ImuError, match="need at least 3 samples, got 0"):
        imukit.allan_deviation(np.zeros(0), 100.0)


def test_simulate_writes_its_tables_into_arrays_numpy_owns():
    # Rust fills arrays NumPy allocated (in place, NumPy's allocator and its huge pages), not
    # vectors handed over afterwards; the numbers are the streamed run's.
    sim = imukit.simulate({"rate_hz": 200.0, "duration_s": 30.0, "trajectory": {"type": "builtin", "name": "figure8"}})
    for table, width in ((sim.truth, 23), (sim.imu, 10)):
        assert table.values.flags["OWNDATA"] and table.values.base is None
        assert table.values.shape == (6001, width) and table.values.flags["C_CONTIGUOUS"]
    # Chunk boundaries (4096 rows) inside: the times are the scenario's, row after row.
    np.testing.assert_array_equal(sim.imu["t_s"], np.arange(6001) / 200.0)
    np.testing.assert_array_equal(sim.truth["t_s"], sim.imu["t_s"])


def test_simulate_gives_the_same_numbers_on_one_thread_or_two():
    # Several chunks, with noise: the truth is made a chunk ahead on a second thread by default
    # (when a core is free) and the noise is drawn on the first, in sample order.
    scenario = {"rate_hz": 500.0, "duration_s": 30.0, "trajectory": {"type": "builtin", "name": "figure8"},
                "imu": {"seed": 3, "accelerometer": {"NoiseDensity": 3e-3, "RandomWalk": 1e-4},
                        "gyroscope": {"NoiseDensity": 1e-4, "BiasInstability": 5e-5}}}
    one = imukit.simulate(scenario, threads=1)
    assert one.imu.values.shape == (15001, 10)
    reseeded = imukit.simulate({**scenario, "imu": {**scenario["imu"], "seed": 4}}, threads=1)
    assert not np.array_equal(reseeded.imu.values, one.imu.values)  # there is noise to draw
    for threads in (None, 2, 16):
        other = imukit.simulate(scenario, threads=threads)
        np.testing.assert_array_equal(other.imu.values, one.imu.values)
        np.testing.assert_array_equal(other.truth.values, one.truth.values)
    for bad in (0, -2):
        with pytest.raises(imukit.ImuError, match=f"threads: must be ≥ 1 thread, got {bad}"):
            imukit.simulate(scenario, threads=bad)
    # A cap beyond any machine is every core; counts that are not whole numbers are named.
    np.testing.assert_array_equal(imukit.simulate(scenario, threads=10**30).imu.values, one.imu.values)
    for name, bad in (("threads", True), ("threads", 2.0), ("run", "1"), ("run", 1.5)):
        with pytest.raises(TypeError, match=f"{name} must be a whole number, got {type(bad).__name__}"):
            imukit.simulate(scenario, **{name: bad})
    with pytest.raises(ValueError, match=r"run must be between -2\*\*63 and 2\*\*63 - 1"):
        imukit.simulate(scenario, run=2**64)


def test_readings_alone_are_the_readings_of_a_run_with_its_truth(tmp_path):
    scenario = {"rate_hz": 400.0, "duration_s": 25.0, "trajectory": {"type": "builtin", "name": "figure8"},
                "imu": {"seed": 5, "accelerometer": {"NoiseDensity": 3e-3, "BiasInstability": 2e-3},
                        "gyroscope": {"NoiseDensity": 1e-4, "RandomWalk": 1e-6}}}
    whole = imukit.simulate(scenario, run=2)
    for threads in (1, None):
        alone = imukit.simulate(scenario, run=2, threads=threads, truth=False)
        assert alone.truth is None
        np.testing.assert_array_equal(alone.imu.values, whole.imu.values)
        assert alone.imu.columns == whole.imu.columns
    path = tmp_path / "job.json"
    path.write_text(json.dumps(scenario))
    np.testing.assert_array_equal(imukit.simulate(path, run=2, truth=False).imu.values, whole.imu.values)
    for bad in (0, 1, "no", None):
        with pytest.raises(TypeError, match=f"truth must be True or False, got {type(bad).__name__}"):
            imukit.simulate(scenario, truth=bad)
    # Monte Carlo keeps the truth of one run only; its readings are the runs' own.
    mc = imukit.monte_carlo({**scenario, "duration_s": 2.0}, runs=3, first_run=1)
    np.testing.assert_array_equal(mc.truth.values, imukit.simulate({**scenario, "duration_s": 2.0}).truth.values)
    np.testing.assert_array_equal(mc.imu[1], imukit.simulate({**scenario, "duration_s": 2.0}, run=2).imu.values)


def test_tables_become_pandas_and_polars_frames_and_read_reads_by_extension(tmp_path):
    import pandas as pd
    import polars as pl
    sim = imukit.simulate({"trajectory": {"type": "builtin", "name": "figure8"}})
    df = sim.truth.to_pandas()
    assert isinstance(df, pd.DataFrame) and list(df.columns) == list(sim.truth.columns)
    # A copy by default (writable); copy=False shares the table's memory.
    assert not np.shares_memory(df.to_numpy(), sim.truth.values)
    assert np.shares_memory(sim.truth.to_pandas(copy=False).to_numpy(), sim.truth.values)
    assert df["vel_x_m_s"].iloc[5] == sim.truth["vel_x_m_s"][5]
    frame = sim.imu.to_polars()
    assert isinstance(frame, pl.DataFrame) and frame.columns == list(sim.imu.columns)
    assert frame["gyro_z_rad_s"].to_numpy().tolist() == sim.imu["gyro_z_rad_s"].tolist()
    path = tmp_path / "imu.csv"
    np.savetxt(path, sim.imu.values, delimiter=",", header=",".join(sim.imu.columns), comments="", fmt="%.17g")
    back = imukit.read(path)
    assert back.columns == sim.imu.columns and np.array_equal(back.values, sim.imu.values)
    with pytest.raises(imukit.ImuError, match="cannot read '.xlsx'"):
        imukit.read(tmp_path / "imu.xlsx")
