"""The horizon study (harness.horizon): the ensemble's horizons against a Lyapunov
exponent computed independently (finite differences of the reference's impact-to-impact
map, tangent vector carried along the orbit), the grid model against the exact
reference, reproducibility, and the `horizon` object of `compare`."""

from dataclasses import replace

import numpy as np
import pytest

from harness.horizon.ensemble import (
    grid_ensemble,
    matched_counts,
    perturbed_ensemble,
)
from harness.horizon.grid import GridRun
from harness.horizon.lyapunov import lyapunov_per_impact, predicted_horizon
from harness.horizon.state import difference, displaced, units
from harness.metrics import match_impacts, match_tolerance
from reference import quaternion as qt
from reference import scene_from_dict, simulate
from reference.scene import InitialState, RunSettings

# An elastic triangle: γ = 1, no chatter, no contact phases; chaotic bouncing whose
# horizon grows steadily as the perturbation shrinks (1e-4 … 1e-7: medians 45 … 83).
ELASTIC_TRIANGLE = scene_from_dict(
    {
        "name": "elastic-triangle",
        "restitution": 1.0,
        "body": {"n": 3, "gyration": 0.5},
        "initial": {"q": [0.03, 0.01, 0.04], "p": [0.05, -0.04, -0.15]},
        "run": {"t_end": 20.0},
    }
)


def _rows(tr):
    return np.concatenate([tr.position, tr.quaternion, tr.velocity, tr.angular_velocity], 1)


def _run(y, t_end, max_impacts):
    ini = InitialState(
        tuple(y[0:3]), tuple(qt.to_rotation_vector(y[3:7])), tuple(y[7:10]), tuple(y[10:13])
    )
    return simulate(replace(ELASTIC_TRIANGLE, initial=ini, run=RunSettings(t_end, max_impacts)))


def _moved(y, s):
    """y moved by s (12: position, world rotation vector, velocity, angular velocity);
    the built-in units are 1 here (a = g = 1, t_end ≥ 1)."""
    out = np.array(y, dtype=float)
    out[0:3] += s[0:3]
    out[3:7] = qt.multiply(qt.from_rotation_vector(s[3:6]), y[3:7])
    out[7:13] += s[6:12]
    return out


def _delta(y, y0):
    rel = qt.to_rotation_vector(qt.multiply(y[3:7], qt.conjugate(y0[3:7])))
    return np.concatenate([y[0:3] - y0[0:3], rel, y[7:13] - y0[7:13]])


def finite_difference_lyapunov(n_impacts: int, h: float = 1e-7) -> float:
    """λ per impact of the impact-to-impact map, independently of the ensemble: the
    section is "halfway between impacts i and i+1" (all contacts off the ground); the
    map's Jacobian by central differences of reference runs (to the next impact, then
    on to the next section), a tangent vector carried along and renormalised."""
    reference = simulate(ELASTIC_TRIANGLE)
    ti = reference.impact_times()
    mid = 0.5 * (ti[:-1] + ti[1:])
    sections = [_rows(simulate(ELASTIC_TRIANGLE, t_end=float(m)))[-1] for m in mid[: n_impacts + 1]]

    def section_map(y, tau):
        t_hit = _run(y, 100.0, 1).impacts[0].t
        return _rows(_run(y, t_hit + tau, 2))[-1]

    v = np.random.default_rng(1).standard_normal(12)
    v /= np.linalg.norm(v)
    logs = []
    for i in range(n_impacts):
        tau = mid[i + 1] - ti[i + 1]
        jac = np.empty((12, 12))
        for c in range(12):
            e = np.zeros(12)
            e[c] = h
            plus = _delta(section_map(_moved(sections[i], e), tau), sections[i + 1])
            minus = _delta(section_map(_moved(sections[i], -e), tau), sections[i + 1])
            jac[:, c] = (plus - minus) / (2 * h)
        w = jac @ v
        logs.append(np.log(np.linalg.norm(w)))
        v = w / np.linalg.norm(w)
    return float(np.mean(logs))


@pytest.fixture(scope="module")
def elastic():
    reference = simulate(ELASTIC_TRIANGLE)
    shallow = perturbed_ensemble(ELASTIC_TRIANGLE, reference, 1e-4, runs=24)
    deep = perturbed_ensemble(ELASTIC_TRIANGLE, reference, 1e-7, runs=24)
    rate = finite_difference_lyapunov(int(np.median(matched_counts(deep))))
    return reference, shallow, deep, rate


