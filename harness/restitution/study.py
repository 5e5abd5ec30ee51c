"""The restitution study: every engine on every cell of a grid of requested γ, impact
speeds (in √(g a)), timesteps, onset phases and geometries (`drops`), each a single
impact read by `impact.read_impact`, and each engine's contract: the speeds and
timesteps where |e_eff/γ − 1| ≤ FAITHFUL (1 %) for every γ and phase.

The onset phase is where in a step the contact begins: the watched contact starts
phase·dt·u⁻ above the ground.  Real impacts come at every phase; a compliant contact's
bounce depends on it (Drake's SAP: ±8 % at γ = 0.3 between phases 0.05 and 0.95, its
mapping is exact at 0.5), so the default grid takes three (DEFAULT_PHASES).

A fixed-step engine runs a cell for LEAD_STEPS + CONTACT_STEPS steps first; when its
contact has not ended by then the cell is run again CONTACT_GROWTH times longer (soft
contacts last hundreds of steps: Drake's SAP contact at γ = 0.95 lasts ~400), up to
MAX_CONTACT_TIME, and a contact point that has come to rest (|u| < RESTING·|u⁻| over
its last RESTING_ROWS rows) is not waited for.  An event-driven engine (the reference)
runs each (geometry, γ, speed) once: its dt column is None."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from reference.trajectory import Trajectory

from ..simulators import is_fixed_step, offers_batch, run_batch, run_simulator
from .drops import GEOMETRIES, LEAD_STEPS, drop_scene, watched_point
from .impact import ImpactReading, read_impact, relative_error, trajectory_states

FAITHFUL = 0.01
DEFAULT_GAMMAS = (0.3, 0.5, 0.8, 0.95)
DEFAULT_SPEEDS = (1e-3, 1e-2, 1e-1, 1.0)
DEFAULT_DTS = (1e-3, 1e-4)
DEFAULT_PHASES = (0.1, LEAD_STEPS, 0.9)
CONTACT_STEPS = 40
CONTACT_GROWTH = 8
MAX_CONTACT_TIME = 0.5
RESTING = 1e-3
RESTING_ROWS = 10
# An event-driven model that stops at a simultaneous impact (the reference at the edge:
# undecidable in its model) has no e_eff there; such cells are left out of the contract.
UNDECIDABLE = "run simultaneous_impact"
# The event-driven reference has no step: its watched contact starts this far (in time
# at the impact speed) above the ground, and the run ends this long after.
EVENT_LEAD = 1e-4
EVENT_AFTER = 1e-2


@dataclass(frozen=True)
class Grid:
    gammas: tuple[float, ...] = DEFAULT_GAMMAS
    speeds: tuple[float, ...] = DEFAULT_SPEEDS
    dts: tuple[float, ...] = DEFAULT_DTS
    geometries: tuple[str, ...] = GEOMETRIES
    phases: tuple[float, ...] = DEFAULT_PHASES

    def cells(self, fixed_step: bool) -> list[tuple]:
        """(geometry, dt, phase, γ, speed) of one engine (dt and phase None for
        event-driven ones)."""
        dts = self.dts if fixed_step else (None,)
        phases = self.phases if fixed_step else (None,)
        return [
            (geo, dt, phase, g, v)
            for geo in self.geometries
            for dt in dts
            for phase in phases
            for g in self.gammas
            for v in self.speeds
        ]

    def to_dict(self) -> dict:
        return {
            "gamma": list(self.gammas),
            "speed": list(self.speeds),
            "dt": list(self.dts),
            "geometry": list(self.geometries),
            "phase": list(self.phases),
        }


def measure_cell(
    engine: str,
    geometry: str,
    dt: float | None,
    gamma: float,
    speed: float,
    phase: float | None = LEAD_STEPS,
    first: Trajectory | None = None,
) -> tuple[ImpactReading, dict]:
    """One cell: the impact reading and the run's facts (steps, wall time, mapping).
    `first`: the first attempt's run when a batch already made it (`first_attempts`)."""
    points, flat = watched_point(geometry)
    if dt is None:
        scene = drop_scene(geometry, gamma, speed, EVENT_LEAD, EVENT_LEAD + EVENT_AFTER)
        traj = run_simulator(engine, scene, None)
        return read_impact(scene, traj, points, flat), _facts(traj, 1)
    lead = (LEAD_STEPS if phase is None else phase) * dt
    steps = CONTACT_STEPS
    attempt = 0
    while True:
        attempt += 1
        t_end = lead + steps * dt
        scene = drop_scene(geometry, gamma, speed, lead, t_end)
        if attempt == 1 and first is not None:
            traj = first
        else:
            traj = run_simulator(engine, scene, dt)
        reading = read_impact(scene, traj, points, flat)
        if reading.outcome != "no separation" or t_end >= MAX_CONTACT_TIME:
            break
        if _resting(traj, points, flat, reading.u_pre):
            break
        steps = min(steps * CONTACT_GROWTH, int(np.ceil(MAX_CONTACT_TIME / dt)))
    return reading, _facts(traj, attempt)


