"""`harness figures`: each of the paper's figures is drawn and judged, one test per figure
(so that a parallel run spreads them); `--only` draws the named ones alone."""

from __future__ import annotations

import json

import pytest

from harness.cli import build_parser, main
from harness.figures import FIGURES


@pytest.mark.parametrize("name", list(FIGURES))
def test_each_figure_is_drawn_with_a_verdict_on_the_paper_claim(name, tmp_path, capsys):
    assert main(["figures", "--only", name, "--out", str(tmp_path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert list(doc) == [name]
    assert isinstance(doc[name]["agree"], bool) and doc[name]["paper"] and doc[name]["ours"]
    assert [p.name for p in tmp_path.iterdir()] == [f"{name}.png"]


def test_only_names_every_figure_in_its_help_and_refuses_another():
    parser = build_parser(["figures"])
    sub = next(a for a in parser._actions if a.dest == "command").choices["figures"]
    only = next(a for a in sub._actions if a.dest == "only")
    assert all(name in only.help for name in FIGURES)
    assert main(["figures", "--only", "fig9", "--out", "x"]) == 2
