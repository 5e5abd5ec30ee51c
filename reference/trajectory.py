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

from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np

from . import quaternion as qt
from .core import layout as L


class Status(StrEnum):
    T_END = "t_end"  # reached the requested end time
    SINGULARITY = "singularity"  # all contacts down: energy exhausted (t_singularity set)
    SIMULTANEOUS_IMPACT = "simultaneous_impact"  # undecidable in this model: stopped
    MAX_IMPACTS = "max_impacts"  # impact budget exhausted
    LEFT_MODEL = "left_model"  # the motion left the model (three_point: off the bumps)
    FAILED = "failed"  # the simulator broke (NaN, solver failure, ...)
    STALLED = "stalled"  # the run stopped advancing (the reference's progress check)


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
    impacts: Sequence[ImpactEvent]  # a list or an ImpactLog
    status: Status
    message: str = ""
    t_final: float = 0.0
    t_singularity: float | None = None
    phases: Sequence[Phase] = field(default_factory=list)  # a list or a PhaseLog
    stats: Mapping[str, Any] = field(default_factory=dict)  # a dict, or RunStats
    t_lo: np.ndarray | None = None
    dt: float | None = None  # fixed timestep of an engine run, None for event-driven
    # the impact law of simultaneous impacts and its simultaneity window, for simulators
    # that apply one (the reference, the linear model); None for the others
    impact_law: str | None = None
    simultaneity_window: float | None = None

    @classmethod
    def failed(cls, engine: str, scene: str, dt: float | None, message: str) -> Trajectory:
        """An empty run with status `failed`: what a simulator that raised produced."""
        empty = np.zeros(0)
        return cls.from_states(
            engine, scene, empty, np.zeros((0, 13)), empty, empty, [], Status.FAILED,
            message=message, dt=dt,
        )  # fmt: skip

    @classmethod
    def from_states(
        cls,
        engine: str,
        scene: str,
        t: np.ndarray,
        states: np.ndarray,
        kinetic_energy: np.ndarray,
        potential_energy: np.ndarray,
        impacts: Sequence[ImpactEvent],
        status: Status,
        **fields: Any,
    ) -> Trajectory:
        """A Trajectory from rows of the 13-component state (x, q wxyz, v, ω) at times
        t; `fields` are the other attributes (message, t_final, phases, stats, …)."""
        S = np.asarray(states, dtype=float).reshape(-1, 13)
        return cls(
            engine=engine,
            scene=scene,
            t=np.asarray(t, dtype=float),
            position=S[:, L.POSITION],
            quaternion=S[:, L.QUATERNION],
            velocity=S[:, L.VELOCITY],
            angular_velocity=S[:, L.ANGULAR_VELOCITY],
            kinetic_energy=np.asarray(kinetic_energy, dtype=float),
            potential_energy=np.asarray(potential_energy, dtype=float),
            impacts=impacts,
            status=status,
            **fields,
        )

    @property
    def wall_time_s(self) -> float | None:
        """Run time of the simulation itself (no one-time compilation or loading)."""
        w = self.stats.get("wall_time_s")
        return None if w is None else float(w)

    @property
    def compile_s(self) -> float:
        """One-time compilation or loading of compiled code before this run (0 if warm)."""
        return float(self.stats.get("compile_s") or 0.0)

    @property
    def energy(self) -> np.ndarray:
        return self.kinetic_energy + self.potential_energy

    @property
    def inclination(self) -> np.ndarray:
        """α(t): angle between the body axis and the vertical."""
        return np.atleast_1d(qt.inclination(self.quaternion)) if self.n_samples else np.zeros(0)

    @property
    def n_samples(self) -> int:
        return len(self.t)

    def impact_column(self, name: str) -> np.ndarray:
        """One field of every impact (ImpactLog.COLUMNS: t, t_lo, contact, impulse,
        v_normal_pre, v_normal_post) as an array, read from the log's rows when the
        impacts are an ImpactLog (no ImpactEvent objects made)."""
        if isinstance(self.impacts, ImpactLog):
            return self.impacts.column(name)
        dtype = int if name == "contact" else float
        return np.array([getattr(e, name) for e in self.impacts], dtype=dtype)

    def impact_times(self) -> np.ndarray:
        return self.impact_column("t")

    def impact_contacts(self) -> np.ndarray:
        return self.impact_column("contact")

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
            "stats": _jsonable(
                self.stats.to_dict() if hasattr(self.stats, "to_dict") else dict(self.stats)
            ),
        }
        if self.dt is not None:
            doc["dt"] = self.dt
        if self.impact_law is not None:
            doc["impact_law"] = self.impact_law
            doc["simultaneity_window"] = self.simultaneity_window
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


