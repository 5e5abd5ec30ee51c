"""The exact event-driven simulator of the linearised model (reference/linear/kernel.py)."""

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest

from reference.linear import kernel as K
from reference.linear.model import LinearModel
from reference.linear.simulate import run_linear, simulate_linear
from reference.scene import scene_from_dict
from reference.trajectory import Status


def _scene(n, rho, gamma, q, p, t_end=5.0, ground="flat", max_impacts=100_000):
    return scene_from_dict(
        {
            "restitution": gamma,
            "body": {"n": n, "radius": 1.0, "mass": 1.0, "gyration": rho},
            "ground": {"kind": ground},
            "initial": {"q": list(q), "p": list(p)},
            "run": {"t_end": t_end, "max_impacts": max_impacts},
        }
    )


def _exact_root(g, v, a):
    """First positive root of g + v s + a s²/2 in 60-digit decimal arithmetic."""
    getcontext().prec = 60
    g, v, a = Decimal(g), Decimal(v), Decimal(a)
    if a == 0:
        return float(-g / v)
    disc = v * v - 2 * a * g
    r = [(-v + s * disc.sqrt()) / a for s in (1, -1)]
    return float(min(x for x in r if x > 0))


def test_first_hit_is_correctly_rounded_even_with_cancellation():
    rng = np.random.default_rng(0)
    for _ in range(300):
        g = 10 ** rng.uniform(-12, 0)
        v = rng.choice([-1, 1]) * 10 ** rng.uniform(-8, 1)
        a = -(10 ** rng.uniform(-3, 1))
        assert K.first_hit(g, v, a) == pytest.approx(_exact_root(g, v, a), rel=4e-16)
    # approaching against a braking acceleration: the first of two roots
    assert K.first_hit(1.0, -3.0, 2.0) == pytest.approx(_exact_root(1.0, -3.0, 2.0), rel=4e-16)
    assert K.first_hit(1.0, -1.0, 2.0) == math.inf  # turns back before the ground
    assert K.first_hit(0.0, 2.0, -4.0) == pytest.approx(1.0, rel=1e-16)  # leaves, returns


def test_flat_drop_is_a_simultaneous_impact_at_the_free_fall_time():
    tr = simulate_linear(_scene(6, 0.5, 0.5, (0, 0, 0.02), (0, 0, 0)))
    assert tr.status is Status.SIMULTANEOUS_IMPACT
    assert tr.t_final == pytest.approx(math.sqrt(2 * 0.02), rel=1e-15)
    assert not tr.impacts


def test_first_impact_time_and_vertex_from_the_flight_parabolas():
    q, p = np.array([0.01, -0.006, 0.05]), np.array([0.05, 0.02, -0.1])
    m = LinearModel.polygon(5, 0.5, 0.8)
    times = [_exact_root(f @ q, f @ p, -1.0) for f in m.F]
    run = run_linear(m, q, p, max_impacts=1)
    i = run.impact_rows[0]
    assert run.contact[i] == int(np.argmin(times))
    assert run.t_hi[i] == pytest.approx(min(times), rel=2e-16)


def test_elastic_impacts_keep_the_energy_to_roundoff():
    q, p = (0.01, -0.004, 0.03), (0.03, 0.05, -0.2)
    run = run_linear(LinearModel.polygon(6, 0.5, 1.0), q, p, t_end=20.0)
    assert run.status is Status.T_END and run.n_impacts > 100
    E = run.energy_post
    assert np.max(np.abs(E - E[0])) < 64 * np.finfo(float).eps * E[0]


def test_energy_lost_at_each_impact_is_the_newton_formula():
    m = LinearModel.polygon(5, 0.4, 0.7)
    run = run_linear(m, (0.01, -0.006, 0.05), (0.05, 0.02, -0.1), max_impacts=200)
    for i in run.impact_rows[:150]:
        f = m.F[run.contact[i]]
        w = f @ (f / m.theta)
        loss = (1 - 0.49) * run.v_pre[i] ** 2 / (2 * w)
        assert run.energy_pre[i] - run.energy_post[i] == pytest.approx(loss, rel=1e-9)


def test_scaling_invariance_is_exact_for_powers_of_two():
    """(q, p, t) → (β²q, βp, βt) (paper §2.6): with β = 2⁻²⁰ the kernel's exact
    renormalisation makes the scaled run the same run, bit for bit."""
    m = LinearModel.polygon(5, 0.5, 0.8)
    q, p = np.array([0.01, -0.006, 0.05]), np.array([0.05, 0.02, -0.1])
    a = run_linear(m, q, p)
    b_ = 2.0**-20
    b = run_linear(m, q * b_**2, p * b_)
    assert a.n_impacts == b.n_impacts > 500
    assert np.array_equal(a.contact, b.contact)
    assert np.array_equal(a.t_hi * b_, b.t_hi)
    assert np.array_equal(a.q_post * b_**2, b.q_post)


