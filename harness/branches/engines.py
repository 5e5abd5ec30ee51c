"""Engines started at the first undecidable state: which impact law each one obeys
(`harness branches SCENE --engine NAME`; docs/laws.md).

The reference runs the scene under the paper's rule to its first undecidable state
(t_u, the state y_u just before the impact).  Each engine starts from the reference's
state a short lead before it, at t_u − lead (the reference's own state there; for a
scene that starts on the undecidable state, y_u carried back by free flight, or y_u
itself when a touching contact separates and would be below the ground earlier), and
runs through the impact to t_m = t_u + after.  A fixed-step engine starts half a step
earlier still (at t_u − lead − dt/2, measured at t_m − dt/2 against the branches there):
the start is a whole number of steps before t_u otherwise, and an impact exactly on a
step boundary is a coincidence of the set-up that decides which contact a stepped
engine meets first; mid-step is the generic case.  Each branch (every law of
reference.scene.IMPACT_LAWS but `paper`, and the sequential law in every order of the
contacts, harness.branches.spread) is the exact reference from the scene's start to
t_m.  Branches whose states at t_m coincide are one outcome (named together).

Units: the horizon's (harness.horizon.state): speeds in U = max(√(g a), a/t_end),
angular velocities in U/a, times in a/U.  The distance of an engine's state at t_m to
a branch's is the Euclidean norm of (Δv/U, Δω a/U, Δuᵢ/U over the contacts of the
impact): its velocities and the post-impact normal velocities.

Verdict per engine and dt:
- `follows L`: L is nearer than every other outcome by FOLLOW_FACTOR (3) or more, and
  the distance to L falls as dt falls (to FALL_FRACTION of it or less, against the next
  larger dt; at the largest dt against the next smaller one), or is at roundoff
  (≤ EXACT_DISTANCE: an event-driven engine that is an exact law);
- `between L and M`: the two nearest outcomes are within FOLLOW_FACTOR of each other;
- `none of the laws`: L is clearly nearest but its distance does not fall with dt, or
  it is farther than FAR_DISTANCE;
- `undecided`: nothing to measure (the engine failed, or one dt of a fixed-step
  engine, whose trend is not measured).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from reference.core import layout as L
from reference.scene import velocity_unit

from ..horizon.state import flown, scene_at
from ..text import run_label
from .follow import FOLLOW_FACTOR
from .spread import ordered_runs

LEAD = 0.02  # the engines start this long (in a/U) before t_u
AFTER = 0.1  # and measured at most this long after it (half the gap to the next impact)
AFTER_MIN = 0.02  # but at least this long after it
EXACT_DISTANCE = 1e-9
# "falls with dt": at the next smaller dt the distance is at most this fraction of it (a
# first-order method gives 1/10 per decade; a bare decrease would count roundoff-level
# changes of an engine that has reached its own floor)
FALL_FRACTION = 0.5
FAR_DISTANCE = 0.5
SAME_OUTCOME = 1e-9  # branches closer than this (dimensionless) are one outcome
LAWS = ("moreau", "sequential", "compliant", "compliant-mass")


@dataclass
class Outcome:
    """One or more branches with the same state at t_m."""

    names: list[str]
    law: str
    order: tuple[int, ...] | None
    state: np.ndarray = field(repr=False)

    @property
    def name(self) -> str:
        return " = ".join(self.names)


@dataclass
class EngineAtImpact:
    """One engine at one dt: its distances to every outcome and the verdict."""

    engine: str
    dt: float | None
    status: str
    distances: dict[str, float]
    verdict: str = "undecided"
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "engine": self.engine, "dt": self.dt, "status": self.status,
            "distances": self.distances, "verdict": self.verdict, "reason": self.reason,
        }  # fmt: skip


@dataclass
class ImpactStudy:
    scene: str
    t_u: float | None
    contacts: list[int]
    lead: float
    after: float
    outcomes: list[Outcome]
    runs: list[EngineAtImpact]
    message: str = ""
    apart: float = math.inf  # the least distance between two outcomes

    def to_dict(self) -> dict[str, Any]:
        return {
            "command": "branches", "mode": "engines", "scene": self.scene, "t_u": self.t_u,
            "contacts": self.contacts, "lead": self.lead, "after": self.after,
            "outcomes": [{"name": o.name, "branches": o.names, "law": o.law,
                          "order": list(o.order) if o.order else None} for o in self.outcomes],
            "outcomes_apart": self.apart if math.isfinite(self.apart) else None,
            "runs": [r.to_dict() for r in self.runs], "message": self.message,
        }  # fmt: skip


def state_of(traj, i: int = -1) -> np.ndarray:
    """The 13-state of a trajectory's sample i."""
    return np.concatenate(
        [traj.position[i], traj.quaternion[i], traj.velocity[i], traj.angular_velocity[i]]
    )


