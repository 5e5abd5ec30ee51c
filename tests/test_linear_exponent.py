"""Energy exponent estimators (paper §3.4, §3.6, §4.3)."""

import math

import numpy as np
import pytest

from reference.linear.exponent_estimates import (
    exponent_from_decades,
    exponent_of_run,
    extrapolate_time_to_go,
    fit_energy_exponent,
    time_to_go,
)
from reference.linear.model import LinearModel
from reference.linear.selfsimilar import selfsimilar_solutions
from reference.linear.simulate import run_linear, run_linear_exponent


def _power_law_events(c=1.3, a=0.7, r=0.8, n=200, T0=2.0):
    ttg = T0 * r ** np.arange(n)
    E = a * ttg**c
    dt = np.concatenate([[0.0], -np.diff(ttg)])
    return ttg, E, dt


def test_regression_recovers_a_power_law():
    ttg, E, _ = _power_law_events()
    fit = fit_energy_exponent(ttg, E)
    assert fit["c"] == pytest.approx(1.3, rel=1e-12)
    assert fit["log_a"] == pytest.approx(math.log(0.7), rel=1e-10)
    assert fit["c_stderr"] < 1e-10


def test_time_to_go_is_summed_from_the_end():
    ttg, _, dt = _power_law_events()
    assert np.allclose(time_to_go(dt, ttg[-1]), ttg, rtol=1e-14)


def test_remainder_is_exact_for_a_power_law():
    ttg, E, dt = _power_law_events()
    with np.errstate(divide="ignore"):
        lrem = extrapolate_time_to_go(np.log2(dt), np.log2(E))
    assert 2.0**lrem == pytest.approx(ttg[-1], rel=1e-9)


def test_decade_durations_give_the_exponent_without_t_f():
    _, E, dt = _power_law_events(c=0.4, r=0.97, n=3000)
    with np.errstate(divide="ignore"):
        d = exponent_from_decades(np.log2(dt), np.log2(E), math.log10(E[-1]), math.log10(E[0]))
    assert d["c"] == pytest.approx(0.4, rel=2e-3)


def test_self_similar_motion_has_exponent_two_and_the_predicted_singularity():
    """γ = 0, n = 6, ρ = 0.5: the self-similar motion is stable, so the run stays on it:
    t_f = τ0/(1 − β) (eq. tdiffscaling) and c = 2 (eq. Ei) by every estimator."""
    m = LinearModel.polygon(6, 0.5, 0.0)
    s = [x for x in selfsimilar_solutions(m) if x.feasible][0]
    run = run_linear(m, s.q0, s.p0, energy_floor=1e-30)
    ex = exponent_of_run(run, skip_start=1.0, skip_end=1.0)
    assert ex["c"] == pytest.approx(2.0, abs=1e-6)
    assert ex["c_decades"] == pytest.approx(2.0, abs=5e-3)  # decade boundaries quantised
    assert ex["c_period"] == pytest.approx(2.0, abs=1e-9) and ex["period"] == 1
    t_f = run.t_final + 2.0 ** ex["log2_time_remaining"]
    assert t_f == pytest.approx(s.tau0 / (1 - s.beta), rel=1e-12)


@pytest.mark.parametrize("n, gamma", [(20, 0.6), (25, 0.5)])
def test_perturbed_unstable_self_similar_motion_still_has_exponent_two(n, gamma):
    """γ > 0, ρ = 0.5: self-similar motion is unstable (paper §3.5), the impact pattern
    drifts away from it, yet the energy exponent stays 2 (paper §3.6, Fig. precession)."""
    m = LinearModel.polygon(n, 0.5, gamma)
    s = [x for x in selfsimilar_solutions(m) if x.feasible][0]
    q, p = s.q0.copy(), s.p0 * (1 + 1e-3 * np.array([1.0, -0.5, 0.0]))
    r = run_linear_exponent(n, 0.5, gamma, q, p, max_impacts=200_000)
    assert r["status"] == "singularity"
    assert r["c"] == pytest.approx(2.0, abs=0.02)
    assert r["c_decades"] == pytest.approx(2.0, abs=0.05)


def test_exponent_run_reports_no_exponent_when_undecidable():
    r = run_linear_exponent(3, 0.5, 0.5, [0.0005, -0.0003, 1.0], [0.02, -0.01, -1.0])
    assert r["status"] == "simultaneous_impact" and r["c"] is None
    assert {"status", "c", "c_stderr", "t_singularity", "n_impacts"} <= set(r)
