"""imukit.ImuSensor (MATLAB-shaped), Allan analysis, presets and parameter files from Python."""
import json
import math
import os
import subprocess

import numpy as np
import pytest

import imukit
from imukit import ImuError

NED_FIELD = [27.5550, -2.4169, -16.0849]


def level(n):
    return np.zeros((n, 3)), np.zeros((n, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))


def test_stationary_accel_gyro_mag_reads_gravity_and_the_field():
    imu = imukit.ImuSensor("accel-gyro-mag", reference_frame="NED", sample_rate=100)
    accel, gyro, mag = imu(*level(10))
    np.testing.assert_array_equal(accel, np.tile([0.0, 0.0, 9.81], (10, 1)))
    np.testing.assert_array_equal(gyro, 0.0)
    np.testing.assert_allclose(mag, np.tile(NED_FIELD, (10, 1)), atol=1e-12)
    enu = imukit.ImuSensor("accel-mag", reference_frame="ENU", profile="default")
    a, m = enu(*level(3))
    np.testing.assert_array_equal(a[:, 2], 9.81)  # specific force: +g up
    np.testing.assert_allclose(m[0], [-2.4169, 27.5550, 16.0849], atol=1e-12)


def test_rotating_platform_turns_the_field_in_the_body_frame():
    n = 600
    t = np.arange(n) / 100.0
    yaw = np.where(t < 4, math.pi / 2 * t, 2 * math.pi + math.pi * (t - 4))
    q = imukit.euler_to_quaternion(np.column_stack([yaw, np.zeros(n), np.zeros(n)]))
    w = np.column_stack([np.zeros(n), np.zeros(n), np.where(t < 4, math.pi / 2, math.pi)])
    imu = imukit.ImuSensor("accel-mag", reference_frame="NED")
    _, mag = imu(np.zeros((n, 3)), w, q)
    c, s = np.cos(yaw), np.sin(yaw)
    np.testing.assert_allclose(mag[:, 0], c * NED_FIELD[0] + s * NED_FIELD[1], atol=1e-9)
    np.testing.assert_allclose(mag[:, 1], -s * NED_FIELD[0] + c * NED_FIELD[1], atol=1e-9)


def test_quaternions_and_matlab_rotation_matrices_agree():
    rng = np.random.default_rng(3)
    e = np.column_stack([rng.uniform(-3, 3, 20), rng.uniform(-1.2, 1.2, 20), rng.uniform(-3, 3, 20)])
    q = imukit.euler_to_quaternion(e)
    nav_to_body = np.swapaxes(imukit.euler_to_dcm(e), 1, 2)  # MATLAB's rotation matrices
    acc = rng.normal(size=(20, 3))
    w = rng.normal(size=(20, 3))
    a = imukit.ImuSensor("accel-gyro-mag", seed=1, gyroscope={"NoiseDensity": 0.01})
    b = imukit.ImuSensor("accel-gyro-mag", seed=1, gyroscope={"NoiseDensity": 0.01})
    for x, y in zip(a(acc, w, q), b(acc, w, nav_to_body)):
        np.testing.assert_allclose(x, y, atol=1e-12)


def test_state_carries_between_calls_and_reset_starts_over():
    params = dict(accelerometer={"NoiseDensity": 0.01, "BiasInstability": 0.002, "RandomWalk": 0.001},
                  gyroscope={"NoiseDensity": 1e-3, "RandomWalk": 1e-4}, seed=5)
    one = imukit.ImuSensor("accel-gyro", **params)
    two = imukit.ImuSensor("accel-gyro", **params)
    acc, w, q = level(1000)
    a1, g1 = one(acc, w, q)
    parts = [two(acc[i:j], w[i:j], q[i:j]) for i, j in [(0, 1), (1, 400), (400, 1000)]]
    np.testing.assert_array_equal(a1, np.vstack([p[0] for p in parts]))
    np.testing.assert_array_equal(g1, np.vstack([p[1] for p in parts]))
    one.reset()
    a2, _ = one(acc, w, q)
    np.testing.assert_array_equal(a1, a2)