def test_scaling_invariance_holds_to_roundoff_for_other_factors():
    m = LinearModel.polygon(5, 0.5, 0.8)
    q, p = np.array([0.01, -0.006, 0.05]), np.array([0.05, 0.02, -0.1])
    a = run_linear(m, q, p, max_impacts=40)
    b_ = 1e-7
    b = run_linear(m, q * b_**2, p * b_, max_impacts=40)
    assert np.array_equal(a.contact, b.contact)
    assert np.allclose(a.t_hi * b_, b.t_hi, rtol=1e-11, atol=0)


def test_rotation_invariance_shifts_the_contacts():
    m = LinearModel.polygon(7, 0.45, 0.6)
    q, p = np.array([0.01, -0.006, 0.05]), np.array([0.05, 0.02, -0.1])
    a = run_linear(m, q, p, max_impacts=30)
    b = run_linear(m, m.R @ q, m.R @ p, max_impacts=30)
    ia, ib = a.impact_rows, b.impact_rows
    assert np.array_equal((a.contact[ia] + 1) % 7, b.contact[ib])
    assert np.allclose(a.t_hi[ia], b.t_hi[ib], rtol=1e-12)


@pytest.mark.parametrize("rho, decidable", [(0.6, False), (0.8, True)])
def test_plastic_triangle_impact_beside_a_held_vertex_follows_the_paper_rule(rho, decidable):
    """γ = 0: vertex 0 lands and stays; when vertex 1 hits, the impulse changes vertex 0's
    velocity by −(1+γ) (f0ᵀΘ⁻¹f1 / f1ᵀΘ⁻¹f1) v1⁻, and f0ᵀΘ⁻¹f1 ∝ 1 + r0·r1/ρ² = 1 − 1/(2ρ²):
    negative (undecidable) for ρ < 1/√2, positive (vertex 0 lifts off) above."""
    m = LinearModel.polygon(3, rho, 0.0)
    q, p = np.array([0.004, 0.01, 0.02]), np.array([0.0, 0.0, -0.01])
    run = run_linear(m, q, p, max_impacts=3)
    first = run.contact[run.impact_rows[0]]
    if decidable:
        assert len(run.impact_rows) >= 2
        i = run.impact_rows[1]
        assert m.F[first] @ run.p_post[i] > 0  # the held vertex lifts off
    else:
        assert run.status is Status.SIMULTANEOUS_IMPACT and run.reason == 2
        assert len(run.impact_rows) == 1


def test_rolling_polygon_keeps_the_held_vertex_on_the_ground_and_none_below():
    sc = _scene(25, 0.5, 0.0, (0.0, 0.05, 0.05), (0.3, 0.0, 0.0), t_end=1.0)
    tr = simulate_linear(sc, sample_dt=1e-3)
    m = LinearModel.from_scene(sc)
    q = np.column_stack([tr.quaternion[:, 1] * 2, tr.quaternion[:, 2] * 2, tr.position[:, 2]])
    gaps = q @ m.F.T
    assert gaps.min() > -1e-12 * 0.05
    contact_phases = [ph for ph in tr.phases if ph.kind == "contact"]
    assert len(contact_phases) > 5 and all(len(ph.contacts) == 1 for ph in contact_phases)
    assert tr.status is Status.T_END and tr.t_final == 1.0


def test_chatter_completion_agrees_with_resolving_the_impacts():
    """A pentagon dropped nearly flat on one vertex: the completed sequence (as soon as
    provably alone) and one resolved impact by impact to 1e-10 of the velocity scale
    reach the same accumulation time and state."""
    m = LinearModel.polygon(5, 0.5, 0.5)
    q, p = np.array([0.0, 0.02, 0.021]), np.array([0.0, 0.0, -0.01])
    fast = run_linear(m, q, p, chatter_tol=math.inf, max_impacts=200)
    slow = run_linear(m, q, p, chatter_tol=1e-10, decouple_tol=1e-13, max_impacts=200)
    ia = np.flatnonzero(fast.kind == K.ACCUMULATION)[0]
    ib = np.flatnonzero(slow.kind == K.ACCUMULATION)[0]
    assert ib > ia + 20  # the slow run resolved 20 more impacts of the sequence
    assert fast.contact[ia] == slow.contact[ib]
    assert fast.t_hi[ia] == pytest.approx(slow.t_hi[ib], rel=1e-14)
    assert np.allclose(fast.q_post[ia], slow.q_post[ib], rtol=1e-9, atol=1e-15)
    assert np.allclose(fast.p_post[ia], slow.p_post[ib], rtol=1e-9, atol=1e-12)


