"""The energy exponent c of E ≈ a (t_f − t)^c (paper eq. scalinglaw, sections 3.4, 3.6, 4.3).

Two estimators that share nothing but the data:

- `fit_energy_exponent`: the paper's regression of log E on log(t_f − t) over the
  impacts; it needs the time of the singularity t_f (here: each impact's time-to-go,
  the following intervals summed from the end plus the extrapolated remainder);
- `exponent_from_decades`: from the time the run spends in successive decades of energy.
  If E = a (t_f − t)^c, the time spent while E falls from 10^(L+1) to 10^L is
  D_L ∝ 10^(L/c): log10 D_L is a line of slope 1/c in L, no t_f needed.
  `exponent_from_period` is the same idea over one period P of a periodic impact
  pattern (E_i/E_(i+P) against the ratio of the durations of consecutive periods),
  exact for motion that repeats scaled.

For self-similar motion (E_(i+1) = β² E_i, τ_(i+1) = β τ_i) every one of them gives 2.
Runs can span hundreds of decades of time (gravity-free chatter with small c), so the
run-level functions work with log2 of intervals and energies.
"""

from __future__ import annotations

import math

import numpy as np

LOG2_10 = math.log2(10.0)


def time_to_go(dt: np.ndarray, remainder: float = 0.0) -> np.ndarray:
    """t_f − t_i for events i, where dt[i] is the interval before event i and
    `remainder` the time from the last event to t_f: summed from the end (smallest
    first), so every value keeps its relative precision however close to t_f."""
    dt = np.asarray(dt, dtype=float)
    out = np.empty(len(dt))
    acc = float(remainder)
    for i in range(len(dt) - 1, -1, -1):
        out[i] = acc
        acc += dt[i]
    return out


def _log2_sum(x: np.ndarray) -> float:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        return -math.inf
    return float(np.logaddexp2.reduce(x))


def extrapolate_time_to_go(log2_dt, log2_energy, span: float = 1.0):
    """log2 of the time from the last event to the singularity, assuming
    E ∝ (t_f − t)^c over the last 2·`span` decades of energy.  With D1, D2 the durations
    of the last two spans (energy drops ΔL1, ΔL2 decades), x = 1/c solves
    D1/D2 = 10^(x ΔL2)(10^(x ΔL1) − 1)/(10^(x ΔL2) − 1), and the rest is
    D2 / (10^(x ΔL2) − 1).  `log2_dt[i]` is log2 of the interval before event i,
    `log2_energy[i]` log2 of the energy after it.  None if the run did not fall
    2·span decades."""
    ldt = np.asarray(log2_dt, dtype=float)
    L = np.asarray(log2_energy, dtype=float) / LOG2_10
    ok = np.isfinite(L)
    if not ok.any():
        return None
    L_end = L[ok][-1]
    n = len(L)
    ia = np.flatnonzero(ok & (L <= L_end + 2 * span))
    ib = np.flatnonzero(ok & (L <= L_end + span))
    if len(ia) == 0 or len(ib) == 0 or L[0] < L_end + 2 * span:
        return None
    a, b = ia[0], ib[0]
    if not (a < b < n - 1):
        return None
    lD1 = _log2_sum(ldt[a + 1 : b + 1])
    lD2 = _log2_sum(ldt[b + 1 :])
    dL1, dL2 = L[a] - L[b], L[b] - L_end
    if not (math.isfinite(lD1) and math.isfinite(lD2) and dL1 > 0 and dL2 > 0):
        return None
    target = math.exp2(lD1 - lD2)
    ln10 = math.log(10.0)

    def ratio(x: float) -> float:
        return 10 ** (x * dL2) * math.expm1(x * dL1 * ln10) / math.expm1(x * dL2 * ln10)

    lo, hi = 1e-4, 30.0
    if not (ratio(lo) <= target <= ratio(hi)):
        return None
    for _ in range(64):
        mid = math.sqrt(lo * hi)
        if ratio(mid) < target:
            lo = mid
        else:
            hi = mid
    x = math.sqrt(lo * hi)
    return lD2 - math.log2(math.expm1(x * dL2 * ln10))


def _ols(x: np.ndarray, y: np.ndarray):
    xm, ym = x.mean(), y.mean()
    sxx = float(np.sum((x - xm) ** 2))
    c = float(np.sum((x - xm) * (y - ym)) / sxx)
    b = float(ym - c * xm)
    r = y - (b + c * x)
    n = len(x)
    rms = float(math.sqrt(np.sum(r * r) / n))
    se = float(math.sqrt(np.sum(r * r) / max(n - 2, 1) / sxx))
    return c, b, se, rms


