"""The CLI and the Python package give bit-identical numbers for the same scenario."""
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import imukit

_D = imukit._core.DEFAULTS

ROOT = Path(__file__).resolve().parents[2]


def imukit_bin() -> str:
    explicit = os.environ.get("IMUKIT_BIN")
    if explicit:
        return explicit
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "imukit"
        if p.exists():
            return str(p)
    found = shutil.which("imukit")
    if found is None:
        pytest.fail("the imukit binary was not found: build it (cargo build -p imu-cli) or set IMUKIT_BIN")
    return found


def read_csv(path: Path):
    # The description line (`# imukit: {...}`) first, when the table has one.
    lines = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    header = lines[0].split(",")
    # float() parses the shortest round-trip text back to the same double.
    rows = [[float(x) for x in line.split(",")] for line in lines[1:]]
    return header, np.array(rows)


SCENARIOS = {
    "expression.toml": """
rate_hz = 200.0
duration_s = 1.0
nav_frame = "NED"
[trajectory]
type = "expression"
constants = { f = 1.0 }
position_m = ["0.8*cos(2*pi*f*t)", "0.8*sin(2*pi*f*t)", "0.3*cos(2*pi*f*t)"]
attitude = "tangent"
[imu]
lever_arm_m = [-0.075, -0.075, 0.025]
accel_sign = "matlab"
""",
    "builtin.toml": '[trajectory]\ntype = "builtin"\nname = "rounded-rectangle"\n',
    "samples.toml": '[trajectory]\ntype = "samples"\nfile = "truth_in.csv"\norder = 4\n',
    "noisy.toml": """
rate_hz = 100.0
duration_s = 20.0
[trajectory]
type = "builtin"
name = "figure8"
[imu]
seed = 42
profile = "matlab"
temperature_c = 31.5
[imu.accelerometer]
noise_density_m_s2_per_rt_hz = 0.003
bias_instability_m_s2 = 0.001
random_walk_m_s2_rt_hz = 0.0001
resolution_m_s2 = 0.0005
[imu.gyroscope]
noise_density_rad_s_per_rt_hz = 1e-4
bias_instability_rad_s = 1e-5
bias_instability_flicker_tau_s = [1, 100]
acceleration_bias_rad_s_per_m_s2 = 1e-4
[imu.magnetometer]
noise_density_ut_per_rt_hz = 0.1
""",
}


@pytest.mark.parametrize("name", sorted(SCENARIOS))
def test_cli_and_python_are_bit_identical(tmp_path, name):
    # A samples file made by the CLI itself from a built-in.
    src = tmp_path / "src.toml"
    src.write_text('[trajectory]\ntype = "builtin"\nname = "tilted-circle"\n')
    subprocess.run([imukit_bin(), "simulate", str(src), "--out", str(tmp_path / "x.csv"),
                    "--truth", str(tmp_path / "truth_in.csv")], check=True, capture_output=True)
    scenario = tmp_path / name
    scenario.write_text(SCENARIOS[name])
    out, truth = tmp_path / "imu.csv", tmp_path / "truth.csv"
    subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(out), "--truth", str(truth)],
                   check=True, capture_output=True)
    sim = imukit.simulate(scenario)
    for path, table in [(out, sim.imu), (truth, sim.truth)]:
        header, values = read_csv(path)
        assert header == list(table.columns)
        assert values.shape == table.values.shape
        assert np.array_equal(values.view(np.uint64), table.values.view(np.uint64)), path.name


def test_a_64_bit_seed_from_a_dict_gives_the_clis_numbers(tmp_path):
    """Any u64 seed (e.g. `secrets.randbits(64)`) works from a Python dict as from the file, bit
    for bit; one a u64 cannot hold is refused naming `imu.seed`."""
    import json
    import tomllib

    scenario = tomllib.loads(SCENARIOS["noisy.toml"])
    scenario["duration_s"] = 2.0
    scenario["imu"]["seed"] = 2**64 - 1
    path = tmp_path / "seeded.json"
    path.write_text(json.dumps(scenario))
    out = tmp_path / "imu.csv"
    subprocess.run([imukit_bin(), "simulate", str(path), "--out", str(out)], check=True, capture_output=True)
    header, values = read_csv(out)
    sim = imukit.simulate(scenario)
    assert header == list(sim.imu.columns)
    assert np.array_equal(values.view(np.uint64), sim.imu.values.view(np.uint64))
    other = imukit.simulate({**scenario, "imu": {**scenario["imu"], "seed": 2**63 + 5}})
    assert not np.array_equal(other.imu.values, sim.imu.values)
    with pytest.raises(imukit.ImuError, match=r"imu\.seed: .*expected u64") as e:
        imukit.simulate({**scenario, "imu": {**scenario["imu"], "seed": 2**64}})
    assert e.value.field == "imu.seed"


