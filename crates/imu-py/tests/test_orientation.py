"""Orientation from Python: ecompass, the filters (MATLAB-shaped), quaternion distance, compare."""
import math

import numpy as np
import pytest

import imukit
from imukit import ImuError

G = 9.81
FIELD_NED = np.array([25.0, 0.0, 50.0 * math.sin(math.radians(60))])


def readings(euler, frame="NED", sign="matlab", field_ned=FIELD_NED):
    """Ideal body-frame accelerometer and magnetometer rows of a body at rest with attitudes
    ``euler`` (N, 3) in ``frame``."""
    c = imukit.euler_to_dcm(euler)  # C_nb
    gravity = np.array([0, 0, G]) if frame == "NED" else np.array([0, 0, -G])
    field = field_ned if frame == "NED" else np.array([field_ned[1], field_ned[0], -field_ned[2]])
    gravity_reading = np.einsum("nji,j->ni", c, gravity)  # C_nbᵀ g: MATLAB's sign
    accel = gravity_reading if sign == "matlab" else -gravity_reading
    mag = np.einsum("nji,j->ni", c, field)
    return accel, mag


def grid():
    y, p, r = np.meshgrid(np.radians(np.arange(-170, 171, 34)), np.radians(np.arange(-80, 81, 20)),
                          np.radians(np.arange(-175, 176, 35)), indexing="ij")
    return np.column_stack([y.ravel(), p.ravel(), r.ravel()])


@pytest.mark.parametrize("frame", ["NED", "ENU"])
@pytest.mark.parametrize("sign", ["matlab", "specific-force"])
def test_ecompass_recovers_every_attitude_of_a_grid(frame, sign):
    e = grid()
    accel, mag = readings(e, frame, sign)
    q = imukit.ecompass(accel, mag, reference_frame=frame, accel_sign=sign)
    d = imukit.quaternion_distance(q, imukit.euler_to_quaternion(e))
    assert d.max() <= 1e-9
    r = imukit.ecompass(accel[:3], mag[:3], reference_frame=frame, accel_sign=sign, orientation_format="rotmat")
    np.testing.assert_allclose(r, np.swapaxes(imukit.euler_to_dcm(e[:3]), 1, 2), atol=1e-12)


def test_ecompass_refuses_degenerate_rows_by_index():
    with pytest.raises(ImuError, match=r"row 1: the magnetic field is parallel to gravity"):
        imukit.ecompass([[0, 0, G], [0, 0, G]], [[20, 0, 40], [0, 0, 40]], conventions="matlab")
    with pytest.raises(ImuError, match="row 0: accelerometer reading is not a finite number"):
        imukit.ecompass([[np.nan, 0, G]], [[20, 0, 40]], conventions="matlab")
    with pytest.raises(ValueError, match=r"mag has 1 rows, expected 2"):
        imukit.ecompass(np.zeros((2, 3)), np.zeros((1, 3)), conventions="matlab")


def filters(frame="NED"):
    kw = dict(reference_frame=frame)
    return {
        "imufilter": (imukit.ImuFilter(100, **kw, conventions="matlab"), False),
        "ahrsfilter": (imukit.AhrsFilter(100, **kw, conventions="matlab"), True),
        "complementary": (imukit.ComplementaryFilter(100, **kw, conventions="matlab"), True),
        "madgwick": (imukit.MadgwickFilter(100, has_magnetometer=True, **kw, conventions="matlab"), True),
        "mahony": (imukit.MahonyFilter(100, **kw, conventions="matlab"), False),
    }


def run(f, mag_used, accel, gyro, mag, **kw):
    return f(accel, gyro, mag, **kw) if mag_used else f(accel, gyro, **kw)


