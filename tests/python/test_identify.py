"""Noise identification (`imukit identify`, `imukit.identify`): the deviation and its degrees of
freedom against allantools (an independent implementation), and the round trip
identify → parameter file → simulate → identify, each written figure inside its new interval."""
import subprocess
import tomllib

import numpy as np
import allantools
import pytest
from allantools import ci as allan_ci

import imukit
from test_cli_vs_python import ROOT, imukit_bin


def test_deviation_edf_and_band_agree_with_allantools():
    fs = 50.0
    rng = np.random.default_rng(3)
    x = 0.01 * rng.standard_normal(40_000)       # white rate noise: α = 0 dominates everywhere
    ident = imukit.identify(x, sample_rate_hz=fs)
    tau = ident.tau_s
    # imukit integrates the N readings into N points (as MATLAB's allanvar does); allantools
    # takes those points as phase data.
    theta = np.cumsum(x) / fs
    taus, adev, _, _ = allantools.oadev(theta, rate=fs, data_type="phase", taus=tau)
    assert np.allclose(taus, tau, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ident.adev[:, 0], adev, rtol=1e-9)
    m = np.rint(tau * fs).astype(int)
    edf = [allan_ci.edf_greenhall(alpha=0, d=2, m=int(k), N=len(x), overlapping=True, modified=False) for k in m]
    np.testing.assert_allclose(ident.edf[:, 0], edf, rtol=1e-9)
    for k in range(len(tau)):
        lo, hi = allan_ci.confidence_interval(adev[k], edf[k], ci=0.95)
        assert abs(ident.lower95[k, 0] / lo - 1) < 1e-6 and abs(ident.upper95[k, 0] / hi - 1) < 1e-6
    n = ident.term("column 0", "N")
    assert n["resolved"] and n["lower"] <= 0.01 / np.sqrt(fs) <= n["upper"]
    assert not ident.term("column 0", "B")["resolved"]


def test_identified_part_simulated_again_is_identified_within_the_intervals(tmp_path):
    exe = imukit_bin()
    run = lambda *a: subprocess.run([exe, *map(str, a)], cwd=tmp_path, check=True, capture_output=True, text=True)
    run("simulate", ROOT / "examples" / "static_log.toml", "--out", "still.csv")
    run("identify", "still.csv", "--out", "a.csv", "--params", "part.toml", "--kalibr", "imu.yaml")
    assert "gyroscope_noise_density" in (tmp_path / "imu.yaml").read_text()
    scenario = (ROOT / "examples" / "static_log.toml").read_text()
    scenario = scenario.replace('preset = "stim300"\nseed = 7', 'params = "part.toml"\nseed = 8')
    (tmp_path / "again.toml").write_text(scenario)
    run("simulate", "again.toml", "--out", "again.csv")
    part = tomllib.loads((tmp_path / "part.toml").read_text())
    again = imukit.identify(str(tmp_path / "again.csv"))
    keys = {"N": "noise_density_{u}_per_rt_hz", "B": "bias_instability_{u}", "K": "random_walk_{u}_rt_hz"}
    checked, missed = 0, []
    for sensor, unit, prefix in (("gyroscope", "rad_s", "gyro"), ("accelerometer", "m_s2", "accel")):
        for axis, name in enumerate("xyz"):
            column = f"{prefix}_{name}_{unit}"
            for symbol, key in keys.items():
                truth = part[sensor][key.format(u=unit)][axis]
                row = again.term(column, symbol)
                if not row["lower"] <= truth <= row["upper"]:
                    missed.append((column, symbol, truth, row["lower"], row["upper"]))
                checked += 1
    # 95 % intervals: over 18 figures, at most 2 outside (the core's test counts the coverage
    # over many runs).
    assert checked == 18 and len(missed) <= 2, missed