def test_out_buffer_is_written_in_place_and_reused_across_chunks():
    params = dict(accelerometer={"NoiseDensity": 0.01, "BiasInstability": 0.002},
                  gyroscope={"NoiseDensity": 1e-3, "RandomWalk": 1e-4}, seed=8)
    rng = np.random.default_rng(4)
    acc, w = rng.normal(size=(900, 3)), rng.normal(size=(900, 3))
    q = imukit.euler_to_quaternion(rng.uniform(-1, 1, size=(900, 3)))
    whole = imukit.ImuSensor("accel-gyro-mag", **params)(acc, w, q)
    chunked = imukit.ImuSensor("accel-gyro-mag", **params)
    buf = np.full((300, 9), np.nan)
    for k in range(3):
        rows = slice(300 * k, 300 * (k + 1))
        accel, gyro, mag = chunked(acc[rows], w[rows], q[rows], out=buf)
        assert np.shares_memory(accel, buf) and np.shares_memory(mag, buf)
        np.testing.assert_array_equal(buf[:, 0:3], whole[0][rows])
        np.testing.assert_array_equal(buf[:, 3:6], whole[1][rows])
        np.testing.assert_array_equal(buf[:, 6:9], whole[2][rows])
    acc2 = imukit.ImuSensor("accel-gyro", seed=1)
    with pytest.raises(ValueError, match=r"out must have shape \(300, 9\), got \(299, 9\)"):
        acc2(acc[:300], w[:300], q[:300], out=np.zeros((299, 9)))
    with pytest.raises(ValueError, match="C-contiguous float64"):
        acc2(acc[:300], w[:300], q[:300], out=np.zeros((300, 9), dtype=np.float32))
    with pytest.raises(ValueError, match="C-contiguous float64"):
        acc2(acc[:300], w[:300], q[:300], out=np.zeros((9, 300)).T)
    frozen = np.zeros((300, 9))
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="not writeable"):
        acc2(acc[:300], w[:300], q[:300], out=frozen)


def test_a_bad_quaternion_is_named_and_leaves_the_state_as_before():
    imu = imukit.ImuSensor("accel-gyro", seed=2, accelerometer={"NoiseDensity": 0.1})
    acc, w, q = level(10)
    q[6] = [np.nan, 0, 0, 0]
    with pytest.raises(ImuError, match=r"quaternion\[6\]"):
        imu(acc, w, q)
    a_after, _ = imu(*level(10))
    a_fresh, _ = imukit.ImuSensor("accel-gyro", seed=2, accelerometer={"NoiseDensity": 0.1})(*level(10))
    np.testing.assert_array_equal(a_after, a_fresh)


def test_matlab_spec_sheet_accelerometer_deterministic_part():
    spec = {"MeasurementRange": 19.62, "Resolution": 0.00059875, "ConstantBias": 0.4905, "AxesMisalignment": 2,
            "NoiseDensity": 0.0, "TemperatureBias": [0.34335, 0.34335, 0.5886], "TemperatureScaleFactor": 0.02}
    imu = imukit.ImuSensor("accel-gyro", accelerometer=spec, temperature=35)
    accel, _ = imu(*level(1))
    u = np.array([0.0, 0.0, 9.81])
    m = np.full((3, 3), 2.0) + np.eye(3) * 98.0
    y = (1 + 10 * 0.02 / 100) * (m @ u / 100 + 0.4905 + 10 * np.array([0.34335, 0.34335, 0.5886]))
    np.testing.assert_allclose(accel[0], 0.00059875 * np.round(np.clip(y, -19.62, 19.62) / 0.00059875), atol=1e-12)


def test_noise_density_convention_per_profile():
    # MATLAB profile: double-sided, σ = N·√(fs/2); default profile: single-sided, σ = N·√fs.
    n, fs, nd = 100_000, 200.0, 0.01
    acc, w, q = level(n)
    for profile, beta in [("matlab", fs / 2), ("default", fs)]:
        imu = imukit.ImuSensor("accel-gyro", sample_rate=fs, gyroscope={"NoiseDensity": nd}, profile=profile, seed=9)
        _, gyro = imu(acc, w, q)
        ratio = gyro.var(axis=0, ddof=1) / (nd**2 * beta)
        assert np.all(np.abs(ratio - 1) < 5 * math.sqrt(2 / (n - 1))), (profile, ratio)


