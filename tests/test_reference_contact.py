"""Sustained contact: forces against an independent Newton–Euler solve and the paper's
closed form; lift-off where the force crosses zero; no drift."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from reference import ReferenceOptions
from reference import quaternion as qt
from reference.core.contacts import vertex_lever
from reference.core.held import held_forces, new_work
from reference.geometry import contact_points, scene_contact_kinematics
from reference.simulate import simulate
from tests.conftest import core_model, make_scene


def newton_euler_single_contact(scene, y: np.ndarray, k: int):
    """Paper eqs. (rollF), (rollM), (rollc) for one flat-ground contact as a 7×7 linear
    system in (v̇, ω̇, η), assembled here independently of the core."""
    q, w = y[3:7], y[10:13]
    r = qt.rotate(q, contact_points(scene.body, scene.ground)[k])
    i1, _, i3 = scene.body.inertia_diag
    e = [qt.rotate(q, axis) for axis in np.eye(3)]
    Iw = sum(i * np.outer(a, a) for i, a in zip((i1, i1, i3), e, strict=True))
    mass, g = scene.body.mass, scene.gravity
    ez = np.array([0.0, 0.0, 1.0])
    M = np.zeros((7, 7))
    rhs = np.zeros(7)
    M[0:3, 0:3] = mass * np.eye(3)
    M[0:3, 6] = -ez
    rhs[0:3] = -mass * g * ez
    M[3:6, 3:6] = Iw
    M[3:6, 6] = -np.cross(r, ez)
    rhs[3:6] = -np.cross(w, Iw @ w)
    # ez·(v̇ + ω̇ × r + ω × (ω × r)) = 0, with ez·(ω̇ × r) = ω̇·(r × ez)
    M[6, 0:3] = ez
    M[6, 3:6] = np.cross(r, ez)
    rhs[6] = -ez @ np.cross(w, np.cross(w, r))
    return np.linalg.solve(M, rhs)


def rocking_state(wy=1.5, wz=0.0, tilt=0.3):
    """Vertex 0 (body point (1, 0, 0)) on the ground with zero normal velocity, the body
    rocking about world y."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector([0.0, tilt, 0.0])
    y[10:13] = [0.0, wy, wz]
    rx, ry, rz = vertex_lever(y, 1.0, 0.0)
    y[2] = -rz
    y[9] = -(y[10] * ry - y[11] * rx)
    return y


def contact_force(scene, y, k):
    model, pts = core_model(scene)
    scratch = new_work()
    _, ok = held_forces(y, model, pts, np.array([k, 0, 0]), 1, scratch[0])
    assert ok
    return scratch[0]["lam"][0]


def test_single_contact_force_matches_independent_newton_euler_solve():
    scene = make_scene(n=5, rho=0.41)
    y = rocking_state(wy=0.7, wz=1.3, tilt=0.2)
    expect = newton_euler_single_contact(scene, y, 0)[6]
    assert abs(contact_force(scene, y, 0) - expect) < 1e-13 * abs(expect)


def test_contact_force_at_rest_small_tilt_is_the_papers_closed_form():
    """Linearised model (paper eq. under (pacccontact)): η = m g / (1 + ρ⁻²)."""
    for rho in (0.3, 0.5, 0.8):
        scene = make_scene(n=5, rho=rho)
        y = rocking_state(wy=0.0, wz=0.0, tilt=1e-7)
        assert abs(contact_force(scene, y, 0) - 1.0 / (1.0 + rho**-2)) < 1e-12


def test_lift_off_time_is_where_the_force_crosses_zero():
    """Reference lift-off against scipy's event location on an independently written
    constrained RHS (the 7×7 solve above), DOP853 at rtol 1e-12."""
    scene0 = make_scene(n=3, gamma=0.0)
    y0 = rocking_state(wy=1.5)
    traj = simulate(make_scene(n=3, gamma=0.0, state=y0, t_end=0.5))
    assert traj.stats["lift_offs"] >= 1
    contact = traj.phases[0]
    assert contact.kind == "contact" and contact.contacts == (0,)
    t_ref = contact.t_end

    def rhs(_t, y):
        sol = newton_euler_single_contact(scene0, y, 0)
        dy = np.zeros(13)
        dy[0:3] = y[7:10]
        dy[3:7] = 0.5 * qt.multiply(np.r_[0.0, y[10:13]], y[3:7])
        dy[7:13] = sol[0:6]
        return dy

    def force(_t, y):
        return newton_euler_single_contact(scene0, y, 0)[6]

    force.terminal = True
    force.direction = -1
    sol = solve_ivp(rhs, (0, 0.5), y0, method="DOP853", rtol=1e-12, atol=1e-14, events=force)
    t_scipy = sol.t_events[0][0]
    assert abs(t_ref - t_scipy) < 1e-9


