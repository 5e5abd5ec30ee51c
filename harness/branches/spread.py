"""The branches of a scene at its first undecidable state (`harness branches`).

The reference runs the scene under the paper's rule; where it stops
`simultaneous_impact` (at t_u, contacts C touching) each branch runs the same scene
under another impact law: every law of the registry that resolves a simultaneous impact
(reference.core.laws: `moreau`, `sequential` with the fastest approach first, ...) and,
when at most three contacts touch, `sequential` in every order of C.  Up to t_u every branch
is the same exact run (the same compiled loop); after it they differ only by the law.
The contacts of the impact are those touching at t_u and those the laws gave impulses
there.
Per branch: the energy just after t_u, the next impacts, the final status, t_f and the
exponent c (reference.exponent, for runs that reach the singularity)."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from reference.core.laws import resolving_laws
from reference.core.tolerances import EPS, GAP_NOISE_ULPS, RATE_NOISE_ULPS
from reference.geometry import contact_kinematics
from reference.trajectory import Trajectory

# impacts after t_u listed per branch
NEXT_IMPACTS = 4
# orders of the sequential law are tried for at most this many touching contacts
MAX_ORDERED_CONTACTS = 3
# touching: gap within this many roundoff bands of the ground (the loop reaches a
# contact to a few ulps of |z| + a)
TOUCH_ULPS = 4 * GAP_NOISE_ULPS


@dataclass
class Branch:
    name: str  # "moreau", "sequential", "sequential[2,0,1]"
    law: str
    order: tuple[int, ...] | None
    status: str
    message: str
    t_final: float
    t_singularity: float | None
    energy_after: float | None  # excess energy just after t_u
    impacts_at: list[dict[str, Any]]  # the impact rows at t_u (one per contact)
    next_impacts: list[dict[str, Any]]  # the first impacts after t_u
    n_impacts: int
    c: float | None
    c_stderr: float | None
    energy_curve: tuple[np.ndarray, np.ndarray] = field(repr=False, default=None)  # t, E
    trajectory: Trajectory | None = field(repr=False, default=None)  # the whole run

    @property
    def t_f(self) -> float:
        return self.t_singularity if self.t_singularity is not None else self.t_final

    def to_dict(self) -> dict[str, Any]:
        return {
            "branch": self.name, "impact_law": self.law,
            "order": list(self.order) if self.order else None,
            "status": self.status, "message": self.message, "t_final": self.t_final,
            "t_singularity": self.t_singularity, "t_f": self.t_f,
            "energy_after": self.energy_after, "impacts_at_undecidable": self.impacts_at,
            "next_impacts": self.next_impacts, "n_impacts": self.n_impacts,
            "c": self.c, "c_stderr": self.c_stderr,
        }  # fmt: skip


@dataclass
class Spread:
    scene: str
    t_end: float
    undecidable: dict[str, Any] | None  # {"t", "contacts", "message"}; None: none reached
    paper: Branch
    branches: list[Branch]

    def to_dict(self) -> dict[str, Any]:
        return {
            "command": "branches",
            "scene": self.scene,
            "t_end": self.t_end,
            "undecidable": self.undecidable,
            "branches": [b.to_dict() for b in [self.paper, *self.branches]],
            "spread": spread_of(self.branches),
        }


def spread_of(branches: list[Branch]) -> dict[str, Any]:
    """Range over the branches of the energy after t_u, t_f and c."""

    def span(values):
        v = [x for x in values if x is not None and math.isfinite(x)]
        return {"min": min(v), "max": max(v)} if v else None

    return {
        "energy_after": span(b.energy_after for b in branches),
        "t_f": span(b.t_f for b in branches),
        "c": span(b.c for b in branches),
        "statuses": sorted({b.status for b in branches}),
    }


def touching_contacts(scene, y: np.ndarray, separating: bool = False) -> np.ndarray:
    """Contacts touching the ground at state y and not separating: gap ≤ TOUCH_ULPS ε
    (|z| + a), normal velocity ≤ its roundoff (the rule of the loop's simultaneous
    impacts, reference.core.law_event); `separating`: the touching ones that separate
    too (the laws that take them, `ImpactLaw.separating`)."""
    gap, vn = contact_kinematics(y, scene.contacts)
    gap, vn = gap[0], vn[0]
    a = scene.body.radius
    gap_tol = TOUCH_ULPS * EPS * (abs(y[2]) + a)
    v_scale = np.linalg.norm(y[7:10]) + a * np.linalg.norm(y[10:13])
    at_rest = vn <= RATE_NOISE_ULPS * EPS * v_scale
    return np.flatnonzero((gap <= gap_tol) & (at_rest | separating))


def ordered_runs(contacts: list[int]) -> list[tuple[str, str, tuple[int, ...]]]:
    """(name, law, order) of the sequential law in every order of the contacts (when at
    most MAX_ORDERED_CONTACTS of them, more than one)."""
    if not 1 < len(contacts) <= MAX_ORDERED_CONTACTS:
        return []
    return [
        (f"sequential[{','.join(map(str, order))}]", "sequential", order)
        for order in itertools.permutations(contacts)
    ]


def run_branch(scene, t_end, name, law, order, t_u) -> Branch:
    """One branch: the scene under `law` (and `order`), summarised after t_u."""
    from reference import ReferenceOptions, simulate

    traj = simulate(
        scene, t_end=t_end, options=ReferenceOptions(impact_law=law, sequential_order=order)
    )
    return summarise(traj, scene, name, law, order, t_u)


def summarise(traj, scene, name, law, order, t_u) -> Branch:
    """A run's branch record: what happened at and after t_u."""
    from reference.exponent import excess_energy_of, trajectory_exponent

    energy = excess_energy_of(traj, scene)
    t_imp = traj.impact_times()
    after = [e.to_dict() for e in traj.impacts if t_u is not None and e.t > t_u]
    at = [e.to_dict() for e in traj.impacts if t_u is not None and e.t == t_u]
    e_after = None
    if t_u is not None and traj.n_samples:
        i = int(np.searchsorted(traj.t, t_u, side="right"))
        e_after = float(energy[min(i, len(energy) - 1)]) if i < len(energy) else None
        if at and i > 0 and traj.t[i - 1] == t_u:  # the sample after the impact at t_u
            e_after = float(energy[i - 1])
    c = c_err = None
    if traj.status.value == "singularity" and len(t_imp) > 8:
        fit = trajectory_exponent(traj, energy=energy)
        c, c_err = fit.c, fit.c_stderr
    return Branch(
        name=name, law=law, order=order, status=traj.status.value, message=traj.message,
        t_final=traj.t_final, t_singularity=traj.t_singularity, energy_after=e_after,
        impacts_at=at, next_impacts=after[:NEXT_IMPACTS], n_impacts=len(traj.impacts),
        c=c, c_stderr=c_err, energy_curve=(traj.t.copy(), np.asarray(energy)), trajectory=traj,
    )  # fmt: skip


