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
(a ``ValueError``) with a message that says what and where.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, Mapping, Optional, Sequence, Union

import numpy as np

from . import _core
from ._core import ImuError

__all__ = [
    "ImuError",
    "Table",
    "Simulation",
    "simulate",
    "monte_carlo",
    "MonteCarlo",
    "ImuSensor",
    "AccelParams",
    "GyroParams",
    "MagParams",
    "allan_deviation",
    "identify_noise",
    "presets",
    "convert",
    "preset_params",
    "loadparams",
    "strapdown",
    "compare",
    "planar_dead_reckon",
    "read_planar",
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
]


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

    def __repr__(self) -> str:
        return f"Table({len(self)} rows: {', '.join(self.columns)})"


@dataclass(frozen=True)
class Simulation:
    """Truth kinematics and IMU readings of a scenario."""

    truth: Table
    imu: Table


def _table(out) -> Table:
    columns, values = out
    return Table(columns, values)


def simulate(scenario: Union[str, os.PathLike, Mapping], *, run: Optional[int] = None) -> Simulation:
    """Runs a scenario: a path to a TOML/JSON scenario file, or a dict with the same keys.

    Relative file paths are taken from the scenario file's folder (for a dict, from the current
    directory). The numbers equal those of ``imukit simulate`` bit for bit. ``run=r`` gives
    Monte Carlo run ``r`` (noise drawn from (seed, r)), the same as file ``r`` of
    ``imukit simulate --runs``.

    >>> sim = simulate({"trajectory": {"type": "builtin", "name": "static"}})
    >>> float(sim.imu["accel_z_m_s2"][0])
    9.81
    """
    if isinstance(scenario, Mapping):
        text = json.dumps(scenario)
        out = _core.simulate_text(text, format="json", origin="scenario dict", base_dir=os.getcwd(), run=run)
    else:
        path = Path(scenario)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as e:
            raise ImuError(f"{path}: {e.strerror or e}") from None
        fmt = "json" if path.suffix.lower() == ".json" else "toml"
        out = _core.simulate_text(text, format=fmt, origin=str(path), base_dir=str(path.parent), run=run)
    truth, imu = out
    return Simulation(truth=_table(truth), imu=_table(imu))


def read_csv(path: Union[str, os.PathLike]) -> Table:
    """Every column of an imukit CSV file (truth, IMU readings, navigation output, errors, Allan
    table) as a :class:`Table`; :class:`ImuError` names the file, row and column of bad input."""
    return _table(_core.read_csv(str(path)))


def builtin_scenarios() -> list:
    """Names of the built-in scenarios."""
    return list(_core.builtin_names())


def builtin_scenario_toml(name: str) -> str:
    """A built-in scenario as an editable TOML text."""
    return _core.builtin_toml(name)


def _times(t_s) -> np.ndarray:
    t = np.ascontiguousarray(t_s, dtype=np.float64)
    if t.ndim != 1:
        raise ValueError(f"t_s must be one-dimensional, got shape {t.shape}")
    return t


def _rows(name: str, x, width: int, n: Optional[int] = None) -> np.ndarray:
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name} must have shape (N, {width}), got {a.shape}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name} has {a.shape[0]} rows, expected {n} (one per time)")
    return a


