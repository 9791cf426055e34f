"""imukit.plot: each figure kind drawn from tables and files, checked for size and series count;
the animation's frames; bad input."""
import struct

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import imukit  # noqa: E402
import imukit.plot as ip  # noqa: E402


@pytest.fixture(scope="module")
def sim():
    return imukit.simulate({"trajectory": {"type": "builtin", "name": "figure8"}})


def png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def lines(fig):
    return [len(ax.get_lines()) for ax in fig.axes]


def test_truth_figure_has_the_trajectory_and_six_panels_and_saves_at_its_size(sim, tmp_path):
    fig = ip.figure(sim.truth)
    assert [ax.get_title() for ax in fig.axes] == [
        "Trajectory", "Position", "Velocity", "Acceleration (navigation frame)",
        "Attitude (z-y-x Euler angles)", "Body rate", "Body angular acceleration"]
    assert lines(fig) == [1] + [3] * 6
    assert fig.axes[0].name == "3d"  # the figure-8 leaves the plane
    # Attitude is drawn in degrees.
    yaw = fig.axes[4].get_lines()[0].get_ydata()
    np.testing.assert_allclose(yaw, np.degrees(sim.truth["yaw_rad"]))
    out = tmp_path / "truth.png"
    fig.savefig(out, dpi=50)
    assert png_size(out) == (2 * 280, 4 * 160)  # 2 × 4 cells of 5.6 × 3.2 in at 50 dpi


def test_truth_and_estimate_overlay_dashed(sim):
    nav = imukit.strapdown(sim.imu, initial=sim.truth)
    fig = ip.figure(sim.truth, nav, labels=["truth", "nav"])
    # Position, velocity and attitude get both tables; the others only the truth's.
    assert lines(fig) == [2, 6, 6, 3, 6, 3, 3]
    styles = [ln.get_linestyle() for ln in fig.axes[1].get_lines()]
    assert styles == ["-"] * 3 + ["--"] * 3
    assert fig.axes[1].get_lines()[3].get_label() == "x (nav)"


def test_imu_errors_and_allan_figures_from_files(sim, tmp_path):
    imu = tmp_path / "imu.csv"
    np.savetxt(imu, sim.imu.values, delimiter=",", header=",".join(sim.imu.columns), comments="")
    assert lines(ip.figure(imu)) == [3, 3, 3]
    nav = imukit.strapdown(sim.imu, initial=sim.truth)
    errors, _ = imukit.compare(sim.truth, nav)
    fig = ip.figure(errors)
    assert [ax.get_title() for ax in fig.axes] == ["Position error", "Velocity error", "Attitude error"]
    assert lines(fig) == [4, 3, 1]
    still = imukit.simulate({"rate_hz": 100.0, "duration_s": 200.0,
                             "trajectory": {"type": "builtin", "name": "static"},
                             "imu": {"preset": "mpu-6050", "seed": 3}})
    tau, adev = imukit.allan_deviation(still.imu.values[:, 1:7], 100.0)
    fig = ip.allan(tau, adev)
    assert lines(fig) == [6]
    assert fig.axes[0].get_xscale() == "log" and fig.axes[0].get_yscale() == "log"


def test_errors_of_a_fused_estimate_are_drawn_against_three_sigma():
    scenario = {"rate_hz": 50.0, "duration_s": 30.0,
                "trajectory": {"type": "expression", "position_m": ["60*sin(0.16*t)", "60*(1 - cos(0.16*t))", "0"],
                               "attitude": "tangent"},
                "imu": {"kind": "accel-gyro", "preset": "stim300"},
                "gnss": {"rate_hz": 5.0, "decay_factor": 0.0}}
    car = imukit.simulate(scenario)
    nav = imukit.fuse(car.imu, car.gnss, initial=car.truth, scenario=scenario)
    errors, _ = imukit.compare(car.truth, nav)
    np.testing.assert_array_equal(errors["pos_x_sigma_m"], nav["pos_x_sigma_m"])
    # Position and velocity gain a dotted pair at ±3σ per axis, the attitude angle one at ±3σ of
    # the root sum of squares of its axes' one-sigma, as imukit plot draws them.
    fig = ip.figure(errors)
    assert lines(fig) == [4 + 6, 3 + 6, 1 + 2]
    pos = fig.axes[0].get_lines()
    np.testing.assert_allclose(pos[4].get_ydata(), 3 * nav["pos_x_sigma_m"])
    np.testing.assert_allclose(pos[5].get_ydata(), -3 * nav["pos_x_sigma_m"])
    rss = np.sqrt(sum(nav[f"att_{a}_sigma_rad"] ** 2 for a in "xyz"))
    np.testing.assert_allclose(fig.axes[2].get_lines()[1].get_ydata(), 3 * np.degrees(rss))


def test_plain_arrays_by_column_name_plot_like_tables(sim):
    arrays = {c: np.array(sim.imu[c]) for c in sim.imu.columns}
    assert lines(ip.figure(arrays)) == lines(ip.figure(sim.imu)) == [3, 3, 3]
    with pytest.raises(ValueError, match="column .gyro_z_rad_s. has 4 rows, column .t_s. has 3"):
        ip.figure({"t_s": np.zeros(3), "gyro_z_rad_s": np.zeros(4)})


