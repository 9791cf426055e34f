"""Attitude conversions between z-y-x Euler angles ``[yaw, pitch, roll]``, quaternions
``[w, x, y, z]`` (``q_nb``) and direction cosine matrices ``C_nb``, row by row."""
from __future__ import annotations

import numpy as np

from . import _core
from ._convert import _f64, _rows


def _matrices(dcm) -> np.ndarray:
    """Matrices (N, 3, 3); a single matrix (3, 3) is one."""
    m = np.asarray(dcm, dtype=np.float64)
    return _f64("dcm", m[None] if m.ndim == 2 else m, 3)


def euler_to_quaternion(euler_rad) -> np.ndarray:
    """``[yaw, pitch, roll]`` (N, 3) → ``[w, x, y, z]`` (N, 4), ``q = q_nb``."""
    return _core.euler_to_quaternion(_rows("euler_rad", euler_rad))

def quaternion_to_euler(quaternion) -> np.ndarray:
    """``[w, x, y, z]`` (N, 4) → ``[yaw, pitch, roll]`` (N, 3)."""
    return _core.quaternion_to_euler(_rows("quaternion", quaternion))

def euler_to_dcm(euler_rad) -> np.ndarray:
    """``[yaw, pitch, roll]`` (N, 3) → ``C_nb = Rz·Ry·Rx`` (N, 3, 3)."""
    return _core.euler_to_dcm(_rows("euler_rad", euler_rad))

def dcm_to_euler(dcm) -> np.ndarray:
    """``C_nb`` (N, 3, 3) → ``[yaw, pitch, roll]`` (N, 3)."""
    return _core.dcm_to_euler(_matrices(dcm))

def quaternion_to_dcm(quaternion) -> np.ndarray:
    """``[w, x, y, z]`` (N, 4) → ``C_nb`` (N, 3, 3)."""
    return _core.quaternion_to_dcm(_rows("quaternion", quaternion))

def dcm_to_quaternion(dcm) -> np.ndarray:
    """``C_nb`` (N, 3, 3) → ``[w, x, y, z]`` (N, 4)."""
    return _core.dcm_to_quaternion(_matrices(dcm))
