"""Engines from other packages: the entry-point registry finds them, `harness engines`
lists them, `harness compare` runs them, and a broken or missing one is bad input (exit
2, its name and the reason, no traceback).  Listing and the reference import no engine.

The default tests put a hand-made dist-info (what pip writes) on sys.path; the slow test
installs examples/toy-engine with pip into a temporary directory."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from harness import simulators
from harness.cli import main

ROOT = Path(__file__).resolve().parent.parent
TOY = ROOT / "examples" / "toy-engine"


def _dist_info(where: Path, name: str, version: str, entry_points: str) -> None:
    info = where / f"{name.replace('-', '_')}-{version}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n")
    (info / "entry_points.txt").write_text(f"[harness.engines]\n{entry_points}\n")


@pytest.fixture
def plugins(tmp_path, monkeypatch):
    """The toy engine (its source directory) and a broken engine, installed as
    distributions on sys.path for this test only."""
    _dist_info(tmp_path, "harness-toy-engine", "0.1.0", "toy = toy_engine:simulate")
    _dist_info(tmp_path, "broken-engine", "9.9", "broken = broken_engine:simulate")
    (tmp_path / "broken_engine.py").write_text("raise ImportError('needs libfoo.so')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.syspath_prepend(str(TOY))
    simulators.refresh()
    yield tmp_path
    simulators.refresh()


def test_an_installed_engine_is_discovered_with_its_package(plugins):
    assert "toy" in simulators.engine_names()
    info = {i.name: i for i in simulators.engine_infos()}["toy"]
    assert (info.package, info.version) == ("harness-toy-engine", "0.1.0")
    assert simulators.is_fixed_step("toy")


def test_harness_engines_lists_the_plugin_and_names_the_broken_one(plugins, capsys):
    assert main(["engines", "--json"]) == 2  # one engine fails to load
    out, err = capsys.readouterr()
    rows = {r["name"]: r for r in json.loads(out)["engines"]}
    assert rows["toy"]["package"] == "harness-toy-engine" and rows["toy"]["error"] is None
    assert rows["reference"]["fixed_step"] is False and rows["mujoco"]["fixed_step"] is True
    assert "broken" in err and "needs libfoo.so" in err and "Traceback" not in err


def test_compare_runs_the_plugin_against_the_reference(plugins, capsys):
    code = main(
        ["compare", "pentagon-bounce", "--engine", "toy", "--dt", "1e-3", "--t-end", "0.5"]
        + ["--json"]
    )
    assert code == 0
    run = json.loads(capsys.readouterr().out)["engines"][0]
    assert run["engine"] == "toy" and run["status"] == "t_end"
    # the toy's Newton impacts come in the reference's order (the first 4, t < 0.5)
    assert run["impacts_matched"] >= 4


@pytest.mark.parametrize(
    "engine, reason", [("broken", "needs libfoo.so"), ("not-installed", "unknown engine")]
)
def test_a_broken_or_missing_engine_is_bad_input(plugins, capsys, engine, reason):
    assert main(["compare", "pentagon-bounce", "--engine", engine]) == 2
    err = capsys.readouterr().err
    assert engine in err and reason in err and "Traceback" not in err


def test_listing_engines_and_running_the_reference_import_no_physics_engine():
    code = (
        "import sys\n"
        "from harness.cli import main\n"
        "assert main(['engines']) == 0\n"
        "assert main(['simulate', 'pentagon-bounce', '--t-end', '0.3']) == 0\n"
        "heavy = ('mujoco', 'pybullet', 'pydrake', 'dartpy', 'jax', 'distributed', 'dask')\n"
        "heavy = [m for m in heavy if m in sys.modules]\n"
        "assert not heavy, heavy\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, cwd=ROOT)


@pytest.mark.slow
def test_pip_installed_plugin_appears_and_runs_without_changing_this_package(tmp_path):
    """pip install --target (build isolation fetches setuptools: ~20 s with network)."""
    target = tmp_path / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(target)]
        + [str(TOY)],
        check=True,
        capture_output=True,
    )
    env = {**os.environ, "PYTHONPATH": str(target)}
    harness = [sys.executable, "-m", "harness"]
    listed = subprocess.run(harness + ["engines", "--json"], env=env, capture_output=True)
    rows = {r["name"]: r for r in json.loads(listed.stdout)["engines"]}
    assert rows["toy"]["package"] == "harness-toy-engine" and listed.returncode == 0
    compared = subprocess.run(
        harness
        + ["compare", "pentagon-bounce", "--engine", "toy", "--dt", "1e-3"]
        + ["--t-end", "0.5", "--json"],
        env=env,
        capture_output=True,
    )
    assert compared.returncode == 0, compared.stderr.decode()
    assert json.loads(compared.stdout)["engines"][0]["impacts_matched"] >= 4


@pytest.fixture
def missing_extra(tmp_path, monkeypatch):
    """An engine whose library (a distribution that is not installed) comes from an
    extra named `ghost`."""
    _dist_info(tmp_path, "ghost-engine", "1.0", "ghost = ghost_engine:simulate")
    (tmp_path / "ghost_engine.py").write_text(
        "from engines.interface import engine_entry\n"
        "@engine_entry(library='no-such-distribution-x7', extra='ghost')\n"
        "def simulate(scene, *, dt=None, t_end=None):\n"
        "    raise AssertionError('never run')\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    simulators.refresh()
    yield
    simulators.refresh()


def test_harness_engines_names_the_extra_of_an_engine_that_is_not_installed(missing_extra, capsys):
    assert main(["engines", "--json"]) == 0  # a missing extra is a choice, not an error
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)["engines"]}
    ghost = rows["ghost"]
    assert ghost["installed"] is False and ghost["error"] is None and ghost["extra"] == "ghost"
    assert ghost["install"] == "pip install 'euler-disk-harness[ghost]'"
    assert rows["mujoco"]["installed"] is True and rows["mujoco"]["extra"] is None
    assert main(["engines"]) == 0
    assert "not installed: pip install 'euler-disk-harness[ghost]'" in capsys.readouterr().out


def test_running_an_engine_whose_extra_is_missing_is_one_line_exit_2(missing_extra, capsys):
    code = main(["simulate", "pentagon-bounce", "--engine", "ghost", "--t-end", "0.01"])
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert code == 2 and len(err) == 1
    assert "pip install 'euler-disk-harness[ghost]'" in err[0]


@pytest.fixture
def batching(tmp_path, monkeypatch):
    """An engine `batchy` (MuJoCo underneath) that offers simulate_batch and counts its
    calls in `batchy_engine.CALLS`."""
    _dist_info(tmp_path, "batchy-engine", "1.0", "batchy = batchy_engine:simulate")
    (tmp_path / "batchy_engine.py").write_text(
        "from engines.builtin import mujoco\n"
        "from engines.interface import engine_entry\n"
        "CALLS = []\n"
        "@engine_entry(fixed_step=True)\n"
        "def simulate(scene, *, dt, t_end=None):\n"
        "    return mujoco(scene, dt=dt, t_end=t_end)\n"
        "def simulate_batch(scenes, *, dt, t_end=None):\n"
        "    CALLS.append(len(scenes))\n"
        "    return [mujoco(s, dt=dt, t_end=t_end) for s in scenes]\n"
        "simulate.simulate_batch = simulate_batch\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    simulators.refresh()
    import batchy_engine

    batchy_engine.CALLS.clear()
    yield batchy_engine
    simulators.refresh()


def test_run_batch_uses_the_engines_batch_and_gives_the_serial_runs(batching):
    from tests.conftest import make_scene

    scenes = [make_scene(n=5, t_end=0.3), make_scene(n=5, q=(0.02, 0.0, 0.05), t_end=0.3)]
    assert simulators.offers_batch("batchy") and not simulators.offers_batch("mujoco")
    batch = simulators.run_batch("batchy", scenes, 1e-4)
    assert batching.CALLS == [2]
    for sc, b in zip(scenes, batch, strict=True):
        serial = simulators.run_simulator("mujoco", sc, 1e-4)
        assert (b.t == serial.t).all() and (b.position == serial.position).all()
        assert [e.t for e in b.impacts] == [e.t for e in serial.impacts]
    fallback = simulators.run_batch("mujoco", scenes, 1e-4)  # no batch: serial runs
    assert [len(t.impacts) for t in fallback] == [len(t.impacts) for t in batch]


def test_restitution_runs_each_dt_and_phase_as_one_batch(batching):
    from harness.restitution.study import Grid, run_study

    grid = Grid(gammas=(0.5, 0.8), speeds=(1.0,), dts=(1e-4,), geometries=("vertex",))
    rows = run_study(["batchy"], grid)["engines"][0]["rows"]
    assert batching.CALLS == [2, 2, 2]  # three onset phases, two gammas each
    plain = run_study(["mujoco"], grid)["engines"][0]["rows"]
    assert [r["e_eff"] for r in rows] == [r["e_eff"] for r in plain]


def test_the_builtin_engines_loaded_without_metadata_are_the_ones_pyproject_registers():
    import tomllib

    from engines.builtin import BUILTIN_ENGINES

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    registered = project["project"]["entry-points"]["harness.engines"]
    assert registered == {name: f"engines.builtin:{a}" for name, a in BUILTIN_ENGINES.items()}


def test_a_plugin_cannot_take_a_builtin_name(plugins, monkeypatch):
    _dist_info(plugins / "more", "impostor", "1.0", "reference = toy_engine:simulate")
    monkeypatch.syspath_prepend(str(plugins / "more"))  # found first
    simulators.refresh()
    info = {i.name: i for i in simulators.engine_infos()}["reference"]
    assert info.target == "engines.builtin:reference"
    assert simulators.load_engine("reference").__module__ == "engines.builtin"
