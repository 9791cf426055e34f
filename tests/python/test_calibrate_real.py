"""A real multi-position log (IMU-TK's Xsens log, tests/data/imu_tk/README.md) calibrated as a
user would: the first 300 s and the rest calibrated separately agree term by term within their
stated uncertainties (combined 3σ); the first calibration applied to the second part's rests
reads gravity there about as well as that part's own fit, far better than the nominal scale;
the command and Python give the same file."""
import subprocess

import numpy as np

import imukit
from test_cli_vs_python import ROOT, imukit_bin

LOG = ROOT / "tests" / "data" / "imu_tk" / "xsens.csv"
GRAVITY = 9.81744  # IMU-TK's example's figure for this log
SPLIT_S = 300.0


def readings() -> imukit.Table:
    """The counts in SI units with nominal figures: gyroscope 1/6258 rad/s a count, centred on
    32768; accelerometer centred on 32768 and scaled so that the first rest reads gravity."""
    raw = imukit.read(LOG)
    acc = np.column_stack([raw[f"acc_{a}_counts"] for a in "xyz"]) - 32768.0
    scale = GRAVITY / np.linalg.norm(acc[:4000].mean(axis=0))
    columns = {"t_s": raw["t_s"]}
    for k, a in enumerate("xyz"):
        columns[f"accel_{a}_m_s2"] = acc[:, k] * scale
    for a in "xyz":
        columns[f"gyro_{a}_rad_s"] = (raw[f"gyro_{a}_counts"] - 32768.0) / 6258.0
    return imukit.Table.of(columns)


def part(table: imukit.Table, first: bool) -> imukit.Table:
    keep = (table["t_s"] < SPLIT_S) if first else (table["t_s"] >= SPLIT_S)
    return imukit.Table(list(table.columns), table.values[keep])


def test_two_halves_of_a_real_log_agree_within_their_uncertainties():
    si = readings()
    a, b = imukit.calibrate(part(si, True), gravity_m_s2=GRAVITY), imukit.calibrate(part(si, False), gravity_m_s2=GRAVITY)
    assert len(a.rests) >= 20 and len(b.rests) >= 15, (len(a.rests), len(b.rests))
    for sensor, unit in (("accelerometer", "m_s2"), ("gyroscope", "rad_s")):
        x, y = getattr(a, sensor), getattr(b, sensor)
        for key, sigma in (("matrix", "matrix_sigma"), (f"bias_{unit}", f"bias_sigma_{unit}")):
            d = np.asarray(x[key]) - np.asarray(y[key])
            s = np.hypot(x[sigma], y[sigma])
            z = np.divide(d, s, out=np.zeros_like(d), where=s > 0)
            assert np.all(np.abs(z) < 3), f"{sensor} {key}: {np.round(z, 2)}"
    # What was found is a real part's: scale factors within a few per cent of one another,
    # the gyroscope's about 1.31 times the nominal 1/6258 rad/s a count, and the residual of
    # gravity's magnitude at the rests near a millimetre per second squared.
    assert np.allclose(np.diag(a.gyroscope["matrix"]), 1.31, atol=0.01)
    assert a.accelerometer["residual_rms_m_s2"] < 2e-3
    assert a.gyroscope["residual_rms_rad"] < 1e-2


def test_a_calibration_applied_to_another_part_of_the_log_reads_gravity_at_its_rests():
    si = readings()
    first = imukit.calibrate(part(si, True), gravity_m_s2=GRAVITY)
    second = part(si, False)
    corrected = first.apply(second)
    again = imukit.calibrate(corrected, gravity_m_s2=GRAVITY)
    # Recalibrated, the corrected readings need almost nothing more: the matrix is the identity
    # and the bias zero within the two calibrations' uncertainty.
    acc = again.accelerometer
    assert np.allclose(np.diag(acc["matrix"]), 1.0, atol=2e-3)
    assert np.all(np.abs(acc["bias_m_s2"]) < 3 * np.hypot(acc["bias_sigma_m_s2"], first.accelerometer["bias_sigma_m_s2"]))
    # Gravity's magnitude at the second part's rests: as good as that part's own fit, against
    # centimetres per second squared off with the nominal scale.
    acc_cols = [f"accel_{a}_m_s2" for a in "xyz"]

    def magnitude_rms(table):
        v = np.column_stack([table[c] for c in acc_cols])
        return np.sqrt(np.mean([(np.linalg.norm(v[s:e].mean(axis=0)) - GRAVITY) ** 2 for s, e in again.rests]))

    calibrated, nominal = magnitude_rms(corrected), magnitude_rms(second)
    assert calibrated < 3e-3 and nominal > 10 * calibrated, (calibrated, nominal)


def test_the_command_writes_what_python_finds(tmp_path):
    si = readings()
    log = tmp_path / "xsens_si.csv"
    si.write(log)
    out = tmp_path / "cal.toml"
    done = subprocess.run([imukit_bin(), "calibrate", str(log), "--gravity-m-s2", str(GRAVITY),
                           "--end-s", str(SPLIT_S - si["t_s"][0]), "--out", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "rests found" in done.stdout and "gyroscope" in done.stdout
    ours = imukit.Calibration.load(out)
    py = imukit.calibrate(imukit.Table(list(si.columns), si.values[si["t_s"] - si["t_s"][0] <= SPLIT_S - si["t_s"][0]]),
                          gravity_m_s2=GRAVITY)
    np.testing.assert_allclose(ours.gyroscope["matrix"], py.gyroscope["matrix"], rtol=1e-12)
    # --calibration applies it wherever readings are read: the Allan command reads corrected
    # rates (the calibrated gyroscope's scale is 1.31 times the nominal).
    plain, fixed = tmp_path / "plain.csv", tmp_path / "fixed.csv"
    for args, dest in (([], plain), (["--calibration", str(out)], fixed)):
        done = subprocess.run([imukit_bin(), "allan", str(log), "--column", "gyro_x_rad_s", "--end-s", "50",
                               "--out", str(dest), *args], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
    ratio = imukit.read(fixed)["adev_gyro_x_rad_s"][0] / imukit.read(plain)["adev_gyro_x_rad_s"][0]
    assert abs(ratio - 1.31) < 0.02, ratio
