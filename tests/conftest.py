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
    bump_height=0.0,
    floor_depth=None,
    t_end=3.0,
    max_impacts=100_000,
    state=None,
    name="test",
) -> Scene:
    """A scene from linear coordinates (q, p) or from a full 13-state `state`
    (floor_depth: the three_point ground's floor, None for its default)."""
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
        ground=Ground(
            kind=ground, bump_radius=bump, bump_height=bump_height, floor_depth=floor_depth
        ),
        initial=initial,
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=t_end, max_impacts=max_impacts),
    )


@pytest.fixture
def scene_factory():
    return make_scene


def core_model(scene: Scene):
    """(model record, contact points) of a scene, as the compiled core reads them."""
    from reference.simulate import model_record

    return model_record(scene)[0], np.array(scene.contacts.core_points, order="C")


def flight(scene: Scene, y0: np.ndarray, s: float) -> np.ndarray:
    """The state after a closed-form free flight of s from y0 (reference.core.flight)."""
    from reference.core.flight import flight_constants, free_flight

    i1, _, i3 = scene.body.inertia_diag
    out = np.empty(13)
    free_flight(np.asarray(y0, dtype=float), flight_constants(y0, i1, i3), scene.gravity, s, out)
    return out


def gaps(scene: Scene, y: np.ndarray) -> np.ndarray:
    """Contact gaps (k,) of one state."""
    from reference.geometry import scene_contact_kinematics

    return scene_contact_kinematics(scene, y)[0][0]


def angular_momentum(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N, 3) angular momentum about the centre of mass, I_w ω with
    I_w = i1 1 + (i3 − i1) e3 e3ᵀ, from the states (written here for the tests)."""
    states = np.atleast_2d(states)
    i1, _, i3 = scene.body.inertia_diag
    e3 = qt.body_axis(states[:, 3:7])
    w = states[:, 10:13]
    return i1 * w + (i3 - i1) * np.sum(w * e3, axis=1)[:, None] * e3


def states_of(traj) -> np.ndarray:
    """(N, 13) sample states of a Trajectory."""
    return np.hstack([traj.position, traj.quaternion, traj.velocity, traj.angular_velocity])


def empty_output():
    """The core's Output with one row per array and zero counts (for calling core
    functions that take it directly)."""
    from reference.core.output import Output

    return Output(
        np.zeros((1, 2)), np.zeros((1, 13)), np.zeros((1, 2)), np.zeros((1, 6)),
        np.zeros((1, 6)), np.zeros(1), np.zeros(5, dtype=np.int64),
    )  # fmt: skip