def test_ensemble_horizon_agrees_with_the_finite_difference_lyapunov_prediction(elastic):
    reference, shallow, deep, rate = elastic
    n_shallow = float(np.median(matched_counts(shallow)))
    n_deep = float(np.median(matched_counts(deep)))
    predicted = predicted_horizon(n_shallow, 1e-4, 1e-7, rate)
    print(f"λ_fd {rate:.3f}; n(1e-4) {n_shallow}, n(1e-7) {n_deep}, predicted {predicted:.1f}")
    assert n_deep > n_shallow + 10  # the horizon grows as the perturbation shrinks
    assert predicted == pytest.approx(n_deep, rel=0.25)


def test_ensemble_growth_rate_agrees_with_the_finite_difference_lyapunov(elastic):
    reference, _, deep, fd = elastic
    rate = lyapunov_per_impact(ELASTIC_TRIANGLE, reference, deep)
    print(f"λ ensemble {rate:.3f}, finite differences {fd:.3f}")
    assert rate == pytest.approx(fd, rel=0.35)


@pytest.mark.parametrize("name", ["pentagon-bounce", "triangle-chatter"])
def test_grid_model_of_zero_width_is_the_reference_impact_by_impact(name):
    from harness.scenes import resolve_scene

    scene = resolve_scene(name)
    reference = simulate(scene)
    run = GridRun(scene, 0.0, 0.0, reference.t_final, 0.0)
    while run.step() and len(run.impacts) < 120:
        pass
    traj = run.trajectory()
    traj.dt = None
    m = match_impacts(traj, reference, match_tolerance(traj, reference, scene.gravity))
    assert m.n_matched >= min(len(run.impacts), len(reference.impacts)) - 1
    times = np.array([e.t for e in run.impacts[: m.n_matched]])
    assert np.allclose(times, reference.impact_times()[: m.n_matched], rtol=0, atol=1e-9)


def test_grid_model_applies_impacts_on_the_grid_and_keeps_contacts_above_ground():
    from harness.scenes import resolve_scene
    from reference.geometry import scene_contact_kinematics

    scene = resolve_scene("pentagon-bounce")
    reference = simulate(scene)
    dt, phase = 1e-3, 3.7e-4
    run = GridRun(scene, dt, phase, reference.t_final, 0.0)
    while run.step() and len(run.impacts) < 20:
        pass
    t = np.array([e.t for e in run.impacts])
    k = np.round((t - phase) / dt)
    assert np.allclose(t, phase + k * dt, rtol=0, atol=1e-12)
    gaps, _ = scene_contact_kinematics(scene, np.concatenate(run.states))
    assert gaps.min() > -1e-12
    assert 0 < run.max_depth < 1e-2  # the delay did push contacts into the ground


def test_ensembles_are_reproducible_and_extend_with_more_members():
    from harness.scenes import resolve_scene

    scene = resolve_scene("pentagon-bounce")
    reference = simulate(scene)
    a = matched_counts(perturbed_ensemble(scene, reference, 1e-4, runs=4, seed=7))
    b = matched_counts(perturbed_ensemble(scene, reference, 1e-4, runs=6, seed=7))
    assert list(a) == list(b[:4])
    g1 = matched_counts(grid_ensemble(scene, reference, 1e-3, runs=3, seed=7))
    g2 = matched_counts(grid_ensemble(scene, reference, 1e-3, runs=3, seed=7))
    assert list(g1) == list(g2)


def test_displacement_and_difference_are_inverse():
    from harness.horizon.state import start_state
    from harness.scenes import resolve_scene

    scene = resolve_scene("three-point-disk")
    y = start_state(scene)
    step = np.arange(1, 13) * 1e-6
    assert np.allclose(difference(scene, displaced(scene, y, step), y), step, atol=1e-12)
    assert units(scene).shape == (12,)


