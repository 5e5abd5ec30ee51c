"""The Makefile's choice of installer (`INSTALLER`: uv by default, or pip), read from
`make -n` (what make would run, nothing run) for a venv that does not exist yet; an
unknown installer is refused before anything runs."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="no make here")


# what a make that runs the tests passes on to the makes they start (`make test
# INSTALLER=pip` sets INSTALLER in MAKEFLAGS): left out, so that the defaults are tested
MAKE_ENVIRONMENT = ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "INSTALLER")


def make_setup(tmp_path, *args) -> subprocess.CompletedProcess:
    """`make setup` with the venv in tmp_path (every step is then due)."""
    env = {k: v for k, v in os.environ.items() if k not in MAKE_ENVIRONMENT}
    return subprocess.run(
        ["make", "--no-print-directory", "setup", f"VENV={tmp_path / 'venv'}", *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )


@pytest.fixture(scope="module")
def dry_runs(tmp_path_factory) -> dict[str, subprocess.CompletedProcess]:
    """`make -n setup` with each installer (the default, then INSTALLER=pip), run once for
    this file's tests (each reads the make files and asks pip a question: ~2 s)."""
    venv = tmp_path_factory.mktemp("dry")
    return {"uv": make_setup(venv, "-n"), "pip": make_setup(venv, "-n", "INSTALLER=pip")}


def install_lines(out: str) -> list[str]:
    return [line for line in out.splitlines() if " install " in line]


def test_the_default_installer_is_uv_installed_by_pip(dry_runs):
    run = dry_runs["uv"]
    assert run.returncode == 0, run.stderr
    lines = install_lines(run.stdout)
    uv_by_pip = [line for line in lines if "'uv>=0.5'" in line]
    by_uv = [line for line in lines if line not in uv_by_pip]
    assert uv_by_pip and all(" -m pip --python " in line or "/bin/pip install" in line
                             for line in uv_by_pip)  # fmt: skip
    assert by_uv and all("/bin/uv pip install --python" in line for line in by_uv)
    assert any(line.endswith("-e '.[all,dev]'") for line in by_uv)


def test_the_set_up_names_its_installer_before_it_installs(dry_runs):
    for installer, run in dry_runs.items():
        lines = run.stdout.splitlines()
        named = [i for i, line in enumerate(lines) if line.startswith('echo "  installer: ')]
        first_install = min(i for i, line in enumerate(lines) if " install " in line)
        assert named and named[0] < first_install
        assert lines[named[0]].startswith(f'echo "  installer: {installer} (')


def test_installer_pip_installs_every_package_with_pip(dry_runs):
    run = dry_runs["pip"]
    assert run.returncode == 0, run.stderr
    lines = install_lines(run.stdout)
    assert lines and not any("uv" in line for line in lines)
    assert any("/bin/pip install --progress-bar off --no-compile -e '.[all,dev]'" in line
               for line in lines)  # fmt: skip


def test_an_unknown_installer_is_refused_with_one_line_and_status_2(tmp_path):
    run = make_setup(tmp_path, "INSTALLER=conda")
    assert run.returncode == 2
    assert run.stdout == ""
    [line] = run.stderr.splitlines()
    assert line.startswith("Makefile:")
    assert line.endswith("*** INSTALLER is uv or pip, not 'conda'.  Stop.")
    assert list(tmp_path.iterdir()) == []
