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
from ._warning import _emit

_S = _core.DEFAULTS["imu_sensor"]  # MATLAB imuSensor's defaults, as the library states them


def _matlab_name(field: str) -> str:
    """MATLAB's property name of a parameter field: ``noise_density`` → ``NoiseDensity``."""
    return "".join(part.title() for part in field.split("_"))


@dataclass
class _SensorParams:
    """MATLAB's accelparams/gyroparams/magparams properties (SI units); ``None`` leaves a property
    at its neutral value. ``axes_misalignment`` takes MATLAB's forms (scalar, 3-vector, 3×3, %);
    ``bias_instability_coefficients`` is ``(numerator, denominator)``. Beyond MATLAB, the sensing
    element's ``scale_factor_nonlinearity`` (K₂ in 1/unit: an axis reads ``u + K₂u²``) and
    ``scale_factor_asymmetry`` (%: positive inputs read ``(1 + ε/2)u``, negative ``(1 − ε/2)u``),
    which rectify vibration into a bias."""

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
    scale_factor_nonlinearity: Optional[object] = None
    scale_factor_asymmetry: Optional[object] = None

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
    in (rad/s)/(m/s²) and the g²-sensitivity ``acceleration_squared_bias`` in (rad/s)/(m/s²)²
    (on the acceleration along the same axis)."""

    acceleration_bias: Optional[object] = None
    acceleration_squared_bias: Optional[object] = None

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
        imu_type: str = _S["imu_type"],
        *,
        reference_frame: str = _S["reference_frame"],
        sample_rate: float = _S["sample_rate"],
        temperature: float = _S["temperature"],
        magnetic_field: Optional[Sequence[float]] = None,
        accelerometer: Optional[Union[Mapping[str, Any], "AccelParams"]] = None,
        gyroscope: Optional[Union[Mapping[str, Any], "GyroParams"]] = None,
        magnetometer: Optional[Union[Mapping[str, Any], "MagParams"]] = None,
        preset: Optional[str] = None,
        seed: int = 0,
        profile: str = _S["profile"],
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

class Identification:
    """Noise terms of a static log (:func:`identify`).

    ``terms`` is a list of dicts, one per column and term (``column``, ``term``, ``symbol``,
    ``value``, ``lower``, ``upper``, ``resolved``, ``needs_record_s``, ``unit``,
    ``datasheet_unit``, ``datasheet_value``): ``pandas.DataFrame(ident.terms)`` tabulates them.
    A term not resolved has ``value`` as fitted, ``lower`` 0 and ``upper`` its 95 % bound.
    ``tau_s`` (T,) and ``adev``, ``lower95``, ``upper95``, ``edf``, ``fit`` (T, k) are the curves;
    ``params_toml`` the part as an imukit parameter file, ``kalibr_yaml`` as Kalibr's imu.yaml;
    ``filter_noise`` the fusion filter's ``(sensor, white, bias drift)`` for it.
    ``scaled_terms`` lists the terms with a time scale a column's curve supports (IEEE Std 952's
    exponentially correlated ``markov`` noise and ``sinusoid``): ``value`` is the Markov noise's
    stationary σ or the sinusoid's peak, ``scale`` its correlation time (s) or frequency (Hz),
    each with its 95 % interval, and ``chi2_drop`` how much better it made the fit than the
    ``criterion`` it had to beat (``4 ln n`` for ``n`` points).
    ``mean_at_rest`` maps each column to its mean and that mean's one-sigma (a gyroscope's
    turn-on bias, written as ``constant_bias`` in ``params_toml``); ``warnings`` lists what
    :func:`identify` also warned about (:class:`ImuWarning`): a log that moves (where), a fit
    whose reduced χ² exceeds 3 (the intervals are then widened by its square root, and the τ it
    misses named)."""

    def __init__(self, columns, raw: dict) -> None:
        self.columns = list(columns)
        self.tau_s = raw["tau_s"]
        self.adev, self.lower95, self.upper95 = raw["adev"], raw["lower95"], raw["upper95"]
        self.edf, self.fit = raw["edf"], raw["fit"]
        self.reduced_chi2 = dict(zip(self.columns, raw["reduced_chi2"]))
        self.mean_at_rest = dict(zip(self.columns, raw["mean_at_rest"]))
        self.warnings = list(raw["warnings"])
        self.samples = raw["samples"]
        keys = ("column", "term", "symbol", "value", "lower", "upper", "resolved", "needs_record_s",
                "unit", "datasheet_unit", "datasheet_factor")
        self.terms = []
        for row in raw["terms"]:
            d = dict(zip(keys, row))
            factor = d.pop("datasheet_factor")
            shown = d["value"] if d["resolved"] else d["upper"]
            d["datasheet_value"] = None if factor is None else shown / factor
            self.terms.append(d)
        self.scaled_terms = [dict(row) for row in raw["scaled_terms"]]
        self.params_toml = raw["params_toml"]
        self.kalibr_yaml = raw["kalibr_yaml"]
        self.filter_noise = raw["filter_noise"]

    def term(self, column: str, term: str) -> dict:
        """The row of ``term`` (``white_noise``, ``bias_instability``, ``random_walk``,
        ``quantization``, ``rate_ramp`` or its symbol N, B, K, Q, R) of ``column``."""
        for d in self.terms:
            if d["column"] == column and term in (d["term"], d["symbol"]):
                return d
        raise KeyError(f"no term {term!r} of column {column!r}")

    def __repr__(self) -> str:
        resolved = sum(d["resolved"] for d in self.terms)
        return f"Identification({len(self.columns)} columns, {resolved} of {len(self.terms)} terms resolved)"


def identify(data, sample_rate_hz: Optional[float] = None, *, columns=None, kalibr_inflation: float = _core.DEFAULTS["kalibr_inflation"],
             kalibr_topic: str = _core.DEFAULTS["kalibr_topic"], **read_options) -> "Identification":
    """Noise identification of a static log, as ``imukit identify`` does it.

    ``data`` is a path (any format :func:`imukit.read` takes; ``read_options`` such as ``map=`` or
    ``topic=`` go to it), a table or mapping with ``t_s`` (the rate from its times), or an (N,) or
    (N, k) array with ``sample_rate_hz``. ``columns`` default to every ``gyro_*``/``accel_*``
    column. Each term comes with its 95 % interval, or, not resolved, its bound and the record
    length that would resolve it."""
    source = "array"
    if isinstance(data, (str, os.PathLike)):
        source = os.path.basename(os.fspath(data))
        from . import read as _read
        data = _read(data, **read_options)
    if isinstance(data, np.ndarray):
        if sample_rate_hz is None:
            raise ValueError("an array needs sample_rate_hz")
        a = np.ascontiguousarray(data, dtype=np.float64)
        a = a[:, None] if a.ndim == 1 else a
        names = list(columns) if columns is not None else [f"column {k}" for k in range(a.shape[1])]
    else:
        from ._table import Table
        table = Table.of(data)
        names = list(columns) if columns is not None else [
            c for c in table.keys() if c.startswith(("gyro_", "accel_"))]
        if not names:
            raise ValueError("no gyro_* or accel_* columns: name them with columns=")
        a = np.column_stack([np.asarray(table[c], dtype=np.float64) for c in names])
        if sample_rate_hz is None:
            t = np.asarray(table["t_s"], dtype=np.float64)
            if t.size < 2 or not t[-1] > t[0]:
                raise ValueError("t_s needs at least 2 increasing times to give the sample rate")
            sample_rate_hz = (t.size - 1) / (t[-1] - t[0])
    raw = _core.identify(np.ascontiguousarray(a), float(sample_rate_hz), names, source,
                         kalibr_inflation=float(kalibr_inflation), kalibr_topic=kalibr_topic)
    ident = Identification(names, raw)
    _emit(ident.warnings)
    return ident

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


def chain_response(chain: Mapping[str, Any], rate_hz: float, frequencies_hz) -> "Table":
    """A part's signal chain in closed form (docs/sensors.md, "The signal chain"): ``chain`` the
    ``[imu.chain]`` table as a dict (``internal_rate_hz`` or a rate per sensor, each low-pass), read at
    ``rate_hz``; a row per frequency of ``frequencies_hz`` (Hz) with the alias it appears at in
    the output (``alias_hz``) and per sensor the filter's gain, phase (rad) and group delay (s):
    ``accel_gain``, ``accel_phase_rad``, ``accel_delay_s``, ``gyro_…``, ``mag_…``.

    >>> t = chain_response({"internal_rate_hz": 8000,
    ...                     "gyroscope": {"filter": "butterworth", "order": 2, "cutoff_hz": 200}},
    ...                    100, [40.0, 200.0, 1130.0])
    >>> [round(float(g), 4) for g in t["gyro_gain"]], [float(f) for f in t["alias_hz"]]
    ([0.9992, 0.7071, 0.0274], [40.0, 0.0, 30.0])
    """
    from ._table import Table
    columns, values = _core.chain_response(dict(chain), float(rate_hz),
                                           [float(f) for f in np.atleast_1d(frequencies_hz)])
    return Table(columns, values)


def spectrum(readings: Any, columns: Optional[list] = None, *,
             segment_s: float = _core.DEFAULTS["segment_s"]) -> "Table":
    """The power spectral density of readings, as ``imukit spectrum`` computes it (Welch:
    segments of ``segment_s`` half overlapping, each less its mean under a periodic Hann window,
    one-sided, so the density integrates to the variance): a Table ``frequency_hz,
    psd_<column>…`` in the column's unit squared per Hz. ``columns`` defaults to every
    gyroscope and accelerometer column; ``readings`` is a table with ``t_s`` or a file's path.
    :func:`imukit.chain_response` says where a part's chain puts a vibration."""
    if isinstance(readings, (str, os.PathLike)):
        from ._truth import read
        source, table = str(readings), read(readings)
    else:
        from ._table import Table
        source, table = "readings", Table.of(readings, "readings")
    names = list(columns) if columns is not None else [
        c for c in ("gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s", "accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2")
        if c in table.columns]
    if not names:
        raise _core.ImuError(f"{source}: no gyro_* or accel_* columns: name the columns")
    from ._convert import _table_args
    from ._table import Table as _Table
    out_columns, values = _core.spectrum(*_table_args("readings", table), names, float(segment_s), source)
    return _Table(out_columns, values)
