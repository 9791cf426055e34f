"""Real time stamps: each sample integrated over its own interval, jitter and gaps bridged and
reported, never refused — through the strapdown, every orientation filter and `imukit orient`."""
import os
import subprocess
import warnings

import numpy as np
import pytest

import imukit

RATE_HZ = 100.0


def stamps(seconds: float, jittered: bool, every: int = 600, seed: int = 7) -> np.ndarray:
    """Times at a nominal 100 Hz: regular, or each moved by up to ±1 ms (every interval within
    ±20 % of 10 ms) with a gap of 30 ms (two samples lost) every `every` samples."""
    k = np.arange(int(round(seconds * RATE_HZ)) + 1)
    t = k / RATE_HZ
    if not jittered:
        return t
    rng = np.random.default_rng(seed)
    t = t + np.where(k > 0, 1e-3 * rng.uniform(-1.0, 1.0, k.size), 0.0)
    return t[~((k % every == every // 2) | (k % every == every // 2 + 1))]


def flight(t: np.ndarray):
    truth = imukit.truth_from_expressions(
        t, ["20*sin(0.1*t)", "10*sin(0.2*t)", "0.5*sin(0.3*t)"], attitude="tangent", min_speed_m_s=0.1)
    return truth, imukit.ideal_imu(truth)


def strapdown_errors(t: np.ndarray, scheme: str):
    truth, imu = flight(t)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        nav = imukit.strapdown(imu, initial=truth, scheme=scheme)
    _, summary = imukit.compare(truth, nav)
    return summary["position_max_m"], summary["attitude_max_rad"], [str(w.message) for w in caught]


@pytest.mark.parametrize("scheme", ["coning", "rk4"])
def test_strapdown_takes_each_interval_and_reports_the_gaps(scheme):
    regular = strapdown_errors(stamps(60.0, False), scheme)
    jittered = strapdown_errors(stamps(60.0, True), scheme)
    assert regular[2] == []
    # Ten gaps of three nominal intervals, bridged and named.
    (note,) = jittered[2]
    assert note.startswith("imu: 10 gaps longer than 2.5 median intervals"), note
    if scheme == "coning":
        # Second order: its error follows the sum of the squared intervals, which ±20 % jitter
        # raises by 1.3 % and the ten gaps by 0.3 %; the error is that of the regular grid.
        assert jittered[0] <= 1.1 * regular[0] and jittered[1] <= 1.3 * regular[1], (regular, jittered)
    else:
        # Fourth order on quintic interpolation: at rounding level on either grid.
        assert regular[0] < 1e-9 and jittered[0] < 1e-9, (regular, jittered)


class Readings:
    def __init__(self, table):
        self.table = table
        self.accel, self.gyro, self.mag = (
            np.column_stack([table[f"{s}_{a}_{u}"] for a in "xyz"])
            for s, u in (("accel", "m_s2"), ("gyro", "rad_s"), ("mag", "ut")))


def swaying(t: np.ndarray):
    """The attitude Rz(0.4 t) Rx(0.3 sin 0.5 t) at a fixed point, in ENU, in a field that
    points to true north (so that a magnetometer's yaw is the truth's)."""
    truth = imukit.truth_from_expressions(
        t, ["0", "0", "0"], yaw_rad="0.4*t", roll_rad="0.3*sin(0.5*t)")
    return truth, Readings(imukit.ideal_imu(truth, magnetic_field_ut=(0.0, 25.0, -43.3)))


FILTERS = [
    (imukit.ImuFilter, {}, False),
    (imukit.AhrsFilter, {}, True),
    (imukit.ComplementaryFilter, {"has_magnetometer": False}, False),
    (imukit.MadgwickFilter, {"has_magnetometer": False}, False),
    (imukit.MahonyFilter, {"has_magnetometer": False}, False),
]


def filter_error(cls, kw, mag, t, timed):
    truth, imu = swaying(t)
    f = cls(RATE_HZ, **kw)
    args = [imu.accel, imu.gyro] + ([imu.mag] if mag else [])
    q = f(*args, t_s=t if timed else None)
    q_true = np.column_stack([truth[c] for c in ("q_w", "q_x", "q_y", "q_z")])
    return float(np.max(imukit.quaternion_distance(q, q_true)))


@pytest.mark.parametrize("cls,kw,mag", FILTERS)
def test_each_filter_takes_the_stamps_through_jitter_and_gaps(cls, kw, mag):
    # Ten gaps in 20 s.
    regular, jittered = stamps(20.0, False), stamps(20.0, True, every=200)
    e_regular = filter_error(cls, kw, mag, regular, True)
    e_stamped = filter_error(cls, kw, mag, jittered, True)
    e_fixed = filter_error(cls, kw, mag, jittered, False)
    assert e_stamped <= 2.5 * e_regular and e_stamped < 1e-2, (e_regular, e_stamped)
    if not mag:
        # Nothing corrects the heading: at a fixed 100 Hz it drifts by what the stamps say.
        assert e_fixed > 10 * e_stamped, (e_fixed, e_stamped)


def test_stamped_calls_in_chunks_equal_one_call_and_bad_times_are_named():
    t = stamps(5.0, True)
    _, imu = swaying(t)
    whole = imukit.ImuFilter(RATE_HZ)(imu.accel, imu.gyro, t_s=t)
    f = imukit.ImuFilter(RATE_HZ)
    parts = [f(imu.accel[a:b], imu.gyro[a:b], t_s=t[a:b]) for a, b in [(0, 7), (7, 250), (250, len(t))]]
    np.testing.assert_array_equal(np.vstack(parts), whole)
    f.reset()
    np.testing.assert_array_equal(f(imu.accel, imu.gyro, t_s=t), whole)
    bad = t.copy()
    bad[40] = bad[39]
    g = imukit.ImuFilter(RATE_HZ)
    with pytest.raises(imukit.ImuError, match=r"t_s: row 40: the time .* does not increase"):
        g(imu.accel, imu.gyro, t_s=bad)
    # Refused whole: the filter and its clock are as before, so the good call starts afresh.
    np.testing.assert_array_equal(g(imu.accel, imu.gyro, t_s=t), whole)
    with pytest.raises(imukit.ImuError, match="t_s: has 3 times"):
        g(imu.accel, imu.gyro, t_s=t[:3])


def imukit_bin() -> str:
    return os.environ.get("IMUKIT_BIN", "imukit")


def test_orient_runs_a_file_with_gaps_and_says_so(tmp_path):
    t = stamps(60.0, True)
    _, imu = swaying(t)
    path = tmp_path / "jittery.csv"
    imu.table.write(path)
    out = tmp_path / "o.csv"
    for extra, timing in [([], "each over its own interval"), (["--param", "SampleRate=100"], "at a fixed 100 Hz")]:
        done = subprocess.run([imukit_bin(), "orient", str(path), "--filter", "imufilter", "--out", str(out), *extra],
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        assert timing in done.stderr and not done.stdout, done.stderr
        assert f"imukit: warning: {path}: 10 gaps longer than 2.5 median intervals" in done.stderr, done.stderr
        assert len(imukit.read(out)) == len(t)
