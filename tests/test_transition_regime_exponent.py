"""A regime's energy exponent is measured only where its energy follows a power law."""

import numpy as np

from harness.transition.regimes import regime_exponent


def test_a_regime_falling_as_a_power_of_the_time_to_go_gets_that_power():
    ttg = np.logspace(-6, -2, 30)
    fit = regime_exponent(ttg, 3.0 * ttg**2, e_end=0.0)
    assert abs(fit["c"] - 2.0) < 1e-9


def test_the_plateau_a_run_keeps_at_its_end_is_left_out_of_the_fit():
    ttg = np.logspace(-9, -2, 40)
    plateau = 4.5e-9
    fit = regime_exponent(ttg, 10.0 * ttg**2 + plateau, e_end=plateau)
    assert abs(fit["c"] - 2.0) < 0.05


def test_an_energy_that_barely_changes_gets_no_exponent():
    ttg = np.logspace(-9, -2, 40)
    fit = regime_exponent(ttg, 4.5e-9 * (1 + 0.1 * ttg), e_end=0.0)
    assert fit["c"] is None and "decades" in fit["reason"]


def test_too_few_impacts_get_no_exponent():
    ttg = np.logspace(-4, -2, 4)
    fit = regime_exponent(ttg, ttg**2, e_end=0.0)
    assert fit["c"] is None and "impacts" in fit["reason"]
