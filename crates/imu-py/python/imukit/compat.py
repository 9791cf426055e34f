"""Compatibility with the MATLAB trajectory tool: its five functions ``my_lin``, ``my_tang``, ``my_ang``,
``my_rotate`` and ``my_imu`` with their arguments and outputs, on NumPy arrays.

``option='num'`` differentiates sampled arrays (MATLAB ``gradient`` by default, ``order=2``;
pass ``order=6`` for imukit's accurate default); ``option='sym'`` takes three formula strings or
sympy expressions of ``t`` and differentiates them exactly (dual numbers, no sympy needed for
strings). Constants other than ``t``, ``pi`` and ``e`` go in ``constants={...}``.

Migration from the MATLAB tool
------------------------------

====================  =======================================  ==========================================
MATLAB tool           imukit.compat                            notes
====================  =======================================  ==========================================
``my_lin(s,'num',t)`` ``my_lin(s, 'num', t)``                   same outputs; ``order=6`` for 1e-8 accuracy
``my_lin(s,'sym',t)`` ``my_lin(["0.8*cos(2*pi*f*t)", ...],      strings or sympy; ``constants={'f': 1}``
                      'sym', t, constants={'f': 1})``
``my_tang(v,t)``      ``my_tang(v, t)``                         returns ``phi_tz, phi_ty, phi_tx, ta``;
                                                                holds the last attitude at standstill
                                                                (the tool returns NaN there)
``my_ang(phi,o,t)``   ``my_ang(phi, o, t)``                     ``phi`` columns ``[phi_x, phi_y, phi_z]`` =
                                                                ``[roll, pitch, yaw]`` as in the tool. omega
                                                                is the **body** rate (what a gyro measures);
                                                                the tool's eq. (7) ``dR/dt·R⁻¹`` is the
                                                                nav-frame rate: ``frame='nav'`` gives it
``my_rotate(phi,aN,t)`` ``my_rotate(phi, aN, t)``               returns ``C_nbᵀ·aN`` (nav → body). The tool
                                                                multiplies by ``R = C_nb`` (body → nav), the
                                                                opposite rotation; ``tool_convention=True``
                                                                reproduces its numbers
``my_imu(aB,w,al,r,t)`` ``my_imu(aB, w, al, r, t)``             ``aB + ω×(ω×r) + α×r`` (the tool's eq. 9)
gravity               ``imukit.ideal_imu`` / ``simulate``       imukit reports the specific force ``a − g_n``
                                                                (at rest ENU ``[0, 0, +9.81]``);
                                                                ``accel_sign='matlab'`` gives MATLAB
                                                                imuSensor's ``g_n − a`` (``[0, 0, −9.81]``).
                                                                The tool's scripts add ``[0, 0, −g]``, i.e.
                                                                ``a + g_n``: MATLAB's sign at rest but the
                                                                motion term of the specific force — neither
====================  =======================================  ==========================================

Shapes: time ``t`` is (N,); vectors are (N, 3); angles returned by ``my_tang`` are (N,).
"""
from __future__ import annotations

from typing import Mapping, Optional, Sequence

import numpy as np

from . import _core
from . import truth_from_expressions, truth_from_samples

__all__ = ["my_lin", "my_tang", "my_ang", "my_rotate", "my_imu", "sympy_to_formula"]


def sympy_to_formula(expr, name: str = "expression") -> str:
    """Prints a sympy expression of ``t`` in imukit's formula language (``Piecewise`` included)."""
    try:
        import sympy
        from sympy.printing.str import StrPrinter
    except ImportError as e:  # pragma: no cover - exercised only without sympy
        raise TypeError(f"{name}: not a string or number, and sympy is not installed") from e

    if not isinstance(expr, sympy.Basic):
        raise TypeError(f"{name}: expected a formula string, a number or a sympy expression, got {type(expr).__name__}")

    class _Printer(StrPrinter):
        def _print_Piecewise(self, e):
            args = []
            fallback = "0/0"  # undefined outside the pieces: imukit reports it with its time
            for value, cond in e.args:
                if cond == sympy.true:
                    fallback = self._print(value)
                    break
                args += [self._print(cond), self._print(value)]
            if not args:
                return fallback
            return f"piecewise({', '.join(args + [fallback])})"

        def _print_And(self, e):
            return " && ".join(f"({self._print(a)})" for a in e.args)

        def _print_Or(self, e):
            return " || ".join(f"({self._print(a)})" for a in e.args)

        def _print_Not(self, e):
            return f"!({self._print(e.args[0])})"

        def _print_Pi(self, e):
            return "pi"

        def _print_Exp1(self, e):
            return "e"

    return _Printer().doprint(expr)


def _three(name: str, s) -> list:
    if len(s) != 3:
        raise ValueError(f"{name} must hold 3 functions (x, y, z), got {len(s)}")
    return list(s)


def _option(option: str) -> str:
    o = str(option).lower()
    if o not in ("num", "sym"):
        raise ValueError(f"option must be 'num' or 'sym', got {option!r}")
    return o