@pytest.mark.parametrize("frame", ["NED", "ENU"])
def test_every_filter_holds_a_static_attitude_and_runs_the_same_in_chunks(frame):
    e = np.tile([[0.5, 0.2, -0.3]], (600, 1))
    accel, mag = readings(e, frame)
    gyro = np.zeros_like(accel)
    for name, (f, mag_used) in filters(frame).items():
        q = run(f, mag_used, accel, gyro, mag)
        truth = e.copy()
        if not mag_used:
            truth[:, 0] = 0.0  # heading relative to the start
        assert imukit.quaternion_distance(q, imukit.euler_to_quaternion(truth)).max() < 1e-9, name
        f.reset()
        parts = [run(f, mag_used, accel[i:j], gyro[i:j], mag[i:j]) for i, j in [(0, 1), (1, 250), (250, 600)]]
        np.testing.assert_array_equal(np.vstack(parts), q, err_msg=name)


def test_filters_are_chunk_invariant_on_noisy_motion():
    rng = np.random.default_rng(5)
    n = 800
    e = np.column_stack([0.5 * np.sin(np.arange(n) / 90), 0.3 * np.sin(np.arange(n) / 70), np.zeros(n)])
    accel, mag = readings(e)
    accel += rng.normal(scale=0.05, size=accel.shape)
    mag += rng.normal(scale=0.5, size=mag.shape)
    gyro = rng.normal(scale=0.01, size=accel.shape)
    for name, (f, mag_used) in filters().items():
        whole, w_whole = run(f, mag_used, accel, gyro, mag, return_angular_velocity=True)
        f.reset()
        parts = [run(f, mag_used, accel[i:j], gyro[i:j], mag[i:j], return_angular_velocity=True)
                 for i, j in [(0, 333), (333, 334), (334, n)]]
        np.testing.assert_array_equal(np.vstack([p[0] for p in parts]), whole, err_msg=name)
        np.testing.assert_array_equal(np.vstack([p[1] for p in parts]), w_whole, err_msg=name)


def test_kalman_filters_estimate_a_constant_gyroscope_bias_within_5_percent_after_60_s():
    n = 6000
    accel, mag = readings(np.zeros((n, 3)))
    bias = np.array([0.02, -0.015, 0.01])
    imu = imukit.ImuFilter(100, conventions="matlab")
    imu(accel, np.tile([bias[0], bias[1], 0.0], (n, 1)))
    np.testing.assert_allclose(imu.gyroscope_offset[:2], bias[:2], rtol=0.05)
    ahrs = imukit.AhrsFilter(100, conventions="matlab")
    q, w = ahrs(accel, np.tile(bias, (n, 1)), mag, return_angular_velocity=True)
    np.testing.assert_allclose(ahrs.gyroscope_offset, bias, rtol=0.05)
    np.testing.assert_allclose(w[-1], 0.0, atol=0.05 * np.abs(bias).max())


def test_decimation_rotmat_and_tuned_initial_process_noise():
    accel, _ = readings(np.zeros((12, 3)))
    f = imukit.ImuFilter(100, decimation_factor=4, orientation_format="rotmat",
                         initial_process_noise=imukit.ImuFilter.DEFAULT_INITIAL_PROCESS_NOISE * 10, conventions="matlab")
    r = f(accel, np.zeros((12, 3)))
    assert r.shape == (3, 3, 3)
    np.testing.assert_allclose(r, np.tile(np.eye(3), (3, 1, 1)), atol=1e-12)


def test_bad_input_is_named():
    with pytest.raises(ImuError, match="SampleRate = 0: must be finite and > 0"):
        imukit.ImuFilter(0, conventions="matlab")
    with pytest.raises(ImuError, match="LinearAccelerationDecayFactor = 2: must be in"):
        imukit.ImuFilter(linear_acceleration_decay_factor=2, conventions="matlab")
    with pytest.raises(ImuError, match="DecimationFactor"):
        imukit.ImuFilter(decimation_factor=0, conventions="matlab")
    with pytest.raises(ValueError, match=r"initial_process_noise must be \(9,\)"):
        imukit.ImuFilter(initial_process_noise=np.ones(4), conventions="matlab")
    with pytest.raises(ImuError, match="AccelerometerGain"):
        imukit.ComplementaryFilter(accelerometer_gain=1.5, conventions="matlab")
    f = imukit.AhrsFilter(conventions="matlab")
    accel, mag = readings(np.zeros((4, 3)))
    gyro = np.zeros((4, 3))
    bad = gyro.copy()
    bad[2, 1] = np.nan
    with pytest.raises(ImuError, match="row 2: gyroscope reading is not a finite number"):
        f(accel, bad, mag)
    # The failed call left no trace: the same filter now gives a fresh filter's numbers.
    np.testing.assert_array_equal(f(accel, gyro, mag), imukit.AhrsFilter(conventions="matlab")(accel, gyro, mag))
    with pytest.raises(ValueError, match=r"gyro has 3 rows, expected 4"):
        f(accel, gyro[:3], mag)
    with pytest.raises(ValueError, match="has_magnetometer=False"):
        imukit.MahonyFilter(conventions="matlab")(accel, gyro, mag)


