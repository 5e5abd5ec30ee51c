"""Output names must match what is written (exit 2, one line, nothing written), and
`--record PATH` writes exactly PATH (docs/inputs.md)."""

from __future__ import annotations

import pytest

from harness.cli import main

QUICK = ["near-simultaneous", "--t-end", "0.01"]


@pytest.mark.parametrize(
    ("argv", "option", "suffix"),
    [
        (["simulate", *QUICK, "--out", "rod.csv"], "--out", ".parquet"),
        (["simulate", *QUICK, "--record", "foo.png"], "--record", ".rrd"),
        (["compare", *QUICK, "--engine", "linear", "--record", "cmp.txt"], "--record", ".rrd"),
        (["compare", *QUICK, "--engine", "linear", "--out", "diff.txt"], "table", ".csv"),
        (["bench", *QUICK, "--engine", "linear", "--out", "bench.csv"], "--out", ".json"),
        (["fidelity", "pentagon-bounce", "--out", "fid.txt"], "--out", ".json"),
        (["report", "x.json", "--out", "report.txt"], "report", ".html"),
    ],
)
def test_output_with_the_wrong_suffix_is_refused_before_any_work(
    argv, option, suffix, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "x.json").write_text("{}")
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith(f"harness: error: {option} ") and suffix in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.json"]  # nothing written


def test_record_writes_exactly_the_path_given(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", *QUICK, "--record", "run.rrd"]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.rrd"]  # no recordings/ folder
