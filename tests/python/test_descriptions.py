"""What a table holds travels with it in Python as it does in files: a NED simulation stays NED
through write, read, pandas and every job, and an argument that contradicts it is refused."""
import subprocess
from pathlib import Path

import numpy as np
import pytest

import imukit
from imukit import ImuError

from test_cli_vs_python import imukit_bin

ROOT = Path(__file__).resolve().parents[2]

NED = {"rate_hz": 100.0, "duration_s": 30.0, "nav_frame": "NED",
       "trajectory": {"type": "builtin", "name": "platform-turn"}}


@pytest.fixture(scope="module")
def ned():
    return imukit.simulate(NED)


def test_simulated_tables_say_their_frame_and_kind(ned):
    assert ned.imu.description["nav_frame"] == "NED"
    assert ned.imu.description["body_frame"] == "FRD"
    assert ned.imu.description["kind"] == "readings"
    assert ned.truth.description["kind"] == "truth"
    assert ned.truth.description["earth"] == "flat"
    # A table made from plain columns knows nothing.
    assert dict(imukit.Table(["t_s"], [[0.0]]).description) == {}


def test_ned_written_read_and_integrated_ends_where_the_command_line_ends(ned, tmp_path):
    imu, truth = tmp_path / "imu.csv", tmp_path / "truth.csv"
    ned.imu.write(imu)
    ned.truth.write(truth)
    nav = imukit.strapdown(imukit.read(imu), initial=imukit.read(truth))
    assert nav.description["nav_frame"] == "NED"
    out = tmp_path / "nav.csv"
    subprocess.run([imukit_bin(), "integrate", str(imu), "--init", str(truth), "--out", str(out)],
                   check=True, capture_output=True)
    cli = imukit.read(out)
    assert cli.columns == nav.columns
    final = lambda t: np.array([t[c][-1] for c in ("pos_x_m", "pos_y_m", "pos_z_m")])  # noqa: E731
    assert np.linalg.norm(final(cli) - final(nav)) < 1e-9
    # Ideal readings in their own frame come back to the truth; read as ENU they would not.
    assert imukit.compare(ned.truth, nav).summary["position_final_m"] < 1e-6


def test_an_argument_that_contradicts_a_description_is_refused(ned):
    with pytest.raises(ImuError, match=r"nav_frame: ENU contradicts the imu table, whose description says NED"):
        imukit.strapdown(ned.imu, initial=ned.truth, nav_frame="ENU")
    with pytest.raises(ImuError, match=r"accel_sign: matlab contradicts the imu table"):
        imukit.strapdown(ned.imu, initial=ned.truth, accel_sign="matlab")
    # Saying what it says is fine.
    imukit.strapdown(ned.imu, initial=ned.truth, nav_frame="NED")
    enu = imukit.simulate({**NED, "nav_frame": "ENU", "duration_s": 1.0})
    with pytest.raises(ImuError, match=r"nav_frame.*the inputs disagree"):
        imukit.strapdown(ned.imu, initial=enu.truth)
    nav = imukit.strapdown(enu.imu, initial=enu.truth)
    with pytest.raises(ImuError, match=r"nav_frame.*disagree"):
        imukit.compare(ned.truth, nav)


def test_a_description_rides_along_in_a_pandas_frame(ned):
    df = ned.imu.to_pandas()
    assert df.attrs["imukit"]["nav_frame"] == "NED"
    a = imukit.strapdown(df, initial=ned.truth.to_pandas())
    b = imukit.strapdown(ned.imu, initial=ned.truth)
    np.testing.assert_array_equal(a.values, b.values)
    assert imukit.Table.of(df).description["nav_frame"] == "NED"
    # A frame whose attrs were dropped is plain data: the defaults apply, as for a plain CSV.
    df.attrs.clear()
    with pytest.raises(ImuError):
        # ENU applied to NED readings: the truth table still says NED.
        imukit.strapdown(df, initial=ned.truth, nav_frame="ENU")


def test_a_bad_description_is_refused_by_its_key(ned):
    bad = imukit.Table(ned.imu.columns, ned.imu.values, {**ned.imu.description, "nav_frame": "NWU"})
    with pytest.raises(ImuError, match=r"imu.description: key nav_frame"):
        imukit.strapdown(bad)


@pytest.fixture(scope="module")
def ned_road():
    return imukit.simulate({"rate_hz": 100.0, "nav_frame": "NED",
                            "trajectory": {"type": "waypoints", "time_s": [5, 15, 25, 35],
                                           "position_m": [[0, 0, 0], [60, 0, 0], [150, 30, 0], [220, 90, 0]],
                                           "velocity_m_s": [[0, 0, 0], [0, 0, 0]]},
                            "imu": {"preset": "stim300", "seed": 3},
                            "gnss": {"rate_hz": 5.0, "horizontal_accuracy_m": 1.5, "vertical_accuracy_m": 3.0,
                                     "velocity_accuracy_m_s": 0.1, "decay_factor": 0.0}})


