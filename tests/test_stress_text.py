"""`harness stress`'s report: a verdict matrix within 100 columns with a legend, the
reasons of failed and skipped runs grouped, `--wide` for every measurement and reason."""

from __future__ import annotations

from harness.stress import format_stress

ENGINES = ["reference", "mujoco", "drake", "pybullet-default", "drake-continuous", "mujoco-default"]


def row(case, engine, verdict, reason=""):
    return {
        "case": case,
        "engine": engine,
        "verdict": verdict,
        "status": "t_end",
        "finished": True,
        "nan": False,
        "energy_gain": 0.0,
        "max_penetration": 1e-6,
        "penetration_relative": 1e-4,
        "missed_impacts": 0,
        "spurious_impacts": 0,
        "wall_time_s": 1.0,
        "reason": reason,
    }


def document():
    too_short = "dt (0.0001 s) must not exceed t_end (9.26009e-06 s)"
    rows = [row("alpha-1e-12", "reference", "ok")]
    rows += [row("alpha-1e-12", e, "skipped (not runnable)", too_short) for e in ENGINES[1:]]
    rows += [row("long-elastic-with-a-long-name", e, "ok") for e in ENGINES]
    rows[-2] = row(
        "long-elastic-with-a-long-name",
        "drake-continuous",
        "degraded",
        "3 missed, 2 spurious impacts (first mismatch: t=0.1, run t=0.2 (window 0.01))",
    )
    rows[-1] = row("long-elastic-with-a-long-name", "mujoco-default", "failed", "x" * 300)
    return {
        "cases": rows,
        "dt": 1e-4,
        "budget_s": 30.0,
        "wall_time_s": 10.0,
        "load": {"before": [1, 1, 1], "after": [1, 1, 1]},
        "cpu_count": 2,
    }


def test_default_report_fits_100_columns_with_a_legend():
    text = format_stress(document())
    assert max(len(line) for line in text.splitlines()) <= 100
    assert "FAILED: NaN" in text and "n/a:" in text  # the legend


def test_matrix_has_one_row_per_case_and_a_column_per_simulator():
    lines = format_stress(document()).splitlines()
    alpha = next(line for line in lines if line.startswith("alpha-1e-12 "))
    assert alpha.split() == ["alpha-1e-12", "ok"] + ["n/a"] * 5
    assert "-continuous" in lines[2] and "pybullet" in lines[1]  # names over two lines


def test_same_reason_shares_a_line_and_degraded_ones_are_counted():
    text = format_stress(document())
    assert "alpha-1e-12 / mujoco, drake, pybullet-default, drake-continuous, mujoco-default" in text
    assert "3 missed" not in text and "(1 degraded runs" in text


def test_wide_report_has_every_reason_in_full():
    text = format_stress(document(), wide=True)
    assert "x" * 300 in text and "(first mismatch: t=0.1, run t=0.2 (window 0.01))" in text
    assert "pen/L" in text
