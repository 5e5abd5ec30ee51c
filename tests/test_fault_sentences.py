"""A sentence for every fault: stdout on a full, closed or broken device, report inputs
nested too deeply or holding a huge integer, --plot names without an image suffix,
memory exhausted while writing, a worker pool that cannot start: each ends with exit
status 2 and one line on stderr, nothing written, never a traceback."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

from harness.cli import main

ROOT = Path(__file__).resolve().parent.parent


def _harness(argv: list[str], **kwargs) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-m", "harness", *argv],
        cwd=ROOT,
        env=env,
        stderr=subprocess.PIPE,
        text=True,
        timeout=300,
        **kwargs,
    )


def _one_error_line(err: str) -> str:
    lines = [line for line in err.strip().splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("harness: error:"), lines
    assert "Traceback" not in err
    return lines[0]


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_results_onto_a_full_device_are_one_line_and_exit_2():
    with open("/dev/full", "w") as full:
        run = _harness(["scenes"], stdout=full)
    assert run.returncode == 2
    assert "cannot write to stdout: No space left on device" in _one_error_line(run.stderr)


@pytest.mark.slow
@pytest.mark.parametrize(
    "argv", [["simulate", "triangle-chatter"], ["engines"], ["branches", "triangle-chatter"]]
)
def test_every_command_onto_a_full_device_is_one_line(argv):
    with open("/dev/full", "w") as full:
        run = _harness(argv, stdout=full)
    assert run.returncode == 2
    assert "cannot write to stdout" in _one_error_line(run.stderr)


@pytest.mark.slow
def test_a_closed_stdout_is_one_line_and_exit_2():
    run = _harness(["scenes"], stdout=subprocess.DEVNULL, preexec_fn=lambda: os.close(1))
    assert run.returncode == 2
    assert "stdout is closed" in _one_error_line(run.stderr)


@pytest.mark.slow
def test_a_pipe_closed_by_its_reader_is_one_line_and_exit_2():
    read, write = os.pipe()
    os.close(read)  # the reader is gone before anything is written: EPIPE
    try:
        run = _harness(["scenes"], stdout=write)
    finally:
        os.close(write)
    assert run.returncode == 2
    assert "Broken pipe" in _one_error_line(run.stderr)


def test_stdout_faults_inside_the_process_are_one_line(monkeypatch, capsys):
    class Full:
        def write(self, text):
            raise OSError(28, "No space left on device")

        def flush(self):
            raise OSError(28, "No space left on device")

    monkeypatch.setattr("sys.stdout", Full())
    assert main(["scenes"]) == 2
    assert "No space left on device" in _one_error_line(capsys.readouterr().err)


@pytest.mark.parametrize(
    "text,reason",
    [
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
        ('{"kind": "compare", "n": ' + "7" * 5000 + "}", "not a JSON document"),
    ],
    ids=["nested-1e5", "integer-5000-digits"],
)
def test_report_refuses_json_it_cannot_read_with_one_line(tmp_path, capsys, text, reason):
    doc = tmp_path / "doc.json"
    doc.write_text(text)
    out = tmp_path / "report.html"
    assert main(["report", str(doc), "--out", str(out)]) == 2
    assert reason in _one_error_line(capsys.readouterr().err)
    assert not out.exists()


@pytest.mark.parametrize("name", ["new.txt", "noext"])
@pytest.mark.parametrize(
    "command",
    [
        ["branches", "triangle-chatter"],
        ["transition"],
        ["bench", "triangle-chatter", "--engine", "linear"],
        ["fidelity", "pentagon-bounce", "--engine", "linear"],
    ],
    ids=lambda c: c[0],
)
def test_a_plot_name_without_an_image_suffix_is_refused_before_any_run(
    tmp_path, capsys, command, name
):
    plot = tmp_path / name
    assert main([*command, "--plot", str(plot)]) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert "--plot" in line and ("must end in" in line or "suffix must name" in line)
    assert list(tmp_path.iterdir()) == []


def test_memory_exhausted_while_writing_keeps_the_runs_status_and_writes_nothing(
    tmp_path, capsys, monkeypatch
):
    def exhausted(traj, path, force=False):
        raise MemoryError("cannot allocate the table")

    monkeypatch.setattr("harness.io.write_trajectory_parquet", exhausted)
    out = tmp_path / "run.parquet"
    argv = ["simulate", "triangle-chatter", "--engine", "linear", "--out", str(out)]
    assert main(argv) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert "out of memory while writing" in line and "nothing written" in line
    assert "the run itself ended" in line
    assert list(tmp_path.iterdir()) == []


def test_a_library_that_cannot_be_mapped_is_out_of_memory_in_one_line(
    tmp_path, capsys, monkeypatch
):
    """Under `ulimit -v` the loader cannot map a shared library (numba's LLVM, here at the
    first import of the linear kernel); its importer reports that as another OSError
    raised while handling the loader's.  The command says out of memory, in one line."""

    def unmappable(args):
        try:
            raise OSError("/venv/libllvmlite.so: failed to map segment from shared object")
        except OSError:
            raise OSError("Could not find/load shared object file 'libllvmlite.so'") from None

    monkeypatch.setattr("harness.cli.simulate.run", unmappable)
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "triangle-chatter", "--engine", "linear"]) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert line.startswith("harness: error: out of memory: ")
    assert "failed to map segment" in line and line.endswith("; nothing written")
    assert list(tmp_path.iterdir()) == []


def _address_space_limit():
    limit = 600_000 * 1024  # ulimit -v 600000
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


@pytest.mark.slow
def test_a_worker_pool_that_cannot_start_is_one_line_not_a_hang(tmp_path):
    out = tmp_path / "sweep"
    argv = ["sweep", "exponent", "--gyration", "0.5", "--restitution", "0.3:0.6:2"]
    argv += ["--samples", "4", "--engine", "linear", "--workers", "2", "--out", str(out)]
    run = _harness(argv, stdout=subprocess.DEVNULL, preexec_fn=_address_space_limit)
    if run.returncode == 0:
        pytest.skip("the pool started within 600 MB of address space on this machine")
    assert run.returncode == 2 and "Traceback" not in run.stderr
    last = run.stderr.strip().splitlines()[-1]  # after the progress bar's lines
    # the pool's start, or before it loading numba's LLVM (where the command needs more
    # address space than 600 MB; measured: 650 MB on the 2-core machine)
    assert last.startswith(
        ("harness: error: the local worker pool cannot run", "harness: error: out of memory")
    )
