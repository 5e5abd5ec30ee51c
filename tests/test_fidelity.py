"""`harness fidelity`: the leading impacts, α* and its power law in dt, the budget, the CLI.

The end-to-end tests use an engine installed for the test as a plug-in (a dist-info on
sys.path, as pip writes it): it returns the exact motion when the motion's time scale ε
is at least K·dt and nothing otherwise, so its fidelity limit is known in advance:
ε* = the smallest grid ε ≥ K·dt, α* = α(ε*) ≈ ε*² α(1), and k = 2."""

from __future__ import annotations

import json
import math
import textwrap

import numpy as np
import pytest

from harness import simulators
from harness.cli import main
from harness.fidelity import FidelityCriteria, alpha_star, eps_values, fidelity, power_law_fit
from harness.fidelity.criteria import exponent_check, impacts_pass
from harness.fidelity.leading import leading_impacts, run_end
from harness.metrics import RELATIVE_TIME_TOLERANCE, STEPS_TIME_TOLERANCE
from harness.scenes import resolve_scene
from reference.simulate import simulate

K = 10.0  # the plug-in follows the motion when ε >= K dt
P0 = (0.05, 0.02, -0.1)  # pentagon-bounce's p at ε = 1

FAKE_ENGINE = f'''
"""Follows the exact motion when its time scale eps >= {K} dt (eps from |p|), else fails."""
import dataclasses, math
from reference.simulate import simulate
from reference.trajectory import Trajectory

P0 = math.hypot(*{P0!r})


def simulate_resolving(scene, *, dt, t_end=None):
    eps = math.hypot(*scene.initial.p) / P0
    if eps < {K} * dt * (1 - 1e-9):
        return Trajectory.failed("resolving", scene.name, dt, "motion faster than its steps")
    return dataclasses.replace(simulate(scene, t_end=t_end), engine="resolving", dt=dt)


simulate_resolving.fixed_step = True
'''


@pytest.fixture
def resolving_engine(tmp_path, monkeypatch):
    """The plug-in engine `resolving`, installed for this test only."""
    info = tmp_path / "resolving_engine-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: resolving-engine\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        "[harness.engines]\nresolving = resolving_engine:simulate_resolving\n"
    )
    (tmp_path / "resolving_engine.py").write_text(textwrap.dedent(FAKE_ENGINE))
    monkeypatch.syspath_prepend(str(tmp_path))
    simulators.refresh()
    yield "resolving"
    simulators.refresh()


# ----------------------------------------------------------------------------- α*


def _rows(verdicts, alphas=None):
    """Rows of one engine and dt: verdicts True / False / None (skipped), largest α first."""
    alphas = alphas or [10.0**-k for k in range(len(verdicts))]
    return [
        {"alpha": a, "eps": math.sqrt(a), "passes": v, "skipped": None if v is not None else "x"}
        for a, v in zip(alphas, verdicts, strict=True)
    ]


def test_alpha_star_is_the_smallest_alpha_passed_before_the_first_failure():
    star = alpha_star(_rows([True, True, False, True, False]))
    assert star["alpha_star"] == 1e-1 and star["alpha_first_fail"] == 1e-2
    assert star["bound"] == "bracket"
    assert star["passes_below"] == [1e-3]  # luck after a failure is not fidelity
    assert (star["alpha_lowest_pass"], star["alpha_below_lowest_pass"]) == (1e-3, 1e-4)
    assert (star["runs"], star["passes"]) == (5, 3)


def test_skipped_scales_do_not_interrupt_the_walk_and_are_counted():
    star = alpha_star(_rows([None, None, True, True, False]))
    assert star["alpha_star"] == 1e-3 and star["bound"] == "bracket" and star["skipped"] == 2


def test_alpha_star_at_the_edges_of_the_grid_says_so():
    everywhere = alpha_star(_rows([True, True, True]))
    assert everywhere["bound"] == "at most" and everywhere["alpha_star"] == 1e-2
    nowhere = alpha_star(_rows([False, True]))
    assert nowhere["bound"] == "above grid" and nowhere["alpha_star"] is None
    assert nowhere["alpha_first_fail"] == 1.0
    assert alpha_star(_rows([None, None]))["bound"] == "not measured"


def test_the_impact_criterion_is_a_fraction_of_the_leading_impacts():
    c = FidelityCriteria(leading=10, match_fraction=0.9)
    assert impacts_pass(9, 10, c) and not impacts_pass(8, 10, c) and not impacts_pass(0, 0, c)
    assert impacts_pass(7, 10, FidelityCriteria(match_fraction=0.7))


