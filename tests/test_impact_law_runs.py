"""Runs of the exact reference under the impact laws of simultaneous impacts
(reference.core.law_event, inside the compiled loop): scenes that start on 2, 3 and 6
contacts against the enumerated LCP (tests/oracle/lcp.py), the flat drop's bounces
listed and completed in closed form, the law named in every output, and the scene key
and options."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from harness.cli import main
from harness.scenes import resolve_scene
from reference import ReferenceOptions, simulate
from reference import quaternion as qt
from reference.scene import DEFAULT_SIMULTANEITY_WINDOW, SceneError, scene_from_dict
from tests.conftest import angular_momentum, make_scene, states_of
from tests.oracle.body import BodyModel
from tests.oracle.lcp import delassus, moreau_lcp


def _on_ground(n, rotation, velocity, omega, gamma=0.5, ground="flat"):
    """A scene whose body starts exactly on its lowest contacts."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector(rotation)
    y[7:10], y[10:13] = velocity, omega
    scene = make_scene(n=n, gamma=gamma, state=y, t_end=0.5, ground=ground)
    model = BodyModel.from_scene(scene)
    y[2] = -model.contacts(y)[0].min()
    return make_scene(n=n, gamma=gamma, state=y, t_end=0.5, ground=ground), y


EDGE = np.array([-np.sin(np.pi / 4), np.cos(np.pi / 4), 0.0])  # a square's edge 0-1
STARTS = {
    "two (a square on its edge)": (4, 0.3 * EDGE, [0.1, 0.0, -0.8], [0.3, -0.2, 0.5]),
    "three (a flat triangle)": (3, [0, 0, 0.2], [0.0, 0.1, -0.6], [0.4, 0.3, 0.1]),
    "six (a flat hexagon)": (6, [0, 0, 0.1], [0.2, 0.0, -1.0], [0.3, -0.4, 0.7]),
}


@pytest.mark.parametrize("case", list(STARTS))
def test_a_start_on_several_contacts_takes_the_lcp_impulses_under_moreau(case):
    n, rot, v, w = STARTS[case]
    scene, y = _on_ground(n, rot, v, w)
    model = BodyModel.from_scene(scene)
    gap = model.contacts(y)[0]
    touching = [int(k) for k in np.flatnonzero(gap <= 1e-15)]
    assert len(touching) == {"two": 2, "three": 3, "six": 6}[case.split()[0]]
    paper = simulate(scene)
    assert paper.status.value == "simultaneous_impact" and paper.t_final == 0.0
    traj = simulate(scene, options=ReferenceOptions(impact_law="moreau"))
    _, _, W, u = delassus(model, y, touching)
    oracle = moreau_lcp(W, u, scene.restitution)
    at_start = [e for e in traj.impacts if e.t == 0.0]
    took = {e.contact: e for e in at_start}
    expected = {c: lam for c, lam in zip(touching, oracle.impulses, strict=True) if lam > 0}
    assert set(took) == set(expected)
    for c, lam in expected.items():
        assert took[c].impulse == pytest.approx(lam, rel=1e-10)
        i = touching.index(c)
        assert took[c].v_normal_post == pytest.approx(oracle.u_post[i], abs=1e-12)
    assert traj.status.value != "simultaneous_impact" or traj.t_final > 0
    assert traj.impact_law == "moreau"


@pytest.mark.parametrize("gamma", [0.0, 0.3, 0.7])
def test_a_flat_drop_bounces_flat_and_rests_at_the_accumulation_time(gamma):
    """Dropped flat from h with a horizontal drift: every vertex lands at t1 = √(2h/g)
    with v1 = g t1, takes m(1 + γ)v1/n, and the flat bounces end at
    t_f = t1 + 2γv1/(g(1 − γ)), at rest, having drifted v_x t_f."""
    h, g, n, vx = 0.32, 2.0, 6, 0.15
    scene = scene_from_dict(
        {
            "gravity": g, "restitution": gamma, "impact_law": "moreau", "body": {"n": n},
            "initial": {"position": [0, 0, h], "rotation_vector": [0, 0, 0.3],
                        "velocity": [vx, 0, 0], "angular_velocity": [0, 0, 0.2]},
            "run": {"t_end": 10.0},
        }
    )  # fmt: skip
    traj = simulate(scene)
    t1 = math.sqrt(2 * h / g)
    v1 = g * t1
    t_f = t1 + 2 * gamma * v1 / (g * (1 - gamma))
    assert traj.status.value == "singularity"
    assert traj.t_singularity == pytest.approx(t_f, rel=1e-12)
    first = [e for e in traj.impacts if e.t == traj.impacts[0].t]
    assert len(first) == n
    for e in first:
        assert e.t == pytest.approx(t1, rel=1e-12)
        assert e.impulse == pytest.approx((1 + gamma) * v1 / n, rel=1e-10)
    assert traj.position[-1][0] == pytest.approx(vx * t_f, rel=1e-12)
    assert abs(traj.velocity[-1][2]) < 1e-15 and traj.kinetic_energy[-1] == pytest.approx(
        0.5 * vx**2 + 0.5 * scene.body.inertia_diag[2] * 0.2**2, rel=1e-12
    )


