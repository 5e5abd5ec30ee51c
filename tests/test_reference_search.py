"""The event search of the compiled core (reference.core.search): the state at the
horizon, and the large-polygon window against every-vertex searches."""

from __future__ import annotations

import numpy as np
import pytest

from harness.scenes import resolve_scene
from reference import ReferenceOptions, simulate
from reference import quaternion as qt
from reference.core.flight import flight_bounds, flight_constants
from reference.core.records import EVENT_IMPACT, EVENT_NONE, RIM_VERTEX_ON_PLANE
from reference.geometry import initial_state
from reference.scene import Body, Ground, InitialState, RunSettings, Scene, initial_from_linear
from tests.conftest import core_model, flight, gaps, make_scene
from tests.core_calls import (
    examine_range_as_the_loop_does,
    find_flight_event_as_the_loop_does,
    on_the_loops_state,
)
from tests.oracle.body import BodyModel
from tests.oracle.events import next_flight_event
from tests.oracle.flight import flight_constants as oracle_flight_constants


def test_final_sample_at_t_end_is_the_closed_form_state_there():
    """With no contact reached before t_end the run ends with the closed-form state at
    t_end, not at the search's last safe step."""
    scene = resolve_scene("elastic-hexagon").with_run(t_end=0.05)  # no impact before 0.05
    traj = simulate(scene)
    assert len(traj.impacts) == 0 and traj.t[-1] == 0.05
    exact = flight(scene, initial_state(scene.initial), 0.05)
    assert qt.angle_between(traj.quaternion[-1], exact[3:7]) < 1e-14
    assert np.max(np.abs(traj.position[-1] - exact[0:3])) < 1e-15


def _polygon(n, initial, gamma=1.0, t_end=10.0, max_impacts=100_000):
    return Scene(
        name=f"n{n}",
        body=Body(n=n, gyration=0.5),
        ground=Ground(),
        initial=initial,
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=t_end, max_impacts=max_impacts),
    )


