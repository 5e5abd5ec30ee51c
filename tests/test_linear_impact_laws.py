"""The linear model under the exact reference's impact laws (reference/linear/laws.py)."""

import math

import numpy as np
import pytest

from reference.core.impact_laws import SETTLED
from reference.core.laws import LAW_NAMES, law_code
from reference.linear import kernel as K
from reference.linear.laws import apply_law, delassus
from reference.linear.model import LinearModel, full_states
from reference.linear.simulate import run_linear, simulate_linear
from reference.scene import scene_from_dict
from reference.trajectory import Status
from tests.oracle.quaternion import to_matrix as oracle_rotation

LAW_MOREAU, LAW_SEQUENTIAL = law_code("moreau"), law_code("sequential")
LAWS = (LAW_MOREAU, LAW_SEQUENTIAL)


def _random_model(rng, n=None):
    n = int(rng.integers(3, 9)) if n is None else n
    return LinearModel.polygon(n, float(rng.uniform(0.3, 0.9)), float(rng.uniform(0.05, 0.95)))


@pytest.mark.parametrize("law", LAWS)
def test_one_contact_under_a_law_is_the_kernels_own_impact_bit_for_bit(law):
    rng = np.random.default_rng(1)
    for _ in range(50):
        m = _random_model(rng)
        F, tinv = m.F, 1.0 / m.theta
        w = K._contact_products(F, tinv)[0]
        j = int(rng.integers(m.n_contacts))
        p = rng.normal(size=3)
        p[2] -= abs(F[j] @ p) + 0.1  # contact j approaches
        p_kernel, q, q_pre, p_pre = p.copy(), np.zeros(3), np.zeros(3), np.zeros(3)
        _, lam_kernel = K._apply_impulse(F, tinv, w, m.restitution, j, q, p_kernel, q_pre, p_pre)
        p_law = p.copy()
        status, lam, _, u_post, _, _ = apply_law(F, m.theta, m.restitution, p_law, [j], law)
        assert status == SETTLED
        assert lam[0] == lam_kernel
        assert np.array_equal(p_law, p_kernel)
        assert u_post[0] == pytest.approx(-m.restitution * (F[j] @ p), rel=1e-14, abs=1e-15)


def _exact_delassus(n, rho, phi):
    """W = J M⁻¹ Jᵀ of the rigid n-gon (a = m = 1, I = ρ² diag(1, 1, 2)) at rotation
    vector (φx, φy, 0), normals e_z: an independent derivation (not the core's code)."""
    R = oracle_rotation(full_states(np.array([phi[0], phi[1], 0.0]), np.zeros(3))[0, 3:7])
    inv_i = R @ np.diag([1 / rho**2, 1 / rho**2, 1 / (2 * rho**2)]) @ R.T
    ang = 2 * np.pi * np.arange(n) / n
    r = (R @ np.stack([np.cos(ang), np.sin(ang), np.zeros(n)])).T
    J = np.hstack([np.tile([0.0, 0.0, 1.0], (n, 1)), np.cross(r, [0.0, 0.0, 1.0])])
    m_inv = np.zeros((6, 6))
    m_inv[:3, :3] = np.eye(3)
    m_inv[3:, 3:] = inv_i
    return J @ m_inv @ J.T


def test_linear_delassus_matrix_is_the_rigid_bodys_at_zero_tilt_to_second_order():
    for n, rho in ((3, 0.5), (5, 0.7), (8, 0.4)):
        W_lin, _ = delassus(LinearModel.polygon(n, rho, 0.5).F, (rho**2, rho**2, 1.0), range(n))
        errors = []
        for tilt in (1e-2, 1e-3):
            phi = tilt * np.array([0.6, 0.8])
            errors.append(np.abs(_exact_delassus(n, rho, phi) - W_lin).max() / W_lin.max())
        assert _exact_delassus(n, rho, (0.0, 0.0)) == pytest.approx(W_lin, rel=1e-14, abs=1e-14)
        assert errors[0] < 1e-3  # O(tilt²): 1e-4 at 1e-2 rad
        assert 50 < errors[0] / errors[1] < 200  # second order: ×100 per decade


def test_the_core_forms_the_same_delassus_matrix_the_test_derives():
    from reference.compiled import function
    from reference.scenes import as_scene
    from reference.simulate import model_record

    scene = as_scene("triangle-chatter")
    n, rho = scene.body.n, scene.body.gyration
    phi = (0.003, -0.002)
    y = full_states(np.array([phi[0], phi[1], 0.0]), np.array([0.1, -0.2, -1.0]))[0]
    k = n
    cs = np.arange(k, dtype=np.int64)
    W, chol = np.zeros((k, k)), np.zeros((k, k))
    u_pre, lam, u_post, vec = np.zeros(k), np.zeros(k), np.zeros(k), np.zeros(2 * k)
    active, result = np.zeros(k, dtype=np.int64), np.zeros(3, dtype=np.int64)
    pts = np.ascontiguousarray(scene.contacts.core_points, dtype=float)
    function("multi_impact")(
        y.copy(), model_record(scene), pts, LAW_MOREAU, cs, k, np.zeros(0, dtype=np.int64), 0,
        10, 1e-6, W, u_pre, lam, u_post, chol, vec, active, result,
    )  # fmt: skip
    a = scene.body.radius
    W_test = _exact_delassus(n, rho, phi) * np.array([[1.0]])  # a = m = 1 in the scene
    assert a == 1.0 and scene.body.mass == 1.0
    assert W == pytest.approx(W_test, rel=1e-12)