def my_lin(s, option: str, t_, *, order: int = 2, constants: Optional[Mapping[str, float]] = None):
    """Position, velocity and acceleration: ``[s_calc, v_calc, a_calc] = my_lin(s, option, t_)``.

    ``'num'``: ``s`` is (N, 3) sampled positions. ``'sym'``: ``s`` is three formulas of ``t``.
    """
    t = np.ascontiguousarray(t_, dtype=np.float64).ravel()
    if _option(option) == "num":
        truth = truth_from_samples(t, s, attitude="level", order=order)
    else:
        truth = truth_from_expressions(t, _three("s", s), attitude="level", constants=constants)
    pos = np.column_stack([truth[f"pos_{a}_m"] for a in "xyz"])
    vel = np.column_stack([truth[f"vel_{a}_m_s"] for a in "xyz"])
    acc = np.column_stack([truth[f"acc_{a}_m_s2"] for a in "xyz"])
    return pos, vel, acc


def my_tang(v, t=None):
    """Tangent Euler angles: ``[phi_tz, phi_ty, phi_tx, ta] = my_tang(v, t)``.

    ``phi_tz = atan2(v_y, v_x)`` (unwrapped), ``phi_ty = −asin(v_z/|v|)``, ``phi_tx = 0``,
    ``ta`` the unit tangent (N, 3). At standstill the last valid attitude is held.
    """
    e = _core.tangent_euler(np.ascontiguousarray(v, dtype=np.float64))
    ta = _core.euler_to_dcm(np.ascontiguousarray(e))[:, :, 0]
    return e[:, 0].copy(), e[:, 1].copy(), e[:, 2].copy(), ta


def my_ang(phi, option: str, t_, *, order: int = 2, frame: str = "body",
           constants: Optional[Mapping[str, float]] = None):
    """Euler angles, angular rate and angular acceleration: ``[phi, omega, alpha] = my_ang(...)``.

    ``phi`` columns (or the three formulas) are ``[phi_x, phi_y, phi_z]`` = ``[roll, pitch, yaw]``
    as in the tool. ``frame='body'`` (default) gives the gyro's body rate; ``frame='nav'`` the
    navigation-frame rate of the tool's eq. (7).
    """
    t = np.ascontiguousarray(t_, dtype=np.float64).ravel()
    if frame not in ("body", "nav"):
        raise ValueError(f"frame must be 'body' or 'nav', got {frame!r}")
    zeros = np.zeros((t.shape[0], 3))
    if _option(option) == "num":
        p = np.ascontiguousarray(phi, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"phi must have shape (N, 3), got {p.shape}")
        truth = truth_from_samples(t, zeros, euler_rad=p[:, ::-1], order=order)
    else:
        roll, pitch, yaw = _three("phi", phi)
        truth = truth_from_expressions(t, ["0", "0", "0"], yaw_rad=yaw, pitch_rad=pitch, roll_rad=roll,
                                       constants=constants)
    angles = np.column_stack([truth["roll_rad"], truth["pitch_rad"], truth["yaw_rad"]])
    omega = np.column_stack([truth[f"omega_{a}_rad_s"] for a in "xyz"])
    alpha = np.column_stack([truth[f"alpha_{a}_rad_s2"] for a in "xyz"])
    if frame == "nav":
        # ω_n = C_nb ω_b and, since Ċ_nb ω_b = C_nb (ω_b × ω_b) = 0, α_n = C_nb α_b.
        c = _core.euler_to_dcm(np.ascontiguousarray(angles[:, ::-1]))
        omega = np.einsum("nij,nj->ni", c, omega)
        alpha = np.einsum("nij,nj->ni", c, alpha)
    return angles, omega, alpha


def my_rotate(phi, aN, t=None, *, tool_convention: bool = False):
    """Navigation-frame vectors in the body frame: ``aB = my_rotate(phi, aN, t)``.

    ``phi`` columns ``[phi_x, phi_y, phi_z]`` = ``[roll, pitch, yaw]``. Returns ``C_nbᵀ·aN``;
    with ``tool_convention=True`` returns the tool's ``R(phi)·aN`` (which is ``C_nb·aN``).
    """
    p = np.ascontiguousarray(phi, dtype=np.float64)
    a = np.ascontiguousarray(aN, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"phi must have shape (N, 3), got {p.shape}")
    euler = np.ascontiguousarray(p[:, ::-1])
    if tool_convention:
        return np.einsum("nij,nj->ni", _core.euler_to_dcm(euler), a)
    return _core.nav_to_body(euler, a)


def my_imu(aB, omega, alpha, r: Sequence[float], t=None):
    """Acceleration at the IMU point: ``a_IMU = aB + ω×(ω×r) + α×r`` (the tool's eq. 9), body frame."""
    f = lambda x: np.ascontiguousarray(x, dtype=np.float64)  # noqa: E731
    return _core.at_lever_arm(f(aB), f(omega), f(alpha), [float(c) for c in r])
