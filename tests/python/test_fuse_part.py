"""The filter's model apart from any scenario: `imukit fuse IMU GNSS --imu PART --gnss-*` and
`imukit.fuse(imu, gnss, imu_model=…)` give the numbers of the scenario route when they state the
same part and receiver, and refuse a bad part or accuracy by name."""
import subprocess

import numpy as np
import pytest

import imukit
from imukit import ImuError
from test_cli_vs_python import ROOT, imukit_bin

PART = ["--imu", "stim300", "--gnss-horizontal-accuracy-m", "1.5", "--gnss-vertical-accuracy-m", "3",
        "--gnss-velocity-accuracy-m-s", "0.1"]


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    """The car of examples/car_tunnel.toml with MATLAB's default GNSS noise model (what the
    part route assumes), simulated once."""
    tmp = tmp_path_factory.mktemp("fuse_part")
    text = (ROOT / "examples" / "car_tunnel.toml").read_text()
    scenario = tmp / "car.toml"
    scenario.write_text("\n".join(line for line in text.splitlines() if not line.startswith("decay_factor")))
    files = {name: tmp / f"{name}.csv" for name in ("imu", "truth", "gnss")}
    done = subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(files["imu"]),
                           "--truth", str(files["truth"]), "--gnss", str(files["gnss"]), "--quiet"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return tmp, scenario, files


def fuse(files, out, *extra):
    return subprocess.run([imukit_bin(), "fuse", str(files["imu"]), str(files["gnss"]), "--init", str(files["truth"]),
                           "--out", str(out), *extra], capture_output=True, text=True)


def test_a_part_and_its_receiver_give_the_scenario_routes_numbers(drive):
    tmp, scenario, files = drive
    by_scenario, by_part = tmp / "scenario.csv", tmp / "part.csv"
    for out, extra in [(by_scenario, ["--scenario", str(scenario)]), (by_part, PART)]:
        done = fuse(files, out, *extra)
        assert done.returncode == 0, done.stderr
    assert by_part.read_bytes() == by_scenario.read_bytes()
    imu, gnss, truth = (imukit.read(files[k]) for k in ("imu", "gnss", "truth"))
    python = imukit.fuse(imu, gnss, initial=truth, imu_model="stim300", gnss_horizontal_accuracy_m=1.5,
                         gnss_vertical_accuracy_m=3.0, gnss_velocity_accuracy_m_s=0.1)
    cli = imukit.read(by_part)
    for column in cli:
        np.testing.assert_array_equal(python[column], cli[column], err_msg=column)
    # The part as a parameter file (what `imukit presets` prints) is the same part.
    params = tmp / "stim300.toml"
    params.write_text(subprocess.run([imukit_bin(), "presets", "stim300"], capture_output=True, text=True,
                                     check=True).stdout)
    by_file = tmp / "file.csv"
    done = fuse(files, by_file, *(["--imu", str(params)] + PART[2:]))
    assert done.returncode == 0, done.stderr
    assert by_file.read_bytes() == by_scenario.read_bytes()


def test_a_bad_part_or_accuracy_is_refused_by_name(drive):
    tmp, scenario, files = drive
    out = tmp / "never.csv"
    done = fuse(files, out, "--imu", "stim301")
    assert done.returncode == 65 and "stim301" in done.stderr, done.stderr
    done = fuse(files, out, "--imu", "stim300", "--gnss-horizontal-accuracy-m", "-1")
    assert done.returncode == 65 and "--gnss-horizontal-accuracy-m" in done.stderr, done.stderr
    done = fuse(files, out, "--imu", "stim300", "--scenario", str(scenario))
    assert done.returncode == 2, done.stderr
    assert not out.exists()
    with pytest.raises(ValueError, match="scenario= .* or imu_model=.*not both"):
        imukit.fuse(imukit.read(files["imu"]), imukit.read(files["gnss"]), initial=imukit.read(files["truth"]),
                    scenario=str(scenario), imu_model="stim300")
    # The receiver's options are refused by Python's keyword, as the command line names its flag.
    for keyword, value in [("gnss_horizontal_accuracy_m", -1.0), ("gnss_decay_factor", 2.0),
                           ("gnss_latency_s", -0.5), ("gnss_lever_arm_m", [0.0, float("nan"), 0.0])]:
        with pytest.raises(ValueError) as e:
            imukit.fuse(imukit.read(files["imu"]), imukit.read(files["gnss"]),
                        initial=imukit.read(files["truth"]), imu_model="stim300", **{keyword: value})
        assert e.value.field == keyword, e.value
    done = fuse(files, out, "--imu", "stim300", "--gnss-decay-factor", "2")
    assert done.returncode == 65 and "--gnss-decay-factor" in done.stderr, done.stderr


