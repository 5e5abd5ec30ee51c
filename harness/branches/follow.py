"""Which branch a run follows after the reference's first undecidable state, and how
far it stays with it (`harness compare`).

The reference under the paper's rule stops `simultaneous_impact` at t_u;
harness.branches.spread continues it under every law (the branches b).  A run (an
engine, the linear model) is set against each branch after t_u:

- impacts: the run's impacts after t_u against the branch's, walked with the rule of
  `compare` (harness.metrics.match_impacts with the run's MatchTolerance: same
  contact, time within the branch impact's window w, chatter tails skipped).  The walk
  starts at the branch's first impact after t_u and at the run's first impact after
  t_u that is not the undecidable impact itself (leading run impacts at a contact of
  the undecidable state, no later than the widest window of the branch's impact rows
  at t_u);
- energy: the energy above the resting level E at t_e = t_u + the energy guard
  (harness.metrics.energy_guard: 3 steps for fixed-step runs, 0 event-driven), the
  run's against the branch's, over the reference's E just before t_u (E_u; the
  absolute difference if E_u is not positive, a body with no energy left to share).

Distance (dimensionless): d = d_impacts + d_energy with

    d_impacts = (Σ_matched |t_run − t_b| / w + U) / K,   d_energy = |E_run − E_b| / E_u

over the branch's first K = NEXT_IMPACTS impacts after t_u inside the common window:
the matched ones count their time offset in windows (≤ 1), chatter tails skipped
count 0, U is the number of those not reproduced (missed, or after the first
disagreement; 1 for an extra run impact where the branch has fewer than K).  The
nearest branch has the least d (ties: the first in the branches' order).  How far the
run stays with it: k of its N impacts after t_u (in the common window) reproduced in
order (s tails skipped on the way: k+s/N), until the first disagreement, or the end of
the common window when there is none; a branch that ends at the singularity is at rest
from then on (`stays_until`): a run impact after that, faster than the chatter tails, is
a disagreement (and counts as an extra impact in d_impacts), and a run without one stays
with the branch to its own end.  The choice is *decided* when the run had not left the
reference before t_u and the next nearest branch of another distance is FOLLOW_FACTOR
(3) times the nearest's distance or farther (the factor of `harness branches
--engine`, harness.branches.engines); branches at exactly the nearest's distance (in
practice the same run: the sequential law in the order it would choose anyway) are
taken as its outcome.  A run that left the reference before t_u gets no branch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.exponent import excess_energy_of
from reference.trajectory import Trajectory

from ..metrics import common_window, energy_guard, impact_windows, match_impacts, match_tolerance
from .spread import NEXT_IMPACTS, Branch, Spread

# the nearest branch is decided when the runner-up is this many times farther
FOLLOW_FACTOR = 3.0


@dataclass(frozen=True)
class BranchDistance:
    """A run against one branch after t_u (module docstring)."""

    branch: str
    law: str
    order: tuple[int, ...] | None
    impacts: int  # k: the branch's impacts after t_u reproduced in order
    skipped: int  # s: its chatter-tail impacts skipped on the way
    of: int  # N: its impacts after t_u inside the common window
    until: float | None  # first disagreement, else the end of the common window
    impacts_distance: float
    energy_distance: float

    @property
    def distance(self) -> float:
        return self.impacts_distance + self.energy_distance

    def to_dict(self) -> dict[str, Any]:
        return {
            "branch": self.branch, "law": self.law,
            "order": list(self.order) if self.order else None,
            "impacts": self.impacts, "skipped": self.skipped, "of": self.of,
            "until": self.until, "distance": self.distance,
            "impacts_distance": self.impacts_distance, "energy_distance": self.energy_distance,
        }  # fmt: skip


@dataclass(frozen=True)
class BranchFollow:
    """The branch a run follows: the nearest of `candidates` (in the branches' order)."""

    t_u: float
    t_energy: float  # t_e, where the energies are read
    energy_run: float | None  # the run's E at t_e
    followed_reference: bool  # the run had not diverged from the reference before t_u
    candidates: list[BranchDistance]

    @property
    def nearest(self) -> BranchDistance:
        return min(self.candidates, key=lambda c: c.distance)

    @property
    def runner_up(self) -> BranchDistance | None:
        """The nearest branch of another outcome (another distance), if any."""
        d = self.nearest.distance
        others = [c for c in self.candidates if c.distance != d]
        return min(others, key=lambda c: c.distance, default=None)

    @property
    def margin(self) -> float | None:
        """The runner-up's distance less the nearest's (None without a runner-up)."""
        r = self.runner_up
        return None if r is None else r.distance - self.nearest.distance

    @property
    def decided(self) -> bool:
        """The run stayed on the reference to t_u and the runner-up is FOLLOW_FACTOR
        times the nearest's distance or farther (branches at exactly the nearest's
        distance are taken as its outcome)."""
        r = self.runner_up
        if not self.followed_reference or r is None:
            return False
        return r.distance >= FOLLOW_FACTOR * self.nearest.distance

    def to_dict(self) -> dict[str, Any]:
        doc = self.nearest.to_dict()
        doc.update(
            t_u=self.t_u, t_energy=self.t_energy, energy_run=self.energy_run,
            followed_reference=self.followed_reference, margin=self.margin,
            decided=self.decided,
            candidates=[c.to_dict() for c in self.candidates],
        )  # fmt: skip
        return doc


def excess_at(t: np.ndarray, e: np.ndarray, when: float) -> float | None:
    """E at the last sample at or before `when` (after an impact there: samples at one
    time are in order), None without one."""
    i = int(np.searchsorted(t, when, side="right")) - 1
    return float(e[i]) if i >= 0 else None


def walk_start(run: Trajectory, branch: Trajectory, t_u: float, tolerance) -> tuple[int, int]:
    """(i, j): the branch's first impact after t_u, and the run's first impact after t_u
    that is not the undecidable impact itself (module docstring)."""
    tb, tr, cr = branch.impact_times(), run.impact_times(), run.impact_contacts()
    at = np.flatnonzero(tb == t_u)
    i = int(np.searchsorted(tb, t_u, side="right"))
    j = int(np.searchsorted(tr, t_u, side="right"))
    if at.size:
        w = float(np.max(impact_windows(branch, tolerance)[at]))
        took = set(branch.impact_contacts()[at].tolist())
        while j < len(tr) and tr[j] - t_u <= w and int(cr[j]) in took:
            j += 1
    return i, j


def stays_until(run: Trajectory, b: Branch, tail_speed: float) -> float:
    """Where a run that agrees with branch `b` as far as both go stops agreeing: a
    branch that ends at the singularity is at rest from then on, so the run's first
    impact after it that is not slower than `tail_speed` (a chatter tail); the run's end
    without one.  Other branches: the end of the common window."""
    if b.status != "singularity":
        window = common_window(run, b.trajectory)
        return window[1] if window else float(run.t[-1])
    t_rest = float(b.trajectory.t[-1])
    t = run.impact_times()
    fast = (t > t_rest) & (np.abs(run.impact_column("v_normal_pre")) >= tail_speed)
    return float(t[fast][0]) if fast.any() else float(run.t[-1])


def branch_distance(
    run: Trajectory,
    b: Branch,
    t_u: float,
    gravity: float,
    energy_run: float | None,
    t_e: float,
    e_u: float,
) -> BranchDistance:
    """The run against branch `b` (module docstring)."""
    tol = match_tolerance(run, b.trajectory, gravity)
    i0, j0 = walk_start(run, b.trajectory, t_u, tol)
    m = match_impacts(run, b.trajectory, tol, start=(i0, j0))
    n_after = max(m.n_reference - i0, 0)
    first = min(NEXT_IMPACTS, n_after)
    windows = impact_windows(b.trajectory, tol)
    offsets = [abs(dt) / windows[i] for (i, _), dt in zip(m.pairs, m.time_errors, strict=True)
               if i < i0 + first]  # fmt: skip
    skipped = sum(1 for i in m.skipped_reference_indices if i < i0 + first)
    unreproduced = first - len(offsets) - skipped
    until = m.mismatch_time if m.mismatch is not None else stays_until(run, b, tol.tail_speed)
    bounces_after_rest = b.status == "singularity" and until < float(run.t[-1])
    disagrees = m.mismatch is not None or bounces_after_rest
    if disagrees and unreproduced == 0 and first < NEXT_IMPACTS:
        unreproduced = 1  # an extra run impact where the branch has no more
    e_b = excess_at(*b.energy_curve, t_e)
    e_dist = math.inf if energy_run is None or e_b is None else abs(energy_run - e_b) / e_u
    return BranchDistance(
        b.name, b.law, b.order, m.n_matched, m.skipped_reference, n_after, until,
        (sum(offsets) + unreproduced) / NEXT_IMPACTS, e_dist,
    )  # fmt: skip


def follow_branches(
    run: Trajectory, spread: Spread, scene, first_divergence: float | None
) -> BranchFollow | None:
    """The run against every branch of `spread`; None when the reference reached no
    undecidable state or the run has no sample after t_u."""
    if spread.undecidable is None or not spread.branches:
        return None
    t_u = float(spread.undecidable["t"])
    if run.n_samples == 0 or run.t[-1] <= t_u:
        return None
    t_e = t_u + energy_guard(run)
    energy_run = excess_at(run.t, excess_energy_of(run, scene), t_e)
    e_u = excess_at(*spread.paper.energy_curve, t_u)
    e_u = e_u if e_u is not None and e_u > 0 else 1.0
    candidates = [
        branch_distance(run, b, t_u, scene.gravity, energy_run, t_e, e_u) for b in spread.branches
    ]
    followed = first_divergence is None or first_divergence >= t_u
    return BranchFollow(t_u, t_e, energy_run, followed, candidates)
