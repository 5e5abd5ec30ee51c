"""Effective restitution of a run's own impacts."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.trajectory import Trajectory

from .matching import chatter_tail_speed

# ----------------------------------------------------------------------------- restitution


@dataclass(frozen=True)
class RestitutionEstimate:
    """Effective restitution e_i = −v_post / v_pre of a run's own impacts."""

    median: float | None
    quartiles: tuple[float, float] | None
    range: tuple[float, float] | None
    n: int
    speed_threshold: float


def effective_restitution(traj: Trajectory, gravity: float) -> RestitutionEstimate:
    """Median (and quartiles, range) of e_i = −v_normal_post / v_normal_pre over the
    trajectory's impacts that approach faster than the threshold

        v_pre < −max(10·g·dt, 0.01 · max_i |v_pre,i|)    (dt = 0 for event-driven runs)

    (`slow_impact_speed`: slower "impacts" are solver contact flicker or late chatter,
    dominated by resolution and by the other contacts' forces; they say nothing about
    the impact law)."""
    pre = traj.impact_column("v_normal_pre")
    post = traj.impact_column("v_normal_post")
    v_min = chatter_tail_speed(traj, gravity, traj.dt)
    use = pre < -v_min
    if not np.any(use):
        return RestitutionEstimate(None, None, None, 0, v_min)
    e = -post[use] / pre[use]
    q1, med, q3 = np.percentile(e, [25, 50, 75])
    return RestitutionEstimate(
        float(med), (float(q1), float(q3)), (float(e.min()), float(e.max())), int(e.size), v_min
    )