def _random_flights(n: int, count: int, seed: int):
    """n-gons in flight above flat ground: tilt from 1e-4 to 0.3 rad, spin about every
    axis, the lowest vertex 1e-9 … 1e-2 above the ground, falling or rising."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        tilt = 10 ** rng.uniform(-4, np.log10(0.3))
        az = rng.uniform(0, 2 * np.pi)
        rotvec = (tilt * np.cos(az), tilt * np.sin(az), rng.uniform(-np.pi, np.pi))
        scene = _polygon(
            n,
            InitialState(
                position=(0.0, 0.0, float(np.sin(tilt) + 10 ** rng.uniform(-9, -2))),
                rotation_vector=tuple(float(x) for x in rotvec),
                velocity=(0.0, 0.0, float(rng.uniform(-0.5, 0.2))),
                angular_velocity=tuple(float(x) for x in rng.normal(0, 0.5, 3)),
            ),
        )
        y = initial_state(scene.initial)
        if gaps(scene, y).min() > 0:
            yield scene, y


def _product_event(scene, y, window):
    model, pts = core_model(scene)
    fc = flight_constants(y, scene.body.inertia_diag[0], scene.body.inertia_diag[2])
    bounds = on_the_loops_state(flight_bounds, y, fc, model, pts, 10.0)
    out, together = y.copy(), np.empty(len(pts), dtype=np.int64)  # out: the state at 0
    ev = find_flight_event_as_the_loop_does(y, fc, bounds, model, pts, window, 0.0, 10.0, out,
                                            together)  # fmt: skip
    return ev, sorted(together[: ev.n_together].tolist())


@pytest.mark.parametrize(
    "n,count",
    # n = 10,000 repeats n = 1,000's check at ten times its cost: `-m slow`
    [(20, 40), (24, 40), (33, 40), (100, 40), (1000, 20),
     pytest.param(10_000, 6, marks=pytest.mark.slow)],
)  # fmt: skip
def test_large_n_window_search_finds_the_event_of_every_vertex_search(n, count):
    """For n > SMALL_N (19) the search examines only a window of vertices near the lowest
    direction and bounds the rest by the circle through them.  Against the same search
    over every vertex, and against the oracle's (every vertex, the original derivative
    bounds): the same first vertex, the same time to 1e-12."""
    compared = 0
    for scene, y in _random_flights(n, count, seed=n):
        win, win_c = _product_event(scene, y, True)
        full, full_c = _product_event(scene, y, False)
        model = BodyModel.from_scene(scene)
        orc = next_flight_event(model, oracle_flight_constants(model, y), 10.0)
        assert (win.kind == EVENT_NONE) == (full.kind == EVENT_NONE) == (orc is None)
        if orc is None:
            continue
        assert win.kind == full.kind == EVENT_IMPACT and orc.kind == "impact"
        assert win_c == full_c == list(orc.contacts)
        assert abs(win.s - orc.s) <= 1e-12 * max(1.0, orc.s)
        assert abs(full.s - orc.s) <= 1e-12 * max(1.0, orc.s)
        compared += 1
    assert compared >= count // 2


@pytest.mark.parametrize("n,n_compare", [(100, 20), (1000, 12), (10_000, 4)])
def test_large_n_runs_agree_with_every_vertex_runs(n, n_compare):
    """Whole bouncing runs (searches right after an impact, the impacting vertex and its
    neighbours within roundoff of the ground): window search and every-vertex search give
    the same impacts."""
    scene = _polygon(
        n, initial_from_linear((0.01, -0.004, 0.03), (0.03, 0.05, -0.2)), t_end=100.0,
        max_impacts=n_compare,
    )  # fmt: skip
    win = simulate(scene)
    full = simulate(scene, options=ReferenceOptions(window_search=False))
    assert len(win.impacts) == len(full.impacts) == n_compare
    for a, b in zip(win.impacts, full.impacts, strict=True):
        assert a.contact == b.contact
        assert abs((a.t - b.t) + (a.t_lo - b.t_lo)) <= 1e-12


@pytest.mark.parametrize(
    "n,gamma,count,tol", [(200, 0.0, 150, 1e-12), (1000, 0.0, 150, 1e-12), (1000, 0.5, 1500, 5e-11)]
)
def test_large_n_contact_phases_agree_with_every_vertex_contact_phases(n, gamma, count, tol):
    """Rolling and rocking large polygons (γ = 0: one contact phase per impact): contact
    steps that examine a window of vertices give the impacts of steps that examine all.
    The two searches take different steps to the same events, so they differ by
    roundoff, which the rocking amplifies: for γ = 0.5 from 1e-15 to ~1e-11 over 1,500
    impacts (tolerance 5e-11); for γ = 0 at most 4e-14 over 150 (tolerance 1e-12)."""
    scene = make_scene(
        n=n, gamma=gamma, rho=0.45, q=(0.012, -0.007, 0.05), p=(0.2, -0.15, -0.5),
        t_end=100.0, max_impacts=count,
    )  # fmt: skip
    win = simulate(scene)
    full = simulate(scene, options=ReferenceOptions(window_search=False))
    assert win.stats.contact_phases >= 20
    assert len(win.impacts) == len(full.impacts) == count
    for a, b in zip(win.impacts, full.impacts, strict=True):
        assert a.contact == b.contact
        assert abs((a.t - b.t) + (a.t_lo - b.t_lo)) <= tol


@pytest.mark.parametrize("seed", range(3))
def test_examining_the_likeliest_vertex_first_gives_the_least_step(seed):
    """The order in which a search step examines vertices (`examine_range`: the
    likeliest to bind first) changes the step only within the roots' tolerance: it lies
    between the least of the vertices' safe steps, each computed alone without a cap
    (`roots.safe_step`: from below, within ROOT_REL_TOL), and that least step's root
    bound, min/(1 − ROOT_REL_TOL); random states of a 64-gon with the rim just above the
    ground, spinning fast or tumbling.  Where one vertex's step is clearly the least,
    that vertex sets it."""
    from reference.core.contacts import contact_jet, rim_jet
    from reference.core.flight import flight_acceleration
    from reference.core.roots import safe_step
    from reference.core.search import STEP, STEP_K
    from reference.core.tolerances import ROOT_REL_TOL

    scene = make_scene(n=64)
    model, pts = core_model(scene)
    i1, _, i3 = scene.body.inertia_diag
    rng = np.random.default_rng(seed)
    compared = distinct = 0
    for _ in range(200):
        y = np.zeros(13)
        tilt = 10 ** rng.uniform(-3, -0.5)
        y[3:7] = qt.from_rotation_vector([tilt, 0.0, rng.uniform(-3, 3)])
        y[2] = np.sin(tilt) * (1 + rng.uniform(0.001, 0.2))
        y[7:10] = rng.normal(size=3) * 0.3
        y[10:13] = rng.normal(size=3) * [1.0, 1.0, rng.choice([1.0, 30.0])]
        fc = flight_constants(y, i1, i3)
        bounds = on_the_loops_state(flight_bounds, y, fc, model, pts, 10.0)
        acc = flight_acceleration(fc, y, scene.gravity)
        res = np.array([np.inf, -1.0, np.inf, -1.0, -1.0])
        jet = on_the_loops_state(rim_jet, y, acc, 1.0)
        examine_range_as_the_loop_does(y, acc, jet, pts, 64, bounds.K, bounds.B, 0, 64, 1e-14, res,
                                       1.0)  # fmt: skip
        alone = []
        for k in range(64):
            j = contact_jet(y, RIM_VERTEX_ON_PLANE, pts, k, acc)
            alone.append(safe_step(j.gap, j.rate, j.accel, bounds.K, bounds.B, np.inf))
        order = np.argsort(alone)
        least = alone[order[0]]
        assert least <= res[STEP] <= least / (1 - ROOT_REL_TOL)
        if alone[order[1]] > least / (1 - ROOT_REL_TOL) ** 2:  # a clear least: it sets it
            assert res[STEP_K] == order[0]
            distinct += 1
        compared += np.isfinite(least)
    assert compared >= 150 and distinct >= 100


def _circle_bound(delta, y, jet, g, B):
    """F(δ) = Z3(δ) − |p + δq| − δ²|r|/2 of `circle_step`'s docstring, written out."""
    p, q, r = np.array(jet[0:2]), np.array(jet[2:4]), np.array(jet[4:6])
    z3 = y[2] + y[9] * delta - 0.5 * g * delta**2 - B * delta**3 / 6
    return z3 - np.linalg.norm(p + delta * q) - 0.5 * delta**2 * np.linalg.norm(r)


