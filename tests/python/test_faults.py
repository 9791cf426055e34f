"""Faults from Python: Ctrl-C in ``monte_carlo(out=…)`` leaves every file whole or absent, and
inputs that once panicked or wrote files imukit cannot read back are refused with ``ImuError``."""
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import imukit
from imukit import ImuError

RUNS = r"""
import sys, imukit
print("started", flush=True)
imukit.monte_carlo({"rate_hz": 1000.0, "duration_s": 60.0, "trajectory": {"type": "builtin", "name": "figure8"},
                    "imu": {"preset": "mpu-6050", "seed": 5}}, runs=400, out=sys.argv[1], threads=2)
"""


def test_ctrl_c_in_monte_carlo_leaves_whole_files_or_none(tmp_path):
    out = tmp_path / "mc" / "imu.csv"
    proc = subprocess.Popen([sys.executable, "-c", RUNS, str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout.readline().strip() == b"started"
    # Interrupted once the first runs have written their files, with others under way.
    deadline = time.monotonic() + 60
    while not any(f.suffix == ".csv" for f in out.parent.glob("*.csv")) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert proc.poll() is None, "the runs ended before the interrupt"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert b"KeyboardInterrupt" in err, err[-500:]
    files = sorted((tmp_path / "mc").iterdir())
    assert not [f for f in files if "imukit-partial" in f.name]
    assert 0 < len(files) < 400, "the interrupt stopped nothing"
    for f in files:
        table = imukit.read(f)
        assert table.values.shape == (60001, 10), f.name


def test_a_fusion_of_no_imu_rows_is_refused_not_a_panic():
    scenario = {"rate_hz": 10.0, "duration_s": 10.0,
                "trajectory": {"type": "expression", "position_m": ["5*t", "0", "0"], "attitude": "tangent"},
                "imu": {"kind": "accel-gyro"}, "gnss": {"rate_hz": 1.0}}
    sim = imukit.simulate(scenario)
    empty = imukit.Table(list(sim.imu.columns), np.zeros((0, len(sim.imu.columns))))
    with pytest.raises(ImuError, match="0 rows: fusion needs at least two samples"):
        imukit.fuse(empty, sim.gnss, initial=sim.truth, scenario=scenario)


@pytest.mark.parametrize("name, message", [("x" * 100_000, "a name of 100000 bytes"), ("a,b", "holds ','"),
                                           ("t_s", "the name of column 1 too")])
@pytest.mark.parametrize("ext", ["csv", "parquet", "npy", "npz"])
def test_column_names_a_file_could_not_carry_back_are_refused(tmp_path, name, message, ext):
    table = imukit.Table(["t_s", name], np.ones((3, 2)))
    with pytest.raises(ImuError, match=message):
        table.write(tmp_path / f"o.{ext}")
    assert list(tmp_path.iterdir()) == []
