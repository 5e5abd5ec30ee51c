"""The work-precision study of `harness bench` on one scene.

The truth is the exact reference at its tightest setting (`TRUTH`: DOP853 rtol 1e-12 in
contact phases, chatter completed below 1e-6 of the velocity scale).  Every other run is
scored against it with `harness.metrics.evaluate` (impacts matched, impact time error,
energy error, ...), DiffEqDevTools-style:

- fixed-step engines over a sweep of timesteps (`DEFAULT_DTS`, coarse to fine), a setting
  being skipped (and listed under "skipped") when its predicted cost exceeds the budget;
- the reference over its accuracy settings (`REFERENCE_SETTINGS`, loose to tight);
- the linear model once (it is exact for its own model: its error is the linearisation's).

Wall time: one untimed warm-up run per simulator (imports, JIT compilation, caches), then
`repeats` timed runs per setting; the median and the minimum are reported.  Every
simulator runs to the same physical time: the scene's t_end, or the truth's end when the
reference stops earlier (singularity, undecidable impact), so that all costs are for the
same stretch of motion.  (The reference's settings are given the requested t_end, so
that the tightest one repeats the truth exactly, samples included; they stop where the
truth stopped unless their own motion differs.)

Derived numbers (`derived`, per error metric and simulator) come from the log-log
work-precision curves: each curve is reduced to its Pareto front (runs that are more
accurate than every cheaper run of the same simulator) and log(error) is interpolated
linearly in log(time) between front points (`loglog_interp`).  See `derive`.
"""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Callable, Sequence
from typing import Any

from reference.scene import Scene, SceneError
from reference.scenes import as_scene
from reference.trajectory import Status, Trajectory

from ..metrics import evaluate
from ..metrics.follows import follows_reference
from ..progress import progress_bar
from ..simulators import check_engine, check_run, engine_names, is_fixed_step
from .derive import derive
from .plot import plot_work_precision
from .settings import (
    DEFAULT_BUDGET_S,
    DEFAULT_DTS,
    ERROR_FLOOR,
    REFERENCE_SETTINGS,
    TRUTH,
    Setting,
    reference_setting,
)
from .table import _fmt

# ----------------------------------------------------------------------------- timing


def timed(setting: Setting, scene: Scene, t_end: float) -> tuple[Trajectory, float]:
    """One run and its wall time (perf_counter around the whole call: model building,
    simulation, Trajectory assembly).  An exception becomes a `failed` Trajectory."""
    start = time.perf_counter()
    try:
        traj = setting.run(scene, t_end)
    except Exception as exc:  # a broken simulator is a result
        traj = Trajectory.failed(
            setting.engine, scene.name, setting.dt, f"{type(exc).__name__}: {exc}"
        )
    return traj, time.perf_counter() - start


def predict_time(measured: Sequence[tuple[float, float]], dt: float) -> float:
    """Predicted wall time at timestep dt from measured (dt, time) pairs of the same
    engine: time ∝ dt^(−s), s from the two finest measured steps (at least 1: a step
    never costs less), s = 1 with a single measurement."""
    pts = sorted(measured, reverse=True)
    d1, t1 = pts[-1]
    s = 1.0
    if len(pts) >= 2:
        d0, t0 = pts[-2]
        if d0 > d1 and t0 > 0 and t1 > 0:
            s = max(1.0, math.log(t1 / t0) / math.log(d0 / d1))
    return t1 * (d1 / dt) ** s


# ----------------------------------------------------------------------------- rows


def score(
    setting: Setting, traj: Trajectory, times: list[float], truth: Trajectory, gravity: float
) -> dict[str, Any]:
    """The bench row of one setting: contract fields plus the other metrics."""
    m = evaluate(traj, truth, gravity)
    return {
        "engine": setting.engine,
        "setting": setting.label,
        "dt": setting.dt,
        "contact_rtol": setting.contact_rtol,
        "chatter_tol": setting.chatter_tol,
        "wall_time_s": statistics.median(times),
        "wall_time_min_s": min(times),
        "wall_times_s": list(times),
        "repeats": len(times),
        "status": traj.status.value,
        "message": traj.message,
        "t_final": traj.t_final,
        "impacts": len(traj.impacts),
        "reference_impacts": m.reference_impacts,
        "impacts_matched": m.impacts_matched,
        "impact_time_error": m.impact_time_error,
        "energy_error": m.energy_error,
        "energy_error_agreeing": m.energy_error_agreeing,
        "attitude_error": m.attitude_error,
        "attitude_error_agreeing": m.attitude_error_agreeing,
        "first_divergence_time": m.first_divergence_time,
        "divergence_reason": m.divergence_reason,
        "follows_reference": follows_reference(m.impacts_matched, m.reference_impacts),
    }


