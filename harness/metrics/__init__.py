"""Metrics of one simulator run against the reference (`harness compare`; docs/contract.md,
docs/output.md).

Every function here is a plain function of Trajectories: `run` (an engine, the linear
model, or the reference itself) and `reference` (the exact event-driven solution).  They
compare the two over their *common window* [max of the first sample times, min of the
last sample times]: the reference may stop early (singularity, undecidable simultaneous
impact) and an engine may fail.

Facts of the exact model that the definitions rely on (docs/architecture.md, "The model"):
- the attitude is continuous in time (impacts change velocities only), so it can be
  interpolated across impacts;
- the energy is constant in flight and in frictionless sustained contact and jumps down
  at each impact (γ < 1), so it must be interpolated *within* a phase, never across an
  impact, and a run whose impact comes a little before or after the reference's must not
  be charged the whole jump for that timing offset (impact timing is its own metric).

Tolerances and thresholds are module constants, stated in each docstring and echoed in
the `compare` document.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.trajectory import Trajectory

from .attitude import (  # noqa: F401  (the package's API)
    DIVERGENCE_TILT_FRACTION,
    attitude_error,
    attitude_error_series,
    attitude_threshold,
    first_divergence_time,
    largest_tilt,
)
from .energy import (  # noqa: F401
    ENERGY_GUARD_STEPS,
    energy_error,
    energy_error_series,
    energy_guard,
)
from .matching import (  # noqa: F401
    EVENT_TIME_TOLERANCE,
    RELATIVE_TIME_TOLERANCE,
    SLOW_IMPACT_GRAVITY_STEPS,
    SLOW_IMPACT_RELATIVE_SPEED,
    STEPS_TIME_TOLERANCE,
    ImpactMatch,
    MatchTolerance,
    Mismatch,
    chatter_tail,
    chatter_tail_speed,
    common_window,
    impact_time_error,
    impact_windows,
    impacts_matched,
    match_impacts,
    match_tolerance,
    slow_impact_speed,
)
from .restitution import RestitutionEstimate, effective_restitution  # noqa: F401
from .run_exponent import followed_to_singularity, run_exponent  # noqa: F401

# ----------------------------------------------------------------------------- all of them


@dataclass(frozen=True)
class RunMetrics:
    """Every metric of one run against the reference (the `compare` row's numbers)."""

    impacts: int
    reference_impacts: int
    impacts_matched: int
    impact_time_error: float | None
    energy_error: float | None
    energy_samples: int
    attitude_error: float | None
    energy_error_agreeing: float | None
    attitude_error_agreeing: float | None
    attitude_threshold: float
    first_divergence_time: float | None
    divergence_reason: str | None
    tolerance: MatchTolerance
    skipped_reference: int
    skipped_run: int
    common_window: tuple[float, float] | None
    restitution: RestitutionEstimate
    match: ImpactMatch | None = None
    divergence_kind: str | None = None  # "attitude" or the Mismatch kind

    @property
    def first_mismatch(self) -> Mismatch | None:
        return None if self.match is None else self.match.mismatch

    def to_dict(self) -> dict[str, Any]:
        r = self.restitution
        return {
            "impacts": self.impacts,
            "reference_impacts": self.reference_impacts,
            "impacts_matched": self.impacts_matched,
            "impact_time_error": self.impact_time_error,
            "energy_error": self.energy_error,
            "energy_samples": self.energy_samples,
            "attitude_error": self.attitude_error,
            "energy_error_agreeing": self.energy_error_agreeing,
            "attitude_error_agreeing": self.attitude_error_agreeing,
            "attitude_threshold": self.attitude_threshold,
            "first_divergence_time": self.first_divergence_time,
            "divergence_reason": self.divergence_reason,
            "time_tolerance": self.tolerance.to_dict(),
            "skipped_reference_impacts": self.skipped_reference,
            "skipped_run_impacts": self.skipped_run,
            "common_window": list(self.common_window) if self.common_window else None,
            "effective_restitution": r.median,
            "effective_restitution_quartiles": list(r.quartiles) if r.quartiles else None,
            "effective_restitution_range": list(r.range) if r.range else None,
            "effective_restitution_n": r.n,
            "restitution_speed_threshold": r.speed_threshold,
            "divergence_kind": self.divergence_kind,
            "first_mismatch": self.first_mismatch.to_dict() if self.first_mismatch else None,
        }


def evaluate(run: Trajectory, reference: Trajectory, gravity: float) -> RunMetrics:
    """All metrics of `run` against `reference` with the stated default tolerances.

    Besides the contract's maxima over the whole common window, `*_agreeing` are the
    same maxima over the part before the first divergence (all of it if none): once
    the runs are in different motions the whole-window numbers measure that difference,
    while the agreeing ones measure the run's accuracy while it follows the reference."""
    tol = match_tolerance(run, reference, gravity)
    m = match_impacts(run, reference, tol)
    t_e, e_err = energy_error_series(run, reference, tol)
    t_a, a_err = attitude_error_series(run, reference)
    threshold = attitude_threshold(run, reference)
    t_div, why = first_divergence_time(run, reference, tol, threshold)
    cut = math.inf if t_div is None else t_div
    kind = None
    if t_div is not None:
        kind = m.mismatch.kind if m.mismatch and t_div == m.mismatch_time else "attitude"
    return RunMetrics(
        impacts=len(run.impacts),
        reference_impacts=m.n_reference,
        impacts_matched=m.n_matched,
        impact_time_error=float(np.max(np.abs(m.time_errors))) if m.n_matched else None,
        energy_error=_max_or_none(e_err),
        energy_samples=int(e_err.size),
        attitude_error=_max_or_none(a_err),
        energy_error_agreeing=_max_or_none(e_err[t_e < cut]),
        attitude_error_agreeing=_max_or_none(a_err[t_a < cut]),
        attitude_threshold=threshold,
        first_divergence_time=t_div,
        divergence_reason=why,
        tolerance=tol,
        skipped_reference=m.skipped_reference,
        skipped_run=m.skipped_run,
        common_window=common_window(run, reference),
        restitution=effective_restitution(run, gravity),
        match=m,
        divergence_kind=kind,
    )


def _max_or_none(x: np.ndarray) -> float | None:
    return float(x.max()) if x.size else None
