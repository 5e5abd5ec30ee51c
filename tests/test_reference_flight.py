"""Closed-form free flight against a tight numerical integration of Newton–Euler."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from reference import quaternion as qt
from reference.body import BodyModel, cross
from reference.flight import flight_constants, free_flight
from tests.conftest import make_scene


def newton_euler_rhs(model: BodyModel):
    """Torque-free Newton–Euler in world frame: I_w ω̇ = −ω × I_w ω, q̇ = ½ (0, ω) ⊗ q."""

    def rhs(_t, y):
        q, w = y[3:7], y[10:13]
        e3 = qt.body_axis(q / np.linalg.norm(q))
        Iw = model.i1 * np.eye(3) + (model.i3 - model.i1) * np.outer(e3, e3)
        wdot = np.linalg.solve(Iw, -cross(w, Iw @ w))
        dy = np.zeros(13)
        dy[0:3] = y[7:10]
        dy[3:7] = 0.5 * qt.multiply(np.r_[0.0, w], q)
        dy[7:10] = [0.0, 0.0, -model.gravity]
        dy[10:13] = wdot
        return dy

    return rhs


def tumbling_state():
    y = np.zeros(13)
    y[0:3] = [0.1, -0.2, 2.0]
    y[3:7] = qt.from_rotation_vector([0.3, -0.5, 1.1])
    y[7:10] = [0.2, -0.1, 0.7]
    y[10:13] = [1.3, -0.4, 2.1]
    return y


def test_closed_form_flight_matches_dop853_to_1e_11():
    model = BodyModel.from_scene(make_scene(n=5, rho=0.37))
    y0 = tumbling_state()
    fc = flight_constants(model, y0)
    T = 2.0
    sol = solve_ivp(
        newton_euler_rhs(model),
        (0, T),
        y0,
        method="DOP853",
        rtol=1e-13,
        atol=1e-15,
        dense_output=True,
    )
    for s in np.linspace(0.1, T, 9):
        exact = free_flight(fc, s)
        num = sol.sol(s)
        num[3:7] /= np.linalg.norm(num[3:7])
        assert np.max(np.abs(exact[0:3] - num[0:3])) < 1e-11
        assert qt.angle_between(exact[3:7], num[3:7]) < 1e-11
        assert np.max(np.abs(exact[7:13] - num[7:13])) < 1e-11


def test_flight_keeps_angular_momentum_and_energy():
    model = BodyModel.from_scene(make_scene(n=7, rho=0.42))
    y0 = tumbling_state()
    fc = flight_constants(model, y0)
    L0 = model.angular_momentum(y0)
    E0 = model.energy(y0)
    for s in (0.3, 1.7, 12.5):
        y = free_flight(fc, s)
        assert np.max(np.abs(model.angular_momentum(y) - L0)) < 1e-13 * np.linalg.norm(L0)
        assert abs(model.energy(y) - E0) < 1e-13 * E0


def test_flight_of_tiny_rotation_keeps_relative_digits():
    """Rotation vectors of 1e-12 keep their digits: the attitude after a flight equals
    the linear prediction φ(t) = φ0 + ω t to relative 1e-9 (O(φ) terms only)."""
    model = BodyModel.from_scene(make_scene(n=5))
    y0 = np.zeros(13)
    y0[3:7] = qt.from_rotation_vector([1e-12, -2e-12, 0.0])
    y0[10:13] = [3e-12, 1e-12, 0.0]
    y0[2] = 1.0
    fc = flight_constants(model, y0)
    y = free_flight(fc, 0.5)
    phi = qt.to_rotation_vector(y[3:7])
    expect = np.array([1e-12 + 1.5e-12, -2e-12 + 0.5e-12, 0.0])
    assert np.max(np.abs(phi - expect)) < 1e-9 * 1e-12