def test_allan_round_trip_recovers_the_white_noise_density():
    nd, fs = 2e-3, 100.0
    imu = imukit.ImuSensor("accel-gyro", sample_rate=fs, profile="default", gyroscope={"noise_density_rad_s_per_rt_hz": nd}, seed=2)
    _, gyro = imu(*level(200_000))
    tau, adev = imukit.allan_deviation(gyro, fs)
    assert adev.shape == (len(tau), 3)
    ident = imukit.identify(gyro, sample_rate_hz=fs)
    for k in range(3):
        n = ident.term(f"column {k}", "N")
        assert n["resolved"] and n["lower"] <= nd <= n["upper"], n
    tau1, adev1 = imukit.allan_deviation(gyro[:, 0], fs)
    np.testing.assert_array_equal(adev1, adev[:, 0])


def test_presets_and_parameter_files(tmp_path):
    assert "ideal" in imukit.presets()
    ideal = imukit.preset_params("ideal")
    assert ideal["grade"] == "ideal" and "gyroscope" in ideal
    path = tmp_path / "matlab.json"
    path.write_text(json.dumps({"MyPart": {"Gyroscope": {"NoiseDensity": 0.001, "MeasurementRange": "inf"}}}))
    p = imukit.loadparams(path)
    assert p["name"] == "MyPart"
    assert p["gyroscope"]["noise_density_rad_s_per_rt_hz"] == 0.001
    assert p["gyroscope"]["measurement_range_rad_s"] == "inf"
    imu = imukit.ImuSensor("accel-gyro", gyroscope=p["gyroscope"], profile="default", seed=3)
    _, g = imu(*level(10))
    assert np.all(np.isfinite(g)) and np.any(g != 0)


def test_bad_parameters_raise_imu_errors_naming_the_field(tmp_path):
    with pytest.raises(ImuError, match=r"imu.gyroscope.*noise_density\[0\] must be ≥ 0"):
        imukit.ImuSensor(gyroscope={"NoiseDensity": -1})
    with pytest.raises(ImuError, match=r"MeasurementRange|measurement_range must be > 0"):
        imukit.ImuSensor(accelerometer={"MeasurementRange": 0})
    with pytest.raises(ImuError, match=r"unknown preset \"nope\""):
        imukit.ImuSensor(preset="nope")
    with pytest.raises(ImuError, match=r"unknown parameter"):
        imukit.ImuSensor(gyroscope={"Noise": 1})
    with pytest.raises(ImuError, match=r"imu_type"):
        imukit.ImuSensor("accel-baro")
    bad = tmp_path / "bad.json"
    bad.write_text('{\n "P": {\n  "Gyroscope": {"NoiseDensity": 0.1,}\n }\n}\n')
    with pytest.raises(ImuError, match=r"bad.json.*line 3"):
        imukit.loadparams(bad)
    with pytest.raises(ValueError, match=r"orientation must have shape"):
        imukit.ImuSensor()(np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 5)))


def test_convert_datasheet_units():
    v, unit, fits = imukit.convert(0.15, "°/√h")
    assert unit == "rad/s/√Hz" and "noise_density" in fits
    assert abs(v - 0.15 * math.pi / 180 / 60) < 1e-18
    assert "mpu-6050" in imukit.presets()
    mpu = imukit.preset_params("mpu-6050")
    assert abs(mpu["gyroscope"]["noise_density_rad_s_per_rt_hz"] - imukit.convert(0.005, "°/s/√Hz")[0]) < 1e-9
    with pytest.raises(ImuError, match="unknown unit"):
        imukit.convert(1, "furlongs")


def test_parameter_classes_mirror_matlabs_accelparams():
    accel = imukit.AccelParams(measurement_range=19.62, resolution=0.00059875, constant_bias=0.4905,
                               axes_misalignment=2, noise_density=0.0, temperature_bias=[0.34335, 0.34335, 0.5886],
                               temperature_scale_factor=0.02)
    gyro = imukit.GyroParams(acceleration_bias=1e-4, bias_instability=0.0,
                             bias_instability_coefficients=([1.0], [1.0, -0.5]))
    assert accel.to_dict()["MeasurementRange"] == 19.62
    assert gyro.to_dict()["BiasInstabilityCoefficients"] == {"Numerator": [1.0], "Denominator": [1.0, -0.5]}
    a = imukit.ImuSensor("accel-gyro", accelerometer=accel, gyroscope=gyro, temperature=35)
    b = imukit.ImuSensor("accel-gyro", accelerometer=accel.to_dict(), gyroscope=gyro.to_dict(), temperature=35)
    for x, y in zip(a(*level(5)), b(*level(5))):
        np.testing.assert_array_equal(x, y)
    with pytest.raises(TypeError, match="AccelParams"):
        imukit.ImuSensor(accelerometer=[1, 2, 3])


