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


def _random_flights(n: int, count: int, seed: int):
    """States of an n-gon in flight above flat ground: tilt from 1e-4 to 0.3 rad, spin
    about every axis, the lowest vertex 1e-9 … 1e-2 above the ground, falling or rising."""
    import numpy as np

    from reference.body import BodyModel, initial_state
    from reference.scene import Body, Ground, InitialState, RunSettings, Scene

    rng = np.random.default_rng(seed)
    for i in range(count):
        tilt = 10 ** rng.uniform(-4, np.log10(0.3))
        az = rng.uniform(0, 2 * np.pi)
        rotvec = (tilt * np.cos(az), tilt * np.sin(az), rng.uniform(-np.pi, np.pi))
        height = np.sin(tilt) + 10 ** rng.uniform(-9, -2)  # radius 1
        scene = Scene(
            name=f"n{n}-random{i}",
            body=Body(n=n, gyration=0.5),
            ground=Ground(),
            initial=InitialState(
                position=(0.0, 0.0, float(height)),
                rotation_vector=tuple(float(x) for x in rotvec),
                velocity=(0.0, 0.0, float(rng.uniform(-0.5, 0.2))),
                angular_velocity=tuple(float(x) for x in rng.normal(0, 0.5, 3)),
            ),
            restitution=1.0,
            gravity=1.0,
            run=RunSettings(t_end=10.0),
        )
        model = BodyModel.from_scene(scene)
        y = initial_state(scene)
        if model.contacts(y)[0].min() > 0:
            yield model, y


@pytest.mark.parametrize("n,count", [(33, 40), (100, 40), (1000, 20), (10_000, 6)])
def test_large_n_search_finds_the_event_of_the_all_vertex_search(n, count):
    """For n > 32 the compiled search examines only a window of vertices near the
    lowest direction and bounds the rest by the circle through them; the Python
    specification examines every vertex.  Same first vertex, same time to 1e-12."""
    from reference.flight import flight_constants

    compared = 0
    for model, y in _random_flights(n, count, seed=n):
        fc = flight_constants(model, y)
        py = events.next_flight_event(model, fc, 10.0, compiled=False)
        nb = events.next_flight_event(model, fc, 10.0, compiled=True)
        assert (py is None) == (nb is None)
        if py is None:
            continue
        assert nb.contacts == py.contacts and nb.kind == py.kind
        assert abs(nb.s - py.s) <= 1e-12 * max(1.0, py.s)
        compared += 1
    assert compared >= count // 2


@pytest.mark.parametrize("n,n_compare", [(100, 20), (1000, 12), (10_000, 4)])
def test_large_n_runs_agree_with_the_python_specification(n, n_compare, monkeypatch):
    """Whole runs of a bouncing n-gon (searches starting right after an impact, with the
    impacting vertex and its neighbours within roundoff of the ground): the compiled
    loop with its vertex window and circle bound gives the impacts of the Python path,
    which examines every vertex at every step."""
    from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear

    scene = Scene(
        name=f"n{n}-elastic",
        body=Body(n=n, gyration=0.5),
        ground=Ground(),
        initial=initial_from_linear((0.01, -0.004, 0.03), (0.03, 0.05, -0.2)),
        restitution=1.0,
        gravity=1.0,
        run=RunSettings(t_end=100.0, max_impacts=n_compare),
    )
    monkeypatch.setattr(events, "USE_KERNEL", False)
    py = simulate(scene)
    monkeypatch.setattr(events, "USE_KERNEL", True)
    nb = simulate(scene)
    assert len(py.impacts) == len(nb.impacts) == n_compare
    for a, b in zip(py.impacts, nb.impacts, strict=True):
        assert a.contact == b.contact
        assert abs((a.t - b.t) + (a.t_lo - b.t_lo)) <= 1e-12