def distance(scene, y, y_ref, contacts: list[int]) -> float:
    """The dimensionless distance of state y to y_ref (module docstring)."""
    from reference.geometry import scene_contact_kinematics

    u, a = velocity_unit(scene), scene.body.radius
    dv = (y[L.VELOCITY] - y_ref[L.VELOCITY]) / u
    dw = (y[L.ANGULAR_VELOCITY] - y_ref[L.ANGULAR_VELOCITY]) * a / u
    _, vn = scene_contact_kinematics(scene, np.stack([y, y_ref]))
    du = (vn[0, contacts] - vn[1, contacts]) / u
    return float(np.sqrt(dv @ dv + dw @ dw + du @ du))


def undecidable_state(scene, t_end: float):
    """(paper trajectory, t_u, y_u, touching contacts) or (traj, None, None, [])."""
    from reference import simulate

    from .spread import touching_contacts

    paper = simulate(scene.with_impact_law("paper"), t_end=t_end)
    if paper.status.value != "simultaneous_impact":
        return paper, None, None, []
    y_u = state_of(paper)
    touching = touching_contacts(scene, y_u, separating=True)
    return paper, float(paper.t_final), y_u, touching.tolist()


def start_before(scene, t_u: float, y_u: np.ndarray, lead: float) -> tuple[np.ndarray, float]:
    """(state, lead): the reference's state at t_u − lead, or y_u carried back by free
    flight when t_u < lead (lead 0 when a contact would be below the ground there)."""
    from reference import simulate
    from reference.geometry import scene_contact_kinematics

    if t_u >= lead:
        return state_of(simulate(scene.with_impact_law("paper"), t_end=t_u - lead)), lead
    y0 = flown(scene, y_u, -lead)
    gap, _ = scene_contact_kinematics(scene, y0[None, :])
    if gap.min() < 0.0:
        return np.array(y_u, dtype=float), 0.0
    return y0, lead


def mid_step_start(scene, t_u: float, y_u, y0, lead: float, dt: float | None):
    """(start state, its lead) of an engine at step dt: half a step before the common
    start, so that t_u lies mid-step on the engine's grid (module docstring); the common
    start for an event-driven engine, or where no earlier state exists."""
    if dt is None:
        return y0, lead
    y, shifted = start_before(scene, t_u, y_u, lead + 0.5 * dt)
    return (y, shifted) if shifted == lead + 0.5 * dt else (y0, lead)


def branch_list(contacts: list[int]) -> list[tuple[str, str, tuple[int, ...] | None]]:
    """(name, law, order) of every branch: each law, the sequential law in each order."""
    return [(law, law, None) for law in LAWS] + ordered_runs(contacts)


def law_run(scene, t_end: float, law: str, order=None):
    """The exact reference under `law` (and `order`) to t_end."""
    from reference import ReferenceOptions, simulate

    opts = ReferenceOptions(impact_law=law, sequential_order=order)
    return simulate(scene, t_end=t_end, options=opts)