def first_attempts(engine: str, cells: list[tuple]) -> dict[tuple, Trajectory]:
    """The first attempt of every fixed-step cell, run as batches (one per dt and onset
    phase: one t_end) when the engine offers `simulate_batch`; {} otherwise.  Each run is
    the one `measure_cell` would make for the cell's first attempt."""
    if not offers_batch(engine):
        return {}
    groups: dict[tuple, list[tuple]] = {}
    for cell in cells:
        geometry, dt, phase, gamma, speed = cell
        if dt is not None:
            groups.setdefault((dt, phase), []).append(cell)
    out: dict[tuple, Trajectory] = {}
    for (dt, phase), group in groups.items():
        lead = (LEAD_STEPS if phase is None else phase) * dt
        t_end = lead + CONTACT_STEPS * dt
        scenes = [drop_scene(g, gm, v, lead, t_end) for g, _, _, gm, v in group]
        out.update(zip(group, run_batch(engine, scenes, dt, t_end), strict=True))
    return out


def _resting(traj, points, flat, u_pre) -> bool:
    """The watched point no longer moves (its last RESTING_ROWS rows)."""
    from reference.geometry import contact_kinematics

    from .impact import watched_contact

    states = trajectory_states(traj)[-RESTING_ROWS:]
    un = contact_kinematics(states, watched_contact(points, flat))[1][:, 0]
    return bool(np.max(np.abs(un)) < RESTING * abs(u_pre))


def _facts(traj, attempts: int) -> dict:
    stats = traj.stats if isinstance(traj.stats, dict) else {}
    return {
        "status": traj.status.value,
        "attempts": attempts,
        "steps": stats.get("steps"),
        "mapping": stats.get("restitution_model"),
    }


def run_study(
    engines: Sequence[str],
    grid: Grid,
    progress: Callable[[str], None] | None = None,
    tick: Callable[[int], None] | None = None,
    now: Callable[[str], None] | None = None,
) -> dict:
    """Every engine on every cell: {"engines": [{engine, fixed_step, rows, contract,
    mapping, wall_time_s}]}.  `tick(1)` after each cell; `now(engine)` when an engine
    starts (the progress line's "now")."""
    out = []
    for engine in engines:
        if now is not None:
            now(engine)
        fixed = is_fixed_step(engine)
        t0 = time.perf_counter()
        rows = []
        cells = grid.cells(fixed)
        batched = first_attempts(engine, cells) if fixed else {}
        for cell in cells:
            geometry, dt, phase, gamma, speed = cell
            first = batched.get(cell)
            reading, facts = measure_cell(engine, geometry, dt, gamma, speed, phase, first)
            rows.append(_row(geometry, dt, phase, gamma, speed, reading, facts))
            if tick is not None:
                tick(1)
        wall = time.perf_counter() - t0
        if progress is not None:
            progress(f"{engine}: {len(rows)} impacts in {wall:.1f} s")
        out.append(
            {
                "engine": engine,
                "fixed_step": fixed,
                "mapping": engine_mapping(engine, rows, grid),
                "rows": rows,
                "contract": contract(rows, grid, fixed),
                "wall_time_s": wall,
            }
        )
    return {"kind": "restitution", "faithful": FAITHFUL, "grid": grid.to_dict(), "engines": out}


