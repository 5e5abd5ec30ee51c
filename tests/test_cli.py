"""The `harness` command as users and outside checks call it (docs/contract.md)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq

from harness.cli import main

SIMULATE_FIELDS = {
    "engine",
    "scene",
    "status",
    "message",
    "t_final",
    "t_singularity",
    "impacts",
    "energy",
    "final_state",
    "stats",
}


def test_simulate_json_has_the_contract_fields(capsys):
    assert main(["simulate", "near-simultaneous", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert SIMULATE_FIELDS <= set(doc)
    assert doc["engine"] == "reference" and doc["scene"] == "near-simultaneous"
    assert {"t", "contact", "impulse"} <= set(doc["impacts"][0])
    assert {"position", "quaternion_wxyz", "velocity", "angular_velocity"} <= set(
        doc["final_state"]
    )
    assert doc["status"] in {"t_end", "singularity", "simultaneous_impact", "max_impacts", "failed"}
    assert "wall_time_s" in doc["stats"]


def test_undecidable_physics_is_a_result_with_exit_zero(capsys, tmp_path):
    scene = tmp_path / "square.toml"
    scene.write_text(
        'name = "square"\nrestitution = 0.5\n[body]\nn = 4\n[initial]\n'
        "q = [0.0, 0.0, 0.05]\np = [0.0, 0.0, -1.0]\n"
    )
    assert main(["simulate", str(scene), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["status"] == "simultaneous_impact"
    assert "0" in doc["message"]


def test_out_writes_samples_and_impacts_as_parquet(tmp_path, capsys):
    out = tmp_path / "run.parquet"
    assert main(["simulate", "near-simultaneous", "--t-end", "0.1", "--out", str(out)]) == 0
    samples = pq.read_table(out)
    impacts = pq.read_table(tmp_path / "run.impacts.parquet")
    assert {"t", "quaternion_w", "energy"} <= set(samples.column_names)
    assert impacts.num_rows == 5 and set(impacts.column("contact").to_pylist()) == {0, 1, 2, 3}
    meta = json.loads(samples.schema.metadata[b"summary"])
    assert meta["scene"] == "near-simultaneous"


def test_scale_option_scales_linear_coordinates(capsys):
    """q·ε², p·ε: the linear part of the energy (½ m v² + ½ I1 |ω|² + m g h) scales as
    ε² exactly; the full state adds ½ (I3 − I1) ω3² with ω3 = ω·e3 = O(|φ| |ω|), so the
    ratio E(ε)/(ε² E(1)) differs from 1 by at most O(|φ|²) (|φ| = 0.0117 here;
    measured 5.6e-7)."""
    assert main(["simulate", "pentagon-bounce", "--t-end", "0.001", "--json"]) == 0
    e1 = json.loads(capsys.readouterr().out)["energy"]["initial"]
    assert (
        main(["simulate", "pentagon-bounce", "--scale", "0.01", "--t-end", "0.001", "--json"]) == 0
    )
    e_eps = json.loads(capsys.readouterr().out)["energy"]["initial"]
    phi2 = 0.01**2 + 0.006**2  # |φ|² of pentagon-bounce's q
    assert abs(e_eps / (1e-4 * e1) - 1.0) <= phi2


def test_bad_input_exits_2_with_one_line_and_no_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\n[body]\nn = 1\n[initial]\nq = [0,0,1]\np = [0,0,0]\n')
    cases = [
        ["simulate", "no-such-scene"],
        ["simulate", str(bad)],
        ["simulate", "rod", "--engine", "nonsense"],
        ["simulate", "rod", "--t-end", "-1"],
        ["analyze", "chatter", "--n", "3", "--gyration", "0.3", "--restitution", "2"],
    ]
    exe = Path(sys.executable).with_name("harness")
    for args in cases:
        r = subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=60)
        assert r.returncode == 2, (args, r.stderr)
        lines = [x for x in r.stderr.splitlines() if x.strip()]
        assert len(lines) == 1, (args, r.stderr)
        assert "Traceback" not in r.stderr


def test_argument_errors_name_the_program_once_and_the_command(capsys):
    assert main(["nosuch"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("harness: error: argument COMMAND: invalid choice: 'nosuch'")
    assert err.count("harness") == 1
    assert main(["simulate", "rod", "--dt", "-1"]) == 2
    assert capsys.readouterr().err.startswith("harness: error: simulate: argument --dt")


def test_version_prints_the_installed_distribution_version(capsys):
    from importlib.metadata import version

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"harness {version('euler-disk-harness')}"


def test_scenes_lists_every_builtin(capsys):
    from harness.scenes import builtin_names

    assert main(["scenes"]) == 0
    out = capsys.readouterr().out
    for name in builtin_names():
        assert name in out


def test_selfsimilar_table_names_the_kind_of_every_solution(capsys):
    assert (
        main(["analyze", "selfsimilar", "--n", "25", "--gyration", "0.5", "--restitution", "0"])
        == 0
    )
    text = capsys.readouterr().out
    assert (
        main(
            [
                "analyze",
                "selfsimilar",
                "--n",
                "25",
                "--gyration",
                "0.5",
                "--restitution",
                "0",
                "--json",
            ]
        )
        == 0
    )
    doc = json.loads(capsys.readouterr().out)
    table = text.split("\n\n")[0]  # the legend follows after a blank line
    rows = [line.split() for line in table.splitlines()[3:]]
    assert len(rows) == len(doc["solutions"]) > 0
    for row, sol in zip(rows, doc["solutions"], strict=True):
        assert row[1] == ("trivial" if sol["trivial"] else "nontrivial")


def test_progress_is_shown_only_with_verbose_before_or_after_the_command(capsys):
    argv = ["compare", "near-simultaneous", "--engine", "reference", "--t-end", "0.05"]
    assert main(argv) == 0
    quiet = capsys.readouterr()
    assert quiet.err == "" and "reference" in quiet.out
    for loud in (["-v", *argv], [*argv, "--verbose"]):
        assert main(loud) == 0
        assert "compare: reference:" in capsys.readouterr().err


def test_pybullet_banner_does_not_reach_the_terminal():
    """PyBullet prints its build time from C on import; the adapter imports it quietly."""
    plain = subprocess.run(
        [sys.executable, "-c", "import pybullet"], capture_output=True, text=True, timeout=60
    )
    assert "build time" in plain.stdout + plain.stderr  # the banner this test is about
    quiet = subprocess.run(
        [sys.executable, "-c", "import engines.pybullet; print('ok')"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (quiet.stdout, quiet.stderr) == ("ok\n", "")


def test_figures_summary_says_for_each_claim_whether_it_was_reproduced():
    from harness.figures import format_figures

    doc = {
        "a": {"agree": True, "headline": "c = 2.01 (paper: 2)", "ours": "x"},
        "b": {"agree": False, "note": "only in part", "headline": "1 of 3", "ours": "x"},
        "c": {"agree": False, "ours": "c = 3.5 (paper: 2) " * 10},
    }
    text = format_figures(doc, Path("out"))
    lines = text.splitlines()
    assert max(map(len, lines)) <= 100
    assert any(
        line.split() == ["reproduced", "a:", "c", "=", "2.01", "(paper:", "2)"] for line in lines
    )
    assert any(line.strip().startswith("partly  b: 1 of 3") for line in lines)
    assert any(line.strip().startswith("NOT reproduced  c: c = 3.5") for line in lines)
    assert "{" not in text
