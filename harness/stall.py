"""A bound on reference runs that stop advancing, at the harness's edge.

The reference's loop returns to Python every `work_budget` steps (ReferenceOptions)
with the time it reached.  `StallGuard` is that progress callback: when STALL_YIELDS
returns in a row each advanced t by less than one roundoff unit of the motion's time
scale per step (work_budget × ε × τ, τ = reference.scene.time_unit: √(a/g)), the run
is creeping below what double precision can resolve of the motion and would not end;
the guard raises `Stalled` with t, and the caller reports the run `failed` with that
sentence.  A run that approaches its singularity advances by its shrinking impact
intervals, far above this bound until the loop ends it (energy floor, tilt floor).
"""

from __future__ import annotations

import sys

from reference.options import ReferenceOptions
from reference.scene import Scene, time_unit

STALL_YIELDS = 3
EPS = sys.float_info.epsilon


class Stalled(Exception):
    """A reference run that stopped advancing (the message names t and the bound)."""


class StallGuard:
    """progress(t) for reference.simulate that raises Stalled (module docstring)."""

    def __init__(self, scene: Scene, work_budget: int = ReferenceOptions().work_budget):
        self.work_budget = work_budget
        self.bound = work_budget * EPS * time_unit(scene)
        self.last: float | None = None
        self.slow = 0

    def __call__(self, t: float) -> None:
        slow = self.last is not None and t - self.last < self.bound
        self.slow = self.slow + 1 if slow else 0
        self.last = t
        if self.slow >= STALL_YIELDS:
            raise Stalled(
                f"stalled at t = {t:.17g}: {STALL_YIELDS} x {self.work_budget} loop steps "
                f"advanced t by less than {self.bound:.3g} each (one roundoff unit of the "
                "motion's time scale per step); the run would not end"
            )
