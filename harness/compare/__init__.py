"""`harness compare`: the reference against named simulators on one scene.

The reference runs once; every other simulator runs at every timestep given (fixed-step
engines) or once (`reference`, `linear`: event-driven, dt does not apply).  Each run is
scored by `harness.metrics.evaluate`.  An engine that raises is recorded as a run with
status `failed` and the exception as its message, so one broken engine does not hide the
others' results; bad input (`SceneError`) still stops the command.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.scene import Scene, SceneError
from reference.trajectory import Status, Trajectory

from ..metrics import (
    RELATIVE_TIME_TOLERANCE,
    STEPS_TIME_TOLERANCE,
    RunMetrics,
    effective_restitution,
    evaluate,
)
from ..simulators import DEFAULT_DT, is_fixed_step, run_simulator
from ..text import table


@dataclass
class EngineRun:
    """One simulator run and its metrics against the reference."""

    engine: str
    dt: float | None
    trajectory: Trajectory
    wall_time_s: float
    metrics: RunMetrics

    def to_dict(self) -> dict[str, Any]:
        traj = self.trajectory
        doc: dict[str, Any] = {
            "engine": self.engine,
            "dt": self.dt,
            "status": traj.status.value,
            "message": traj.message,
            "wall_time_s": self.wall_time_s,
            "t_final": traj.t_final,
        }
        doc.update(self.metrics.to_dict())
        return doc


@dataclass
class CompareResult:
    scene: Scene
    reference: Trajectory
    reference_wall_time_s: float
    runs: list[EngineRun]

    def to_dict(self) -> dict[str, Any]:
        """The contract's `compare` document."""
        ref = self.reference.summary(with_impacts=False)
        ref["wall_time_s"] = self.reference_wall_time_s
        r = effective_restitution(self.reference, self.scene.gravity)
        ref["effective_restitution"] = r.median
        return {
            "scene": self.scene.name,
            "restitution": self.scene.restitution,
            "reference": ref,
            "engines": [run.to_dict() for run in self.runs],
        }


def compare(
    scene: Scene,
    engines: list[str],
    dts: list[float] | None = None,
    t_end: float | None = None,
    progress: Callable[[str], None] | None = None,
    max_steps: int | None = None,
) -> CompareResult:
    """Run the reference once and each engine at each dt (DEFAULT_DT when `dts` is None;
    once for `reference` and `linear`), all to the same t_end, and score every run.
    `progress` gets one line per run with its wall time (for stderr).  An engine run
    stopped by Ctrl-C stops the comparison (KeyboardInterrupt)."""
    say = progress or (lambda _msg: None)
    dts = list(dts) if dts else [DEFAULT_DT]
    reference, ref_wall = _timed_run("reference", scene, None, t_end, reraise=True)
    say(_progress_line("reference", None, reference, ref_wall))
    runs: list[EngineRun] = []
    for engine in engines:
        for dt in dts if is_fixed_step(engine) else [None]:
            if engine == "reference":
                traj, wall = reference, ref_wall
            else:
                traj, wall = _timed_run(engine, scene, dt, t_end, max_steps=max_steps)
                say(_progress_line(engine, dt, traj, wall))
            metrics = evaluate(traj, reference, scene.gravity)
            runs.append(EngineRun(engine, dt, traj, wall, metrics))
    return CompareResult(scene, reference, ref_wall, runs)


def _timed_run(
    engine: str,
    scene: Scene,
    dt: float | None,
    t_end: float | None,
    reraise: bool = False,
    max_steps: int | None = None,
) -> tuple[Trajectory, float]:
    start = time.perf_counter()
    try:
        traj = run_simulator(engine, scene, dt=dt, t_end=t_end, max_steps=max_steps)
        if traj.stats.get("interrupted"):
            raise KeyboardInterrupt
    except SceneError:
        raise
    except Exception as exc:  # an engine that breaks is a result, not a crash
        if reraise:
            raise
        traj = Trajectory.failed(engine, scene.name, dt, f"{type(exc).__name__}: {exc}")
    return traj, time.perf_counter() - start


def _progress_line(engine: str, dt: float | None, traj: Trajectory, wall: float) -> str:
    label = engine if dt is None else f"{engine} dt={dt:g}"
    text = f"compare: {label}: {traj.status.value}, {len(traj.impacts)} impacts, "
    text += f"t_final={traj.t_final:.6g} ({wall:.2f} s)"
    if traj.status is Status.FAILED and traj.message:
        text += f": {traj.message}"
    return text


# ----------------------------------------------------------------------------- text


def _num(x: float | None, fmt: str = ".2e") -> str:
    return "-" if x is None or not np.isfinite(x) else format(x, fmt)


def format_compare(result: CompareResult) -> str:
    """A readable table: one row per run, then the rules behind the columns."""
    ref = result.reference
    scene = result.scene
    lines = [
        f"scene      {scene.name}  (n={scene.body.n}, {scene.ground.kind}, "
        f"gamma={scene.restitution:g})",
        f"reference  {ref.status.value}: t_final={ref.t_final:.6g}, "
        f"{len(ref.impacts)} impacts, {result.reference_wall_time_s:.2f} s"
        + (f", t_sing={ref.t_singularity:.10g}" if ref.t_singularity is not None else ""),
        "",
    ]
    header = [
        "engine",
        "dt",
        "status",
        "wall[s]",
        "impacts",
        "matched",
        "tails",
        "t_err[s]",
        "E_err",
        "E_err<div",
        "att_err[rad]",
        "att<div",
        "diverge[s]",
        "e_eff",
    ]
    rows = []
    for run in result.runs:
        m = run.metrics
        r = m.restitution
        e_eff = "-" if r.median is None else f"{r.median:.4f} (n={r.n})"
        rows.append(
            [
                run.engine,
                "-" if run.dt is None else f"{run.dt:g}",
                run.trajectory.status.value,
                f"{run.wall_time_s:.2f}",
                str(m.impacts),
                f"{m.impacts_matched}/{m.reference_impacts}",
                f"{m.skipped_reference}/{m.skipped_run}",
                _num(m.impact_time_error),
                _num(m.energy_error),
                _num(m.energy_error_agreeing),
                _num(m.attitude_error),
                _num(m.attitude_error_agreeing),
                _num(m.first_divergence_time, ".4g"),
                e_eff,
            ]
        )
    lines.append(table(rows, header))
    lines += [
        "",
        f"matched: leading impacts with the reference's contact and time, |dt| <= "
        f"{STEPS_TIME_TOLERANCE:g} steps (1e-9 s event-driven) + "
        f"{RELATIVE_TIME_TOLERANCE:g}*t, capped at half the gap to the next same-contact "
        "reference impact; of the reference impacts in the common window",
        "tails: chatter-tail impacts skipped (reference/run): approach slower than "
        "max(10 g dt, 1% of the fastest), at a contact already in the chatter episode",
        "E_err: max |E - E_ref|/E_ref(0) away from impacts; att_err: max attitude angle; "
        "<div: the same before the first divergence",
        "diverge: first impact mismatch or attitude error > 0.1 x max reference tilt; "
        "e_eff: median -v_post/v_pre of the run's impacts approaching faster than "
        "max(10 g dt, 1% of the fastest)",
    ]
    for run in result.runs:
        m = run.metrics
        label = run.engine if run.dt is None else f"{run.engine} dt={run.dt:g}"
        if m.divergence_reason:
            lines.append(f"  {label}: {m.divergence_reason}")
        if run.trajectory.status is Status.FAILED and run.trajectory.message:
            lines.append(f"  {label}: failed: {run.trajectory.message}")
    return "\n".join(lines)
