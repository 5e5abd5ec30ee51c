"""When a run is faithful, the fidelity limit α* of an engine, and its power law in dt.

- A run **passes** at one scale when it matches at least `match_fraction` (default
  90 %) of the reference's leading impacts (leading.py; matched = same contact and time
  within the window of harness.metrics.match_impacts, in order), and, where the
  reference and the run both have an energy exponent c (harness.metrics.run_exponent:
  only runs that reach the end of the motion), |c − c_ref| ≤ `c_tolerance`·|c_ref|
  (default 10 %).  Where either has no c the run is judged on its impacts alone and the
  row says why (`c_check`).
- **α*** of an engine at one dt: walking the ε grid from the largest inclination down,
  the smallest α at which the engine passes before its first failure.  Runs skipped for
  the budget do not interrupt the walk (they are counted).  `bound` says what the grid
  tells: "bracket" (it passes at α* and fails at the next α of the grid,
  `alpha_first_fail`), "at most" (it passes at every α run: α* ≤ the smallest), "above
  grid" (it fails at the largest α run: α* > it, value null) or "not measured".  Passes
  below the first failure are listed (`passes_below`): between α* and the smallest α
  passed (`alpha_lowest_pass`) lies a transition band where passing depends on the exact
  α (an O(dt) timing error decides whether a close pair of impacts keeps its order), so
  a finer ε grid can find a failure above a coarse grid's α*.
- **k** of α* ∝ dt^k: ordinary least squares of log10 α* on log10 dt over the dts
  whose α* is a "bracket" value, with the slope's standard error
  (reference.exponent.ordinary_least_squares); no standard error with fewer than 3
  points, no k with fewer than 2.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from reference.exponent import ordinary_least_squares

from ..metrics import follows
from ..metrics.follows import LEADING_IMPACTS, MATCH_FRACTION

DEFAULT_LEADING = LEADING_IMPACTS
DEFAULT_MATCH_FRACTION = MATCH_FRACTION
DEFAULT_C_TOLERANCE = 0.1


@dataclass(frozen=True)
class FidelityCriteria:
    """The thresholds of the test (module docstring), stated in every output."""

    leading: int = DEFAULT_LEADING
    match_fraction: float = DEFAULT_MATCH_FRACTION
    c_tolerance: float = DEFAULT_C_TOLERANCE

    def describe(self) -> str:
        return (
            f"a run passes when it matches >= {self.match_fraction:.0%} of the reference's "
            f"first {self.leading} leading impacts (chatter tails left out) and, where the "
            f"reference and the run both have an energy exponent c, |c - c_ref| <= "
            f"{self.c_tolerance:.0%} of c_ref; alpha* is the smallest inclination at which "
            "it passes, every larger one it ran passing too"
        )

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "rule": self.describe()}


def impacts_pass(matched: int, leading: int, criteria: FidelityCriteria) -> bool:
    """matched / leading ≥ match_fraction (with leading ≥ 1; harness.metrics.follows)."""
    return follows.impacts_pass(matched, leading, criteria.match_fraction)


def exponent_check(
    c_run: float | None,
    c_ref: float | None,
    criteria: FidelityCriteria,
    run_reason: str = "",
    ref_reason: str = "",
) -> tuple[bool | None, str]:
    """(verdict, explanation) of the exponent criterion: True / False when both runs
    have a c, None (not compared) otherwise, with the reason."""
    if c_ref is None:
        return None, f"not compared: the reference has no c ({ref_reason or 'no reason given'})"
    if c_run is None:
        return None, f"not compared: the run has no c ({run_reason or 'no reason given'})"
    rel = abs(c_run - c_ref) / abs(c_ref)
    ok = rel <= criteria.c_tolerance
    return ok, f"|c - c_ref| / c_ref = {rel:.3g} {'<=' if ok else '>'} {criteria.c_tolerance:g}"


def alpha_star(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """α* of one engine at one dt from its rows (module docstring), and the bottom of its
    transition band: the smallest α it passed at all (`alpha_lowest_pass`) and the next
    α run below it (`alpha_below_lowest_pass`, failed; None at the grid's bottom).  Each
    row has `alpha`, `eps`, `passes` (True / False, None when not run) and `skipped`
    (None or the reason)."""
    ordered = sorted(rows, key=lambda r: -r["alpha"])
    ran = [r for r in ordered if r.get("passes") is not None]
    star: dict[str, Any] | None = None
    first_fail: dict[str, Any] | None = None
    for row in ran:
        if not row["passes"]:
            first_fail = row
            break
        star = row
    passed = [r for r in ran if r["passes"]]
    lowest = passed[-1] if passed else None
    after = [r for r in ran if lowest is not None and r["alpha"] < lowest["alpha"]]
    below = [] if first_fail is None else [r for r in ran if r["alpha"] < first_fail["alpha"]]
    return {
        "alpha_star": star["alpha"] if star else None,
        "eps_star": star["eps"] if star else None,
        "alpha_first_fail": first_fail["alpha"] if first_fail else None,
        "bound": _bound(star, first_fail, ran),
        "alpha_lowest_pass": lowest["alpha"] if lowest else None,
        "alpha_below_lowest_pass": after[0]["alpha"] if after else None,
        "runs": len(ran),
        "passes": len(passed),
        "skipped": sum(1 for r in ordered if r.get("skipped")),
        "passes_below": [r["alpha"] for r in below if r["passes"]],
    }


def _bound(star, first_fail, ran) -> str:
    if not ran:
        return "not measured"
    if star is None:
        return "above grid"
    return "at most" if first_fail is None else "bracket"


def power_law_fit(
    dts: Sequence[float], alphas: Sequence[float], fails: Sequence[float] | None = None
) -> dict[str, Any]:
    """k, its standard error and log10 A of α* = A dt^k (least squares in log-log).

    `fails`: the first failing α below each α* (the bracket).  The true threshold lies in
    (α_fail, α*], so log10 α* overstates it by u_i ∈ [0, s_i), s_i = log10(α*/α_fail),
    and the slope k = Σ w_i y_i (w_i = (x_i − x̄)/Σ(x − x̄)²) by Σ w_i u_i: `k_grid` is
    the interval [k − Σ_{w>0} w_i s_i, k − Σ_{w<0} w_i s_i] that the grid's resolution
    leaves for k (the standard error says how far the points are from a line, this how
    far the line can move inside the brackets)."""
    x = np.log10(np.asarray(dts, dtype=float))
    y = np.log10(np.asarray(alphas, dtype=float))
    n = len(x)
    out: dict[str, Any] = {
        "k": None,
        "k_stderr": None,
        "k_grid": None,
        "log10_A": None,
        "n_points": n,
    }
    if n < 2 or np.ptp(x) == 0:
        return out
    k, b, se, rms = ordinary_least_squares(x, y)
    out.update(k=k, log10_A=b, rms_residual_decades=rms)
    out["k_stderr"] = se if n >= 3 and math.isfinite(se) else None
    if fails is not None:
        steps = y - np.log10(np.asarray(fails, dtype=float))
        w = (x - x.mean()) / np.sum((x - x.mean()) ** 2)
        out["k_grid"] = [
            k - float(np.sum((w * steps)[w > 0])),
            k - float(np.sum((w * steps)[w < 0])),
        ]
    return out