def test_a_log_that_moves_is_warned_about_and_the_bias_at_rest_is_written(tmp_path):
    import warnings

    rng = np.random.default_rng(4)
    n = 60_000
    still = {f"gyro_{a}_rad_s": b + 1e-3 * rng.standard_normal(n) for a, b in zip("xyz", (0.01, -0.02, 0.003))}
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # a static log: no warning at all
        ident = imukit.identify(still, 100.0)
    part = tomllib.loads(ident.params_toml)
    for k, a in enumerate("xyz"):
        mean, sigma = ident.mean_at_rest[f"gyro_{a}_rad_s"]
        assert abs(mean - (0.01, -0.02, 0.003)[k]) < 5 * 1e-3 / np.sqrt(n)
        assert part["gyroscope"]["constant_bias_rad_s"][k] == mean
    moved = dict(still)
    moved["gyro_z_rad_s"] = moved["gyro_z_rad_s"] + np.where((np.arange(n) >= 20_000) & (np.arange(n) < 21_500), 0.4, 0.0)
    with pytest.warns(imukit.ImuWarning, match="gyro_z_rad_s: not at rest at t = 200–215 s"):
        imukit.identify(moved, 100.0)
    # The CLI: --params alone (no --out) is a run of its own, and says the same.
    names = ["t_s", *moved]
    np.savetxt(tmp_path / "moved.csv", np.column_stack([np.arange(n) / 100.0, *moved.values()]),
               delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    done = subprocess.run([imukit_bin(), "identify", str(tmp_path / "moved.csv"), "--params",
                           str(tmp_path / "p.toml")], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "not at rest at t = 200–215 s" in done.stderr and (tmp_path / "p.toml").exists()


def test_a_gauss_markov_bias_round_trips_through_simulate_and_identify(tmp_path):
    """A part whose gyroscope bias is first-order Gauss–Markov (σ 2e-4 rad/s, 3 s) simulated at
    rest for 40 minutes: ``identify`` finds the Markov term on every axis, its σ and correlation
    time inside their intervals (but for one of the six), and writes the part back as a Gauss–Markov bias; the command
    and Python write the same file."""
    part = """name = "markov part"
[accelerometer]
noise_density_m_s2_per_rt_hz = 1e-3
noise_type = "single-sided"
[gyroscope]
noise_density_rad_s_per_rt_hz = 1e-4
bias_instability_rad_s = 2e-4
bias_instability_correlation_time_s = 3.0
noise_type = "single-sided"
"""
    (tmp_path / "part.toml").write_text(part)
    scenario = (ROOT / "examples" / "static_log.toml").read_text()
    scenario = scenario.replace('preset = "stim300"\nseed = 7', 'params = "part.toml"\nseed = 3')
    scenario = scenario.replace("duration_s = 1200.0", "duration_s = 2400.0")
    (tmp_path / "still.toml").write_text(scenario)
    exe = imukit_bin()
    run = lambda *a: subprocess.run([exe, *map(str, a)], cwd=tmp_path, check=True, capture_output=True, text=True)
    run("simulate", "still.toml", "--out", "still.csv")
    printed = run("identify", "still.csv", "--params", "found.toml").stdout
    ident = imukit.identify(str(tmp_path / "still.csv"))
    assert ident.params_toml.splitlines()[2:] == (tmp_path / "found.toml").read_text().splitlines()[2:]
    markov = [d for d in ident.scaled_terms if d["term"] == "markov"]
    assert sorted(d["column"] for d in markov) == [f"gyro_{a}_rad_s" for a in "xyz"]
    # Six 95 % intervals (σ and T_c per axis): at most one outside (the core's tests count the
    # coverage over many runs).
    missed = [d for d in markov if not d["lower"] <= 2e-4 <= d["upper"]]
    missed += [d for d in markov if not d["scale_lower"] <= 3.0 <= d["scale_upper"]]
    assert len(missed) <= 1, missed
    for d in markov:
        assert d["chi2_drop"] > d["criterion"] and d["unit"] == "rad/s" and d["scale_unit"] == "s"
        assert f"correlation time {d['scale']:.4f} s" in printed
    found = tomllib.loads(ident.params_toml)["gyroscope"]
    median = sorted(d["scale"] for d in markov)[1]
    assert found["bias_instability_correlation_time_s"] == pytest.approx(median, rel=1e-5)
    assert found["bias_instability_rad_s"] == pytest.approx([d["value"] for d in markov], rel=1e-5)
