"""What a run hands back: the output arrays the compiled loop writes into, grown on
request without changing the run and never returned with rows missing, and the status
and message it ends with."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from harness.scenes import resolve_scene
from reference import ReferenceOptions, compiled
from reference.core.records import N_IMPACTS, OVERFLOW
from reference.simulate import _trajectory, make_problem, run_problem, simulate


def test_output_arrays_grown_during_the_run_give_the_run_that_had_room():
    """pentagon-bounce (hundreds of impacts, contact phases, samples on a grid) started with 8
    rows of each output array: the loop asks for more again and again, and the result
    is the same, bit for bit, as the run sized for max_impacts."""
    scene = resolve_scene("pentagon-bounce")
    opts = ReferenceOptions()
    whole = simulate(scene, options=opts)
    problem = make_problem(scene, scene.run.t_end, opts)
    for name in ("sample_t", "sample_y", "sample_e", "impacts", "phases", "accumulations"):
        arr = getattr(problem, name)
        setattr(problem, name, np.empty((8, *arr.shape[1:]), dtype=arr.dtype))
    problem.full_rows = dict.fromkeys(problem.full_rows, 0)  # (double each time)
    run_problem(compiled.run_events(), problem, opts.max_samples)
    grown = _trajectory(scene, problem, opts, scene.run.t_end, 0.0, 0.0)
    assert len(grown.impacts) == len(whole.impacts) > 500
    assert grown.impacts == list(whole.impacts)
    assert list(grown.phases) == list(whole.phases)
    assert len(grown.t) == len(whole.t) > 2000
    np.testing.assert_array_equal(grown.t, whole.t)
    np.testing.assert_array_equal(grown.quaternion, whole.quaternion)


def test_a_run_starts_with_rows_for_its_first_impacts_and_grows_once_to_max_impacts(
    monkeypatch,
):
    """Outputs start with rows for FIRST_IMPACTS impacts (a short run never maps memory
    for max_impacts); pentagon-bounce's impacts (over 500), started with rows for 256,
    make them grow once, straight to the rows for max_impacts; arrays with room are
    kept."""
    simulate_module = importlib.import_module("reference.simulate")
    monkeypatch.setattr(simulate_module, "FIRST_IMPACTS", 256)
    scene = resolve_scene("pentagon-bounce")
    opts = ReferenceOptions()
    whole = simulate(scene, options=opts)
    problem = make_problem(scene, scene.run.t_end, opts)
    first = 256 + simulate_module.MIN_ROWS
    assert len(problem.impacts) == first < 500 < len(whole.impacts)
    run_problem(compiled.run_events(), problem, opts.max_samples)
    full = simulate_module.output_rows(scene.run.max_impacts, scene.run.t_end, opts)
    assert len(problem.impacts) == full["impacts"] == scene.run.max_impacts + 64
    assert len(problem.phases) == 2 * first > len(whole.phases)  # had room: kept
    assert int(problem.counts[N_IMPACTS]) == len(whole.impacts)


def test_a_run_whose_output_ran_out_of_rows_raises_instead_of_returning_it_truncated():
    scene = resolve_scene("rod")
    opts = ReferenceOptions()
    problem = make_problem(scene, 0.1, opts)
    run_problem(compiled.run_events(), problem, opts.max_samples)
    problem.counts[OVERFLOW] = 1
    with pytest.raises(RuntimeError, match="ran out of rows"):
        _trajectory(scene, problem, opts, 0.1, 0.0, 0.0)


def test_every_loop_status_ends_with_its_status_and_its_own_message():
    """status_message formats only the ending status's sentence: each loop status of the
    core maps to its Trajectory status (written out here, not read from simulate) with
    a message of its own; an unknown code is `failed` with `loop status N`."""
    from reference.core import records as R
    from reference.simulate import initial_record, model_record, options_record, status_message
    from reference.trajectory import Status

    expected = {
        "T_END": Status.T_END,
        "SINGULARITY": Status.SINGULARITY,
        "ENERGY_EXHAUSTED": Status.SINGULARITY,
        "AT_REST": Status.SINGULARITY,
        "TILT_FLOOR": Status.SINGULARITY,
        "SIMULTANEOUS": Status.SIMULTANEOUS_IMPACT,
        "PUSHED": Status.SIMULTANEOUS_IMPACT,
        "MAX_IMPACTS": Status.MAX_IMPACTS,
        "OFF_FACE": Status.LEFT_MODEL,
        "BELOW_FLOOR": Status.LEFT_MODEL,
        "LAW_UNDECIDED": Status.SIMULTANEOUS_IMPACT,
        "FLAT_REST": Status.SINGULARITY,
        "FAILED_NONFINITE": Status.FAILED,
        "FAILED_LCP": Status.FAILED,
        "FAILED_STUCK": Status.FAILED,
        "FAILED_INTEGRATION": Status.FAILED,
        "FAILED_NO_ADVANCE": Status.FAILED,
        "STALLED": Status.STALLED,
    }

    scene = resolve_scene("rod")
    opts = options_record(scene, 1.0, ReferenceOptions())[0]
    model = model_record(scene)[0]
    state = initial_record(np.zeros(13))[0]
    state["info_t"], state["n_info"] = 0.125, 1
    state["info"][0] = 2
    codes = {
        k[7:]: v for k, v in vars(R).items() if k.startswith("STATUS_") and k != "STATUS_RUNNING"
    }
    assert set(codes) == set(expected)
    messages = set()
    for name, code in codes.items():
        state["status"] = code
        status, message = status_message(state, opts, model)
        assert status == expected[name], name
        assert message and not message.startswith("loop status")
        messages.add(message)
    assert len(messages) == len(codes)
    state["status"] = R.STATUS_SIMULTANEOUS
    assert status_message(state, opts, model)[1] == "contact 2 hit simultaneously at t = 0.125"
    text = status_message(state, opts, model, label=lambda k: f"v{k}")[1]
    assert text == "v2 hit simultaneously at t = 0.125"
    state["status"] = R.STATUS_LAW_UNDECIDED  # one sentence per way a law leaves it
    said = set()
    for outcome in range(1, 5):  # NOT_SETTLED, SINGULAR, TOO_MANY, law_event.NO_PROGRESS
        state["law_outcome"] = outcome
        said.add(status_message(state, opts, model)[1])
    assert len(said) == 4
    state["status"] = 999
    assert status_message(state, opts, model) == (Status.FAILED, "loop status 999")
