"""The documented Python API (docs/api.md): built-in scene names wherever a scene is
taken, and `compare` giving the `compare --json` document."""

from __future__ import annotations

import json

import pytest

from harness.cli import main
from harness.compare import compare
from harness.simulators import run_simulator
from reference import load_scene, simulate
from reference.linear.simulate import simulate_linear
from reference.scenes import builtin_dir


def test_load_scene_takes_a_builtin_name_and_a_path():
    by_name = load_scene("pentagon-bounce")
    by_path = load_scene(builtin_dir() / "pentagon-bounce.toml")
    assert by_name == by_path and by_name.body.n == 5


@pytest.mark.parametrize(
    "run",
    [
        lambda s: simulate(s, t_end=0.05),
        lambda s: simulate_linear(s, t_end=0.05),
        lambda s: run_simulator("linear", s, t_end=0.05),
    ],
    ids=["simulate", "simulate_linear", "run_simulator"],
)
def test_runs_take_a_builtin_name(run):
    by_name = run("near-simultaneous")
    by_scene = run(load_scene("near-simultaneous"))
    assert by_name.scene == "near-simultaneous"
    assert by_name.impact_times().tolist() == by_scene.impact_times().tolist()


def test_compare_result_is_the_json_document(capsys):
    argv = ["compare", "near-simultaneous", "--engine", "linear", "--t-end", "0.05", "--json"]
    assert main(argv) == 0
    cli = json.loads(capsys.readouterr().out)
    doc = compare("near-simultaneous", "linear", t_end=0.05).to_dict()
    assert set(cli) - {"provenance"} == set(doc)
    assert doc["scene"] == cli["scene"] and doc["reference"]["status"] == cli["reference"]["status"]
    (row,) = doc["engines"]
    assert set(row) == set(cli["engines"][0])
    assert row["engine"] == "linear" and row["dt"] is None
    assert row["impacts_matched"] == cli["engines"][0]["impacts_matched"]


def test_compare_takes_one_dt_or_several():
    one = compare("near-simultaneous", ["mujoco"], 1e-3, t_end=0.01)
    two = compare("near-simultaneous", ["mujoco"], [1e-3, 5e-4], t_end=0.01)
    assert [r.dt for r in one.runs] == [1e-3] and [r.dt for r in two.runs] == [1e-3, 5e-4]