def test_planar_paths_are_drawn_from_above_with_equal_scales():
    t = np.linspace(0.0, 10.0, 101)
    table = imukit.Table(["t_s", "pos_x_m", "pos_y_m", "yaw_rad"],
                         np.column_stack([t, 10 * np.cos(t / 5), 3 * np.sin(t / 5), t / 5]))
    fig = ip.trajectory(table)
    ax = fig.axes[0]
    assert ax.name == "rectilinear" and ax.get_aspect() == 1.0
    start, end = ax.get_lines()[1].get_xydata()[0], ax.get_lines()[2].get_xydata()[0]
    np.testing.assert_allclose(start, [10.0, 0.0])
    np.testing.assert_allclose(end, [10 * np.cos(2.0), 3 * np.sin(2.0)])


def test_animation_frames_follow_the_frame_plan_and_save_as_gif(sim, tmp_path):
    anim = ip.animate(sim.truth, fps=5.0, lever_arm_m=(-0.075, -0.075, 0.025))
    # 1 s of motion lasts 4 s by default: 5 frames/s → 21 frames.
    out = tmp_path / "body.gif"
    anim.save(out, writer="pillow", fps=5)
    from PIL import Image

    with Image.open(out) as im:
        assert im.n_frames == 21
        assert im.size == (640, 480)


def test_bad_input_is_refused_with_what_and_where(sim, tmp_path):
    with pytest.raises(imukit.ImuError, match=r"unknown kind of table \(columns: a, b\)"):
        ip.figure(imukit.Table(["a", "b"], np.zeros((2, 2))))
    with pytest.raises(imukit.ImuError, match="overlay tables of one kind"):
        ip.figure(sim.truth, sim.imu)
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    with pytest.raises(imukit.ImuError, match="empty.csv: empty file"):
        ip.figure(empty)
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,pos_x_m,pos_y_m,yaw_rad\n0,1,2,0\n1,nan,2,0\n")
    with pytest.raises(imukit.ImuError, match="bad.csv"):
        ip.figure(bad)
    with pytest.raises(imukit.ImuError, match="no q_w column"):
        ip.animate(imukit.Table(["t_s", "pos_x_m", "pos_y_m", "pos_z_m"], np.zeros((3, 4))))
    with pytest.raises(imukit.ImuError, match="row 3: t_s = 0 does not increase"):
        t = sim.truth.values.copy()
        t[1, 0] = 0.0
        ip.animate(imukit.Table(sim.truth.columns, t))
    with pytest.raises(ValueError, match="body_m"):
        ip.animate(sim.truth, body_m=(0.1, -1.0, 0.1))


def test_ned_truth_is_drawn_east_north_up(tmp_path):
    sim = imukit.simulate({"nav_frame": "NED", "rate_hz": 50.0, "duration_s": 2.0,
                           "trajectory": {"type": "expression", "position_m": ["t", "2*t", "-3*t"],
                                          "attitude": "level"}})
    anim = ip.animate(sim.truth, nav_frame="NED", fps=5.0)
    path = anim._fig.axes[0].get_lines()[0].get_data_3d()  # the grey path
    t = sim.truth["t_s"]
    np.testing.assert_allclose(path[0], 2 * t)   # east = NED y
    np.testing.assert_allclose(path[1], t)       # north = NED x
    np.testing.assert_allclose(path[2], 3 * t)   # up = −NED z: the body climbs
    anim.save(tmp_path / "ned.gif", writer="pillow", fps=5)
    with pytest.raises(imukit.ImuError, match="nav_frame"):
        ip.animate(sim.truth, nav_frame="XYZ")


def test_orientation_outputs_and_their_errors_have_their_panels():
    t = np.arange(50) / 10.0
    e = np.column_stack([0.1 * t, np.zeros(50), np.zeros(50)])
    truth = imukit.truth_from_samples(t, np.zeros((50, 3)), euler_rad=e, nav_frame="NED")
    estimate = imukit.Table(["t_s", "q_w", "q_x", "q_y", "q_z", "yaw_rad", "pitch_rad", "roll_rad"],
                            np.column_stack([t, imukit.euler_to_quaternion(e + [0.01, 0, 0]), e + [0.01, 0, 0]]))
    errors, _ = imukit.compare(truth, estimate)
    assert imukit.plot.kind(estimate) == "orientation" and imukit.plot.kind(errors) == "errors"
    fig = imukit.plot.figure(estimate)
    assert [len(ax.get_lines()) for ax in fig.axes] == [3, 4]   # Euler angles; quaternion
    fig = imukit.plot.figure(errors)
    assert [len(ax.get_lines()) for ax in fig.axes] == [1, 3]   # quaternion distance; Euler errors
    np.testing.assert_allclose(fig.axes[1].get_lines()[0].get_ydata(), np.degrees(0.01), atol=1e-9)


def test_a_figure_takes_a_size_and_resolution_and_is_titled_with_its_tables_and_frame(sim):
    # The frame is the table's own (its description says ENU), named in the title.
    fig = ip.figure(sim.truth, size_in=(8.0, 5.0), dpi=150, labels=["truth"])
    assert tuple(fig.get_size_inches()) == (8.0, 5.0)
    assert fig.dpi == 150
    assert fig._suptitle.get_text() == "truth (truth) — ENU"
    # A plain array's frame is the argument's.
    plain = imukit.Table(sim.truth.columns, sim.truth.values)
    assert ip.figure(plain, nav_frame="NED", labels=["t"])._suptitle.get_text() == "t (truth) — NED"