def test_a_flat_drop_lists_its_bounces_then_completes_them_in_closed_form():
    """Dropped flat from h = a/2 with γ = 1/2 (g = a = 1): landing k comes at
    t_k = t1 + Σⱼ₌₁..ₖ 2γʲv1/g, every vertex hit with the body's vertical speed γᵏv1,
    while the bounces are above the completion speed; the rest of the series ends at
    rest at t_f = t1 + 2γv1/(g(1 − γ)), an accumulation time."""
    h, g, gamma, n = 0.5, 1.0, 0.5, 3
    scene = scene_from_dict(
        {
            "gravity": g, "restitution": gamma, "impact_law": "moreau", "body": {"n": n},
            "initial": {"position": [0, 0, h], "rotation_vector": [0, 0, 0.3],
                        "velocity": [0, 0, 0], "angular_velocity": [0, 0, 0]},
            "run": {"t_end": 10.0},
        }
    )  # fmt: skip
    traj = simulate(scene)
    t1 = math.sqrt(2 * h / g)
    v1 = g * t1
    landings = sorted({e.t for e in traj.impacts})
    assert len(landings) >= 5
    assert len(traj.impacts) == n * len(landings)
    t_k = t1
    for k, t in enumerate(landings):
        assert t == pytest.approx(t_k, rel=1e-14, abs=0)
        rows = [e for e in traj.impacts if e.t == t]
        assert sorted(e.contact for e in rows) == list(range(n))
        for e in rows:
            assert e.v_normal_pre == pytest.approx(-(gamma**k) * v1, rel=1e-9)
        t_k += 2 * gamma ** (k + 1) * v1 / g
    t_f = t1 + 2 * gamma * v1 / (g * (1 - gamma))
    assert traj.status.value == "singularity"
    assert traj.t_singularity == pytest.approx(t_f, rel=1e-12, abs=0)
    assert traj.stats.chatter_accumulation_times[-1] == traj.t_singularity
    assert traj.stats.simultaneous_impacts == len(landings)


def test_the_sequential_law_resolves_a_flat_landing_without_gaining_energy():
    scene, _ = _on_ground(6, [0, 0, 0.1], [0.0, 0.0, -1.0], [0.0, 0.0, 0.0], gamma=0.5)
    traj = simulate(scene, options=ReferenceOptions(impact_law="sequential"))
    assert traj.status.value in ("singularity", "t_end")
    e = traj.energy
    assert np.all(np.diff(e) <= 1e-12 * e[0])
    assert traj.impact_law == "sequential"


def test_the_scene_key_and_its_checks():
    base = {"body": {"n": 3}, "initial": {"q": [0.01, 0, 0.02], "p": [0, 0, 0]}}
    assert scene_from_dict(base).impact_law == "paper"
    assert scene_from_dict(base).simultaneity_window is None  # the simulator's default
    assert scene_from_dict({**base, "impact_law": "sequential"}).impact_law == "sequential"
    with pytest.raises(SceneError, match="impact_law must be one of"):
        scene_from_dict({**base, "impact_law": "stronge"})
    assert scene_from_dict({**base, "simultaneity_window": 1e-9}).simultaneity_window == 1e-9
    with pytest.raises(SceneError, match="simultaneity_window"):
        scene_from_dict({**base, "simultaneity_window": -1.0})


