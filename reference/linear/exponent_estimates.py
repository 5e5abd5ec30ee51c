"""The energy exponent c of E ≈ a (t_f − t)^c for the linear model (paper eq. scalinglaw,
sections 3.4, 3.6, 4.3).

c itself is the project's one estimator, reference.exponent (the regression of log E
before each impact on log(t_f − t) inside its fit window, with its standard error);
`exponent_of_run` feeds it a LinearRun, whose intervals and energies are kept as log2
so that runs spanning hundreds of decades (gravity-free chatter with small c) keep
their digits.  Two cross-checks that share nothing with it but the data:

- `exponent_from_decades`: from the time the run spends in successive decades of energy.
  If E = a (t_f − t)^c, the time spent while E falls from 10^(L+1) to 10^L is
  D_L ∝ 10^(L/c): log10 D_L is a line of slope 1/c in L, no t_f needed.
- `exponent_from_period`: the same idea over one period P of a periodic impact
  pattern (E_i/E_(i+P) against the ratio of the durations of consecutive periods),
  exact for motion that repeats scaled.

For self-similar motion (E_(i+1) = β² E_i, τ_(i+1) = β τ_i) every one of them gives 2.
"""

from __future__ import annotations

import math

import numpy as np

from ..exponent import (  # noqa: F401  (the one estimator; re-exported for the linear API)
    LOG2_10,
    MIN_DECADES,
    SKIP_END,
    SKIP_START,
    _log2_sum,
    distinct_impacts,
    extrapolate_time_to_go,
    fit_energy_exponent,
    fit_log_energy_exponent,
    ordinary_least_squares,
    regress_in_window,
    time_to_go,
)


def exponent_from_decades(log2_dt, log2_energy, lo: float, hi: float) -> dict:
    """c from the durations of whole decades of energy between 10^lo and 10^hi (module
    docstring); `log2_dt[i]` is log2 of the interval before event i, `log2_energy[i]`
    log2 of the energy after it.  Returns c = 1/slope of the least-squares line of
    log10 D_L against L, its standard error (propagated from the slope's) and the
    log10 D_L values.  A line over all decades rather than ratios of neighbours: the
    impacts quantise the decade boundaries, which biases single ratios."""
    from .kernel import log2_segment_sums

    ldt = np.ascontiguousarray(log2_dt, dtype=float)
    L = np.asarray(log2_energy, dtype=float) / LOG2_10
    levels = np.arange(math.floor(hi), math.ceil(lo) - 1, -1)
    Lmin = np.minimum.accumulate(np.where(np.isfinite(L), L, np.inf))
    # first event at or below each level (Lmin is non-increasing)
    first = np.searchsorted(-Lmin, -levels, side="left")
    ok = first < len(L)
    first, levels = first[ok], levels[ok]
    lD = log2_segment_sums(ldt, first.astype(np.int64)) if len(first) > 1 else np.zeros(0)
    ok = np.isfinite(lD)
    if ok.sum() < 3:
        return {"c": None, "c_spread": None, "values": []}
    # log10 D_L = const + L / c over the decades: slope 1/c by least squares
    x = levels[:-1][ok].astype(float)
    y = lD[ok] / LOG2_10
    s, _, se, _ = ordinary_least_squares(x, y)
    if not s > 0:
        return {"c": None, "c_spread": None, "values": list(y)}
    return {"c": float(1.0 / s), "c_spread": float(se / s**2), "values": list(y)}


def pattern_period(contacts: np.ndarray, n: int, tail: int = 60, max_period: int = 12):
    """Smallest P ≤ max_period such that the steps d_i = (c_(i+1) − c_i) mod n of the
    last `tail` impacts repeat with period P (the pattern up to the rotation R), or
    None."""
    c = np.asarray(contacts, dtype=int)
    if len(c) < tail + 2:
        return None
    d = np.mod(np.diff(c[-(tail + 1) :]), n)
    for P in range(1, max_period + 1):
        if np.all(d[P:] == d[:-P]):
            return P
    return None


