"""The driver every fixed-step engine adapter plugs into (docs/engines.md).

An adapter only builds its engine's model of the scene and steps it: it wraps the model in
an `Adapter` (a `Stepper` that takes steps and records rows, plus `recording`, which
hands over the rows in the reference's conventions with the contact impulses).
`simulate_fixed_step` (or `run_fixed_step`, without the Trajectory) owns what every adapter
does the same way:

- the end time (scene.run.t_end unless given), the step count (`step_count`) and the
  check of dt;
- the stats every engine reports with the same meaning (`run_fixed_step`): wall_time_s,
  steps, steps_per_s, interrupted;
- the Trajectory (engines.base.build_trajectory: impacts from contact onsets).

`run_steps`, the loop inside it, drives the adapter to the end time and owns:

- progress: `progress(done, total)` before every chunk of steps;
- the checks after every chunk (`first_failure`): a non-finite state, or a contact point
  more than FALL_THROUGH_DEPTH·a below its ground, ends the run with status `failed` and a
  message naming the time; the rows before a non-finite one are kept, a fall-through row
  is kept (it shows where the body went);
- Ctrl-C (KeyboardInterrupt): the run ends `failed`, "interrupted", with the rows recorded
  so far kept (`LoopResult.interrupted`; the harness exits 130 after printing them);
- the timing of the stepping alone (`LoopResult.stepping_s`, for stats["steps_per_s"]).

A new engine is one module with a builder and an `Adapter`, plus its entry point
(engines/builtin.py and pyproject.toml).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from reference.geometry import scene_contact_kinematics
from reference.scene import Scene
from reference.trajectory import Status, Trajectory

# Radius of the engines' contact spheres (one per vertex, or the bumps), in units of the
# body radius a.  Any value from 1e-2 to 1e-6 gave the same impacts (docs/engines.md); it
# must be small against a, so that the three_point distance error r(1 − cos α) and the
# mapping of points to vertices are negligible, and large against the roundoff of the
# positions (1e-16 a).
SPHERE_RADIUS_FRACTION = 1e-3
# A contact point more than FALL_THROUGH_DEPTH·a below its ground has gone through it: the
# thinnest body face a built-in model gives the bumps (PyBullet's box, 0.05 a; MuJoCo's
# and Drake's are 0.1 a half-thick), past which an engine pushes a bump out the wrong
# side.  No sane step penetrates more than a small fraction of the spheres' radius.
FALL_THROUGH_DEPTH = 0.05

Progress = Callable[[int, int], None]
# What `first_failure` reports (completed by " at t = …" in the run's message).
NON_FINITE = "the body's state became non-finite"
FELL_THROUGH = "the body fell through the ground"


@dataclass
class Rows:
    """The rows an adapter recorded during one `Stepper.advance`: times (m,) and states
    (m, 13) in the reference's conventions (x, q wxyz, v, ω world).  `broken`: the
    engine's own reason to stop right after these rows (e.g. MuJoCo resetting its
    state), or None."""

    t: np.ndarray
    states: np.ndarray
    broken: str | None = None


class Stepper(Protocol):
    """What an adapter gives `run_steps`."""

    def advance(self, steps: int) -> Rows:
        """Take `steps` steps from where the last call ended and return the rows recorded
        during them (any number: every step, or only those the adapter keeps)."""
        ...

    def cut(self, keep: int) -> None:
        """Keep only the first `keep` rows of the last `advance` (a failure was found in
        the rows after them); nothing is stepped after this."""
        ...

    def settle(self) -> float:
        """After Ctrl-C interrupted `advance`: make the rows recorded so far consistent
        (drop a half-recorded one) and return the time of the last row kept."""
        ...


@dataclass
class LoopResult:
    """How `run_steps` ended."""

    status: Status
    message: str
    steps: int  # steps taken (as counted by the loop: whole chunks, or up to Ctrl-C)
    stepping_s: float  # wall time inside `advance`
    interrupted: bool = False


def first_failure(scene: Scene, states: np.ndarray) -> tuple[int, str] | None:
    """(row, what happened) of the first row that ends a run: a non-finite state, or a
    contact point more than FALL_THROUGH_DEPTH·a below its ground; None when every row is
    sane."""
    if len(states) == 0:
        return None
    finite = np.isfinite(states).all(axis=1)
    gaps = scene_contact_kinematics(scene, np.where(finite[:, None], states, 0.0))[0]
    fell = gaps.min(axis=1) < -FALL_THROUGH_DEPTH * scene.body.radius
    bad = np.flatnonzero(~finite | fell)
    if not bad.size:
        return None
    row = int(bad[0])
    return row, (NON_FINITE if not finite[row] else FELL_THROUGH)


def run_steps(
    stepper: Stepper,
    scene: Scene,
    n_steps: int,
    chunk_steps: int,
    progress: Progress | None = None,
    t_end: float | None = None,
) -> LoopResult:
    """Drive `stepper` through n_steps steps in chunks of at most chunk_steps, with the
    checks, progress and Ctrl-C handling described in the module's docstring."""
    done, stepping, t0 = 0, 0.0, None
    status, message = Status.T_END, f"reached t_end = {t_end:g}" if t_end is not None else ""
    try:
        while done < n_steps:
            if progress is not None:
                progress(done, n_steps)
            chunk = min(chunk_steps, n_steps - done)
            t0 = time.perf_counter()
            rows = stepper.advance(chunk)
            stepping += time.perf_counter() - t0
            t0 = None
            done += chunk
            failure = first_failure(scene, rows.states)
            if failure is not None:
                row, what = failure
                stepper.cut(row if what == NON_FINITE else row + 1)
                message = f"{what} at t = {rows.t[row]:.6g}"
                return LoopResult(Status.FAILED, message, done, stepping)
            if rows.broken is not None:
                return LoopResult(Status.FAILED, rows.broken, done, stepping)
    except KeyboardInterrupt as exc:  # Ctrl-C, or the harness's SIGTERM (a subclass)
        if t0 is not None:  # interrupted inside advance
            stepping += time.perf_counter() - t0
        t_last = stepper.settle()
        reason = getattr(exc, "reason", "interrupted (Ctrl-C)")
        message = f"{reason} at t = {t_last:.6g}; the steps before are kept"
        return LoopResult(Status.FAILED, message, done, stepping, interrupted=True)
    return LoopResult(status, message, done, stepping)