class ImpactLog(Sequence[ImpactEvent]):
    """The impacts of a run as columns (t, t_lo, contact, impulse, v_normal_pre,
    v_normal_post) in one growing array: the compiled loop appends thousands of rows at
    once without creating Python objects.  Reads as a sequence of `ImpactEvent`
    (built on access), so it stands wherever a list of events does."""

    COLUMNS = ("t", "t_lo", "contact", "impulse", "v_normal_pre", "v_normal_post")

    def __init__(self, events: Iterable[ImpactEvent] = ()) -> None:
        self._rows = np.empty((256, 6))
        self._n = 0
        for e in events:
            self.append(e)

    def __len__(self) -> int:
        return self._n

    def _reserve(self, k: int) -> None:
        need = self._n + k
        if need > len(self._rows):
            new = np.empty((max(need, 2 * len(self._rows)), 6))
            new[: self._n] = self._rows[: self._n]
            self._rows = new

    def append(self, e: ImpactEvent) -> None:
        self._reserve(1)
        self._rows[self._n] = (
            e.t,
            e.t_lo,
            e.contact,
            e.impulse,
            e.v_normal_pre,
            e.v_normal_post,
        )
        self._n += 1

    @classmethod
    def from_rows(cls, rows: np.ndarray) -> ImpactLog:
        """A log holding rows laid out as COLUMNS (copied)."""
        log = cls()
        log.extend_rows(np.asarray(rows, dtype=float).reshape(-1, 6))
        return log

    def extend_rows(self, rows: np.ndarray) -> None:
        """Append rows laid out as COLUMNS."""
        k = len(rows)
        self._reserve(k)
        self._rows[self._n : self._n + k] = rows
        self._n += k

    def column(self, name: str) -> np.ndarray:
        """One column as a new array (contact as int)."""
        col = self._rows[: self._n, self.COLUMNS.index(name)].copy()
        return col.astype(int) if name == "contact" else col

    @staticmethod
    def _event(r: np.ndarray) -> ImpactEvent:
        return ImpactEvent(
            t=float(r[0]),
            t_lo=float(r[1]),
            contact=int(r[2]),
            impulse=float(r[3]),
            v_normal_pre=float(r[4]),
            v_normal_post=float(r[5]),
        )

    def __getitem__(self, i):  # type: ignore[override]
        if isinstance(i, slice):
            return [self._event(r) for r in self._rows[: self._n][i]]
        if i < 0:
            i += self._n
        if not 0 <= i < self._n:
            raise IndexError("impact index out of range")
        return self._event(self._rows[i])

    def __iter__(self) -> Iterator[ImpactEvent]:
        for r in self._rows[: self._n]:
            yield self._event(r)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Sequence):
            return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))
        return NotImplemented

    def __repr__(self) -> str:
        return f"ImpactLog({self._n} impacts)"


class PhaseLog(Sequence[Phase]):
    """Phases as rows (t_start, t_end, kind, contact0, contact1, contact2) with kind
    0 = flight, 1 = contact and −1 padding, read as a sequence of `Phase`."""

    KINDS = ("flight", "contact")

    def __init__(self, rows: np.ndarray) -> None:
        self._rows = np.asarray(rows, dtype=float).reshape(-1, 6).copy()

    def __len__(self) -> int:
        return len(self._rows)

    def _phase(self, r: np.ndarray) -> Phase:
        contacts = tuple(int(c) for c in r[3:6] if c >= 0)
        return Phase(float(r[0]), float(r[1]), self.KINDS[int(r[2])], contacts)

    def __getitem__(self, i):  # type: ignore[override]
        if isinstance(i, slice):
            return [self._phase(r) for r in self._rows[i]]
        return self._phase(self._rows[i])

    def __iter__(self) -> Iterator[Phase]:
        for r in self._rows:
            yield self._phase(r)

    def __repr__(self) -> str:
        return f"PhaseLog({len(self)} phases)"
