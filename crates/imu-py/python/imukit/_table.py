"""The :class:`Table` every result comes back as, and :class:`Simulation`."""
from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Iterator, Mapping, Optional, Sequence, Union

import numpy as np

#: What every function that takes a table accepts: an :class:`imukit.Table`, a pandas or polars
#: ``DataFrame``, a NumPy structured array, or any mapping of column names to 1-D arrays of one
#: length (``{"t_s": t, "gyro_x_rad_s": gx, …}``). Columns are named as imukit's CSV names them.
TableLike = Union["Table", Mapping[str, Any], Any]

_SHOWN_COLUMNS = 6


class Table:
    """Named columns over a 2-D float64 array (one row per sample), and what they hold.

    ``table["t_s"]`` is a column (a read-only view), ``table.values`` the whole array,
    ``table.columns`` the names in order, ``len(table)`` the number of rows.

    ``table.description`` says what the table holds, as an imukit file's description does
    (docs/formats.md): ``kind``, ``nav_frame`` and ``body_frame``, ``earth``, the origin,
    gravity, ``accel_sign``, the sensor. :func:`simulate`, :func:`read` and every job fill it;
    every job that takes the table honours it as the command line honours a file's (an argument
    that contradicts it is refused), and :meth:`write` and :meth:`to_pandas` (as
    ``DataFrame.attrs["imukit"]``) keep it. A table made from plain columns has none.
    """

    def __init__(self, columns: Sequence[str], values: np.ndarray,
                 description: Optional[Mapping[str, Any]] = None) -> None:
        values = np.asarray(values, dtype=np.float64)
        if values.ndim != 2 or values.shape[1] != len(columns):
            raise ValueError(f"values must have shape (N, {len(columns)}), got {values.shape}")
        values.setflags(write=False)
        self.columns: tuple = tuple(columns)
        self.values: np.ndarray = values
        self._index = {c: k for k, c in enumerate(self.columns)}
        self._description = MappingProxyType(dict(description or {}))

    @property
    def description(self) -> Mapping[str, Any]:
        """What the table holds (read-only; empty when nothing is known)."""
        return self._description

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
        otherwise — atomically (imukit's own writer, as the command line's), with its
        description where the format has room (CSV's first line, Parquet's metadata)."""
        from . import _core
        _core.write_table_file(str(path), list(self.columns), self.values,
                               dict(self._description) or None)

    @classmethod
    def of(cls, data: TableLike, name: str = "table") -> "Table":
        """A table from anything :data:`TableLike`: a Table as it is; a pandas or polars
        ``DataFrame`` (its index is not a column; put time in a ``t_s`` column); a NumPy
        structured array; a mapping of names to 1-D arrays. Every column must hold numbers
        (converted to float64); ``name`` names the argument in errors.

        >>> import numpy as np
        >>> Table.of({"t_s": np.arange(3.0), "gyro_z_rad_s": [0.1, 0.2, 0.3]})
        Table(3 rows × 2 columns: t_s, gyro_z_rad_s)
        """
        if isinstance(data, Table):
            return data
        if isinstance(data, np.ndarray):
            if data.dtype.names is None:
                raise TypeError(f"{name}: a plain array has no column names; pass a structured array, "
                                "a DataFrame, a mapping of names to columns or an imukit.Table")
            return cls._from_columns(name, {n: data[n] for n in data.dtype.names})
        columns = getattr(data, "columns", None)
        to_numpy = getattr(data, "to_numpy", None)
        if columns is not None and callable(to_numpy):  # pandas, polars and alike
            names = [c for c in columns]
            table = cls._from_columns(name, {c: data[c] for c in names})
            return cls(table.columns, table.values, _description_of(data))
        if isinstance(data, Mapping):
            return cls._from_columns(name, data)
        raise TypeError(f"{name} must be an imukit.Table, a pandas or polars DataFrame, a NumPy structured "
                        f"array or a mapping of column names to arrays, got {type(data).__name__}")

    @classmethod
    def _from_columns(cls, name: str, columns: Mapping[Any, Any]) -> "Table":
        names = list(columns)
        for c in names:
            if not isinstance(c, str):
                raise TypeError(f"{name}: column names must be strings, got {c!r}")
        arrays = []
        rows = None
        for c in names:
            column = columns[c]
            to_numpy = getattr(column, "to_numpy", None)
            raw = to_numpy() if callable(to_numpy) else column
            try:
                a = np.asarray(raw, dtype=np.float64)
            except (TypeError, ValueError):
                raise TypeError(f"{name}: column {c!r} does not hold numbers") from None
            if a.ndim != 1:
                raise ValueError(f"{name}: column {c!r} must be 1-D, got shape {a.shape}")
            if rows is None:
                rows = a.shape[0]
            elif a.shape[0] != rows:
                raise ValueError(f"{name}: column {c!r} has {a.shape[0]} rows, column {names[0]!r} has {rows}")
            arrays.append(a)
        values = np.column_stack(arrays) if arrays else np.zeros((0, 0))
        return cls(names, values)

    def to_pandas(self, *, copy: bool = True):
        """A pandas ``DataFrame`` of the columns. By default a copy you can change; with
        ``copy=False`` a read-only view of the table's own memory (no copy; a write raises).
        The description goes along as ``df.attrs["imukit"]``, so the frame passed back to imukit
        is still known to be, say, NED. Needs pandas (``pip install "imukit[pandas]"``).

        >>> df = Table(["t_s", "x"], [[0.0, 1.0], [1.0, 2.0]]).to_pandas()
        >>> df.loc[0, "x"] = 5.0
        >>> float(df["x"].sum())
        7.0
        """
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("Table.to_pandas needs pandas (pip install pandas)") from None
        if copy:
            df = pd.DataFrame(np.array(self.values), columns=list(self.columns))
        else:
            df = pd.DataFrame(self.values, columns=list(self.columns), copy=False)
        if self._description:
            df.attrs["imukit"] = dict(self._description)
        return df

    def to_polars(self):
        """A polars ``DataFrame`` of the columns. polars keeps each column contiguous, so the
        row-major values are copied once, column by column. Needs polars."""
        try:
            import polars as pl
        except ImportError:
            raise ImportError("Table.to_polars needs polars (pip install polars)") from None
        return pl.DataFrame({c: self.values[:, k] for k, c in enumerate(self.columns)})

    def __repr__(self) -> str:
        names = list(self.columns)
        if len(names) > _SHOWN_COLUMNS:
            names = names[: _SHOWN_COLUMNS - 1] + ["…", names[-1]]
        return f"Table({len(self)} rows × {len(self.columns)} columns: {', '.join(names)})"

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

    def __repr__(self) -> str:
        parts = [f"{k}={v!r}" for k, v in (("imu", self.imu), ("truth", self.truth), ("gnss", self.gnss),
                                          ("baro", self.baro), ("odometer", self.odometer)) if v is not None]
        return f"Simulation({', '.join(parts)})"

def _description_of(data: Any) -> dict:
    """The description a table argument carries: a Table's, or a pandas frame's
    ``attrs["imukit"]`` (as :meth:`Table.to_pandas` leaves it); else none."""
    if isinstance(data, Table):
        return dict(data.description)
    attrs = getattr(data, "attrs", None)
    if isinstance(attrs, Mapping) and isinstance(attrs.get("imukit"), Mapping):
        return dict(attrs["imukit"])
    return {}


def _described(**tables: Any) -> list:
    """``[(argument, description), …]`` of the table arguments that carry one, for the core."""
    return [(name, d) for name, t in tables.items() if t is not None for d in [_description_of(t)] if d]


def _table(out) -> Table:
    """A Table from the core's ``(columns, values)`` or ``(columns, values, description)``."""
    return Table(*out)
