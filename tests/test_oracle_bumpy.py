"""The oracle (tests/oracle) on the bumpy ground: rim vertices on the plane and
bumps under the face at once.  Each kind's gap, normal velocity, normal acceleration and
Jacobian row against finite differences of the closed-form flight; impacts of each kind
against the single-impact law and the invariants it keeps; energy through an elastic run
with both kinds hitting; and the two limits: bumps that never reach the face give the
flat-ground run, a plane that the rim never reaches gives the three-point run (bumps
lowered by their height)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from reference.scene import Ground
from tests.conftest import make_scene
from tests.oracle import quaternion as qt
from tests.oracle.body import BodyModel, Q, V, W, X
from tests.oracle.events import gap_jet
from tests.oracle.flight import flight_acceleration, flight_constants, free_flight
from tests.oracle.impact import impact_impulse
from tests.oracle.simulate import simulate as oracle_simulate

N = 6
DELTA = 2e-3


def bumpy(scene, **ground):
    return replace(scene, ground=Ground(kind="bumpy", **ground))


def tumbling_state() -> np.ndarray:
    """A generic state: tilted, spinning, moving, above both kinds of contact."""
    y = np.zeros(13)
    y[X] = (0.02, -0.01, 0.3)
    y[Q] = qt.from_rotation_vector(np.array([0.25, -0.1, 0.4]))
    y[V] = (0.1, -0.2, -0.3)
    y[W] = (0.7, -0.4, 3.0)
    return y


@pytest.fixture
def model():
    scene = bumpy(make_scene(n=N, rho=0.5), bump_radius=0.5, bump_height=DELTA)
    return BodyModel.from_scene(scene)


def test_bumpy_ground_numbers_rim_vertices_then_bumps(model):
    assert model.n_rim == N and model.n_contacts == N + 3
    assert [model.is_bump(k) for k in range(N + 3)] == [False] * N + [True] * 3
    assert np.allclose(model.bumps[:, 2], DELTA) and np.allclose(
        np.hypot(model.bumps[:, 0], model.bumps[:, 1]), 0.5
    )


def test_gap_jets_of_both_kinds_match_finite_differences_of_the_flight(model):
    fc = flight_constants(model, tumbling_state())
    h = 1e-4
    s0 = 0.05
    ys = [free_flight(fc, s0 + d * h) for d in (-2, -1, 0, 1, 2)]
    gaps = np.array([model.contacts(y)[0] for y in ys])
    jet = gap_jet(model, ys[2], flight_acceleration(fc, ys[2]))
    rate_fd = (gaps[0] - 8 * gaps[1] + 8 * gaps[3] - gaps[4]) / (12 * h)
    accel_fd = (-gaps[0] + 16 * gaps[1] - 30 * gaps[2] + 16 * gaps[3] - gaps[4]) / (12 * h * h)
    assert np.allclose(jet.rate, rate_fd, rtol=0, atol=1e-10)
    assert np.allclose(jet.accel, accel_fd, rtol=0, atol=1e-6)


def test_jacobian_rows_of_both_kinds_are_the_gaps_derivative_along_a_rigid_motion(model):
    y = tumbling_state()
    gap, normal, lever, vn, _ = model.contacts(y)
    J = model.jacobian(normal, lever)
    rng = np.random.default_rng(3)
    du = rng.normal(size=6)
    eps = 1e-6

    def moved(e):
        z = np.array(y)
        z[X] += e * du[:3]
        z[Q] = qt.normalize(qt.multiply(qt.from_rotation_vector(e * du[3:]), y[Q]))
        return model.contacts(z)[0]

    fd = (moved(eps) - moved(-eps)) / (2 * eps)
    assert np.allclose(J @ du, fd, rtol=0, atol=1e-9)
    assert np.allclose(J @ np.concatenate([y[V], y[W]]), vn, rtol=0, atol=1e-14)


def _landing(model, k):
    """The tumbling state moved so contact k touches (gap 0) while approaching."""
    y = tumbling_state()
    y[V] = (0.0, 0.0, -1.0)
    y[X][2] -= model.contacts(y, [k])[0][0] / model.contacts(y, [k])[1][0][2]
    return y


@pytest.mark.parametrize("k", [0, N + 1])  # a rim vertex, a bump
@pytest.mark.parametrize("gamma", [0.0, 0.5, 1.0])
def test_an_impact_of_either_kind_follows_the_single_impact_law(model, k, gamma):
    y = _landing(model, k)
    assert abs(model.contacts(y, [k])[0][0]) < 1e-14
    res = impact_impulse(model, y, k, gamma)
    assert res.u_pre < 0 and res.u_post == pytest.approx(-gamma * res.u_pre, abs=1e-14)
    # the impulse is along the contact normal, applied at the contact point
    gap, normal, lever, _, _ = model.contacts(y, [k])
    P = model.mass * (res.y_post[V] - y[V])
    assert np.allclose(P, res.impulse * normal[0], atol=1e-14)
    L = model.angular_momentum
    assert np.allclose(
        L(res.y_post) - L(y), np.cross(lever[0], normal[0]) * res.impulse, atol=1e-13
    )
    # energy: ΔE = −½ (1 − γ²) u⁻² / w, w = J M⁻¹ Jᵀ
    w = -(1 + gamma) * res.u_pre / res.impulse
    dE = model.energy(res.y_post) - model.energy(y)
    assert dE == pytest.approx(-0.5 * (1 - gamma**2) * res.u_pre**2 / w, abs=1e-14)


def test_a_rim_impact_keeps_the_spin_about_the_vertical_and_a_bump_impact_the_spin_about_e3(
    model,
):
    y = _landing(model, 1)
    post = impact_impulse(model, y, 1, 0.5).y_post
    assert model.angular_momentum(post)[2] == pytest.approx(model.angular_momentum(y)[2], abs=1e-14)
    assert np.allclose(post[V][:2], y[V][:2], atol=1e-15)
    y = _landing(model, N + 2)
    post = impact_impulse(model, y, N + 2, 0.5).y_post
    e3 = qt.body_axis(y[Q])
    assert float(post[W] @ e3) == pytest.approx(float(y[W] @ e3), abs=1e-14)


def rolling_scene(n=N, gamma=1.0, delta=DELTA, tilt=2.5e-3, t_end=0.6, **kw):
    """A spinning n-gon low over the bumpy ground: tilted by `tilt`, its lowest vertex
    just above the plane, turning about its axis and nutating."""
    y = np.zeros(13)
    rv = np.array([tilt, 0.0, 0.0])
    y[Q] = qt.from_rotation_vector(rv)
    y[W] = (0.0, 0.3, 2.0)
    y[V] = (0.0, 0.0, -0.02)
    base = make_scene(n=n, gamma=gamma, rho=0.5, t_end=t_end, state=y, **kw)
    scene = bumpy(base, bump_radius=0.5, bump_height=delta)
    z0 = -float(BodyModel.from_scene(scene).contacts(y)[0].min()) + 1e-4
    y[X] = (0.0, 0.0, z0)
    return bumpy(
        make_scene(n=n, gamma=gamma, rho=0.5, t_end=t_end, state=y, **kw),
        bump_radius=0.5,
        bump_height=delta,
    )


def test_an_elastic_run_hits_both_kinds_and_keeps_its_energy():
    scene = rolling_scene()
    tr = oracle_simulate(scene)
    contacts = {ev.contact for ev in tr.impacts}
    assert any(k < N for k in contacts) and any(k >= N for k in contacts), contacts
    E = tr.kinetic_energy + tr.potential_energy
    assert np.max(np.abs(E - E[0])) <= 1e-11 * abs(E[0]) + 1e-13


def test_bumps_that_never_reach_the_face_give_exactly_the_flat_run():
    """Bumps at height 0 close to the axis: the tilted polygon's face stays above them
    (its centre is higher than a·sin α·0.05), so every impact is a rim impact, the same
    as on the flat ground, to the last bit."""
    scene = rolling_scene(gamma=0.5, tilt=0.1, t_end=1.0)
    far = replace(scene, ground=Ground(kind="bumpy", bumps=((0.01, 0.0, 0.0), (-0.01, 0.01, 0.0))))
    flat = replace(scene, ground=Ground(kind="flat"))
    a, b = oracle_simulate(far), oracle_simulate(flat)
    assert len(b.impacts) > 5
    assert [e.contact for e in a.impacts] == [e.contact for e in b.impacts]
    # the same events; the search steps differ (the bumps' bounds join the rim's), so
    # the times and impulses agree to roundoff, not bit for bit
    for ea, eb in zip(a.impacts, b.impacts, strict=True):
        assert ea.t == pytest.approx(eb.t, rel=1e-12)
        assert ea.impulse == pytest.approx(eb.impulse, rel=1e-12)
    assert (a.status, a.t_final) == (b.status, b.t_final)


def test_a_plane_the_rim_never_reaches_gives_the_three_point_run():
    """A disk low over three bumps of height 0.1 a, tilted 1e-3: its rim stays 0.099 a
    above the plane, and the run is the three-point ground's with everything lowered by
    0.1 a: the same contacts (n + k ↔ k), times and impulses to 1e-9 over the first 40
    impacts (the rocking is chaotic: the impulses part by 1e-6 near impact 75, the
    contacts near 100)."""
    h, lead = 0.1, 40
    y = np.zeros(13)
    y[Q] = qt.from_rotation_vector(np.array([1e-3, -5e-4, 0.0]))
    y[W] = (0.05, -0.02, 0.0)
    y[V] = (0.0, 0.0, -0.05)
    y[X] = (0.0, 0.0, 0.01)
    run = dict(t_end=2.0, max_impacts=lead + 1)  # as far as the compared impacts
    three = make_scene(n=N, gamma=0.5, rho=0.5, state=y, ground="three_point", **run)
    y_up = np.array(y)
    y_up[2] += h
    up = make_scene(n=N, gamma=0.5, rho=0.5, state=y_up, **run)
    up = bumpy(up, bump_radius=0.5, bump_height=h)
    a, b = oracle_simulate(up), oracle_simulate(three)
    assert len(a.impacts) > lead and len(b.impacts) > lead
    assert [e.contact - N for e in a.impacts[:lead]] == [e.contact for e in b.impacts[:lead]]
    ta = np.array([e.t for e in a.impacts[:lead]])
    tb = np.array([e.t for e in b.impacts[:lead]])
    assert np.allclose(ta, tb, rtol=0, atol=1e-9)
    ia = np.array([e.impulse for e in a.impacts[:lead]])
    ib = np.array([e.impulse for e in b.impacts[:lead]])
    assert np.allclose(ia, ib, rtol=0, atol=1e-9 * np.abs(ib).max())


def test_a_bump_outside_the_face_ends_the_run_left_model():
    """Bumps at 0.9 a and a disk drifting sideways fast: a bump meets the face's plane
    outside the rim; the model has no contact there."""
    y = np.zeros(13)
    y[X] = (0.5, 0.1, 0.05)
    y[Q] = qt.from_rotation_vector(np.array([0.013, 0.02, 0.0]))
    y[V] = (1.0, 0.0, -0.1)
    scene = bumpy(make_scene(n=N, gamma=0.5, t_end=2.0, state=y), bump_radius=0.9, bump_height=0.0)
    tr = oracle_simulate(scene)
    assert tr.status == "left_model", tr.message


# ------------------------------------------------------------------ the compiled core
def random_drop(seed: int):
    """A spinning n-gon dropped tilted over three bumps: n, γ, tilt, spin, bump radius
    and height drawn from the seed; the lowest contact of either kind 0.01 a up."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 13))
    y = np.zeros(13)
    y[Q] = qt.from_rotation_vector(np.array([*rng.uniform(-0.03, 0.03, 2), rng.uniform(0, 6)]))
    y[V] = (*rng.normal(0, 0.05, 2), -0.1)
    y[W] = (*rng.normal(0, 0.3, 2), rng.uniform(-2, 2))
    ground = dict(
        bump_radius=float(rng.uniform(0.3, 0.6)), bump_height=float(rng.uniform(0.002, 0.02))
    )
    gamma = float(rng.choice([0.5, 1.0]))  # γ = 0: the oracle's contact phases take minutes
    scene = bumpy(make_scene(n=n, gamma=gamma, rho=0.5, t_end=1.5, state=y), **ground)
    y[X] = (0.0, 0.0, 0.01 - float(BodyModel.from_scene(scene).contacts(y)[0].min()))
    return bumpy(make_scene(n=n, gamma=gamma, rho=0.5, t_end=1.5, state=y), **ground)


