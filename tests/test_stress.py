"""`harness stress`: verdict logic on hand-made Trajectories, then one real tiny case."""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness import stress as S
from harness.metrics import match_tolerance
from harness.stress import budget as stress_budget
from harness.stress import cases as stress_cases
from harness.stress import judge as stress_judge
from harness.stress import study as stress_study
from reference.scene import Body, Ground, InitialState, RunSettings, Scene, SceneError
from reference.trajectory import ImpactEvent, Status, Trajectory

pytestmark = pytest.mark.usefixtures("fork_children")  # capped runs fork (conftest)


CONTRACT_ROW = {
    "case",
    "engine",
    "verdict",
    "status",
    "finished",
    "nan",
    "energy_gain",
    "max_penetration",
    "missed_impacts",
    "spurious_impacts",
}
H = 0.1  # initial height of the flat-lying triangle: its length scale L


def flat_scene() -> Scene:
    """A triangle lying level at height H: every vertex gap equals the centre's z."""
    return Scene(
        name="hand-made",
        body=Body(n=3),
        ground=Ground(),
        initial=InitialState((0.0, 0.0, H), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
        run=RunSettings(t_end=1.0),
    )


def level_run(z, energy, impacts=(), status=Status.T_END, dt=1e-3, engine="mujoco"):
    """A level body (identity attitude) at heights z(t) with the given total energy."""
    z = np.asarray(z, dtype=float)
    n = len(z)
    t = np.linspace(0.0, 1.0, n)
    pos = np.zeros((n, 3))
    pos[:, 2] = z
    return Trajectory(
        engine=engine,
        scene="hand-made",
        t=t,
        position=pos,
        quaternion=np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)),
        velocity=np.zeros((n, 3)),
        angular_velocity=np.zeros((n, 3)),
        kinetic_energy=np.zeros(n),
        potential_energy=np.asarray(energy, dtype=float),
        impacts=list(impacts),
        status=status,
        t_final=float(t[-1]),
        dt=dt,
    )


def test_length_scale_of_a_level_body_is_its_height():
    assert stress_judge.length_scale(flat_scene()) == pytest.approx(H, rel=1e-15)


def test_consistent_run_is_ok():
    row = S.assess(level_run([H, 0.05, 0.0, 0.05], [1.0, 0.9, 0.8, 0.8]), None, flat_scene(), 1.0)
    assert row["verdict"] == "ok"
    assert row["finished"] and not row["nan"]
    assert row["energy_gain"] == 0.0
    assert row["max_penetration"] == 0.0


def test_nan_run_fails():
    run = level_run([H, 0.05, np.nan, np.nan], [1.0, 0.9, np.nan, np.nan])
    row = S.assess(run, None, flat_scene(), 1.0)
    assert row["nan"] is True
    assert row["finished"] is False
    assert row["verdict"] == "failed"
    assert "NaN" in row["reason"]


def test_energy_gain_is_the_largest_relative_rise():
    # E0 = 2, peak 2.5: gain (2.5 - 2)/2 = 0.25 (> 10 %: failed); peak 2.01: 5e-3 degraded
    big = S.assess(level_run([H, H, H], [2.0, 2.5, 1.0]), None, flat_scene(), 1.0)
    assert big["energy_gain"] == pytest.approx(0.25, rel=1e-15)
    assert big["verdict"] == "failed" and "energy gain" in big["reason"]
    small = S.assess(level_run([H, H, H], [2.0, 2.01, 1.0]), None, flat_scene(), 1.0)
    assert small["energy_gain"] == pytest.approx(0.005, rel=1e-12)
    assert small["verdict"] == "degraded" and "energy gain" in small["reason"]


def test_penetrating_run_is_flagged_by_depth_relative_to_length_scale():
    # level body: every vertex gap is z, so z = -0.01 is a penetration of 0.01 = 0.1 L
    row = S.assess(level_run([H, -0.01, 0.0], [1.0, 1.0, 1.0]), None, flat_scene(), 1.0)
    assert row["max_penetration"] == pytest.approx(0.01, rel=1e-12)
    assert row["penetration_relative"] == pytest.approx(0.1, rel=1e-12)
    assert row["verdict"] == "degraded" and "penetration" in row["reason"]
    deep = S.assess(level_run([H, -0.2, 0.0], [1.0, 1.0, 1.0]), None, flat_scene(), 1.0)
    assert deep["verdict"] == "failed"


def test_exact_simulator_is_held_to_roundoff():
    # a 1e-6 energy gain is fine for an engine and degraded for the reference
    run = level_run([H, H], [1.0, 1.0 + 1e-6], dt=None, engine="reference")
    assert S.assess(run, None, flat_scene(), 1.0)["verdict"] == "ok"
    assert S.assess(run, None, flat_scene(), 1.0, exact=True)["verdict"] == "degraded"


def test_run_stopping_early_is_not_finished():
    run = level_run([H, H, H], [1.0, 1.0, 1.0])  # ends at t = 1
    row = S.assess(run, None, flat_scene(), 2.0)
    assert row["finished"] is False and row["verdict"] == "failed"
    stopped = level_run([H, H, H], [1.0, 1.0, 1.0], status=Status.SINGULARITY)
    assert S.assess(stopped, None, flat_scene(), 2.0)["finished"] is True


def test_a_stalled_run_fails_with_its_message_even_when_it_reached_t_end():
    run = level_run([H, H, H], [1.0, 1.0, 1.0], status=Status.STALLED)
    run.message = "the run stopped advancing at t = 1"
    row = S.assess(run, None, flat_scene(), 2.0)
    assert row["finished"] is False and row["verdict"] == "failed"
    assert "status stalled: the run stopped advancing" in row["reason"]
    assert S.assess(run, None, flat_scene(), 1.0)["verdict"] == "failed"


