"""Real foot-mounted walks (x-io's public `short_walk.csv` and `long_walk.csv`,
tests/data/gait/README.md): fused from their readings and column map alone, the foot ends where
it started within 0.5 % of the ~25 m and ~60 m walked — the command and Python alike."""
import subprocess

import numpy as np
import pytest

import imukit
from test_cli_vs_python import ROOT, imukit_bin

GAIT = ROOT / "tests" / "data" / "gait"
DISTANCE_M = 25.0  # x-io's figure for the loop


def closure(nav) -> float:
    return float(np.hypot(nav["pos_x_m"][-1] - nav["pos_x_m"][0], nav["pos_y_m"][-1] - nav["pos_y_m"][0]))


def fuse_walk(name: str, out):
    """`imukit fuse LOG --map ngimu.map.toml --zupt --out OUT` on the walk `name`, checked to succeed."""
    done = subprocess.run([imukit_bin(), "fuse", str(GAIT / name), "--map", str(GAIT / "ngimu.map.toml"),
                           "--zupt", "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def test_a_real_walk_closes_its_loop_from_its_readings_alone(tmp_path):
    out = tmp_path / "nav.csv"
    done = fuse_walk("short_walk.csv", out)
    # What the run learnt and dropped, said.
    assert "205 rows repeat the row before exactly" in done.stderr
    assert "found at the start" in done.stderr
    assert "learnt from the populations" in done.stderr
    # Every stride's stance is found, rolling heel to toe as it is: no stretch goes without one.
    assert "found no stance" not in done.stderr
    nav = imukit.read(str(out))
    error = closure(nav)
    assert error <= 0.005 * DISTANCE_M, f"{error:.3f} m"
    # The foot stands at the end: the last second's speed is a stance's.
    speed = np.hypot(nav["vel_x_m_s"], nav["vel_y_m_s"])
    assert speed[-400:].max() < 0.05

    # Python: the same numbers, and the repeated rows as a warning.
    imu = imukit.read(str(GAIT / "short_walk.csv"), map=str(GAIT / "ngimu.map.toml"))
    with pytest.warns(imukit.ImuWarning, match="205 rows repeat the row before exactly"):
        fused = imukit.fuse(imu, None, zupt=True)
    np.testing.assert_array_equal(np.asarray(fused["pos_x_m"]), np.asarray(nav["pos_x_m"]))


def test_a_long_walk_with_long_rests_finds_every_stance_and_closes_its_loop(tmp_path):
    # Its rests fill half the log: a third population of the stance detector's statistic, below
    # the rolling stances, which the threshold must not settle between.
    out = tmp_path / "nav.csv"
    done = fuse_walk("long_walk.csv", out)
    assert "252 rows repeat the row before exactly" in done.stderr
    assert "stances apart from swings and rests" in done.stderr
    assert "found no stance" not in done.stderr
    error = closure(imukit.read(str(out)))
    assert error <= 0.005 * 60.0, f"{error:.3f} m"
