"""Gravity-free chatter (paper §4): the rod's formulas and the CC/PCC properties, checked
against the eigenvalues they stand for and against simulations of the same model."""

import math

import numpy as np
import pytest

from reference.linear.chatter import (
    analyze_chatter,
    c_lin,
    format_chatter,
    gravity_free_selfsimilar,
    gravity_free_stability,
    pcc_property,
    rod_betas,
    rod_conditions,
)
from reference.linear.model import LinearModel
from reference.linear.simulate import run_linear, run_linear_exponent
from reference.trajectory import Status


@pytest.mark.parametrize("rho, gamma", [(0.3, 0.2), (0.2, 0.5), (0.1, 0.8), (0.45, 0.05)])
def test_rod_eigenvalues_are_the_rod_formulas(rho, gamma):
    """R⁻¹U0 of the 2-gon has eigenvalues −1 (the roll about the rod's axis) and the
    roots of x² − ψ(1+γ)x + γ, i.e. β_p, β_q of the literature."""
    m = LinearModel.polygon(2, rho, gamma)
    lam = np.linalg.eigvals(m.R.T @ m.U(0))
    assert np.min(np.abs(lam + 1)) < 1e-14
    rest = np.sort_complex(lam[np.argsort(np.abs(lam + 1))[1:]])
    b = rod_betas(rho, gamma)
    if b is None:  # complex pair: the quadratic's discriminant is negative
        psi = (1 - rho * rho) / (1 + rho * rho)
        assert np.all(np.abs(rest.imag) > 0)
        assert np.allclose(np.real(rest), psi * (1 + gamma) / 2)
    else:
        assert np.allclose(np.sort(rest.real), sorted(b), rtol=1e-13)
        assert b[0] * b[1] == pytest.approx(gamma, rel=1e-14)


@pytest.mark.parametrize("gamma", [0.05, 0.3, 0.7])
def test_c_lin_is_two_on_the_gravity_condition_boundary(gamma):
    psi = (gamma ** (1 / 3) + gamma ** (2 / 3)) / (1 + gamma)
    rho = math.sqrt((1 - psi) / (1 + psi))
    bp, bq = rod_betas(rho, gamma)
    assert bp == pytest.approx(gamma ** (1 / 3), rel=1e-7)
    assert c_lin(bp, bq) == pytest.approx(2.0, rel=1e-6)


def test_rod_cc_property_is_goyal_condition():
    for rho in np.linspace(0.05, 0.95, 19):
        for gamma in np.linspace(0.02, 0.98, 25):
            doc = analyze_chatter(2, float(rho), float(gamma))
            cond = rod_conditions(float(rho), float(gamma))
            if abs(cond["psi"] - cond["psi_threshold_without_gravity"]) > 1e-9:
                assert doc["cc"] == cond["cc_without_gravity"]
            # the gravity condition is stricter (Or's)
            assert cond["psi_threshold_with_gravity"] >= cond["psi_threshold_without_gravity"]


@pytest.mark.parametrize("rho, gamma", [(0.3, 0.2), (0.1, 0.5)])
def test_gravity_free_rod_chatter_has_exponent_c_lin(rho, gamma):
    m = LinearModel.polygon(2, rho, gamma, gravity=0.0)
    run = run_linear(m, [0.0, 0.01, 0.05], [0.0, 0.1, -1.0], energy_floor=1e-40)
    from reference.linear.exponent_estimates import exponent_of_run

    ex = exponent_of_run(run)
    cl = analyze_chatter(2, rho, gamma)["c_lin"]
    assert ex["c_period"] == pytest.approx(cl, rel=1e-9) and ex["period"] == 1
    assert ex["c"] == pytest.approx(cl, rel=1e-6)


@pytest.mark.parametrize("rho, gamma", [(0.3, 0.2), (0.2, 0.3), (0.35, 0.1)])
def test_rod_with_gravity_under_or_condition_reaches_c_lin(rho, gamma):
    """ψ above Or's threshold: gravity becomes negligible and c → c_lin (paper §4.2)."""
    assert rod_conditions(rho, gamma)["cc_with_gravity"]
    r = run_linear_exponent(2, rho, gamma, [0.0, 0.01, 0.05], [0.0, 0.1, -1.0], energy_floor=1e-40)
    assert r["status"] == "singularity"
    assert r["c"] == pytest.approx(analyze_chatter(2, rho, gamma)["c_lin"], rel=1e-6)