def bench(
    scene: Scene | str,
    engines: Sequence[str] | None = None,
    dts: Sequence[float] | None = None,
    t_end: float | None = None,
    repeats: int = 3,
    plot: str | os.PathLike | None = None,
    progress: Callable[[str], None] | None = None,
    budget_s: float = DEFAULT_BUDGET_S,
    reference_settings: Sequence[tuple[float, float]] | None = None,
) -> dict[str, Any]:
    """Work-precision study of `scene` (module docstring).  Returns the contract's bench
    document plus `truth`, `skipped`, `derived`, `load` and the study's settings.

    engines: simulators to sweep (default every installed engine, `engine_names()`); the
    reference at its tightest setting is always run and timed, its looser settings only when
    "reference" is among `engines`.  dts: timesteps for the fixed-step engines (default
    `DEFAULT_DTS`).  budget_s: a setting whose predicted cost (repeats × predicted
    single-run time) exceeds it is skipped, and so are the finer timesteps after it.
    reference_settings: (contact_rtol, chatter_tol) pairs; the truth is always `TRUTH`.
    `scene` may be a Scene, a file or a built-in name."""
    say = progress or (lambda _msg: None)
    scene = as_scene(scene)
    if repeats < 1:
        raise SceneError(f"--repeats must be >= 1, got {repeats}")
    engines = list(engines) if engines else engine_names()
    for e in engines:
        check_engine(e)
    dts = sorted({float(d) for d in (dts or DEFAULT_DTS)}, reverse=True)
    ref_settings = list(reference_settings or REFERENCE_SETTINGS)
    if "reference" not in engines:
        ref_settings = []
    ref_settings = [s for s in ref_settings if tuple(s) != TRUTH] + [TRUTH]
    t_request = float(t_end if t_end is not None else scene.run.t_end)
    load_before = os.getloadavg()

    truth_setting = reference_setting(TRUTH)
    truth, truth_wall = timed(truth_setting, scene, t_request)
    if truth.status is Status.FAILED or truth.t_final <= 0:
        raise RuntimeError(f"the reference failed on {scene.name}: {truth.message}")
    horizon = truth.t_final
    say(
        f"bench: truth (reference {truth_setting.label}): {truth.status.value}, "
        f"{len(truth.impacts)} impacts, t_final={horizon:.6g} ({truth_wall:.2f} s, warm-up)"
    )

    results: list[dict[str, Any]] = []
    skipped: list[dict[str, Any]] = []

    def measure(setting: Setting) -> dict[str, Any]:
        times, traj = [], None
        # the reference stops by itself where the truth did: same t_end, same samples
        until = t_request if setting.engine == "reference" else horizon
        for _ in range(repeats):
            traj, wall = timed(setting, scene, until)
            times.append(wall)
        row = score(setting, traj, times, truth, scene.gravity)
        results.append(row)
        say(
            f"bench: {setting.engine} {setting.label}: {row['status']}, "
            f"median {row['wall_time_s']:.3g} s, matched {row['impacts_matched']}/"
            f"{row['reference_impacts']}, E error following {_fmt(row['energy_error_agreeing'])}"
        )
        return row

    plan = _ordered(engines)
    total = len(ref_settings) if "reference" in engines else 1
    total += sum(len(dts) if is_fixed_step(e) else 1 for e in plan if e != "reference")
    with progress_bar(total, f"bench {scene.name}", unit="setting") as bar:

        def measured_once(setting: Setting) -> dict[str, Any]:
            bar.set_postfix_str(f"{setting.engine} {setting.label}", refresh=False)
            row = measure(setting)
            bar.update()
            return row

        for engine in plan:
            if engine == "reference":
                for rc in ref_settings:
                    measured_once(reference_setting(rc))
            elif not is_fixed_step(engine):
                setting = Setting(engine)
                timed(setting, scene, horizon)  # warm-up (e.g. numba compilation)
                measured_once(setting)
            else:
                before = len(skipped)
                _fixed_step_sweep(
                    engine, scene, dts, horizon, repeats, budget_s, measured_once, skipped, say
                )
                bar.update(len(skipped) - before)
        if "reference" not in engines:  # the truth setting is always timed
            measured_once(truth_setting)

    derived = derive(results)
    doc: dict[str, Any] = {
        "scene": scene.name,
        "t_end": horizon,
        "t_end_requested": t_request,
        "truth": {
            "engine": "reference",
            "setting": truth_setting.label,
            "status": truth.status.value,
            "message": truth.message,
            "t_final": truth.t_final,
            "impacts": len(truth.impacts),
            "wall_time_s": truth_wall,
        },
        "repeats": repeats,
        "budget_s": budget_s,
        "dts": dts,
        "results": results,
        "skipped": skipped,
        "derived": derived,
        "error_floor": ERROR_FLOOR,
        "load": {"before": list(load_before), "after": list(os.getloadavg())},
        "cpu_count": os.cpu_count(),
        "notes": [
            "errors against the reference at " + truth_setting.label,
            "wall_time_s: median of `repeats` runs after one warm-up run per simulator",
            "derived: Pareto front per simulator, log(error) linear in log(time) between "
            f"front points; errors below {ERROR_FLOOR:g} count as {ERROR_FLOOR:g}",
        ],
    }
    if plot:
        doc["plot"] = str(plot_work_precision(doc, plot))
        say(f"bench: wrote {doc['plot']}")
    return doc


