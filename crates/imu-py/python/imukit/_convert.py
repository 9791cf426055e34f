"""Turning Python arguments into what the compiled core takes: contiguous float64 arrays of the
right number of dimensions (the core checks their shapes and names the argument), and tables."""
from __future__ import annotations

from typing import Optional

import numpy as np

from ._table import Table


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


def _table_args(name: str, t) -> tuple:
    """``(columns, values)`` of an :class:`imukit.Table`."""
    if not isinstance(t, Table):
        raise TypeError(f"{name} must be an imukit.Table, got {type(t).__name__}")
    return list(t.columns), np.ascontiguousarray(t.values)