def test_vibration_rectifies_through_the_elements_nonlinearity():
    # A 2 g shake along x, 40 Hz sampled at 1 kHz for 100 whole periods: an accelerometer with
    # K₂ = 1e-3 /(m/s²) reads a mean K₂A²/2 on x (MATLAB's sign flips the shake, not the square),
    # a gyroscope with g²-sensitivity k a mean kA²/2; asymmetry ε reads u(1 ± ε/2).
    n, a = 2500, 19.62
    t = np.arange(n) / 1000.0
    acc = np.zeros((n, 3))
    acc[:, 0] = a * np.sin(2 * np.pi * 40 * t)
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    imu = imukit.ImuSensor("accel-gyro", sample_rate=1000,
                           accelerometer=imukit.AccelParams(scale_factor_nonlinearity=[1e-3, 0, 0]),
                           gyroscope=imukit.GyroParams(acceleration_squared_bias=[2e-6, 0, 0]))
    accel, gyro = imu(acc, np.zeros((n, 3)), quat)
    assert abs(accel[:, 0].mean() / (1e-3 * a * a / 2) - 1) < 1e-9
    assert abs(gyro[:, 0].mean() / (2e-6 * a * a / 2) - 1) < 1e-9
    skew = imukit.ImuSensor("accel-gyro", accelerometer=imukit.AccelParams(scale_factor_asymmetry=2.0))
    reading, _ = skew(np.array([[-3.0, 3.0, 0.0]]), np.zeros((1, 3)), quat[:1])
    np.testing.assert_allclose(reading[0, :2], [3.0 * 1.01, -3.0 * 0.99], rtol=1e-15)
    with pytest.raises(ImuError, match="scale_factor_asymmetry"):
        imukit.ImuSensor(accelerometer=imukit.AccelParams(scale_factor_asymmetry=120.0))


def test_an_infinite_measurement_range_reaches_rust_as_infinity():
    # Parameter objects are handed over typed (no JSON text, which has no infinity): an
    # infinite range means no saturation, so a reading far beyond any finite range passes.
    imu = imukit.ImuSensor(accelerometer=imukit.AccelParams(measurement_range=float("inf")))
    accel, _ = imu(np.array([[1e6, 0.0, 0.0]]), np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0, 0.0]]))
    assert accel[0].tolist() == [-1e6, 0.0, 9.81]  # MATLAB's sign: gravity minus acceleration
    limited = imukit.ImuSensor(accelerometer=imukit.AccelParams(measurement_range=19.6))
    accel, _ = limited(np.array([[1e6, 0.0, 0.0]]), np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0, 0.0]]))
    assert accel[0, 0] == -19.6
    # The same through a scenario dict.
    sim = imukit.simulate({"rate_hz": 10.0, "duration_s": 0.1,
                           "trajectory": {"type": "builtin", "name": "static"},
                           "imu": {"accelerometer": {"MeasurementRange": float("inf")}}})
    assert sim.imu["accel_z_m_s2"][0] == 9.81


def test_imu_errors_carry_the_field_for_programs():
    with pytest.raises(ImuError) as e:
        imukit.ImuSensor(gyroscope=imukit.GyroParams(noise_density=-1.0))
    assert e.value.field == "imu.gyroscope.noise_density"
    assert e.value.file is None and e.value.row is None and e.value.column is None
    with pytest.raises(ImuError) as e:
        imukit.ImuSensor(gyroscope={"NoSuchParameter": 1.0})
    assert e.value.field == "imu.gyroscope.NoSuchParameter"
    with pytest.raises(ImuError) as e:
        imukit.ImuSensor("accel-gyro", reference_frame="XYZ")
    assert e.value.field == "reference_frame"
    with pytest.raises(TypeError, match="gyroscope"):
        imukit.ImuSensor(gyroscope=[1.0, 2.0])


