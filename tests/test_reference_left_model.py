"""The three-point ground holds the body only while the bumps are under its face: a bump
meeting the face's plane outside the rim ends the run `left_model` (before that status
existed, an elastic disk walked off the bumps and went on colliding its infinite plane
with them, its centre falling for ever).  The floor plane under the bumps, the ground's
other limit (tests/test_reference_floor.py), is put infinitely far down here
(floor_depth = inf): these runs tip far before they leave the bumps."""

import numpy as np
import pytest

from reference.scene import scene_from_dict
from reference.simulate import simulate
from reference.trajectory import Status
from tests.conftest import states_of
from tests.oracle.body import BodyModel

BUMP = 0.5  # bump radius b (the face's radius a is 1)


def _scene(gamma, initial):
    return scene_from_dict(
        {
            "name": "three-point",
            "restitution": gamma,
            "body": {"n": 3, "gyration": 0.5},
            "ground": {"kind": "three_point", "bump_radius": BUMP, "floor_depth": float("inf")},
            "initial": initial,
            "run": {"t_end": 100.0, "max_impacts": 20_000},
        }
    )


def _distance_in_face(state, k):
    """How far from the centre, in the face's plane, bump k's foot lies: the length of
    its lever (the in-plane part of b_k − x) by the independent oracle."""
    oracle = BodyModel.from_scene(_scene(1.0, {"q": [0, 0, 0], "p": [0, 0, 0]}))
    return float(np.linalg.norm(oracle.contacts(state, [k])[2][0]))


def _named_bump(message):
    """k of the message's 'bk meets the face's plane ...'."""
    return int(message.split()[0].removeprefix("b"))


def test_an_elastic_disk_bouncing_off_its_bumps_ends_left_model():
    traj = simulate(_scene(1.0, {"q": [0.012, -0.007, 0.05], "p": [0.2, -0.15, -0.5]}), t_end=100.0)
    assert traj.status is Status.LEFT_MODEL
    k = _named_bump(traj.message)
    assert "left the bumps" in traj.message
    assert _distance_in_face(states_of(traj)[-1], k) > 1.0
    assert traj.t_final < 20.0  # it does not go on falling past the bumps


def test_every_impact_before_leaving_is_under_the_face():
    traj = simulate(_scene(1.0, {"q": [0.012, -0.007, 0.05], "p": [0.2, -0.15, -0.5]}), t_end=100.0)
    states = states_of(traj)
    assert len(traj.impacts) > 3
    for imp in traj.impacts:
        i = int(np.flatnonzero(traj.t == imp.t)[0])  # a sample at every event
        assert _distance_in_face(states[i], imp.contact) <= 1.0


@pytest.mark.parametrize("vx", [3.0, 10.0])
def test_a_disk_landing_beside_a_bump_ends_left_model_without_an_impact(vx):
    traj = simulate(
        _scene(
            0.5,
            {
                "position": [0.0, 0.0, 0.3],
                "rotation_vector": [0.0, 0.05, 0.0],
                "velocity": [vx, 0.0, 0.0],
                "angular_velocity": [0.0, 0.0, 0.0],
            },
        ),
        t_end=100.0,
    )
    assert traj.status is Status.LEFT_MODEL
    assert len(traj.impacts) == 0
    assert _distance_in_face(states_of(traj)[-1], _named_bump(traj.message)) > 1.0


def test_a_held_bump_sliding_out_of_the_face_ends_left_model():
    traj = simulate(
        _scene(
            0.0,
            {
                "position": [0.0, 0.0, 0.3],
                "rotation_vector": [0.0, 0.2, 0.0],
                "velocity": [0.3, 0.0, 0.0],
                "angular_velocity": [0.0, 0.0, 2.0],
            },
        ),
        t_end=100.0,
    )
    assert traj.status is Status.LEFT_MODEL
    k = _named_bump(traj.message)
    assert traj.phases[-1].kind == "contact" and k in traj.phases[-1].contacts
    assert _distance_in_face(states_of(traj)[-1], k) > 1.0


def test_long_flights_over_the_bumps_take_few_search_iterations():
    """The bounds of a flight over the bumps are taken over segments of its own time
    scale (`flight.bound_segment`), not over the time left to t_end (which made them
    grow with its square and cube: 10–260 iterations per flight of this run)."""
    traj = simulate(_scene(1.0, {"q": [0.012, -0.007, 0.05], "p": [0.2, -0.15, -0.5]}), t_end=1e4)
    assert traj.stats.search_iterations_per_impact <= 3.0
