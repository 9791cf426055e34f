"""imukit.compat: the MATLAB trajectory tool's functions, their arguments and outputs, 'num' and 'sym'."""
import math

import numpy as np
import pytest
import sympy as sp

import imukit
from imukit.compat import my_ang, my_imu, my_lin, my_rotate, my_tang, sympy_to_formula

T = np.arange(0, 1.0 + 1e-12, 0.005)
W = 2 * math.pi


def test_my_lin_sym_is_exact_for_strings_and_sympy():
    t = sp.Symbol("t")
    f = sp.Symbol("f")
    s, v, a = my_lin([0.8 * sp.cos(2 * sp.pi * f * t), "0.8*sin(2*pi*f*t)", "0.3*cos(2*pi*f*t)"], "sym", T,
                     constants={"f": 1.0})
    np.testing.assert_allclose(s[:, 0], 0.8 * np.cos(W * T), rtol=0, atol=1e-15)
    np.testing.assert_allclose(v[:, 1], 0.8 * W * np.cos(W * T), rtol=0, atol=1e-13)
    np.testing.assert_allclose(a[:, 2], -0.3 * W * W * np.cos(W * T), rtol=0, atol=1e-12)


def test_my_lin_num_is_matlab_gradient_by_default():
    s = np.column_stack([np.cos(W * T), np.sin(W * T), T])
    _, v, a = my_lin(s, "num", T)
    g = np.gradient(s, T, axis=0, edge_order=1)
    np.testing.assert_allclose(v, g, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a, np.gradient(g, T, axis=0, edge_order=1), rtol=0, atol=1e-9)
    _, v6, _ = my_lin(s, "num", T, order=6)
    assert np.max(np.abs(v6[:, 0] + W * np.sin(W * T))) < 1e-8 * W


def test_sympy_piecewise_becomes_an_exact_piecewise_formula():
    t = sp.Symbol("t")
    yaw = sp.Piecewise((sp.pi / 2 * t, t < 4), (2 * sp.pi + sp.pi * (t - 4), True))
    text = sympy_to_formula(yaw)
    assert text.startswith("piecewise(")
    _, omega, alpha = my_ang([0, 0, yaw], "sym", np.array([1.0, 2.0, 5.0, 5.5]))
    np.testing.assert_allclose(omega[:, 2], [math.pi / 2, math.pi / 2, math.pi, math.pi], atol=1e-15)
    np.testing.assert_allclose(alpha, 0.0, atol=1e-15)


def test_my_tang_gives_tangent_angles_and_unit_tangent():
    v = np.column_stack([-np.sin(W * T), np.cos(W * T), 0.3 * np.ones_like(T)])
    tz, ty, tx, ta = my_tang(v, T)
    np.testing.assert_allclose(tz, W * T + math.pi / 2, atol=1e-12)  # unwrapped
    np.testing.assert_allclose(ty, -np.arcsin(0.3 / np.sqrt(1.09)), atol=1e-14)
    np.testing.assert_allclose(tx, 0.0)
    np.testing.assert_allclose(ta, v / np.linalg.norm(v, axis=1)[:, None], atol=1e-14)
    # Standstill holds the attitude instead of returning NaN.
    v[10:20] = 0.0
    tz, ty, _, _ = my_tang(v, T)
    assert np.all(np.isfinite(tz)) and np.all(tz[10:20] == tz[9])


def test_my_ang_body_rate_and_the_tools_nav_frame_rate():
    pitch = "asin(3*sqrt(2)*sin(2*pi*t)/sqrt(137 - 9*cos(4*pi*t)))"
    phi, omega_b, alpha_b = my_ang(["0", pitch, "2*pi*t + pi/2"], "sym", T)
    exact = imukit.truth_from_expressions(T, [0, 0, 0], yaw_rad="2*pi*t + pi/2", pitch_rad=pitch)
    np.testing.assert_array_equal(omega_b[:, 1], exact["omega_y_rad_s"])
    _, omega_n, alpha_n = my_ang(["0", pitch, "2*pi*t + pi/2"], "sym", T, frame="nav")
    c = imukit.euler_to_dcm(phi[:, ::-1])
    np.testing.assert_allclose(np.einsum("nij,nj->ni", c, omega_b), omega_n, atol=1e-12)
    # |ω| is frame-independent, the components are not.
    np.testing.assert_allclose(np.linalg.norm(omega_n, axis=1), np.linalg.norm(omega_b, axis=1), rtol=1e-12)
    assert np.max(np.abs(omega_n - omega_b)) > 0.1
    # 'num' at order 6 agrees with 'sym'.
    _, omega_num, _ = my_ang(phi, "num", T, order=6)
    assert np.max(np.abs(omega_num - omega_b)) < 1e-8 * np.max(np.abs(omega_b))


def test_my_rotate_goes_nav_to_body_and_can_reproduce_the_tool():
    phi = np.array([[0.0, 0.0, math.pi / 2]])  # [roll, pitch, yaw]
    north = np.array([[0.0, 1.0, 0.0]])
    np.testing.assert_allclose(my_rotate(phi, north), [[1.0, 0.0, 0.0]], atol=1e-15)
    np.testing.assert_allclose(my_rotate(phi, north, tool_convention=True), [[-1.0, 0.0, 0.0]], atol=1e-15)


def test_my_imu_adds_centripetal_and_euler_terms():
    a = np.array([[1.0, 2.0, 3.0]])
    w = np.array([[0.0, 0.0, 2.0]])
    al = np.array([[0.0, 0.0, 0.5]])
    r = [0.1, 0.0, 0.0]
    # ω×(ω×r) = [−0.4, 0, 0]; α×r = [0, 0.05, 0]
    np.testing.assert_allclose(my_imu(a, w, al, r, None), [[0.6, 2.05, 3.0]], atol=1e-15)


def test_bad_option_and_shapes():
    with pytest.raises(ValueError, match="option must be 'num' or 'sym'"):
        my_lin(np.zeros((5, 3)), "numeric", np.arange(5.0))
    with pytest.raises(ValueError, match=r"phi must have shape \(N, 3\)"):
        my_rotate(np.zeros((3, 2)), np.zeros((3, 3)))
