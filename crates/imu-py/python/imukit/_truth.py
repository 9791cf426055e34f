"""Scenarios and truth: :func:`simulate`, truth from formulas, samples, body rates and waypoints,
ideal readings, CSV files and the built-in scenarios."""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, Union

from . import _core
from ._convert import _f64, _flag, _table_args, _times, _whole
from ._core import ImuError
from ._table import Simulation, Table, _table
from ._warning import _emit

_D = _core.DEFAULTS  # the library's request defaults, shared with the command line

DEFAULT_GRAVITY_M_S2: float = _core.DEFAULT_GRAVITY_M_S2  # m/s², MATLAB imuSensor's value


def simulate(
    scenario: Union[str, os.PathLike, Mapping],
    *,
    run: Optional[int] = None,
    threads: Optional[int] = None,
    truth: bool = True,
) -> Simulation:
    """Runs a scenario: a path to a TOML/JSON scenario file, or a dict with the same keys.

    Relative file paths are taken from the scenario file's folder (for a dict, from the current
    directory). The numbers equal those of ``imukit simulate`` bit for bit. ``run=r`` gives
    Monte Carlo run ``r`` (noise drawn from (seed, r)), the same as file ``r`` of
    ``imukit simulate --runs``. ``threads`` caps the threads the run uses: by default two when a
    second core is free and the run has 1 537 samples or more (four chunks; the truth is made a
    chunk ahead of the sensors), ``threads=1`` keeps it on one; the numbers are the same either
    way. ``truth=False`` keeps only the readings (``Simulation.truth`` is ``None``): the
    same readings, without the truth table's 23 columns (184 MB a million samples) and the time
    to fill them, as ``imukit simulate --out`` without ``--truth``.

    >>> sim = simulate({"trajectory": {"type": "builtin", "name": "static"}})
    >>> float(sim.imu["accel_z_m_s2"][0])
    9.81
    >>> simulate({"trajectory": {"type": "builtin", "name": "static"}}, truth=False).truth is None
    True
    """
    run, threads = _whole("run", run), _whole("threads", threads, at_most=True)
    keep_truth = _flag("truth", truth)
    if isinstance(scenario, Mapping):
        out = _core.simulate_dict(dict(scenario), base_dir=os.getcwd(), run=run, threads=threads,
                                  truth=keep_truth)
    else:
        path = Path(scenario)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as e:
            raise ImuError(f"{path}: {e.strerror or e}") from None
        fmt = "json" if path.suffix.lower() == ".json" else "toml"
        out = _core.simulate_text(
            text, format=fmt, origin=str(path), base_dir=str(path.parent), run=run, threads=threads,
            truth=keep_truth,
        )
    truth_out, imu, gnss, baro, odometer, notes = out
    _emit(notes)
    optional = lambda t: None if t is None else _table(t)  # noqa: E731
    return Simulation(truth=optional(truth_out), imu=_table(imu), gnss=optional(gnss),
                      baro=optional(baro), odometer=optional(odometer))

def read_csv(path: Union[str, os.PathLike]) -> Table:
    """Every column of an imukit CSV file (truth, IMU readings, navigation output, errors, Allan
    table) as a :class:`Table`; :class:`ImuError` names the file, row and column of bad input."""
    return _table(_core.read_csv(str(path)))