@pytest.mark.parametrize("seed", range(2))
def test_circle_step_is_within_its_tolerance_below_the_circle_bound_root(seed):
    """The circle step of a 1000-gon lies below the first root of its bound F and within
    CIRCLE_STEP_REL_TOL of it (root by scipy's brentq on F written out), the rim 1e-13
    … 1e-2 above the ground, spinning fast or tumbling, falling or rising.  A root
    within roundoff of the bracket's far end is found too (chords held there would end
    the solve at 0 after 100 evaluations)."""
    from scipy.optimize import brentq

    from reference.core.contacts import rim_jet
    from reference.core.flight import flight_acceleration
    from reference.core.rim import circle_step
    from reference.core.tolerances import CIRCLE_STEP_REL_TOL

    scene = make_scene(n=1000)
    model, pts = core_model(scene)
    i1, _, i3 = scene.body.inertia_diag
    rng = np.random.default_rng(seed)
    tiny = 0
    for _ in range(300):
        y = np.zeros(13)
        tilt = 10 ** rng.uniform(-3, -0.5)
        y[3:7] = qt.from_rotation_vector([tilt, 0.0, rng.uniform(-3, 3)])
        height = 10 ** rng.uniform(-13, -2)
        y[2] = np.sin(tilt) + height
        y[7:10] = rng.normal(size=3) * 0.3
        y[9] = -abs(y[9]) - 1.0 if height < 1e-9 else y[9]
        y[10:13] = rng.normal(size=3) * [1.0, 1.0, rng.choice([1.0, 30.0])]
        if height < 1e-9 and rng.uniform() < 0.5:  # tilting about x, q ∥ p: F nearly
            y[3:7] = qt.from_rotation_vector([tilt, 0.0, 0.0])  # linear to its root
            y[10:13] = [rng.choice([-1.0, 1.0]), 0.0, 0.0]
        fc = flight_constants(y, i1, i3)
        bounds = on_the_loops_state(flight_bounds, y, fc, model, pts, 10.0)
        jet = on_the_loops_state(rim_jet, y, flight_acceleration(fc, y, scene.gravity), 1.0)
        step = circle_step(y, jet, scene.gravity, bounds.B)
        if not y[2] - np.hypot(jet[0], jet[1]) > 0:  # F(0): the circle's lowest point
            continue
        hi = 1e-14
        while _circle_bound(hi, y, jet, scene.gravity, bounds.B) > 0:
            hi *= 2
        root = brentq(_circle_bound, 0.0, hi, args=(y, jet, scene.gravity, bounds.B), xtol=1e-300,
                      rtol=1e-15)  # fmt: skip
        slack = 1e-5 * root if height < 1e-9 else 1e-12 * root  # F's roundoff at the root
        assert (1 - CIRCLE_STEP_REL_TOL) * root - slack <= step <= root + slack
        tiny += height < 1e-9
    assert tiny >= 40


