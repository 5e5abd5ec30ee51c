"""The energy exponent c of E ≈ a (t_f − t)^c: the one estimator of this project.

Used by every simulator's result (the exact reference, the engines, the linear model),
by `harness compare`, the recordings, the sweeps and the figures.

Definition (Baranyai & Várkonyi, eq. scalinglaw, sections 3.4, 4.3):

- **E** is the energy that goes to zero at the singularity: the energy above the resting
  level that the invariants allow (reference.geometry.excess_energy: on flat ground the
  horizontal momentum and the vertical angular momentum are kept, so the motion ends at
  ½ m |v_h|² + L_z²/(2 I3), not at 0).  For the linear model this is its own energy.
- **The points are the impacts**: E_i is the energy just before impact i, t_f − t_i its
  time to go.  Between impacts E is constant, so these are the corners of the staircase
  the paper's bounds (eq. scalinglaw2) enclose.
- **c** is the slope of the ordinary least-squares line log E_i = log a + c log(t_f − t_i)
  over the impacts inside the fit window; **c_stderr** its standard error,
  sqrt(Σr²/(k − 2) / Σ(x − x̄)²).  The residuals of a staircase are correlated, so the
  standard error understates the uncertainty; `c_spread` (the larger change of c when
  only the first or only the second half of the points is fitted) is a second measure.
- **Fit window** (`fit_window`): the first SKIP_START = 3 decades of energy below the
  initial energy are left out (the transient from the initial state, before the motion
  settles into its asymptotic pattern) and the last SKIP_END = 2 decades above the lowest
  energy reached (where the error of the extrapolated time to go t_f − t_K matters).  No
  c unless the window spans MIN_DECADES = 6 decades with MIN_POINTS = 8 impacts: the
  paper's exponents differ by O(1) (c = 2 against c_lin ∈ (0, 2)), and 6 decades of
  energy make a slope error of 0.1 a residual of more than half a decade.
- **Only runs that reach the end of the motion** have a c: status singularity (t_f is the
  run's t_singularity), or a run that followed a reference to its singularity (the
  caller passes the reference's t_f; harness.metrics.run_exponent decides).  A run stopped
  by an undecidable impact, a budget or t_end has no t_f, and the paper records no c
  for it either.

Time to go is summed from the intervals between impacts, smallest first (`time_to_go`),
each interval from the (t, t_lo) double-double parts, so it keeps its relative precision
however close to t_f.  Runs can span hundreds of decades (gravity-free chatter with small
c), so the linear model works in log2 of intervals and energies (`extrapolate_time_to_go`,
reference.linear.exponent_estimates.exponent_of_run) and both end in `regress_in_window`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .scene import Scene
    from .trajectory import Trajectory

LOG2_10 = math.log2(10.0)
LN10 = math.log(10.0)
SKIP_START = 3.0  # decades below the initial energy left out (transient)
SKIP_END = 2.0  # decades above the lowest energy left out (extrapolated remainder)
MIN_DECADES = 6.0  # the window must span this many decades of energy ...
MIN_POINTS = 8  # ... with at least this many impacts


# ----------------------------------------------------------------------------- time to go


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
    x = _inverse_exponent(math.exp2(lD1 - lD2), dL1, dL2)
    if x is None:
        return None
    return lD2 - math.log2(math.expm1(x * dL2 * LN10))


def _inverse_exponent(target: float, dL1: float, dL2: float) -> float | None:
    """x = 1/c with 10^(x ΔL2)(10^(x ΔL1) − 1)/(10^(x ΔL2) − 1) = target, by bisection
    in log x over [1e-4, 30] (the ratio grows with x); None outside that bracket."""

    def ratio(x: float) -> float:
        return 10 ** (x * dL2) * math.expm1(x * dL1 * LN10) / math.expm1(x * dL2 * LN10)

    lo, hi = 1e-4, 30.0
    if not (ratio(lo) <= target <= ratio(hi)):
        return None
    for _ in range(64):
        mid = math.sqrt(lo * hi)
        if ratio(mid) < target:
            lo = mid
        else:
            hi = mid
    return math.sqrt(lo * hi)


# ----------------------------------------------------------------------------- regression


def ordinary_least_squares(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float, float]:
    """Line y = b + c x: (c, b, standard error of c, rms residual), with
    c = Σ(x − x̄)(y − ȳ)/Σ(x − x̄)², b = ȳ − c x̄ and residuals r = y − (b + c x)."""
    n = len(x)
    xm, ym = float(x.sum()) / n, float(y.sum()) / n
    dx = x - xm
    sxx = float(dx @ dx)
    c = float(dx @ (y - ym)) / sxx
    b = ym - c * xm
    r = y - (b + c * x)
    rr = float(r @ r)
    return c, b, math.sqrt(rr / max(n - 2, 1) / sxx), math.sqrt(rr / n)


def fit_log_energy_exponent(log_ttg, log_energy) -> dict:
    """`fit_energy_exponent` on natural logs of time-to-go and energy (non-finite pairs
    are left out)."""
    x = np.asarray(log_ttg, dtype=float)
    y = np.asarray(log_energy, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    n = len(x)
    x_span = float(x.max() - x.min()) if n else 0.0
    out = {
        "c": None,
        "c_stderr": None,
        "log_a": None,
        "n_points": n,
        "rms_residual": None,
        "log10_energy_span": float(y.max() - y.min()) / LN10 if n else 0.0,
        "log10_time_span": x_span / LN10,
        "c_spread": None,
    }
    if n < 3 or x_span == 0:
        return out
    c, log_a, se, rms = ordinary_least_squares(x, y)
    out.update(c=c, c_stderr=se, log_a=log_a, rms_residual=rms)
    if n >= 8:
        h = n // 2
        c1 = ordinary_least_squares(x[:h], y[:h])[0]
        c2 = ordinary_least_squares(x[h:], y[h:])[0]
        out["c_spread"] = float(max(abs(c1 - c), abs(c2 - c)))
    return out


def fit_energy_exponent(time_to_go, energy) -> dict:
    """Least-squares line log E = log a + c log(t_f − t) over all points with t_f − t > 0
    and E > 0 (no window: `regress_in_window` is the estimator; this is its regression).

    Returns c, its standard error c_stderr, log_a (natural log of a), the number of
    points, the rms residual, the decades spanned, and c_spread (module docstring)."""
    tt = np.asarray(time_to_go, dtype=float)
    E = np.asarray(energy, dtype=float)
    ok = (tt > 0) & (E > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return fit_log_energy_exponent(
            np.where(ok, np.log(np.where(ok, tt, 1.0)), np.nan),
            np.where(ok, np.log(np.where(ok, E, 1.0)), np.nan),
        )


def fit_window(
    log10_initial: float,
    log10_lowest: float,
    skip_start: float = SKIP_START,
    skip_end: float = SKIP_END,
) -> tuple[float, float]:
    """(bottom, top) of the fit window in log10 E: [lowest + skip_end, initial − skip_start]."""
    return log10_lowest + skip_end, log10_initial - skip_start


def regress_in_window(
    log_ttg: np.ndarray,
    log_energy: np.ndarray,
    log10_initial: float,
    log10_lowest: float,
    skip_start: float = SKIP_START,
    skip_end: float = SKIP_END,
    min_decades: float = MIN_DECADES,
    min_points: int = MIN_POINTS,
) -> dict:
    """The estimator: the regression of the points (natural logs of t_f − t_i and E_i)
    whose energy lies in the `fit_window`.  Returns c (None unless the window spans
    `min_decades` with `min_points` points), c_stderr, log_a, c_spread, n_points,
    fit_decades (the window's span, ≥ 0), window (bottom, top) in log10 E, `selected`
    (mask of the points used) and `reason` (why c is None; "" when it is not)."""
    x = np.asarray(log_ttg, dtype=float)
    y = np.asarray(log_energy, dtype=float)
    bottom, top = fit_window(log10_initial, log10_lowest, skip_start, skip_end)
    L = y / LN10
    with np.errstate(invalid="ignore"):
        sel = np.isfinite(x) & np.isfinite(L) & (L <= top) & (L >= bottom)
    span = top - bottom
    out = {
        "c": None,
        "c_stderr": None,
        "log_a": None,
        "c_spread": None,
        "n_points": int(sel.sum()),
        "fit_decades": float(max(span, 0.0)),
        "window": (float(bottom), float(top)),
        "selected": sel,
        "reason": "",
    }
    if span < min_decades or sel.sum() < min_points:
        out["reason"] = (
            f"fit window spans {max(span, 0.0):.1f} decades with {int(sel.sum())} impacts "
            f"(needs {min_decades:g} decades and {min_points})"
        )
        return out
    fit = fit_log_energy_exponent(x[sel], y[sel])
    out.update(c=fit["c"], c_stderr=fit["c_stderr"], log_a=fit["log_a"], c_spread=fit["c_spread"])
    return out


# ----------------------------------------------------------------------------- trajectories


@dataclass(frozen=True)
class ExponentFit:
    """c of one run, how it was obtained, and the points (for plots).

    t_f: time of the singularity used; t_f_source: "t_singularity" (the run's own,
    resolved), "extrapolated" (the last decades of energy, `extrapolate_time_to_go`),
    "last_impact" (a run with status singularity but no t_singularity) or "reference"
    (a run that followed the reference to its singularity); n_used: leading impacts
    whose intervals are resolved; time_to_go, energy: t_f − t_i and E_i of those;
    selected: which of them the regression used; reason: why c is None ("" if not)."""

    c: float | None = None
    c_stderr: float | None = None
    log_a: float | None = None
    c_spread: float | None = None
    n_points: int = 0
    fit_decades: float = 0.0
    window: tuple[float, float] | None = None
    t_f: float | None = None
    t_f_source: str | None = None
    n_used: int = 0
    reason: str = ""
    time_to_go: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    energy: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    selected: np.ndarray = field(default_factory=lambda: np.zeros(0, bool), repr=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON fields (no arrays)."""
        return {
            "c": self.c,
            "c_stderr": self.c_stderr,
            "c_spread": self.c_spread,
            "t_f": self.t_f,
            "t_f_source": self.t_f_source,
            "fit_decades": self.fit_decades,
            "fit_window_log10_energy": list(self.window) if self.window else None,
            "n_points": self.n_points,
            "reason": self.reason or None,
        }

    def describe(self) -> str:
        """'c = 1.17 ± 0.03 (9.2 decades, 41 impacts)' or the reason there is none."""
        if self.c is None:
            return f"no c: {self.reason}"
        return (
            f"c = {self.c:.3f} ± {self.c_stderr:.2g} ({self.fit_decades:.1f} decades, "
            f"{self.n_points} impacts)"
        )


def states_of(traj: Trajectory) -> np.ndarray:
    """(N, 13) states (x, q wxyz, v, ω) of a trajectory's samples."""
    return np.concatenate(
        [traj.position, traj.quaternion, traj.velocity, traj.angular_velocity], axis=1
    )


def excess_energy_of(traj: Trajectory, scene: Scene) -> np.ndarray:
    """E of the paper per sample: energy above the resting level
    (reference.geometry.excess_energy)."""
    from .geometry import excess_energy

    if traj.n_samples == 0:
        return np.zeros(0)
    return excess_energy(scene, states_of(traj))


def pre_impact_samples(traj: Trajectory) -> np.ndarray:
    """Index of the last sample strictly before each impact (−1 if none), comparing
    times as (t, t_lo) pairs so that impacts closer together than an ulp of t stay
    ordered.  Energy is constant in flight, so for exact simulators the energy of that
    sample is the energy just before the impact."""
    n_s = traj.n_samples
    t_s = np.asarray(traj.t, dtype=float)
    lo_s = np.zeros(n_s) if traj.t_lo is None else np.asarray(traj.t_lo, dtype=float)
    t_i, lo_i = traj.impact_column("t"), traj.impact_column("t_lo")
    hi = np.concatenate([t_s, t_i])
    lo = np.concatenate([lo_s, lo_i])
    is_sample = np.concatenate([np.ones(n_s, dtype=bool), np.zeros(len(t_i), dtype=bool)])
    # order by time; at an exact tie the impact comes first (the sample is not before it)
    order = np.lexsort((is_sample, lo, hi))
    samples_before = np.cumsum(is_sample[order]) - is_sample[order]
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    return samples_before[rank[n_s:]] - 1


def distinct_impacts(t_i: np.ndarray, lo_i: np.ndarray) -> np.ndarray:
    """Indices of the first impact row at each distinct time (t, t_lo): the rows of a
    simultaneous impact (one per contact, all at one time; impact laws other than the
    paper's) are one impact of the series."""
    if len(t_i) == 0:
        return np.zeros(0, dtype=np.int64)
    same = (np.diff(t_i) == 0) & (np.diff(lo_i) == 0)
    return np.flatnonzero(np.concatenate([[True], ~same]))


def _resolved_impacts(t_i: np.ndarray, lo_i: np.ndarray, tol: float) -> tuple[np.ndarray, int]:
    """Intervals before each impact (the first from t = 0) and the index K of the last
    impact whose interval is resolved (every interval up to it ≥ tol·max(t, 1))."""
    tau = np.empty(len(t_i))
    tau[0] = t_i[0] + lo_i[0]
    tau[1:] = np.diff(t_i) + np.diff(lo_i)
    bad = np.flatnonzero(~(tau[1:] > tol * np.maximum(np.abs(t_i[1:]), 1.0)))
    return tau, (int(bad[0]) if len(bad) else len(t_i) - 1)


def _remainder(
    t_sing: float | None,
    t_k: float,
    lo_k: float,
    tau: np.ndarray,
    e_after: np.ndarray,
) -> tuple[float | None, str | None]:
    """Time from the last used impact K (at t_k + lo_k) to t_f, and where it came from:
    t_sing − t_K when resolved (≥ 1e-12 t_f); else the geometric extrapolation of the
    last decades of energy; without t_sing, 0 (t_f = the last impact)."""
    if t_sing is None:
        return 0.0, "last_impact"
    r = (float(t_sing) - t_k) - lo_k
    if r >= 1e-12 * max(abs(float(t_sing)), 1.0):
        return r, "t_singularity"
    with np.errstate(divide="ignore", invalid="ignore"):
        lrem = extrapolate_time_to_go(np.log2(tau), np.log2(e_after))
    if lrem is None:
        return None, None
    return 2.0**lrem, "extrapolated"


def trajectory_exponent(
    traj: Trajectory,
    energy: np.ndarray | None = None,
    t_singularity: float | None = None,
    from_reference: bool = False,
    skip_start: float = SKIP_START,
    skip_end: float = SKIP_END,
    min_decades: float = MIN_DECADES,
    resolution: float | None = None,
) -> ExponentFit:
    """c of a Trajectory that reached the end of the motion (module docstring).

    `energy`: E per sample, the excess energy (`excess_energy_of`); default traj.energy,
    for runs whose energy already is that excess (the linear model, test stand-ins).
    t_f: `t_singularity` when given (with `from_reference`: the reference's, for a run
    that followed it to the end), else traj.t_singularity; a run with neither status
    singularity nor a given t_singularity has no c.

    Only the leading impacts whose intervals are resolved are used (every interval
    ≥ `resolution` × t; default 1e-28 with t_lo, 1e-13 without): the rest are below the
    simulator's time resolution.  The remainder from the last used impact K to t_f is
    t_f − t_K when that difference is resolved (≥ 1e-12 t_f), else extrapolated from the
    last decades of energy (`extrapolate_time_to_go`, as the linear model does); a run
    with status singularity but no t_singularity takes t_f = t_K."""
    from .trajectory import Status

    t_sing = t_singularity if t_singularity is not None else traj.t_singularity
    if t_singularity is None and traj.status is not Status.SINGULARITY:
        return ExponentFit(reason=f"the run ended {traj.status.value}, not at the singularity")
    imps = traj.impacts
    N = len(imps)
    if N < MIN_POINTS or traj.n_samples < 2:
        return ExponentFit(reason=f"{N} impacts (needs {MIN_POINTS})")
    E = np.asarray(traj.energy if energy is None else energy, dtype=float)
    if not E[0] > 0:
        return ExponentFit(reason="no energy above the resting level at the start")
    t_i, lo_i = traj.impact_column("t"), traj.impact_column("t_lo")
    has_lo = traj.t_lo is not None or bool(np.any(lo_i != 0))
    tol = resolution if resolution is not None else (1e-28 if has_lo else 1e-13)
    idx = pre_impact_samples(traj)
    first = distinct_impacts(t_i, lo_i)  # a simultaneous impact is one impact
    t_i, lo_i, idx = t_i[first], lo_i[first], idx[first]
    N = len(t_i)
    E_pre = np.where(idx >= 0, E[np.maximum(idx, 0)], np.nan)
    tau, K = _resolved_impacts(t_i, lo_i, tol)
    e_after = np.append(E_pre[1 : K + 1], E_pre[K + 1] if K + 1 < N else E[-1])
    rem, how = _remainder(t_sing, t_i[K], lo_i[K], tau[: K + 1], e_after)
    if rem is None:
        return ExponentFit(n_used=K + 1, reason="the time to the singularity cannot be resolved")
    if from_reference:
        how = "reference"
    ttg = time_to_go(tau[: K + 1], rem)  # t_f − t_i for impacts 0..K
    E_used = E_pre[: K + 1]
    pos = E_used[E_used > 0]
    base = {
        "t_f": float(t_i[K] + lo_i[K] + rem),
        "t_f_source": how,
        "n_used": K + 1,
        "time_to_go": ttg,
        "energy": E_used,
    }
    if len(pos) < 2:
        return ExponentFit(reason="fewer than 2 impacts with energy above rest", **base)
    with np.errstate(divide="ignore", invalid="ignore"):
        lx = np.where(ttg > 0, np.log(np.where(ttg > 0, ttg, 1.0)), np.nan)
        ly = np.log(E_used)
    fit = regress_in_window(
        lx, ly, math.log10(E[0]), math.log10(pos.min()), skip_start, skip_end, min_decades
    )
    return ExponentFit(
        c=fit["c"],
        c_stderr=fit["c_stderr"],
        log_a=fit["log_a"],
        c_spread=fit["c_spread"],
        n_points=fit["n_points"],
        fit_decades=fit["fit_decades"],
        window=fit["window"],
        reason=fit["reason"],
        selected=fit["selected"],
        **base,
    )
