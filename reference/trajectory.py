"""`Trajectory`: the one result type every simulator returns (reference, linear, engines).

Conventions (shared by every simulator):
- time t in seconds from the scene's start; `t_lo` is the low part of a double-double
  time where a simulator keeps one (the reference does), so that t_f − t is exact near
  the singularity;
- position: centre of mass, world frame; quaternion (w, x, y, z), body → world;
- velocity: centre of mass; angular velocity ω in the world frame;
- energy = kinetic + potential (m g z), zero when the body lies flat on the ground.

Impacts carry the contact index (vertex k on flat ground, bump k on three_point), the
normal impulse and the pre/post normal velocities of the contact point.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np

from . import quaternion as qt


class Status(StrEnum):
    T_END = "t_end"  # reached the requested end time
    SINGULARITY = "singularity"  # all contacts down: energy exhausted (t_singularity set)
    SIMULTANEOUS_IMPACT = "simultaneous_impact"  # undecidable in this model: stopped
    MAX_IMPACTS = "max_impacts"  # impact budget exhausted
    FAILED = "failed"  # the simulator broke (NaN, solver failure, ...)


@dataclass(frozen=True)
class ImpactEvent:
    t: float
    contact: int
    impulse: float
    v_normal_pre: float
    v_normal_post: float
    t_lo: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return {
            "t": self.t,
            "contact": self.contact,
            "impulse": self.impulse,
            "v_normal_pre": self.v_normal_pre,
            "v_normal_post": self.v_normal_post,
        }


@dataclass(frozen=True)
class Phase:
    """A stretch of motion between events: `flight` or `contact` (with the contacts held)."""

    t_start: float
    t_end: float
    kind: str
    contacts: tuple[int, ...] = ()


@dataclass
class Trajectory:
    engine: str
    scene: str
    t: np.ndarray
    position: np.ndarray
    quaternion: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    kinetic_energy: np.ndarray
    potential_energy: np.ndarray
    impacts: list[ImpactEvent]
    status: Status
    message: str = ""
    t_final: float = 0.0
    t_singularity: float | None = None
    phases: list[Phase] = field(default_factory=list)
    stats: dict[str, Any] = field(default_factory=dict)
    t_lo: np.ndarray | None = None
    dt: float | None = None  # fixed timestep of an engine run, None for event-driven

    @classmethod
    def failed(cls, engine: str, scene: str, dt: float | None, message: str) -> Trajectory:
        """An empty run with status `failed`: what a simulator that raised produced."""
        empty3 = np.zeros((0, 3))
        return cls(
            engine=engine,
            scene=scene,
            t=np.zeros(0),
            position=empty3,
            quaternion=np.zeros((0, 4)),
            velocity=empty3,
            angular_velocity=empty3,
            kinetic_energy=np.zeros(0),
            potential_energy=np.zeros(0),
            impacts=[],
            status=Status.FAILED,
            message=message,
            dt=dt,
        )

    @property
    def energy(self) -> np.ndarray:
        return self.kinetic_energy + self.potential_energy

    @property
    def inclination(self) -> np.ndarray:
        """α(t): angle between the body axis and the vertical."""
        return np.array([qt.inclination(q) for q in self.quaternion])

    @property
    def n_samples(self) -> int:
        return len(self.t)

    def impact_times(self) -> np.ndarray:
        return np.array([e.t for e in self.impacts])

    def impact_contacts(self) -> np.ndarray:
        return np.array([e.contact for e in self.impacts], dtype=int)

    def final_state(self) -> dict[str, list[float]]:
        return {
            "position": self.position[-1].tolist(),
            "quaternion_wxyz": self.quaternion[-1].tolist(),
            "velocity": self.velocity[-1].tolist(),
            "angular_velocity": self.angular_velocity[-1].tolist(),
        }

    def summary(self, with_impacts: bool = True) -> dict[str, Any]:
        """The contract's `simulate` JSON document."""
        doc: dict[str, Any] = {
            "engine": self.engine,
            "scene": self.scene,
            "status": self.status.value,
            "message": self.message,
            "t_final": self.t_final,
            "t_singularity": self.t_singularity,
            "n_impacts": len(self.impacts),
            "energy": {
                "initial": float(self.energy[0]) if self.n_samples else None,
                "final": float(self.energy[-1]) if self.n_samples else None,
            },
            "final_state": self.final_state() if self.n_samples else None,
            "stats": _jsonable(self.stats),
        }
        if self.dt is not None:
            doc["dt"] = self.dt
        if with_impacts:
            doc["impacts"] = [e.to_dict() for e in self.impacts]
        return doc


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


class SampleBuffer:
    """Accumulates samples of a run, then freezes them into a Trajectory's arrays."""

    def __init__(self) -> None:
        self.rows: list[np.ndarray] = []
        self.t_hi: list[float] = []
        self.t_lo: list[float] = []
        self.ke: list[float] = []
        self.pe: list[float] = []

    def add(self, t_hi: float, t_lo: float, y: np.ndarray, ke: float, pe: float) -> None:
        self.t_hi.append(t_hi)
        self.t_lo.append(t_lo)
        self.rows.append(np.array(y, dtype=float))
        self.ke.append(ke)
        self.pe.append(pe)

    def arrays(self) -> dict[str, np.ndarray]:
        Y = np.array(self.rows).reshape(-1, 13)
        return {
            "t": np.array(self.t_hi),
            "t_lo": np.array(self.t_lo),
            "position": Y[:, 0:3],
            "quaternion": Y[:, 3:7],
            "velocity": Y[:, 7:10],
            "angular_velocity": Y[:, 10:13],
            "kinetic_energy": np.array(self.ke),
            "potential_energy": np.array(self.pe),
        }