def test_the_exponent_criterion_applies_only_where_both_runs_have_a_c():
    c = FidelityCriteria(c_tolerance=0.1)
    assert exponent_check(2.1, 2.0, c)[0] is True
    assert exponent_check(2.3, 2.0, c)[0] is False
    verdict, why = exponent_check(None, 2.0, c, run_reason="ended t_end")
    assert verdict is None and "ended t_end" in why
    assert exponent_check(2.0, None, c, ref_reason="ended simultaneous_impact")[0] is None


def test_power_law_fit_matches_numpy_least_squares_with_its_standard_error():
    dts = np.array([1e-3, 3e-4, 1e-4, 3e-5, 1e-5])
    rng = np.random.default_rng(3)
    alphas = 7.0 * dts**1.8 * 10 ** rng.normal(0, 0.1, dts.size)
    fit = power_law_fit(dts, alphas)
    coef, cov = np.polyfit(np.log10(dts), np.log10(alphas), 1, cov=True)
    assert fit["k"] == pytest.approx(coef[0], rel=1e-12)
    assert fit["log10_A"] == pytest.approx(coef[1], rel=1e-12)
    assert fit["k_stderr"] == pytest.approx(math.sqrt(cov[0, 0]), rel=1e-9)


def test_the_grid_interval_of_k_is_what_the_brackets_allow():
    """Exact α* = dt² at dt = 1e-3, 1e-5 on a grid a decade apart: the thresholds can lie
    anywhere in (α*/10, α*], so k can be 2 ± 1/2 (one decade over two decades of dt)."""
    dts = [1e-3, 1e-5]
    fit = power_law_fit(dts, [d**2 for d in dts], [d**2 / 10 for d in dts])
    assert fit["k"] == pytest.approx(2.0) and fit["k_stderr"] is None
    assert fit["k_grid"] == pytest.approx([1.5, 2.5])
    assert power_law_fit([1e-3], [1e-6])["k"] is None


# ----------------------------------------------------------------------------- leading


def test_leading_impacts_are_the_same_impacts_at_every_scale():
    """Under the scaling the leading impacts keep their contacts and t/ε to O(α)."""
    scene = resolve_scene("triangle-chatter")
    out = []
    for eps in (1.0, 1e-3):
        s = scene.scaled(eps)
        ref = simulate(s, t_end=eps * scene.run.t_end)
        lead = leading_impacts(ref, 10, s.gravity)
        out.append((ref, lead, eps))
    (r1, l1, _), (r2, l2, e2) = out
    assert l1.n == l2.n == 10
    assert np.array_equal(r1.impact_contacts()[l1.indices], r2.impact_contacts()[l2.indices])
    t1, t2 = r1.impact_times()[l1.indices], r2.impact_times()[l2.indices] / e2
    assert np.max(np.abs(t2 - t1)) < 0.05 * 0.02 * t1.max()  # O(α), α(1) = 0.02
    speeds = np.array([-e.v_normal_pre for e in r1.impacts])
    assert np.all(speeds[l1.indices] > 0)


def test_an_engine_runs_past_the_last_leading_impact_by_the_matching_window():
    scene = resolve_scene("pentagon-bounce")
    ref = simulate(scene)
    lead = leading_impacts(ref, 10, scene.gravity)
    t_last, dt = lead.t_last, 1e-3
    end = run_end(lead, ref.t_final, scene.run.t_end, dt, "leading")
    window = STEPS_TIME_TOLERANCE * dt + RELATIVE_TIME_TOLERANCE * t_last
    assert end >= t_last + window and end >= 0.5 * (t_last + lead.t_next)
    assert end < ref.impact_times()[lead.indices[-1] + 2]
    whole = run_end(lead, ref.t_final, scene.run.t_end, dt, "whole")
    assert ref.t_final < whole <= scene.run.t_end


def test_eps_values_are_log_spaced_largest_first():
    assert eps_values(1.0, 1e-4, 5) == pytest.approx([1.0, 0.1, 0.01, 1e-3, 1e-4])


# ----------------------------------------------------------------------------- end to end


def test_an_engine_that_follows_motions_slower_than_k_steps_has_k_equal_2(resolving_engine):
    scene = resolve_scene("pentagon-bounce")
    dts = [1e-2, 1e-3]
    doc = fidelity(scene, [resolving_engine], dts, eps_values(1.0, 1e-3, 7))
    stars = {s["dt"]: s for s in doc["alpha_star"]}
    alpha_at = {r["eps"]: r["alpha"] for r in doc["reference"]}
    for dt in dts:
        eps_star = min(e for e in alpha_at if e >= K * dt * (1 - 1e-9))
        assert stars[dt]["eps_star"] == pytest.approx(eps_star)
        assert stars[dt]["alpha_star"] == alpha_at[stars[dt]["eps_star"]]
        assert stars[dt]["bound"] == "bracket"
    fit = doc["fits"][0]
    assert fit["k"] == pytest.approx(2.0, abs=1e-3)  # α ∝ ε² up to O(α)
    assert fit["lowest"]["k"] == pytest.approx(fit["k"])  # monotone: no transition band
    for row in doc["runs"]:
        if row["passes"]:
            assert row["leading_matched"] == row["leading"] == 10
            assert row["impact_time_error_s"] == 0.0
            assert row["c_check"].startswith("not compared")  # stopped after the leading ones