def test_imu_errors_name_file_row_and_column(tmp_path):
    bad = tmp_path / "imu.csv"
    bad.write_text("t_s,gyro_x_rad_s\n0,0.1\n0.01,nan\n")
    with pytest.raises(ImuError) as e:
        imukit.read_csv(bad)
    assert (e.value.file, e.value.row, e.value.column) == (str(bad), 3, "gyro_x_rad_s")
    assert e.value.field is None


def test_matlab_parity_gaps_closed():
    # Non-finite input is refused (MATLAB refuses it), naming the argument and row.
    acc = np.zeros((3, 3))
    acc[1, 2] = np.nan
    imu = imukit.ImuSensor()
    with pytest.raises(ImuError, match=r"acceleration\[1\]: is not a finite number") as e:
        imu(acc, np.zeros((3, 3)), np.tile([1.0, 0, 0, 0], (3, 1)))
    assert e.value.field == "acceleration[1]"
    # A matrix that is not a rotation is refused, not silently replaced.
    m = np.tile(np.eye(3), (2, 1, 1))
    m[1, 0, 0] = 1.01
    with pytest.raises(ImuError, match=r"orientation\[1\]: is not a rotation matrix"):
        imukit.ImuSensor()(np.zeros((2, 3)), np.zeros((2, 3)), m)
    m[1] = np.diag([1.0, 1.0, -1.0])
    with pytest.raises(ImuError, match=r"reflection"):
        imukit.ImuSensor()(np.zeros((2, 3)), np.zeros((2, 3)), m)
    # Without an orientation the body is level (MATLAB's identity).
    a, g = imukit.ImuSensor()(np.zeros((2, 3)), np.zeros((2, 3)))
    assert a.tolist() == [[0.0, 0.0, 9.81]] * 2
    # AxesMisalignment as a 3×1 column means the 3-vector form.
    col = imukit.ImuSensor(accelerometer={"AxesMisalignment": [[1.0], [2.0], [3.0]]})
    vec = imukit.ImuSensor(accelerometer={"AxesMisalignment": [1.0, 2.0, 3.0]})
    u = np.array([[0.3, -0.2, 0.1]])
    q = np.array([[1.0, 0, 0, 0]])
    assert col(u, np.zeros((1, 3)), q)[0].tolist() == vec(u, np.zeros((1, 3)), q)[0].tolist()


def test_a_matlab_parameter_file_means_what_it_means_in_matlab(tmp_path):
    path = tmp_path / "parts.json"
    path.write_text(json.dumps({"MPU_6050": {"Gyroscope": {"NoiseDensity": 0.001}},
                                "Other": {"Gyroscope": {"NoiseDensity": 0.002}}}))
    # MATLAB's loadparams leaves NoiseType double-sided, whatever imukit's profile.
    p = imukit.loadparams(path, part="mpu-6050")  # part names match as MATLAB identifiers
    assert p["gyroscope"]["noise_type"] == "double-sided"
    assert p["gyroscope"]["noise_density_rad_s_per_rt_hz"] == 0.001


def test_a_matlab_file_with_keys_matlab_skips_is_read_with_warnings(tmp_path):
    path = tmp_path / "vendor.json"
    path.write_text(json.dumps({"Part": {"Vendor": "ACME",
                                         "Gyroscope": {"NoiseDensity": 0.001, "Colour": "blue"}}}))
    with pytest.warns(UserWarning) as caught:
        p = imukit.loadparams(path)
    messages = sorted(str(w.message) for w in caught)
    assert messages[0].endswith("Part: Gyroscope.Colour: unknown property, skipped (as MATLAB does)")
    assert messages[1].endswith("Part: Vendor: not a sensor, skipped (as MATLAB does)")
    assert p["gyroscope"]["noise_density_rad_s_per_rt_hz"] == 0.001
    # imukit's own files stay strict.
    own = tmp_path / "own.toml"
    own.write_text("[gyroscope]\ncolour = 1\n")
    with pytest.raises(ImuError, match="unknown parameter"):
        imukit.loadparams(own)


