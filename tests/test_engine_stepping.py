"""engines.stepping: the run loop every fixed-step adapter plugs into.  A stepper with a
closed-form motion (a body sinking at constant speed, flat, through the ground) checks
where the loop stops, what it keeps and what it says."""

from __future__ import annotations

import numpy as np
import pytest

from engines.stepping import (
    FALL_THROUGH_DEPTH,
    Recording,
    Rows,
    run_fixed_step,
    run_steps,
    step_count,
)
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


# ------------------------------------------------------------------ the driver
class Recorded(Sinking):
    """A Sinking adapter for the driver: hands over its rows, reports a compile time,
    and notes that it was closed."""

    compile_s = 0.0
    closed = False

    def recording(self, loop) -> Recording:
        states = np.array(self.rows)
        impulses = np.zeros((len(states), 5))
        stats = {"compile_time_s": self.compile_s, "mine": 1}
        return Recording(self.dt * np.arange(len(states)), states, impulses, len(states) - 1, stats)

    def close(self) -> None:
        self.closed = True


@pytest.mark.parametrize(
    ("t_end", "dt", "steps"),
    [(1.0, 1e-3, 1000), (1.0000000000001, 1e-3, 1000), (1.0005, 1e-3, 1001)],
)
def test_the_step_count_is_the_fewest_steps_that_reach_t_end(t_end, dt, steps):
    assert step_count(t_end, dt) == steps
    assert step_count(1e-9, 1.0) == 1


def test_the_driver_defaults_t_end_counts_steps_and_closes_the_adapter():
    scene = make_scene(n=5, t_end=0.05)
    made = []

    def build(n_steps):
        made.append(n_steps)
        made.append(Recorded(z0=1.0, speed=0.0, dt=1e-3))
        return made[-1]

    run = run_fixed_step(scene, 1e-3, None, build, chunk_steps=20)
    assert made[0] == 50 and made[1].closed and made[1].advances == [20, 20, 10]
    assert run.status is Status.T_END and run.stats["steps"] == 50 and run.stats["mine"] == 1
    assert run.stats["steps_per_s"] > 0 and run.stats["wall_time_s"] >= 0


def test_wall_time_leaves_out_the_compile_time_the_adapter_reports():
    scene = make_scene(n=5, t_end=0.01)

    def build(n_steps):
        adapter = Recorded(z0=1.0, speed=0.0, dt=1e-3)
        adapter.compile_s = 1e6  # far longer than the run itself
        return adapter

    run = run_fixed_step(scene, 1e-3, None, build)
    assert run.stats["compile_time_s"] == 1e6 and run.stats["wall_time_s"] < 0


@pytest.mark.parametrize("dt", [0.0, -1e-3, float("nan"), float("inf")])
def test_the_driver_refuses_a_step_that_is_not_positive_and_finite(dt):
    with pytest.raises(ValueError, match="dt must be > 0"):
        run_fixed_step(make_scene(), dt, None, lambda n: Recorded(1.0, 0.0, 1e-3))
