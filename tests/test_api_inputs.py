"""The Python API validates like the command line (reference.checks, one shared check):
`simulate`, `simulate_linear` and `run_simulator` raise SceneError for a NaN, zero,
negative or out-of-range t_end and for unusable options, before any work (issue 34)."""

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
    with pytest.raises(SceneError, match="a Scene is needed"):
        reference.simulate({"body": {"n": 3}}, t_end=1.0)
