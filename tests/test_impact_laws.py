"""Impact laws of simultaneous impacts (reference.core.impact_laws): Moreau's law against
an LCP solved by enumerating active sets (tests/oracle/lcp.py), its reduction to eq. F,
the uniqueness of u⁺ where the impulses are not unique, and the invariants of every law
(energy, horizontal momentum, vertical angular momentum, no contact left approaching)
on random states of the real body with 2 to 6 touching contacts."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from reference import quaternion as qt
from reference.core.impact_laws import (
    MAX_SEQUENTIAL_IMPACTS,
    NOT_SETTLED,
    SETTLED,
    moreau_impulses,
    sequential_impulses,
)
from tests.conftest import make_scene, tilted_spinning_state
from tests.oracle.body import BodyModel
from tests.oracle.impact import impact_impulse
from tests.oracle.lcp import delassus, moreau_lcp


def _moreau(W, u, gamma):
    k = len(u)
    lam, u_post = np.zeros(k), np.zeros(k)
    status = moreau_impulses(
        np.ascontiguousarray(W), np.ascontiguousarray(u), gamma, k, lam, u_post,
        np.zeros((k, k)), np.zeros(2 * k), np.zeros(k, dtype=np.int64),
    )  # fmt: skip
    assert status == SETTLED
    return lam, u_post


def _sequential(W, u, gamma, order=(), max_hits=MAX_SEQUENTIAL_IMPACTS):
    k = len(u)
    lam, u_post = np.zeros(k), np.zeros(k)
    o = np.array(order, dtype=np.int64)
    status, hits = sequential_impulses(
        np.ascontiguousarray(W), np.ascontiguousarray(u), gamma, k, o, len(o), lam, u_post,
        max_hits,
    )  # fmt: skip
    return status, hits, lam, u_post


def _flat_state(rng, yaw=0.0, approach=True):
    """A body lying flat on the ground (every vertex touching) with a random velocity;
    approach: every vertex approaching."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector([0.0, 0.0, yaw])
    y[7:10] = rng.normal(size=3) * [0.3, 0.3, 0.2]
    y[10:13] = rng.normal(size=3) * 0.3
    if approach:
        y[9] = -1.0 - 0.5 * np.linalg.norm(y[10:12])
    return y


def _edge_state(rng, n):
    """A tilted n-gon resting on its edge (vertices 0 and 1 at the ground)."""
    body = make_scene(n=n)
    model = BodyModel.from_scene(body)
    edge = model.vertices[1] - model.vertices[0]
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector(0.4 * edge / np.linalg.norm(edge))
    y[2] = -model.contacts(y, np.array([0]))[0][0]
    y[7:10] = rng.normal(size=3) * 0.3 + [0, 0, -1.0]
    y[10:13] = rng.normal(size=3) * 0.2
    return body, y


def _cases(seed=0, per_case=6):
    """(scene, state, contacts) with 2..6 touching contacts: flat n-gons (n = 3..6: W of
    rank 3, degenerate beyond three), subsets of a flat octagon, an edge, the three
    bumps under a flat face."""
    rng = np.random.default_rng(seed)
    for n in (3, 4, 5, 6):
        for rho in (0.3, 0.5):
            scene = make_scene(n=n, rho=rho, gamma=0.5)
            for _ in range(per_case):
                yield scene, _flat_state(rng, yaw=rng.uniform(0, 6)), list(range(n))
    scene = make_scene(n=8)
    for size in (2, 3, 4, 5, 6):
        for _ in range(per_case):
            cs = sorted(rng.choice(8, size=size, replace=False).tolist())
            yield scene, _flat_state(rng, approach=False), cs
    for n in (3, 7):
        for _ in range(per_case):
            scene, y = _edge_state(rng, n)
            yield scene, y, [0, 1]
    scene = make_scene(n=3, ground="three_point", bump=0.6)
    for _ in range(per_case):
        yield scene, _flat_state(rng), [0, 1, 2]


CASES = list(_cases())


@pytest.mark.parametrize("ground", ["flat", "three_point"])
@pytest.mark.parametrize("gamma", [0.0, 0.4, 1.0])
def test_moreau_with_one_contact_is_eq_F(gamma, ground):
    scene = make_scene(n=5, gamma=gamma, ground=ground)
    model = BodyModel.from_scene(scene)
    y = tilted_spinning_state()
    _, _, W, u = delassus(model, y, [2])
    lam, u_post = _moreau(W, u, gamma)
    expected = impact_impulse(model, y, 2, gamma)
    assert lam[0] == pytest.approx(expected.impulse, rel=1e-14)
    assert u_post[0] == pytest.approx(-gamma * u[0], rel=1e-13, abs=1e-15)


@pytest.mark.parametrize("gamma", [0.0, 0.3, 0.8])
def test_moreau_matches_the_enumerated_lcp_on_real_bodies(gamma):
    """Same u⁺ and, where the impulses are unique, the same Λ; where they are not (W
    singular), the least-norm Λ of the enumerated solutions (measured on 1,500 random
    Delassus matrices: Λ within 6e-15, u⁺ within 3e-14 relative)."""
    for scene, y, cs in CASES:
        model = BodyModel.from_scene(scene)
        _, _, W, u = delassus(model, y, cs)
        lam, u_post = _moreau(W, u, gamma)
        oracle = moreau_lcp(W, u, gamma)
        scale = np.abs(u).max()
        np.testing.assert_allclose(u_post, oracle.u_post, rtol=0, atol=1e-12 * scale)
        lam_scale = np.abs(oracle.impulses).max() + 1e-300
        np.testing.assert_allclose(lam, oracle.impulses, rtol=0, atol=1e-10 * lam_scale)