def read(path: Union[str, os.PathLike], *, topic: Optional[str] = None, receive_time: bool = False,
         map: Optional[Union[str, os.PathLike, Mapping[str, Any]]] = None,
         calibration: Optional[Union[str, os.PathLike]] = None) -> Table:
    """A table file as a :class:`Table`, its format by its extension: ``.csv``, ``.parquet``
    (float64 columns, as ``imukit simulate --out x.parquet`` writes them), ``.npy`` (a structured
    array of float64 fields) or ``.npz`` (one float64 array per column, as ``numpy.savez`` writes
    them), ``.mcap``, ``.db3`` or ``.bag`` (a ROS 2 or ROS 1 bag: one topic's messages — ``sensor_msgs/Imu``, ``NavSatFix``,
    ``nav_msgs/Odometry``, … — as imukit's columns; ``topic`` names it where the bag holds
    several, else its IMU topic is read). Any other extension is refused with the formats read.
    A EuRoC/TUM-VI file (``#timestamp [ns],w_RS_S_x [rad s^-1],…``) is read as imukit's columns
    by its header. Readings that look like a unit slip — accelerations whose median magnitude
    is 1 (g) or 1000 (mg) rather than gravity's 9.81, rates beyond any MEMS gyroscope's, samples
    a second or more apart — raise an :class:`ImuWarning` naming the likely unit.

    ``map`` reads a vendor's CSV through a column map — the path of a TOML map, or the same keys
    as a dict — giving ``t_s`` and the sensors' columns in SI units and body axes
    (docs/formats.md)::

        imukit.read("log.csv", map={"time": {"column": "Timestamp", "unit": "ms"},
                                    "accel": {"columns": ["AccX", "AccY", "AccZ"], "unit": "g"},
                                    "gyro": {"columns": ["GyrX", "GyrY", "GyrZ"], "unit": "deg/s"},
                                    "axes": ["x", "-y", "-z"]})

    ``calibration`` corrects the readings as they are read with a part's calibration file (as
    ``imukit calibrate --out`` writes it and ``--calibration FILE`` reads it): each calibrated
    sensor's three columns, after the map.
    """
    suffix = Path(path).suffix.lower()
    if Path(path).is_dir() and (Path(path) / "metadata.yaml").is_file():
        suffix = ".mcap"  # a ROS 2 bag's folder
    if suffix not in TABLE_FORMATS:
        raise ImuError(f"{path}: cannot read {suffix or 'a file without an extension'!r} tables "
                       f"(read: {', '.join(TABLE_FORMATS)})")
    cal = None if calibration is None else str(calibration)
    if topic is not None or receive_time:
        if suffix not in (".mcap", ".db3", ".bag"):
            raise ImuError(f"{path}: topic= and receive_time= are a ROS bag's (.mcap, .db3, .bag), not a {suffix} file's")
        if map is not None:
            raise ImuError(f"{path}: map= reads a vendor's CSV; a bag's topics have their own columns")
        return _table(_core.read_table_file(str(path), topic=None if topic is None else str(topic),
                                            receive_time=bool(receive_time), calibration_path=cal))
    if map is None:
        table = _table(_core.read_table_file(str(path), calibration_path=cal))
    elif isinstance(map, Mapping):
        table = _table(_core.read_table_file(str(path), map_json=json.dumps(dict(map)), calibration_path=cal))
    else:
        table = _table(_core.read_table_file(str(path), map_path=str(map), calibration_path=cal))
    # Readings that look like a unit slip (g as m/s², °/s as rad/s, ms as s) are warned about.
    _emit(_core.implausible(list(table.columns), table.values, str(path)))
    return table


def describe(path: Union[str, os.PathLike]) -> dict[str, Union[str, float]]:
    """What an imukit table file says it holds: the entries of its description (``kind``,
    ``nav_frame``, ``body_frame``, ``earth``, ``origin_latitude_deg``, …, ``scenario``), from a
    CSV file's first line or a Parquet file's metadata; empty for a file without one (``.npy``,
    ``.npz``, another program's CSV). See docs/formats.md.

    >>> import imukit, tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "truth.csv"
    >>> imukit.simulate({"trajectory": {"type": "builtin", "name": "static"}}).truth.write(path)
    >>> imukit.describe(path)["kind"]
    'truth'
    """
    return dict(_core.read_description(str(path)) or {})


#: The extensions of the table files imukit reads and writes.
TABLE_FORMATS = (".csv", ".parquet", ".npy", ".npz", ".mcap", ".db3", ".bag", ".nmea")


def builtin_scenarios() -> list:
    """Names of the built-in scenarios."""
    return list(_core.builtin_names())

def builtin_scenario_toml(name: str) -> str:
    """A built-in scenario as an editable TOML text."""
    return _core.builtin_toml(name)

def _formula(name: str, f) -> Optional[str]:
    if f is None:
        return None
    if isinstance(f, str):
        return f
    if isinstance(f, (int, float)):
        return repr(float(f))
    from .compat import sympy_to_formula  # sympy is optional

    return sympy_to_formula(f, name)

def truth_from_expressions(
    t_s,
    position_m: Sequence,
    *,
    attitude: Optional[str] = None,
    yaw_rad=None,
    pitch_rad=None,
    roll_rad=None,
    constants: Optional[Mapping[str, float]] = None,
    nav_frame: str = _D["nav_frame"],
    min_speed_m_s: Optional[float] = None,
) -> Table:
    """Exact truth from formulas of ``t`` (strings, numbers or sympy expressions).

    ``attitude`` is ``"tangent"`` (body x along the velocity) or ``"level"``; or give
    ``yaw_rad``/``pitch_rad``/``roll_rad`` formulas (missing ones are 0). Derivatives are exact
    (dual numbers), so results are at machine precision.
    """
    if len(position_m) != 3:
        raise ValueError(f"position_m must have 3 formulas, got {len(position_m)}")
    pos = [_formula(f"position_m[{k}]", f) for k, f in enumerate(position_m)]
    return _table(
        _core.truth_from_expressions(
            _times(t_s),
            pos,
            attitude=attitude,
            yaw_rad=_formula("yaw_rad", yaw_rad),
            pitch_rad=_formula("pitch_rad", pitch_rad),
            roll_rad=_formula("roll_rad", roll_rad),
            constants=None if constants is None else {k: float(v) for k, v in constants.items()},
            nav_frame=nav_frame,
            min_speed_m_s=min_speed_m_s,
        )
    )

