"""Orientation from IMU readings, shaped like MATLAB's ``ecompass``, ``imufilter``,
``ahrsfilter`` and ``complementaryFilter`` (plus Madgwick and Mahony).

Orientations are quaternions ``[w, x, y, z]`` = imukit's ``q_nb`` = MATLAB's orientation
quaternion, or with ``orientation_format="rotmat"`` MATLAB's rotation matrices (nav → body,
``C_nbᵀ``). Frame and accelerometer sign follow imukit's conventions unless told otherwise, as
``imukit orient`` does: ENU (FLU body axes) and specific force (``+g`` up at rest). MATLAB's —
NED and its accelerometer sign (gravity minus acceleration) — are one keyword away,
``conventions="matlab"``; ``reference_frame`` and ``accel_sign`` override either.
Filters keep their state between calls (a run in chunks equals the run whole); ``reset()``
starts over. The equations are in the Rust docs of ``imu_core::orientation``.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from . import _core

# The library's defaults (`imukit._core.DEFAULTS`): each filter's settings by MATLAB name.
_F = _core.DEFAULTS["filters"]
_IMU, _AHRS = _F["imufilter"], _F["ahrsfilter"]
_IPN_DIAG = np.array(_core.DEFAULTS["initial_process_noise"])


def _rows(name: str, x, n: Optional[int] = None) -> np.ndarray:
    a = np.ascontiguousarray(np.atleast_2d(x), dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3), got {np.shape(x)}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name} has {a.shape[0]} rows, expected {n}")
    return a


def _format(q: np.ndarray, orientation_format: str) -> np.ndarray:
    if orientation_format == "quaternion":
        return q
    if orientation_format == "rotmat":
        return np.ascontiguousarray(np.swapaxes(_core.quaternion_to_dcm(q), 1, 2))
    raise ValueError(f'orientation_format must be "quaternion" or "rotmat", got {orientation_format!r}')


def ecompass(accel, mag, *, conventions: Optional[str] = None, reference_frame: Optional[str] = None,
             accel_sign: Optional[str] = None, orientation_format: str = "quaternion") -> np.ndarray:
    """Orientation from accelerometer and magnetometer readings (N, 3), one per row, yaw from
    magnetic north (MATLAB ``ecompass``).

    >>> import numpy as np
    >>> q = ecompass([[0.0, 0.0, 9.81]], [[0.0, 27.0, -16.0]])   # ENU: level, facing magnetic east
    >>> float(quaternion_distance(q[0], [1.0, 0.0, 0.0, 0.0])[0]) < 1e-12
    True
    >>> q = ecompass([[0.0, 0.0, 9.81]], [[27.0, 0.0, 16.0]], conventions="matlab")   # NED: north
    >>> np.round(q, 12).tolist()
    [[1.0, 0.0, 0.0, 0.0]]
    """
    a = _rows("accel", accel)
    m = _rows("mag", mag, a.shape[0])
    q = _core.ecompass(a, m, conventions=conventions, reference_frame=reference_frame, accel_sign=accel_sign)
    return _format(q, orientation_format)


def quaternion_distance(q1, q2) -> np.ndarray:
    """Angle (rad) of the rotation between orientations row by row (MATLAB ``dist``); (N, 4)
    arrays or single quaternions."""
    a = np.ascontiguousarray(np.atleast_2d(q1), dtype=np.float64)
    b = np.ascontiguousarray(np.atleast_2d(q2), dtype=np.float64)
    if a.shape[0] == 1 and b.shape[0] > 1:
        a = np.ascontiguousarray(np.repeat(a, b.shape[0], axis=0))
    if b.shape[0] == 1 and a.shape[0] > 1:
        b = np.ascontiguousarray(np.repeat(b, a.shape[0], axis=0))
    return _core.quaternion_distance(a, b)


class _Filter:
    """Shared machinery: one ``_core.OrientationFilter`` and MATLAB's call shape."""

    _kind = ""

    def __init__(self, sample_rate: float, conventions: Optional[str], reference_frame: Optional[str],
                 accel_sign: Optional[str], magnetometer: bool, settings: dict, orientation_format: str,
                 initial_process_noise=None, smooth: bool = False) -> None:
        if orientation_format not in ("quaternion", "rotmat"):
            raise ValueError(f'orientation_format must be "quaternion" or "rotmat", got {orientation_format!r}')
        self.orientation_format = orientation_format
        self.sample_rate = float(sample_rate)
        self._magnetometer = magnetometer
        self._filter = _core.OrientationFilter(
            self._kind, sample_rate=self.sample_rate, conventions=conventions, reference_frame=reference_frame,
            accel_sign=accel_sign,
            magnetometer=magnetometer, settings=[(k, float(v)) for k, v in settings.items()],
            initial_process_noise=initial_process_noise, smooth=smooth)

    def _run(self, accel, gyro, mag, t_s, return_angular_velocity: bool):
        a = _rows("accel", accel)
        g = _rows("gyro", gyro, a.shape[0])
        m = None if mag is None else _rows("mag", mag, a.shape[0])
        t = None if t_s is None else np.ascontiguousarray(t_s, dtype=np.float64).reshape(-1)
        q, w = self._filter.step(a, g, m, t)
        q = _format(q, self.orientation_format)
        return (q, w) if return_angular_velocity else q

    def reset(self) -> None:
        """Back to the state before the first sample."""
        self._filter.reset()

    @property
    def reference_frame(self) -> str:
        """The navigation frame of the orientations, ``"ENU"`` or ``"NED"``."""
        return self._filter.reference_frame


