"""Chatter (Zeno) with 0 < γ < 1: completion against one-by-one resolution, and the
linear-limit bouncing point."""

from __future__ import annotations

import numpy as np
import pytest

from reference import quaternion as qt
from reference.core.contacts import vertex_lever
from reference.simulate import ReferenceOptions, simulate
from tests.conftest import make_scene


def _post_impact_on_vertex(u, tilt=0.05, spin=(0.0, 0.0, 0.0)):
    """Vertex 0 (body point (1, 0, 0)) on the ground moving up at u (just after an
    impact); the others in the air."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector([0.2 * tilt, tilt, 0.0])
    y[10:13] = spin
    rx, ry, rz = vertex_lever(y, 1.0, 0.0)
    y[2] = -rz
    y[9] = u - (y[10] * ry - y[11] * rx)
    return y


def _chatter_scene(gamma, u=0.02):
    y0 = _post_impact_on_vertex(u, spin=(0.01, -0.01, 0.1))
    return make_scene(n=3, gamma=gamma, state=y0, t_end=2 * u / (1 - gamma) + 0.02)


def _difference(a, b):
    dt = abs(a.stats["chatter_accumulation_times"][0] - b.stats["chatter_accumulation_times"][0])
    ds = max(
        np.max(np.abs(a.position[-1] - b.position[-1])),
        np.max(np.abs(a.velocity[-1] - b.velocity[-1])),
        np.max(np.abs(a.angular_velocity[-1] - b.angular_velocity[-1])),
        qt.angle_between(a.quaternion[-1], b.quaternion[-1]),
    )
    return dt, ds


@pytest.mark.parametrize("gamma", [0.3, 0.5, 0.8])
def test_completed_chatter_agrees_with_one_by_one_resolution(gamma):
    """Completion at u ≤ 1e-4 V (skipping a third or more of the impacts) against
    resolution one by one down to the resolvable floor (bounce height 1e4 roundoff bands
    of the gap; chatter_tol = 0): accumulation time and state after the chatter agree
    to ≤ 1e-9."""
    scene = _chatter_scene(gamma)
    early = simulate(scene, options=ReferenceOptions(chatter_tol=1e-4))
    full = simulate(scene, options=ReferenceOptions(chatter_tol=0.0))
    assert early.stats["chatter_completions"] >= 1
    assert len(full.impacts) > len(early.impacts)
    dt, ds = _difference(early, full)
    assert dt <= 1e-9 and ds <= 1e-9


def test_completion_error_falls_as_the_square_of_the_completion_speed():
    """The completion's error bound O((u/V)²): ten times smaller u gives ≥ 30× smaller
    accumulation-time error (measured ≈ 100×)."""
    scene = _chatter_scene(0.8)
    full = simulate(scene, options=ReferenceOptions(chatter_tol=0.0))
    e2 = _difference(simulate(scene, options=ReferenceOptions(chatter_tol=1e-2)), full)[0]
    e3 = _difference(simulate(scene, options=ReferenceOptions(chatter_tol=1e-3)), full)[0]
    assert e2 / e3 >= 30


@pytest.mark.parametrize("gamma", [0.25, 0.5, 0.75])
def test_single_vertex_chatter_in_the_linear_limit_is_a_bouncing_point(gamma):
    """Linear limit (paper §2.4): a vertex in free flight has acceleration −g, impacts
    reverse its normal velocity with factor γ, so after leaving at speed u it hits at
    intervals 2u γ^k / g and comes to rest at t∞ = 2u / (g (1 − γ)).  At scale ε the
    nonlinear terms are O(ε²) relative."""
    eps = 1e-4
    u = 1.0 * eps
    y0 = _post_impact_on_vertex(u, tilt=100 * u * u, spin=(0.0, 0.0, 0.0))
    traj = simulate(
        make_scene(n=3, gamma=gamma, state=y0, t_end=3.0 * u / (1 - gamma)),
        options=ReferenceOptions(chatter_tol=1e-12),
    )
    ts = np.array([e.t for e in traj.impacts[:6]])
    expect = np.cumsum(2 * u * gamma ** np.arange(6) / 1.0)
    assert all(e.contact == 0 for e in traj.impacts)
    assert np.max(np.abs(ts - expect)) <= 1e-6 * u
    t_inf = traj.stats["chatter_accumulation_times"][0]
    assert abs(t_inf - 2 * u / (1 - gamma)) <= 1e-6 * u
    # after the accumulation the vertex is held (sustained contact)
    assert traj.phases[-1].kind == "contact" and traj.phases[-1].contacts == (0,)
