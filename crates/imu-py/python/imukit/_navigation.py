"""Navigation: planar dead reckoning, 3D strapdown, and errors against truth."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Dict, Mapping, NamedTuple, Optional, Sequence, Union

import numpy as np

from . import _core
from ._warning import _emit
from ._core import ImuError
from ._convert import _f64, _table_args, _times
from ._table import Table, TableLike, _described, _table

_D = _core.DEFAULTS  # the library's request defaults, shared with the command line


def planar_dead_reckon(
    t_s,
    accel_x_m_s2,
    accel_y_m_s2,
    gyro_z_rad_s,
    *,
    scheme: str = _D["planar_scheme"],
    position0_m: Sequence[float] = tuple(_D["planar_position0_m"]),
    heading0_rad: float = 0.0,
    velocity0_m_s: Sequence[float] = (0.0, 0.0),
) -> Table:
    """Planar dead reckoning of a cart (the planar cart exercise): body x forward, y left, ω_z counter-clockwise.

    ``scheme="trapezoid"`` (second order, default) or ``"exercise"`` (the exercise's rules
    verbatim; its rotation turns increments by −α, which mirrors left turns into right turns).
    The defaults are the exercise's initial conditions (X₀ = [100, 100], α₀ = 0, v₀ = 0). Returns
    ``t_s, pos_x_m, pos_y_m, yaw_rad, vel_x_m_s, vel_y_m_s, body_vel_x_m_s, body_vel_y_m_s``.
    """
    return _table(_core.planar_dead_reckon(
        _times(t_s), _f64("accel_x_m_s2", accel_x_m_s2, 1), _f64("accel_y_m_s2", accel_y_m_s2, 1),
        _f64("gyro_z_rad_s", gyro_z_rad_s, 1), scheme=scheme,
        position0_m=[float(v) for v in position0_m], heading0_rad=float(heading0_rad),
        velocity0_m_s=[float(v) for v in velocity0_m_s]))

def read_planar(path: Union[str, os.PathLike]) -> Table:
    """Planar IMU data from a CSV (``t_s, accel_x_m_s2, accel_y_m_s2, gyro_z_rad_s``) or the
    exercise's whitespace ``.dat`` file (t, a_x, a_y, ω_z)."""
    return _table(_core.read_planar(str(path)))