def truth_from_samples(
    t_s,
    position_m,
    *,
    euler_rad=None,
    quaternion=None,
    attitude: Optional[str] = None,
    order: int = _D["finite_difference_order"],
    nav_frame: str = _D["nav_frame"],
    min_speed_m_s: Optional[float] = None,
) -> Table:
    """Truth from sampled positions (N, 3) and attitude by finite differences.

    Attitude: ``euler_rad`` (N, 3) as ``[yaw, pitch, roll]``, or ``quaternion`` (N, 4) as
    ``[w, x, y, z]``, or ``attitude="tangent"`` / ``"level"`` (default level). ``order`` 2 is
    MATLAB's ``gradient`` (for comparison with MATLAB scripts); 4, 6 (default) and 8 use
    Fornberg stencils of that order with one-sided stencils at the ends.
    """
    t = _times(t_s)
    return _table(
        _core.truth_from_samples(
            t,
            _f64("position_m", position_m, 2),
            euler_rad=None if euler_rad is None else _f64("euler_rad", euler_rad, 2),
            quaternion=None if quaternion is None else _f64("quaternion", quaternion, 2),
            attitude=attitude,
            order=int(order),
            nav_frame=nav_frame,
            min_speed_m_s=min_speed_m_s,
        )
    )

def ideal_imu(
    truth: Table,
    *,
    lever_arm_m: Sequence[float] = (0.0, 0.0, 0.0),
    accel_sign: str = _D["accel_sign"],
    gravity_m_s2: float = DEFAULT_GRAVITY_M_S2,
    magnetic_field_ut: Optional[Sequence[float]] = None,
    nav_frame: str = _D["nav_frame"],
    kind: str = _D["imu_type"],
) -> Table:
    """Ideal IMU readings from truth: specific force at the lever arm (body frame, m), body
    rate, magnetic field (navigation frame, µT; MATLAB's default when ``None``)."""
    return _table(
        _core.ideal_imu(
            *_table_args("truth", truth),
            lever_arm_m=[float(v) for v in lever_arm_m],
            accel_sign=accel_sign,
            gravity_m_s2=float(gravity_m_s2),
            magnetic_field_ut=None if magnetic_field_ut is None else [float(v) for v in magnetic_field_ut],
            nav_frame=nav_frame,
            kind=kind,
        )
    )

def truth_from_body_rates(
    t_s,
    accel_body_m_s2,
    omega_body_rad_s,
    *,
    position0_m: Sequence[float] = (0.0, 0.0, 0.0),
    velocity0_m_s: Sequence[float] = (0.0, 0.0, 0.0),
    euler0_rad: Sequence[float] = (0.0, 0.0, 0.0),
    nav_frame: str = _D["nav_frame"],
) -> Table:
    """Truth from body-frame acceleration (kinematic, no gravity) and angular velocity, as MATLAB's
    ``kinematicTrajectory`` builds it: exact rotation-vector attitude step,
    ``p ← p + vΔt + ½aΔt²``, the state before each update at each sample (first order)."""
    return _table(_core.truth_from_body_rates(
        _times(t_s), _f64("accel_body_m_s2", accel_body_m_s2, 2), _f64("omega_body_rad_s", omega_body_rad_s, 2),
        position0_m=[float(v) for v in position0_m], velocity0_m_s=[float(v) for v in velocity0_m_s],
        euler0_rad=[float(v) for v in euler0_rad], nav_frame=nav_frame))

def truth_from_waypoints(t_s, time_s, position_m, *, velocity_m_s=None, euler_rad=None, nav_frame: str = _D["nav_frame"]) -> Table:
    """Exact truth at ``t_s`` of a waypoint trajectory (like MATLAB's waypointTrajectory): a natural
    cubic spline through ``position_m`` (N, 3) at ``time_s`` (N,), clamped to ``velocity_m_s`` when it
    has 2 rows (start, end) or through all of them when it has one row per waypoint; the attitude is
    tangent, or a spline through ``euler_rad`` (N, 3) ``[yaw, pitch, roll]``. With one velocity row per
    waypoint each interval is a quintic Hermite polynomial, so the path stays C²."""
    return _table(_core.truth_from_waypoints(
        _times(t_s), _f64("time_s", time_s, 1), _f64("position_m", position_m, 2),
        velocity_m_s=None if velocity_m_s is None else _f64("velocity_m_s", velocity_m_s, 2),
        euler_rad=None if euler_rad is None else _f64("euler_rad", euler_rad, 2), nav_frame=nav_frame))
