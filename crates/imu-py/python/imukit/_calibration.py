"""Calibrating a part from a procedure (:func:`calibrate`) and applying the result
(:class:`Calibration`), as ``imukit calibrate`` and ``--calibration FILE`` do."""
from __future__ import annotations

import os
from typing import Any, Optional, Union

import numpy as np

from . import _core
from ._convert import _table_args
from ._sensor import _toml_to_dict
from ._table import Table, TableLike

_DEFAULT_GRAVITY = _core.DEFAULTS["gravity_m_s2"]


def _arrays(section: Optional[dict]) -> Optional[dict]:
    """A sensor's table with its matrices and vectors as NumPy arrays."""
    if section is None:
        return None
    return {k: (np.asarray(v, dtype=float) if isinstance(v, list) else v) for k, v in section.items()}


class Calibration:
    """A part's calibration: per sensor ``calibrated = matrix · (reading − bias)``, with what the
    fit says of it — one standard deviation of every term, the rests or rotations fitted, the
    residual, and for a magnetometer the field's strength and the fit error.

    ``accelerometer``, ``gyroscope`` and ``magnetometer`` are dicts (``None`` for a sensor not
    calibrated) with the calibration file's keys: ``matrix`` and ``matrix_sigma`` (3×3 arrays),
    ``bias_m_s2``/``bias_rad_s``/``bias_ut`` and ``bias_sigma_…`` (3-vectors), ``rests``,
    ``residual_rms_m_s2``, ``rotations``, ``residual_rms_rad``, ``field_ut``, ``fit_error``.
    ``rests`` lists the static intervals found as ``(start, end)`` sample ranges, ``noise`` the
    white noise learnt from the log's quiet stretches (accelerometer m/s², gyroscope rad/s a
    sample), ``warnings`` what could not be calibrated and why, ``residuals`` what the
    calibration leaves of each residual beside the raw readings' (arrays: ``rest_t_s``,
    ``accel_m_s2``/``accel_raw_m_s2`` — gravity's magnitude less each rest's mean reading;
    ``rotation_t_s``, ``gyro_rad``/``gyro_raw_rad`` — the angle by which each turn misses the
    next rest's gravity; ``mag_t_s``, ``mag``/``mag_raw`` — the distance from the fitted sphere,
    a fraction; drawn by :func:`imukit.plot.calibration`). :meth:`apply` corrects readings,
    :meth:`save` writes the file ``--calibration`` reads, :meth:`load` reads one.
    """

    def __init__(self, text: str, rests: Optional[list] = None, warnings: Optional[list] = None,
                 noise: Optional[tuple] = None, origin: Optional[str] = None,
                 residuals: Optional[dict] = None) -> None:
        self.text = text
        self._origin = origin or "calibration"  # how a message names a calibration not read from a file
        doc = _toml_to_dict(text)
        self.accelerometer: Optional[dict[str, Any]] = _arrays(doc.get("accelerometer"))
        self.gyroscope: Optional[dict[str, Any]] = _arrays(doc.get("gyroscope"))
        self.magnetometer: Optional[dict[str, Any]] = _arrays(doc.get("magnetometer"))
        self.rests: list[tuple[int, int]] = list(rests or [])
        self.warnings: list[str] = list(warnings or [])
        self.noise: Optional[tuple[float, float]] = noise
        self.residuals: dict[str, np.ndarray] = {k: np.asarray(v, dtype=float) for k, v in (residuals or {}).items()}

    @classmethod
    def load(cls, path: Union[str, os.PathLike]) -> "Calibration":
        """The calibration file at ``path`` (as ``imukit calibrate --out`` writes it)."""
        return cls(_core.read_calibration(str(path)), origin=str(path))

    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the calibration file (TOML) to ``path``, atomically."""
        _core.write_calibration(str(path), self.text)

    def apply(self, readings: TableLike) -> Table:
        """``readings`` with each calibrated sensor's three columns corrected; other columns as
        they are. The description of a Table is kept."""
        table = Table.of(readings, "readings")
        columns, values = _core.apply_calibration(*_table_args("readings", table), self.text,
                                                  self._origin)
        return Table(columns, values, dict(table._description))

    def __repr__(self) -> str:
        sensors = [s for s in ("accelerometer", "gyroscope", "magnetometer") if getattr(self, s) is not None]
        return f"Calibration({', '.join(sensors) or 'no sensor'}; {len(self.rests)} rests)"


def calibrate(readings: Union[TableLike, str, os.PathLike], *,
              gravity_m_s2: float = _DEFAULT_GRAVITY) -> Calibration:
    """Calibrates a part from the readings of a procedure, without equipment (as ``imukit
    calibrate``): the white noise learnt from the log's quiet stretches, the rests found with it;
    the accelerometer's bias, scale and misalignment from gravity's magnitude ``gravity_m_s2`` at
    the rests (scale and bias only with fewer than 12 rests); the gyroscope's bias from the rests
    and its scale and misalignment from the turns between them; a magnetometer's hard and soft
    iron and the field's strength from an ellipsoid fit. ``readings`` is a table (``t_s`` and
    the sensors' columns) or a file's path (read as :func:`imukit.read` reads it). A sensor the
    log cannot calibrate is left out and said in ``warnings``; none at all raises
    :class:`ImuError`. See docs/sensors.md, "Calibration"."""
    if isinstance(readings, (str, os.PathLike)):
        from ._truth import read
        source = str(readings)
        table = read(readings)
    else:
        source = "readings"
        table = Table.of(readings, "readings")
    text, rests, warnings, noise, residuals = _core.calibrate(*_table_args("readings", table),
                                                              float(gravity_m_s2), source)
    return Calibration(text, rests, warnings, noise, residuals=dict(residuals))
