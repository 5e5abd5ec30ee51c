"""The stall guard (harness.stall): a reference run whose loop returns advance t by less
than one roundoff unit of the motion's time scale per step, three times in a row, ends
`failed` ("stalled at t = ...") instead of running for ever; a run that advances is left
alone."""

from __future__ import annotations

import math
import sys

import pytest

from harness.cli import main
from harness.stall import STALL_YIELDS, Stalled, StallGuard
from reference import load_scene


@pytest.fixture(scope="module")
def scene():
    return load_scene("bumpy-transition")


def test_the_bound_is_one_roundoff_unit_of_the_time_scale_per_step(scene):
    guard = StallGuard(scene, work_budget=1000)
    tau = math.sqrt(scene.body.radius / scene.gravity)
    assert guard.bound == pytest.approx(1000 * sys.float_info.epsilon * tau, rel=1e-12)


def test_returns_that_creep_end_the_run_with_t(scene):
    guard = StallGuard(scene)
    guard(0.25)
    for k in range(1, STALL_YIELDS):
        guard(0.25 + k * 0.1 * guard.bound)
    with pytest.raises(Stalled, match=r"stalled at t = 0\.25"):
        guard(0.25 + STALL_YIELDS * 0.1 * guard.bound)


def test_one_return_that_advances_resets_the_count(scene):
    guard = StallGuard(scene)
    t = 0.25
    guard(t)
    for _ in range(10):
        for _ in range(STALL_YIELDS - 1):
            t += 0.5 * guard.bound
            guard(t)
        t += 2.0 * guard.bound  # a return that advances: never STALL_YIELDS slow in a row
        guard(t)


@pytest.mark.slow
def test_the_creeping_transition_at_gamma_0_ends_failed_with_its_time(capsys):
    assert main(["transition", "--restitution", "0", "--json"]) == 0
    out = capsys.readouterr().out
    assert '"status": "failed"' in out and "stalled at t = 0.2969" in out
