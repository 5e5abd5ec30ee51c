"""Self-similar motion (paper §3): every analytic result against a direct simulation."""

import numpy as np
import pytest

from reference.linear.model import LinearModel
from reference.linear.selfsimilar import (
    analyze_selfsimilar,
    finite_difference_jacobian,
    format_selfsimilar,
    reduced_map,
    reduced_map_jacobian,
    selfsimilar_solutions,
    selfsimilar_state,
)
from reference.linear.simulate import run_linear

CASES = [(25, 0.5, 0.0), (6, 0.5, 0.0), (4, 0.5, 0.0), (25, 0.5, 0.5), (3, 0.5, 0.3),
         (3, 0.25, 0.3), (25, 0.25, 0.3), (20, 0.5, 0.6)]  # fmt: skip


def _feasible(n, rho, gamma):
    m = LinearModel.polygon(n, rho, gamma)
    sols = [s for s in selfsimilar_solutions(m) if s.feasible]
    assert sols, "expected a feasible self-similar motion"
    return m, sols[0]


@pytest.mark.parametrize("n, rho, gamma", CASES)
def test_one_simulated_step_returns_the_scaled_rotated_state(n, rho, gamma):
    """From (q0, p0) the exact simulator hits vertex 0, then vertex 1 after τ0 in the state
    (β² R q0, β R p0) (eqs. selfsimilar1-2) to 1e-12."""
    m, s = _feasible(n, rho, gamma)
    run = run_linear(m, s.q0, s.p0, max_impacts=2, energy_floor=0.0)
    i0, i1 = run.impact_rows[:2]
    assert (run.contact[i0], run.contact[i1]) == (0, 1)
    assert run.dt[i1] == pytest.approx(s.tau0, rel=1e-12)
    R = m.R
    assert np.linalg.norm(run.p_pre[i1] - s.beta * R @ s.p0) <= 1e-12 * np.linalg.norm(s.p0)
    assert np.linalg.norm(run.q_pre[i1] - s.beta**2 * R @ s.q0) <= 1e-12 * np.linalg.norm(s.q0)


@pytest.mark.parametrize("n, rho, gamma", CASES[:5])
def test_solution_is_a_fixed_point_of_the_reduced_map(n, rho, gamma):
    m, s = _feasible(n, rho, gamma)
    p1, q1, tau = reduced_map(m, s.p0, s.q0)
    assert np.allclose(p1, s.p0, atol=1e-13) and np.allclose(q1, s.q0, atol=1e-13)
    assert tau == pytest.approx(s.tau0, rel=1e-12)


@pytest.mark.parametrize("n, rho, gamma", CASES)
def test_closed_form_jacobian_matches_finite_differences(n, rho, gamma):
    m, s = _feasible(n, rho, gamma)
    J = reduced_map_jacobian(m, s.p0, s.q0)
    Jfd = finite_difference_jacobian(m, s.p0, s.q0, h=1e-6)
    assert np.max(np.abs(J - Jfd)) <= 1e-6 * max(1.0, np.max(np.abs(J)))


@pytest.mark.parametrize("n, rho, gamma, zeros", [(6, 0.5, 0.0, 4), (25, 0.3, 0.0, 4),
                                                  (10, 0.5, 0.5, 2), (3, 0.5, 0.3, 2)])  # fmt: skip
def test_jacobian_has_the_structural_zero_eigenvalues(n, rho, gamma, zeros):
    """|p| = 1 and f0ᵀq = 0 on the image (and, for γ = 0, the held vertex's gap and
    velocity): 4 zero eigenvalues for γ = 0, 2 for γ > 0 (paper §3.3, §3.5)."""
    _, s = _feasible(n, rho, gamma)
    lam = np.sort(np.abs(s.eigenvalues))
    # (the zeros form nilpotent blocks: computed eigenvalues are ~√ε there)
    assert np.all(lam[:zeros] < 1e-6) and np.all(lam[zeros:] > 1e-2)