def exponent_from_period(log2_tau, log2_energy_pre, P: int, tail: int = 60) -> dict:
    """c = log(E_i/E_(i+P)) / log(D_i/D_(i+P)) over the last `tail` impacts, D_i the
    duration of the P intervals that start at impact i: exact for a pattern that repeats
    scaled (self-similar: 2; gravity-free chatter: c_lin).  `log2_tau[i]` is log2 of
    the interval from impact i to i+1, `log2_energy_pre[i]` log2 of the energy before
    impact i."""
    lt = np.asarray(log2_tau, dtype=float)
    lE = np.asarray(log2_energy_pre, dtype=float)
    m = min(len(lt), len(lE))
    lt, lE = lt[:m], lE[:m]
    if m < 2 * P + 2:
        return {"c": None, "c_spread": None, "period": P}
    # D_i for the windows the last `tail` ratios read: i and i + P, i from `first`
    n_windows = m - P + 1
    first = max(0, n_windows - P - tail)
    lD = np.array([_log2_sum(lt[j : j + P]) for j in range(first, n_windows)])
    i = np.arange(first, n_windows - P)
    num = lE[i] - lE[i + P]
    den = lD[i - first] - lD[i - first + P]
    ok = np.isfinite(num) & np.isfinite(den) & (den != 0)
    if not ok.any():
        return {"c": None, "c_spread": None, "period": P}
    vals = num[ok] / den[ok]
    return {"c": float(np.median(vals)), "c_spread": float(np.ptp(vals)), "period": P}


def exponent_of_run(
    run,
    skip_start: float = SKIP_START,
    skip_end: float = SKIP_END,
    min_decades: float = MIN_DECADES,
) -> dict:
    """The estimators on a LinearRun that followed the energy down.

    Points are the impacts: the time-to-go at impact i (intervals summed from the end,
    plus the extrapolated remainder) against the energy just before it; c, c_stderr,
    c_spread and fit_decades come from reference.exponent.regress_in_window (the window
    between the initial energy and the lowest energy after any event), c_decades and
    c_period are the cross-checks of this module."""
    from . import kernel as K

    lE = run.log2_energy  # after each event
    out = {
        "c": None,
        "c_stderr": None,
        "log_a": None,
        "c_spread": None,
        "c_decades": None,
        "c_decades_spread": None,
        "c_period": None,
        "period": None,
        "log2_time_remaining": None,
        "log10_energy_drop": None,
        "fit_decades": 0.0,
    }
    fin = np.isfinite(lE)
    if fin.sum() < 2:
        return out
    out["log10_energy_drop"] = float((lE[0] - lE[fin][-1]) / LOG2_10)
    lrem = extrapolate_time_to_go(run.log2_dt, lE)
    if run.impact_law != "paper" and run.reason == K.REASON_SINGULARITY:
        lrem = -math.inf  # at rest at the last row's time (a bounce series' closed form)
    out["log2_time_remaining"] = lrem
    imp = np.flatnonzero((run.kind == K.IMPACT) | (run.kind == K.ACCUMULATION))
    if run.impact_law != "paper":  # a simultaneous impact's rows are one impact
        imp = imp[distinct_impacts(run.t_hi[imp], run.t_lo[imp])]
    if lrem is None or len(imp) < 8:
        return out
    lttg = K.log2_time_to_go(np.ascontiguousarray(run.log2_dt), float(lrem))
    lEpre = np.concatenate([[lE[0]], lE[:-1]])  # energy before event i
    ln2 = math.log(2.0)
    fit = regress_in_window(
        lttg[imp] * ln2,
        lEpre[imp] * ln2,
        lE[0] / LOG2_10,
        lE[fin][-1] / LOG2_10,
        skip_start,
        skip_end,
        min_decades,
    )
    out["fit_decades"] = fit["fit_decades"]
    if fit["c"] is None:
        return out
    sel = imp[fit["selected"]]
    out.update(c=fit["c"], c_stderr=fit["c_stderr"], log_a=fit["log_a"], c_spread=fit["c_spread"])
    bottom, top = fit["window"]
    dec = exponent_from_decades(run.log2_dt, lE, bottom, top)
    out["c_decades"], out["c_decades_spread"] = dec["c"], dec["c_spread"]
    P = pattern_period(run.contact[sel], run.model.symmetry, tail=min(60, len(sel) - 2))
    if P is not None:
        # interval from impact sel[k] to sel[k+1]
        ltau = K.log2_segment_sums(np.ascontiguousarray(run.log2_dt), sel.astype(np.int64))
        per = exponent_from_period(ltau, lEpre[sel][:-1], P)
        out["c_period"], out["period"] = per["c"], P
    return out