def test_a_scenario_that_contradicts_the_datas_description_is_refused(drive):
    tmp, scenario, files = drive
    ned = tmp / "ned.toml"
    ned.write_text(scenario.read_text().replace('nav_frame = "ENU"', 'nav_frame = "NED"'))
    out = tmp / "never.csv"
    done = fuse(files, out, "--scenario", str(ned))
    assert done.returncode == 65, done.stderr
    assert f"--nav-frame: the scenario {ned} says NED, the description of {files['imu']} says ENU" in done.stderr
    # In Python alike: the tables read back say ENU, the scenario NED.
    with pytest.raises(ImuError, match="nav_frame: the scenario says NED, the description of the imu table says ENU"):
        imukit.fuse(imukit.read(files["imu"]), imukit.read(files["gnss"]), initial=imukit.read(files["truth"]),
                    scenario=ned)
    assert not out.exists()


def test_a_kalibr_file_is_a_part_of_its_four_figures(drive):
    """`--imu imu.yaml` (Kalibr's file, here as `imukit presets … --format kalibr` writes it):
    the filter of white noise and bias random walk alone, the same as the parameter file
    `imukit presets --params imu.yaml` prints; Python's `imu_model=` reads it alike."""
    tmp, _, files = drive
    kalibr = tmp / "imu.yaml"
    kalibr.write_text(subprocess.run([imukit_bin(), "presets", "stim300", "--format", "kalibr", "--rate-hz", "100"],
                                     capture_output=True, text=True, check=True).stdout)
    params = tmp / "kalibr_params.toml"
    params.write_text(subprocess.run([imukit_bin(), "presets", "--params", str(kalibr)],
                                     capture_output=True, text=True, check=True).stdout)
    assert "random_walk_rad_s_rt_hz = 1.327716e-7" in params.read_text()
    assert "bias_instability_rad_s = 0.0" in params.read_text()
    gnss = PART[2:]
    outs = []
    for model in (kalibr, params):
        out = tmp / f"fused-{model.suffix[1:]}.csv"
        done = fuse(files, out, "--imu", str(model), *gnss)
        assert done.returncode == 0, done.stderr
        outs.append(imukit.read(out))
    assert outs[0].columns == outs[1].columns and np.array_equal(outs[0].values, outs[1].values)
    fused = imukit.fuse(imukit.read(files["imu"]), imukit.read(files["gnss"]), initial=imukit.read(files["truth"]),
                        imu_model=str(kalibr), gnss_horizontal_accuracy_m=1.5, gnss_vertical_accuracy_m=3.0,
                        gnss_velocity_accuracy_m_s=0.1)
    assert np.array_equal(fused.values, outs[0].values)
    # A Kalibr file missing a figure is refused by file and key.
    kalibr.write_text("\n".join(l for l in kalibr.read_text().splitlines() if not l.startswith("gyroscope_random")))
    done = fuse(files, tmp / "bad.csv", "--imu", str(kalibr), *gnss)
    assert done.returncode == 65 and "imu.yaml" in done.stderr and "gyroscope_random_walk: missing" in done.stderr


