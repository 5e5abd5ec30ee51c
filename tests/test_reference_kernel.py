"""The compiled flight/impact loop finds the same events as the Python specification."""

from __future__ import annotations

import pytest

import reference.events as events
from harness.scenes import resolve_scene
from reference.simulate import simulate


@pytest.mark.parametrize(
    "name,n_compare",
    [
        ("triangle-chatter", 50),
        ("near-simultaneous", 5),
        ("grazing-contact", 5),
        ("elastic-hexagon", 25),
        ("pentagon-bounce", 30),
        ("rod", 40),
    ],
)
def test_compiled_and_python_paths_agree_on_the_leading_impacts(name, n_compare, monkeypatch):
    """Chaotic runs separate after ~100 impacts (roundoff × ~1.2 per impact), so only
    the leading impacts are compared: same contact, times within 1e-12."""
    scene = resolve_scene(name)
    monkeypatch.setattr(events, "USE_KERNEL", False)
    py = simulate(scene)
    monkeypatch.setattr(events, "USE_KERNEL", True)
    nb = simulate(scene)
    assert len(py.impacts) >= n_compare and len(nb.impacts) >= n_compare
    scale = max(abs(e.impulse) for e in py.impacts[:n_compare])
    for a, b in zip(py.impacts[:n_compare], nb.impacts[:n_compare], strict=True):
        assert a.contact == b.contact
        assert abs((a.t - b.t) + (a.t_lo - b.t_lo)) <= 1e-12
        assert abs(a.impulse - b.impulse) <= 1e-10 * scale


def test_final_sample_at_t_end_is_the_closed_form_state_there():
    """Regression: the compiled search must return the state at the horizon, not at its
    last safe step, when no contact is reached before t_end."""
    import numpy as np

    from reference import quaternion as qt
    from reference.body import BodyModel, initial_state
    from reference.flight import flight_constants, free_flight

    scene = resolve_scene("elastic-hexagon").with_run(t_end=0.05)  # no impact before 0.05
    traj = simulate(scene)
    assert len(traj.impacts) == 0 and traj.t[-1] == 0.05
    model = BodyModel.from_scene(scene)
    exact = free_flight(flight_constants(model, initial_state(scene)), 0.05)
    assert qt.angle_between(traj.quaternion[-1], exact[3:7]) < 1e-14
    assert np.max(np.abs(traj.position[-1] - exact[0:3])) < 1e-15
