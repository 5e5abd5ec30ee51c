"""README.md's `## Commands` block runs as written, in order, from an empty folder: each
command exits 0, writes what it names (`--out`, `--plot`, `--record`) and finds every
file it reads (a path argument) among what the commands above it wrote.

The commands are read from the README itself, so the test keeps the README honest.  The
slow ones run with small settings: `SMALL` replaces the README's value of an option
(every occurrence) or adds it; nothing else is changed."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from harness.cli import main

README = Path(__file__).resolve().parent.parent / "README.md"
HARNESS = re.compile(r"^(?:\S*/)?harness\s+")
OUTPUT_OPTIONS = ("--out", "--plot", "--record")
WIDTH = 100  # columns every command's default output fits

# subcommand -> {option: values}: small settings for the slow commands (seconds, not
# minutes), replacing the README's values of these options.
SMALL: dict[str, dict[str, list[str]]] = {
    # horizon ensembles of 4 members, not 24: the same tables and verdicts
    "compare": {"--dt": ["1e-3"], "--horizon-runs": ["4"]},
    "bench": {"--engine": ["mujoco"], "--dt": ["1e-3"], "--repeats": ["1"]},
    "stress": {"--engine": ["mujoco"], "--case": ["grazing"]},
    "fidelity": {
        "--engine": ["mujoco"],
        "--dt": ["1e-3"],
        "--eps-grid": ["1:0.01:3"],
        "--horizon-runs": ["4"],
    },
    "sweep": {"--gyration": ["0.3:0.6:2"], "--restitution": ["0.2:0.4:2"], "--samples": ["5"]},
    # one figure (tests/test_paper_figures.py draws each of them)
    "figures": {"--only": ["rod_clin"]},
    "restitution": {
        "--engine": ["mujoco"],
        "--gamma": ["0.8"],
        "--speed": ["1"],
        "--dt": ["1e-4"],
        "--phase": ["0.5"],
    },
}


def readme_commands() -> list[str]:
    """The harness command lines of the first ```sh block under `## Commands`."""
    text = README.read_text(encoding="utf-8")
    section = text.split("\n## Commands", 1)[1]
    block = section.split("```sh\n", 1)[1].split("```", 1)[0]
    lines = [line.split(" #", 1)[0].strip() for line in block.splitlines()]
    return [line for line in lines if HARNESS.match(line)]


def with_small_settings(argv: list[str]) -> list[str]:
    """argv with the options of `SMALL[subcommand]` replaced by the small values."""
    small = SMALL.get(argv[0], {})
    out: list[str] = []
    skip = False
    for arg in argv:
        if skip:
            skip = False
        elif arg in small:
            skip = True
        else:
            out.append(arg)
    for option, values in small.items():
        for value in values:
            out += [option, value]
    return out


def outputs(argv: list[str]) -> list[str]:
    return [argv[i + 1] for i, a in enumerate(argv[:-1]) if a in OUTPUT_OPTIONS]


def path_inputs(argv: list[str]) -> list[str]:
    """Arguments that name files in the working folder (contain a '/') and are not
    outputs: what the command reads."""
    outs = set(outputs(argv))
    return [a for a in argv[1:] if "/" in a and not a.startswith("-") and a not in outs]


def test_readme_lists_the_commands():
    names = [shlex.split(HARNESS.sub("", line))[0] for line in readme_commands()]
    assert {"simulate", "compare", "bench", "report"} <= set(names)


def test_readme_commands_run_in_order_and_print_within_100_columns(tmp_path, monkeypatch, capsys):
    """Each command exits 0, writes what it names, and every line it prints (stdout and
    stderr, progress lines included) is at most WIDTH characters."""
    monkeypatch.chdir(tmp_path)
    for line in readme_commands():
        argv = with_small_settings(shlex.split(HARNESS.sub("", line)))
        for path in path_inputs(argv):
            assert Path(path).exists(), f"README: `{line}` reads {path}, not written above"
        rc = main(argv)
        out, err = capsys.readouterr()
        assert rc == 0, f"README: `{line}` exited {rc}: {err.strip()[-400:]}"
        for path in outputs(argv):
            assert Path(path).exists(), f"README: `{line}` did not write {path}"
        if "--json" not in argv:
            wide = [x for x in (out + err).splitlines() if len(x) > WIDTH]
            assert not wide, f"README: `{line}` prints lines over {WIDTH} columns: {wide}"


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (
            ["bench", "s", "--plot", "p.png", "--dt", "1e-4", "--dt", "1e-5"],
            ["bench", "s", "--plot", "p.png", "--engine", "mujoco", "--dt", "1e-3"]
            + ["--repeats", "1"],
        ),
        (["scenes"], ["scenes"]),
    ],
)
def test_small_settings_replace_the_readme_values(argv, expected):
    assert with_small_settings(argv) == expected
