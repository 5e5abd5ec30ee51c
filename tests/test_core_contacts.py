"""Contact primitives of the compiled core (reference.core.contacts, inertia, held)
against the oracle's numpy expressions (tests/oracle): gap jets, the contact system
A = J M⁻¹ Jᵀ and b, the complementarity problem and the projections, on random states
over every ground (bumpy: both kinds at once)."""

from __future__ import annotations

import numpy as np
import pytest

from reference import quaternion as qt
from reference.core.contacts import contact_jet
from reference.core.held import contact_system, new_work
from reference.core.inertia import free_acceleration
from tests.conftest import core_model, make_scene
from tests.core_calls import (
    project_held_as_the_loop_does,
    solve_lcp_as_the_loop_does,
    zero_normal_velocities_as_the_loop_does,
)
from tests.oracle.body import BodyModel
from tests.oracle.contact import contact_system as oracle_system
from tests.oracle.contact import project_positions, project_velocities, solve_contact_lcp
from tests.oracle.events import gap_jet

GROUNDS = [("flat", 5), ("flat", 100), ("three_point", 3), ("bumpy", 12)]
# bumpy: rim vertices and bumps 0.01 a high, both kinds in one contact list
HEIGHT = {"bumpy": {"bump_height": 0.01}}


def _random_state(rng, tilt=0.2):
    y = np.zeros(13)
    y[0:3] = rng.normal(0, 0.1, 3)
    y[2] = 0.3
    y[3:7] = qt.from_rotation_vector([*rng.normal(0, tilt, 2), rng.uniform(-3, 3)])
    y[7:10] = rng.normal(0, 0.5, 3)
    y[10:13] = rng.normal(0, 2.0, 3)
    return y


@pytest.mark.parametrize("ground,n", GROUNDS)
def test_gap_jets_equal_the_oracles_array_expressions(ground, n):
    rng = np.random.default_rng(n)
    scene = make_scene(n=n, ground=ground, rho=0.43, **HEIGHT.get(ground, {}))
    model, pts = core_model(scene)
    oracle = BodyModel.from_scene(scene)
    for _ in range(20):
        y = _random_state(rng)
        acc = tuple(float(a) for a in rng.normal(0, 1, 6))
        ref = gap_jet(oracle, y, np.array(acc))
        for k in range(len(pts)):
            j = contact_jet(y, scene.contacts.kind(k), pts, k, acc)
            assert abs(j.gap - ref.gap[k]) <= 4e-16
            assert abs(j.rate - ref.rate[k]) <= 1e-14
            assert abs(j.accel - ref.accel[k]) <= 1e-13
            assert j.noise == pytest.approx(ref.noise[k], rel=1e-12, abs=1e-30)


@pytest.mark.parametrize("ground,n", GROUNDS)
def test_contact_system_equals_the_oracles(ground, n):
    rng = np.random.default_rng(7 + n)
    scene = make_scene(n=n, ground=ground, rho=0.43, **HEIGHT.get(ground, {}))
    model, pts = core_model(scene)
    oracle = BodyModel.from_scene(scene)
    scratch = new_work()
    work = scratch[0]
    for _ in range(20):
        y = _random_state(rng)
        idx = np.array(sorted(rng.choice(len(pts), 3, replace=False)))
        i1, _, i3 = scene.body.inertia_diag
        contact_system(y, model, pts, idx, 3, free_acceleration(y, i1, i3, 1.0), work)
        A, b, *_ = oracle_system(oracle, y, list(idx))
        np.testing.assert_allclose(work["A"], A, rtol=0, atol=1e-14)
        np.testing.assert_allclose(work["b"], b, rtol=0, atol=1e-13)


def test_lcp_chooses_the_oracles_active_set():
    """Two or three candidates at rest on the ground, random motions: the same active
    contacts as the oracle's enumeration."""
    rng = np.random.default_rng(3)
    scene = make_scene(n=6, rho=0.4)
    model, pts = core_model(scene)
    oracle = BodyModel.from_scene(scene)
    active = np.empty(4, dtype=np.int64)
    held = 0
    for _ in range(200):
        y = _random_state(rng, tilt=0.05)
        cand = np.array(sorted(rng.choice(6, 2, replace=False)))
        n = solve_lcp_as_the_loop_does(y, model, pts, cand, 2, active)
        expect, _ = solve_contact_lcp(oracle, y, list(cand))
        assert sorted(active[:n].tolist()) == sorted(expect)
        held += n
    assert held > 50  # both outcomes occur


@pytest.mark.parametrize("ground,n", GROUNDS)
def test_projection_equals_the_oracles(ground, n):
    """A state a little off two held contacts, projected back: the same state as the
    oracle's Gauss–Newton passes and normal impulses, and the held gaps and normal
    velocities at roundoff."""
    rng = np.random.default_rng(11 + n)
    scene = make_scene(n=n, ground=ground, rho=0.43, **HEIGHT.get(ground, {}))
    model, pts = core_model(scene)
    oracle = BodyModel.from_scene(scene)
    for _ in range(10):
        y = np.zeros(13)  # lying flat on every contact, then moved by 1e-6
        y[3] = 1.0
        y[0:7] += rng.normal(0, 1e-6, 7)
        y[3:7] /= np.linalg.norm(y[3:7])
        y[7:13] = rng.normal(0, 0.5, 6)
        idx = np.array([0, 1, 0])
        ours = y.copy()
        assert project_held_as_the_loop_does(ours, model, pts, idx, 2)
        ref = project_velocities(oracle, project_positions(oracle, y, [0, 1]), [0, 1])
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-13)
        gap, _, _, vn, _ = oracle.contacts(ours, np.array([0, 1]))
        assert np.max(np.abs(gap)) < 1e-14 and np.max(np.abs(vn)) < 1e-13


def test_zero_normal_velocities_keep_horizontal_momentum_and_vertical_spin():
    scene = make_scene(n=5, rho=0.43)
    model, pts = core_model(scene)
    y = _random_state(np.random.default_rng(1))
    before = y.copy()
    assert zero_normal_velocities_as_the_loop_does(y, model, pts, [0, 2], 2)
    np.testing.assert_allclose(y[7:9], before[7:9], rtol=0, atol=1e-15)
    i1, _, i3 = scene.body.inertia_diag

    def lz(s):
        e3 = qt.body_axis(s[3:7])
        return (i1 * s[10:13] + (i3 - i1) * (s[10:13] @ e3) * e3)[2]

    assert abs(lz(y) - lz(before)) < 1e-14