def test_exception_fails():
    row = S.assess(level_run([H], [1.0]), None, flat_scene(), 0.0, error="RuntimeError: boom")
    assert row["verdict"] == "failed" and "boom" in row["reason"]


def hit(t, k, v=-1.0):
    return ImpactEvent(t=t, contact=k, impulse=1.0, v_normal_pre=v, v_normal_post=-0.5 * v)


def test_unmatched_impacts_count_missed_and_spurious_in_any_order():
    ref = level_run([H] * 11, [1.0] * 11, [hit(0.1, 0), hit(0.2, 1), hit(0.3, 0)], dt=None)
    # the run swaps nothing, shifts one hit by 1e-4 s (< 3 dt), misses 0 @ 0.3, adds 2 @ 0.25
    run = level_run([H] * 11, [1.0] * 11, [hit(0.1001, 0), hit(0.2, 1), hit(0.25, 2)])
    tol = match_tolerance(run, ref, gravity=1.0)
    assert stress_judge.unmatched_impacts(run, ref, tol) == (1, 1, 3)
    row = S.assess(run, ref, flat_scene(), 1.0)
    assert row["missed_impacts"] == 1 and row["spurious_impacts"] == 1
    assert row["verdict"] == "degraded"
    # nothing in common: failed
    other = level_run([H] * 11, [1.0] * 11, [hit(0.5, 2)])
    assert S.assess(other, ref, flat_scene(), 1.0)["verdict"] == "failed"


def test_candidate_pairs_are_every_pair_within_its_window_closest_first():
    """unmatched_impacts' candidates (judge._closest_first) against every pair of the
    two lists tried one by one: |t_run − t_ref| ≤ the reference impact's window, sorted
    by that distance, then reference index, then run index; exact ties included (run
    impacts at reference times) and zero windows."""
    rng = np.random.default_rng(3)
    for _ in range(300):
        tr = np.sort(rng.uniform(0.0, 1.0, rng.integers(0, 25)))
        te = np.sort(np.concatenate([rng.uniform(0.0, 1.0, rng.integers(0, 25)), tr[:3]]))
        wr = rng.uniform(0.0, 0.1, tr.size) * (rng.random(tr.size) < 0.9)
        ir = np.flatnonzero(rng.random(tr.size) < 0.7)
        ie = np.flatnonzero(rng.random(te.size) < 0.7)
        every = sorted(
            (abs(te[j] - tr[i]), i, j) for i in ir for j in ie if abs(te[j] - tr[i]) <= wr[i]
        )
        want = [(int(i), int(j)) for _, i, j in every]
        assert stress_judge._closest_first(tr, wr, ir, te, ie) == want


def test_alpha_cases_start_at_their_inclination():
    cases = S.select_cases(["alpha"])
    assert [c.name for c in cases] == ["alpha-1e-3", "alpha-1e-6", "alpha-1e-9", "alpha-1e-12"]
    for case, alpha in zip(cases, stress_cases.ALPHAS, strict=True):
        # linear coordinates: the rotation vector (phi_x, phi_y, 0) has length alpha
        assert math.hypot(*case.scene.initial.rotation_vector) == pytest.approx(alpha, rel=1e-12)


def test_unknown_case_is_bad_input():
    with pytest.raises(SceneError):
        S.select_cases(["no-such-case"])


def test_real_tiny_case_gives_contract_rows(monkeypatch):
    doc = S.stress(engines=["reference", "mujoco"], cases=["grazing"], dt=1e-3)
    rows = doc["cases"]
    assert [(r["case"], r["engine"]) for r in rows] == [
        ("grazing", "reference"),
        ("grazing", "mujoco"),
    ]
    for r in rows:
        assert CONTRACT_ROW <= set(r)
        assert r["verdict"] in {"ok", "degraded", "failed"}
    ref = rows[0]
    assert ref["verdict"] == "ok" and ref["missed_impacts"] == 0 and ref["finished"]

    # an engine predicted over the budget is listed as skipped, not dropped
    monkeypatch.setattr(stress_study, "predict_engine_time", lambda *a: 1e9)
    doc = S.stress(engines=["mujoco"], cases=["grazing"], dt=1e-3, budget_s=1.0)
    (row,) = doc["cases"]
    assert row["verdict"] == S.SKIPPED and "budget" in row["reason"]
    assert "skipped" in S.format_stress(doc)


def test_run_past_the_hard_cap_is_stopped_and_reported(monkeypatch):
    import time

    def slow(*args, **kwargs):
        time.sleep(30.0)

    monkeypatch.setattr(stress_study, "predict_engine_time", lambda *a: None)
    monkeypatch.setattr(stress_budget, "run_simulator", slow)
    start = time.perf_counter()
    doc = S.stress(engines=["mujoco"], cases=["grazing"], budget_s=0.3)
    assert time.perf_counter() - start < 10.0
    (row,) = doc["cases"]
    assert row["verdict"] == S.SKIPPED and "hard cap" in row["reason"]


def test_engine_process_dying_is_a_failed_run(monkeypatch):
    import os

    monkeypatch.setattr(stress_study, "predict_engine_time", lambda *a: None)
    monkeypatch.setattr(stress_budget, "run_simulator", lambda *a, **k: os._exit(3))
    (row,) = S.stress(engines=["mujoco"], cases=["grazing"])["cases"]
    assert row["verdict"] == "failed" and "exit code 3" in row["reason"]
