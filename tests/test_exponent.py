"""The one exponent estimator (reference.exponent) and when a run may have an exponent
(harness.metrics.exponent)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness.metrics import evaluate, run_exponent
from harness.scenes import resolve_scene
from reference.exponent import regress_in_window, trajectory_exponent
from reference.trajectory import ImpactEvent, Status, Trajectory

T_F = 3.0


def power_law_run(c: float, status=Status.SINGULARITY, k: int = 30, t_sing=T_F) -> Trajectory:
    """Impacts at t_f − 2^−i; energy above rest (vertical kinetic energy) 0.5 (2^−i)^c
    between the impact before and impact i; samples between the impacts."""
    tau = 0.5 ** np.arange(k)
    t_imp = T_F - tau
    t = np.concatenate([[0.0], T_F - 1.5 * tau[1:]])
    e = 0.5 * tau**c
    vz = -np.sqrt(2 * e)
    states = np.zeros((k, 13))
    states[:, 3] = 1.0
    states[:, 9] = vz
    return Trajectory.from_states(
        "stand-in", "power-law", t, states, e, np.zeros(k),
        [ImpactEvent(float(x), i % 3, 1.0, -1.0, 0.5) for i, x in enumerate(t_imp)],
        status, t_singularity=t_sing, t_final=T_F,
    )  # fmt: skip


def test_regression_in_the_window_recovers_the_slope_and_its_standard_error():
    rng = np.random.default_rng(0)
    x = np.linspace(0, -30, 200)  # ln(t_f − t)
    noise = 0.05 * rng.standard_normal(200)
    y = math.log(2.0) + 1.3 * x + noise
    fit = regress_in_window(x, y, y.max() / math.log(10), y.min() / math.log(10))
    sel = fit["selected"]
    slope, intercept = np.polyfit(x[sel], y[sel], 1)  # an independent least squares
    assert fit["c"] == pytest.approx(slope, rel=1e-10)
    resid = y[sel] - (intercept + slope * x[sel])
    se = math.sqrt(resid @ resid / (sel.sum() - 2) / np.sum((x[sel] - x[sel].mean()) ** 2))
    assert fit["c_stderr"] == pytest.approx(se, rel=1e-10)
    bottom, top = fit["window"]
    L = y / math.log(10)
    assert np.array_equal(sel, (L >= bottom) & (L <= top))
    assert top == pytest.approx(L.max() - 3) and bottom == pytest.approx(L.min() + 2)


def test_too_short_a_window_gives_no_exponent_and_says_why():
    x = np.linspace(0, -10, 50)
    y = 1.0 * x  # 4.3 decades of energy: a 0-decade window after the skips
    fit = regress_in_window(x, y, y.max() / math.log(10), y.min() / math.log(10))
    assert fit["c"] is None and "needs 6 decades" in fit["reason"]


def test_a_run_that_reached_the_singularity_has_its_exponent():
    fit = trajectory_exponent(power_law_run(1.7))
    assert fit.c == pytest.approx(1.7, rel=1e-9) and fit.t_f_source == "t_singularity"
    assert fit.to_dict()["c"] == fit.c and "decades" in fit.describe()


def test_a_run_stopped_before_the_singularity_has_none():
    fit = trajectory_exponent(power_law_run(1.7, status=Status.T_END, t_sing=None))
    assert fit.c is None and "t_end" in fit.reason


def test_a_run_that_followed_the_reference_to_its_singularity_uses_its_t_f():
    scene = resolve_scene("pentagon-bounce")
    reference = power_law_run(2.0)
    engine = power_law_run(2.0, status=Status.T_END, t_sing=None)
    engine.dt = 1e-9  # a fine fixed-step run: every impact within its window
    metrics = evaluate(engine, reference, scene.gravity)
    fit = run_exponent(engine, scene, reference, metrics.match)
    assert fit.c == pytest.approx(2.0, rel=1e-9) and fit.t_f_source == "reference"
    # one impact off: it left the reference, no exponent
    engine.impacts[10] = ImpactEvent(engine.impacts[10].t, 2, 1.0, -1.0, 0.5)
    metrics = evaluate(engine, reference, scene.gravity)
    fit = run_exponent(engine, scene, reference, metrics.match)
    assert fit.c is None and "left the reference" in fit.reason