def _leading_agree(a, b, lead):
    """The first `lead` impacts: same contacts, times within 1e-9, impulses within 1e-9
    of the largest (tests/test_oracle.py's criteria for impacts in flight)."""
    ea, eb = a.impacts[:lead], b.impacts[:lead]
    assert [e.contact for e in ea] == [e.contact for e in eb]
    assert np.allclose([e.t for e in ea], [e.t for e in eb], rtol=0, atol=1e-9)
    big = max(abs(e.impulse) for e in eb)
    assert np.allclose([e.impulse for e in ea], [e.impulse for e in eb], rtol=0, atol=1e-9 * big)


# Seeds whose first 30 impacts hit both kinds (6 and 7: the rim alone).  Measured over
# seeds 0-9: every compared impact agrees, times within 2e-12 (the most, seed 2, 1.8e-12).
BOTH_KINDS = (0, 1, 2, 3, 4, 5, 8, 9)


@pytest.mark.parametrize("seed", BOTH_KINDS)
def test_the_core_follows_the_oracle_impact_by_impact_on_random_bumpy_drops(seed):
    from reference import simulate

    scene = random_drop(seed).with_run(max_impacts=30)  # as far as the compared impacts
    ours, exact = simulate(scene), oracle_simulate(scene)
    lead = min(30, len(ours.impacts), len(exact.impacts))
    kinds = {e.contact >= scene.body.n for e in exact.impacts[:lead]}
    assert lead >= 5 and kinds == {False, True}, (lead, kinds)
    _leading_agree(ours, exact, lead)