def test_contact_phase_keeps_energy_and_constraints():
    y0 = rocking_state(wy=1.0)
    scene = make_scene(n=3, gamma=0.0, state=y0, t_end=0.4)
    traj = simulate(scene)
    assert traj.phases[0].kind == "contact"
    E = traj.energy
    assert np.max(np.abs(E - E[0])) < 1e-11 * E[0]
    # the held vertex stays on the ground: gap from the samples, recomputed here
    for i in range(0, traj.n_samples, 50):
        y = np.r_[traj.position[i], traj.quaternion[i], traj.velocity[i], traj.angular_velocity[i]]
        g = scene_contact_kinematics(scene, y)[0][0, 0]
        assert abs(g) < 1e-12  # dense-output samples inside chunks; chunk ends are projected


def test_gamma_zero_heavy_rim_triangle_reaches_the_singularity():
    """Regression (sweep at ρ = 1, γ = 0): a contact force that is already pulling at a
    chunk start, or crosses zero only in the projected end state, is a lift-off, not a
    root-finding failure.  The run must end in a decided state with energy exhausted.
    Strictly sequential (the paper's default window 0): at t = 2.7377 the edge 1-2 lands
    with its vertices 1.3e-13 apart at 0.12 and 0.09, which the laws' default window
    makes one simultaneous impact (the paper's rule then ends the run there: checked)."""
    q = (-0.0004465939407552824, 0.000480321018228262, 1.0)
    p = (-0.03882222191615614, 0.03983622205983048, -1.0)
    scene = make_scene(n=3, rho=1.0, gamma=0.0, q=q, p=p, t_end=200.0)
    windowed = simulate(scene, options=ReferenceOptions(simultaneity_window=1e-11))
    traj = simulate(scene)
    assert traj.status.value == "singularity"
    # the pair of the strictly sequential run that the window merges: two contacts within
    # 1e-11 |u| of each other, where the windowed run stops
    pair = next(
        (a, b)
        for a, b in pairwise(traj.impacts)
        if a.contact != b.contact and b.t - a.t <= 1e-11 * abs(a.v_normal_pre)
    )
    assert windowed.status.value == "simultaneous_impact"
    assert windowed.t_final == pytest.approx(pair[0].t, abs=1e-12)
    assert f"v{min(pair[0].contact, pair[1].contact)}, " in windowed.message
    assert traj.t_singularity is not None and traj.t_singularity > traj.impacts[-1].t - 1e-9


def test_impact_ending_a_contact_phase_is_where_the_gap_is_zero():
    """The impact of a vertex that reaches the ground during a contact phase (γ = 0, a
    rolling square) is at the time a run with a 100× tighter integration tolerance gives:
    it is located on the gap's zero, not where the gap came within the integrator's
    resolution (which would put it ~1e-10 early on these grazing approaches)."""
    from reference import ReferenceOptions

    scene = make_scene(n=4, gamma=0.0, rho=0.45, q=(0.012, -0.007, 0.05), p=(0.2, -0.15, -0.5))
    run = simulate(scene)
    tight = simulate(scene, options=ReferenceOptions(contact_rtol=1e-14))
    assert run.stats.contact_phases >= 5
    n = min(len(run.impacts), len(tight.impacts))
    assert n >= 10
    for a, b in zip(run.impacts[:n], tight.impacts[:n], strict=True):
        assert a.contact == b.contact
        assert abs(a.t - b.t) <= 1e-11


