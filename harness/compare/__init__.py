"""`harness compare`: the reference against named simulators on one scene.

The reference runs once; every other simulator runs at every timestep given (fixed-step
engines) or once (`reference`, `linear`: event-driven, dt does not apply).  Each run is
scored by `harness.metrics.evaluate`, and gets an energy exponent c only if it reached
the end of the motion (`harness.metrics.run_exponent`).  An engine that raises is
recorded as a run with status `failed` and the exception as its message, so one broken
engine (a plug-in raising SceneError for a scene it does not take included) does not
hide the others' results; bad input is refused before any run (harness.simulators.
check_run).

When the reference ends `simultaneous_impact` (the paper's rule at an undecidable state,
t_u), the scene is continued from there under every impact law (harness.branches.spread)
and each run gets the branch it follows after t_u and how far it stays with it
(harness.branches.follow); otherwise `branch` is None.

Text output: `text.format_compare` (100 columns, one verdict line per run; `wide=True`
for every column); the impact-by-impact diff: `diff.impact_diff` (`--out`).  The columns
are defined in docs/output.md.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from reference.exponent import ExponentFit
from reference.scene import Scene
from reference.scenes import as_scene
from reference.trajectory import Status, Trajectory

from ..branches.follow import BranchFollow, follow_branches
from ..branches.spread import Spread, branches_from
from ..horizon.settings import DEFAULT_SEED
from ..horizon.verdict import Horizon, engine_horizon, planned_members, scene_horizon
from ..metrics import RunMetrics, effective_restitution, evaluate, run_exponent
from ..progress import progress_bar
from ..simulators import DEFAULT_DT, is_fixed_step, run_simulator, warm_up
from ..text import run_label


@dataclass
class EngineRun:
    """One simulator run, its metrics against the reference and its exponent."""

    engine: str
    dt: float | None
    trajectory: Trajectory
    wall_time_s: float
    metrics: RunMetrics
    exponent: ExponentFit
    horizon: Horizon | None = None
    branch: BranchFollow | None = None

    @property
    def label(self) -> str:
        """'mujoco 1e-04' for fixed-step runs, the engine name otherwise."""
        return run_label(self.engine, self.dt)

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
        doc["exponent"] = self.exponent.to_dict()
        doc["horizon"] = None if self.horizon is None else self.horizon.to_dict()
        doc["branch"] = None if self.branch is None else self.branch.to_dict()
        return doc


@dataclass
class CompareResult:
    scene: Scene
    reference: Trajectory
    reference_wall_time_s: float
    runs: list[EngineRun]
    reference_exponent: ExponentFit | None = None
    spread: Spread | None = None  # the branches at the reference's undecidable state

    def first_to_diverge(self) -> EngineRun | None:
        """The run whose first divergence from the reference comes earliest (None if
        no run diverges)."""
        diverged = [r for r in self.runs if r.metrics.first_divergence_time is not None]
        return min(diverged, key=lambda r: r.metrics.first_divergence_time, default=None)

    def to_dict(self) -> dict[str, Any]:
        """The contract's `compare` document, plus the exponents and the verdicts."""
        from .branch_text import branch_sentence
        from .text import divergence_sentence, horizon_sentence, verdict_line

        ref = self.reference.summary(with_impacts=False)
        ref["wall_time_s"] = self.reference_wall_time_s
        r = effective_restitution(self.reference, self.scene.gravity)
        ref["effective_restitution"] = r.median
        if self.reference_exponent is not None:
            ref["exponent"] = self.reference_exponent.to_dict()
        first = self.first_to_diverge()
        engines = []
        for run in self.runs:
            row = run.to_dict()
            row["verdict"] = verdict_line(run, self.scene)
            if row["horizon"] is not None:
                row["horizon"]["sentence"] = horizon_sentence(run)
            if row["branch"] is not None:
                row["branch"]["sentence"] = branch_sentence(run)
            engines.append(row)
        return {
            "kind": "compare",
            "scene": self.scene.name,
            "restitution": self.scene.restitution,
            "impact_law": self.reference.impact_law,
            "simultaneity_window": self.reference.simultaneity_window,
            "reference": ref,
            "engines": engines,
            "branches": None if self.spread is None else branches_summary(self.spread),
            "first_to_diverge": None
            if first is None
            else {
                "engine": first.engine,
                "dt": first.dt,
                "t": first.metrics.first_divergence_time,
                "why": divergence_sentence(first, self.scene),
            },
        }