def _row(geometry, dt, phase, gamma, speed, reading: ImpactReading, facts: dict) -> dict:
    r = reading.to_dict()
    err = relative_error(reading.e_eff, gamma)
    energy_error = None
    if reading.energy_change is not None and reading.energy_loss_exact:
        energy_error = -reading.energy_change / reading.energy_loss_exact - 1.0
    return {
        "geometry": geometry,
        "dt": dt,
        "phase": phase,
        "gamma": gamma,
        "speed": speed,
        **r,
        "e_error": err,
        "faithful": bool(err is not None and reading.outcome == "ok" and abs(err) <= FAITHFUL),
        "applicable": not reading.outcome.startswith(UNDECIDABLE),
        "energy_loss_error": energy_error,
        **facts,
    }


def engine_mapping(engine: str, rows: list[dict], grid: Grid) -> str:
    """How the engine's adapter maps γ, as its runs report it (stats' restitution_model
    at the middle γ), else the entry point's own description."""
    from ..simulators import load_engine

    mid = grid.gammas[len(grid.gammas) // 2]
    for r in rows:
        if r["gamma"] == mid and r.get("mapping"):
            return f"{r['mapping']} (at gamma = {mid:g})"
    doc = (load_engine(engine).__doc__ or "").strip().splitlines()
    return doc[0] if doc else "not reported by the adapter"


def contract(rows: list[dict], grid: Grid, fixed_step: bool) -> list[dict]:
    """Per dt (None: event-driven) and geometry: the speeds where every γ and phase is
    faithful,
    and the widest run of consecutive grid speeds among them ([lo, hi], None if none)."""
    out = []
    for dt in grid.dts if fixed_step else (None,):
        for geometry in (*grid.geometries, "all"):
            ok = []
            for v in grid.speeds:
                cell = [
                    r
                    for r in rows
                    if r["dt"] == dt
                    and r["speed"] == v
                    and geometry in ("all", r["geometry"])
                    and r["applicable"]
                ]
                ok.append(bool(cell) and all(r["faithful"] for r in cell))
            out.append(
                {
                    "dt": dt,
                    "geometry": geometry,
                    "faithful_speeds": [v for v, good in zip(grid.speeds, ok, strict=True) if good],
                    "range": _widest_run(grid.speeds, ok),
                }
            )
    return out


def worst_row(rows: list[dict]) -> dict | None:
    """The row that says least for the engine among one cell's phases: one that did not
    end in a bounce, else the largest |e_eff/γ − 1|."""
    if not rows:
        return None
    bad = [r for r in rows if r["outcome"] != "ok" or r["e_error"] is None]
    if bad:
        return bad[0]
    return max(rows, key=lambda r: abs(r["e_error"]))


def _widest_run(speeds: Sequence[float], ok: Sequence[bool]) -> list[float] | None:
    order = np.argsort(speeds)
    best: tuple[int, int] | None = None
    start = None
    for pos, i in enumerate([*order, None]):
        good = i is not None and ok[i]
        if good and start is None:
            start = pos
        if not good and start is not None:
            if best is None or pos - start > best[1] - best[0]:
                best = (start, pos)
            start = None
    if best is None:
        return None
    return [float(speeds[order[best[0]]]), float(speeds[order[best[1] - 1]])]