def test_quaternion_distance_and_compare_of_an_orientation_output():
    q = imukit.euler_to_quaternion([[0.3, 0.1, -0.2]])
    turned = imukit.euler_to_quaternion([[0.3 + 1e-7, 0.1, -0.2]])
    np.testing.assert_allclose(imukit.quaternion_distance(q, turned), [1e-7], rtol=1e-6)
    np.testing.assert_allclose(imukit.quaternion_distance(q, -q), [0.0], atol=1e-15)  # same rotation
    t = np.arange(50) / 10.0
    e = np.column_stack([0.1 * t, np.zeros(50), np.zeros(50)])
    truth = imukit.truth_from_samples(t, np.zeros((50, 3)), euler_rad=e, nav_frame="NED")
    est_q = imukit.euler_to_quaternion(e + [0.01, 0.0, 0.0])
    estimate = imukit.Table(["t_s", "q_w", "q_x", "q_y", "q_z"], np.column_stack([t, est_q]))
    errors, summary = imukit.compare(truth, estimate)
    assert list(errors.columns) == ["t_s", "att_err_rad", "heading_err_rad", "inclination_err_rad",
                                    "yaw_err_rad", "pitch_err_rad", "roll_err_rad"]
    np.testing.assert_allclose(errors["yaw_err_rad"], 0.01, atol=1e-9)
    # A yaw error is all heading: BROAD's split of the error rotation.
    np.testing.assert_allclose(errors["heading_err_rad"], 0.01, atol=1e-9)
    np.testing.assert_allclose(errors["inclination_err_rad"], 0.0, atol=1e-7)
    np.testing.assert_allclose(summary["heading_offset_rad"], 0.01, atol=1e-9)
    aligned = imukit.compare(truth, estimate, align_heading=True).summary
    assert aligned["attitude_rms_rad"] < 1e-7 and aligned["skipped_rows"] == 0
    np.testing.assert_allclose(summary["attitude_rms_rad"], 0.01, atol=1e-9)
    assert "position_rms_m" not in summary and summary["attitude_max_rad"] >= summary["attitude_rms_rad"]


def test_decimation_takes_whole_blocks_per_call_as_matlab_does():
    rng = np.random.default_rng(9)
    accel, mag = readings(np.zeros((24, 3)))
    accel += rng.normal(scale=0.05, size=accel.shape)
    gyro = rng.normal(scale=0.01, size=accel.shape)
    whole = imukit.AhrsFilter(100, decimation_factor=4, conventions="matlab")(accel, gyro, mag)
    f = imukit.AhrsFilter(100, decimation_factor=4, conventions="matlab")
    parts = [f(accel[i:j], gyro[i:j], mag[i:j]) for i, j in [(0, 4), (4, 16), (16, 24)]]
    assert [p.shape[0] for p in parts] == [1, 3, 2]
    np.testing.assert_array_equal(np.vstack(parts), whole)
    # MATLAB refuses a call whose row count is not a multiple of DecimationFactor; so does imukit,
    # and the refused call leaves the filter as it was.
    g = imukit.ImuFilter(100, decimation_factor=3, conventions="matlab")
    a50, g50 = readings(np.zeros((50, 3)))[0], np.zeros((50, 3))
    with pytest.raises(ImuError, match="50 rows is not a multiple of DecimationFactor = 3"):
        g(a50, g50)
    np.testing.assert_array_equal(g(a50[:48], g50[:48]), imukit.ImuFilter(100, decimation_factor=3, conventions="matlab")(a50[:48], g50[:48]))