def fractalcoef(poles, alpha=1.0):
    """MATLAB's ``fractalcoef`` (Kasdin 1995): Num = 1, Den = [1, a1, …] with a_k = (k−1−α/2)a_{k−1}/k."""
    den = [1.0]
    for k in range(1, poles + 1):
        den.append((k - 1 - alpha / 2) * den[-1] / k)
    return [1.0], den


def test_matlabs_500_pole_fractal_filter_runs_as_in_matlab():
    # MATLAB's Allan example: BiasInstabilityCoefficients = fractalcoef(500), 501 coefficients.
    # With only bias instability on, the gyro reads y = filter(1, den, B·n); filtering y by the
    # FIR `den` gives B·n back, white with σ = B, only if all 501 coefficients act.
    num, den = fractalcoef(500)
    b, n = 0.01, 20000
    imu = imukit.ImuSensor("accel-gyro", seed=3, gyroscope=imukit.GyroParams(
        bias_instability=b, bias_instability_coefficients=(num, den)))
    _, gyro = imu(*level(n))
    white = np.convolve(gyro[:, 0], den)[:n] / b
    assert abs(white.std() - 1.0) < 5 / math.sqrt(2 * n)
    assert abs(white.mean()) < 5 / math.sqrt(n)
    assert abs(np.corrcoef(white[:-1], white[1:])[0, 1]) < 5 / math.sqrt(n)

    # Slow memory shows in block means: for white noise, 40 means of 500 samples times √500 have
    # standard deviation 1, estimated to ±1/√78 (5σ: 0.57).
    def block_spread(x):
        return x.reshape(40, 500).mean(axis=1).std(ddof=1) * math.sqrt(500)

    assert abs(block_spread(white) - 1.0) < 5 / math.sqrt(78)
    # Undone with only its first 8 coefficients, the 1/f memory remains: the test can fail.
    assert block_spread(np.convolve(gyro[:, 0], den[:8])[:n] / b) > 2.0


def test_filters_longer_than_4096_coefficients_are_refused_with_the_bound_named():
    with pytest.raises(ImuError, match="4097 coefficients, at most 4096 taken") as e:
        imukit.ImuSensor("accel-gyro", gyroscope=imukit.GyroParams(
            bias_instability=0.01, bias_instability_coefficients=fractalcoef(4096)))
    assert e.value.field.endswith("bias_instability_coefficients")

def test_a_chains_response_is_the_one_the_simulation_reads():
    # A gyroscope shaken at 1130 Hz behind an 8 kHz chain reads, at 100 Hz, a sine at the alias
    # the response gives with its gain (the Rust tests check the phase and delay to 1e-6).
    chain = {"internal_rate_hz": 8000, "gyroscope": {"filter": "butterworth", "order": 2, "cutoff_hz": 200}}
    r = imukit.chain_response(chain, 100, [1130.0])
    sim = imukit.simulate({"rate_hz": 100, "duration_s": 4,
                           "trajectory": {"type": "expression", "position_m": [0, 0, 0]},
                           "imu": {"kind": "accel-gyro", "chain": chain,
                                   "vibration": {"sines": [{"kind": "angular-rate", "axis": "z",
                                                            "frequency_hz": 1130, "amplitude": 0.5}]}}})
    t, gz = sim.imu["t_s"][50:], sim.imu["gyro_z_rad_s"][50:]
    f = r["alias_hz"][0]
    design = np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)])
    amplitude = np.hypot(*np.linalg.lstsq(design, gz, rcond=None)[0])
    assert f == 30.0 and abs(amplitude / (0.5 * r["gyro_gain"][0]) - 1) < 1e-3
    assert r["accel_gain"][0] == 1.0  # no filter: decimated alone
    with pytest.raises(ImuError, match=r"imu.chain.gyroscope"):
        imukit.chain_response({"internal_rate_hz": 8000, "gyroscope": {"filter": "butterworth", "order": 2,
                                                                      "cutoff_hz": 5000}}, 100, [1.0])