def test_the_core_gives_the_flat_run_when_the_bumps_never_reach_the_face():
    """The compiled core on the flat-limit scene: the flat ground's impacts, the same
    contacts, times and impulses to roundoff (measured: 3.3e-16; the search steps differ
    beside the bumps, so not bit for bit), the same status and end."""
    from reference import simulate

    scene = rolling_scene(gamma=0.5, tilt=0.1, t_end=1.0)
    far = replace(scene, ground=Ground(kind="bumpy", bumps=((0.01, 0.0, 0.0), (-0.01, 0.01, 0.0))))
    a, b = simulate(far), simulate(replace(scene, ground=Ground(kind="flat")))
    assert len(b.impacts) > 5
    assert [e.contact for e in a.impacts] == [e.contact for e in b.impacts]
    for ea, eb in zip(a.impacts, b.impacts, strict=True):
        assert ea.t == pytest.approx(eb.t, rel=1e-14)
        assert ea.impulse == pytest.approx(eb.impulse, rel=1e-12)
    assert (a.status, a.t_final) == (b.status, b.t_final)


def test_the_core_gives_the_three_point_run_when_the_rim_never_reaches_the_plane():
    """The compiled core on the three-point-limit scene (bumps 0.1 a high, the disk
    tilted 1e-3 over them): the three-point ground's first 40 impacts, lowered by 0.1 a
    (measured: the first 60 within 3e-11 s; chaos parts them near impact 96)."""
    from reference import simulate

    h = 0.1
    y = np.zeros(13)
    y[Q] = qt.from_rotation_vector(np.array([1e-3, -5e-4, 0.0]))
    y[W] = (0.05, -0.02, 0.0)
    y[V] = (0.0, 0.0, -0.05)
    y[X] = (0.0, 0.0, 0.01)
    three = make_scene(n=N, gamma=0.5, rho=0.5, t_end=2.0, state=y, ground="three_point")
    y[2] += h
    up = bumpy(
        make_scene(n=N, gamma=0.5, rho=0.5, t_end=2.0, state=y), bump_radius=0.5, bump_height=h
    )
    a, b = simulate(up), simulate(three)
    lead = 40
    assert [e.contact - N for e in a.impacts[:lead]] == [e.contact for e in b.impacts[:lead]]
    ta, tb = [e.t for e in a.impacts[:lead]], [e.t for e in b.impacts[:lead]]
    assert np.allclose(ta, tb, rtol=0, atol=1e-9)
