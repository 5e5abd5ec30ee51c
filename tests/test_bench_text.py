"""`harness bench`'s terminal text and summary: 100 columns by default with a legend,
`--wide` for every column, and a summary that counts only runs following the reference
(harness.metrics.follows)."""

from __future__ import annotations

from harness import bench as B
from harness.metrics.follows import follows_reference


def result(engine, t, err, matched, n, dt=None, rtol=None, status="simultaneous_impact"):
    return {
        "engine": engine,
        "setting": f"dt={dt:g}" if dt else (f"rtol={rtol:g} chatter={rtol:g}" if rtol else "exact"),
        "dt": dt,
        "contact_rtol": rtol,
        "chatter_tol": rtol,
        "wall_time_s": t,
        "wall_time_min_s": t,
        "status": status,
        "impacts_matched": matched,
        "reference_impacts": n,
        "impact_time_error": err,
        "energy_error": err,
        "energy_error_agreeing": err,
        "attitude_error_agreeing": err,
        "first_divergence_time": 1.234,
        "follows_reference": follows_reference(matched, n),
    }


def document():
    rows = [
        result("reference", 1e-3, 1e-7, 147, 596, rtol=1e-10),
        result("reference", 2e-3, 0.0, 596, 596, rtol=B.TRUTH[0]),
        result("mujoco", 0.03, 2e-3, 15, 338, dt=1e-3, status="t_end"),
        result("pybullet-default", 19.9, 9e-6, 1, 596, dt=1e-4, status="t_end"),
    ]
    return {
        "scene": "pentagon-bounce",
        "t_end": 2.4,
        "truth": {"setting": "rtol=1e-12 chatter=1e-06", "status": "t_end", "impacts": 596},
        "results": rows,
        "skipped": [],
        "derived": B.derive(rows),
        "repeats": 3,
        "load": {"before": [1.0, 1.0, 1.0], "after": [1.0, 1.0, 1.0]},
        "cpu_count": 2,
    }


def test_following_needs_nine_of_the_first_ten_impacts():
    assert follows_reference(15, 338) and follows_reference(9, 596)
    assert not follows_reference(8, 596) and not follows_reference(1, 596)
    assert not follows_reference(1, 2) and follows_reference(2, 2)
    assert follows_reference(0, 0)  # nothing to follow: nothing missed


def test_summary_counts_only_runs_that_follow_the_reference():
    derived = document()["derived"]["impact_time_error"]
    # pybullet-default's 9e-6 is the error of its one matched impact: not a result
    assert "pybullet-default" not in derived and "mujoco" in derived
    text = B.format_bench(document())
    row = next(line for line in text.splitlines() if line.endswith("follows the reference"))
    assert row.split() == ["pybullet-default", "-", "-", "no", "run", "follows", "the", "reference"]


def test_default_table_fits_100_columns_with_a_legend():
    text = B.format_bench(document())
    assert max(len(line) for line in text.splitlines()) <= 100
    rows = {line.split()[0]: line.split() for line in text.splitlines() if " 596 " in line}
    assert rows["pybullet-default"][5:8] == ["1", "596", "no"]  # matched, of, follows
    assert "15  338      yes" in text
    assert "a small `of`" in text  # the denominators explained


def test_wide_table_has_every_column():
    text = B.format_bench(document(), wide=True)
    assert "rtol=1e-10 chatter=1e-10" in text and "simultaneous_impact" in text
    assert "diverges at [s]" in text and "min [s]" in text
