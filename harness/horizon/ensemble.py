"""Ensembles of the exact model around one reference run, and how many of its leading
impacts each member reproduces (the matching of `compare`: harness.metrics.matching).

Two kinds of member:
- perturbed: the reference restarted from its state at a start (the initial state, or
  just after one of its impacts) displaced by `level` times a random direction
  (`state.random_directions`: uniform on the unit sphere of the dimensionless
  12-component difference, `state.units`), lifted onto the ground if the displacement
  put a contact below it (`state.lifted`);
- grid: the grid model of `grid.py` at a timestep dt, with a uniform random phase.

Every member is seeded from (seed, member index) alone, so an ensemble is reproducible
and a larger one extends a smaller one.  Each member becomes a Trajectory with the
judged engine's dt, so that the time windows are the engine's (3·dt + 1 %·t).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from reference import Trajectory
from reference.scene import Scene

from ..metrics import ImpactMatch, chatter_tail_speed, match_impacts, match_tolerance
from .grid import GridRun
from .settings import DEFAULT_RUNS, DEFAULT_SEED
from .state import displaced, lifted, post_impact_states, random_directions, run_from

CHECK_EVERY = 16  # grid runs: impacts between checks whether they have diverged


@dataclass(frozen=True)
class Member:
    """One member: its trajectory (times of the reference's run) and its match."""

    trajectory: Trajectory
    match: ImpactMatch

    @property
    def matched(self) -> int:
        return self.match.n_matched


def member_rng(seed: int, index: int) -> np.random.Generator:
    """The random stream of member `index` of an ensemble seeded with `seed`."""
    return np.random.default_rng([int(seed), int(index)])


def rematched(
    members: list[Member], reference: Trajectory, gravity: float, dt: float | None
) -> list[Member]:
    """The same members judged as runs at timestep dt (its matching windows)."""
    out = []
    for m in members:
        traj = replace(m.trajectory, dt=dt)
        out.append(Member(traj, matched(traj, reference, gravity)))
    return out


def matched(run: Trajectory, reference: Trajectory, gravity: float) -> ImpactMatch:
    """`compare`'s matching of run against reference (harness.metrics.match_impacts)."""
    return match_impacts(run, reference, match_tolerance(run, reference, gravity))


# ----------------------------------------------------------------------------- perturbed


def perturbed_member(
    scene: Scene,
    reference: Trajectory,
    start: int | None,
    step: np.ndarray,
    dt: float | None,
) -> Member:
    """The reference restarted at `start` (None: its initial state; k: just after its
    impact k) from its state there displaced by the dimensionless `step` (12,)."""
    if start is None:
        t0, y0 = 0.0, _initial_row(reference)
        prefix_t, prefix_y, prefix_imp = np.zeros(0), np.zeros((0, 13)), []
    else:
        t0 = float(reference.impacts[start].t)
        y0 = post_impact_states(reference)[start]
        keep = reference.t < t0
        prefix_t, prefix_y = reference.t[keep], _rows(reference)[keep]
        prefix_imp = list(reference.impacts)[: start + 1]
    y, _ = lifted(scene, displaced(scene, y0, step))
    sub = run_from(scene, y, max(reference.t_final - t0, 0.0), scene.run.max_impacts)
    traj = Trajectory.from_states(
        "perturbed", scene.name,
        np.concatenate([prefix_t, t0 + sub.t]), np.concatenate([prefix_y, _rows(sub)]),
        np.zeros(len(prefix_t) + len(sub.t)), np.zeros(len(prefix_t) + len(sub.t)),
        prefix_imp + [_shifted(e, t0) for e in sub.impacts], sub.status,
        message=sub.message, t_final=t0 + sub.t_final, dt=dt,
    )  # fmt: skip
    return Member(traj, matched(traj, reference, scene.gravity))


def perturbed_ensemble(
    scene: Scene,
    reference: Trajectory,
    level: float,
    runs: int = DEFAULT_RUNS,
    seed: int = DEFAULT_SEED,
    start: int | None = None,
    dt: float | None = None,
    progress: Callable[[], None] | None = None,
) -> list[Member]:
    """`runs` members perturbed at `level` (module docstring), judged at timestep dt."""
    members = []
    for i in range(runs):
        step = level * random_directions(member_rng(seed, i), 1)[0]
        members.append(perturbed_member(scene, reference, start, step, dt))
        if progress is not None:
            progress()
    return members


# ----------------------------------------------------------------------------- grid


def grid_member(
    scene: Scene,
    reference: Trajectory,
    dt: float,
    phase: float,
    tail: float,
    limit: int | None = None,
) -> Member:
    """One run of the grid model, stopped once it has diverged from the reference (the
    match is checked every CHECK_EVERY impacts) or after `limit` impacts (default: as
    many as the reference has plus CHECK_EVERY)."""
    run = GridRun(scene, dt, phase, reference.t_final, tail)
    limit = len(reference.impacts) + CHECK_EVERY if limit is None else limit
    while run.step():
        if len(run.impacts) >= limit:
            break
        if len(run.impacts) % CHECK_EVERY == 0:
            m = matched(run.trajectory(), reference, scene.gravity)
            if m.mismatch is not None:
                break
    traj = run.trajectory()
    return Member(traj, matched(traj, reference, scene.gravity))


def grid_ensemble(
    scene: Scene,
    reference: Trajectory,
    dt: float,
    runs: int = DEFAULT_RUNS,
    seed: int = DEFAULT_SEED,
    progress: Callable[[], None] | None = None,
    limit: int | None = None,
) -> list[Member]:
    """`runs` grid-model runs at dt with phases uniform in [0, dt) (grid.py), each of
    at most `limit` impacts (grid_member)."""
    tail = chatter_tail_speed(reference, scene.gravity, dt)
    members = []
    for i in range(runs):
        phase = float(member_rng(seed, i).uniform(0.0, dt))
        members.append(grid_member(scene, reference, dt, phase, tail, limit))
        if progress is not None:
            progress()
    return members


# ----------------------------------------------------------------------------- helpers


def matched_counts(members: list[Member]) -> np.ndarray:
    return np.array([m.matched for m in members], dtype=int)


def _rows(traj: Trajectory) -> np.ndarray:
    return np.concatenate(
        [traj.position, traj.quaternion, traj.velocity, traj.angular_velocity], axis=1
    )


def _initial_row(traj: Trajectory) -> np.ndarray:
    return _rows(traj)[0]


def _shifted(e, t0: float):
    from reference.trajectory import ImpactEvent

    return ImpactEvent(t0 + e.t, e.contact, e.impulse, e.v_normal_pre, e.v_normal_post)
