"""imukit.calibrate: the magnetometer's ellipsoid fit equal to an independent NumPy
implementation of the published algebraic fit on the same readings; a calibration applied,
saved, loaded and read with a file alike; refusals named."""
import numpy as np
import pytest

import imukit
from imukit import ImuError


def algebraic_ellipsoid(m: np.ndarray):
    """The ten-term algebraic ellipsoid fit (NXP AN4246; MATLAB magcal with a symmetric matrix),
    written here from the published method: centre and scale the readings, the eigenvector of
    the smallest eigenvalue of DᵀD, the centre −Q⁻¹l, E = Q/(x₀ᵀQx₀ − d); C = E^½/det(E)^⅙ and
    B = det(E)^(−⅙) back in µT. Returns (hard iron, soft iron C, field B)."""
    c = m.mean(axis=0)
    s = np.sqrt(((m - c) ** 2).sum(axis=1).mean())
    x, y, z = ((m - c) / s).T
    d = np.column_stack([x * x, y * y, z * z, 2 * y * z, 2 * x * z, 2 * x * y, 2 * x, 2 * y, 2 * z,
                         np.ones_like(x)])
    w, v = np.linalg.eigh(d.T @ d)
    beta = v[:, np.argmin(w)]
    q = np.array([[beta[0], beta[5], beta[4]], [beta[5], beta[1], beta[3]], [beta[4], beta[3], beta[2]]])
    if np.trace(q) < 0:
        beta, q = -beta, -q
    x0 = -np.linalg.solve(q, beta[6:9])
    k = x0 @ q @ x0 - beta[9]
    e = q / (k * s * s)
    ew, ev = np.linalg.eigh(e)
    root = ev @ np.diag(np.sqrt(ew)) @ ev.T
    det = np.linalg.det(root)
    return c + s * x0, root / np.cbrt(det), 1.0 / np.cbrt(det)


def tumble():
    """A magnetometer turned through all directions, with hard and soft iron and white noise."""
    return imukit.simulate({
        "rate_hz": 50, "duration_s": 120,
        "trajectory": {"type": "expression", "position_m": [0, 0, 0], "yaw_rad": "0.31*t",
                       "pitch_rad": "1.2*sin(0.173*t)", "roll_rad": "0.57*t"},
        "imu": {"kind": "accel-gyro-mag", "seed": 5,
                "magnetometer": {"constant_bias_ut": [12, -30, 5],
                                 "axes_misalignment_pct": [[110, 5, -2], [5, 95, 3], [-2, 3, 102]],
                                 "noise_density_ut_per_rt_hz": 0.05}},
    }).imu


def test_the_ellipsoid_fit_equals_an_independent_implementation_of_the_published_fit():
    imu = tumble()
    cal = imukit.calibrate(imu)
    mag = np.column_stack([imu["mag_x_ut"], imu["mag_y_ut"], imu["mag_z_ut"]])
    hard, soft, field = algebraic_ellipsoid(mag)
    ours = cal.magnetometer
    np.testing.assert_allclose(ours["bias_ut"], hard, rtol=1e-9)
    np.testing.assert_allclose(ours["matrix"], soft, rtol=1e-9, atol=1e-12)
    assert abs(ours["field_ut"] / field - 1) < 1e-9
    # The fitness figure: RMS of |C(m − b)|² − B² over 2B², as the calibration states it.
    r = ((mag - hard) @ soft.T) ** 2
    fit = np.sqrt(((r.sum(axis=1) - field ** 2) ** 2).mean()) / (2 * field ** 2)
    assert abs(ours["fit_error"] / fit - 1) < 1e-6
    # 0.05 µT/√Hz at 50 Hz is 0.35 µT a reading along the radius: the fit error is that over the
    # field's strength (to within the sample's and the soft iron's few per cent).
    expected = 0.05 * np.sqrt(50) / ours["field_ut"]
    assert abs(ours["fit_error"] / expected - 1) < 0.1, (ours["fit_error"], expected)


def test_a_calibration_is_applied_saved_loaded_and_read_with_a_file_alike(tmp_path):
    imu = tumble()
    cal = imukit.calibrate(imu)
    corrected = cal.apply(imu)
    mag = np.column_stack([corrected["mag_x_ut"], corrected["mag_y_ut"], corrected["mag_z_ut"]])
    # On the sphere of the field's strength, to within the readings' noise.
    radius = np.linalg.norm(mag, axis=1)
    assert abs(radius.mean() / cal.magnetometer["field_ut"] - 1) < 1e-3
    assert radius.std() < 0.02 * cal.magnetometer["field_ut"]
    np.testing.assert_array_equal(corrected["gyro_x_rad_s"], imu["gyro_x_rad_s"])
    path = tmp_path / "cal.toml"
    cal.save(path)
    back = imukit.Calibration.load(path)
    np.testing.assert_array_equal(back.magnetometer["matrix"], cal.magnetometer["matrix"])
    log = tmp_path / "imu.csv"
    imu.write(log)
    read = imukit.read(log, calibration=path)
    np.testing.assert_allclose(read.values, corrected.values, rtol=0, atol=1e-12)


def test_refusals_name_what_and_where(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[gyroscope]\nmatrix = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\nbias_rad_s = [0, 0]\n")
    with pytest.raises(ImuError, match=r"bad.toml: gyroscope.bias_rad_s: expected 3 numbers"):
        imukit.Calibration.load(bad)
    with pytest.raises(ImuError, match="neither accelerometer and gyroscope columns"):
        imukit.calibrate({"t_s": np.arange(10.0), "x": np.zeros(10)})
    # At rest throughout: no rests to tell orientations apart, said with the count.
    still = imukit.simulate({"rate_hz": 100, "duration_s": 20,
                             "trajectory": {"type": "builtin", "name": "static"},
                             "imu": {"kind": "accel-gyro", "preset": "mpu-6050", "seed": 1}}).imu
    with pytest.raises(ImuError, match=r"calibrates no sensor: .*static intervals found, the fit needs at least 7"):
        imukit.calibrate(still)


def test_the_residuals_fall_to_the_noise_and_are_drawn(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import imukit.plot

    cal = imukit.calibrate(tumble())
    r = cal.residuals
    # The magnetometer alone: its readings' distance from the sphere, raw (hard and soft iron:
    # tens of per cent) against calibrated (the readings' noise, about 1 %).
    assert len(r["mag_t_s"]) == len(r["mag"]) == len(r["mag_raw"]) > 1000
    assert np.sqrt(np.mean(r["mag"] ** 2)) < 0.02 < np.sqrt(np.mean(r["mag_raw"] ** 2))
    assert len(r["rest_t_s"]) == 0  # a tumble has no rests
    fig = imukit.plot.calibration(cal)
    assert [a.get_title().split(":")[0] for a in fig.axes] == ["Magnetometer, distance from the sphere"]
    fig.savefig(tmp_path / "residuals.png")