# --------------------------------------------------------------------------- the driver
def step_count(t_end: float, dt: float) -> int:
    """Steps of a fixed-step run to t_end: the fewest that reach t_end (to 1e-9 of a
    step, so that t_end/dt = 1000.0000000001 is 1000 steps), at least one."""
    return max(1, math.ceil(t_end / dt - 1e-9))


def check_dt(dt: float) -> float:
    """dt as a float; ValueError unless it is a positive finite number."""
    dt = float(dt)
    if not (dt > 0.0 and math.isfinite(dt)):
        raise ValueError(f"dt must be > 0, got {dt}")
    return dt


@dataclass
class Recording:
    """What an adapter hands over after the loop, in the reference's conventions:
    times (N,), states (N, 13), normal impulses (N, k) per contact on the row of the
    state they were computed at (engines.base), the steps taken, the adapter's own stats
    (its parameters; `compile_time_s` for an engine that compiles before it steps, which
    wall_time_s then leaves out) and the sample thinning for the Trajectory."""

    t: np.ndarray
    states: np.ndarray
    impulses: np.ndarray
    steps: int
    stats: dict = field(default_factory=dict)
    sample_every: int = 1


class Adapter(Stepper, Protocol):
    """A `Stepper` that also hands over its rows (`run_fixed_step`)."""

    def recording(self, loop: LoopResult) -> Recording:
        """The rows recorded (after `cut` or `settle`, when the loop called them)."""
        ...


@dataclass
class FixedStepRun:
    """One run of `run_fixed_step`."""

    recording: Recording
    status: Status
    message: str
    stats: dict


def run_fixed_step(
    scene: Scene,
    dt: float,
    t_end: float | None,
    build: Callable[[int], Adapter],
    *,
    chunk_steps: int | None = None,
    progress: Progress | None = None,
) -> FixedStepRun:
    """Build the engine's model (`build(n_steps)` returns its Adapter), drive it with
    `run_steps` to t_end (scene.run.t_end by default) in chunks of chunk_steps (None: one
    chunk) and collect its Recording.  An adapter with a `close()` method is closed
    afterwards, also on error.

    stats, with one meaning for every engine: wall_time_s, the wall time of the engine's
    run (building the model, stepping, converting its output to the reference's
    conventions; not the Trajectory's assembly, and not a JIT compilation, which the
    adapter reports as compile_time_s); steps; steps_per_s, steps per second of the
    stepping alone; interrupted (only when Ctrl-C stopped the run); then the adapter's."""
    dt = check_dt(dt)
    t_end = scene.run.t_end if t_end is None else float(t_end)
    n_steps = step_count(t_end, dt)
    t_wall = time.perf_counter()
    adapter = build(n_steps)
    try:
        loop = run_steps(adapter, scene, n_steps, chunk_steps or n_steps, progress, t_end)
        rec = adapter.recording(loop)
    finally:
        close = getattr(adapter, "close", None)
        if close is not None:
            close()
    wall = time.perf_counter() - t_wall - float(rec.stats.get("compile_time_s", 0.0))
    stats = {
        "wall_time_s": wall,
        "steps": rec.steps,
        "steps_per_s": rec.steps / loop.stepping_s if loop.stepping_s > 0 else None,
    }
    if loop.interrupted:
        stats["interrupted"] = True
    stats.update(rec.stats)
    return FixedStepRun(rec, loop.status, loop.message, stats)


def simulate_fixed_step(
    scene: Scene,
    engine: str,
    dt: float,
    t_end: float | None,
    build: Callable[[int], Adapter],
    *,
    chunk_steps: int | None = None,
    progress: Progress | None = None,
) -> Trajectory:
    """`run_fixed_step`, then the Trajectory named `engine` (engines.base.build_trajectory:
    samples thinned by the Recording's sample_every, impacts from every recorded row)."""
    from .base import build_trajectory

    run = run_fixed_step(scene, dt, t_end, build, chunk_steps=chunk_steps, progress=progress)
    rec = run.recording
    return build_trajectory(
        scene,
        engine,
        check_dt(dt),
        rec.t,
        rec.states,
        rec.impulses,
        run.status,
        run.message,
        run.stats,
        rec.sample_every,
    )