def impact_contacts(scene, t_u: float, touching: list[int]) -> tuple[list[int], float]:
    """(contacts of the impact, time to the first impact after t_u): those touching and
    those a law gave an impulse at t_u; the least gap to a later impact over the laws'
    runs (AFTER a/U at most)."""
    gap = AFTER * scene.body.radius / velocity_unit(scene)
    took = set(touching)
    for law in LAWS:
        impacts = law_run(scene, t_u + gap, law).impacts
        t = np.asarray([e.t for e in impacts], dtype=float)
        took |= {e.contact for e in impacts if e.t == t_u}
        later = t[t > t_u]
        gap = min(gap, float(later[0] - t_u)) if later.size else gap
    return sorted(int(c) for c in took), gap


def measure_time(scene, lead: float, gap: float, dts) -> float:
    """The engines' run, lead + after: after = half the gap to the next impact, at least
    AFTER_MIN a/U (a chatter's next bounces are then part of what is compared), rounded
    up to a whole number of the largest dt."""
    unit = scene.body.radius / velocity_unit(scene)
    total = lead + max(0.5 * gap, AFTER_MIN * unit)
    steps = [dt for dt in dts if dt]
    if steps:
        total = math.ceil(total / max(steps) - 1e-9) * max(steps)
    return total


def outcomes_at(scene, t_m: float, contacts: list[int]) -> list[Outcome]:
    """Every branch's state at t_m, grouped by state (within SAME_OUTCOME)."""
    out: list[Outcome] = []
    for name, law, order in branch_list(contacts):
        y = state_of(law_run(scene, t_m, law, order))
        same = [o for o in out if distance(scene, y, o.state, contacts) <= SAME_OUTCOME]
        if same:
            same[0].names.append(name)
        else:
            out.append(Outcome([name], law, order, y))
    return out


def run_engine(engine: str, scene, y0, duration: float, dt, contacts, outcomes) -> EngineAtImpact:
    """The engine from y0 for `duration`; its distances to every outcome at the end."""
    from ..simulators import run_simulator

    eng_scene = scene_at(scene, y0, duration, scene.run.max_impacts)
    traj = run_simulator(engine, eng_scene, dt, duration)
    status = traj.status.value
    if traj.n_samples == 0 or not math.isclose(float(traj.t[-1]), duration, rel_tol=1e-6):
        return EngineAtImpact(engine, dt, status, {}, "undecided", "the run ended early")
    y = state_of(traj)
    if not np.all(np.isfinite(y)):
        return EngineAtImpact(engine, dt, status, {}, "undecided", "no finite state")
    dist = {o.name: distance(scene, y, o.state, contacts) for o in outcomes}
    return EngineAtImpact(engine, dt, status, dist)


def verdicts(runs: list[EngineAtImpact]) -> None:
    """In place: each run's verdict (module docstring), per engine over its dts."""
    by_engine: dict[str, list[EngineAtImpact]] = {}
    for r in runs:
        by_engine.setdefault(r.engine, []).append(r)
    for rows in by_engine.values():
        measured = sorted((r for r in rows if r.distances), key=lambda r: -(r.dt or 0.0))
        for i, r in enumerate(measured):
            neighbour = measured[i - 1] if i > 0 else (measured[1] if len(measured) > 1 else None)
            r.verdict, r.reason = verdict(r, neighbour)


