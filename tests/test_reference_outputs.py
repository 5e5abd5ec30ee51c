"""The output arrays the compiled loop writes into: grown on request without changing
the run, and never returned with rows missing."""

from __future__ import annotations

import numpy as np
import pytest

from harness.scenes import resolve_scene
from reference import ReferenceOptions, compiled
from reference.core.records import OVERFLOW
from reference.simulate import _trajectory, make_problem, run_problem, simulate


def test_output_arrays_grown_during_the_run_give_the_run_that_had_room():
    """pentagon-bounce (533 impacts, contact phases, samples on a grid) started with 8
    rows of each output array: the loop asks for more again and again, and the result
    is the same, bit for bit, as the run sized for max_impacts."""
    scene = resolve_scene("pentagon-bounce")
    opts = ReferenceOptions()
    whole = simulate(scene, options=opts)
    problem = make_problem(scene, scene.run.t_end, opts)
    for name in ("sample_t", "sample_y", "sample_e", "impacts", "phases", "accumulations"):
        arr = getattr(problem, name)
        setattr(problem, name, np.empty((8, *arr.shape[1:]), dtype=arr.dtype))
    run_problem(compiled.run_events(), problem, opts.max_samples)
    grown = _trajectory(scene, problem, opts, scene.run.t_end, 0.0, 0.0)
    assert len(grown.impacts) == len(whole.impacts) == 533
    assert grown.impacts == list(whole.impacts)
    assert list(grown.phases) == list(whole.phases)
    assert len(grown.t) == len(whole.t) > 2000
    np.testing.assert_array_equal(grown.t, whole.t)
    np.testing.assert_array_equal(grown.quaternion, whole.quaternion)


def test_a_run_whose_output_ran_out_of_rows_raises_instead_of_returning_it_truncated():
    scene = resolve_scene("rod")
    opts = ReferenceOptions()
    problem = make_problem(scene, 0.1, opts)
    run_problem(compiled.run_events(), problem, opts.max_samples)
    problem.counts[OVERFLOW] = 1
    with pytest.raises(RuntimeError, match="ran out of rows"):
        _trajectory(scene, problem, opts, 0.1, 0.0, 0.0)
