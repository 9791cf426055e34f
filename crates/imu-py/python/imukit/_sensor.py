"""Realistic sensors: MATLAB-shaped :class:`ImuSensor` and parameter classes, presets,
parameter files, datasheet units, Allan deviation."""
from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np

from . import _core
from ._convert import _out, _rows


def _matlab_name(field: str) -> str:
    """MATLAB's property name of a parameter field: ``noise_density`` → ``NoiseDensity``."""
    return "".join(part.title() for part in field.split("_"))


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
                out[_matlab_name(field)] = v
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

def _params(params):
    """Parameters as the core takes them: a dict (the core checks names and values)."""
    return params.to_dict() if isinstance(params, _SensorParams) else params

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
    (``C_nbᵀ``; a matrix that is not a rotation to 1e-6 is refused); without an orientation the
    body is level, as in MATLAB. Non-finite inputs are refused, naming the argument and row, as
    MATLAB refuses them. It returns ``(accel, gyro)``, ``(accel, mag)`` or ``(accel, gyro, mag)`` per
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
        accelerometer: Optional[Union[Mapping[str, Any], "AccelParams"]] = None,
        gyroscope: Optional[Union[Mapping[str, Any], "GyroParams"]] = None,
        magnetometer: Optional[Union[Mapping[str, Any], "MagParams"]] = None,
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
            accelerometer=_params(accelerometer),
            gyroscope=_params(gyroscope),
            magnetometer=_params(magnetometer),
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

    def __call__(self, acc, ang_vel, orientation=None, *, out: Optional[np.ndarray] = None):
        a = _rows("acc", acc)
        w = _rows("ang_vel", ang_vel)
        if orientation is None:  # MATLAB: without an orientation the body is level (identity)
            orientation = np.tile([1.0, 0.0, 0.0, 0.0], (a.shape[0], 1))
        o = np.ascontiguousarray(orientation, dtype=np.float64)
        if o.ndim == 1 and o.shape == (4,) or o.ndim == 2 and o.shape == (3, 3):
            o = o[None]
        if o.ndim == 2:
            rows = self._imu.step(a, w, quaternion=o, out=_out(out))
        elif o.ndim == 3:
            # MATLAB's rotation matrices (nav → body, C_nbᵀ), as the core takes them.
            rows = self._imu.step(a, w, dcm=o, out=_out(out))
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
    tau, adev = _core.allan_deviation(a[:, None] if a.ndim == 1 else a, float(sample_rate_hz))
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

def kalibr_yaml(name: str, *, rate_hz: float = _core.DEFAULTS["kalibr_rate_hz"],
                topic: str = _core.DEFAULTS["kalibr_topic"]) -> str:
    """A preset as Kalibr's ``imu.yaml`` text (as ``imukit presets NAME --format kalibr``): the
    densities in Kalibr's single-sided convention, the random walk a bias instability implies
    where the part gives none, each choice in the file's comments. ``rate_hz`` is the logger's."""
    return _core.preset_kalibr_yaml(name, rate_hz=rate_hz, topic=topic)

def loadparams(path: Union[str, os.PathLike], part: Optional[str] = None) -> dict:
    """Reads a parameter file — imukit TOML/JSON, or MATLAB ``loadparams`` JSON (``part`` picks one
    of several parts) — into a dict like :func:`preset_params`."""
    text, skipped = _core.load_params_toml(str(path), part=part)
    for what in skipped:  # MATLAB's loadparams skips these too
        warnings.warn(what, stacklevel=2)
    return _toml_to_dict(text)