def strapdown(
    imu: TableLike,
    *,
    initial: Optional[Union[TableLike, Mapping[str, Any]]] = None,
    nav_frame: Optional[str] = None,
    gravity_m_s2: Optional[float] = None,
    coning: bool = _D["coning"],
    sculling: bool = _D["sculling"],
    accel_sign: Optional[str] = None,
    scheme: str = _D["scheme"],
    substeps: int = _D["substeps"],
    earth: Optional[str] = None,
    vertical: str = _D["vertical"],
    baro_time_constant_s: float = _D["baro_time_constant_s"],
    earth_gravity: Optional[str] = None,
    baro: Optional[TableLike] = None,
) -> Table:
    """3D strapdown navigation of an IMU table — rates (``accel_*_m_s2``, ``gyro_*_rad_s``) or
    increments (``dv_*_m_s``, ``dtheta_*_rad``) — in a flat-Earth ENU/NED frame, with the exact
    rotation-vector attitude step, two-sample coning and sculling corrections and gravity.

    ``nav_frame`` (``"ENU"``/``"NED"``), ``accel_sign``, ``gravity_m_s2``, ``earth`` and
    ``earth_gravity`` left out are what the tables' descriptions say (``imu.description``: a
    simulated or read table knows its frame), else imukit's defaults (ENU, specific force,
    9.81 m/s², flat); one given that contradicts a description is refused.

    ``initial`` is a truth ``Table`` (its first row is used) or a dict with ``position_m``,
    ``velocity_m_s`` and ``quaternion`` (``[w, x, y, z]``) or ``euler_rad`` (``[yaw, pitch, roll]``);
    by default at rest, level, at the origin. Returns ``t_s, pos_*, vel_*, q_*, yaw_rad, pitch_rad,
    roll_rad``.

    ``scheme="auto"`` (default) takes the best scheme for the input: ``"rk4"`` for rates, ``"coning"``
    for increments or when ``coning``/``sculling`` are switched off. ``"coning"`` (docs/models.md
    §4, second order; rates or increments) or ``"rk4"``
    (fourth order: RK4 with ``substeps`` per interval on quintic-interpolated rates; rates only).

    ``earth="wgs84"`` navigates on the rotating WGS-84 Earth (Earth rate, transport rate, Coriolis,
    normal gravity — or ``earth_gravity="constant"`` for ``gravity_m_s2``): the start needs a
    geodetic position, from a truth Table of a ``wgs84`` scenario (``lat_rad, lon_rad, height_m``)
    or the dict keys ``latitude_deg``, ``longitude_deg``, ``height_m``. ``vertical`` is ``"free"``
    (unstable, as physics says), ``"hold"`` or ``"baro"`` (a third-order loop with time constant
    ``baro_time_constant_s`` on barometer readings: ``baro=sim.baro`` or the IMU table's
    ``baro_height_m`` column). The output adds
    ``lat_rad, lon_rad, height_m``; ``pos_*`` stay in the tangent plane of the truth's origin.

    Each sample is integrated over its own interval (``t_s`` as stamped): jitter and gaps are
    integrated across, and gaps longer than 2.5 median intervals are reported as an
    :class:`ImuWarning`.
    """
    start: dict = {}
    if isinstance(initial, (Table, np.ndarray)) or hasattr(initial, "to_numpy"):  # a truth table or frame
        start["initial_columns"], start["initial_values"] = _table_args("initial", initial)
    elif isinstance(initial, Mapping):
        keys = {"position_m": "position0_m", "velocity_m_s": "velocity0_m_s", "quaternion": "quaternion0",
                "euler_rad": "euler0_rad"}
        scalars = {"latitude_deg": "lat0_deg", "longitude_deg": "lon0_deg", "height_m": "height0_m"}
        unknown = set(initial) - set(keys) - set(scalars)
        if unknown:
            raise ValueError(f"initial: unknown keys {sorted(unknown)}; known: {sorted(keys) + sorted(scalars)}")
        start = {keys[k]: [float(v) for v in value] for k, value in initial.items() if k in keys}
        start.update({scalars[k]: float(v) for k, v in initial.items() if k in scalars})
    elif initial is not None:
        raise TypeError("initial must be a truth Table or a dict")
    nav, notes = _core.strapdown(
        *_table_args("imu", imu), **start,
        nav_frame=nav_frame, gravity_m_s2=None if gravity_m_s2 is None else float(gravity_m_s2),
        coning=bool(coning), sculling=bool(sculling),
        accel_sign=accel_sign, scheme=scheme, substeps=int(substeps), earth=earth, vertical=vertical,
        baro_time_constant_s=float(baro_time_constant_s), earth_gravity=earth_gravity,
        **({} if baro is None else dict(zip(("baro_columns", "baro_values"), _table_args("baro", baro)))),
        described=_described(imu=imu, initial=None if isinstance(initial, Mapping) else initial, baro=baro))
    _emit(notes, stacklevel=2)
    return _table(nav)

class Comparison(NamedTuple):
    """What :func:`compare` returns: the errors over time and their summary. It unpacks as
    ``errors, summary = imukit.compare(truth, estimate)``."""

    errors: Table
    summary: Dict[str, float]

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}={v:.4g}" for k, v in self.summary.items())
        return f"Comparison(errors={self.errors!r}, summary={{{shown}}})"