def test_triangle_two_point_chatter_ends_undecidable_for_small_gyration():
    """triangle-chatter (ρ = 0.3, γ = 0.5): after a two-vertex accumulation the third
    vertex hits beside two held ones and would drive them into the ground."""
    sc = _scene(3, 0.3, 0.5, (0.02, 0.0, 0.05), (0.0, 0.0, 0.0), t_end=3.0)
    tr = simulate_linear(sc)
    assert tr.status is Status.SIMULTANEOUS_IMPACT
    assert any(len(a["contacts"]) == 2 for a in tr.stats["accumulations"])


def test_rod_with_roll_ends_in_a_two_point_accumulation():
    """ψ = 0.86 > (γ^⅓+γ^⅔)/(1+γ) = 0.77: the rod chatters to rest on both endpoints in
    finite time; the roll ωx, invisible to the contacts, keeps its energy."""
    sc = _scene(2, 0.27, 0.2, (0.0, 0.02, 0.05), (0.3, 0.0, -0.1))
    tr = simulate_linear(sc)
    assert tr.status is Status.SINGULARITY
    assert tr.t_singularity == tr.t_final
    assert tr.angular_velocity[-1, 0] == pytest.approx(0.3, rel=1e-15)


def test_trajectory_summary_of_a_linear_run():
    sc = _scene(5, 0.5, 0.8, (0.01, -0.006, 0.05), (0.05, 0.02, -0.1), t_end=1.0)
    tr = simulate_linear(sc)
    doc = tr.summary()
    assert doc["engine"] == "linear" and doc["status"] == "t_end"
    t = tr.impact_times()
    assert np.all(np.diff(t) > 0) and set(t) <= set(tr.t)
    m = LinearModel.from_scene(sc)
    # energies are the linear quadratic form of the mapped state
    i = len(tr.t) // 2
    qv = np.array([2 * tr.quaternion[i, 1], 2 * tr.quaternion[i, 2], tr.position[i, 2]])
    pv = np.array([tr.angular_velocity[i, 0], tr.angular_velocity[i, 1], tr.velocity[i, 2]])
    assert tr.energy[i] == pytest.approx(m.energy(qv, pv), rel=1e-6)


def test_max_impacts_stops_the_run():
    run = run_linear(LinearModel.polygon(5, 0.5, 0.9), (0.01, 0, 0.05), (0, 0, -0.1), max_impacts=7)
    assert run.status is Status.MAX_IMPACTS and run.n_impacts == 7


@pytest.mark.parametrize("name", ["pentagon-bounce", "triangle-chatter", "three-point-disk"])
def test_grid_samples_inside_a_phase_keep_the_linear_energy(name):
    """Regression: grid samples are evaluated on each segment's quadratic with that
    segment's acceleration (−g u3, or a_contact when held), so the linear energy
    ½pᵀΘp + m g h is constant between events to roundoff."""
    import numpy as np

    from harness.scenes import resolve_scene

    t = simulate_linear(resolve_scene(name), t_end=1.0)
    events = np.array([p.t_start for p in t.phases] + [p.t_end for p in t.phases])
    worst = 0.0
    for i in range(len(t.t) - 1):
        a, b = t.t[i], t.t[i + 1]
        if np.any((events >= a - 1e-15) & (events <= b + 1e-15)):
            continue
        worst = max(worst, abs(t.energy[i + 1] - t.energy[i]))
    assert worst <= 1e-14 * t.energy[0]


def test_a_linear_run_is_timed_without_the_kernels_compilation_and_compiles_it_once():
    scene = _scene(3, 0.5, 0.5, [0.1, 0.05, 0.2], [0.0, 0.0, 0.0], t_end=1.0)
    simulate_linear(scene)  # compiled or loaded here, if not before in this process
    again = simulate_linear(scene)
    assert again.compile_s == 0.0 and again.wall_time_s > 0.0
    # the types the kernel was compiled for are those of its calls: nothing more compiled
    assert len(K.start_kernel.signatures) == 1 and len(K.continue_kernel.signatures) == 1
