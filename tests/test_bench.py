"""`harness bench`: interpolation rules against analytic curves, then a short real study."""

from __future__ import annotations

import math

import pytest

from harness import bench as B
from harness.scenes import resolve_scene

CONTRACT_ROW = {
    "engine",
    "setting",
    "wall_time_s",
    "impacts_matched",
    "impact_time_error",
    "energy_error",
}


def test_predicted_time_scales_as_one_over_dt_from_one_point():
    assert B.predict_time([(1e-3, 2.0)], 1e-4) == pytest.approx(20.0, rel=1e-12)


def test_predicted_time_follows_the_measured_power():
    # t = dt^-2: 1 at 1, 100 at 0.1  ->  10^4 at 0.01
    assert B.predict_time([(1.0, 1.0), (0.1, 100.0)], 0.01) == pytest.approx(1e4, rel=1e-12)
    # never cheaper than 1/dt, even if the finer step measured faster
    assert B.predict_time([(1.0, 1.0), (0.1, 0.5)], 0.01) == pytest.approx(5.0, rel=1e-12)


def test_pareto_front_keeps_only_improving_points():
    pts = [(3.0, 1e-3), (1.0, 1e-2), (2.0, 2e-2), (4.0, 1e-4)]
    assert B.pareto_front(pts) == [(1.0, 1e-2), (3.0, 1e-3), (4.0, 1e-4)]


def test_loglog_interpolation_is_exact_on_a_power_law():
    xs, ys = [1.0, 100.0], [1e-2, 1e-6]  # y = 1e-2 x^-2
    y, where = B.loglog_interp(10.0, xs, ys)
    assert where == "interpolated" and y == pytest.approx(1e-4, rel=1e-12)
    assert B.loglog_interp(1000.0, xs, ys) == (1e-6, "above")
    assert B.loglog_interp(0.5, xs, ys) == (1e-2, "below")


def row(engine, t, err, dt=None, rtol=None):
    return {
        "engine": engine,
        "wall_time_s": t,
        "status": "t_end",
        "dt": dt,
        "contact_rtol": rtol,
        "energy_error_agreeing": err,
        "energy_error": err,
        "impact_time_error": err,
    }


def test_derived_numbers_on_power_laws():
    rows = [
        row("reference", 1.0, 1e-3, rtol=1e-6),
        row("reference", 4.0, 1e-5, rtol=B.TRUTH[0]),
        row("mujoco", 1.0, 1e-2, dt=1e-3),
        row("mujoco", 100.0, 1e-4, dt=1e-5),
    ]
    d = B.derive(rows)["energy_error_agreeing"]["mujoco"]
    # the reference (tightest) costs 4 s; mujoco's curve is err = 1e-2 t^-1
    assert d["reference_cost_s"] == 4.0
    assert d["error_at_reference_cost"] == pytest.approx(2.5e-3, rel=1e-12)
    assert d["error_at_reference_cost_bound"] == "exact"
    # at mujoco's best (1e-4, 100 s) the reference needs 2 s (log-midway between 1e-3 @ 1 s
    # and 1e-5 @ 4 s): ratio 50
    assert d["cost_ratio"] == pytest.approx(50.0, rel=1e-12)
    assert d["cost_ratio_bound"] == "exact"
    # an accuracy every reference setting beats: the ratio is a lower bound
    rows[3]["energy_error_agreeing"] = 5e-3
    d = B.derive(rows)["energy_error_agreeing"]["mujoco"]
    assert d["cost_ratio"] == pytest.approx(100.0, rel=1e-12)
    assert d["cost_ratio_bound"] == "lower"


def test_short_bench_returns_contract_fields_and_a_plot(tmp_path):
    scene = resolve_scene("triangle-chatter")
    png = tmp_path / "wp.png"
    doc = B.bench(
        scene,
        engines=["reference", "mujoco"],
        dts=[1e-3, 5e-4],
        t_end=0.3,
        repeats=1,
        plot=png,
        reference_settings=[(1e-6, 1e-3), B.TRUTH],
    )
    assert doc["scene"] == "triangle-chatter"
    rows = doc["results"]
    assert [(r["engine"], r["setting"]) for r in rows] == [
        ("reference", "rtol=1e-06 chatter=0.001"),
        ("reference", "rtol=1e-12 chatter=1e-06"),
        ("mujoco", "dt=0.001"),
        ("mujoco", "dt=0.0005"),
    ]
    for r in rows:
        assert CONTRACT_ROW <= set(r)
        assert r["wall_time_s"] > 0
    tight = rows[1]
    assert tight["impacts_matched"] == tight["reference_impacts"] == doc["truth"]["impacts"] > 0
    assert tight["impact_time_error"] == 0.0
    assert tight["energy_error"] == 0.0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "mujoco" in doc["derived"]["energy_error"]
    text = B.format_bench(doc)
    assert any(line.split()[:2] == ["mujoco", "5e-4"] for line in text.splitlines())
    assert "load average" in text


def test_settings_over_budget_are_skipped_and_listed():
    scene = resolve_scene("triangle-chatter")
    doc = B.bench(
        scene, engines=["mujoco"], dts=[1e-3, 1e-4, 1e-5], t_end=0.1, repeats=1, budget_s=1e-9
    )
    # the coarsest step always runs; every finer one is predicted over the budget
    assert [r["setting"] for r in doc["results"] if r["engine"] == "mujoco"] == ["dt=0.001"]
    assert [s["dt"] for s in doc["skipped"]] == [1e-4, 1e-5]
    assert all(math.isfinite(s["predicted_wall_time_s"]) for s in doc["skipped"])
