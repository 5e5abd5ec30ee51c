"""Running stress cases within a budget: the reference's pilot, engine time prediction
from pilot runs, and engine runs isolated in a child process stopped at a hard cap."""

from __future__ import annotations

import multiprocessing
import time
from collections.abc import Callable
from typing import Any

from reference.scene import Scene
from reference.simulate import ReferenceOptions, simulate
from reference.trajectory import Status, Trajectory

from ..child_processes import start_method
from ..simulators import run_simulator

# Engines: runs longer than this many steps are predicted from pilots first.
PILOT_FREE_STEPS = 5000
# Engines and the linear model run in a child process stopped at this × the budget
# (pilot predictions miss contact-heavy later phases: measured up to 10x+ too low).
HARD_CAP_FACTOR = 2.0
PILOT_STEPS = (200, 2000)
# Reference: pilot over this fraction of t_end and of max_impacts.
REFERENCE_PILOT_FRACTION = 0.1


def timed(fn: Callable[[], Trajectory]) -> tuple[Trajectory | None, float, str | None]:
    start = time.perf_counter()
    try:
        traj, err = fn(), None
    except Exception as exc:  # a broken simulator is a result
        traj, err = None, f"{type(exc).__name__}: {exc}"
    return traj, time.perf_counter() - start, err


def engine_run(engine: str, scene: Scene, dt: float | None, t_end: float):
    """One run of a simulator, timed: (its trajectory, a `failed` one when it raised; the
    wall time; the error, or None)."""
    traj, wall, err = timed(lambda: run_simulator(engine, scene, dt, t_end))
    if traj is None:
        traj = Trajectory.failed(engine, scene.name, dt, err or "")
    return traj, wall, err


def run_reference(scene: Scene, budget_s: float) -> tuple[Trajectory | None, float, float, bool]:
    """The reference on a case within the budget: (trajectory, wall, predicted, skipped).

    A pilot runs the first REFERENCE_PILOT_FRACTION of the case (of t_end and of
    max_impacts, same sample grid).  If it ends on its own (singularity, undecidable
    impact, failure) it is the whole run; else the full run is predicted to cost
    wall / (fraction of the case done) and is run only within the budget.  When it is
    skipped the pilot is returned (skipped = True) as the basis for the engines."""
    t_end, n_max = scene.run.t_end, scene.run.max_impacts
    opts = ReferenceOptions(sample_dt=t_end / 2000.0)
    f = REFERENCE_PILOT_FRACTION
    pilot_scene = scene.with_run(max_impacts=max(100, int(f * n_max)))
    pilot, wall, err = timed(lambda: simulate(pilot_scene, t_end=f * t_end, options=opts))
    if pilot is None:
        raise RuntimeError(f"the reference raised on {scene.name}: {err}")
    if pilot.status not in (Status.T_END, Status.MAX_IMPACTS):
        return pilot, wall, wall, False
    done = max(pilot.t_final / t_end, len(pilot.impacts) / max(n_max, 1), 1e-9)
    predicted = wall / done
    if predicted > budget_s:
        return pilot, wall, predicted, True
    full, wall, err = timed(lambda: simulate(scene, options=opts))
    if full is None:
        raise RuntimeError(f"the reference raised on {scene.name}: {err}")
    return full, wall, predicted, False


def predict_engine_time(engine: str, scene: Scene, dt: float) -> float | None:
    """Predicted wall time of a fixed-step engine run of the whole case: pilots of
    PILOT_STEPS steps (the short one twice, the first as warm-up) give setup a and
    per-step cost c, predicted = a + c·steps.  None when the run is short enough to
    just run (≤ PILOT_FREE_STEPS steps)."""
    steps = scene.run.t_end / dt
    if steps <= PILOT_FREE_STEPS:
        return None
    short, long_ = PILOT_STEPS
    run_simulator(engine, scene, dt=dt, t_end=short * dt)  # warm-up: imports, caches
    _, t_long, _ = timed(lambda: run_simulator(engine, scene, dt=dt, t_end=long_ * dt))
    _, t_short, _ = timed(lambda: run_simulator(engine, scene, dt=dt, t_end=short * dt))
    c = max((t_long - t_short) / (long_ - short), 0.5 * t_long / long_)
    return max(t_short - c * short, 0.0) + c * steps


def over_budget(predicted: float, budget: float) -> str:
    return f"predicted {predicted:.3g} s > budget {budget:g} s"


def run_capped(
    fn: Callable[[], Any], cap_s: float, tick: Callable[[], None] | None = None
) -> tuple[Any, str | None]:
    """fn() in a child process (forked, or spawned where forking is unsafe:
    harness.child_processes; fn must then be picklable, e.g. a functools.partial of a
    module-level function), stopped after cap_s seconds of wall time; `tick()` is called
    about every TICK_S while it runs (a progress line).

    Returns (result, None) when it answered, (None, None) when it was stopped at the
    cap (the child, and only it, is terminated by its pid), and (None, message) when
    it died without answering (a crash inside an engine).  An exception inside fn is
    fn's business: it should return it as data."""
    ctx = multiprocessing.get_context(start_method(multiprocessing.get_all_start_methods()))
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_answer, args=(fn, send), daemon=True)
    proc.start()
    send.close()
    try:
        if _wait(recv, cap_s, tick):
            try:
                out = recv.recv()
            except EOFError:
                proc.join()
                return None, f"simulator process died (exit code {proc.exitcode})"
            proc.join()
            return out, None
        proc.terminate()
        proc.join(5.0)
        if proc.is_alive():
            proc.kill()
            proc.join()
        return None, None
    finally:
        recv.close()


def _answer(fn: Callable[[], Any], send) -> None:
    """The child's work: fn's result through the pipe."""
    send.send(fn())
    send.close()


TICK_S = 1.0


def _wait(recv, cap_s: float, tick: Callable[[], None] | None) -> bool:
    """Whether `recv` has an answer within cap_s, calling tick() every TICK_S."""
    deadline = time.monotonic() + cap_s
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return recv.poll(0)
        if recv.poll(min(left, TICK_S)):
            return True
        if tick is not None:
            tick()