def test_fuse_on_read_ned_tables_with_a_part_takes_their_frame(ned_road, tmp_path):
    paths = {}
    for name in ("imu", "truth", "gnss"):
        paths[name] = tmp_path / f"{name}.csv"
        getattr(ned_road, name).write(paths[name])
    imu, truth, gnss = (imukit.read(paths[n]) for n in ("imu", "truth", "gnss"))
    fused = imukit.fuse(imu, gnss, initial=truth, imu_model="stim300")
    assert fused.description["nav_frame"] == "NED" and fused.description["kind"] == "fused"
    told = imukit.fuse(imu, gnss, initial=truth, imu_model="stim300", nav_frame="NED")
    np.testing.assert_array_equal(fused.values, told.values)
    assert imukit.compare(truth, fused).summary["position_rms_m"] < 3.0
    with pytest.raises(ImuError, match=r"nav_frame: ENU contradicts the imu table"):
        imukit.fuse(imu, gnss, initial=truth, imu_model="stim300", nav_frame="ENU")


def test_command_line_fuse_takes_the_frame_of_a_plain_csv_from_its_options(ned_road, tmp_path):
    files = {}
    for name in ("imu", "truth", "gnss"):
        files[name] = tmp_path / f"{name}.csv"
        getattr(ned_road, name).write(files[name])
        # The same numbers without the description line: a NED export from elsewhere.
        lines = files[name].read_text().splitlines(keepends=True)
        (tmp_path / f"plain_{name}.csv").write_text("".join(lines[1:]))

    def fuse(prefix, *flags):
        out = tmp_path / f"nav_{prefix}{'_'.join(f.strip('-') for f in flags)}.csv"
        subprocess.run([imukit_bin(), "fuse", str(tmp_path / f"{prefix}imu.csv"), str(tmp_path / f"{prefix}gnss.csv"),
                        "--init", str(tmp_path / f"{prefix}truth.csv"), "--imu", "stim300", *flags,
                        "--out", str(out)], check=True, capture_output=True)
        return imukit.read(out)

    described = fuse("")
    assert described.description["nav_frame"] == "NED"
    for flags in (("--nav-frame", "NED"), ("--conventions", "matlab", "--accel-sign", "specific-force")):
        told = fuse("plain_", *flags)
        np.testing.assert_array_equal(told.values, described.values)
    # Contradicting the described file is refused, naming the option and the file.
    r = subprocess.run([imukit_bin(), "fuse", str(files["imu"]), str(files["gnss"]), "--init", str(files["truth"]),
                        "--imu", "stim300", "--nav-frame", "ENU", "--out", str(tmp_path / "x.csv")],
                       capture_output=True, text=True)
    assert r.returncode == 65 and "--nav-frame" in r.stderr and "imu.csv" in r.stderr, r.stderr
    assert not (tmp_path / "x.csv").exists()


def test_integrate_without_a_start_says_what_it_assumed(ned, tmp_path):
    imu = tmp_path / "imu.csv"
    ned.imu.write(imu)
    r = subprocess.run([imukit_bin(), "integrate", str(imu), "--out", str(tmp_path / "nav.csv")],
                       capture_output=True, text=True, check=True)
    assert "no --init" in r.stderr and "at the origin, at rest, level with heading 0" in r.stderr, r.stderr
    r = subprocess.run([imukit_bin(), "integrate", str(imu), "--euler0-rad", "0", "0", "0",
                        "--out", str(tmp_path / "nav.csv")], capture_output=True, text=True, check=True)
    assert "at the origin, at rest (give" in r.stderr, r.stderr


def test_figures_draw_a_described_ned_truth_as_ned():
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    import imukit.plot
    sim = imukit.simulate({"duration_s": 2.0, "trajectory": {"type": "builtin", "name": "platform-turn"}})
    assert sim.truth.description["nav_frame"] == "NED"
    fig = imukit.plot.figure(sim.truth)
    assert fig._suptitle.get_text().endswith("— NED")
    with pytest.raises(imukit.ImuError, match="nav_frame: ENU contradicts"):
        imukit.plot.figure(sim.truth, nav_frame="ENU")
    with pytest.raises(imukit.ImuError, match="nav_frame: ENU contradicts"):
        imukit.plot.animate(sim.truth, nav_frame="ENU")