def test_fixes_of_positions_only_update_the_position_alone(drive):
    """A fix table without velocity columns (a NavSatFix topic, an NMEA log without RMC): the
    filter updates on positions alone, its velocity's one-sigma the wider for it; the alignment
    that takes the heading from the fixes' velocity says why it cannot."""
    tmp, scenario, files = drive
    gnss = imukit.read(files["gnss"])
    positions = tmp / "positions.csv"
    imukit.Table(["t_s", "pos_x_m", "pos_y_m", "pos_z_m"],
                 gnss.values[:, [gnss.columns.index(c) for c in ("t_s", "pos_x_m", "pos_y_m", "pos_z_m")]]).write(positions)
    outs = {}
    for name, fixes in (("full", files["gnss"]), ("positions", positions)):
        out = tmp / f"fused-{name}.csv"
        done = subprocess.run([imukit_bin(), "fuse", str(files["imu"]), str(fixes), "--init", str(files["truth"]),
                               "--scenario", str(scenario), "--out", str(out)], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        outs[name] = imukit.read(out)
    truth = imukit.read(files["truth"])
    err = {n: imukit.compare(truth, o).summary for n, o in outs.items()}
    # Worse without velocities, yet a working solution: metres, not kilometres.
    assert err["full"]["position_rms_m"] <= err["positions"]["position_rms_m"] < 5.0, err
    assert outs["positions"]["vel_x_sigma_m_s"][-1] > outs["full"]["vel_x_sigma_m_s"][-1]
    done = subprocess.run([imukit_bin(), "fuse", str(files["imu"]), str(positions), "--align", "gnss",
                           "--scenario", str(scenario), "--out", str(tmp / "aligned.csv")], capture_output=True, text=True)
    assert done.returncode == 65 and "no velocity" in done.stderr, done.stderr


def test_each_fix_s_own_accuracy_weighs_it(drive):
    """Fixes that say they are poor (`horizontal_accuracy_m`, `vertical_accuracy_m` per fix, as a
    receiver's covariance gives them) are weighed as such: 20 s of fixes 30 m off, marked 1 km
    one-sigma, leave the estimate where the good fixes put it; unmarked, they pull it away."""
    tmp, scenario, files = drive
    gnss = imukit.read(files["gnss"])
    values = gnss.values.copy()
    bad = (gnss["t_s"] >= 60.0) & (gnss["t_s"] < 80.0)
    values[bad, gnss.columns.index("pos_y_m")] += 30.0
    h = np.where(bad, 1000.0, 1.5)
    v = np.where(bad, 1000.0, 3.0)
    paths = {"clean": files["gnss"], "marked": tmp / "marked.csv", "unmarked": tmp / "unmarked.csv"}
    imukit.Table(list(gnss.columns) + ["horizontal_accuracy_m", "vertical_accuracy_m"],
                 np.column_stack([values, h, v])).write(paths["marked"])
    imukit.Table(list(gnss.columns), values).write(paths["unmarked"])
    truth = imukit.read(files["truth"])
    worst = {}
    for name, path in paths.items():
        out = tmp / f"fused-{name}.csv"
        done = fuse({**files, "gnss": path}, out, "--scenario", str(scenario), "--no-gate")
        assert done.returncode == 0, done.stderr
        worst[name] = imukit.compare(truth, imukit.read(out)).summary["position_max_m"]
    assert worst["marked"] < 1.5 * worst["clean"] < 15.0 < worst["unmarked"], worst
    # An accuracy that is no accuracy is refused by its row.
    h[3] = -1.0
    imukit.Table(list(gnss.columns) + ["horizontal_accuracy_m"], np.column_stack([values, h])).write(paths["marked"])
    done = fuse({**files, "gnss": paths["marked"]}, tmp / "refused.csv", "--scenario", str(scenario))
    assert done.returncode == 65 and "row 5: the fix's accuracy must be positive" in done.stderr, done.stderr


def test_a_receiver_stated_as_arguments_fuses_as_the_scenario_does():
    # One meaning per number: car_tunnel.toml's [imu] and [gnss] stated as arguments give the
    # same estimate, column by column; left out, the decay factor is MATLAB's 0.999.
    scenario = ROOT / "examples" / "car_tunnel.toml"
    sim = imukit.simulate(str(scenario))
    by_scenario = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=str(scenario))
    stated = dict(imu_model="stim300", gnss_horizontal_accuracy_m=1.5, gnss_vertical_accuracy_m=3.0,
                  gnss_velocity_accuracy_m_s=0.1)
    by_arguments = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, gnss_decay_factor=0.0, **stated)
    assert list(by_scenario.columns) == list(by_arguments.columns)
    assert all(np.array_equal(by_scenario[c], by_arguments[c]) for c in by_scenario.columns)
    matlab = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, **stated)
    assert not np.array_equal(matlab["pos_x_sigma_m"], by_scenario["pos_x_sigma_m"])


def test_gnss_adaptive_is_the_same_switch_in_python(drive):
    """`--gnss-adaptive` and `gnss_adaptive=True` scale the fixes' noise alike (the scaling
    itself is tested in crates/imu-cli/tests/fuse_model.rs and crates/imukit/tests)."""
    tmp, _, files = drive
    out = tmp / "adaptive.csv"
    done = fuse(files, out, *PART, "--gnss-adaptive")
    assert done.returncode == 0, done.stderr
    imu, gnss, truth = (imukit.read(files[k]) for k in ("imu", "gnss", "truth"))
    python = imukit.fuse(imu, gnss, initial=truth, imu_model="stim300", gnss_horizontal_accuracy_m=1.5,
                         gnss_vertical_accuracy_m=3.0, gnss_velocity_accuracy_m_s=0.1, gnss_adaptive=True)
    cli = imukit.read(out)
    for column in cli:
        np.testing.assert_array_equal(python[column], cli[column], err_msg=column)
