"""Closed-form free flight (reference.core.flight) against a tight numerical integration
of Newton–Euler, and the derivative bounds that make the event search safe."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from reference import quaternion as qt
from reference.core.flight import (
    flight_constants,
    free_flight,
    vertex_height_bounds,
)
from reference.geometry import energies
from tests.conftest import core_model, make_scene
from tests.oracle import flight as oracle_flight
from tests.oracle.body import BodyModel
from tests.oracle.events import gap_jet


def newton_euler_rhs(i1, i3, g):
    """Torque-free Newton–Euler in the world frame, written independently of the core:
    I_w ω̇ = −ω × I_w ω with I_w = i1 1 + (i3 − i1) e3 e3ᵀ, q̇ = ½ (0, ω) ⊗ q."""

    def rhs(_t, y):
        q, w = y[3:7] / np.linalg.norm(y[3:7]), y[10:13]
        w0, x, yy, z = q
        e3 = np.array([2 * (x * z + w0 * yy), 2 * (yy * z - w0 * x), 1 - 2 * (x * x + yy * yy)])
        Iw = i1 * np.eye(3) + (i3 - i1) * np.outer(e3, e3)
        dy = np.zeros(13)
        dy[0:3] = y[7:10]
        wq = np.array([0.0, *w])
        dy[3:7] = 0.5 * np.array(
            [
                wq[0] * q[0] - wq[1] * q[1] - wq[2] * q[2] - wq[3] * q[3],
                wq[0] * q[1] + wq[1] * q[0] + wq[2] * q[3] - wq[3] * q[2],
                wq[0] * q[2] - wq[1] * q[3] + wq[2] * q[0] + wq[3] * q[1],
                wq[0] * q[3] + wq[1] * q[2] - wq[2] * q[1] + wq[3] * q[0],
            ]
        )
        dy[7:10] = [0.0, 0.0, -g]
        dy[10:13] = np.linalg.solve(Iw, -np.cross(w, Iw @ w))
        return dy

    return rhs


def tumbling_state():
    y = np.zeros(13)
    y[0:3] = [0.1, -0.2, 2.0]
    y[3:7] = qt.from_rotation_vector([0.3, -0.5, 1.1])
    y[7:10] = [0.2, -0.1, 0.7]
    y[10:13] = [1.3, -0.4, 2.1]
    return y


def flight(scene, y0, s):
    i1, _, i3 = scene.body.inertia_diag
    out = np.empty(13)
    free_flight(y0, flight_constants(y0, i1, i3), scene.gravity, s, out)
    return out


def test_closed_form_flight_matches_dop853_to_1e_11():
    scene = make_scene(n=5, rho=0.37)
    i1, _, i3 = scene.body.inertia_diag
    y0 = tumbling_state()
    sol = solve_ivp(
        newton_euler_rhs(i1, i3, scene.gravity), (0, 2.0), y0, method="DOP853",
        rtol=1e-13, atol=1e-15, dense_output=True,
    )  # fmt: skip
    for s in np.linspace(0.1, 2.0, 9):
        exact = flight(scene, y0, s)
        num = sol.sol(s)
        num[3:7] /= np.linalg.norm(num[3:7])
        assert np.max(np.abs(exact[0:3] - num[0:3])) < 1e-11
        assert qt.angle_between(exact[3:7], num[3:7]) < 1e-11
        assert np.max(np.abs(exact[7:13] - num[7:13])) < 1e-11


def test_flight_keeps_angular_momentum_and_energy():
    scene = make_scene(n=7, rho=0.42)
    i1, _, i3 = scene.body.inertia_diag
    y0 = tumbling_state()

    def momentum(y):
        e3 = qt.body_axis(y[3:7])
        w = y[10:13]
        return i1 * w + (i3 - i1) * (w @ e3) * e3

    def energy(y):
        ke, pe = energies(scene, y)
        return ke[0] + pe[0]

    L0, E0 = momentum(y0), energy(y0)
    for s in (0.3, 1.7, 12.5):
        y = flight(scene, y0, s)
        assert np.max(np.abs(momentum(y) - L0)) < 1e-13 * np.linalg.norm(L0)
        assert abs(energy(y) - E0) < 1e-13 * E0


def test_flight_of_tiny_rotation_keeps_relative_digits():
    """Rotation vectors of 1e-12 keep their digits: the attitude after a flight equals
    the linear prediction φ(t) = φ0 + ω t to relative 1e-9 (O(φ) terms only)."""
    scene = make_scene(n=5)
    y0 = np.zeros(13)
    y0[3:7] = qt.from_rotation_vector([1e-12, -2e-12, 0.0])
    y0[10:13] = [3e-12, 1e-12, 0.0]
    y0[2] = 1.0
    phi = qt.to_rotation_vector(flight(scene, y0, 0.5)[3:7])
    expect = np.array([1e-12 + 1.5e-12, -2e-12 + 0.5e-12, 0.0])
    assert np.max(np.abs(phi - expect)) < 1e-9 * 1e-12


def _random_flight(rng):
    y0 = np.zeros(13)
    tilt = 10 ** rng.uniform(-9, -0.3)
    axis = rng.normal(size=3)
    axis[2] = 0.0
    y0[3:7] = qt.from_rotation_vector(
        axis / np.linalg.norm(axis) * tilt + [0, 0, rng.uniform(-3, 3)]
    )
    y0[2] = 0.5
    y0[7:10] = rng.normal(size=3)
    w = rng.normal(size=3) * 10 ** rng.uniform(-2, 2)
    w[2] *= rng.choice([1.0, 50.0])
    y0[10:13] = w
    return y0


def _long_flights_of_a_64_gon(seed, flights=25, samples=400):
    """Random flights of a 64-gon (a = 1, g = 1): for each, (contact points, flight
    constants, vertex_height_bounds, sample times over 20 precession periods, the states
    there by the closed-form flight)."""
    rng = np.random.default_rng(seed)
    scene = make_scene(n=64, rho=0.5)
    _, pts = core_model(scene)
    i1, _, i3 = scene.body.inertia_diag
    for _ in range(flights):
        y0 = _random_flight(rng)
        fc = flight_constants(y0, i1, i3)
        ts = np.linspace(0.0, 20.0 / (fc.omega + abs(fc.lam) + 1e-9), samples)
        states = np.empty((samples, 13))
        for i, s in enumerate(ts):
            free_flight(y0, fc, 1.0, s, states[i])
        yield pts, fc, vertex_height_bounds(y0, fc, 1.0, 1.0), ts, states


@pytest.mark.parametrize("seed", range(4))
def test_vertex_height_bounds_hold_for_every_vertex_over_long_flights(seed):
    """K ≥ max |g″| and B ≥ max |g‴| over 20 precession periods, for every vertex of a
    64-gon: sampled g″ from the oracle's gap jets, g‴ by finite differences of them."""
    oracle = BodyModel.from_scene(make_scene(n=64, rho=0.5))
    for _, _, bounds, ts, states in _long_flights_of_a_64_gon(seed):
        K, B = bounds.K, bounds.B
        ofc = oracle_flight.flight_constants(oracle, states[0])
        acc = np.array(
            [gap_jet(oracle, y, oracle_flight.flight_acceleration(ofc, y)).accel for y in states]
        )
        assert np.abs(acc).max() <= K
        assert np.abs(np.diff(acc, axis=0) / (ts[1] - ts[0])).max() <= B * (1 + 1e-3) + 1e-12


