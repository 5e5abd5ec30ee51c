"""The rule for engines as extras (tests/conftest.py): a test whose engine extra is
missing is skipped with a one-line reason, and under CI=true it fails instead."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _run(tmp_path, ci: str | None):
    test = tmp_path / "test_ghost_engine.py"
    test.write_text(
        "from tests.conftest import require_extra\n"
        "def test_needs_ghost():\n"
        "    require_extra('no_such_engine_module_x7', 'ghost')\n"
        "def test_plain():\n"
        "    assert True\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    if ci is not None:
        env["CI"] = ci
    cmd = [sys.executable, "-m", "pytest", "-p", "tests.conftest", "-rs", "-q", str(test)]
    cmd += ["-p", "no:cacheprovider", "--rootdir", str(tmp_path)]
    return subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)


def test_a_missing_extra_skips_its_test_with_the_install_command(tmp_path):
    done = _run(tmp_path, None)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 passed, 1 skipped" in done.stdout
    assert "pip install 'euler-disk-harness[ghost]'" in done.stdout


@pytest.mark.parametrize("ci", ["true", "1"])
def test_under_ci_a_missing_extra_fails_its_test(tmp_path, ci):
    done = _run(tmp_path, ci)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "1 failed, 1 passed" in done.stdout
    assert "engine extra missing: no_such_engine_module_x7" in done.stdout
    assert "CI installs every extra" in done.stdout