def test_ahrs_ignores_a_jammed_magnetometer_sample():
    # A 500 µT spike (more than twice ExpectedMagneticFieldStrength) is treated as jamming: the
    # heading stays where the clean samples put it.
    n = 300
    e = np.tile([[0.4, 0.0, 0.0]], (n, 1))
    accel, mag = readings(e)
    jammed = mag.copy()
    jammed[150] = [500.0, 300.0, 0.0]
    gyro = np.zeros_like(accel)
    clean = imukit.AhrsFilter(100, conventions="matlab")(accel, gyro, mag)
    spiked = imukit.AhrsFilter(100, conventions="matlab")(accel, gyro, jammed)
    assert imukit.quaternion_distance(clean, spiked).max() < 1e-9
    # The same spike just under the jamming bound does move the estimate.
    jammed[150] = [60.0, 60.0, 0.0]
    moved = imukit.AhrsFilter(100, conventions="matlab")(accel, gyro, jammed)
    assert imukit.quaternion_distance(clean, moved).max() > 1e-3


def test_kalman_filters_stay_well_conditioned_over_millions_of_updates():
    # The carried covariance is symmetrised each update; without it rounding made the
    # innovation covariance singular within a few million updates of static data.
    rng = np.random.default_rng(11)
    n = 1_000_000
    accel, mag = readings(np.zeros((1, 3)))
    accel = np.repeat(accel, n, axis=0) + rng.normal(scale=0.02, size=(n, 3))
    mag = np.repeat(mag, n, axis=0) + rng.normal(scale=0.1, size=(n, 3))
    gyro = rng.normal(scale=1e-3, size=(n, 3))
    for f, args in ((imukit.ImuFilter(100, conventions="matlab"), (accel, gyro)), (imukit.AhrsFilter(100, conventions="matlab"), (accel, gyro, mag))):
        for _ in range(2):
            q = f(*args)
        assert np.all(np.isfinite(q)) and imukit.quaternion_distance(q[-1], [1.0, 0, 0, 0])[0] < 0.05


def test_the_robust_filter_learns_its_bias_at_rest_and_flags_what_it_rejects():
    # 20 s at rest with a 1 °/s gyroscope bias, 3 s of shaking (3 m/s² at 2 Hz), then a steady
    # 5 m/s² push for 4 s: the bias is learnt at rest (status at_rest) and held; the shaking, which
    # the accelerometer's low-pass averages out, is not flagged; the push is, once it has lasted
    # AccelerationSustainedTime (1 s); the tilt holds through both.
    fs, bias = 100.0, np.array([0.01, -0.02, 0.015])
    t = np.arange(0, 27.0, 1 / fs)
    rng = np.random.default_rng(4)
    accel = np.tile([0.0, 0.0, 9.81], (t.size, 1)) + 0.02 * rng.standard_normal((t.size, 3))
    shaking = (t >= 20.0) & (t < 23.0)
    pushed = t >= 23.0
    accel[shaking, 0] += 3.0 * np.sin(2 * np.pi * 2.0 * t[shaking])
    accel[pushed, 0] += 5.0
    gyro = bias + 0.002 * rng.standard_normal((t.size, 3))
    f = imukit.RobustFilter(fs)
    q = f(accel, gyro, t_s=t)
    status = f.status
    assert q.shape == (t.size, 4) and status["gyro_bias"].shape == (t.size, 3)
    assert status["at_rest"][(t > 3) & (t < 19.9)].all()
    assert not status["accel_rejected"][t < 23.0].any()
    assert status["accel_rejected"][t >= 24.05].all()
    np.testing.assert_allclose(status["gyro_bias"][t.size // 2 + 500], bias, atol=2e-3)
    np.testing.assert_allclose(f.gyroscope_offset, status["gyro_bias"][-1])
    # The tilt stays level (the push's 27° apparent tilt is never taken).
    roll_pitch = np.degrees(np.abs(np.arcsin(2 * (q[:, 0] * q[:, 2] - q[:, 3] * q[:, 1]))))
    assert roll_pitch[t >= 20.0].max() < 1.0