def _diagonal(ipn, states: int):
    if ipn is None:
        return None
    a = np.asarray(ipn, dtype=np.float64)
    if a.shape == (states, states):
        if np.any(a - np.diag(np.diag(a))):
            raise ValueError("initial_process_noise: only a diagonal matrix is supported")
        a = np.diag(a)
    if a.shape != (states,):
        raise ValueError(f"initial_process_noise must be ({states},) or ({states}, {states}), got {a.shape}")
    return [float(v) for v in a]


class ImuFilter(_Filter):
    """MATLAB's ``imufilter``: an error-state Kalman filter fusing accelerometer and gyroscope
    (orientation, gyroscope offset and linear acceleration errors). Noise settings are
    variances, as MATLAB's properties; the defaults are MATLAB's.

    >>> import numpy as np
    >>> fuse = ImuFilter(sample_rate=100)
    >>> q = fuse(np.tile([0.0, 0.0, 9.81], (5, 1)), np.zeros((5, 3)))
    >>> q.shape, np.allclose(q, [1, 0, 0, 0])
    ((5, 4), True)
    """

    _kind = "imufilter"
    _states = 9
    DEFAULT_INITIAL_PROCESS_NOISE = np.diag(_IPN_DIAG[:9])

    def __init__(self, sample_rate: float = _IMU["SampleRate"], *, conventions: Optional[str] = None,
                 reference_frame: Optional[str] = None, decimation_factor: int = int(_IMU["DecimationFactor"]),
                 accelerometer_noise: float = _IMU["AccelerometerNoise"],
                 gyroscope_noise: float = _IMU["GyroscopeNoise"],
                 gyroscope_drift_noise: float = _IMU["GyroscopeDriftNoise"],
                 linear_acceleration_noise: float = _IMU["LinearAccelerationNoise"],
                 linear_acceleration_decay_factor: float = _IMU["LinearAccelerationDecayFactor"],
                 initial_process_noise=None,
                 orientation_format: str = "quaternion", accel_sign: Optional[str] = None, **magnetic) -> None:
        settings = dict(DecimationFactor=decimation_factor, AccelerometerNoise=accelerometer_noise,
                        GyroscopeNoise=gyroscope_noise, GyroscopeDriftNoise=gyroscope_drift_noise,
                        LinearAccelerationNoise=linear_acceleration_noise,
                        LinearAccelerationDecayFactor=linear_acceleration_decay_factor, **magnetic)
        super().__init__(sample_rate, conventions, reference_frame, accel_sign, self._kind == "ahrsfilter",
                         settings, orientation_format, _diagonal(initial_process_noise, self._states))
        self.decimation_factor = int(decimation_factor)

    def __call__(self, accel, gyro, *, t_s=None, return_angular_velocity: bool = False):
        """Readings (N, 3) → orientations (N / decimation_factor of them), and with
        ``return_angular_velocity=True`` also the bias-corrected body rates (M, 3).

        ``t_s`` (N,), the readings' times in seconds, integrates each sample over its own
        interval (the first from the previous call's last time), so jitter and gaps cost only
        what the motion did meanwhile; without it the filter runs at ``sample_rate``, as
        MATLAB's."""
        return self._run(accel, gyro, None, t_s, return_angular_velocity)

    @property
    def gyroscope_offset(self) -> np.ndarray:
        """The current gyroscope offset (bias) estimate, rad/s."""
        return np.array(self._filter.gyroscope_offset)