def _fixed_step_sweep(
    engine: str,
    scene: Scene,
    dts: list[float],
    horizon: float,
    repeats: int,
    budget_s: float,
    measure: Callable[[Setting], dict[str, Any]],
    skipped: list[dict[str, Any]],
    say: Callable[[str], None],
) -> None:
    """A fixed-step engine over the timesteps, coarse to fine: one warm-up run, then
    `measure` each runnable timestep until the predicted cost exceeds the budget (the
    rest go to `skipped` with their predicted cost)."""
    runnable = _runnable_dts(engine, scene, dts, horizon, skipped, say)
    if runnable:
        timed(Setting(engine, dt=runnable[0]), scene, horizon)  # warm-up
    measured: list[tuple[float, float]] = []
    for i, dt in enumerate(runnable):
        if measured:
            predicted = predict_time(measured, dt)
            if repeats * predicted > budget_s:
                for dt_skip in runnable[i:]:
                    p = predict_time(measured, dt_skip)
                    skipped.append(
                        {
                            "engine": engine,
                            "setting": f"dt={dt_skip:g}",
                            "dt": dt_skip,
                            "predicted_wall_time_s": p,
                            "reason": f"predicted {repeats} x {p:.3g} s > budget {budget_s:g} s",
                        }
                    )
                    say(f"bench: {engine} dt={dt_skip:g}: skipped ({p:.3g} s predicted)")
                break
        row = measure(Setting(engine, dt=dt))
        measured.append((dt, row["wall_time_s"]))


def _runnable_dts(
    engine: str,
    scene: Scene,
    dts: list[float],
    horizon: float,
    skipped: list[dict[str, Any]],
    say: Callable[[str], None],
) -> list[float]:
    """The timesteps the engine can run to `horizon` (harness.simulators.check_run: at
    most t_end, within the step ceiling); the others go to `skipped` with the reason."""
    out = []
    for dt in dts:
        try:
            check_run(engine, scene, dt, horizon)
        except SceneError as exc:
            skipped.append(
                {
                    "engine": engine,
                    "setting": f"dt={dt:g}",
                    "dt": dt,
                    "predicted_wall_time_s": None,
                    "reason": str(exc),
                }
            )
            say(f"bench: {engine} dt={dt:g}: skipped ({exc})")
        else:
            out.append(dt)
    return out


def _ordered(engines: list[str]) -> list[str]:
    """Reference first, then the rest in the order given (no duplicates)."""
    out = ["reference"] if "reference" in engines else []
    for e in engines:
        if e not in out:
            out.append(e)
    return out
