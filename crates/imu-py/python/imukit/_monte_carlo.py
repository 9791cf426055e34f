"""Monte Carlo runs of a scenario, on this machine's cores or on a Dask cluster.

Run ``r`` draws its sensor noise and perturbations from ``(seed, r)`` only, so a run's numbers do
not depend on where it ran, on how many threads or workers there were, or on which other runs were
made: the same as ``imukit simulate --runs`` (file ``r`` of the CLI equals run ``r`` here, bit for
bit).
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, List, Mapping, Optional, Tuple, Union, overload

import numpy as np

from . import _core
from ._core import ImuError
from ._warning import _emit


@dataclass(frozen=True, repr=False)
class MonteCarlo:
    """Gathered Monte Carlo results: ``imu[k]`` is run ``runs[k]`` with columns ``columns``
    (shape (runs, samples, columns)); ``truth`` is common to every run (the columns that differ
    by run, what a random vibration did, are left out: ``imukit.simulate(scenario, run=k)`` has
    run k's), and so is ``description``, what every run's readings hold
    (:attr:`imukit.Table.description`)."""

    runs: np.ndarray
    columns: tuple
    imu: np.ndarray
    truth: Any  # imukit.Table
    description: Any = None  # a mapping

    def run(self, k: int) -> Any:
        """Run ``runs[k]``'s readings as an :class:`imukit.Table`, with their description."""
        from ._table import Table

        return Table(self.columns, self.imu[k], self.description)

    def __repr__(self) -> str:
        n, samples, columns = self.imu.shape
        ids = f"{self.runs[0]}" if n == 1 else f"{self.runs[0]}…{self.runs[-1]}"
        return (f"MonteCarlo({n} runs ({ids}) × {samples} samples × {columns} columns; "
                f"truth={self.truth!r})")


@overload
def monte_carlo(scenario: Union[str, os.PathLike, Mapping[str, Any]], runs: int, *, client: Any = None,
                out: None = None, first_run: int = 0, threads: Optional[int] = None) -> MonteCarlo: ...


@overload
def monte_carlo(scenario: Union[str, os.PathLike, Mapping[str, Any]], runs: int, *, client: Any = None,
                out: Union[str, os.PathLike], first_run: int = 0, threads: Optional[int] = None) -> List[str]: ...


def _scenario_text(scenario: Union[str, os.PathLike, Mapping]) -> Tuple[Any, str, str, str]:
    """(text or dict, format, origin, base_dir): what a worker needs, without reading files
    itself."""
    if isinstance(scenario, Mapping):
        return dict(scenario), "dict", "scenario dict", os.getcwd()
    path = Path(scenario)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise ImuError(f"{path}: {e.strerror or e}") from None
    fmt = "json" if path.suffix.lower() == ".json" else "toml"
    return text, fmt, str(path), str(path.parent.resolve())


def _run(spec: Tuple[Any, str, str, str], run: int, out: Optional[str], runs: int, with_truth: bool,
         imu_out: Optional[np.ndarray] = None):
    """One run (a Dask task or a thread's job): the IMU table (written into ``imu_out`` when
    given: its slot of the gathered array), or the path it was written to."""
    text, fmt, origin, base_dir = spec
    # The runs are what goes in parallel: each keeps to the one thread it is given.
    # The truth is the same in every run: it is tabulated for the one that returns it.
    keep = with_truth and out is None
    if fmt == "dict":
        truth, imu, *_, notes = _core.simulate_dict(text, origin=origin, base_dir=base_dir, run=run, threads=1,
                                                    truth=keep, imu_out=imu_out)
    else:
        truth, imu, *_, notes = _core.simulate_text(
            text, format=fmt, origin=origin, base_dir=base_dir, run=run, threads=1, truth=keep,
            imu_out=imu_out,
        )
    if with_truth:  # the first run speaks for all (warnings are about the scenario and the part)
        _emit(notes, stacklevel=2)
    if out is None:
        return imu, truth
    path = _core.run_path(out, run, runs)
    _core.write_run(path, list(imu[0]), np.ascontiguousarray(imu[1]), text, format=fmt, origin=origin,
                    base_dir=base_dir)
    return path, None


def monte_carlo(
    scenario: Union[str, os.PathLike, Mapping[str, Any]],
    runs: int,
    *,
    client: Any = None,
    out: Optional[Union[str, os.PathLike]] = None,
    first_run: int = 0,
    threads: Optional[int] = None,
) -> Union[MonteCarlo, List[str]]:
    """Runs ``runs`` Monte Carlo runs (``first_run`` … ``first_run + runs − 1``) of a scenario (a
    TOML/JSON path or a dict, as for :func:`imukit.simulate`).

    Without a ``client`` the runs share this machine's cores (``threads``, default all; imukit
    releases the GIL). With a ``dask.distributed.Client`` every run is a Dask task on the cluster;
    the workers need imukit installed, and any file the scenario refers to (a samples CSV, a
    parameter file) at the same path.

    Returns a :class:`MonteCarlo` (the IMU readings of every run in one array, which the runs
    write into in place on this machine's cores, and the truth), or,
    with ``out="dir/imu.csv"``, writes each run where it ran as ``dir/imu_run0007.csv`` (the
    CLI's names) and returns the paths. Interrupted (Ctrl-C), it lets the runs under way finish
    their files, starts no other and raises ``KeyboardInterrupt``: no file is left partial.

    >>> mc = monte_carlo({"trajectory": {"type": "builtin", "name": "static"}, "duration_s": 0.1,
    ...                   "imu": {"preset": "mpu-6050", "seed": 1}}, runs=3)
    >>> mc.imu.shape
    (3, 11, 10)
    """
    if not isinstance(runs, int) or runs < 1:
        raise ValueError(f"runs must be a positive integer, got {runs!r}")
    if not isinstance(first_run, int) or first_run < 0:
        raise ValueError(f"first_run must be a non-negative integer, got {first_run!r}")
    spec = _scenario_text(scenario)
    ids = list(range(first_run, first_run + runs))
    total = first_run + runs
    target = None if out is None else os.fspath(out)
    if target is not None:
        Path(target).parent.mkdir(parents=True, exist_ok=True)
    with_truth = [k == 0 for k in range(runs)]
    slots: List[Optional[np.ndarray]] = [None] * runs
    text, fmt, origin, base_dir = spec
    rows, imu_columns, by_run = _core.simulation_shape(text, format=fmt, origin=origin, base_dir=base_dir)
    if client is None and target is None:
        # Each run writes its readings straight into its slot of the gathered array: no copy,
        # and no second array of every run's readings at the end.
        gathered = np.empty((runs, rows, len(imu_columns)))
        slots = list(gathered)
    if client is None:
        pool = ThreadPoolExecutor(max_workers=threads or os.cpu_count() or 1)
        try:
            results = list(pool.map(_run, [spec] * runs, ids, [target] * runs, [total] * runs, with_truth, slots))
        finally:
            # On Ctrl-C (KeyboardInterrupt) the runs not started are dropped and those under way
            # finish: each file is whole or absent, never partial.
            pool.shutdown(wait=True, cancel_futures=True)
    else:
        futures = client.map(_run, [spec] * runs, ids, [target] * runs, [total] * runs, with_truth, pure=False)
        results = client.gather(futures)
    if target is not None:
        return [path for path, _ in results]
    from . import Table

    columns, _, description = results[0][0]
    imu = gathered if client is None else np.stack([values for (_, values, _), _ in results])
    # The first run kept its truth table; what differs by run (random vibration) is left out.
    truth = Table(*results[0][1])
    if by_run:
        kept = [c for c in truth.columns if c not in by_run]
        truth = Table(kept, truth.values[:, [truth.columns.index(c) for c in kept]], truth.description)
    return MonteCarlo(runs=np.array(ids), columns=tuple(columns), imu=imu, truth=truth,
                      description=description)