def compare(truth: TableLike, estimate: TableLike, *, align_heading: bool = False) -> Comparison:
    """Errors of an estimate against truth on the estimate's times: a :class:`Comparison`
    ``(errors, summary)``.

    A navigation estimate (``t_s, pos_*, vel_*, q_*``) gives the Table ``t_s, pos_err_*_m,
    pos_err_m, vel_err_*_m_s, att_err_rad``; an orientation estimate (``t_s, q_w, q_x, q_y, q_z``,
    as ``imukit orient`` writes) gives ``t_s, att_err_rad, heading_err_rad, inclination_err_rad,
    yaw_err_rad, pitch_err_rad, roll_err_rad`` — scored as orientation benchmarks do (BROAD's
    metric): the error rotation's heading and inclination parts beside its angle; rows where the
    reference has no value (NaN quaternion, a gap in its times) or no time are skipped and counted
    (``skipped_rows``). ``align_heading=True`` removes one constant heading offset first (a 6D
    estimate's heading is arbitrary; ``heading_offset_rad`` says how much). The dict holds RMS,
    maximum and final values (``position_rms_m``, ``position_max_m``, ``position_final_m``, …,
    ``attitude_final_rad``, ``heading_rms_rad``, ``inclination_rms_rad``; position and velocity
    only for navigation estimates). Tables whose descriptions say different frames or Earths are
    refused."""
    table, summary = _core.compare(*_table_args("truth", truth), *_table_args("estimate", estimate),
                                   described=_described(truth=truth, estimate=estimate),
                                   align_heading=align_heading)
    return Comparison(_table(table), {str(k): float(v) for k, v in dict(summary).items()})


