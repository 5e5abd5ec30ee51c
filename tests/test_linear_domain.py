"""The linear model reports leaving its small-tilt domain: status
`left_model`, cut where the tilt reaches reference.linear.domain.TILT_LIMIT."""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness.scenes import resolve_scene
from reference.linear.domain import TILT_LIMIT
from reference.linear.simulate import simulate_linear
from reference.scene import scene_from_dict
from reference.trajectory import Status


def tilts(traj) -> np.ndarray:
    """The angle between the body axis and the vertical, from the quaternion (w, x, y, z)
    of a rotation about a horizontal axis: 2 asin |(x, y)|."""
    q = traj.quaternion
    return 2.0 * np.arcsin(np.minimum(np.hypot(q[:, 1], q[:, 2]), 1.0))


def flight_scene(q, p, t_end=4.0):
    return scene_from_dict(
        {
            "name": "tipping",
            "body": {"n": 5},
            "initial": {"q": q, "p": p},
            "run": {"t_end": t_end},
        }
    )


def test_a_tilt_growing_in_flight_ends_left_model_at_the_analytic_time():
    """In flight φ(t) = q + p t (no torque): |φ| = TILT_LIMIT at t = (L − 0.01) / 0.05,
    long before the centre, falling from 10, comes near the ground (t ≈ 4.47)."""
    traj = simulate_linear(flight_scene([0.01, 0.0, 10.0], [0.05, 0.0, 0.0]))
    t_cross = (TILT_LIMIT - 0.01) / 0.05
    assert traj.status is Status.LEFT_MODEL
    assert "small-tilt domain" in traj.message and f"{TILT_LIMIT:g} rad" in traj.message
    assert traj.t_final == pytest.approx(t_cross, rel=1e-12)
    assert tilts(traj).max() == pytest.approx(TILT_LIMIT, rel=1e-9)
    assert not traj.impacts


def test_a_diagonal_tilt_through_a_contact_phase_is_cut_where_it_reaches_the_limit():
    """The three-point disk on tiny bumps tips over slowly: cut where
    |φ| = TILT_LIMIT, with every sample before within it."""
    scene = resolve_scene("three-point-disk")
    scene = scene_from_dict(
        {
            "name": "tiny-bumps",
            "body": {"n": 64, "gyration": 0.5},
            "ground": {"kind": "three_point", "bump_radius": 1e-6},
            "restitution": scene.restitution,
            "initial": {"q": list(scene.initial.q), "p": list(scene.initial.p)},
            "run": {"t_end": 20.0},
        }
    )
    traj = simulate_linear(scene)
    assert traj.status is Status.LEFT_MODEL
    alpha = tilts(traj)
    assert alpha[-1] == pytest.approx(TILT_LIMIT, rel=1e-9)
    assert alpha[:-1].max() < TILT_LIMIT


def test_a_start_beyond_the_domain_ends_at_once():
    traj = simulate_linear(resolve_scene("grazing-contact"))
    assert traj.status is Status.LEFT_MODEL and traj.t_final == 0.0
    assert f"tilt {tilts(traj)[0]:.3g} rad" in traj.message


@pytest.mark.parametrize("name", ["near-simultaneous", "elastic-hexagon", "triangle-chatter"])
def test_runs_within_the_domain_are_unchanged(name):
    traj = simulate_linear(resolve_scene(name))
    assert traj.status is not Status.LEFT_MODEL
    assert tilts(traj).max() < TILT_LIMIT
    assert math.isfinite(traj.t_final)