def test_every_output_names_the_law(tmp_path, capsys):
    path = tmp_path / "drop.toml"
    path.write_text(
        "restitution = 0.5\n[body]\nn = 6\n[initial]\nposition = [0, 0, 0.5]\n"
        "rotation_vector = [0, 0, 0]\nvelocity = [0, 0, 0]\nangular_velocity = [0, 0, 0]\n"
        "[run]\nt_end = 5.0\n"
    )
    assert main(["simulate", str(path), "--impact-law", "moreau", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert (doc["impact_law"], doc["simultaneity_window"]) == (
        "moreau",
        DEFAULT_SIMULTANEITY_WINDOW,
    )
    assert doc["status"] == "singularity" and doc["t_singularity"] == pytest.approx(3.0)
    landings = {r["t"] for r in doc["impacts"]}
    assert min(landings) == 1.0 and len(doc["impacts"]) == 6 * len(landings)
    assert doc["stats"]["simultaneous_impacts"] == len(landings)
    assert main(["simulate", str(path), "--impact-law", "moreau"]) == 0
    text = capsys.readouterr().out
    assert f"impacts     {6 * len(landings)} ({len(landings)} simultaneous impacts" in text
    assert main(["simulate", str(path)]) == 0
    assert "impact law  paper (simultaneity window 0)" in capsys.readouterr().out
    assert main(["simulate", str(path), "--simultaneity-window", "-1"]) == 2
    assert main(["branches", str(path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    names = [b["branch"] for b in doc["branches"]]
    assert names == ["paper", "moreau", "sequential", "compliant", "compliant-mass"]  # no orders
    assert doc["undecidable"]["t"] == pytest.approx(1.0)
    assert doc["undecidable"]["contacts"] == list(range(6))
    moreau = doc["branches"][1]
    assert moreau["status"] == "singularity" and moreau["t_f"] == pytest.approx(3.0)
    assert [r["contact"] for r in moreau["impacts_at_undecidable"]] == list(range(6))


@pytest.mark.parametrize("case", list(STARTS))
def test_a_start_just_above_the_ground_is_one_simultaneous_impact_within_the_window(case):
    """The same states lifted 1e-12 above the ground: with the default window of the
    laws (DEFAULT_SIMULTANEITY_WINDOW) they are one simultaneous impact: under Moreau's
    law the impulses of the start on the ground, and, given that window, under the
    paper's rule `simultaneous_impact`; with the window 0 the contacts are met one by
    one, picoseconds apart.  (The flat triangle's slowest vertex, at 0.10, has its
    free-flight zero 8.7e-12 after the first vertex's, reached at 0.88: inside
    T|u|/√(g a) = 8.8e-12.)"""
    n, rot, v, w = STARTS[case]
    scene, y = _on_ground(n, rot, v, w)
    y_up = y.copy()
    y_up[2] += 1e-12
    lifted = make_scene(n=n, gamma=scene.restitution, state=y_up, t_end=0.5)
    assert lifted.simultaneity_window is None and DEFAULT_SIMULTANEITY_WINDOW > 0
    on_ground = simulate(scene, options=ReferenceOptions(impact_law="moreau"))
    above = simulate(lifted, options=ReferenceOptions(impact_law="moreau"))
    first = [e for e in on_ground.impacts if e.t == 0.0]
    t0 = above.impacts[0].t
    again = [e for e in above.impacts if e.t == t0]
    assert [e.contact for e in again] == [e.contact for e in first]
    for a, b in zip(again, first, strict=True):
        assert a.impulse == pytest.approx(b.impulse, rel=1e-9)
    windowed = ReferenceOptions(simultaneity_window=DEFAULT_SIMULTANEITY_WINDOW)
    paper = simulate(lifted, options=windowed)
    assert paper.status.value == "simultaneous_impact"
    assert paper.simultaneity_window == DEFAULT_SIMULTANEITY_WINDOW
    assert simulate(lifted).simultaneity_window == 0.0  # the paper's default
    strict = simulate(lifted, options=ReferenceOptions(simultaneity_window=0.0))
    assert strict.status.value != "simultaneous_impact"
    t0 = strict.impacts[0].t
    micro = [e.t for e in strict.impacts if e.t - t0 < DEFAULT_SIMULTANEITY_WINDOW]
    assert len(micro) >= 2 and len(set(micro)) == len(micro)  # single impacts, one by one


def test_the_built_in_near_simultaneous_hits_are_one_impact_under_the_default_window():
    """near-simultaneous: vertices 0 and 1 hit 1e-12 … 2e-12 apart (the scene sets the
    window 0 to show them in order); under the default window they are one impact."""
    scene = resolve_scene("near-simultaneous")
    assert scene.simultaneity_window == 0.0
    traj = simulate(
        scene, options=ReferenceOptions(simultaneity_window=DEFAULT_SIMULTANEITY_WINDOW)
    )
    assert traj.status.value == "simultaneous_impact"
    assert "v0, v1 hit simultaneously" in traj.message and traj.impacts == []


@pytest.mark.parametrize("sample", [0, 1, 2, 3])
def test_a_motion_that_ends_at_the_singularity_has_no_energy_left(sample):
    """The ρ = 0.5 triangle of the sweep (γ = 0.6) under Moreau's law: when the run
    ends at the singularity the energy above the resting level is gone (a third vertex
    landing at speed beside a held edge is an impact, not a silent hold; a body exactly
    flat after a simultaneous impact but tilting away is not below the tilt floor;
    sample 1 rocks on an edge from exactly flat, `test_a_triangle_rocking_...`)."""
    from harness.sweep.grid import SweepConfig, initial_state
    from harness.sweep.run import polygon_scene
    from reference.exponent import excess_energy_of

    config = SweepConfig(n=3, gyration=(0.5, 0.5, 1), restitution=(0.6, 0.6, 1), samples=4,
                         seed=0, engine="reference", impact_law="moreau")  # fmt: skip
    q0, p0 = initial_state(0, 2, 0, sample)
    scene = polygon_scene(config, 0.5, 0.6, q0, p0)
    traj = simulate(scene, options=ReferenceOptions(sample_dt=1.0))
    assert traj.status.value == "singularity"
    excess = excess_energy_of(traj, scene)
    assert excess[-1] <= 1e-9 * excess[0]


def test_branches_text_fits_100_columns_and_names_each_branch(capsys):
    """The terminal text of `harness branches` on the demo scene: one row per branch
    (paper, moreau, sequential and both orders of the two contacts), no line over 100."""
    assert main(["branches", "triangle-chatter"]) == 0
    text = capsys.readouterr().out
    rows = {line.split()[0] for line in text.splitlines() if line.strip()}
    assert {"paper", "moreau", "sequential", "sequential[1,2]", "sequential[2,1]"} <= rows
    assert max(len(line) for line in text.splitlines()) <= 100


def _rocking_time(u, rho, g):
    """The time a thin triangle (a = m = 1, in-plane inertia ρ²) lying flat at z = 0,
    frictionless, takes to rock up on its edge 0-2 and back, its vertex 1 leaving at u:
    with θ the tilt about the edge (its centre at height sin θ / 2, vertex 1 at 3 sin θ
    / 2, no horizontal motion) energy gives (cos²θ/4 + ρ²) θ̇² + g sin θ = (1/4 + ρ²)
    θ̇₀², θ̇₀ = 2u/3; T = 2 ∫ dθ/θ̇ to the top θ_m, with θ = θ_m(1 − s²) (scipy quad)."""
    from scipy.integrate import quad

    c = (0.25 + rho**2) * (2.0 * u / 3.0) ** 2
    top = math.asin(c / g)

    def integrand(s):
        th = top * (1.0 - s * s)
        drop = 2.0 * g * math.cos(0.5 * (top + th)) * math.sin(0.5 * top * s * s)
        return 2.0 * top * s / math.sqrt(drop / (0.25 * math.cos(th) ** 2 + rho**2))

    return 2.0 * quad(integrand, 0.0, 1.0, epsabs=0.0, epsrel=1e-13, limit=200)[0]


def test_a_triangle_rocking_from_exactly_flat_lands_at_the_rocking_time():
    """A triangle exactly flat at z = 0 with vertex 1 leaving at u and vertices 0, 2 at
    rest (the state a simultaneous impact of the ρ = 0.5 sweep left: its contact phase
    once stalled there, every gap and roundoff exactly 0; without spin q_z stays at
    roundoff, which a denormal tolerance rejected at every step): it rocks on edge 0-2
    and vertex 1 lands at the rocking time (`_rocking_time`, independent).  Under the
    paper's rule that landing would push the edge: `simultaneous_impact`; under
    Moreau's (with a spin of 1e-5 about the vertical, as in the sweep's run: its effect
    on the times is of order 1e-10) it bounces at γ times the speed, the next landing
    one rocking time of γu later, and the series ends at the singularity with the
    energy never increasing and the horizontal momentum and vertical angular momentum
    unchanged."""
    rho, gamma, u = 0.5, 0.6, 0.6
    y = np.zeros(13)
    y[3] = 1.0
    y[9] = u / 3.0  # the centre rises at u/3, vertices 0 and 2 at rest, vertex 1 at u
    y[10:13] = 2.0 * u / 3.0 * np.array([math.sqrt(3) / 2, 0.5, 0.0])
    scene = make_scene(n=3, rho=rho, gamma=gamma, state=y, t_end=20.0)
    t1 = _rocking_time(u, rho, scene.gravity)
    paper = simulate(scene)
    assert paper.status.value == "simultaneous_impact"
    assert paper.t_final == pytest.approx(t1, rel=1e-9)
    y[12] = 1e-5
    scene = make_scene(n=3, rho=rho, gamma=gamma, state=y, t_end=20.0)
    traj = simulate(scene, options=ReferenceOptions(impact_law="moreau", sample_dt=0.01))
    landings = sorted({e.t for e in traj.impacts if e.contact == 1})
    expected = np.cumsum([_rocking_time(u * gamma**k, rho, scene.gravity) for k in range(3)])
    assert landings[:3] == pytest.approx(expected, rel=1e-9)
    assert traj.status.value == "singularity"
    assert all(e.v_normal_post >= -1e-12 for e in traj.impacts)
    e = traj.energy
    assert np.all(np.diff(e) <= 1e-10 * e[0])
    assert np.abs(traj.velocity[:, :2]).max() <= 1e-12
    l_z = angular_momentum(scene, states_of(traj))[:, 2]
    assert np.abs(l_z - l_z[0]).max() <= 1e-12
