"""The figures README.md and docs/api.md quote (written between markers by
scripts/docs_figures.py, `make docs-figures`) against what the code prints now: every
number exactly; wall times are masked, since the script re-measures them and a test
never asserts a time."""

from __future__ import annotations

import importlib.util
import json
import re
from pathlib import Path

import pytest

from harness.cli import main

ROOT = Path(__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location("docs_figures", ROOT / "scripts/docs_figures.py")
figures = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(figures)

WALL = re.compile(r"wall time [0-9.e+-]+ (?:s|ms|µs)")
TOGETHER = re.compile(r"[0-9.e+-]+ s together")


def quoted(path: Path, name: str) -> str:
    return figures.figure(path.read_text(encoding="utf-8"), name)


def block(text: str) -> str:
    """The content of the fenced block a figure holds."""
    return text.split("```text\n", 1)[1].split("```", 1)[0]


def masked(text: str) -> list[list[str]]:
    """The words of each line, with every wall time replaced by '*': 'wall time 0.75 ms'
    in sentences and the `wall [s]` column of a table (its last column)."""
    lines, in_table = [], False
    for line in WALL.sub("wall time *", text).splitlines():
        words = line.split()
        in_table = bool(words) and (in_table or line.rstrip().endswith("wall [s]"))
        if in_table and not line.rstrip().endswith("wall [s]"):
            words[-1] = "*"
        lines.append(words)
    return lines


@pytest.mark.parametrize(
    ("path", "name"),
    [
        ("README.md", "demo"),
        ("README.md", "stress"),
        ("README.md", "sweep"),
        ("README.md", "startup"),
        ("docs/performance.md", "startup"),
        ("docs/api.md", "api-output"),
        ("docs/api.md", "api-time"),
    ],
)
def test_every_quoted_figure_was_written_by_the_script(path, name):
    body = quoted(ROOT / path, name).strip()
    assert body and body != "?" and "```text\n```" not in body, (path, name)


def test_readme_stress_figure_is_what_stress_prints(capsys):
    assert main(figures.STRESS) == 0
    doc = json.loads(capsys.readouterr().out)
    want = TOGETHER.sub("* s together", figures.stress_summary(doc))
    assert TOGETHER.sub("* s together", quoted(ROOT / "README.md", "stress")) == want


def installed_engines_masked(text: str) -> str:
    """The example's output with its list of installed engines (`engine_names()`, which
    depends on the extras installed) as '[engines]'."""
    return re.sub(r"(?m)^\['reference', .*\]$", "[engines]", text)


def test_api_md_output_is_what_its_example_prints():
    out, _ = figures.run_api_example()
    quoted_out = block(quoted(ROOT / "docs/api.md", "api-output"))
    assert installed_engines_masked(quoted_out) == installed_engines_masked(out)


def test_readme_startup_ratio_is_the_one_performance_md_gives():
    readme = re.match(r"([0-9.]+)×", quoted(ROOT / "README.md", "startup"))
    row = quoted(ROOT / "docs/performance.md", "startup").strip().strip("|").split("|")
    assert readme and row[-1].strip() == f"{readme.group(1)}×"


def test_readme_demo_header_and_linear_row_are_what_compare_prints(capsys):
    """The demo's first lines (scene, law, reference) and the linear model's row, from a
    compare of the linear model alone (seconds; the whole demo: the slow test below)."""
    assert main(["compare", "triangle-chatter", "--engine", "linear"]) == 0
    ours = masked(capsys.readouterr().out)
    readme = masked(block(quoted(ROOT / "README.md", "demo")))
    head = next(i for i, words in enumerate(ours) if not words)
    first = next(i for i, words in enumerate(readme) if not words)
    assert sum(readme[:first], []) == sum(ours[:head], [])  # words: wrapping may differ
    row = next(words for words in ours if words[:1] == ["linear"])
    assert row in readme


@pytest.mark.slow
def test_readme_demo_is_what_the_demo_prints(capsys):
    assert main(figures.DEMO) == 0
    ours = masked(capsys.readouterr().out)
    readme = masked(block(quoted(ROOT / "README.md", "demo")))
    assert sum(readme, []) == sum(ours, [])  # word for word (wrapping follows the times)


@pytest.mark.slow
def test_readme_sweep_sentence_is_what_its_sweep_prints():
    assert quoted(ROOT / "README.md", "sweep") == figures.sweep_summary(figures.run_sweep())


def test_readme_sweep_sentence_is_about_the_readme_sweep_command():
    from tests.test_readme_commands import readme_commands

    sweep = next(line for line in readme_commands() if " sweep exponent " in line)
    assert sweep.split(" ", 1)[1].split(" --out ")[0].split() == figures.SWEEP[:-1]
