"""What happens while a run runs: Ctrl-C keeps what was computed (exit status 130),
MuJoCo's warnings stay out of stdout and the working directory, and every option of every
command explains itself."""

from __future__ import annotations

import argparse
import json
import re

import numpy as np
import pytest

import engines.mujoco as M
import engines.pybullet as PB
from harness.cli import build_parser, main
from reference.scene import Body, Ground, InitialState, RunSettings, Scene, SceneError
from tests.conftest import make_scene, require_aot_core


class StopAt:
    """A progress callback that raises KeyboardInterrupt (as Ctrl-C does) at call k."""

    def __init__(self, k: int) -> None:
        self.k, self.calls = k, []

    def __call__(self, done: int, total: int) -> None:
        self.calls.append(done)
        if len(self.calls) == self.k:
            raise KeyboardInterrupt

    def close(self) -> None:
        pass


def test_ctrl_c_stops_mujoco_and_keeps_the_whole_chunks_done(monkeypatch):
    monkeypatch.setattr(M, "CHUNK_STEPS", 100)
    stop = StopAt(3)  # called before chunks 0, 1, 2: interrupted after 200 steps
    traj = M.simulate_mujoco(make_scene(n=3, t_end=0.05), 1e-4, progress=stop)
    assert stop.calls == [0, 100, 200]
    assert traj.status.value == "failed" and traj.stats["interrupted"]
    assert "interrupted" in traj.message and traj.n_samples == 201
    assert traj.t[-1] == pytest.approx(0.02) and np.isfinite(traj.energy).all()


def test_ctrl_c_stops_pybullet_and_keeps_the_steps_read(monkeypatch):
    monkeypatch.setattr(PB, "CHUNK_STEPS", 50)
    stop = StopAt(3)  # called before chunks 0, 1, 2: raised after step 100
    traj = PB.simulate_pybullet(make_scene(n=3, t_end=0.05), 1e-4, progress=stop)
    assert stop.calls == [0, 50, 100]
    assert traj.status.value == "failed" and traj.stats["interrupted"]
    assert 0 < traj.t[-1] < 0.0101 and np.isfinite(traj.energy).all()


def test_simulate_stopped_by_ctrl_c_prints_the_part_computed_writes_nothing_exits_130(
    monkeypatch, tmp_path, capsys
):
    import harness.cli.simulate as S

    monkeypatch.setattr(M, "CHUNK_STEPS", 100)
    monkeypatch.setattr(S, "StepProgress", lambda label: StopAt(2))
    monkeypatch.chdir(tmp_path)
    argv = ["simulate", "triangle-chatter", "--engine", "mujoco", "--t-end", "0.05"]
    assert main([*argv, "--out", "run.parquet", "--json"]) == 130
    out, err = capsys.readouterr()
    doc = json.loads(out)
    assert doc["status"] == "failed" and "interrupted" in doc["message"]
    assert doc["t_final"] == pytest.approx(0.01)
    assert "no file written" in err and list(tmp_path.iterdir()) == []


def unresolvable_scene() -> Scene:
    """Beyond the accepted ranges (built directly, not through scene validation): a spin
    of 1e300 rad/s, which MuJoCo turns into NaN at its first step."""
    return Scene(
        name="nan",
        body=Body(n=3, gyration=0.3),
        ground=Ground(),
        initial=InitialState((0, 0, 0.1), (0.02, 0, 0), (0, 0, 0), (1e300, 0, 0)),
        run=RunSettings(t_end=0.01),
    )


def test_mujoco_warnings_go_to_the_run_not_to_stdout_or_a_log_file(monkeypatch, tmp_path, capfd):
    from harness.guard import guard_trajectory
    from harness.simulators import load_engine, run_simulator

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError, match="initial speed"):  # the API checks it too
        run_simulator("mujoco", unresolvable_scene())
    scene = unresolvable_scene()  # handed to the adapter itself, past the checks
    traj = guard_trajectory(scene, load_engine("mujoco")(scene, dt=1e-4, t_end=0.01))
    out, _ = capfd.readouterr()
    assert out == "" and list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT
    assert traj.status.value == "failed" and "non-finite" in traj.message
    assert np.isfinite(traj.energy).all()
    run = M.run_mujoco(unresolvable_scene(), 1e-4)
    assert any("Nan, Inf or huge value" in w for w in run.stats["mujoco_warnings"])


# ----------------------------------------------------------------------------- help


def every_parser(parser: argparse.ArgumentParser, prefix: str = "harness"):
    yield prefix, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from every_parser(sub, f"{prefix} {name}")


def test_every_option_of_every_command_has_help():
    missing = [
        f"{where} {action.option_strings or action.dest}"
        for where, parser in every_parser(build_parser())
        for action in parser._actions
        if not isinstance(action, argparse._SubParsersAction)
        and action.help != argparse.SUPPRESS
        and not (action.help or "").strip()
    ]
    assert missing == []


def test_every_options_help_states_its_default_once():
    """The formatter appends "(default: …)"; a help text that also names the default
    prints it twice."""
    twice = []
    for where, parser in every_parser(build_parser()):
        formatter = parser._get_formatter()
        for action in parser._actions:
            if action.help and action.help != argparse.SUPPRESS:
                text = formatter._get_help_string(action) % {"default": action.default}
                if len(re.findall(r"\bdefault\b", text)) > 1:
                    twice.append(f"{where} {action.option_strings}: {text}")
    assert twice == []


def test_help_shows_defaults_and_units(capsys):
    assert main(["simulate", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "[s]" in text and "(default: 10000000)" in text and "(default: reference)" in text


@pytest.mark.parametrize(
    "analysis,columns",
    [
        ("selfsimilar", ["beta", "feasible", "stable", "spectral radius", "tau0", "failed checks"]),
        ("chatter", ["CC", "PCC", "beta_p, beta_q", "c_lin", "spectral radius"]),
    ],
)
def test_analyze_help_and_output_explain_the_columns(capsys, analysis, columns):
    assert main(["analyze", analysis, "--help"]) == 0
    text = capsys.readouterr().out
    assert all(c in text for c in columns)
    # chatter at rho = 0.3, gamma = 0.2 has a self-similar pair: the table is printed
    gamma = "0.2" if analysis == "chatter" else "0.5"
    argv = ["analyze", analysis, "--n", "3", "--gyration", "0.3", "--restitution", gamma]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert all(c in out for c in columns)


HEAVY = ("numba", "scipy", "pandas", "pyarrow", "matplotlib", "tqdm", "rerun", "dask")


def test_simulate_with_the_compiled_core_imports_no_heavy_library():
    """Start-up: `harness simulate pentagon-bounce --json` with the ahead-of-time core
    imports numpy and the package only (docs/performance.md)."""
    import subprocess
    import sys
    from pathlib import Path

    require_aot_core()
    code = (
        "import sys\n"
        "from harness.cli import main\n"
        "assert main(['simulate', 'pentagon-bounce', '--json']) == 0\n"
        f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))\n"
    )
    root = Path(__file__).resolve().parent.parent
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=root
    )
    assert done.stdout.splitlines()[-1] == "[]"
