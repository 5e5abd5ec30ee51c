"""Derived numbers of the work-precision curves: Pareto fronts, log-log interpolation,
error at the reference's cost and cost ratios at equal accuracy (harness.bench)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..simulators import is_fixed_step
from .settings import ERROR_FLOOR, METRICS, TRUTH

# ----------------------------------------------------------------------------- derived


def pareto_front(points: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """(time, error) points sorted by time, keeping each point only if its error is
    below that of every cheaper point: the best accuracy reachable for a given cost."""
    front: list[tuple[float, float]] = []
    for t, e in sorted(points):
        if not front or e < front[-1][1]:
            front.append((t, e))
    return front


def loglog_interp(x: float, xs: Sequence[float], ys: Sequence[float]) -> tuple[float, str]:
    """y at x on the piecewise log-log-linear curve through (xs, ys) (xs increasing):
    log y = log y_i + (log x − log x_i)/(log x_{i+1} − log x_i) · (log y_{i+1} − log y_i).
    Outside [xs[0], xs[-1]] the end value is returned.  The second item says which:
    "interpolated", "below" (x < xs[0]) or "above" (x > xs[-1])."""
    if x <= xs[0]:
        return ys[0], ("interpolated" if x == xs[0] else "below")
    if x >= xs[-1]:
        return ys[-1], ("interpolated" if x == xs[-1] else "above")
    i = int(np.searchsorted(xs, x)) - 1
    lx0, lx1 = math.log(xs[i]), math.log(xs[i + 1])
    ly0, ly1 = math.log(ys[i]), math.log(ys[i + 1])
    return math.exp(ly0 + (math.log(x) - lx0) / (lx1 - lx0) * (ly1 - ly0)), "interpolated"


def counted(row: dict[str, Any]) -> bool:
    """Whether a row enters the derived numbers: it did not fail and it follows the
    reference (harness.metrics.follows; rows of older documents without the field
    count)."""
    return row["status"] != "failed" and row.get("follows_reference", True)


def _curve(rows: list[dict[str, Any]], engine: str, metric: str) -> list[tuple[float, float]]:
    pts = []
    for r in rows:
        if r["engine"] == engine and r.get(metric) is not None and counted(r):
            pts.append((float(r["wall_time_s"]), max(float(r[metric]), ERROR_FLOOR)))
    return pts


def derive(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per error metric and non-reference simulator (Pareto fronts, `loglog_interp`),
    from the rows that follow the reference (`counted`; a simulator without such a row
    has no entry):

    - reference_cost_s: median wall time of the reference at its tightest setting;
    - error_at_reference_cost: the simulator's error on its front at that cost (the
      best accuracy it reached for at most that cost).  `bound` "upper": the reference
      costs more than every measured run of the simulator, and the value is its best
      error (finer steps might do better); "none": the simulator's cheapest run already costs more
      than the reference (value null); "single setting": a simulator without an
      accuracy knob (linear), whose one error is given whatever its cost;
    - cost_ratio: simulator time / reference time at equal accuracy, at the
      simulator's most accurate run (error ε): reference time to reach ε is read off
      the reference's front (log time linear in log error).  `bound` "lower": every
      reference setting is more accurate than ε, so the reference needs at most its
      cheapest time and the ratio is at least the value given; "upper" (reference never
      reaches ε): the ratio is at most the value, computed with the tightest setting;
    - cost_ratios: the same at every point of the simulator's front."""
    out: dict[str, Any] = {}
    engines = [e for e in dict.fromkeys(r["engine"] for r in rows) if e != "reference"]
    truth_rows = [r for r in rows if r["engine"] == "reference" and r["contact_rtol"] == TRUTH[0]]
    if not truth_rows:
        return out
    t_ref = float(truth_rows[-1]["wall_time_s"])
    for metric in METRICS:
        ref_front = pareto_front(_curve(rows, "reference", metric))
        per: dict[str, Any] = {}
        for engine in engines:
            front = pareto_front(_curve(rows, engine, metric))
            if not front:
                continue
            ts, es = [p[0] for p in front], [p[1] for p in front]
            if len(front) == 1 and not is_fixed_step(engine):
                err, bound = es[0], "single setting"
            elif t_ref < ts[0]:
                err, bound = None, "none"
            else:
                err, _ = loglog_interp(t_ref, ts, es)
                # beyond every measured run: finer settings might do better
                measured = max(p[0] for p in _curve(rows, engine, metric))
                bound = "upper" if t_ref > measured else "exact"
            ratios = [_cost_ratio(t, e, ref_front) for t, e in front]
            best = ratios[-1] if ratios else None
            per[engine] = {
                "reference_cost_s": t_ref,
                "error_at_reference_cost": err,
                "error_at_reference_cost_bound": bound,
                "best_error": es[-1],
                "best_error_cost_s": ts[-1],
                "cost_ratio": best["ratio"] if best else None,
                "cost_ratio_bound": best["bound"] if best else None,
                "cost_ratios": ratios,
            }
        out[metric] = per
    return out


def _cost_ratio(t: float, err: float, ref_front: list[tuple[float, float]]) -> dict[str, Any]:
    """Simulator cost t at accuracy err over the reference's cost at the same accuracy."""
    if not ref_front:
        return {"error": err, "time_s": t, "reference_time_s": None, "ratio": None, "bound": None}
    # reference front: time increasing, error decreasing; invert error -> time
    rt = [p[0] for p in ref_front][::-1]
    re_ = [p[1] for p in ref_front][::-1]  # increasing error
    t_r, where = loglog_interp(err, re_, rt)
    bound = {"above": "lower", "below": "upper", "interpolated": "exact"}[where]
    return {"error": err, "time_s": t, "reference_time_s": t_r, "ratio": t / t_r, "bound": bound}
