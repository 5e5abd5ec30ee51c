"""Event location: nothing missed, nothing spurious, no penetration."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from harness.scenes import builtin_names, resolve_scene
from reference import quaternion as qt
from reference.core.contacts import vertex_lever
from reference.geometry import initial_state
from reference.simulate import simulate
from tests.conftest import flight, gaps, make_scene, states_of


def _grazing_state(dip):
    """Vertex 0 at a gap minimum of −dip (two roots ≈ 2√(dip/c) apart) at t = 0."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector([0.02, 0.1, 0.0])
    y[10:13] = [0.5, -5.0, 0.0]
    rx, ry, rz = vertex_lever(y, 1.0, 0.0)
    y[2] = -rz - dip
    y[9] = -(y[10] * ry - y[11] * rx)
    return y


def test_two_roots_within_a_millisecond_are_found_at_the_first_root():
    """The gap dips 1e-10 below zero for ~2e-5 s: a sign test with any step above that
    misses it.  The reference must hit at the first root, found independently here by
    dense sampling + brentq on the closed-form gap."""
    scene = make_scene(n=3)
    T = 0.05
    y0 = flight(scene, _grazing_state(1e-10), -T)
    assert np.all(gaps(scene, y0) > 0)
    gap0 = lambda s: gaps(scene, flight(scene, y0, s))[0]  # noqa: E731
    grid = np.linspace(T - 1e-4, T, 2001)
    vals = np.array([gap0(s) for s in grid])
    i = np.flatnonzero(vals <= 0)[0]
    t_first = brentq(gap0, grid[i - 1], grid[i], xtol=1e-16, rtol=1e-15)
    traj = simulate(make_scene(n=3, state=y0, t_end=T + 1e-3))
    assert len(traj.impacts) >= 1
    first = traj.impacts[0]
    assert first.contact == 0
    assert abs(first.t - t_first) < 1e-11


def test_grazing_touch_is_not_an_impact_and_does_not_penetrate():
    scene = resolve_scene("grazing-contact")  # vertex 0 grazes at t = 0.1 exactly
    traj = simulate(scene)
    assert not [e for e in traj.impacts if abs(e.t - 0.1) < 1e-3]
    y0 = initial_state(scene.initial)
    s = np.linspace(0.1 - 1e-4, 0.1 + 1e-4, 401)
    g0 = np.array([gaps(scene, flight(scene, y0, x))[0] for x in s])
    assert g0.min() > -1e-15  # the exact motion only touches


def test_hits_1e12_apart_are_resolved_in_order_not_declared_simultaneous():
    scene = resolve_scene("near-simultaneous")
    traj = simulate(scene)
    assert traj.status.value != "simultaneous_impact"
    a, b = traj.impacts[0], traj.impacts[1]
    assert (a.contact, b.contact) == (0, 1)
    dt = (b.t - a.t) + (b.t_lo - a.t_lo)
    # vertex 1 was 1e-12 higher; after the first impact it still approaches at a speed
    # between 0.5 and 1 (it falls at 1 before): Δt in [1e-12, 2e-12]
    assert 1e-12 <= dt <= 2e-12


def test_exactly_symmetric_hits_end_the_run_as_simultaneous():
    """A square dropped flat-on-an-edge: vertices 0 and 1 at equal heights."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector(np.array([-1.0, 1.0, 0.0]) * 0.02 / np.sqrt(2))
    g = gaps(make_scene(n=4), y)
    assert abs(g[0] - g[1]) < 1e-17
    y[2] = 0.05 - g[0]
    y[9] = -1.0
    traj = simulate(make_scene(n=4, state=y))
    assert traj.status.value == "simultaneous_impact"
    assert "v0, v1 hit simultaneously" in traj.message


@pytest.mark.parametrize("name", [n for n in builtin_names() if n != "polygon25-rolling"])
def test_no_builtin_scene_penetrates_beyond_1e_12(name):
    scene = resolve_scene(name)
    traj = simulate(scene)
    assert traj.stats["max_penetration"] <= 1e-12
    from reference.geometry import scene_contact_kinematics

    assert scene_contact_kinematics(scene, states_of(traj))[0].min() >= -1e-12