def test_others_safe_time_ends_before_any_other_contact_reaches_the_ground():
    """Just after a vertex of a heptagon has hit and is moving away, the time the other
    vertices are certified safe for (`_others_safe_time`, the hit vertex bounded from
    the safe side as the search bounds it) ends before any vertex reaches the ground:
    gaps of the closed-form flight sampled over it (independent geometry) stay above
    the roundoff; it is positive, the separating vertex not standing in the way."""
    from reference.core.contacts import contact_jet, rate_noise
    from reference.core.flight import flight_acceleration
    from reference.core.search import _others_safe_time

    scene = make_scene(n=7)
    model, pts = core_model(scene)
    i1, _, i3 = scene.body.inertia_diag
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(200):
        y = np.zeros(13)
        tilt = 10 ** rng.uniform(-2, -0.5)
        y[3:7] = qt.from_rotation_vector([tilt, 0.0, rng.uniform(-3, 3)])
        y[10:13] = rng.normal(size=3) * [1.0, 1.0, rng.choice([1.0, 20.0])]
        y[2] = 1.0
        k = int(np.argmin(gaps(scene, y)))
        y[2] -= gaps(scene, y)[k]  # vertex k at the ground
        fc = flight_constants(y, i1, i3)
        acc = flight_acceleration(fc, y, scene.gravity)
        j = contact_jet(y, RIM_VERTEX_ON_PLANE, pts, k, acc)
        y[9] += 0.3 - j.rate  # vertex k moving away at 0.3
        fc = flight_constants(y, i1, i3)
        acc = flight_acceleration(fc, y, scene.gravity)
        bounds = on_the_loops_state(flight_bounds, y, fc, model, pts, 10.0)
        end = 10.0
        t = on_the_loops_state(_others_safe_time, y, acc, model, pts, k, end, 0.0, bounds.K,
                               bounds.B, False, rate_noise(y, 1.0))  # fmt: skip
        assert t > 0
        others = np.delete(np.arange(7), k)
        for s in np.linspace(0.0, t, 200)[1:]:
            assert gaps(scene, flight(scene, y, s))[others].min() > -1e-15
        checked += t < end
    assert checked >= 150


def test_a_polygon_rolling_down_its_vertices_finds_each_impact_in_the_first_search_step():
    """A 100-gon spinning fast, tilted, γ = 0.5: its vertices hit one after another, each
    with the last one still touching and moving away.  The bracket shortcut certifies
    the others until the next vertex's zero from the first search step (not a step later, once
    the last vertex has lifted off, one per impact): under 0.5 per
    impact, where every-vertex and window searches agree on the impacts."""
    import math

    scene = Scene(
        name="spin", body=Body(n=100, gyration=0.5), ground=Ground(), restitution=0.5,
        initial=InitialState(
            position=(0.0, 0.0, math.sin(0.02) + 0.01), rotation_vector=(0.02, 0.0, 0.0),
            velocity=(0.0, 0.0, -0.1), angular_velocity=(0.0, 0.3, 20.0),
        ),
        run=RunSettings(t_end=100.0, max_impacts=1000),
    )  # fmt: skip
    traj = simulate(scene)
    assert len(traj.impacts) == 1000
    assert traj.stats.search_iterations_per_impact < 0.5
    full = simulate(scene, options=ReferenceOptions(window_search=False))
    for a, b in zip(traj.impacts[:20], full.impacts[:20], strict=True):  # then chaos
        assert a.contact == b.contact and abs((a.t - b.t) + (a.t_lo - b.t_lo)) <= 1e-14


