"""The Python API validates like the command line (reference.checks, one shared check):
`simulate`, `simulate_linear` and `run_simulator` raise SceneError for a NaN, zero,
negative or out-of-range t_end and for unusable options, before any work."""

from __future__ import annotations

import math
import time

import pytest

import reference
from harness.cli import main
from harness.scenes import resolve_scene
from harness.simulators import run_simulator
from reference.linear.simulate import simulate_linear
from reference.options import ReferenceOptions
from reference.scene import SceneError

BAD_T_END = [math.nan, 0, 0.0, -1.0, math.inf, 1e300, "1", True]
ENTRY_POINTS = {
    "simulate": lambda scene, t: reference.simulate(scene, t_end=t),
    "simulate_linear": lambda scene, t: simulate_linear(scene, t_end=t),
    "run_simulator": lambda scene, t: run_simulator("linear", scene, t_end=t),
}


@pytest.fixture(scope="module")
def scene():
    return resolve_scene("triangle-chatter")


@pytest.mark.parametrize("t_end", BAD_T_END, ids=repr)
@pytest.mark.parametrize("entry", sorted(ENTRY_POINTS))
def test_a_bad_t_end_is_refused_at_once_by_every_entry_point(scene, entry, t_end):
    t0 = time.monotonic()
    with pytest.raises(SceneError, match="t_end must be"):
        ENTRY_POINTS[entry](scene, t_end)
    assert time.monotonic() - t0 < 1.0  # refused before the run: no loop was entered


@pytest.mark.parametrize("t_end", ["nan", "0", "-1", "inf", "1e300"])
def test_the_command_line_refuses_the_same_values(t_end, capsys):
    assert main(["simulate", "triangle-chatter", "--engine", "linear", "--t-end", t_end]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and ("--t-end" in err[0] or "t_end" in err[0]), err


@pytest.mark.parametrize(
    "options,field",
    [
        (dict(work_budget=0), "work_budget"),
        (dict(work_budget=2.5), "work_budget"),
        (dict(chatter_tol=math.nan), "chatter_tol"),
        (dict(contact_rtol=-1.0), "contact_rtol"),
        (dict(energy_floor=math.nan), "energy_floor"),
        (dict(sample_dt=0.0), "sample_dt"),
        (dict(max_samples=0), "max_samples"),
    ],
)
def test_unusable_reference_options_are_refused(scene, options, field):
    with pytest.raises(SceneError, match=field):
        reference.simulate(scene, options=ReferenceOptions(**options))


@pytest.mark.parametrize(
    "options,field",
    [
        (dict(sample_dt=math.nan), "sample_dt"),
        (dict(energy_floor=-1.0), "energy_floor"),
        (dict(chatter_tol=math.nan), "chatter_tol"),
    ],
)
def test_unusable_linear_options_are_refused(scene, options, field):
    with pytest.raises(SceneError, match=field):
        simulate_linear(scene, **options)


def test_a_scene_that_is_no_scene_is_refused():
    with pytest.raises(
        SceneError, match="a Scene, a scene file or a built-in scene name is needed"
    ):
        reference.simulate({"body": {"n": 3}}, t_end=1.0)


def test_the_linear_loop_returns_to_python_every_budget_of_events(scene, monkeypatch):
    """Ctrl-C is seen between calls of the compiled loop: with a budget of 10 passes the
    run takes one call per 10 events, and its events are those of one long call."""
    import numpy as np

    import reference.linear.simulate as ls
    from reference.linear import kernel as K
    from reference.linear import segment
    from reference.linear.model import LinearModel, linear_state

    model = LinearModel.from_scene(scene)
    q0, p0 = linear_state(scene)
    whole = ls.run_linear(model, q0, p0, t_end=3.0)
    calls = []
    real = K.continue_kernel

    def counted(*args):
        calls.append(args[-1])
        return real(*args)

    monkeypatch.setattr(segment, "LOOP_BUDGET", 10)
    monkeypatch.setattr(K, "continue_kernel", counted)
    sliced = ls.run_linear(model, q0, p0, t_end=3.0)
    assert len(whole.kind) > 50 and len(calls) >= len(whole.kind) // 10
    assert set(calls) == {10}
    np.testing.assert_array_equal(sliced.t_hi, whole.t_hi)
    np.testing.assert_array_equal(sliced.q_post, whole.q_post)
    assert sliced.status is whole.status and sliced.message == whole.message
