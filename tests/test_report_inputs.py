"""`harness report` refuses what is not a valid result document of its kind (one line
naming the field, exit 2, nothing written), links only to http(s) URLs and relative
files, and escapes every string; text from files reaches the terminal escaped; a BOM is
accepted and a FIFO named as one."""

from __future__ import annotations

import json
import os
import re

import pytest

from harness.cli import main
from harness.report.links import file_href, link_problem
from harness.text import terminal_safe
from reference.scene import show_path
from tests.conftest import harness_json


@pytest.fixture(scope="module")
def compare_doc():
    return harness_json(["compare", "pentagon-bounce", "--engine", "linear", "--t-end", "0.3"])


def report(tmp_path, capsys, doc, raw: bytes | None = None):
    src = tmp_path / "in.json"
    src.write_bytes(raw if raw is not None else json.dumps(doc).encode())
    out = tmp_path / "r.html"
    code = main(["report", str(src), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    return code, err, out


@pytest.mark.parametrize(
    "mutate,field",
    [
        (lambda d: d["engines"][0].pop("status"), "engines[0].status: missing"),
        (lambda d: d.update(engines="x"), "engines: a list expected, got a string"),
        (lambda d: d["reference"].update(t_final="soon"), "reference.t_final: a number expected"),
        (lambda d: d["engines"][0].update(impacts_matched=1.5), "impacts_matched: an integer"),
        (lambda d: d.pop("scene"), "field scene: missing"),
        (lambda d: d.update(recording="javascript:alert(document.domain)"), "not a javascript:"),
        (lambda d: d.update(recording="data:text/html,<b>x</b>"), "not a data: URL"),
    ],
    ids=["missing", "list-mistyped", "number-mistyped", "int-mistyped", "scene", "js", "data"],
)
def test_a_malformed_document_is_one_line_naming_the_field(
    tmp_path, capsys, compare_doc, mutate, field
):
    doc = json.loads(json.dumps(compare_doc))
    mutate(doc)
    code, err, out = report(tmp_path, capsys, doc)
    assert code == 2 and len(err) == 1 and field in err[0], err
    assert "not a valid compare document" in err[0]
    assert not out.exists()


def test_links_are_relative_files_or_http_and_every_string_is_escaped(
    tmp_path, capsys, compare_doc, monkeypatch
):
    monkeypatch.chdir(tmp_path)  # the recording's path is relative to the working folder
    doc = json.loads(json.dumps(compare_doc))
    doc["scene"] = "<script>alert(1)</script>"
    doc["recording"] = "javascript:x/../../run.rrd"  # a folder named 'javascript:x'
    code, err, out = report(tmp_path, capsys, doc)
    assert code == 2 and "not a javascript: URL" in err[0]
    doc["recording"] = "sub/javascript:alert(1).rrd"
    code, err, out = report(tmp_path, capsys, doc)
    assert code == 0, err
    html = out.read_text()
    assert "<script>" not in html and "&lt;script&gt;" in html
    hrefs = re.findall(r'href="([^"]*)"', html)
    assert hrefs == ["sub/javascript%3Aalert%281%29.rrd"]


def test_an_http_link_is_kept_and_other_schemes_are_refused(tmp_path):
    assert file_href("https://example.org/run.rrd", tmp_path) == "https://example.org/run.rrd"
    for bad in ("javascript:alert(1)", "JavaScript:alert(1)", " vbscript:x", "file:///etc/x"):
        assert link_problem(bad), bad
    assert link_problem("runs/a\x1b.rrd") == "a link with control characters"


def test_a_bom_json_is_read_and_a_fifo_is_named(tmp_path, capsys, compare_doc):
    code, err, out = report(
        tmp_path, capsys, None, b"\xef\xbb\xbf" + json.dumps(compare_doc).encode()
    )
    assert code == 0, err
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    assert main(["report", str(fifo), "--out", str(tmp_path / "f.html")]) == 2
    assert capsys.readouterr().err.strip() == (
        f"harness: error: {show_path(fifo)}: a FIFO (named pipe), not a regular file"
    )


def test_a_bom_scene_is_accepted_and_a_fifo_scene_named(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_bytes(
        b"\xef\xbb\xbf"
        + b'name = "bom"\n[body]\nn = 3\n[initial]\nq = [0.01, 0, 1]\np = [0, 0, -0.1]\n'
    )
    assert main(["simulate", str(scene), "--t-end", "0.01"]) == 0
    assert "bom" in capsys.readouterr().out
    fifo = tmp_path / "s2.toml"
    os.mkfifo(fifo)
    assert main(["simulate", str(fifo)]) == 2
    assert "a FIFO (named pipe), not a regular file" in capsys.readouterr().err


def test_names_from_files_reach_the_terminal_escaped(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(  # TOML escapes: ESC ] 0 ; title BEL, then a right-to-left override
        'name = "x\\u001b]0;pwned\\u0007\\u202ey"\n[body]\nn = 3\n'
        "[initial]\nq = [0.01, 0, 1]\np = [0, 0, -0.1]\n"
    )
    assert main(["simulate", str(scene), "--t-end", "0.01"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\x07" not in out and "\u202e" not in out
    assert "x\\x1b]0;pwned\\x07\\u202ey" in out


def test_terminal_safe_keeps_line_breaks_and_tabs():
    assert terminal_safe("a\tb\nc\rd\x00\x9b") == "a\tb\nc\\x0dd\\x00\\x9b"
