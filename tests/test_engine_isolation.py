"""One failing engine never aborts the others: a plug-in engine that raises (SceneError
included: a scene it does not take) is reported as failed on its own rows, with its
message, while bench, compare, stress, fidelity, restitution and sweep finish the other
engines' work."""

from __future__ import annotations

import json

import pytest

from harness import simulators
from harness.cli import main

MESSAGE = "the raiser engine takes no scene"
RAISER = f'''
from engines.interface import engine_entry
from reference.scene import SceneError


@engine_entry(fixed_step=True)
def simulate(scene, *, dt=None, t_end=None):
    raise SceneError("{MESSAGE}")
'''

pytestmark = pytest.mark.usefixtures("fork_children")  # capped runs fork (conftest)


@pytest.fixture
def raiser(tmp_path, monkeypatch):
    """An installed plug-in engine `raiser` whose every run raises SceneError."""
    info = tmp_path / "raiser_engine-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: raiser-engine\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[harness.engines]\nraiser = raiser_engine:simulate\n")
    (tmp_path / "raiser_engine.py").write_text(RAISER)
    monkeypatch.syspath_prepend(str(tmp_path))
    simulators.refresh()
    yield "raiser"
    simulators.refresh()


def test_a_run_of_an_engine_that_raises_is_its_failed_run(raiser):
    traj = simulators.run_simulator(raiser, "triangle-chatter", dt=1e-3, t_end=0.01)
    assert traj.status.value == "failed" and MESSAGE in traj.message
    assert "SceneError" in traj.stats["error"]


def _doc(capsys) -> dict:
    return json.loads(capsys.readouterr().out)


def test_bench_reports_the_raising_engine_failed_and_finishes_the_others(raiser, capsys, tmp_path):
    out = tmp_path / "bench.json"
    argv = ["bench", "triangle-chatter", "--engine", raiser, "--engine", "linear"]
    assert main([*argv, "--dt", "1e-3", "--repeats", "1", "--json", "--out", str(out)]) == 0
    rows = _doc(capsys)["results"]
    failed = [r for r in rows if r["engine"] == raiser]
    assert failed and all(r["status"] == "failed" and MESSAGE in r["message"] for r in failed)
    assert [r["status"] for r in rows if r["engine"] == "linear"] != ["failed"]
    assert out.exists()


def test_compare_reports_the_raising_engine_failed_and_scores_the_others(raiser, capsys):
    argv = ["compare", "triangle-chatter", "--engine", raiser, "--engine", "linear"]
    assert main([*argv, "--dt", "1e-3", "--t-end", "0.2", "--horizon-runs", "0", "--json"]) == 0
    runs = {r["engine"]: r for r in _doc(capsys)["engines"]}
    assert runs[raiser]["status"] == "failed" and MESSAGE in runs[raiser]["message"]
    assert runs["linear"]["status"] != "failed"


def test_stress_reports_the_raising_engine_failed_and_goes_on(raiser, capsys):
    argv = ["stress", "--engine", raiser, "--engine", "linear", "--case", "chatter"]
    assert main([*argv, "--dt", "1e-3", "--json"]) == 0
    rows = _doc(capsys)["cases"]
    assert any(r["engine"] == raiser and r["status"] == "failed" for r in rows)
    assert any(r["engine"] == "linear" and r["status"] != "failed" for r in rows)


def test_restitution_reports_the_raising_engine_failed_and_reads_the_reference(raiser, capsys):
    argv = ["restitution", "--engine", "reference", "--engine", raiser, "--gamma", "0.5"]
    argv += ["--speed", "0.1", "--dt", "1e-3", "--phase", "0.5", "--geometry", "vertex"]
    assert main([*argv, "--json"]) == 0
    doc = _doc(capsys)
    text = json.dumps(doc)
    assert MESSAGE in text
    assert "reference" in text


@pytest.mark.slow
def test_fidelity_reports_the_raising_engine_failed_and_finishes_the_others(raiser, capsys):
    argv = ["fidelity", "pentagon-bounce", "--engine", raiser, "--engine", "linear"]
    assert main([*argv, "--dt", "1e-2", "--eps-grid", "1:1e-1:2", "--json"]) == 0
    assert MESSAGE in json.dumps(_doc(capsys))


@pytest.mark.slow
def test_a_sweep_of_the_raising_engine_records_failed_rows(raiser, capsys, tmp_path):
    argv = ["sweep", "exponent", "--gyration", "0.5", "--restitution", "0.5", "--samples", "2"]
    argv += ["--engine", raiser, "--workers", "1", "--out", str(tmp_path / "s"), "--json"]
    assert main(argv) == 0
    assert "failed" in json.dumps(_doc(capsys))