def _out(out: Optional[np.ndarray]) -> Optional[np.ndarray]:
    """A caller's output buffer, checked to be one the readings can be written into in place."""
    if out is None:
        return None
    if not isinstance(out, np.ndarray) or out.dtype != np.float64 or not out.flags.c_contiguous:
        raise ValueError("out must be a C-contiguous float64 numpy array of shape (N, 9)")
    return out


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
    nav_frame: str = "ENU",
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
    order: int = 6,
    nav_frame: str = "ENU",
    min_speed_m_s: Optional[float] = None,
) -> Table:
    """Truth from sampled positions (N, 3) and attitude by finite differences.

    Attitude: ``euler_rad`` (N, 3) as ``[yaw, pitch, roll]``, or ``quaternion`` (N, 4) as
    ``[w, x, y, z]``, or ``attitude="tangent"`` / ``"level"`` (default level). ``order`` 2 is
    MATLAB's ``gradient`` (for comparison with MATLAB scripts); 4, 6 (default) and 8 use
    Fornberg stencils of that order with one-sided stencils at the ends.
    """
    t = _times(t_s)
    n = t.shape[0]
    return _table(
        _core.truth_from_samples(
            t,
            _rows("position_m", position_m, 3, n),
            euler_rad=None if euler_rad is None else _rows("euler_rad", euler_rad, 3, n),
            quaternion=None if quaternion is None else _rows("quaternion", quaternion, 4, n),
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
    accel_sign: str = "specific-force",
    gravity_m_s2: float = 9.81,
    magnetic_field_ut: Optional[Sequence[float]] = None,
    nav_frame: str = "ENU",
    kind: str = "accel-gyro-mag",
) -> Table:
    """Ideal IMU readings from truth: specific force at the lever arm (body frame, m), body
    rate, magnetic field (navigation frame, µT; MATLAB's default when ``None``)."""
    if not isinstance(truth, Table):
        raise TypeError(f"truth must be an imukit.Table, got {type(truth).__name__}")
    return _table(
        _core.ideal_imu(
            list(truth.columns),
            np.ascontiguousarray(truth.values),
            lever_arm_m=[float(v) for v in lever_arm_m],
            accel_sign=accel_sign,
            gravity_m_s2=float(gravity_m_s2),
            magnetic_field_ut=None if magnetic_field_ut is None else [float(v) for v in magnetic_field_ut],
            nav_frame=nav_frame,
            kind=kind,
        )
    )


def euler_to_quaternion(euler_rad) -> np.ndarray:
    """``[yaw, pitch, roll]`` (N, 3) → ``[w, x, y, z]`` (N, 4), ``q = q_nb``."""
    return _core.euler_to_quaternion(_rows("euler_rad", np.atleast_2d(euler_rad), 3))


def quaternion_to_euler(quaternion) -> np.ndarray:
    """``[w, x, y, z]`` (N, 4) → ``[yaw, pitch, roll]`` (N, 3)."""
    return _core.quaternion_to_euler(_rows("quaternion", np.atleast_2d(quaternion), 4))


def euler_to_dcm(euler_rad) -> np.ndarray:
    """``[yaw, pitch, roll]`` (N, 3) → ``C_nb = Rz·Ry·Rx`` (N, 3, 3)."""
    return _core.euler_to_dcm(_rows("euler_rad", np.atleast_2d(euler_rad), 3))


def dcm_to_euler(dcm) -> np.ndarray:
    """``C_nb`` (N, 3, 3) → ``[yaw, pitch, roll]`` (N, 3)."""
    m = np.ascontiguousarray(dcm, dtype=np.float64)
    return _core.dcm_to_euler(m.reshape(1, 3, 3) if m.ndim == 2 else m)


def quaternion_to_dcm(quaternion) -> np.ndarray:
    """``[w, x, y, z]`` (N, 4) → ``C_nb`` (N, 3, 3)."""
    return _core.quaternion_to_dcm(_rows("quaternion", np.atleast_2d(quaternion), 4))


def dcm_to_quaternion(dcm) -> np.ndarray:
    """``C_nb`` (N, 3, 3) → ``[w, x, y, z]`` (N, 4)."""
    m = np.ascontiguousarray(dcm, dtype=np.float64)
    return _core.dcm_to_quaternion(m.reshape(1, 3, 3) if m.ndim == 2 else m)


@dataclass
class _SensorParams:
    """MATLAB's accelparams/gyroparams/magparams properties (SI units); ``None`` leaves a property
    at its neutral value. ``axes_misalignment`` takes MATLAB's forms (scalar, 3-vector, 3×3, %);
    ``bias_instability_coefficients`` is ``(numerator, denominator)``."""

    measurement_range: Optional[float] = None
    resolution: Optional[float] = None
    constant_bias: Optional[object] = None
    axes_misalignment: Optional[object] = None
    noise_density: Optional[object] = None
    bias_instability: Optional[object] = None
    bias_instability_coefficients: Optional[tuple] = None
    random_walk: Optional[object] = None
    noise_type: Optional[str] = None
    temperature_bias: Optional[object] = None
    temperature_scale_factor: Optional[object] = None

    _MATLAB = {
        "measurement_range": "MeasurementRange", "resolution": "Resolution", "constant_bias": "ConstantBias",
        "axes_misalignment": "AxesMisalignment", "noise_density": "NoiseDensity",
        "bias_instability": "BiasInstability", "random_walk": "RandomWalk", "noise_type": "NoiseType",
        "temperature_bias": "TemperatureBias", "temperature_scale_factor": "TemperatureScaleFactor",
        "acceleration_bias": "AccelerationBias",
    }

    def to_dict(self) -> dict:
        """The parameters under MATLAB's property names (what ``ImuSensor`` and scenario files take)."""
        out = {}
        for field, value in self.__dict__.items():
            if value is None:
                continue
            if field == "bias_instability_coefficients":
                num, den = value
                out["BiasInstabilityCoefficients"] = {"Numerator": list(np.atleast_1d(num).astype(float)),
                                                      "Denominator": list(np.atleast_1d(den).astype(float))}
            else:
                v = np.asarray(value, dtype=float).tolist() if not isinstance(value, str) else value
                out[self._MATLAB[field]] = v
        return out


@dataclass
class AccelParams(_SensorParams):
    """Accelerometer parameters, MATLAB's ``accelparams`` (m/s² units)."""


@dataclass
class GyroParams(_SensorParams):
    """Gyroscope parameters, MATLAB's ``gyroparams`` (rad/s units), with ``acceleration_bias``
    in (rad/s)/(m/s²)."""

    acceleration_bias: Optional[object] = None


@dataclass
class MagParams(_SensorParams):
    """Magnetometer parameters, MATLAB's ``magparams`` (µT units)."""


def _params_json(name: str, params) -> Optional[str]:
    if params is None:
        return None
    if isinstance(params, _SensorParams):
        params = params.to_dict()
    if isinstance(params, Mapping):
        return json.dumps({k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in params.items()})
    raise TypeError(
        f"{name} must be AccelParams/GyroParams/MagParams or a dict of parameters (imukit or MATLAB names), "
        f"got {type(params).__name__}"
    )


class ImuSensor:
    """An IMU simulator shaped like MATLAB's ``imuSensor``.

    >>> imu = ImuSensor("accel-gyro-mag", reference_frame="NED", sample_rate=100,
    ...                 gyroscope={"NoiseDensity": 1e-4}, seed=67)
    >>> accel, gyro, mag = imu(np.zeros((5, 3)), np.zeros((5, 3)), np.tile([1.0, 0, 0, 0], (5, 1)))
    >>> accel[0].tolist()    # MATLAB's sign: gravity minus acceleration, NED
    [0.0, 0.0, 9.81]

    Parameters are dicts with MATLAB's property names (``MeasurementRange``, ``NoiseDensity``,
    ``BiasInstabilityCoefficients={"Numerator": …, "Denominator": …}``, …, SI units) or imukit's
    unit-suffixed keys (``noise_density_rad_s_per_rt_hz``, …); ``preset="NAME"`` starts from a
    preset. ``profile="matlab"`` (the default here, as the class mirrors MATLAB) uses MATLAB's
    conventions: double-sided noise densities, gravity-minus-acceleration accelerometer sign,
    gyroscope AccelerationBias on the raw nav-frame acceleration; ``profile="default"`` uses
    imukit's (single-sided, specific force, body-frame g-sensitivity).

    Calling ``imu(acc, ang_vel, orientation)`` takes nav-frame acceleration without gravity
    (N, 3), nav-frame angular velocity (N, 3), and the orientation as quaternions
    ``[w, x, y, z]`` (N, 4) — MATLAB's navigation-to-body frame rotation, imukit's ``q_nb`` — or as
    MATLAB rotation matrices (N, 3, 3), which rotate navigation-frame vectors into the body frame
    (``C_nbᵀ``). It returns ``(accel, gyro)``, ``(accel, mag)`` or ``(accel, gyro, mag)`` per
    ``imu_type``. The drift state and the seeded noise stream carry over between calls (so one
    call of 2N samples equals two calls of N); ``reset()`` starts over.

    ``out=`` takes a C-contiguous float64 (N, 9) array (accelerometer, gyroscope, magnetometer
    columns; absent sensors zero) that the readings are written into, and the returned arrays
    are views of it: a long run processed in chunks then reuses one buffer instead of
    allocating (and page-faulting) a new one per chunk.
    """

    def __init__(
        self,
        imu_type: str = "accel-gyro",
        *,
        reference_frame: str = "NED",
        sample_rate: float = 100.0,
        temperature: float = 25.0,
        magnetic_field: Optional[Sequence[float]] = None,
        accelerometer: Optional[Mapping] = None,
        gyroscope: Optional[Mapping] = None,
        magnetometer: Optional[Mapping] = None,
        preset: Optional[str] = None,
        seed: int = 0,
        profile: str = "matlab",
        accel_sign: Optional[str] = None,
    ) -> None:
        self._imu = _core.ImuSensor(
            imu_type,
            reference_frame=reference_frame,
            sample_rate=float(sample_rate),
            temperature=float(temperature),
            magnetic_field=None if magnetic_field is None else [float(v) for v in magnetic_field],
            accelerometer=_params_json("accelerometer", accelerometer),
            gyroscope=_params_json("gyroscope", gyroscope),
            magnetometer=_params_json("magnetometer", magnetometer),
            preset=preset,
            seed=int(seed),
            profile=profile,
            accel_sign=accel_sign,
        )

    @property
    def imu_type(self) -> str:
        return self._imu.imu_type

    @property
    def temperature(self) -> float:
        """Temperature of the sensors, °C (may be changed between calls)."""
        return self._imu.temperature

    @temperature.setter
    def temperature(self, value: float) -> None:
        self._imu.temperature = float(value)

    def __call__(self, acc, ang_vel, orientation, *, out: Optional[np.ndarray] = None):
        a = _rows("acc", np.atleast_2d(acc), 3)
        w = _rows("ang_vel", np.atleast_2d(ang_vel), 3, a.shape[0])
        o = np.ascontiguousarray(orientation, dtype=np.float64)
        if o.ndim == 1 and o.shape == (4,) or o.ndim == 2 and o.shape == (3, 3):
            o = o[None]
        if o.ndim == 2 and o.shape[1] == 4:
            rows = self._imu.step(a, w, quaternion=_rows("orientation", o, 4, a.shape[0]), out=_out(out))
        elif o.ndim == 3 and o.shape[1:] == (3, 3):
            if o.shape[0] != a.shape[0]:
                raise ValueError(f"orientation has {o.shape[0]} matrices, expected {a.shape[0]}")
            # MATLAB's rotation matrices take navigation-frame vectors to the body frame: C_nbᵀ.
            rows = self._imu.step(a, w, dcm=np.ascontiguousarray(np.swapaxes(o, 1, 2)), out=_out(out))
        else:
            raise ValueError(f"orientation must have shape (N, 4) or (N, 3, 3), got {o.shape}")
        accel, gyro, mag = rows[:, 0:3], rows[:, 3:6], rows[:, 6:9]
        return {"accel-gyro": (accel, gyro), "accel-mag": (accel, mag)}.get(self.imu_type, (accel, gyro, mag))

    def reset(self) -> None:
        """Back to the initial drift state and the start of the noise stream."""
        self._imu.reset()


def allan_deviation(x, sample_rate_hz: float):
    """Overlapping Allan deviation of rate data at octave τ (MATLAB ``allanvar`` formula).

    ``x`` is (N,) or (N, k); returns ``(tau_s, adev)`` with ``adev`` (T,) or (T, k).
    """
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim not in (1, 2):
        raise ValueError(f"x must be (N,) or (N, k), got shape {a.shape}")
    tau, adev = _core.allan_deviation(a.reshape(a.shape[0], -1), float(sample_rate_hz))
    return tau, (adev[:, 0] if a.ndim == 1 else adev)


def identify_noise(tau_s, adev) -> dict:
    """N (at τ = 1 s on the −½ line), K (at τ = 3 s on the +½ line) and B (floor / 0.664) of an
    Allan curve, with the fitted lines as ``(slope, log10 intercept)``; ``None`` where absent."""
    return _core.identify_noise(np.ascontiguousarray(tau_s, dtype=np.float64), np.ascontiguousarray(adev, dtype=np.float64))


def convert(value: float, unit: str) -> tuple:
    """A datasheet figure in imukit's SI parameter units: ``(value, unit, parameters it fits)``.

    Densities are single-sided (datasheet convention), g = 9.80665 m/s²:
    ``convert(0.15, "°/√h")`` → ``(4.3633e-05, "rad/s/√Hz", "gyroscope noise_density (angle random walk)")``.
    """
    return _core.convert(float(value), unit)


def presets() -> list:
    """Names of the sensor presets (``imukit presets`` lists them with grade and source)."""
    return list(_core.preset_names())


def _toml_to_dict(text: str) -> dict:
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib  # type: ignore[no-redef]
    return tomllib.loads(text)


def preset_params(name: str) -> dict:
    """A preset as a dict: ``name``, ``grade``, ``source`` and ``accelerometer``/``gyroscope``/
    ``magnetometer`` tables with imukit's unit-suffixed keys (usable as ``ImuSensor`` arguments)."""
    return _toml_to_dict(_core.preset_toml(name))


def loadparams(path: Union[str, os.PathLike], part: Optional[str] = None) -> dict:
    """Reads a parameter file — imukit TOML/JSON, or MATLAB ``loadparams`` JSON (``part`` picks one
    of several parts) — into a dict like :func:`preset_params`."""
    return _toml_to_dict(_core.load_params_toml(str(path), part=part))


def planar_dead_reckon(
    t_s,
    accel_x_m_s2,
    accel_y_m_s2,
    gyro_z_rad_s,
    *,
    scheme: str = "trapezoid",
    position0_m: Sequence[float] = (100.0, 100.0),
    heading0_rad: float = 0.0,
    velocity0_m_s: Sequence[float] = (0.0, 0.0),
) -> Table:
    """Planar dead reckoning of a cart (seed 001): body x forward, y left, ω_z counter-clockwise.

    ``scheme="trapezoid"`` (second order, default) or ``"exercise"`` (the exercise's rules
    verbatim; its rotation turns increments by −α, which mirrors left turns into right turns).
    The defaults are the exercise's initial conditions (X₀ = [100, 100], α₀ = 0, v₀ = 0). Returns
    ``t_s, pos_x_m, pos_y_m, yaw_rad, vel_x_m_s, vel_y_m_s, body_vel_x_m_s, body_vel_y_m_s``.
    """
    col = lambda name, x: np.ascontiguousarray(x, dtype=np.float64).ravel()  # noqa: E731
    return _table(_core.planar_dead_reckon(
        _times(t_s), col("accel_x_m_s2", accel_x_m_s2), col("accel_y_m_s2", accel_y_m_s2),
        col("gyro_z_rad_s", gyro_z_rad_s), scheme=scheme,
        position0_m=[float(v) for v in position0_m], heading0_rad=float(heading0_rad),
        velocity0_m_s=[float(v) for v in velocity0_m_s]))


def read_planar(path: Union[str, os.PathLike]) -> Table:
    """Planar IMU data from a CSV (``t_s, accel_x_m_s2, accel_y_m_s2, gyro_z_rad_s``) or the
    exercise's whitespace ``.dat`` file (t, a_x, a_y, ω_z)."""
    return _table(_core.read_planar(str(path)))


def strapdown(
    imu: Table,
    *,
    initial: Optional[Union[Table, Mapping]] = None,
    nav_frame: str = "ENU",
    gravity_m_s2: float = 9.81,
    coning: bool = True,
    sculling: bool = True,
    accel_sign: str = "specific-force",
    scheme: str = "coning",
    substeps: int = 4,
) -> Table:
    """3D strapdown navigation of an IMU table — rates (``accel_*_m_s2``, ``gyro_*_rad_s``) or
    increments (``dv_*_m_s``, ``dtheta_*_rad``) — in a flat-Earth ENU/NED frame, with the exact
    rotation-vector attitude step, two-sample coning and sculling corrections and gravity.

    ``initial`` is a truth ``Table`` (its first row is used) or a dict with ``position_m``,
    ``velocity_m_s`` and ``quaternion`` (``[w, x, y, z]``) or ``euler_rad`` (``[yaw, pitch, roll]``);
    by default at rest, level, at the origin. Returns ``t_s, pos_*, vel_*, q_*, yaw_rad, pitch_rad,
    roll_rad``.

    ``scheme="coning"`` (default, DESIGN §6, second order; rates or increments) or ``"rk4"``
    (fourth order: RK4 with ``substeps`` per interval on quintic-interpolated rates; rates only).
    """
    if not isinstance(imu, Table):
        raise TypeError(f"imu must be an imukit.Table, got {type(imu).__name__}")
    pos, vel, quat = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]
    if isinstance(initial, Table):
        pos = [float(initial[f"pos_{a}_m"][0]) for a in "xyz"]
        vel = [float(initial[f"vel_{a}_m_s"][0]) for a in "xyz"]
        quat = [float(initial[c][0]) for c in ("q_w", "q_x", "q_y", "q_z")]
    elif isinstance(initial, Mapping):
        pos = [float(v) for v in initial.get("position_m", pos)]
        vel = [float(v) for v in initial.get("velocity_m_s", vel)]
        if "euler_rad" in initial:
            quat = euler_to_quaternion([initial["euler_rad"]])[0].tolist()
        else:
            quat = [float(v) for v in initial.get("quaternion", quat)]
    elif initial is not None:
        raise TypeError("initial must be a truth Table or a dict")
    return _table(_core.strapdown(
        list(imu.columns), np.ascontiguousarray(imu.values), position0_m=pos, velocity0_m_s=vel, quaternion0=quat,
        nav_frame=nav_frame, gravity_m_s2=float(gravity_m_s2), coning=bool(coning), sculling=bool(sculling),
        accel_sign=accel_sign, scheme=scheme, substeps=int(substeps)))


