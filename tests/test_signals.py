"""Signals at the command line's edge (harness.signals): SIGINT exits 130, SIGTERM 143,
each within about a second in engine stepping (Python) and in the reference's compiled
loop, nothing half written, and a signal swallowed on its way up (a finaliser's
"Exception ignored") still ends the command with its status, never 0."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from harness import signals, simulators
from harness.cli import main
from harness.outputs import TEMP_PREFIX

ROOT = Path(__file__).resolve().parent.parent
TOY = ROOT / "examples" / "toy-engine"

# A run the reference's compiled loop works on for far longer than the test waits: the
# elastic hexagon bouncing for 1e6 time units (about 8.5 impacts per unit, a few hundred
# thousand impacts a second); the loop returns to Python every work_budget steps.
LONG_REFERENCE_RUN = (ROOT / "reference" / "scenes" / "elastic-hexagon.toml").read_text()
LONG_REFERENCE_RUN = LONG_REFERENCE_RUN.replace("t_end = 20.0", "t_end = 1e6")
LONG_REFERENCE_RUN = LONG_REFERENCE_RUN.replace("max_impacts = 100000", "max_impacts = 10000000")


# SIGINT with Python's own handler, as an interactive shell starts a command: a test run
# started in the background (`make test &`, `nohup`) inherits SIGINT ignored, and the
# harness leaves an ignored SIGINT ignored (harness.signals.handled).
PYTHONS_SIGINT = "import signal; signal.signal(signal.SIGINT, signal.default_int_handler); "


@pytest.fixture
def pythons_sigint():
    """SIGINT handled by Python (KeyboardInterrupt) in this process for the test."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def _start(argv: list[str], cwd: Path) -> subprocess.Popen:
    """`harness ARGV` in a child that says `ready` on stderr once main() runs (SIGINT
    handled by Python there, whatever this process inherited)."""
    code = (
        f"{PYTHONS_SIGINT}import sys, harness.cli as c; sys.stderr.write('ready\\n'); "
        f"sys.stderr.flush(); sys.exit(c.main({argv!r}))"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stderr.readline().strip() == "ready"
    return proc


def _signal_and_wait(proc: subprocess.Popen, sig: int, after_s: float) -> tuple[int, float, str]:
    time.sleep(after_s)
    assert proc.poll() is None, "the run ended before the signal"
    proc.send_signal(sig)
    sent = time.monotonic()
    _, err = proc.communicate(timeout=30)
    return proc.returncode, time.monotonic() - sent, err


@pytest.mark.parametrize(
    "sig,status,line",
    [(signal.SIGTERM, 143, "harness: terminated"), (signal.SIGINT, 130, "harness: interrupted")],
)
def test_a_signal_stops_the_reference_loop_within_about_a_second(tmp_path, sig, status, line):
    scene = tmp_path / "long.toml"
    scene.write_text(LONG_REFERENCE_RUN)
    out = tmp_path / "run.parquet"
    proc = _start(["simulate", str(scene), "--out", str(out)], tmp_path)
    # after 1 s the loop runs: `simulate` reaches it ~0.3 s after the harness is imported
    code, latency, err = _signal_and_wait(proc, sig, after_s=1.0)
    assert code == status, err
    assert err.strip().splitlines()[-1] == line
    assert latency < 3.0  # the loop returns to Python every work_budget steps (~0.5 s)
    assert not out.exists() and not list(tmp_path.glob(f"{TEMP_PREFIX}*"))


@pytest.fixture
def toy(tmp_path, monkeypatch):
    """The pure-Python toy engine (examples/toy-engine), installed for this test."""
    info = tmp_path / "harness_toy_engine-0.1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: harness-toy-engine\nVersion: 0.1.0\n"
    )
    (info / "entry_points.txt").write_text("[harness.engines]\ntoy = toy_engine:simulate\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.syspath_prepend(str(TOY))
    simulators.refresh()
    yield
    simulators.refresh()


@pytest.mark.parametrize(
    "sig,status,reason",
    [(signal.SIGTERM, 143, "terminated (SIGTERM)"), (signal.SIGINT, 130, "interrupted (Ctrl-C)")],
)
def test_a_signal_in_engine_stepping_names_itself_and_exits_with_its_status(
    toy, pythons_sigint, tmp_path, capsys, sig, status, reason
):
    """In Python stepping (engines.stepping.run_steps) the run ends `failed` with the
    signal's reason, the steps so far kept in the summary, and no file written.  The run
    is bounded (200,000 toy steps, ~20 s here), so that a signal that does not stop it
    fails the test instead of holding its worker for the scene's whole 3 s (minutes)."""
    out = tmp_path / "toy.parquet"
    argv = ["simulate", "triangle-chatter", "--engine", "toy", "--dt", "1e-6", "--t-end", "0.2"]
    timer = threading.Timer(1.0, os.kill, (os.getpid(), sig))
    timer.start()
    t0 = time.monotonic()
    try:
        code = main([*argv, "--out", str(out)])
    finally:
        timer.cancel()
    captured = capsys.readouterr()
    assert code == status, (captured.out[-2000:], captured.err)
    assert reason in captured.out and "failed" in captured.out
    assert time.monotonic() - t0 < 1.0 + 2.0
    assert not out.exists()


def test_a_signal_swallowed_on_its_way_up_never_ends_in_exit_0(monkeypatch, capsys):
    """A SIGTERM whose exception a finaliser swallows ("Exception ignored in ...") still
    ends the command with 143, and nothing is moved into place after it."""
    import gc

    from harness.cli import scenes as scenes_command

    class SwallowsInFinaliser:
        def __del__(self):
            os.kill(os.getpid(), signal.SIGTERM)  # the handler raises here; Python ignores it

    def run(args):
        SwallowsInFinaliser()
        gc.collect()
        return 0

    monkeypatch.setattr(scenes_command, "run", run)  # registered by name at parse time
    monkeypatch.setattr("sys.unraisablehook", lambda unraisable: None)
    assert main(["scenes"]) == signals.EXIT_TERMINATED
    assert capsys.readouterr().err.strip().splitlines()[-1] == "harness: terminated"


def test_no_file_is_moved_into_place_after_a_swallowed_signal(tmp_path, monkeypatch):
    from harness.outputs import write_text

    monkeypatch.setattr(signals, "_received", [signal.SIGTERM])
    with pytest.raises(signals.Terminated):
        write_text(tmp_path / "late.txt", "after the signal")
    assert list(tmp_path.iterdir()) == []


def test_a_signal_is_forgotten_once_its_command_ended(toy, tmp_path):
    """After a command that was terminated, writing a file in the same process works."""
    from harness.outputs import write_text

    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGTERM))
    timer.start()
    try:
        code = main(["simulate", "triangle-chatter", "--engine", "toy", "--dt", "1e-6",
                     "--t-end", "0.2"])  # fmt: skip
    finally:
        timer.cancel()
    assert code == signals.EXIT_TERMINATED and signals.received() is None
    assert write_text(tmp_path / "after.txt", "fine").read_text() == "fine"


def test_a_signal_during_a_deferred_block_is_delivered_after_it():
    """signals.deferred: a SIGTERM sent inside the block (from another thread, as the
    kernel may deliver it there) does not cut the block; it is raised right after it."""
    steps = []
    with pytest.raises(signals.Terminated), signals.handled():
        with signals.deferred():
            sender = threading.Thread(target=os.kill, args=(os.getpid(), signal.SIGTERM))
            sender.start()
            sender.join()
            for _ in range(1000):  # bytecode boundaries, where Python runs handlers
                time.sleep(0)
            steps.append("the block ran to its end")
        steps.append("after the block")
    assert steps == ["the block ran to its end"]
