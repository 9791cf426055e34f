"""imukit — fast, exact and reproducible IMU simulation (Python face of the Rust core).

Conventions (the same everywhere in imukit):

* SI units; magnetic field in µT. Names carry their unit (``t_s``, ``position_m``).
* Navigation frame ``"ENU"`` (default) or ``"NED"``; body frame FLU under ENU, FRD under NED.
* Attitude ``C_nb`` maps body to navigation: ``v_n = C_nb v_b``. Euler angles are intrinsic
  z-y-x, given as ``[yaw, pitch, roll]`` columns. Quaternions are Hamilton, scalar first
  ``[w, x, y, z]``, ``q = q_nb``.
* Accelerometers report specific force (``+g`` up at rest) unless ``accel_sign="matlab"``.

Results are :class:`Table` objects whose columns are reachable by their CSV names
(``truth["omega_z_rad_s"]``) as NumPy arrays. Rejected input raises :class:`ImuError`
(a ``ValueError``) with a message that says what and where, and attributes that say it to
programs: ``field`` (the key or argument), ``file``, ``row`` and ``column`` (``None`` where
unknown).

The package is split by area as the compiled core is: ``_truth`` (scenarios and truth),
``_rotations``, ``_sensor`` (``ImuSensor``, parameters, presets, Allan), ``_navigation``,
``_orientation``, ``_calibration``, ``_monte_carlo``, ``_study``, ``_examples`` (the shipped examples), ``plot``,
``compat``; this file only re-exports.
"""
from __future__ import annotations

from ._core import ImuError, __version__
from ._warning import ImuWarning
from ._table import Simulation, Table, TableLike
from ._truth import (
    builtin_scenario_toml,
    builtin_scenarios,
    describe,
    ideal_imu,
    read,
    read_csv,
    simulate,
    truth_from_body_rates,
    truth_from_expressions,
    truth_from_samples,
    truth_from_waypoints,
)
from ._rotations import (
    dcm_to_euler,
    dcm_to_quaternion,
    euler_to_dcm,
    euler_to_quaternion,
    quaternion_to_dcm,
    quaternion_to_euler,
)
from ._sensor import (
    AccelParams,
    GyroParams,
    ImuSensor,
    MagParams,
    allan_deviation,
    chain_response,
    spectrum,
    convert,
    identify,
    Identification,
    kalibr_yaml,
    loadparams,
    preset_params,
    presets,
)
from ._navigation import Comparison, compare, fuse, planar_dead_reckon, read_planar, strapdown
from ._calibration import Calibration, calibrate
from ._examples import example, examples
from ._monte_carlo import MonteCarlo, monte_carlo
from ._study import PresetSummary, StudyResult, study
from ._orientation import (
    AhrsFilter,
    ComplementaryFilter,
    ImuFilter,
    MadgwickFilter,
    MahonyFilter,
    RobustFilter,
    ecompass,
    quaternion_distance,
)

__all__ = [
    "__version__",
    "ImuError",
    "ImuWarning",
    "Table",
    "TableLike",
    "Simulation",
    "Comparison",
    "simulate",
    "example",
    "examples",
    "monte_carlo",
    "study",
    "StudyResult",
    "PresetSummary",
    "MonteCarlo",
    "ImuSensor",
    "AccelParams",
    "GyroParams",
    "MagParams",
    "allan_deviation",
    "identify",
    "Identification",
    "chain_response",
    "calibrate",
    "Calibration",
    "spectrum",
    "presets",
    "convert",
    "preset_params",
    "kalibr_yaml",
    "loadparams",
    "strapdown",
    "fuse",
    "compare",
    "planar_dead_reckon",
    "read_planar",
    "read",
    "describe",
    "read_csv",
    "builtin_scenarios",
    "builtin_scenario_toml",
    "truth_from_expressions",
    "truth_from_samples",
    "truth_from_body_rates",
    "truth_from_waypoints",
    "ideal_imu",
    "euler_to_quaternion",
    "quaternion_to_euler",
    "euler_to_dcm",
    "dcm_to_euler",
    "quaternion_to_dcm",
    "dcm_to_quaternion",
    "ecompass",
    "quaternion_distance",
    "ImuFilter",
    "AhrsFilter",
    "ComplementaryFilter",
    "MadgwickFilter",
    "MahonyFilter",
    "RobustFilter",
]