def test_a_data_sheets_filter_and_a_parts_setting_from_python():
    # A filter given as a data sheet gives it: its bandwidth and delay are the chain's.
    r = imukit.chain_response({"gyroscope_internal_rate_hz": 1000,
                               "gyroscope": {"filter": "bandwidth_delay", "bandwidth_hz": 42, "delay_s": 0.0048}},
                              100, [0.0, 42.0])
    assert abs(r["gyro_gain"][1] - 2 ** -0.5) < 1e-9 and abs(r["gyro_delay_s"][0] - 0.0048) < 1e-12
    # A preset's setting, chosen in a scenario dict; one it lacks is refused by its key.
    scenario = {"rate_hz": 100, "duration_s": 2, "trajectory": {"type": "expression", "position_m": [0, 0, 0]},
                "imu": {"preset": "mpu-6050", "chain": {"setting": 3}}}
    sim = imukit.simulate(scenario)
    assert sim.imu["t_s"].shape[0] == 201
    scenario["imu"]["chain"]["setting"] = 9
    with pytest.raises(ImuError, match=r"imu.chain.setting: preset mpu-6050's DLPF_CFG has no setting 9"):
        imukit.simulate(scenario)


def test_the_spectrum_integrates_to_the_variance_and_the_command_writes_the_same(tmp_path):
    t = np.arange(20000) / 100.0
    x = 2.0 * np.sin(2 * np.pi * 7.3 * t) + 0.5 * np.cos(2 * np.pi * 31.0 * t)
    table = imukit.Table.of({"t_s": t, "gyro_x_rad_s": x})
    psd = imukit.spectrum(table, ["gyro_x_rad_s"], segment_s=10.0)
    f, p = psd["frequency_hz"], psd["psd_gyro_x_rad_s"]
    assert abs(p.sum() * (f[1] - f[0]) / x.var() - 1) < 1e-3
    assert abs(f[np.argmax(p)] - 7.3) <= f[1] - f[0]
    log = tmp_path / "x.csv"
    table.write(log)
    out = tmp_path / "psd.csv"
    done = subprocess.run([os.environ.get("IMUKIT_BIN", "imukit"), "spectrum", str(log), "--segment-s", "10",
                           "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    np.testing.assert_allclose(imukit.read(out)["psd_gyro_x_rad_s"], p, rtol=1e-12)
    with pytest.raises(ImuError, match="segment_s"):
        imukit.spectrum(table, ["gyro_x_rad_s"], segment_s=-1.0)


def test_the_truth_says_what_the_vibration_did_and_monte_carlo_keeps_what_all_runs_share():
    # A roll shake of 0.2 rad/s at 7 Hz turns the sensor by 0.2/ω·(1 − cos ωt) about x; at rest
    # the ideal gyroscope reads the shake alone, and the truth holds both.
    shake = {"sines": [{"kind": "angular-rate", "axis": "x", "frequency_hz": 7, "amplitude": 0.2}]}
    scenario = {"rate_hz": 100, "duration_s": 2,
                "trajectory": {"type": "expression", "position_m": [0, 0, 0]},
                "imu": {"kind": "accel-gyro", "vibration": shake}}
    sim = imukit.simulate(scenario)
    t, omega = sim.truth["t_s"], 2 * np.pi * 7
    np.testing.assert_allclose(sim.truth["mount_rot_x_rad"], 0.2 / omega * (1 - np.cos(omega * t)),
                               rtol=0, atol=1e-14)
    np.testing.assert_array_equal(sim.truth["vib_gyro_x_rad_s"], sim.imu["gyro_x_rad_s"])
    np.testing.assert_allclose(sim.truth["vib_accel_y_m_s2"], sim.imu["accel_y_m_s2"], rtol=0, atol=1e-15)
    assert imukit.monte_carlo(scenario, runs=2).truth.columns == sim.truth.columns
    # A random shake differs by run: Monte Carlo's common truth leaves its columns out, and
    # each run's own truth has them.
    scenario["imu"]["vibration"] = {"random": [{"kind": "angular-rate", "axis": "x", "psd": [[5, 1e-4], [40, 1e-4]]}]}
    mc = imukit.monte_carlo(scenario, runs=2)
    assert "t_s" in mc.truth and not any(c.startswith(("vib_", "mount_")) for c in mc.truth.columns)
    runs = [imukit.simulate(scenario, run=r) for r in (0, 1)]
    for k, r in enumerate(runs):
        np.testing.assert_array_equal(r.truth["vib_gyro_x_rad_s"], mc.imu[k][:, mc.columns.index("gyro_x_rad_s")])
    assert not np.array_equal(runs[0].truth["mount_rot_x_rad"], runs[1].truth["mount_rot_x_rad"])
