"""Event location: nothing missed, nothing spurious, no penetration."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from harness.scenes import builtin_names, resolve_scene
from reference import quaternion as qt
from reference.body import BodyModel, initial_state
from reference.flight import flight_constants, free_flight
from reference.simulate import simulate
from tests.conftest import make_scene


def _grazing_state(model, dip):
    """Vertex 0 at a gap minimum of −dip (two roots ≈ 2√(dip/c) apart) at t = 0."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector([0.02, 0.1, 0.0])
    y[10:13] = [0.5, -5.0, 0.0]
    _, _, lever, _, _ = model.contacts(y)
    y[2] = -lever[0, 2] - dip
    y[9] = -(y[10] * lever[0, 1] - y[11] * lever[0, 0])
    return y


def test_two_roots_within_a_millisecond_are_found_at_the_first_root():
    """The gap dips 1e-10 below zero for ~2e-5 s: a sign test with any step above that
    misses it.  The reference must hit at the first root, found independently here by
    dense sampling + brentq on the closed-form gap."""
    model = BodyModel.from_scene(make_scene(n=3))
    T = 0.05
    y_min = _grazing_state(model, 1e-10)
    y0 = free_flight(flight_constants(model, y_min), -T)
    assert np.all(model.contacts(y0)[0] > 0)
    fc = flight_constants(model, y0)
    gap0 = lambda s: model.contacts(free_flight(fc, s))[0][0]  # noqa: E731
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
    model = BodyModel.from_scene(scene)
    fc = flight_constants(model, initial_state(scene))
    s = np.linspace(0.1 - 1e-4, 0.1 + 1e-4, 401)
    gaps = np.array([model.contacts(free_flight(fc, x))[0][0] for x in s])
    assert gaps.min() > -1e-15  # the exact motion only touches


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
    model = BodyModel.from_scene(make_scene(n=4))
    g = model.contacts(y)[0]
    assert abs(g[0] - g[1]) < 1e-17
    y[2] = 0.05 - g[0]
    y[9] = -1.0
    traj = simulate(make_scene(n=4, state=y))
    assert traj.status.value == "simultaneous_impact"
    assert "[0, 1]" in traj.message


@pytest.mark.parametrize("name", [n for n in builtin_names() if n != "polygon25-rolling"])
def test_no_builtin_scene_penetrates_beyond_1e_12(name):
    scene = resolve_scene(name)
    traj = simulate(scene)
    assert traj.stats["max_penetration"] <= 1e-12
    model = BodyModel.from_scene(scene)
    for i in range(traj.n_samples):
        y = np.r_[traj.position[i], traj.quaternion[i], traj.velocity[i], traj.angular_velocity[i]]
        assert model.contacts(y)[0].min() >= -1e-12


def test_compiled_gap_jet_of_a_large_polygon_equals_the_array_expression(monkeypatch):
    """Gap jets over flat ground come from a compiled loop; they must equal the
    J·acc + bias array expression (reference.body.COMPILED_KINEMATICS = False)."""
    import numpy as np

    import reference.body as body_mod
    from reference.body import BodyModel, initial_state
    from reference.events import gap_jet
    from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear

    scene = Scene(
        name="n1000",
        body=Body(n=1000, gyration=0.5),
        ground=Ground(),
        initial=initial_from_linear((0.01, -0.004, 0.03), (0.03, 0.05, -0.2)),
        restitution=0.8,
        gravity=1.0,
        run=RunSettings(t_end=1.0),
    )
    model = BodyModel.from_scene(scene)
    y = initial_state(scene)
    y[10:13] = (0.3, -0.2, 0.7)
    acc = np.array([0.1, 0.2, -0.9, 0.3, 0.4, 0.5])
    fast = gap_jet(model, y, acc)
    fast_idx = gap_jet(model, y, acc, [3, 500, 999])
    monkeypatch.setattr(body_mod, "COMPILED_KINEMATICS", False)
    slow = gap_jet(model, y, acc, np.arange(1000))  # the array expression
    for f in ("gap", "rate", "accel", "noise"):
        np.testing.assert_allclose(
            getattr(fast_idx, f), getattr(slow, f)[[3, 500, 999]], rtol=0, atol=1e-15
        )
    for f in ("gap", "rate", "accel", "noise", "rate_noise"):
        np.testing.assert_allclose(getattr(fast, f), getattr(slow, f), rtol=0, atol=1e-15)