def verdict(r: EngineAtImpact, neighbour: EngineAtImpact | None) -> tuple[str, str]:
    """(verdict, reason) of one run; `neighbour` the same engine at the adjacent dt."""
    ranked = sorted(r.distances.items(), key=lambda kv: kv[1])
    (best, d_best) = ranked[0]
    d_next = ranked[1][1] if len(ranked) > 1 else math.inf
    if d_next < FOLLOW_FACTOR * d_best:
        return f"between {best} and {ranked[1][0]}", f"{d_best:.3g} vs {d_next:.3g}"
    if d_best <= EXACT_DISTANCE:
        return f"follows {best}", f"at roundoff ({d_best:.3g})"
    if d_best > FAR_DISTANCE:
        return "none of the laws", f"the nearest, {best}, is {d_best:.3g} away"
    if neighbour is None or neighbour.dt is None or r.dt is None:
        return "undecided", f"nearest {best} ({d_best:.3g}); one dt: no trend measured"
    d_other = neighbour.distances.get(best, math.inf)
    smaller, larger = (d_best, d_other) if r.dt < neighbour.dt else (d_other, d_best)
    falls = smaller <= FALL_FRACTION * larger
    if falls:
        return f"follows {best}", f"{d_best:.3g}, falling with dt"
    return "none of the laws", f"nearest {best} ({d_best:.3g}) but not falling with dt"


def planned_runs(engines: list[str], dts: list[float | None]) -> int:
    """How many engine runs `study` makes for one scene (a progress bar's total)."""
    return sum(len(_engine_dts(engine, dts)) for engine in engines)


def study(scene, engines: list[str], dts: list[float | None], t_end: float | None = None,
          bar=None) -> ImpactStudy:  # fmt: skip
    """Every engine at every dt against every branch (module docstring).  `bar`: a
    harness.progress bar, advanced once per engine run (by all of them at once when the
    scene has no undecidable state)."""
    t_end = float(t_end if t_end is not None else scene.run.t_end)
    _, t_u, y_u, contacts = undecidable_state(scene, t_end)
    if t_u is None:
        if bar is not None:
            bar.update(planned_runs(engines, dts))
        return ImpactStudy(scene.name, None, [], 0.0, 0.0, [], [],
                           "no undecidable state: every law gives the same run")  # fmt: skip
    unit = scene.body.radius / velocity_unit(scene)
    y0, lead = start_before(scene, t_u, y_u, LEAD * unit)
    contacts, gap = impact_contacts(scene, t_u, contacts)
    duration = measure_time(scene, lead, gap, dts)
    after = duration - lead
    outcomes = outcomes_at(scene, t_u + after, contacts)
    apart = min((distance(scene, a.state, b.state, contacts) for i, a in enumerate(outcomes)
                 for b in outcomes[i + 1 :]), default=math.inf)  # fmt: skip
    starts: dict[float | None, tuple] = {}
    runs = []
    for engine in engines:
        for dt in _engine_dts(engine, dts):
            if bar is not None:
                bar.set_postfix_str(f"{scene.name}: {run_label(engine, dt)}", refresh=False)
            if dt not in starts:
                starts[dt] = engine_start(scene, t_u, y_u, y0, lead, after, dt, contacts)
            y_dt, outcomes_dt = starts[dt] if starts[dt][1] is not None else (y0, outcomes)
            runs.append(run_engine(engine, scene, y_dt, duration, dt, contacts, outcomes_dt))
            if bar is not None:
                bar.update()
    verdicts(runs)
    return ImpactStudy(scene.name, t_u, contacts, lead, after, outcomes, runs, apart=apart)


def engine_start(scene, t_u, y_u, y0, lead, after, dt, contacts) -> tuple:
    """(start state, outcomes at its measuring time) for an engine at step dt: from
    `mid_step_start`, with the branches' states at t_u + after − the extra lead (None
    when the start is the common one, whose outcomes the study has)."""
    y_dt, lead_dt = mid_step_start(scene, t_u, y_u, y0, lead, dt)
    shift = lead_dt - lead
    if shift == 0.0:
        return y0, None
    return y_dt, outcomes_at(scene, t_u + after - shift, contacts)


def _engine_dts(engine: str, dts: list[float | None]) -> list[float | None]:
    """The dts of a fixed-step engine; [None] for an event-driven one."""
    from ..simulators import is_fixed_step

    return list(dts) if is_fixed_step(engine) else [None]
