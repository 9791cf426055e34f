"""The outage study from Python: which IMU bridges a GNSS outage (``imukit study``), with its runs
on this machine's cores or on a Dask cluster.

Run ``r`` of a preset draws its noise from ``(seed, r)`` only, so the table does not depend on
where the runs ran or how many threads or workers there were: the same as ``imukit study``.
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Tuple, Any, List, Optional, Union

from . import _core
from ._warning import _emit
from ._table import Table, _table


@dataclass(frozen=True)
class PresetSummary:
    """One preset at the last IMU sample of the first outage: the RMS over completed runs of the
    horizontal error and of the filter's horizontal one-sigma (``None`` with fewer than two
    completed runs), the runs completed and diverged, that sample's time into the outage, and the
    times the filter lost the fixes and was reset to them over the completed runs (its one-sigma
    then understates its error). With ``smooth = true`` in the study, ``smoothed_rms_error_m``
    is the smoothed estimate's RMS error at the same sample and the largest along the outage."""

    preset: str
    completed: int
    diverged: int
    rms_error_m: Optional[float]
    sigma_m: Optional[float]
    outage_s: float
    resets: int
    smoothed_rms_error_m: Optional[Tuple[float, float]] = None


@dataclass(frozen=True)
class StudyResult:
    """The study's table (``t_s`` into the outage, ``<preset>_rms_error_m``, ``<preset>_sigma_m``)
    and one :class:`PresetSummary` per preset."""

    table: Table
    summaries: List[PresetSummary]


def _run(path: str, case: int, run: int):
    """One run (a thread's job or a Dask task): plain lists, as the summary takes them."""
    t, error, sigma, diverged, resets, smoothed = _core.study_run(path, case, run)
    if diverged is not None:
        return None, None, None, diverged, 0, None
    return t.tolist(), error.tolist(), sigma.tolist(), None, resets, smoothed.tolist()


def study(path: Union[str, os.PathLike], *, client: Any = None, threads: Optional[int] = None) -> StudyResult:
    """Runs the outage study in the file ``path`` (``scenario = "…"``, ``presets = […]``,
    ``runs = N`` …, as ``imukit study`` reads it) and returns its table and summaries.

    Without a ``client`` the runs share this machine's cores (``threads``, default all; imukit
    releases the GIL). With a ``dask.distributed.Client`` every run is a Dask task; the workers
    need imukit installed and the study and scenario files at the same path. Presets not
    described alike (one gives a turn-on bias, a bias drift or scale-factor and misalignment
    errors that another leaves out, taken as zero) are named in an :class:`ImuWarning` first.
    """
    where = str(Path(path).resolve())
    presets, runs = _core.study_plan(where)
    _emit(f"the presets are not described alike: {line}" for line in _core.study_undescribed(where))
    jobs = [(case, run) for case in range(len(presets)) for run in range(runs)]
    cases = [c for c, _ in jobs]
    ids = [r for _, r in jobs]
    if client is None:
        with ThreadPoolExecutor(max_workers=threads or os.cpu_count() or 1) as pool:
            flat = list(pool.map(_run, [where] * len(jobs), cases, ids))
    else:
        flat = client.gather(client.map(_run, [where] * len(jobs), cases, ids, pure=False))
    outcomes = [flat[c * runs:(c + 1) * runs] for c in range(len(presets))]
    table, summaries = _core.study_summarise(where, outcomes)
    return StudyResult(table=_table(table),
                       summaries=[PresetSummary(*s) for s in summaries])
