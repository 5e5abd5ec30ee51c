"""engines.stepping: the run loop every fixed-step adapter plugs into.  A stepper with a
closed-form motion (a body sinking at constant speed, flat, through the ground) checks
where the loop stops, what it keeps and what it says."""

from __future__ import annotations

import numpy as np
import pytest

from engines.stepping import FALL_THROUGH_DEPTH, Rows, run_steps
from reference.trajectory import Status
from tests.conftest import make_scene


class Sinking:
    """Every step moves the body down by `speed`·dt from height z0 (flat, level); step
    `nan_at` (if given) gives a non-finite state."""

    def __init__(self, z0: float, speed: float, dt: float, nan_at: int | None = None):
        self.z0, self.speed, self.dt, self.nan_at = z0, speed, dt, nan_at
        self.rows: list[np.ndarray] = [self.state(0)]
        self.first = 0
        self.advances: list[int] = []

    def state(self, j: int) -> np.ndarray:
        y = np.zeros(13)
        y[2] = self.z0 - self.speed * self.dt * j
        y[3] = 1.0  # level: every vertex at the centre's height
        if j == self.nan_at:
            y[2] = np.nan
        return y

    def advance(self, steps: int) -> Rows:
        self.advances.append(steps)
        self.first = len(self.rows)
        self.rows += [self.state(j) for j in range(self.first, self.first + steps)]
        return Rows(
            self.dt * np.arange(self.first, len(self.rows)), np.array(self.rows[self.first :])
        )

    def cut(self, keep: int) -> None:
        del self.rows[self.first + keep :]

    def settle(self) -> float:
        return self.dt * (len(self.rows) - 1)


def test_a_body_below_the_fall_through_depth_ends_the_run_at_that_row():
    scene = make_scene(n=5)
    # z = 1.003 − 0.01 j: below −FALL_THROUGH_DEPTH·a (a = 1) first at the next whole j
    stepper = Sinking(z0=1.003, speed=10.0, dt=1e-3)
    loop = run_steps(stepper, scene, n_steps=1000, chunk_steps=50, t_end=1.0)
    first_below = int(np.ceil((1.003 + FALL_THROUGH_DEPTH) / 0.01))
    assert loop.status is Status.FAILED
    assert loop.message == f"the body fell through the ground at t = {first_below * 1e-3:.6g}"
    assert len(stepper.rows) == first_below + 1  # the row that fell is kept
    assert stepper.advances == [50, 50, 50]  # no step after the chunk that fell


def test_a_non_finite_state_ends_the_run_and_is_not_kept():
    stepper = Sinking(z0=1.0, speed=0.0, dt=1e-3, nan_at=70)
    loop = run_steps(stepper, make_scene(n=5), n_steps=1000, chunk_steps=50, t_end=1.0)
    assert loop.status is Status.FAILED and "non-finite" in loop.message
    assert len(stepper.rows) == 70 and np.isfinite(np.array(stepper.rows)).all()


def test_a_sane_run_reaches_t_end_in_chunks_with_progress_before_each():
    calls = []
    stepper = Sinking(z0=1.0, speed=0.0, dt=1e-3)
    loop = run_steps(
        stepper, make_scene(n=5), 120, 50, lambda done, total: calls.append((done, total)), 0.12
    )
    assert (loop.status, loop.message, loop.steps) == (Status.T_END, "reached t_end = 0.12", 120)
    assert stepper.advances == [50, 50, 20] and calls == [(0, 120), (50, 120), (100, 120)]


def test_ctrl_c_ends_the_run_failed_interrupted_with_the_rows_so_far():
    def stop(done, total):
        if done == 100:
            raise KeyboardInterrupt

    stepper = Sinking(z0=1.0, speed=0.0, dt=1e-3)
    loop = run_steps(stepper, make_scene(n=5), 1000, 50, stop, 1.0)
    assert loop.interrupted and loop.status is Status.FAILED
    assert loop.message == "interrupted (Ctrl-C) at t = 0.1; the steps before are kept"
    assert len(stepper.rows) == 101 and loop.steps == 100


@pytest.mark.parametrize("chunk", [1, 7, 1000])
def test_the_rows_do_not_depend_on_the_chunk_size(chunk):
    stepper = Sinking(z0=1.0, speed=1.0, dt=1e-3)
    run_steps(stepper, make_scene(n=5), 300, chunk, t_end=0.3)
    np.testing.assert_array_equal(np.array(stepper.rows)[:, 2], 1.0 - 1e-3 * np.arange(301))