def test_chunk_cap_keeps_the_time_scale_of_a_body_passing_flat_while_moving():
    """horizon.local_time_cap: with the body flat at the bumps' height (L = |z| + a sin α
    = 0) and rising at ż = U, the cap is LOCAL_TIME_FRACTION √(L_reach/K) with
    L_reach = U²/(2K), i.e. F·U/(√2 K) (not √(0/K) = 0, which would make chunks of 1e-21 s
    after impacts beside two held contacts); at rest it is F √(L/K)."""
    from reference.core.horizon import local_time_cap
    from reference.core.tolerances import LOCAL_TIME_FRACTION as F

    model, _ = core_model(make_scene(n=3, ground="three_point"))
    K, U = 2.5, 0.02
    y = np.zeros(13)
    y[3] = 1.0
    y[9] = U
    assert local_time_cap(y, model, K) == pytest.approx(F * U / (np.sqrt(2.0) * K), rel=1e-12)
    y[9], y[2] = 0.0, 1e-4
    assert local_time_cap(y, model, K) == pytest.approx(F * np.sqrt(1e-4 / K), rel=1e-12)


def test_a_chunk_far_shorter_than_the_integrators_step_is_one_heun_euler_step():
    """phases._short_chunk: a rolling square (γ = 0) stepped one loop step at a time has
    chunks of two right-hand-side evaluations (the Heun–Euler step and the held forces
    at its end), each at most HEUN_STEP_RATIO of the step the integrator proposed
    before it, where a DOP853 chunk costs 12 or more; its impacts agree with a run at a
    100× tighter tolerance (`test_impact_ending_a_contact_phase_is_where_the_gap_is_zero`)."""
    from reference import ReferenceOptions, compiled
    from reference.core.records import RETURN_DONE, RETURN_GROW
    from reference.core.tolerances import HEUN_STEP_RATIO
    from reference.simulate import make_problem

    scene = make_scene(n=4, gamma=0.0, rho=0.45, q=(0.012, -0.007, 0.05), p=(0.2, -0.15, -0.5))
    opts = ReferenceOptions(work_budget=1)
    problem = make_problem(scene, scene.run.t_end, opts)
    kernel = compiled.run_events()
    short = 0
    while True:
        state0, evals0 = problem.state[0].copy(), int(problem.counters[0]["contact_rhs_evals"])
        code = kernel(*problem.arguments())
        evals = int(problem.counters[0]["contact_rhs_evals"]) - evals0
        if state0["in_contact"] and evals == 2:
            short += 1
            state1 = problem.state[0]
            h = (state1["t_hi"] - state0["t_hi"]) + (state1["t_lo"] - state0["t_lo"])
            assert 0 < h <= HEUN_STEP_RATIO * state0["h_next"] * (1 + 1e-12)
        if code == RETURN_DONE:
            break
        if code == RETURN_GROW:
            problem.grow(opts.max_samples)
    assert short >= 3


def test_a_rod_released_at_rest_on_one_vertex_falls_flat_at_the_energy_equations_time():
    """A rod (n = 2) at rest, tilted θ0 = 0.3 on vertex 0 (frictionless): the vertex
    slides, the centre falls straight down (z = a sin θ) and θ̇² = 2g(sin θ0 − sin θ) /
    (a (cos²θ + ρ²)); vertex 1 lands at T = ∫₀^θ0 dθ/θ̇ (quadrature, independent), where
    the paper's rule stops (both vertices down).  A start with every velocity exactly 0
    runs (it does not fail at t = 0 with "step size below roundoff")."""
    from scipy.integrate import quad

    from tests.test_impact_law_runs import _on_ground

    theta0 = 0.3
    scene, y = _on_ground(2, [0.0, theta0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    traj = simulate(make_scene(n=2, gamma=0.5, state=y, t_end=5.0))
    a, rho, g = scene.body.radius, scene.body.gyration, scene.gravity

    def dt_dtheta(th):
        return 1.0 / np.sqrt(
            2 * g * (np.sin(theta0) - np.sin(th)) / (a * (np.cos(th) ** 2 + rho**2))
        )

    landing, err = quad(dt_dtheta, 0.0, theta0, limit=200)
    assert err < 1e-10
    assert traj.status.value == "simultaneous_impact"
    assert traj.t_final == pytest.approx(landing, rel=1e-10)
    assert np.max(np.abs(traj.position[:, 0] - traj.position[0, 0])) < 1e-12  # no push
