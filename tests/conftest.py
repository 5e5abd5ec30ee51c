"""Shared fixtures: scenes built in code (independent of the shipped TOML files)."""

from __future__ import annotations

import numpy as np
import pytest

from reference import quaternion as qt
from reference.scene import Body, Ground, InitialState, RunSettings, Scene, initial_from_linear


def make_scene(
    n=5,
    rho=0.5,
    gamma=0.5,
    q=(0.01, -0.006, 0.05),
    p=(0.05, 0.02, -0.1),
    ground="flat",
    bump=0.5,
    t_end=3.0,
    max_impacts=100_000,
    state=None,
    name="test",
) -> Scene:
    """A scene from linear coordinates (q, p) or from a full 13-state `state`."""
    if state is not None:
        y = np.asarray(state, dtype=float)
        initial = InitialState(
            tuple(y[0:3]), tuple(qt.to_rotation_vector(y[3:7])), tuple(y[7:10]), tuple(y[10:13])
        )
    else:
        initial = initial_from_linear(q, p)
    return Scene(
        name=name,
        body=Body(n=n, gyration=rho),
        ground=Ground(kind=ground, bump_radius=bump),
        initial=initial,
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=t_end, max_impacts=max_impacts),
    )


@pytest.fixture
def scene_factory():
    return make_scene