def test_moreau_post_velocity_is_unique_where_impulses_are_not():
    """A flat hexagon (W of rank 3): every basic solution of the LCP has the same u⁺,
    a non-negative null vector of W added to Λ is another solution, and the law's Λ is
    the least-norm one."""
    rng = np.random.default_rng(3)
    scene = make_scene(n=6, rho=0.5)
    model = BodyModel.from_scene(scene)
    y = _flat_state(rng)
    _, _, W, u = delassus(model, y, list(range(6)))
    assert np.linalg.matrix_rank(W) == 3
    oracle = moreau_lcp(W, u, 0.5)
    assert len(oracle.all_u_post) > 1 and not oracle.unique_impulses
    for u_post in oracle.all_u_post:
        np.testing.assert_allclose(u_post, oracle.u_post, atol=1e-12)
    lam, u_post = _moreau(W, u, 0.5)
    null = np.linalg.svd(W)[2][3:]  # W's null space (3 vectors)
    other = lam + 0.1 * np.abs(lam).max() * null[0] / np.abs(null[0]).max()
    other = other if other.min() >= 0 else lam - (other - lam)
    assert other.min() >= 0
    np.testing.assert_allclose(u + W @ other, u_post, atol=1e-12)
    assert np.linalg.norm(lam) < np.linalg.norm(other)


def _approaching_cases():
    for scene, y, cs in CASES:
        model = BodyModel.from_scene(scene)
        J, Minv, W, u = delassus(model, y, cs)
        if (u <= 0).all():
            yield model, y, J, Minv, W, u


def _invariants(model, y, J, Minv, lam, u_post, flat):
    """(ΔT, Δ horizontal momentum, Δ vertical angular momentum about the centre) of the
    impulses Λ; the state's normal velocities after them are the law's u⁺."""
    dq = Minv @ J.T @ lam
    y_post = y.copy()
    y_post[7:10] += dq[:3]
    y_post[10:13] += dq[3:]
    dT = model.kinetic_energy(y_post) - model.kinetic_energy(y)
    dp = model.mass * dq[:2]
    dL = model.angular_momentum(y_post) - model.angular_momentum(y)
    u_pre = J @ np.concatenate([y[7:10], y[10:13]])
    u_now = J @ np.concatenate([y_post[7:10], y_post[10:13]])
    np.testing.assert_allclose(u_now, u_post, rtol=0, atol=1e-12 * np.abs(u_pre).max())
    return dT, dp, dL[2] if flat else 0.0


@pytest.mark.parametrize("gamma", [0.0, 0.5, 0.9])
@pytest.mark.parametrize("law", ["moreau", "sequential", "sequential-orders"])
def test_laws_dissipate_and_keep_the_momenta_frictionless_normals_keep(law, gamma):
    n_checked = 0
    for model, y, J, Minv, W, u in _approaching_cases():
        k = len(u)
        runs = []
        if law == "moreau":
            runs.append(_moreau(W, u, gamma))
        elif law == "sequential":
            status, _, lam, u_post = _sequential(W, u, gamma)
            assert status == SETTLED
            runs.append((lam, u_post))
        else:
            for order in itertools.islice(itertools.permutations(range(k)), 6):
                status, _, lam, u_post = _sequential(W, u, gamma, order)
                assert status == SETTLED
                runs.append((lam, u_post))
        for lam, u_post in runs:
            assert lam.min() >= 0
            assert u_post.min() >= -1e-12 * np.abs(u).max()  # none left approaching
            dT, dp, dLz = _invariants(model, y, J, Minv, lam, u_post, model.flat)
            T = model.kinetic_energy(y)
            assert dT <= 1e-13 * T
            np.testing.assert_allclose(dp, 0.0, atol=1e-14 * T)
            assert abs(dLz) <= 1e-14 * (1 + np.abs(model.angular_momentum(y)).max())
            if law == "moreau":  # ΔT = ½ Σ Λᵢ (1 − γ) u⁻ᵢ
                assert dT == pytest.approx(0.5 * (1 - gamma) * lam @ u, rel=1e-9, abs=1e-14)
        n_checked += 1
    assert n_checked >= 30


def test_sequential_with_one_contact_is_eq_F():
    W, u = np.array([[2.5]]), np.array([-0.7])
    status, hits, lam, u_post = _sequential(W, u, 0.3)
    assert (status, hits) == (SETTLED, 1)
    assert lam[0] == pytest.approx(1.3 * 0.7 / 2.5, rel=1e-15)
    assert u_post[0] == pytest.approx(0.21, rel=1e-15)


def test_sequential_fastest_first_hits_the_fastest_contact_first():
    W = np.array([[2.0, 0.5], [0.5, 2.0]])
    u = np.array([-0.2, -1.0])
    _, hits, lam, _ = _sequential(W, u, 0.0, max_hits=1)
    assert hits == 1 and lam[0] == 0 and lam[1] == pytest.approx(0.5)


def test_sequential_that_does_not_settle_says_so():
    """A flat hexagon with γ = 0 approaches rest geometrically: capped at three single
    impacts it has not settled."""
    rng = np.random.default_rng(5)
    model = BodyModel.from_scene(make_scene(n=6))
    y = _flat_state(rng)
    _, _, W, u = delassus(model, y, list(range(6)))
    status, hits, _, _ = _sequential(W, u, 0.0, max_hits=3)
    assert (status, hits) == (NOT_SETTLED, 3)
