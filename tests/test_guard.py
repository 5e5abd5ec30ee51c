"""harness.guard: whatever a simulator returns, no non-finite state, no broken attitude
and no body through the ground leaves run_simulator with a normal status."""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness.guard import PENETRATION_TOLERANCE, guard_trajectory
from reference import geometry
from reference import quaternion as qt
from reference.trajectory import ImpactEvent, Status, Trajectory
from tests.conftest import make_scene


def trajectory(scene, states, impacts=()) -> Trajectory:
    """A t_end run through the given states, one per 0.01 s, energies from geometry."""
    states = np.asarray(states, dtype=float)
    ke, pe = geometry.energies(scene, states)
    t = 0.01 * np.arange(len(states))
    return Trajectory.from_states(
        "fake", scene.name, t, states, ke, pe, list(impacts), Status.T_END,
        message="reached t_end", t_final=float(t[-1]), dt=0.01,
    )  # fmt: skip


def resting_states(n_rows: int, tilt: float = 0.02, height: float = 0.05) -> np.ndarray:
    y = np.zeros((n_rows, 13))
    y[:, 3:7] = qt.from_rotation_vector(np.array([tilt, 0.0, 0.0]))
    y[:, 2] = height
    return y


def test_a_valid_run_passes_unchanged():
    scene = make_scene(n=3)
    traj = trajectory(scene, resting_states(20))
    assert guard_trajectory(scene, traj) is traj


@pytest.mark.parametrize(
    "break_row",
    [
        lambda y: y.__setitem__((7, 9), math.nan),  # a NaN velocity
        lambda y: y.__setitem__((7, 0), math.inf),  # an infinite position
        lambda y: y.__setitem__((7, slice(3, 7)), 0.0),  # a null quaternion
        lambda y: y.__setitem__((7, slice(3, 7)), [1.001, 0, 0, 0]),  # not a rotation
    ],
    ids=["nan", "inf", "null-quaternion", "norm-1.001"],
)
def test_the_run_is_cut_at_the_first_invalid_sample(break_row):
    scene = make_scene(n=3)
    y = resting_states(20)
    break_row(y)
    impacts = [ImpactEvent(0.03, 0, 0.1, -1, 0.5), ImpactEvent(0.09, 1, 0.1, -1, 0.5)]
    out = guard_trajectory(scene, trajectory(scene, y, impacts))
    assert out.status is Status.FAILED and out.n_samples == 7
    assert "t = 0.07" in out.message and "reached t_end" in out.message
    assert np.isfinite(out.energy).all() and out.t_final == pytest.approx(0.06)
    assert [e.t for e in out.impacts] == [0.03]  # the impact after the cut is dropped


def test_a_vertex_deeper_than_the_tolerance_fails_and_a_shallower_one_passes():
    """Triangle tilted by 0.3 rad, its lowest vertex first on the ground, then lowered:
    to −0.04 a it passes, to −0.06 a (beyond the 0.05 a tolerance) it fails there."""
    scene = make_scene(n=3)
    y = resting_states(10, tilt=0.3, height=0.0)
    lowest = geometry.scene_contact_kinematics(scene, y[:1])[0].min()
    for depth, ok in ((-0.04, True), (-(PENETRATION_TOLERANCE + 0.01), False)):
        z = y.copy()
        z[:, 2] = -lowest
        z[5:, 2] += depth
        out = guard_trajectory(scene, trajectory(scene, z))
        assert (out.status is Status.T_END) == ok
        if not ok:
            assert out.n_samples == 5 and "below the ground" in out.message


def test_the_circle_bound_finds_a_deep_vertex_of_a_large_polygon():
    """n = 10,000: only rows whose circumcircle dips below the tolerance get exact gaps;
    the first deep row is still found exactly."""
    scene = make_scene(n=10_000)
    y = resting_states(200, tilt=0.1, height=0.0)
    y[:, 2] = 1.0 * math.sin(0.1) + 0.01  # every vertex above the ground
    y[150:, 2] -= 0.2  # now the lowest vertex is 0.19 a below
    out = guard_trajectory(scene, trajectory(scene, y))
    assert out.status is Status.FAILED and out.n_samples == 150


def test_an_impact_with_a_nan_impulse_cuts_the_run_there():
    scene = make_scene(n=3)
    impacts = [ImpactEvent(0.03, 0, 0.1, -1, 0.5), ImpactEvent(0.055, 1, math.nan, -1, 0.5)]
    out = guard_trajectory(scene, trajectory(scene, resting_states(20), impacts))
    assert out.status is Status.FAILED and out.t_final <= 0.055 and len(out.impacts) == 1