def test_bracketed_newton_stops_at_the_zero_instead_of_alternating_between_its_ends(
    monkeypatch,
):
    """Near a zero the computed gap is roundoff: on grazing-contact's flights a Newton
    step from one end of the bracket could land on the other and back, 60 evaluations
    (the cap) between two times a few ulps apart.  A step onto a bracket end bisects
    instead.  Each flight after an impact (its state the run's post-impact sample),
    brackets of the next impact's zero drawn over decades on both sides, Newton started
    at the bracket's safe end or anywhere inside: at most 16 evaluations (counted on the
    Python form of `search._newton_in_bracket`, with the compiled flight), ending inside
    the bracket where the gap is within its roundoff."""
    from reference.core import search
    from reference.core.contacts import contact_jet
    from reference.core.flight import flight_acceleration

    scene = resolve_scene("grazing-contact")
    traj = simulate(scene)
    _, pts = core_model(scene)
    i1, _, i3 = scene.body.inertia_diag
    calls, compiled_flight = [], search.free_flight

    def counted_flight(*args):
        calls.append(args[3])
        return compiled_flight(*args)

    newton = search._newton_in_bracket.py_func
    monkeypatch.setitem(newton.__globals__, "free_flight", counted_flight)
    rng = np.random.default_rng(0)
    for before, e in zip(traj.impacts[:-1], traj.impacts[1:], strict=True):
        i = np.flatnonzero(traj.t == before.t)[-1]  # the state just after `before`
        y0 = np.concatenate([traj.position[i], traj.quaternion[i], traj.velocity[i],
                             traj.angular_velocity[i]])  # fmt: skip
        fc = flight_constants(y0, i1, i3)
        s_hit = e.t - before.t
        for _ in range(100):
            lo = s_hit * (1 - 10 ** rng.uniform(-6, -1))
            hi = s_hit * (1 + 10 ** rng.uniform(-8, -2))
            calls.clear()
            y = np.empty(13)
            x0 = lo if rng.uniform() < 0.5 else rng.uniform(lo, hi)  # (its start)
            x = newton(y0, fc, scene.gravity, RIM_VERTEX_ON_PLANE, pts, e.contact, lo, hi, x0, y)
            jet = contact_jet(
                y, RIM_VERTEX_ON_PLANE, pts, e.contact, flight_acceleration(fc, y, scene.gravity)
            )
            assert len(calls) <= 16
            assert lo < x < hi and abs(jet.gap) <= jet.noise


def test_direction_angle_is_atan2_within_its_error_bound():
    """The window's lowest direction (`window.direction_angle`, a series in place of
    libm's atan2) is math.atan2 to ANGLE_ERROR over 200,000 random vectors of every
    magnitude and on the octant and reduction boundaries; measured 1.7e-10."""
    import math

    from reference.core.tolerances import ANGLE_ERROR
    from reference.core.window import direction_angle

    rng = np.random.default_rng(3)
    xs = rng.normal(size=(200_000, 2)) * 10.0 ** rng.uniform(-300, 300, size=(200_000, 1))
    t = 2.0 - math.sqrt(3.0)  # tan(π/12), where the reduction starts
    edges = [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1), (1, t),
             (t, 1), (-1, -t), (1, 1e-300), (-1e-300, 1)]  # fmt: skip
    # as floats, the argument types the search passes (an int would compile another
    # specialisation)
    points = [*xs, *((float(x), float(y)) for x, y in edges)]
    worst = max(abs(direction_angle(x, y) - math.atan2(y, x)) for x, y in points)
    assert worst <= ANGLE_ERROR