def _growth_per_impact(m, s, n_impacts, eps=1e-9):
    """Perturb the self-similar state (keeping f0ᵀq = 0, and for γ = 0 the held vertex
    n−1 at rest on the ground), simulate, and fit the growth of the normalised, rotated
    pre-impact states' distance from the fixed point per impact."""
    n, F = m.n_contacts, m.F
    C = [np.r_[np.zeros(3), F[0]]]
    if m.restitution == 0:
        C += [np.r_[F[n - 1], np.zeros(3)], np.r_[np.zeros(3), F[n - 1]]]
    C = np.array(C).T
    d = np.random.default_rng(0).normal(size=6)
    d -= C @ np.linalg.lstsq(C, d, rcond=None)[0]
    d *= eps / np.linalg.norm(d)
    run = run_linear(m, s.q0 + d[3:], s.p0 + d[:3], max_impacts=n_impacts, energy_floor=0.0)
    x_star = np.r_[s.p0, s.q0]
    dev = []
    for k, i in enumerate(run.impact_rows):
        assert run.contact[i] == k % n
        Rk = np.linalg.matrix_power(m.R.T, k)
        pn = np.linalg.norm(run.p_pre[i])
        dev.append(
            np.linalg.norm(np.r_[Rk @ run.p_pre[i] / pn, Rk @ run.q_pre[i] / pn**2] - x_star)
        )
    k = np.arange(len(dev))
    return float(np.exp(np.polyfit(k[5:], np.log(dev[5:]), 1)[0]))


@pytest.mark.parametrize("n, rho, gamma, impacts", [(6, 0.5, 0.0, 60), (3, 0.5, 0.3, 60),
                                                    (10, 0.5, 0.5, 300)])  # fmt: skip
def test_predicted_stability_matches_perturbation_growth_in_simulation(n, rho, gamma, impacts):
    """The spectral radius of the Jacobian of C̄ is the measured growth factor per impact
    of a small perturbation: < 1 (decay) for γ = 0, > 1 (growth) for γ > 0 here."""
    m, s = _feasible(n, rho, gamma)
    g = _growth_per_impact(m, s, impacts)
    assert g == pytest.approx(s.spectral_radius, rel=5e-3)
    assert (g < 1) == s.stable


def test_nontrivial_roots_satisfy_the_gap_condition_and_trivial_ones_are_eigenvectors():
    for n, rho, gamma in [(4, 0.3, 0.0), (25, 0.25, 0.3), (3, 0.5, 0.0)]:
        m = LinearModel.polygon(n, rho, gamma)
        M = m.R.T @ m.U(0)
        for s in selfsimilar_solutions(m):
            if s.trivial:
                assert np.allclose(M @ s.p0, s.beta * s.p0, atol=1e-12)
                assert not s.feasible
            else:
                q0, _ = selfsimilar_state(m, s.beta)
                assert abs(m.F[0] @ q0) <= 1e-12 * np.linalg.norm(q0)


def test_infeasible_root_fails_non_penetration():
    """n = 25, ρ = 0.25, γ = 0.3 has three self-similar β; the two small ones have a
    vertex below the ground: simulated from them, the motion is not the predicted one."""
    m = LinearModel.polygon(25, 0.25, 0.3)
    sols = [s for s in selfsimilar_solutions(m) if not s.trivial]
    assert len(sols) == 3 and sum(s.feasible for s in sols) == 1
    for s in sols:
        run = run_linear(m, s.q0, s.p0, max_impacts=2, energy_floor=0.0)
        imp = run.impact_rows
        reproduced = (
            len(imp) == 2
            and tuple(run.contact[imp]) == (0, 1)
            and abs(run.dt[imp[1]] - s.tau0) <= 1e-12 * s.tau0
        )
        assert reproduced == s.feasible


def test_analyze_document_has_the_contract_fields():
    doc = analyze_selfsimilar(25, 0.5, 0.0)
    assert {"n", "gyration", "restitution", "solutions"} <= set(doc)
    s = doc["solutions"][0]
    assert {"beta", "trivial", "feasible", "stable", "spectral_radius", "eigenvalues", "p0",
            "q0"} <= set(s)  # fmt: skip
    assert "beta" in format_selfsimilar(doc)