def test_cli_demo_runs_with_no_arguments(tmp_path):
    result = subprocess.run([imukit_bin(), "demo"], cwd=tmp_path, check=True, capture_output=True, text=True)
    assert "imukit-demo" in result.stdout
    header, values = read_csv(tmp_path / "imukit-demo" / "imu.csv")
    sim = imukit.simulate(tmp_path / "imukit-demo" / "scenario.toml")
    assert np.array_equal(values, sim.imu.values)


def test_monte_carlo_runs_match_python_runs(tmp_path):
    scenario = tmp_path / "noisy.toml"
    scenario.write_text(SCENARIOS["noisy.toml"])
    out = tmp_path / "mc" / "imu.csv"
    out.parent.mkdir()
    subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(out), "--runs", "3"], check=True, capture_output=True)
    for r in range(3):
        header, values = read_csv(out.parent / f"imu_run{r:04d}.csv")
        sim = imukit.simulate(scenario, run=r)
        assert np.array_equal(values.view(np.uint64), sim.imu.values.view(np.uint64)), r
    a, b = imukit.simulate(scenario, run=0), imukit.simulate(scenario, run=1)
    assert not np.array_equal(a.imu.values, b.imu.values)


def test_cli_allan_reads_what_python_computes(tmp_path):
    scenario = tmp_path / "static.toml"
    scenario.write_text('rate_hz = 100.0\nduration_s = 600.0\n[trajectory]\ntype = "builtin"\nname = "static"\n'
                        '[imu]\nseed = 3\n[imu.gyroscope]\nnoise_density_rad_s_per_rt_hz = 2e-3\n')
    imu_csv, adev_csv = tmp_path / "imu.csv", tmp_path / "adev.csv"
    subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(imu_csv)], check=True, capture_output=True)
    svg = tmp_path / "adev.svg"
    result = subprocess.run([imukit_bin(), "allan", str(imu_csv), "--column", "gyro_z_rad_s", "--out", str(adev_csv),
                             "--plot", str(svg)], check=True, capture_output=True, text=True)
    assert "gyro_z_rad_s" in result.stdout
    figure = svg.read_text()
    assert figure.lstrip().startswith("<svg") and figure.rstrip().endswith("</svg>")
    assert "Allan deviation" in figure and "gyro_z_rad_s" in figure
    assert figure.count("<polyline") >= 2  # the curve and at least one fitted line
    assert not list(tmp_path.glob("*.imukit-partial"))
    header, values = read_csv(adev_csv)
    assert header == ["tau_s", "adev_gyro_z_rad_s"]
    sim = imukit.simulate(scenario)
    tau, adev = imukit.allan_deviation(sim.imu["gyro_z_rad_s"], 100.0)
    np.testing.assert_allclose(values[:, 0], tau, rtol=1e-12)
    np.testing.assert_allclose(values[:, 1], adev, rtol=1e-12)
    n = imukit.identify(sim.imu, columns=["gyro_z_rad_s"]).term("gyro_z_rad_s", "N")
    assert n["lower"] <= 2e-3 <= n["upper"], n


ORIENT_SCENARIO = """
[trajectory]
type = "builtin"
name = "platform-turn"

[imu]
kind = "accel-gyro-mag"
profile = "matlab"
seed = 3

[imu.accelerometer]
NoiseDensity = 0.0012361
ConstantBias = 0.05

[imu.gyroscope]
NoiseDensity = 8.7266e-05
ConstantBias = [0.01, -0.02, 0.005]

[imu.magnetometer]
NoiseDensity = 0.06
"""

PYTHON_FILTERS = {
    "imufilter": lambda a, g, m, **kw: imukit.ImuFilter(100, **kw)(a, g),
    "ahrsfilter": lambda a, g, m, **kw: imukit.AhrsFilter(100, **kw)(a, g, m),
    "ecompass": lambda a, g, m, **kw: imukit.ecompass(a, m, **kw),
    "madgwick": lambda a, g, m, **kw: imukit.MadgwickFilter(100, has_magnetometer=True, **kw)(a, g, m),
    "mahony": lambda a, g, m, **kw: imukit.MahonyFilter(100, has_magnetometer=True, **kw)(a, g, m),
    "complementary": lambda a, g, m, **kw: imukit.ComplementaryFilter(100, **kw)(a, g, m),
}