def test_vertex_height_bounds_shrink_with_the_tilt():
    """For a fast spin about the vertical the jerk bound scales with sin α, not with
    a|ω|³ (the bound the search used before): at α = 1e-6 it is ≤ 1e-5 of a|ω|³."""
    scene = make_scene(n=16)
    i1, _, i3 = scene.body.inertia_diag
    y0 = np.zeros(13)
    y0[3:7] = qt.from_rotation_vector([1e-6, 0.0, 0.0])
    y0[2] = 1.0
    y0[10:13] = [0.0, 0.0, 100.0]
    fc = flight_constants(y0, i1, i3)
    _, B, _ = vertex_height_bounds(y0, fc, 1.0, 1.0)
    assert B <= 1e-5 * 100.0**3


@pytest.mark.parametrize("seed", range(4))
def test_rim_depth_bounds_every_vertex_over_long_flights(seed):
    """Bounds.depth ≥ how far any vertex of a 64-gon is below the centre of mass (gaps by
    the independent oracle), sampled over 20/(Ω + |λ|) of random flights (fast spins and
    tumbling; 400 samples, at least 125 per precession period), and it is tight: within
    the polygon's sag and 1e-3 of the radius (the sampling's share; measured at most
    5.3e-4) of the largest sampled depth."""
    oracle = BodyModel.from_scene(make_scene(n=64))
    for _, _, bounds, _, states in _long_flights_of_a_64_gon(seed):
        depth = bounds.depth
        deepest = max(y[2] - oracle.contacts(y)[0].min() for y in states)
        assert deepest <= depth
        assert depth <= deepest + 1e-3 + (1 - np.cos(np.pi / 64))


@pytest.mark.parametrize("tilt", [1e-6, 1e-9, 1e-12])
def test_rim_depth_holds_the_lowest_vertex_of_a_nearly_flat_disk_spinning_about_its_axis(tilt):
    """A disk tilted by α ≤ 1e-6 spinning about its own axis keeps its tilt: its lowest
    vertex is a sin α below the centre for the whole flight (from the axis' horizontal
    components, which keep their digits).  Bounds.depth must not be less, though e3_z
    rounds to 1 (it gave 3.6e-15 a for α = 1e-9)."""
    scene = make_scene(n=16)
    i1, _, i3 = scene.body.inertia_diag
    y0 = np.zeros(13)
    y0[3:7] = qt.from_rotation_vector([tilt, 0.0, 0.0])
    y0[2] = 0.5
    e3 = qt.body_axis(y0[3:7])
    y0[10:13] = 20.0 * e3
    fc = flight_constants(y0, i1, i3)
    depth = vertex_height_bounds(y0, fc, 1.0, 1.0).depth
    assert depth >= np.hypot(e3[0], e3[1])
    assert depth <= np.hypot(e3[0], e3[1]) + 1e-7  # the roundoff margin, not loose
