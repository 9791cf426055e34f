"""The :class:`Table` every result comes back as, and :class:`Simulation`."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterator, Optional, Sequence

import numpy as np


class Table:
    """Named columns over a 2-D float64 array (one row per sample).

    ``table["t_s"]`` is a column (a read-only view), ``table.values`` the whole array,
    ``table.columns`` the names in order, ``len(table)`` the number of rows.
    """

    def __init__(self, columns: Sequence[str], values: np.ndarray) -> None:
        values = np.asarray(values, dtype=np.float64)
        if values.ndim != 2 or values.shape[1] != len(columns):
            raise ValueError(f"values must have shape (N, {len(columns)}), got {values.shape}")
        values.setflags(write=False)
        self.columns: tuple = tuple(columns)
        self.values: np.ndarray = values
        self._index = {c: k for k, c in enumerate(self.columns)}

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.values[:, self._index[name]]
        except KeyError:
            raise KeyError(f"no column {name!r}; columns: {', '.join(self.columns)}") from None

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def __len__(self) -> int:
        return self.values.shape[0]

    def __iter__(self) -> Iterator[str]:
        return iter(self.columns)

    def keys(self) -> tuple:
        """Column names."""
        return self.columns

    def to_dict(self) -> dict:
        """``{name: column}``."""
        return {c: self[c] for c in self.columns}

    def write(self, path) -> None:
        """Writes the table in the format the path's extension names — Parquet for ``.parquet``,
        NumPy for ``.npy`` (a structured array) and ``.npz`` (an array per column), CSV
        otherwise — atomically (imukit's own writer, as the command line's)."""
        from . import _core
        _core.write_table_file(str(path), list(self.columns), self.values)

    def to_pandas(self):
        """A pandas ``DataFrame`` of the columns over the table's own memory (no copy; like the
        table it is read-only until pandas copies on a write). Needs pandas."""
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("Table.to_pandas needs pandas (pip install pandas)") from None
        return pd.DataFrame(self.values, columns=list(self.columns), copy=False)

    def to_polars(self):
        """A polars ``DataFrame`` of the columns. polars keeps each column contiguous, so the
        row-major values are copied once, column by column. Needs polars."""
        try:
            import polars as pl
        except ImportError:
            raise ImportError("Table.to_polars needs polars (pip install polars)") from None
        return pl.DataFrame({c: self.values[:, k] for k, c in enumerate(self.columns)})

    def __repr__(self) -> str:
        return f"Table({len(self)} rows: {', '.join(self.columns)})"

@dataclass(frozen=True)
class Simulation:
    """Truth kinematics and IMU readings of a scenario, and the readings of its aids — the
    ``[gnss]`` receiver, the ``[baro]`` barometer, the ``[odometer]`` (``None`` without them).
    ``truth`` is ``None`` when the run kept only its readings (``simulate(..., truth=False)``)."""

    truth: Optional[Table]
    imu: Table
    gnss: Optional[Table] = None
    baro: Optional[Table] = None
    odometer: Optional[Table] = None

def _table(out) -> Table:
    columns, values = out
    return Table(columns, values)