@pytest.mark.parametrize("conventions", [None, "matlab"])
@pytest.mark.parametrize("filter_name", sorted(PYTHON_FILTERS))
def test_cli_orient_equals_the_python_filters(tmp_path, filter_name, conventions):
    """`imukit orient` on the turning platform (noisy, biased gyroscope) gives the Python filter's
    numbers bit for bit, with the defaults of both (imukit's conventions) and with MATLAB's
    asked for, and `imukit compare` reads the orientation output back."""
    scenario = tmp_path / "platform.toml"
    scenario.write_text(ORIENT_SCENARIO)
    imu_csv, truth_csv, out = tmp_path / "imu.csv", tmp_path / "truth.csv", tmp_path / "orient.csv"

    def run(*args):
        return subprocess.run([imukit_bin(), *args], check=True, capture_output=True, text=True)

    run("simulate", str(scenario), "--out", str(imu_csv), "--truth", str(truth_csv))
    asked = [] if conventions is None else ["--conventions", conventions]
    run("orient", str(imu_csv), "--filter", filter_name, *asked, "--param", "SampleRate=100", "--out", str(out))
    header, rows = read_csv(out)
    assert header == ["t_s", "q_w", "q_x", "q_y", "q_z", "yaw_rad", "pitch_rad", "roll_rad"]
    imu = imukit.read_csv(imu_csv)
    a, g, m = (np.column_stack([imu[f"{s}_{x}_{u}"] for x in "xyz"])
               for s, u in (("accel", "m_s2"), ("gyro", "rad_s"), ("mag", "ut")))
    # The readings say they are NED with MATLAB's sign (the scenario's profile): the command takes
    # that from the file whatever the conventions, the numbers of Python's filters told so.
    np.testing.assert_array_equal(rows[:, 1:5], PYTHON_FILTERS[filter_name](a, g, m, conventions="matlab"))
    report = run("compare", str(truth_csv), str(out)).stdout
    assert "attitude" in report and "position" not in report
    # Without the description (another program's file) the conventions decide, as in Python.
    bare = tmp_path / "bare.csv"
    bare.write_text("".join(line for line in imu_csv.read_text().splitlines(keepends=True)
                            if not line.startswith("#")))
    run("orient", str(bare), "--filter", filter_name, *asked, "--param", "SampleRate=100", "--out", str(out))
    header, rows = read_csv(out)
    np.testing.assert_array_equal(rows[:, 1:5], PYTHON_FILTERS[filter_name](a, g, m, conventions=conventions))
    if conventions is None:  # an ENU estimate against the NED truth: refused, not compared
        refused = subprocess.run([imukit_bin(), "compare", str(truth_csv), str(out)], capture_output=True, text=True)
        assert refused.returncode == 65 and "says NED" in refused.stderr and "says ENU" in refused.stderr


def test_one_version_for_the_package_the_command_and_the_workspace():
    import tomllib

    workspace = tomllib.loads((ROOT / "Cargo.toml").read_text())["workspace"]["package"]["version"]
    printed = subprocess.run([imukit_bin(), "--version"], capture_output=True, text=True, check=True).stdout
    assert imukit.__version__ == workspace
    assert printed.split() == ["imukit", workspace]


def cli_defaults(command: str) -> dict:
    """The `[default: …]` of each flag in `imukit COMMAND --help`."""
    import re

    text = subprocess.run([imukit_bin(), command, "--help"], capture_output=True, text=True, check=True).stdout
    blocks = re.split(r"\n\s+(?=--[a-z])", text)
    out = {}
    for b in blocks:
        flag = re.match(r"--([a-z0-9-]+)", b)
        default = re.search(r"\[default: ([^\]]+)\]", b)
        if flag and default:
            out[flag.group(1).replace("-", "_")] = default.group(1)
    return out


def test_python_and_the_command_line_start_from_the_same_defaults():
    import inspect

    cli = cli_defaults("integrate")
    py = inspect.signature(imukit.strapdown).parameters
    shared = ["nav_frame", "accel_sign", "earth", "vertical", "earth_gravity", "substeps",
              "baro_time_constant_s", "gravity_m_s2"]
    described = {"nav_frame", "accel_sign", "earth", "earth_gravity", "gravity_m_s2"}
    for name in shared:
        want = py[name].default
        got = cli[name]
        if name in described:
            # Taken from the tables' descriptions first (docs/formats.md), else the default: in
            # Python the argument left out (None), on the command line the flag.
            assert want is None, (name, want)
            assert got.startswith("what the input files' descriptions say, else "), (name, got)
            got = got.rsplit("else ", 1)[1].removeprefix("the conventions' (").rstrip(")")
            want = _D[name]
        assert (float(got) == want) if isinstance(want, (int, float)) else (got == want), (name, got, want)
    # The scheme: one default for 3D (`auto`), one for planar (`trapezoid`), named by the library.
    assert py["scheme"].default == imukit._core.DEFAULTS["scheme"] == "auto"
    assert inspect.signature(imukit.planar_dead_reckon).parameters["scheme"].default == "trapezoid"
    orient = cli_defaults("orient")
    assert orient["conventions"] == imukit._core.DEFAULTS["conventions"] == "imukit"
    assert orient["filter"] == imukit._core.DEFAULTS["filter"]
    # The orientation filters' frame and sign, unless told, are the conventions': ENU.
    assert imukit.ImuFilter(100.0).reference_frame == _D["nav_frame"] == "ENU"
    assert cli["nav_frame"].endswith("else the conventions' (ENU)")