def test_pcc_matrix_is_two_alternating_impacts():
    m = LinearModel.polygon(3, 0.2, 0.3)
    assert np.allclose(m.U(0) @ m.R @ m.U(0) @ m.R.T, m.U(0) @ m.U(1), atol=1e-15)


def test_triangle_regions_nest_pcc_inside_cc():
    """The PCC region lies inside the CC region (paper Fig. numsim)."""
    for rho in np.linspace(0.05, 0.6, 12):
        for gamma in np.linspace(0.02, 0.9, 12):
            d = analyze_chatter(3, float(rho), float(gamma))
            assert d["cc"] or not d["pcc"]


def test_triangle_with_pcc_chatters_on_two_vertices_into_an_undecidable_impact():
    rho, gamma = 0.15, 0.05
    assert pcc_property(LinearModel.polygon(3, rho, gamma))
    m = LinearModel.polygon(3, rho, gamma, gravity=0.0)
    run = run_linear(m, [0.003, 0.01, 0.05], [0.1, -0.05, -1.0])
    assert run.status is Status.SIMULTANEOUS_IMPACT


def test_chatter_document():
    doc = analyze_chatter(3, 0.2, 0.3)
    assert doc["cc"] and not doc["pcc"]
    assert doc["beta_p"] > doc["beta_q"] > 0 and doc["c_lin"] == pytest.approx(
        c_lin(doc["beta_p"], doc["beta_q"])
    )
    assert "CC" in format_chatter(doc)


def test_rod_chatter_is_stable_and_triangle_chatter_unstable():
    """Paper §4.3: the triangle's self-similar chatter is unstable, unlike the rod's."""
    rod = LinearModel.polygon(2, 0.3, 0.2)
    ss = gravity_free_selfsimilar(rod, *rod_betas(0.3, 0.2))
    assert np.max(np.abs(gravity_free_stability(rod, ss["p0"], ss["q0"]))) < 1
    d = analyze_chatter(3, 0.2, 0.3)
    assert d["pairs"] and all(not x["stable"] for x in d["pairs"])


@pytest.mark.parametrize("rho, gamma", [(0.2, 0.3), (0.2, 0.36)])
def test_triangle_chatter_instability_matches_perturbation_growth(rho, gamma):
    """Predicted spectral radius of the gravity-free chatter map = growth per impact of a
    1e-10 perturbation in a gravity-free simulation (p and q normalised separately)."""
    m = LinearModel.polygon(3, rho, gamma, gravity=0.0)
    d = analyze_chatter(3, rho, gamma)
    ss = gravity_free_selfsimilar(m, d["beta_p"], d["beta_q"])
    p0, q0 = ss["p0"] / np.linalg.norm(ss["p0"]), ss["q0"] / np.linalg.norm(ss["q0"])
    radius = np.max(np.abs(gravity_free_stability(m, p0, q0)))
    dq = np.array([0.3, 0.5, 0.0])
    dq -= m.F[0] * (m.F[0] @ dq) / (m.F[0] @ m.F[0])
    run = run_linear(m, q0 + 1e-10 * dq, p0 + 1e-10 * np.array([1.0, -0.4, 0.2]),
                     max_impacts=40, energy_floor=0.0)  # fmt: skip
    dev = []
    for k, i in enumerate(run.impact_rows):
        assert run.contact[i] == k % 3
        Rk = np.linalg.matrix_power(m.R.T, k)
        pp, qq = Rk @ run.p_pre[i], Rk @ run.q_pre[i]
        dev.append(
            np.linalg.norm(np.r_[pp / np.linalg.norm(pp) - p0, qq / np.linalg.norm(qq) - q0])
        )
    growth = np.exp(np.polyfit(np.arange(3, len(dev)), np.log(dev[3:]), 1)[0])
    assert growth == pytest.approx(radius, rel=0.02) and radius > 1
