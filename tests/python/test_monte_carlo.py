"""Monte Carlo: the same seeds give the same runs on 1 thread, N threads, a Dask cluster of two
worker processes, and the CLI's `--runs` files."""
import subprocess

import numpy as np
import pytest

import imukit
from test_cli_vs_python import ROOT, imukit_bin

SCENARIO = {
    "rate_hz": 200.0, "duration_s": 2.0,
    "trajectory": {"type": "builtin", "name": "figure8"},
    "imu": {"preset": "mpu-6050", "seed": 42, "temperature_c": 35.0,
            "perturbations": [{"parameter": "accelerometer.constant_bias_m_s2",
                               "distribution": "normal", "mean": 0.0, "std": 0.05}]},
}


def test_runs_do_not_depend_on_threads_and_equal_single_runs():
    one = imukit.monte_carlo(SCENARIO, runs=6, threads=1)
    many = imukit.monte_carlo(SCENARIO, runs=6, threads=4)
    assert one.imu.shape == (6, 401, 10)
    assert np.array_equal(one.imu, many.imu)
    for r in (0, 5):
        assert np.array_equal(one.imu[r], imukit.simulate(SCENARIO, run=r).imu.values)
    # Runs differ from each other (noise and perturbations drawn per run) …
    assert not np.array_equal(one.imu[0], one.imu[1])
    # … and a later batch continues the same sequence.
    tail = imukit.monte_carlo(SCENARIO, runs=2, first_run=4)
    assert np.array_equal(tail.imu, one.imu[4:])
    assert list(tail.runs) == [4, 5]


def test_runs_write_their_readings_into_the_gathered_array():
    # What monte_carlo does locally: the shape first, then each run into its slot.
    from imukit import _core
    rows, columns, by_run = _core.simulation_shape(SCENARIO, format="dict", origin="test", base_dir=".")
    whole = imukit.simulate(SCENARIO, run=3)
    assert (rows, tuple(columns)) == (whole.imu.values.shape[0], whole.imu.columns)
    assert by_run == []  # no random vibration: the truth is the same in every run
    gathered = np.full((2, rows, len(columns)), np.nan)
    _, (names, filled, description), *_ = _core.simulate_dict(SCENARIO, run=3, truth=False, imu_out=gathered[1])
    assert description["kind"] == "readings"
    assert names == list(columns) and np.shares_memory(filled, gathered)
    assert np.array_equal(gathered[1], whole.imu.values) and np.isnan(gathered[0]).all()
    with pytest.raises(ValueError, match=r"imu_out has shape \[400, 10\], the run makes \[401, 10\]"):
        _core.simulate_dict(SCENARIO, run=3, imu_out=gathered[0, 1:])


def test_dask_cluster_gives_the_local_results_bit_for_bit(tmp_path):
    distributed = pytest.importorskip("distributed")
    local = imukit.monte_carlo(SCENARIO, runs=4)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = imukit.monte_carlo(SCENARIO, runs=4, client=client)
        workers = {w for w in client.run(lambda: 1)}
        paths = imukit.monte_carlo(SCENARIO, runs=4, client=client, out=tmp_path / "dask" / "imu.csv")
    assert len(workers) == 2
    assert np.array_equal(local.imu, remote.imu)
    assert np.array_equal(local.truth.values, remote.truth.values)
    assert [p.rsplit("/", 1)[1] for p in paths] == [f"imu_run000{r}.csv" for r in range(4)]
    for r, p in enumerate(paths):
        assert np.array_equal(imukit.read_csv(p).values, local.imu[r])


def test_written_runs_equal_the_cli_files_byte_for_byte(tmp_path):
    import json
    scenario = tmp_path / "mc.json"
    scenario.write_text(json.dumps(SCENARIO))
    cli_out = tmp_path / "cli" / "imu.csv"
    cli_out.parent.mkdir()
    subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(cli_out), "--runs", "3"],
                   check=True, capture_output=True)
    paths = imukit.monte_carlo(scenario, runs=3, out=tmp_path / "py" / "imu.csv")
    for r, p in enumerate(paths):
        cli_file = tmp_path / "cli" / f"imu_run000{r}.csv"
        assert cli_file.read_bytes() == open(p, "rb").read()


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="runs must be a positive integer"):
        imukit.monte_carlo(SCENARIO, runs=0)
    with pytest.raises(imukit.ImuError, match="no-such-part"):
        imukit.monte_carlo({"imu": {"preset": "no-such-part"}, "trajectory": {"type": "builtin", "name": "static"}},
                           runs=2)
    with pytest.raises(imukit.ImuError, match="missing.toml"):
        imukit.monte_carlo(ROOT / "missing.toml", runs=2)


STUDY = "scenario = \"{scenario}\"\npresets = [\"stim300\", \"hg1700\"]\nruns = 4\n"


def test_a_study_from_python_equals_the_cli_on_any_threads_and_on_dask(tmp_path):
    # The outage study: imukit.study on 1 and 3 threads and on a Dask cluster of two worker
    # processes gives the CLI's table bit for bit.
    study = tmp_path / "study.toml"
    study.write_text(STUDY.format(scenario=(ROOT / "examples" / "car_tunnel.toml").as_posix()))
    one = imukit.study(study, threads=1)
    three = imukit.study(study, threads=3)
    assert np.array_equal(one.table.values, three.table.values)
    assert [s.preset for s in one.summaries] == ["stim300", "hg1700"]
    assert all(s.completed == 4 and s.diverged == 0 for s in one.summaries)
    assert one.summaries[0].rms_error_m == pytest.approx(
        np.sqrt(np.mean(one.table["stim300_rms_error_m"][-1] ** 2)))
    out = tmp_path / "study.csv"
    subprocess.run([imukit_bin(), "study", str(study), "--out", str(out)], check=True, capture_output=True)
    cli = imukit.read(out)
    assert cli.columns == one.table.columns and cli.description["kind"] == "study"
    assert np.array_equal(cli.values, one.table.values)
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = imukit.study(study, client=client)
    assert np.array_equal(remote.table.values, one.table.values)
    with pytest.raises(imukit.ImuError, match="runs"):
        (tmp_path / "bad.toml").write_text(STUDY.format(scenario="x.toml").replace("runs = 4", "runs = 1"))
        imukit.study(tmp_path / "bad.toml")