def fit_log_energy_exponent(log_ttg, log_energy) -> dict:
    """`fit_energy_exponent` on natural logs of time-to-go and energy."""
    x = np.asarray(log_ttg, dtype=float)
    y = np.asarray(log_energy, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    n = len(x)
    out = {
        "c": None,
        "c_stderr": None,
        "log_a": None,
        "n_points": n,
        "rms_residual": None,
        "log10_energy_span": float(np.ptp(y) / math.log(10)) if n else 0.0,
        "log10_time_span": float(np.ptp(x) / math.log(10)) if n else 0.0,
        "c_spread": None,
    }
    if n < 3 or np.ptp(x) == 0:
        return out
    c, log_a, se, rms = _ols(x, y)
    out.update(c=c, c_stderr=se, log_a=log_a, rms_residual=rms)
    if n >= 8:
        h = n // 2
        c1 = _ols(x[:h], y[:h])[0]
        c2 = _ols(x[h:], y[h:])[0]
        out["c_spread"] = float(max(abs(c1 - c), abs(c2 - c)))
    return out


def fit_energy_exponent(time_to_go, energy) -> dict:
    """Least-squares line log E = log a + c log(t_f − t) (the paper's regression).

    Returns c, its standard error c_stderr (ordinary least squares; the residuals of a
    staircase are correlated, so this understates the uncertainty: see c_spread), log_a
    (natural log of a), the number of points, the rms residual, the decades spanned, and
    c_spread: the larger difference between c and the slopes of the first and the
    second half of the points."""
    tt = np.asarray(time_to_go, dtype=float)
    E = np.asarray(energy, dtype=float)
    ok = (tt > 0) & (E > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return fit_log_energy_exponent(
            np.where(ok, np.log(np.where(ok, tt, 1.0)), np.nan),
            np.where(ok, np.log(np.where(ok, E, 1.0)), np.nan),
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
    s, _, se, _ = _ols(x, y)
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
    lD = np.array([_log2_sum(lt[i : i + P]) for i in range(m - P + 1)])
    i = np.arange(max(0, len(lD) - P - tail), len(lD) - P)
    num = lE[i] - lE[i + P]
    den = lD[i] - lD[i + P]
    ok = np.isfinite(num) & np.isfinite(den) & (den != 0)
    if not ok.any():
        return {"c": None, "c_spread": None, "period": P}
    vals = num[ok] / den[ok]
    return {"c": float(np.median(vals)), "c_spread": float(np.ptp(vals)), "period": P}


def exponent_of_run(
    run, skip_start: float = 3.0, skip_end: float = 2.0, min_decades: float = 6.0
) -> dict:
    """The estimators on a LinearRun that followed the energy down.

    Points are the impacts: the time-to-go at impact i (intervals summed from the end,
    plus the extrapolated remainder) against the energy just before it.  The window
    leaves out the first `skip_start` decades of energy (transient from the initial
    state) and the last `skip_end` (where the remainder's error matters); c is None
    unless the window spans `min_decades` decades."""
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
    out["log2_time_remaining"] = lrem
    imp = np.flatnonzero((run.kind == K.IMPACT) | (run.kind == K.ACCUMULATION))
    if lrem is None or len(imp) < 8:
        return out
    lttg = K.log2_time_to_go(np.ascontiguousarray(run.log2_dt), float(lrem))
    lEpre = np.concatenate([[lE[0]], lE[:-1]])  # energy before event i
    top = (lE[0] / LOG2_10) - skip_start
    bottom = (lE[fin][-1] / LOG2_10) + skip_end
    Lpre10 = lEpre / LOG2_10
    sel = imp[(Lpre10[imp] <= top) & (Lpre10[imp] >= bottom)]
    if len(sel) < 8 or top - bottom < min_decades:
        return out
    ln2 = math.log(2.0)
    fit = fit_log_energy_exponent(lttg[sel] * ln2, lEpre[sel] * ln2)
    out.update(
        c=fit["c"],
        c_stderr=fit["c_stderr"],
        log_a=fit["log_a"],
        c_spread=fit["c_spread"],
        fit_decades=float(top - bottom),
    )
    dec = exponent_from_decades(run.log2_dt, lE, bottom, top)
    out["c_decades"], out["c_decades_spread"] = dec["c"], dec["c_spread"]
    P = pattern_period(run.contact[sel], run.model.symmetry, tail=min(60, len(sel) - 2))
    if P is not None:
        # interval from impact sel[k] to sel[k+1]
        ltau = K.log2_segment_sums(np.ascontiguousarray(run.log2_dt), sel.astype(np.int64))
        per = exponent_from_period(ltau, lEpre[sel][:-1], P)
        out["c_period"], out["period"] = per["c"], P
    return out