def test_a_run_predicted_over_the_budget_is_skipped_with_every_larger_scale(resolving_engine):
    scene = resolve_scene("pentagon-bounce")
    eps = eps_values(1.0, 1e-2, 3)
    doc = fidelity(scene, [resolving_engine], [1e-4], eps, budget_s=1e-9)
    rows = sorted(doc["runs"], key=lambda r: r["eps"])
    assert rows[0]["skipped"] is None and rows[0]["passes"]  # nothing measured yet: run
    assert "predicted" in rows[1]["skipped"] and "> budget" in rows[1]["skipped"]
    assert rows[2]["skipped"].startswith("skipped: eps=")
    star = doc["alpha_star"][0]
    assert star["bound"] == "at most" and star["skipped"] == 2


def test_cli_fidelity_json_one_alpha_star_per_engine_and_dt_with_provenance(
    resolving_engine, tmp_path, capsys
):
    out = tmp_path / "fid.json"
    argv = ["fidelity", "pentagon-bounce", "--engine", resolving_engine, "--dt", "1e-2"]
    argv += ["--dt", "1e-3", "--eps-grid", "1:1e-2:3", "--json", "--out", str(out)]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    assert json.loads(out.read_text()) == doc
    assert [(s["engine"], s["dt"]) for s in doc["alpha_star"]] == [
        ("resolving", 1e-2),
        ("resolving", 1e-3),
    ]
    assert doc["kind"] == "fidelity" and doc["criteria"]["match_fraction"] == 0.9
    prov = doc["provenance"]
    assert prov["command"].startswith("harness fidelity pentagon-bounce --engine resolving")
    assert prov["versions"]["resolving-engine"] == "0.1"
    assert main(argv) == 2  # --out exists: refused without --force, before any run
    assert "exists" in capsys.readouterr().err


def test_cli_fidelity_refuses_a_scene_not_given_in_q_p(tmp_path, capsys):
    scene = tmp_path / "full.toml"
    scene.write_text(
        "[body]\nn = 3\n[initial]\nposition = [0, 0, 1]\nrotation_vector = [0.1, 0, 0]\n"
        "velocity = [0, 0, 0]\nangular_velocity = [0, 0, 0]\n"
    )
    assert main(["fidelity", str(scene), "--engine", "mujoco"]) == 2
    err = capsys.readouterr().err
    assert "q and p" in err and "Traceback" not in err


def test_the_text_has_one_number_a_cell_and_one_row_per_scale(resolving_engine):
    """k's fit in columns of their own (k, its standard error, the grid's least and
    largest k, the number of dts), and the per-scale table: one row per α with each run's
    leading impacts matched, the counts of the JSON rows."""
    from harness.fidelity.text import format_fidelity

    scene = resolve_scene("pentagon-bounce")
    doc = fidelity(scene, [resolving_engine], [1e-2, 1e-3], eps_values(1.0, 1e-3, 4))
    lines = format_fidelity(doc).splitlines()
    assert max(map(len, lines)) <= 100
    header = next(line for line in lines if line.startswith("engine"))
    assert header.endswith("k  k stderr  k min  k max  dts")
    fit = doc["fits"][0]
    row = lines[lines.index(header) + 2].split()
    lo, hi = fit["k_grid"]
    assert row[-5:] == [f"{fit['k']:.2f}", "-", f"{lo:.2f}", f"{hi:.2f}", "2"]  # 2 dts
    top = next(i for i, line in enumerate(lines) if line.startswith("α [rad]"))
    assert lines[top].split()[4:] == [resolving_engine, "1e-02", resolving_engine, "1e-03"]
    matched = {(r["dt"], r["eps"]): r["leading_matched"] for r in doc["runs"]}
    for eps, line in zip(doc["eps"], lines[top + 2 : top + 2 + len(doc["eps"])], strict=True):
        cells = line.split()
        assert float(cells[1]) == pytest.approx(eps, rel=1e-2)
        expected = [matched.get((dt, eps)) for dt in (1e-2, 1e-3)]
        assert cells[3:] == ["-" if m is None else str(m) for m in expected]