class AhrsFilter(ImuFilter):
    """MATLAB's ``ahrsfilter``: ``ImuFilter`` plus the magnetometer and magnetic disturbance
    (12 error states); yaw from magnetic north. ``fuse(accel, gyro, mag)``."""

    _kind = "ahrsfilter"
    _states = 12
    DEFAULT_INITIAL_PROCESS_NOISE = np.diag(_IPN_DIAG)

    def __init__(self, sample_rate: float = _AHRS["SampleRate"], *,
                 magnetometer_noise: float = _AHRS["MagnetometerNoise"],
                 magnetic_disturbance_noise: float = _AHRS["MagneticDisturbanceNoise"],
                 magnetic_disturbance_decay_factor: float = _AHRS["MagneticDisturbanceDecayFactor"],
                 expected_magnetic_field_strength: float = _AHRS["ExpectedMagneticFieldStrength"],
                 **kwargs) -> None:
        super().__init__(sample_rate, MagnetometerNoise=magnetometer_noise,
                         MagneticDisturbanceNoise=magnetic_disturbance_noise,
                         MagneticDisturbanceDecayFactor=magnetic_disturbance_decay_factor,
                         ExpectedMagneticFieldStrength=expected_magnetic_field_strength, **kwargs)

    def __call__(self, accel, gyro, mag, *, t_s=None,  # type: ignore[override]
                 return_angular_velocity: bool = False):
        """Readings (N, 3) each → orientations, and optionally body rates; ``t_s`` as for
        :class:`ImuFilter`."""
        return self._run(accel, gyro, mag, t_s, return_angular_velocity)


class _SimpleFilter(_Filter):
    def __call__(self, accel, gyro, mag=None, *, t_s=None, return_angular_velocity: bool = False):
        """Readings (N, 3) (``mag`` when built with ``has_magnetometer=True``) → orientations
        (N, 4), and optionally body rates; ``t_s`` (N,), the readings' times in seconds,
        integrates each sample over its own interval (else ``1/sample_rate``)."""
        if (mag is None) == self._magnetometer:
            raise ValueError("give mag readings exactly when the filter has a magnetometer "
                             f"(has_magnetometer={self._magnetometer})")
        return self._run(accel, gyro, mag, t_s, return_angular_velocity)


class ComplementaryFilter(_SimpleFilter):
    """MATLAB's ``complementaryFilter``: gyroscope integration with a fraction of the tilt error
    (``accelerometer_gain``) and heading error (``magnetometer_gain``) removed per sample."""

    _kind = "complementary"

    def __init__(self, sample_rate: float = _F["complementary"]["SampleRate"], *,
                 accelerometer_gain: float = _F["complementary"]["AccelerometerGain"],
                 magnetometer_gain: float = _F["complementary"]["MagnetometerGain"], has_magnetometer: bool = True, conventions: Optional[str] = None,
                 reference_frame: Optional[str] = None, orientation_format: str = "quaternion",
                 accel_sign: Optional[str] = None) -> None:
        super().__init__(sample_rate, conventions, reference_frame, accel_sign, has_magnetometer,
                         dict(AccelerometerGain=accelerometer_gain, MagnetometerGain=magnetometer_gain),
                         orientation_format)


class MadgwickFilter(_SimpleFilter):
    """Madgwick's gradient-descent filter; ``beta`` defaults to 0.033 (0.041 with a
    magnetometer)."""

    _kind = "madgwick"

    def __init__(self, sample_rate: float = _F["madgwick"]["SampleRate"], *, beta: Optional[float] = None, has_magnetometer: bool = False,
                 conventions: Optional[str] = None, reference_frame: Optional[str] = None,
                 orientation_format: str = "quaternion", accel_sign: Optional[str] = None) -> None:
        settings = {} if beta is None else dict(Beta=beta)
        super().__init__(sample_rate, conventions, reference_frame, accel_sign, has_magnetometer, settings,
                         orientation_format)