def test_compare_json_has_the_horizon_object_of_each_run_and_the_recording_its_band(
    capsys, tmp_path
):
    import json

    import rerun as rr

    from harness.cli import main
    from harness.recording.horizon import band_times
    from harness.scenes import resolve_scene

    args = ["compare", "pentagon-bounce", "--engine", "mujoco", "--engine", "linear"]
    rrd = tmp_path / "h.rrd"
    assert main([*args, "--dt", "1e-3", "--horizon-runs", "4", "--json", "--record", str(rrd)]) == 0
    doc = json.loads(capsys.readouterr().out)
    store = rr.chunk.RrdReader(rrd).store()
    chunks = store.stream().filter(content="/impacts/mujoco_dt1e-03/horizon_band").to_chunks()
    times = np.concatenate(
        [
            c.to_record_batch().column("sim_time").cast("int64").to_numpy()
            for c in chunks
            if "sim_time" in c.to_record_batch().schema.names
        ]
    )
    reference = simulate(resolve_scene("pentagon-bounce"))
    quantiles = doc["engines"][0]["horizon"]["matched_quantiles"]
    expected = band_times(reference.impact_times(), quantiles)
    assert np.allclose(np.sort(times) * 1e-9, expected, atol=1e-8)
    mujoco, linear = doc["engines"]
    h = mujoco["horizon"]
    for key in ("matched_quantiles", "within", "own_error", "own_error_quantiles"):
        assert key in h
    assert h["lyapunov_per_impact"] > 0
    q = h["matched_quantiles"]
    assert q[0] <= q[1] <= q[2]
    assert h["within"] == (mujoco["impacts_matched"] >= q[0])
    assert h["own_error"] > 0 and len(h["own_error_quantiles"]) == 3
    assert linear["horizon"]["matched_quantiles"] is None  # event-driven: level (b) only
    assert linear["horizon"]["within"] is None
    assert linear["horizon"]["own_error_quantiles"] is not None


def test_compare_without_horizon_runs_has_no_verdict(capsys):
    import json

    from harness.cli import main

    args = ["compare", "triangle-chatter", "--engine", "linear", "--horizon-runs", "0"]
    assert main([*args, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["engines"][0]["horizon"] is None


def test_fidelity_fails_a_run_only_below_the_horizon_band():
    from harness.fidelity.study import horizon_verdict

    band = [4.0, 6.0, 8.0]
    assert horizon_verdict(5, band, False, None)["horizon_pass"]  # 5 of 10: within the band
    assert not horizon_verdict(3, band, False, None)["horizon_pass"]  # below it
    assert not horizon_verdict(9, band, True, False)["horizon_pass"]  # c failed
    assert horizon_verdict(3, None, False, None)["horizon_pass"] is None


def test_compare_text_stays_within_100_columns_with_the_band_and_long_names():
    from harness.compare import compare, format_compare
    from harness.horizon.verdict import Horizon
    from harness.scenes import resolve_scene

    result = compare(resolve_scene("pentagon-bounce"), ["linear"])
    run = result.runs[0]
    run.engine, run.dt = "pybullet-default", 1e-4  # the longest built-in label
    run.horizon = Horizon(
        22, [15.0, 18.0, 22.0], 1e-4, 0, [12.0, 20.0, 30.0], 25.0, 0.12, 24, 0, 1e-4
    )
    text = format_compare(result)
    assert max(len(line) for line in text.splitlines()) <= 100
    row = next(line for line in text.splitlines()[::-1] if line.startswith("pybullet-default"))
    # the horizon table: the grid's and the perturbed model's 10 % and 90 % in cells of their own
    assert row.split()[-7:] == ["22", "15", "22", "yes", "1.0e-04", "12", "30"]
    assert "matches 22 impacts, at least the 15 that 90 % of the exact model's runs" in text
    run.horizon = replace(run.horizon, matched=14)
    assert "matches 14 impacts, fewer than the 15" in format_compare(result)


def test_profile_prediction_from_the_deep_ensemble_matches_the_shallow_one(elastic):
    from harness.horizon.lyapunov import profile_horizon

    reference, shallow, deep, _ = elastic
    predicted = profile_horizon(reference, deep, ELASTIC_TRIANGLE.gravity, 1e-7, 1e-4)
    measured = float(np.median(matched_counts(shallow)))
    print(f"profile prediction {predicted}, ensemble {measured}")
    assert predicted == pytest.approx(measured, rel=0.25)
