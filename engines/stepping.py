"""The run loop every fixed-step engine adapter plugs into (docs/engines.md).

An adapter builds its engine's model of the scene and wraps it in a `Stepper`: an object
that takes steps and records rows (times and states in the reference's conventions,
plus whatever the adapter needs afterwards, such as contact impulses).  `run_steps` drives
it to the end time and owns what every adapter must do the same way:

- progress: `progress(done, total)` before every chunk of steps;
- the checks after every chunk (`first_failure`): a non-finite state, or a contact point
  more than FALL_THROUGH_DEPTH·a below its ground, ends the run with status `failed` and a
  message naming the time; the rows before a non-finite one are kept, a fall-through row
  is kept (it shows where the body went);
- Ctrl-C (KeyboardInterrupt): the run ends `failed`, "interrupted", with the rows recorded
  so far kept (`LoopResult.interrupted`; the harness exits 130 after printing them);
- the timing of the stepping alone (`LoopResult.stepping_s`, for stats["steps_per_s"]).

The adapter then turns its rows into a Trajectory with `engines.base.build_trajectory`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from reference.geometry import scene_contact_kinematics
from reference.scene import Scene
from reference.trajectory import Status

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
