"""The compliant impact law (reference.core.compliant): its single-contact restitution
against an integrated oscillator, eq. F with one contact, the invariants (energy, u⁺ =
u⁻ + WΛ, no contact left approaching, Λ ≥ 0) and the impulses against an independent
integration with event location (tests/oracle/compliant.py) on real bodies with 2 to 6
touching contacts (separating ones among them) and on random Delassus matrices, full
rank and of rank 3."""

from __future__ import annotations

import numpy as np
import pytest

from reference import ReferenceOptions, simulate
from reference.core.compliant import (
    SETTLED,
    compliant_impulses,
    compliant_mass_impulses,
    damping_ratio,
    restitution_of_damping,
    work_size,
)
from tests.conftest import make_scene, tilted_spinning_state
from tests.oracle import compliant as oracle
from tests.oracle.body import BodyModel
from tests.oracle.impact import impact_impulse
from tests.oracle.lcp import delassus
from tests.test_impact_law_runs import STARTS, _on_ground
from tests.test_impact_laws import CASES

# the oracle integrates at rtol 1e-13; measured agreement with the core: ≤ 3e-13 of
# max|u⁻| in u⁺ and of max Λ in Λ
ORACLE_TOL = 1e-10


def _compliant(W, u, gamma, mass=False):
    k = len(u)
    lam, u_post = np.zeros(k), np.zeros(k)
    solve = compliant_mass_impulses if mass else compliant_impulses
    status = solve(
        np.ascontiguousarray(W, dtype=float), np.ascontiguousarray(u, dtype=float),
        float(gamma), k, lam, u_post, np.zeros(work_size(k)), np.zeros(k, dtype=np.int64),
    )  # fmt: skip
    assert status == SETTLED
    return lam, u_post


@pytest.mark.parametrize("zeta", [0.0, 0.1, 0.5, 0.9, 0.999, 1.0, 1.001, 1.7, 6.0])
def test_the_single_contact_restitution_matches_the_integrated_oscillator(zeta):
    expected = 1.0 if zeta == 0.0 else oracle.single_restitution(zeta)
    assert restitution_of_damping(zeta) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("gamma", [1e-6, 0.01, 0.2, np.exp(-2.0), 0.5, 0.9, 1.0 - 1e-9])
def test_the_damping_ratio_inverts_the_restitution_to_roundoff(gamma):
    assert restitution_of_damping(damping_ratio(gamma)) == pytest.approx(gamma, rel=4e-15)


def test_the_limits_are_undamped_and_infinitely_damped():
    assert damping_ratio(1.0) == 0.0 and damping_ratio(0.0) == np.inf


@pytest.mark.parametrize("mass", [False, True])
@pytest.mark.parametrize("gamma", [0.0, 0.01, 0.1, np.exp(-2.0), 0.3, 0.7, 0.99, 1.0])
def test_one_contact_is_eq_F(gamma, mass):
    scene = make_scene(n=5, gamma=gamma)
    model = BodyModel.from_scene(scene)
    y = tilted_spinning_state()
    _, _, W, u = delassus(model, y, [2])
    lam, u_post = _compliant(W, u, gamma, mass)
    assert u_post[0] == pytest.approx(-gamma * u[0], rel=1e-12, abs=1e-12 * abs(u[0]))
    assert lam[0] == pytest.approx(impact_impulse(model, y, 2, gamma).impulse, rel=1e-12)


def _check_invariants(W, u, lam, u_post, gamma):
    scale = np.abs(u).max()
    np.testing.assert_allclose(u_post, u + W @ lam, rtol=0, atol=1e-13 * scale)
    assert lam.min() >= 0.0
    assert u_post.min() >= -1e-12 * scale  # every contact leaves
    d_energy = 0.5 * lam @ (u + u_post)  # ΔT = ½Λᵀ(u⁻ + u⁺)
    energy = 0.5 * lam @ W @ lam + 1e-300
    assert d_energy <= 1e-12 * energy
    if gamma == 1.0:
        assert abs(d_energy) <= 1e-12 * energy


@pytest.mark.parametrize("gamma", [0.0, 0.2, 0.7, 1.0])
def test_invariants_on_real_bodies_with_2_to_6_contacts(gamma):
    separating = 0
    for scene, y, cs in CASES:
        _, _, W, u = delassus(BodyModel.from_scene(scene), y, cs)
        if u.min() >= 0:
            continue
        lam, u_post = _compliant(W, u, gamma)
        _check_invariants(W, u, lam, u_post, gamma)
        separating += int((u > 0).any())
    assert separating >= 5


@pytest.mark.parametrize("gamma", [0.05, 0.4, 0.8, 1.0])
def test_the_impulses_match_the_integrated_oracle_on_real_bodies(gamma):
    """Every third case of tests/test_impact_laws.CASES (flat n-gons n = 3..6, subsets of
    a flat octagon with separating contacts, edges, three bumps)."""
    for scene, y, cs in CASES[::3]:
        _, _, W, u = delassus(BodyModel.from_scene(scene), y, cs)
        if u.min() >= 0:
            continue
        lam, u_post = _compliant(W, u, gamma)
        lam_o, u_o = oracle.compliant_impulses(W, u, gamma)
        np.testing.assert_allclose(u_post, u_o, rtol=0, atol=ORACLE_TOL * np.abs(u).max())
        np.testing.assert_allclose(lam, lam_o, rtol=0, atol=ORACLE_TOL * np.abs(lam_o).max())