def compare(truth: Table, estimate: Table):
    """Errors of an estimate against truth on the estimate's times: returns ``(errors, summary)``.

    A navigation estimate (``t_s, pos_*, vel_*, q_*``) gives the Table ``t_s, pos_err_*_m,
    pos_err_m, vel_err_*_m_s, att_err_rad``; an orientation estimate (``t_s, q_w, q_x, q_y, q_z``,
    as ``imukit orient`` writes) gives ``t_s, att_err_rad, yaw_err_rad, pitch_err_rad,
    roll_err_rad``. The dict holds RMS, maximum and final values (``position_rms_m``,
    ``position_max_m``, ``position_final_m``, …, ``attitude_final_rad``; attitude only for
    orientation estimates)."""
    table, summary = _core.compare(list(truth.columns), np.ascontiguousarray(truth.values),
                                   list(estimate.columns), np.ascontiguousarray(estimate.values))
    return _table(table), dict(summary)


def truth_from_body_rates(
    t_s,
    accel_body_m_s2,
    omega_body_rad_s,
    *,
    position0_m: Sequence[float] = (0.0, 0.0, 0.0),
    velocity0_m_s: Sequence[float] = (0.0, 0.0, 0.0),
    euler0_rad: Sequence[float] = (0.0, 0.0, 0.0),
    nav_frame: str = "ENU",
) -> Table:
    """Truth from body-frame acceleration (kinematic, no gravity) and angular velocity, as MATLAB's
    ``kinematicTrajectory`` builds it: exact rotation-vector attitude step,
    ``p ← p + vΔt + ½aΔt²``, the state before each update at each sample (first order)."""
    t = _times(t_s)
    n = t.shape[0]
    return _table(_core.truth_from_body_rates(
        t, _rows("accel_body_m_s2", accel_body_m_s2, 3, n), _rows("omega_body_rad_s", omega_body_rad_s, 3, n),
        position0_m=[float(v) for v in position0_m], velocity0_m_s=[float(v) for v in velocity0_m_s],
        euler0_rad=[float(v) for v in euler0_rad], nav_frame=nav_frame))