class RobustFilter(_SimpleFilter):
    """imukit's own attitude (and, with ``has_magnetometer=True``, heading) filter, the default of
    ``imukit orient``: the gyroscope's integral, an inclination correction from the accelerometer
    low-passed in an almost inertial frame (slowed while the body accelerates hard for long), a
    heading correction from the magnetometer (held while a magnet is near), and a gyroscope bias
    learnt at rest and in motion. ``status`` holds, for the last call's estimates, the bias
    estimate (rad/s) and the flags: a dict of ``gyro_bias`` (M, 3), ``at_rest``,
    ``accel_rejected`` (correction slowed) and ``mag_disturbed`` (M,) booleans.

    ``accelerometer_time_constant`` and ``magnetometer_time_constant`` (s) are the two a user
    tunes; ``settings`` takes any other by the name ``imukit orient --filter robust --param``
    uses (angles in rad, times in s). Unset, each is the library's default.

    ``smooth=True`` is for logs processed after the fact (``imukit orient --smooth``): each call
    is a whole run, filtered forward, then backward from where the forward pass ended, and the
    two averaged; nothing carries over between calls.

    >>> import numpy as np
    >>> t = np.arange(500) / 100.0
    >>> gyro = np.column_stack([np.zeros(500), np.zeros(500), np.full(500, 0.2)])   # 0.2 rad/s yaw
    >>> q = RobustFilter(100.0, smooth=True)(np.tile([0.0, 0.0, 9.81], (500, 1)), gyro, t_s=t)
    >>> yaw = 2 * np.arctan2(q[:, 3], q[:, 0])
    >>> bool(abs((yaw[-1] - yaw[0]) - 0.2 * 4.99) < 1e-6)
    True
    """

    _kind = "robust"

    def __init__(self, sample_rate: float = _F["robust"]["SampleRate"], *, has_magnetometer: bool = False,
                 accelerometer_time_constant: Optional[float] = None,
                 magnetometer_time_constant: Optional[float] = None, settings: Optional[dict] = None,
                 conventions: Optional[str] = None, reference_frame: Optional[str] = None,
                 orientation_format: str = "quaternion", accel_sign: Optional[str] = None,
                 smooth: bool = False) -> None:
        all_settings = {}
        if accelerometer_time_constant is not None:
            all_settings["AccelerometerTimeConstant"] = accelerometer_time_constant
        if magnetometer_time_constant is not None:
            all_settings["MagnetometerTimeConstant"] = magnetometer_time_constant
        all_settings.update(settings or {})
        super().__init__(sample_rate, conventions, reference_frame, accel_sign, has_magnetometer,
                         all_settings, orientation_format, smooth=smooth)

    @property
    def status(self) -> dict:
        s = self._filter.status()
        if s is None:
            s = np.zeros((0, 6))
        return {"gyro_bias": s[:, 0:3], "at_rest": s[:, 3] > 0.5, "accel_rejected": s[:, 4] > 0.5,
                "mag_disturbed": s[:, 5] > 0.5}

    @property
    def gyroscope_offset(self):
        """The gyroscope bias estimate after the last sample, rad/s."""
        return self._filter.gyroscope_offset


class MahonyFilter(_SimpleFilter):
    """Mahony's complementary filter with proportional and integral gains."""

    _kind = "mahony"

    def __init__(self, sample_rate: float = _F["mahony"]["SampleRate"], *, kp: float = _F["mahony"]["Kp"],
                 ki: float = _F["mahony"]["Ki"],
                 has_magnetometer: bool = False, conventions: Optional[str] = None,
                 reference_frame: Optional[str] = None, orientation_format: str = "quaternion",
                 accel_sign: Optional[str] = None) -> None:
        super().__init__(sample_rate, conventions, reference_frame, accel_sign, has_magnetometer,
                         dict(Kp=kp, Ki=ki), orientation_format)