def fuse(imu: TableLike, gnss: Optional[TableLike], *, scenario: Optional[Union[str, os.PathLike, Mapping[str, Any]]] = None,
         initial: Optional[TableLike] = None, align: Optional[str] = None,
         gate: bool = True,
         odometer: Optional[TableLike] = None, baro: Optional[TableLike] = None,
         nhc_sigma_m_s: Optional[float] = None, covariance_interval_s: Optional[float] = None,
         sensor_errors: Optional[bool] = None, rest_s: Optional[float] = None, smooth: bool = False,
         zupt: bool = False, gnss_adaptive: bool = False,
         imu_model: Optional[Union[str, os.PathLike]] = None, part: Optional[str] = None,
         gnss_horizontal_accuracy_m: Optional[float] = None, gnss_vertical_accuracy_m: Optional[float] = None,
         gnss_velocity_accuracy_m_s: Optional[float] = None,
         gnss_lever_arm_m: Optional[Sequence[float]] = None, gnss_decay_factor: Optional[float] = None,
         gnss_correlation_time_s: Optional[float] = None, gnss_latency_s: Optional[float] = None,
         gnss_uere_m: Optional[float] = None,
         nav_frame: Optional[str] = None, earth: Optional[str] = None, earth_gravity: Optional[str] = None,
         accel_sign: Optional[str] = None, gravity_m_s2: Optional[float] = None) -> Table:
    """Loosely coupled INS/GNSS fusion: a 15-state error-state Kalman filter over IMU rates and
    GNSS fixes (``imukit.simulate(...).gnss``), on the scenario's Earth (flat, or WGS-84 with
    geodetic fixes and ``lat_rad, lon_rad, height_m`` added to the output). The filter's model comes from
    ``scenario`` — the dict or scenario file that made the data: its ``[imu]`` errors, its
    ``[gnss]`` accuracy and lever arm, its ``[odometer]`` and ``[baro]``. The filter starts from
    ``initial``, a truth Table (its first row), or without truth from ``align="gnss"``: position,
    velocity, heading and pitch of the first fix at 3 m/s or more (roll 0), or ``align="static"``
    on the WGS-84 Earth (at rest: levelling and gyrocompassing over the first 60 s), or
    ``align="level"`` (at rest: levelled, heading zero); the estimate begins there. Returns the navigation columns of :func:`strapdown`, their one-sigma
    (``pos_x_sigma_m`` … ``att_z_sigma_rad``), the bias estimates (``accel_bias_x_m_s2`` …
    ``gyro_bias_z_rad_s``) and their one-sigma (``accel_bias_x_sigma_m_s2`` …); ``gate=False`` applies every update (else a chi-square gate rejects
    outliers). A ground vehicle adds ``odometer=sim.odometer`` (forward speed),
    ``nhc_sigma_m_s=0.1`` (the non-holonomic constraints: no sideways or vertical body
    velocity, with each odometer reading or at 10 Hz) and ``baro=sim.baro`` (height).
    ``covariance_interval_s`` (default 0.05; 0: every sample) steps the covariance less often
    than the IMU samples, for speed. ``sensor_errors=True`` also estimates the IMU's scale
    factors, misalignment and gyroscope g-sensitivity (36 states, their one-sigma at the start
    from the part's figures; columns ``accel_scale_factor_x`` … ``gyro_g_sensitivity_z_rad_s_per_m_s2``
    and their ``…_sigma`` added); by default (``None``) they are estimated when the part's figures
    reach 0.5 % (or 1e-5 (rad/s)/(m/s²) of g-sensitivity). ``rest_s=20`` tells the filter the
    vehicle stands still for the first 20 s (zero-velocity and zero-rate updates at every sample:
    the gyroscope biases are calibrated before the drive); by default (``None``) the rest is found
    in the readings (blocks of 0.5 s whose spread and mean stay within the part's noise), and
    ``rest_s=0`` turns it off.

    Without a scenario, ``imu_model`` names the part — a preset (``"stim300"``), a parameter
    file or Kalibr's ``imu.yaml`` — and ``gnss_horizontal_accuracy_m``, ``gnss_vertical_accuracy_m``,
    ``gnss_velocity_accuracy_m_s``, ``gnss_lever_arm_m``, ``gnss_decay_factor`` (or
    ``gnss_correlation_time_s``) and ``gnss_latency_s`` the receiver, as a scenario's ``[gnss]``
    keys of those names (MATLAB gpsSensor's defaults for those left out: the same figures give
    the same estimate; a receiver whose process — decay factor or correlation time — is stated
    has its correlated errors estimated by the filter, one whose process is not is taken as
    white); ``nav_frame``, ``earth``, ``earth_gravity``, ``accel_sign`` and
    ``gravity_m_s2`` say what the tables are in: left out, what the tables' descriptions say
    (a simulated or read table knows its frame), else imukit's defaults (the sign the part's
    profile's). With a scenario, tables or arguments that contradict it are refused. The sample
    rate is the IMU's median.

    Fixes may carry their own accuracy, one-sigma per fix: ``horizontal_accuracy_m`` and
    ``vertical_accuracy_m`` columns (a ROS ``NavSatFix``'s covariance gives them), or
    ``pos_x_sigma_m``, ``pos_y_sigma_m``, ``pos_z_sigma_m`` per axis, replace the receiver's
    figures fix by fix; ``gnss_uere_m`` makes the horizontal one of an NMEA log's
    ``hdop`` column (HDOP × UERE).

    With neither a scenario nor ``imu_model``, the part is learnt from the log: its white noise
    from the quiet stretches (a rest, a foot's stances), its biases an unknown consumer part's
    (docs/your-own-log.md); the sensor-error states are then off unless asked for.

    ``gnss_adaptive=True`` scales the fixes' noise from their innovations (every 8 fixes whose
    normalised innovations lie outside a consistent filter's 99 % range scale it by their mean,
    between the stated accuracy and 5× it): a receiver worse than its figures. Off by default:
    the innovations cannot tell a receiver worse than stated from an IMU worse than modelled.

    ``zupt=True`` applies zero-velocity (and zero-rate) updates wherever the readings show a
    stance — a foot-mounted IMU — by the SHOE detector with the noise the log shows in its quiet
    stretches (the part's when it has too few) and gravity as its accelerometer reads it at rest;
    ``gnss=None`` runs without fixes. Without ``initial``, ``align`` and fixes the filter starts
    levelled over the rest at the start (``align="level"``): heading zero, at the origin, the
    frame the start's own.
    ``smooth=True`` returns the forward–backward (Rauch–Tung–Striebel) smoothed estimate instead:
    each sample's best estimate from all the data, with its one-sigma, in the same columns.

    When the gate rejects ten fixes in a row the filter has lost them: it is reset to the last
    (position, velocity and, moving, heading), counted in the last column ``gnss_resets``, with
    an :class:`ImuWarning`; fixes still rejected after three resets in a row raise ``ImuError``.
    """
    if scenario is not None and imu_model is not None:
        raise ValueError("give scenario= (the data's [imu] and [gnss]) or imu_model= (a part), not both")
    part_keys = dict(imu_model=None if imu_model is None else str(imu_model), part=part,
                     gnss_horizontal_accuracy_m=gnss_horizontal_accuracy_m,
                     gnss_vertical_accuracy_m=gnss_vertical_accuracy_m,
                     gnss_velocity_accuracy_m_s=gnss_velocity_accuracy_m_s,
                     gnss_lever_arm_m=None if gnss_lever_arm_m is None else [float(v) for v in gnss_lever_arm_m],
                     gnss_decay_factor=None if gnss_decay_factor is None else float(gnss_decay_factor),
                     gnss_correlation_time_s=None if gnss_correlation_time_s is None
                     else float(gnss_correlation_time_s),
                     gnss_latency_s=None if gnss_latency_s is None else float(gnss_latency_s),
                     gnss_uere_m=None if gnss_uere_m is None else float(gnss_uere_m),
                     nav_frame=nav_frame, earth=earth, earth_gravity=earth_gravity, accel_sign=accel_sign,
                     gravity_m_s2=None if gravity_m_s2 is None else float(gravity_m_s2))
    if scenario is None:
        source, fmt, base = None, "dict", os.getcwd()
    elif isinstance(scenario, Mapping):
        source, fmt, base = dict(scenario), "dict", os.getcwd()
    else:
        path = Path(scenario)
        try:
            source = path.read_text(encoding="utf-8")
        except OSError as e:
            raise ImuError(f"{path}: {e.strerror or e}") from None
        fmt, base = ("json" if path.suffix.lower() == ".json" else "toml"), str(path.parent)
    aids = {}
    for name, t in (("odometer", odometer), ("baro", baro)):
        if t is not None:
            aids.update(zip((f"{name}_columns", f"{name}_values"), _table_args(name, t)))
    start = (None, None) if initial is None else _table_args("initial", initial)
    # No fixes: a table without columns (the IMU and the other aids alone, e.g. zupt=True).
    fixes = ([], np.zeros((0, 0))) if gnss is None else _table_args("gnss", gnss)
    table, _, _, warnings = _core.fuse(*_table_args("imu", imu), *fixes, *start,
                             source, format=fmt, base_dir=base, gate=bool(gate),
                             align=None if align is None else str(align),
                             nhc_sigma_m_s=None if nhc_sigma_m_s is None else float(nhc_sigma_m_s),
                             covariance_interval_s=None if covariance_interval_s is None else float(covariance_interval_s),
                             sensor_errors=None if sensor_errors is None else bool(sensor_errors),
                             rest_s=None if rest_s is None else float(rest_s), smooth=bool(smooth),
                             zupt=bool(zupt), gnss_adaptive=bool(gnss_adaptive),
                             **aids, **part_keys,
                             described=_described(imu=imu, gnss=gnss, initial=initial, odometer=odometer, baro=baro))
    _emit(warnings)
    fused = _table(table)
    resets = fused["gnss_resets"]
    if len(resets) and resets[-1] > 0:
        _emit([f"the filter lost the fixes (the gate rejected them one after another) and was reset to them "
               f"{int(resets[-1])} time(s) (column gnss_resets): its one-sigma understates its error around them "
               f"(an IMU worse than described: sensor_errors=True, rest_s=; fixes worse than their stated "
               f"accuracy: gnss_adaptive=True)"])
    return fused
