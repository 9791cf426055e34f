"""A newcomer's first hour from the wheel alone: the shipped examples written where the guides read
them, a built-in scenario with GNSS that fuses, a track that waits at its start, and an outage
study drawn from its table."""
import subprocess

import numpy as np
import pytest

import imukit
from imukit import ImuError

from test_cli_vs_python import imukit_bin


def test_every_example_is_written_and_left_alone_when_unchanged(tmp_path):
    names = imukit.examples()
    assert {"expression", "car_tunnel", "study/tunnel", "data/euroc"} <= set(names)
    folder = imukit.example("all", folder=tmp_path / "ex")
    written = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())
    assert "study/tunnel.toml" in written and "data/euroc/mav0/imu0/data.csv" in written
    # The command line writes the same bytes; files already there are left as they are.
    done = subprocess.run([imukit_bin(), "example", "all", "--out-dir", str(folder)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("is already there") == len(written)


def test_an_edited_example_is_never_overwritten(tmp_path):
    path = imukit.example("track", folder=tmp_path)
    path.write_text("# mine\n")
    with pytest.raises(ImuError, match="exists and differs"):
        imukit.example("track", folder=tmp_path)
    assert path.read_text() == "# mine\n"
    with pytest.raises(ImuError, match="the examples are expression"):
        imukit.example("no-such-example", folder=tmp_path)


def test_the_builtin_car_with_gnss_fuses_within_its_sigma():
    scenario = {"trajectory": {"type": "builtin", "name": "gnss-car"}}
    sim = imukit.simulate(scenario)
    assert sim.gnss is not None
    nav = imukit.fuse(sim.imu, sim.gnss, scenario=scenario, initial=sim.truth)
    # Where the fixes are (before the outage at 60 s), the horizontal error is within 3σ of the
    # filter's own one-sigma on most rows (the fixes' white noise, 1.5 m, is what it assumes).
    t = nav["t_s"]
    rows = (t > 25.0) & (t < 60.0)
    err = np.hypot(nav["pos_x_m"] - sim.truth["pos_x_m"], nav["pos_y_m"] - sim.truth["pos_y_m"])
    sigma = np.hypot(nav["pos_x_sigma_m"], nav["pos_y_sigma_m"])
    inside = np.mean(err[rows] < 3.0 * sigma[rows])
    assert inside > 0.9, inside
    assert float(np.max(err)) < 5.0


def test_a_track_waits_at_its_start():
    sim = imukit.simulate({"rate_hz": 50.0, "trajectory": {
        "type": "track", "speed_m_s": 2.0, "accel_m_s2": 0.5,
        "segments": [{"wait_s": 10.0}, {"straight_m": 20.0}]}})
    t, v = sim.truth["t_s"], sim.truth["vel_x_m_s"]
    assert np.all(v[t < 10.0] == 0.0) and v[t > 10.5].max() > 0.1
    # 20 m at 2 m/s with 0.5 m/s² ramps: 4 s up, 6 s cruise, 4 s down, after the 10 s wait.
    assert t[-1] == pytest.approx(24.0, abs=0.02)
    with pytest.raises(ImuError, match=r"\{ wait_s = T \}.*this one has wait"):
        imukit.simulate({"trajectory": {"type": "track", "speed_m_s": 2.0, "accel_m_s2": 0.5,
                                        "segments": [{"wait": 10.0}, {"straight_m": 20.0}]}})


def test_a_study_table_is_drawn_as_a_study(tmp_path):
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    import imukit.plot
    t = np.linspace(0.0, 30.0, 31)
    table = imukit.Table(["t_s", "stim300_rms_error_m", "stim300_sigma_m", "stim300_smoothed_rms_error_m"],
                         np.column_stack([t, 0.1 + t**2 / 100, 0.1 + t**2 / 90, 0.1 + t / 100]))
    assert imukit.plot.kind(table) == "study"
    fig = imukit.plot.figure(table)
    lines = fig.axes[0].get_lines()
    assert [ln.get_linestyle() for ln in lines] == ["-", "--", ":"]
    path = tmp_path / "study.csv"
    table.write(path)
    out = tmp_path / "study.png"
    done = subprocess.run([imukit_bin(), "plot", str(path), "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert out.stat().st_size > 1000
