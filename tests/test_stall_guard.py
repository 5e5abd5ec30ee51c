"""The loop's progress check (reference.core.loop._stalled): a window of STALL_WINDOW
loop steps without an impact that advanced the clock by less than contact_rtol of the
motion's time scale T = min(√(a/g), a/V) a step ends the run `stalled`, with t, the
contacts held and the law in its message; an impact, or a window that advances, starts
a new one.  Runs that creep on the bumpy ground end there instead of running for ever."""

from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest

from harness.cli import main
from reference import simulate
from reference.core.loop import _stalled, motion_time_scale
from reference.core.records import N_IMPACTS
from reference.core.tolerances import STALL_WINDOW
from reference.options import ReferenceOptions
from reference.scene import scene_from_dict, time_unit
from reference.scenes import builtin_dir, load_scene
from reference.simulate import initial_record, model_record, options_record
from reference.trajectory import Status
from tests.conftest import empty_output

# Where the n = 3 bumpy-rolling runs creep (measured before the check existed: 7.6e-15 s
# per 50,000 steps under moreau, 2e-11 s under sequential).
CREEP_T = {"moreau": 0.0220392780, "sequential": 0.0262002}


@pytest.fixture(scope="module")
def rolling_n3_data():
    """The bumpy-rolling scene's keys with a triangle (n = 3) for its polygon."""
    data = tomllib.loads((builtin_dir() / "bumpy-rolling.toml").read_text())
    data["body"]["n"] = 3
    data["name"] = "bumpy-rolling-n3"
    return data


def _records(scene):
    """The state, model and options records of a run of `scene`, and an empty output."""
    opts = ReferenceOptions()
    state = initial_record(np.zeros(13))
    state["y"][0][3] = 1.0  # (the identity rotation, at rest: V = 0)
    return state, model_record(scene), options_record(scene, 1.0, opts), empty_output()


def _full_window(state, advance):
    """A window of STALL_WINDOW steps from t = 1 that advanced the clock by `advance`."""
    state["stall_t"], state["stall_t_lo"] = 1.0, 0.0
    state["t_hi"], state["t_lo"] = 1.0 + advance, 0.0
    state["stall_steps"] = STALL_WINDOW


def test_the_time_scale_is_gravitys_at_rest_and_the_rims_when_moving_fast():
    scene = load_scene("triangle-singularity")
    state, model, _, _ = _records(scene)
    y = state["y"][0]
    assert motion_time_scale(y, model[0]) == pytest.approx(time_unit(scene), rel=1e-15)
    y[7] = 1e3 * scene.body.radius / time_unit(scene)  # |v|: the rim crosses a in τ/1000
    a_over_v = scene.body.radius / y[7]
    assert motion_time_scale(y, model[0]) == pytest.approx(a_over_v, rel=1e-15)


def test_a_window_below_rtol_of_the_time_scale_a_step_is_stalled():
    scene = load_scene("triangle-singularity")
    state, model, opts, out = _records(scene)
    bound = STALL_WINDOW * float(opts["contact_rtol"][0]) * time_unit(scene)
    _full_window(state, 0.5 * bound)
    assert _stalled(state[0], model[0], opts[0], out)
    assert state["stall_advance"][0] == pytest.approx(0.5 * bound, rel=1e-9)
    assert state["stall_bound"][0] == pytest.approx(bound, rel=1e-12)


def test_a_window_that_advances_enough_starts_the_next_one():
    scene = load_scene("triangle-singularity")
    state, model, opts, out = _records(scene)
    bound = STALL_WINDOW * float(opts["contact_rtol"][0]) * time_unit(scene)
    _full_window(state, 2.0 * bound)
    assert not _stalled(state[0], model[0], opts[0], out)
    assert state["stall_t"][0] == state["t_hi"][0] and state["stall_steps"][0] == 1


def test_an_impact_starts_a_new_window_however_short_the_time_it_advanced():
    scene = load_scene("triangle-singularity")
    state, model, opts, out = _records(scene)
    _full_window(state, 0.0)
    out.counts[N_IMPACTS] = 1  # an impact: progress, counted against max_impacts
    assert not _stalled(state[0], model[0], opts[0], out)
    assert state["stall_impacts"][0] == 1 and state["stall_steps"][0] == 1


def test_a_window_not_yet_full_is_not_judged():
    scene = load_scene("triangle-singularity")
    state, model, opts, out = _records(scene)
    _full_window(state, 0.0)
    state["stall_steps"] = STALL_WINDOW - 1
    assert not _stalled(state[0], model[0], opts[0], out)
    assert _stalled(state[0], model[0], opts[0], out)


@pytest.mark.parametrize("law", ["moreau", "sequential"])
def test_the_creeping_triangle_on_bumps_ends_stalled_where_it_creeps(rolling_n3_data, law):
    scene = scene_from_dict(rolling_n3_data)
    traj = simulate(scene, options=ReferenceOptions(impact_law=law))
    assert traj.status is Status.STALLED, traj.message
    assert traj.t_final == pytest.approx(CREEP_T[law], abs=1e-6)
    assert traj.t_final < scene.run.t_end
    assert f"at t = {traj.t_final:.17g}" in traj.message
    assert "(b1 held," in traj.message and f"{law} law" in traj.message  # bump 1: contact 4


def test_the_same_rolling_with_its_20_gon_is_unaffected():
    traj = simulate("bumpy-rolling", options=ReferenceOptions(impact_law="moreau"))
    assert traj.status is Status.T_END, traj.message


def test_simulate_writes_the_status_stalled(rolling_n3_data, tmp_path, capsys):
    path = tmp_path / "rolling3.toml"
    lines = [f'name = "{rolling_n3_data["name"]}"', "restitution = 0.0", "gravity = 9.81"]
    for table in ("body", "ground", "initial", "run"):
        lines.append(f"[{table}]")
        lines += [f"{k} = {json.dumps(v)}" for k, v in rolling_n3_data[table].items()]
    path.write_text("\n".join(lines) + "\n")
    assert main(["simulate", str(path), "--impact-law", "moreau", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["status"] == "stalled"
    assert math.isclose(doc["t_final"], CREEP_T["moreau"], abs_tol=1e-6)


@pytest.mark.slow
def test_the_creeping_transition_at_gamma_0_ends_stalled_with_its_time(capsys):
    assert main(["transition", "--restitution", "0", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["status"] == "stalled" and "at t = 0.2969" in doc["message"]