def _random_delassus(rng, k, rank):
    """W = J M⁻¹ Jᵀ of k normals sharing e_z (rows (1, a, b): no Λ ≥ 0 with JᵀΛ = 0),
    of the given rank ≤ 3, with random u⁻ (some contacts separating)."""
    J = np.column_stack([np.ones(k), rng.normal(size=(k, 2))])[:, :rank]
    Minv = np.diag(rng.uniform(0.3, 3.0, size=rank))
    v = rng.normal(size=rank)
    v[0] = -abs(v[0]) - 0.3
    return J @ Minv @ J.T, J @ v


@pytest.mark.parametrize("gamma", [0.1, 0.5, 1.0])
@pytest.mark.parametrize("k", [2, 3, 4, 6])
def test_the_impulses_match_the_oracle_on_random_delassus_matrices(k, gamma):
    rng = np.random.default_rng(k)
    for _ in range(4):
        W, u = _random_delassus(rng, k, min(k, 3))
        lam, u_post = _compliant(W, u, gamma)
        _check_invariants(W, u, lam, u_post, gamma)
        lam_o, u_o = oracle.compliant_impulses(W, u, gamma)
        np.testing.assert_allclose(u_post, u_o, rtol=0, atol=ORACLE_TOL * np.abs(u).max())
        np.testing.assert_allclose(lam, lam_o, rtol=0, atol=ORACLE_TOL * np.abs(lam_o).max())


def test_a_separating_contact_pushed_back_by_the_other_bounces():
    """Pushing contact 0 drives contact 1 (separating at 0.05) into the ground: it takes
    an impulse and leaves; the oracle agrees."""
    W = np.array([[1.0, -0.8], [-0.8, 1.0]])
    u = np.array([-1.0, 0.05])
    lam, u_post = _compliant(W, u, 0.5)
    lam_o, u_o = oracle.compliant_impulses(W, u, 0.5)
    assert lam[1] > 0.01
    np.testing.assert_allclose(lam, lam_o, rtol=0, atol=ORACLE_TOL)
    _check_invariants(W, u, lam, u_post, 0.5)


@pytest.mark.parametrize("seed", [7, 8, 9])
def test_the_plastic_limit_is_the_limit_of_small_restitution(seed):
    """γ = 0 (the springs vanish against the dashpots) is the limit γ → 0 of the law:
    measured |u⁺(γ) − u⁺(0)| ≈ (0.5 to 1) γ max|u⁻| for γ = 1e-2 .. 1e-5."""
    W, u = _random_delassus(np.random.default_rng(seed), 3, 3)
    _, u0 = _compliant(W, u, 0.0)
    for gamma in (1e-4, 1e-5):
        _, u_s = _compliant(W, u, gamma)
        assert np.abs(u0 - u_s).max() <= 2.0 * gamma * np.abs(u).max()


@pytest.mark.parametrize("case", list(STARTS))
def test_a_start_on_several_contacts_takes_the_compliant_impulses(case):
    n, rot, v, w = STARTS[case]
    scene, y = _on_ground(n, rot, v, w)
    model = BodyModel.from_scene(scene)
    touching = [int(k) for k in np.flatnonzero(model.contacts(y)[0] <= 1e-15)]
    traj = simulate(scene, options=ReferenceOptions(impact_law="compliant"))
    _, _, W, u = delassus(model, y, touching)
    lam_o, _ = oracle.compliant_impulses(W, u, scene.restitution)
    took = {e.contact: e.impulse for e in traj.impacts if e.t == 0.0}
    expected = {c: lam for c, lam in zip(touching, lam_o, strict=True) if lam > 0}
    assert set(took) == set(expected)
    for c, lam in expected.items():
        assert took[c] == pytest.approx(lam, rel=1e-9)
    assert traj.impact_law == "compliant"


@pytest.mark.parametrize("gamma", [0.0, 0.3, 1.0])
def test_the_mass_scaled_stiffness_keeps_the_invariants(gamma):
    for scene, y, cs in CASES[::2]:
        _, _, W, u = delassus(BodyModel.from_scene(scene), y, cs)
        if u.min() < 0:
            lam, u_post = _compliant(W, u, gamma, mass=True)
            _check_invariants(W, u, lam, u_post, gamma)


@pytest.mark.parametrize("gamma", [0.2, 0.7])
@pytest.mark.parametrize("k", [2, 3, 6])
def test_the_mass_scaled_stiffness_matches_the_oracle(k, gamma):
    """kᵢ ∝ 1/Wᵢᵢ against the integration with that stiffness; where the Wᵢᵢ differ the
    outcome differs from the uniform stiffness's."""
    rng = np.random.default_rng(10 + k)
    differs = 0.0
    for _ in range(4):
        W, u = _random_delassus(rng, k, min(k, 3))
        lam, u_post = _compliant(W, u, gamma, mass=True)
        lam_o, u_o = oracle.compliant_impulses(W, u, gamma, mass=True)
        np.testing.assert_allclose(u_post, u_o, rtol=0, atol=ORACLE_TOL * np.abs(u).max())
        np.testing.assert_allclose(lam, lam_o, rtol=0, atol=ORACLE_TOL * np.abs(lam_o).max())
        differs = max(differs, np.abs(u_post - _compliant(W, u, gamma)[1]).max())
    assert differs > 1e-3