def branches(scene, t_end: float | None = None, progress=None) -> Spread:
    """The paper's run, its first undecidable state, and every branch from there."""
    from reference import simulate

    t_end = float(t_end if t_end is not None else scene.run.t_end)
    scene = scene.with_impact_law("paper")
    return branches_from(scene, t_end, simulate(scene, t_end=t_end), progress)


def branches_from(scene, t_end: float, paper_traj: Trajectory, progress=None) -> Spread:
    """Every branch from the first undecidable state of `paper_traj`, the scene's run
    under the paper's rule to `t_end` (made here by `branches`, by `harness compare`
    as its reference)."""
    scene = scene.with_impact_law("paper")
    undecidable = None
    t_u = None
    contacts: list[int] = []
    if paper_traj.status.value == "simultaneous_impact":
        t_u = paper_traj.t_final
        y = np.concatenate([paper_traj.position[-1], paper_traj.quaternion[-1],
                            paper_traj.velocity[-1], paper_traj.angular_velocity[-1]])  # fmt: skip
        contacts = touching_contacts(scene, y).tolist()
        undecidable = {"t": t_u, "contacts": contacts, "message": paper_traj.message}
    paper = summarise(paper_traj, scene, "paper", "paper", None, t_u)
    if undecidable is None:
        return Spread(scene.name, t_end, None, paper, [])
    out = []
    for law in resolving_laws():
        if progress:
            progress(f"branches: {law.name}")
        out.append(run_branch(scene, t_end, law.name, law.name, None, t_u))
    # the contacts of the impact: those touching, and those the laws gave impulses
    took = {r["contact"] for b in out for r in b.impacts_at}
    contacts = sorted(set(contacts) | took)
    undecidable["contacts"] = contacts
    for name, law, order in ordered_runs(contacts):
        if progress:
            progress(f"branches: {name}")
        out.append(run_branch(scene, t_end, name, law, order, t_u))
    return Spread(scene.name, t_end, undecidable, paper, out)
