"""The growth of a small separation per impact: a finite-time Lyapunov exponent of the
impact map, from a perturbed ensemble (ensemble.perturbed_ensemble).

For a member matched to the reference impact by impact, d_i is the separation
(`state.separation`, dimensionless) of the two states just after their i-th matched
impacts: the impact map's section, so that a mere shift in time (the flow's neutral
direction) does not count.  While d_i is small (≤ LINEAR_SEPARATION) it grows as
d_i ≈ d_0 e^{λ i}; λ of a member is the least-squares slope of ln d_i against i, and the
ensemble's λ the median over members with at least MIN_POINTS such impacts.

Horizon at another level: a member matched n impacts at level ε0 diverges where its
separation reaches the matching window; at level ε it gets there ln(ε0/ε)/λ impacts
later: n(ε) = n(ε0) + ln(ε0/ε)/λ (`predicted_horizon`).  The growth is far from uniform
along a motion (pentagon-bounce: slow over the first ~20 impacts, fast later), so over
decades a constant λ extrapolates poorly; `profile_horizon` uses each member's own
impact-time offsets instead, scaled by ε/ε0 (linear in the perturbation in the tangent
regime), against the matching windows.
"""

from __future__ import annotations

import math

import numpy as np

from reference import Trajectory
from reference.scene import Scene

from ..metrics import impact_windows, match_tolerance
from .ensemble import Member
from .state import post_impact_states, separation

LYAPUNOV_LEVEL = 1e-8  # the perturbation of the ensemble λ is measured on
LINEAR_SEPARATION = 1e-3  # d_i up to this is still growing linearly (tangent regime)
MIN_POINTS = 4


def separations(
    scene: Scene, reference: Trajectory, member: Member
) -> tuple[np.ndarray, np.ndarray]:
    """(reference impact indices, d_i) over the member's matched impacts."""
    pairs = member.match.pairs
    if len(pairs) == 0:
        return np.zeros(0, int), np.zeros(0)
    ref_states = post_impact_states(reference)[pairs[:, 0]]
    run_states = post_impact_states(member.trajectory)[pairs[:, 1]]
    return pairs[:, 0], separation(scene, run_states, ref_states)


def member_growth(index: np.ndarray, d: np.ndarray) -> float | None:
    """Least-squares slope of ln d_i on i over 0 < d_i ≤ LINEAR_SEPARATION, or None
    with fewer than MIN_POINTS such impacts."""
    keep = (d > 0) & (d <= LINEAR_SEPARATION)
    if np.count_nonzero(keep) < MIN_POINTS:
        return None
    return float(np.polyfit(index[keep].astype(float), np.log(d[keep]), 1)[0])


def lyapunov_per_impact(scene: Scene, reference: Trajectory, members: list[Member]) -> float | None:
    """Median growth rate λ per impact over the members (module docstring)."""
    rates = [member_growth(*separations(scene, reference, m)) for m in members]
    rates = [r for r in rates if r is not None]
    return float(np.median(rates)) if rates else None


def predicted_horizon(n0: float, level0: float, level: float, rate: float | None) -> float | None:
    """n(ε) = n(ε0) + ln(ε0/ε)/λ, at least 0: impacts matched at level ε, from n0 at
    ε0; None without a positive growth rate."""
    if rate is None or rate <= 0 or level <= 0 or not math.isfinite(level):
        return None
    return max(0.0, n0 + math.log(level0 / level) / rate)


def profile_horizon(
    reference: Trajectory, members: list[Member], gravity: float, level0: float, level: float
) -> float | None:
    """Median over members of the first matched impact i where the member's impact-time
    offset scaled to the new level, |t_run − t_ref|·ε/ε0, exceeds the matching window
    w_i (harness.metrics.impact_windows with the member's tolerance: the run's dt); a
    member whose scaled offsets stay inside counts its matched impacts.  In the tangent
    regime offsets are linear in the perturbation, so this is where the member would
    stop matching at level ε by the time criterion (a contact swap can come earlier).
    None without members."""
    ends = []
    for m in members:
        if m.match.n_matched == 0:
            continue
        tol = match_tolerance(m.trajectory, reference, gravity)
        w = impact_windows(reference, tol)[m.match.pairs[:, 0]]
        over = np.flatnonzero(np.abs(m.match.time_errors) * (level / level0) > w)
        ends.append(float(m.match.pairs[over[0], 0]) if len(over) else float(m.matched))
    return float(np.median(ends)) if ends else None