@pytest.mark.parametrize("law", LAWS)
def test_a_linear_multi_contact_impact_never_adds_energy_nor_leaves_a_contact_approaching(law):
    rng = np.random.default_rng(5 + law)
    for _ in range(200):
        m = _random_model(rng)
        F = m.F
        p = rng.normal(size=3) * np.array([1.0, 1.0, 0.3])
        p[2] -= 1.0
        u = F @ p
        touching = np.flatnonzero(u <= 0.0)
        if len(touching) < 2:
            continue
        k = int(rng.integers(2, len(touching) + 1))
        contacts = np.sort(rng.choice(touching, size=k, replace=False))
        q = np.zeros(3)
        e_before = m.energy(q, p)
        p_after = p.copy()
        status, lam, u_pre, u_post, _, _ = apply_law(F, m.theta, m.restitution, p_after,
                                                     contacts, law)  # fmt: skip
        assert status == SETTLED
        assert np.all(lam >= 0.0)
        scale = np.abs(u_pre).max()
        assert np.all(F[contacts] @ p_after >= -1e-12 * scale)
        assert F[contacts] @ p_after == pytest.approx(u_post, abs=1e-12 * scale)
        e_after = m.energy(q, p_after)
        assert e_after <= e_before * (1 + 1e-14)
        if law == LAW_MOREAU:  # ΔT = ½ Σ Λᵢ (1 − γ) u⁻ᵢ
            expected = 0.5 * np.sum(lam * (1 - m.restitution) * u_pre)
            assert e_after - e_before == pytest.approx(expected, rel=1e-9, abs=1e-14 * e_before)


def _scene(n, rho, gamma, q, p, law="paper", t_end=5.0, window=0.0):
    return scene_from_dict(
        {
            "restitution": gamma,
            "impact_law": law,
            "simultaneity_window": window,
            "body": {"n": n, "radius": 1.0, "mass": 1.0, "gyration": rho},
            "ground": {"kind": "flat"},
            "initial": {"q": list(q), "p": list(p)},
            "run": {"t_end": t_end, "max_impacts": 100_000},
        }
    )


@pytest.mark.parametrize("n", (3, 6))
def test_a_flat_landing_under_moreau_bounces_flat_and_rests_at_the_zeno_time(n):
    """h₀ above the ground falling flat: lands at t₁ = √(2h₀/g) with v₁ = g t₁, bounces
    flat (every contact at one speed; n equal least-norm impulses (1 + γ)γ^(k−1) m v₁/n
    at bounce k) at t_k = t₁ + Σ_(j<k) 2γʲv₁/g, and rests at t₁ + 2γv₁/(g(1 − γ))."""
    g, gamma, h0 = 1.0, 0.6, 0.02
    t1 = math.sqrt(2 * h0 / g)
    v1 = g * t1
    traj = simulate_linear(_scene(n, 0.5, gamma, (0, 0, h0), (0, 0, 0), "moreau"))
    assert traj.status is Status.SINGULARITY
    assert traj.impact_law == "moreau"
    # one landing resolved by the law in the kernel's loop; its bounces in closed form
    assert traj.stats["simultaneous_impacts"] == 1
    assert traj.t_singularity == pytest.approx(t1 + 2 * gamma * v1 / (g * (1 - gamma)),
                                               rel=1e-13)  # fmt: skip
    times = sorted({ev.t for ev in traj.impacts})
    assert len(times) > 20  # followed down to the energy floor
    for k, t in enumerate(times[:40], start=1):
        bounce = [ev for ev in traj.impacts if ev.t == t]
        t_k = t1 + sum(2 * gamma**j * v1 / g for j in range(1, k))
        assert t == pytest.approx(t_k, rel=1e-14)
        assert sorted(ev.contact for ev in bounce) == list(range(n))
        for ev in bounce:
            assert ev.impulse == pytest.approx((1 + gamma) * gamma ** (k - 1) * v1 / n, rel=1e-7)


def test_under_paper_the_flat_landing_stays_undecidable():
    traj = simulate_linear(_scene(3, 0.5, 0.6, (0, 0, 0.02), (0, 0, 0)))
    assert traj.status is Status.SIMULTANEOUS_IMPACT
    assert traj.impact_law == "paper"


def test_a_triangle_landing_on_an_edge_beside_its_held_vertex_chatters_to_rest_in_closed_form():
    """Vertex 0 held, the opposite edge landing: the edge's vertices and the held one
    touch at q = 0; under moreau the series of bounces about the edge is self-similar
    and ends at rest at a finite time, within t_end."""
    traj = simulate_linear(_scene(3, 0.5, 0.5, (0.0, 0.02, 0.02), (0, 0, 0), "moreau"))
    assert traj.status is Status.SINGULARITY
    assert traj.t_singularity is not None and traj.t_singularity < 5.0
    assert traj.energy[-1] <= 1e-12 * traj.energy[0]


