"""Turning Python arguments into what the compiled core takes: contiguous float64 arrays of the
right number of dimensions (the core checks their shapes and names the argument), and tables."""
from __future__ import annotations

import numbers
from typing import Optional

import numpy as np

from ._table import Table, TableLike


def _times(t_s) -> np.ndarray:
    """A one-dimensional float64 array of times."""
    return _f64("t_s", t_s, 1)


def _f64(name: str, x, ndim: int) -> np.ndarray:
    """``x`` as a C-contiguous float64 array with ``ndim`` dimensions (shapes: the core checks)."""
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim != ndim:
        raise ValueError(f"{name} must be {ndim}-dimensional, got shape {a.shape}")
    return a


def _rows(name: str, x) -> np.ndarray:
    """Rows of vectors (N, K); a single vector (K,) is one row."""
    return _f64(name, np.atleast_2d(np.asarray(x, dtype=np.float64)), 2)


def _out(out: Optional[np.ndarray]) -> Optional[np.ndarray]:
    """A caller's output buffer, checked to be one the readings can be written into in place."""
    if out is None:
        return None
    if not isinstance(out, np.ndarray) or out.dtype != np.float64 or not out.flags.c_contiguous:
        raise ValueError("out must be a C-contiguous float64 numpy array of shape (N, 9)")
    return out


def _table_args(name: str, t: TableLike) -> tuple:
    """``(columns, values)`` of anything :data:`imukit.TableLike` (a Table, a DataFrame, …)."""
    table = Table.of(t, name)
    return list(table.columns), np.ascontiguousarray(table.values)


def _flag(name: str, v) -> bool:
    """A yes/no argument: ``True`` or ``False`` (NumPy's bools too), not a number or a string
    that would be taken as one."""
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    raise TypeError(f"{name} must be True or False, got {type(v).__name__} {v!r}")


def _whole(name: str, v, *, at_most: bool = False) -> Optional[int]:
    """An optional whole-number argument for the core: ``None``, or an integer (a bool is not a
    count) in the 64-bit range the core takes. ``at_most``: a cap, so a larger one is the
    largest (``threads=10**30`` is "every core"); otherwise a larger one is refused by name."""
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, numbers.Integral):
        raise TypeError(f"{name} must be a whole number, got {type(v).__name__} {v!r}")
    v, top = int(v), 2**63 - 1
    if at_most and v > top:
        return top
    if not -top - 1 <= v <= top:
        raise ValueError(f"{name} must be between -2**63 and 2**63 - 1, got {v}")
    return v