def truth_from_waypoints(t_s, time_s, position_m, *, velocity_m_s=None, euler_rad=None, nav_frame: str = "ENU") -> Table:
    """Exact truth at ``t_s`` of a waypoint trajectory (like MATLAB's waypointTrajectory): a natural
    cubic spline through ``position_m`` (N, 3) at ``time_s`` (N,), clamped to ``velocity_m_s`` when it
    has 2 rows (start, end) or through all of them when it has one row per waypoint; the attitude is
    tangent, or a spline through ``euler_rad`` (N, 3) ``[yaw, pitch, roll]``. With one velocity row per
    waypoint each interval is a quintic Hermite polynomial, so the path stays C²."""
    knots = _times(time_s)
    n = knots.shape[0]
    return _table(_core.truth_from_waypoints(
        _times(t_s), knots, _rows("position_m", position_m, 3, n),
        velocity_m_s=None if velocity_m_s is None else _rows("velocity_m_s", velocity_m_s, 3),
        euler_rad=None if euler_rad is None else _rows("euler_rad", euler_rad, 3, n), nav_frame=nav_frame))


from ._monte_carlo import MonteCarlo, monte_carlo  # noqa: E402  (needs Table above)
from ._orientation import (  # noqa: E402
    AhrsFilter,
    ComplementaryFilter,
    ImuFilter,
    MadgwickFilter,
    MahonyFilter,
    ecompass,
    quaternion_distance,
)