@pytest.mark.parametrize("law", ("moreau", "sequential"))
def test_the_linear_triangle_chatter_goes_on_past_its_undecidable_state(law):
    from reference.scenes import as_scene

    paper = simulate_linear("triangle-chatter")
    assert paper.status is Status.SIMULTANEOUS_IMPACT
    assert paper.stats["simultaneous_impacts"] == 0
    traj = simulate_linear(as_scene("triangle-chatter").with_impact_law(law))
    assert traj.impact_law == law
    assert traj.status is Status.SINGULARITY
    assert traj.stats["simultaneous_impacts"] >= 1
    # the same impacts up to the undecidable state, then more
    n = len(paper.impacts)
    assert [(e.t, e.contact) for e in traj.impacts[:n]] == [(e.t, e.contact) for e in paper.impacts]
    assert len(traj.impacts) > n
    assert traj.impacts[n].t == paper.t_final
    energy = traj.energy
    assert np.all(np.diff(energy[traj.t >= paper.t_final]) <= 1e-12 * energy[0])


def test_the_linear_moreau_branch_follows_the_exact_one_to_the_models_accuracy():
    """triangle-chatter scaled by ε (q by ε², p by ε: tilt ∝ ε², the linear motion
    scales exactly, t by ε): from the linear run's undecidable state on, its next impacts
    and rest time under moreau and the exact reference's agree to a relative error
    O(tilt²) (×16 smaller per halving of ε; measured 2.9e-5, 1.8e-6, 1.1e-7, 7.0e-9,
    4.4e-10 at ε = 1 … 1/16)."""
    from reference.options import ReferenceOptions
    from reference.scenes import as_scene
    from reference.simulate import simulate

    errors = []
    for eps in (0.5, 0.25):
        scene = as_scene("triangle-chatter").scaled(eps).with_impact_law("moreau")
        exact = simulate(scene, options=ReferenceOptions(impact_law="moreau"))
        linear = simulate_linear(scene)
        assert exact.status is Status.SINGULARITY and linear.status is Status.SINGULARITY
        t0 = simulate_linear(scene.with_impact_law("paper")).t_final  # undecidable there
        nexts = [sorted({e.t for e in tr.impacts if e.t >= t0 * (1 - 1e-9)})[:5]
                 for tr in (exact, linear)]  # fmt: skip
        rel = [abs(a / b - 1) for a, b in zip(*nexts, strict=True)]
        rel.append(abs(linear.t_singularity / exact.t_singularity - 1))
        errors.append(max(rel))
    assert errors[0] < 4e-6
    assert errors[1] < errors[0] / 10


def test_a_window_makes_two_contacts_close_in_time_one_impact():
    """A tilted triangle landing on two vertices 1e-10 apart in time: strictly
    sequential without a window; with T = 1e-9 one impact (`paper`: undecidable;
    `moreau`: both take an impulse at one time)."""
    dq = 1e-10  # vertex 2 starts this much higher than vertex 1
    F = LinearModel.polygon(3, 0.5, 0.5).F
    # q with gaps (h0 + 0.01, h0, h0 + dq) at vertices 0, 1, 2: solve F q = gaps
    h0 = 0.01
    q = np.linalg.solve(F, [h0 + 0.01, h0, h0 + dq])
    for window, law, status in ((0.0, "paper", None), (1e-9, "paper", "simultaneous_impact")):
        traj = simulate_linear(_scene(3, 0.5, 0.5, q, (0, 0, 0), law, window=window))
        if status:
            assert traj.status.value == status and traj.t_final < 1.0
            assert "simultaneity window" in traj.message
        else:
            assert traj.impacts[0].contact == 1 and traj.impacts[1].contact == 2
            assert traj.impacts[1].t > traj.impacts[0].t
    traj = simulate_linear(_scene(3, 0.5, 0.5, q, (0, 0, 0), "moreau", window=1e-9))
    first = [e for e in traj.impacts if e.t == traj.impacts[0].t]
    assert sorted(e.contact for e in first) == [1, 2]
    assert traj.simultaneity_window == 1e-9


def test_the_law_is_named_for_every_linear_run():
    for law in LAW_NAMES:
        run = run_linear(LinearModel.polygon(4, 0.5, 0.5), (0.01, 0.0, 0.02), (0, 0, 0),
                         t_end=1.0, impact_law=law)  # fmt: skip
        assert run.impact_law == law


def test_the_harness_runs_the_linear_model_under_a_law_and_names_it():
    from harness.simulators import run_simulator
    from reference.scenes import as_scene

    scene = as_scene("triangle-chatter").with_impact_law("moreau", 1e-9)
    traj = run_simulator("linear", scene)
    assert traj.status is Status.SINGULARITY
    summary = traj.summary(with_impacts=False)
    assert summary["impact_law"] == "moreau"
    assert summary["simultaneity_window"] == 1e-9
