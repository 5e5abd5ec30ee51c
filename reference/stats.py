"""`RunStats`: what a run of the exact reference counted, typed, with its JSON form.

It also reads as a mapping (field name → value), like the `stats` dict of the other
simulators, so generic code can use `traj.stats.get("wall_time_s")`."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np


@dataclass(frozen=True)
class RunStats(Mapping):
    """Counters and timings of one reference run.

    wall_time_s: the run itself, without one-time compilation or loading (compile_s);
    impacts_per_s = n_impacts / wall_time_s; search_iterations_per_impact: event-search
    steps per impact (the cost of the conservative advancement); simultaneous_impacts:
    the simultaneous impacts the run's impact law resolved inside the compiled loop (0
    under `paper`, whose rule ends the run there)."""

    wall_time_s: float
    compile_s: float
    n_impacts: int
    impacts_per_s: float
    flight_searches: int
    search_iterations: int
    search_iterations_per_impact: float
    contact_phases: int
    contact_chunks: int
    contact_rhs_evals: int
    chatter_completions: int
    max_completion_u_rel: float
    chatter_accumulation_times: tuple[float, ...]
    activations: int
    lift_offs: int
    horizon_backstops: int
    contact_energy_drift_max: float
    max_penetration: float
    loop_steps: int
    simultaneous_impacts: int
    samples: int

    @classmethod
    def from_counters(
        cls, counters: np.void, wall: float, compile_s: float, n_impacts: int, **extra: Any
    ) -> RunStats:
        """From the core's counter record (reference.core.records.STATS)."""
        c = dict(zip(counters.dtype.names, counters.item(), strict=True))
        iters = int(c["search_iterations"])
        return cls(
            wall_time_s=wall,
            compile_s=compile_s,
            n_impacts=n_impacts,
            impacts_per_s=n_impacts / wall if wall > 0 and n_impacts else 0.0,
            search_iterations_per_impact=iters / n_impacts if n_impacts else 0.0,
            **{k: v for k, v in c.items()},
            **extra,
        )

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["chatter_accumulation_times"] = list(self.chatter_accumulation_times)
        return d

    def __getitem__(self, key: str) -> Any:
        if key not in self._names():
            raise KeyError(key)
        return getattr(self, key)

    def __iter__(self) -> Iterator[str]:
        return iter(self._names())

    def __len__(self) -> int:
        return len(self._names())

    @classmethod
    def _names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))