def compare(
    scene: Scene | str,
    engines: str | Sequence[str],
    dts: float | Sequence[float] | None = None,
    t_end: float | None = None,
    progress: Callable[[str], None] | None = None,
    max_steps: int | None = None,
    horizon_runs: int = 0,
    horizon_seed: int = DEFAULT_SEED,
) -> CompareResult:
    """Run the reference once and each engine at each dt (DEFAULT_DT when `dts` is None;
    once for `reference` and `linear`), all to the same t_end, and score every run.
    `scene` may be a Scene, a file or a built-in name; `engines` and `dts` one value or
    several.  Each simulator is warmed up before it is timed.  `progress` gets one line
    per run with its wall time (for stderr).  An engine run stopped by Ctrl-C stops the
    comparison (KeyboardInterrupt).  Then each run but the reference's gets its horizon
    (harness.horizon.verdict) from ensembles of `horizon_runs` members seeded with
    `horizon_seed` (0, the default here: no horizons; the CLI's default is
    harness.horizon.settings.DEFAULT_RUNS).  `result.to_dict()` is the `compare --json`
    document (docs/api.md)."""
    say = progress or (lambda _msg: None)
    scene = as_scene(scene)
    engines = [engines] if isinstance(engines, str) else list(engines)
    dts = [float(dts)] if isinstance(dts, int | float) else (list(dts) if dts else [DEFAULT_DT])
    plan = [(e, dt) for e in engines for dt in (dts if is_fixed_step(e) else [None])]
    runs: list[EngineRun] = []
    with progress_bar(1 + len(plan), f"compare {scene.name}") as bar:
        bar.set_postfix_str("reference", refresh=False)
        reference, ref_wall = _timed_run("reference", scene, None, t_end, reraise=True)
        say(_progress_line("reference", None, reference, ref_wall))
        bar.update()
        for engine, dt in plan:
            bar.set_postfix_str(run_label(engine, dt), refresh=False)
            if engine == "reference":
                traj, wall = reference, ref_wall
            else:
                traj, wall = _timed_run(engine, scene, dt, t_end, max_steps=max_steps)
                say(_progress_line(engine, dt, traj, wall))
            metrics = evaluate(traj, reference, scene.gravity)
            fit = run_exponent(traj, scene, reference, metrics.match)
            runs.append(EngineRun(engine, dt, traj, wall, metrics, fit))
            bar.update()
    if horizon_runs > 0:
        add_horizons(scene, reference, runs, horizon_runs, horizon_seed, say)
    spread = add_branches(scene, reference, runs, t_end, say)
    return CompareResult(scene, reference, ref_wall, runs, run_exponent(reference, scene), spread)


def add_branches(
    scene: Scene,
    reference: Trajectory,
    runs: list[EngineRun],
    t_end: float | None,
    say: Callable[[str], None],
) -> Spread | None:
    """When the reference ends `simultaneous_impact`: the branches from there
    (harness.branches.spread) and the one each run follows (harness.branches.follow)."""
    if reference.status is not Status.SIMULTANEOUS_IMPACT:
        return None
    start = time.perf_counter()
    t_end = float(t_end if t_end is not None else scene.run.t_end)
    spread = branches_from(scene, t_end, reference)
    for r in runs:
        r.branch = follow_branches(r.trajectory, spread, scene, r.metrics.first_divergence_time)
    say(f"compare: {len(spread.branches)} branches at t_u = {reference.t_final:.9g} s ("
        f"{time.perf_counter() - start:.2f} s)")  # fmt: skip
    return spread


def branches_summary(spread: Spread) -> dict[str, Any]:
    """The `branches` field of the compare document: the undecidable state and one entry
    per branch (as in `harness branches --json`)."""
    doc = spread.to_dict()
    return {"undecidable": doc["undecidable"], "branches": doc["branches"][1:]}


def add_horizons(
    scene: Scene,
    reference: Trajectory,
    runs: list[EngineRun],
    members: int,
    seed: int,
    say: Callable[[str], None],
) -> None:
    """Each run's horizon verdict (harness.horizon.verdict), with a progress bar over
    the ensembles' members."""
    judged = [r for r in runs if r.engine != "reference"]
    if not judged:
        return
    start = time.perf_counter()
    total = planned_members(members, [r.dt is not None for r in judged])
    with progress_bar(total, f"horizon {scene.name}", unit="member") as bar:
        shared = scene_horizon(scene, reference, members, seed, bar.update)
        for r in judged:
            bar.set_postfix_str(r.label, refresh=False)
            match = r.metrics.match
            if match is None:
                continue
            r.horizon = engine_horizon(scene, reference, r.trajectory, match, shared, bar.update)
    say(f"compare: horizons of {len(judged)} run(s), {members} members each ("
        f"{time.perf_counter() - start:.2f} s)")  # fmt: skip


def _timed_run(
    engine: str,
    scene: Scene,
    dt: float | None,
    t_end: float | None,
    reraise: bool = False,
    max_steps: int | None = None,
) -> tuple[Trajectory, float]:
    """The run and its wall time, after a warm-up (simulators.warm_up) so that the time
    is the simulation's, not one-time imports or compilation."""
    warm_up(engine, scene, dt)
    start = time.perf_counter()
    try:
        traj = run_simulator(engine, scene, dt=dt, t_end=t_end, max_steps=max_steps)
        if traj.stats.get("interrupted"):
            raise KeyboardInterrupt
    except Exception as exc:  # an engine that breaks is a result, not a crash
        if reraise:
            raise
        traj = Trajectory.failed(engine, scene.name, dt, f"{type(exc).__name__}: {exc}")
    return traj, time.perf_counter() - start


def _progress_line(engine: str, dt: float | None, traj: Trajectory, wall: float) -> str:
    label = run_label(engine, dt)
    text = f"compare: {label}: {traj.status.value}, {len(traj.impacts)} impacts, "
    text += f"t_final={traj.t_final:.6g} ({wall:.2f} s)"
    if traj.status.value in ("failed", "stalled") and traj.message:
        text += f": {traj.message}"
    return text


def format_compare(result: CompareResult, wide: bool = False) -> str:
    """The terminal report (harness.compare.text)."""
    from .text import format_compare as _format

    return _format(result, wide=wide)
