"""The set-up's steps end their processes without Python's teardown
(reference.process_exit.exit_now), their output written and their status kept."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from tests.conftest import require_aot_core

ROOT = Path(__file__).resolve().parents[1]


def run_python(*args: str) -> subprocess.CompletedProcess:
    """`python *args` writing into pipes, block-buffered (as under `make`'s log
    redirection, unless PYTHONUNBUFFERED is set)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    return subprocess.run(
        [sys.executable, *args], cwd=ROOT, env=env, capture_output=True, text=True,
        timeout=60,
    )  # fmt: skip


def test_exit_now_writes_what_is_buffered_and_exits_with_the_status():
    run = run_python(
        "-c",
        "import sys; from reference.process_exit import exit_now; "
        "sys.stdout.write('out, unflushed'); sys.stderr.write('err, unflushed'); exit_now(3)",
    )
    assert (run.returncode, run.stdout, run.stderr) == (3, "out, unflushed", "err, unflushed")


def test_the_build_command_on_a_fresh_module_says_so_and_exits_0():
    require_aot_core()
    run = run_python("-m", "reference.core.aot")
    assert run.returncode == 0, run.stderr
    assert run.stdout == "the reference's ahead-of-time module is up to date\n"
