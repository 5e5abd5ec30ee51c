"""Steps that bound every vertex at once from the circle through them
(reference.core.rim): the symmetry axis in closed form against the oracle's flight, and
the rim descent never passing a vertex while ending near the ground."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference import quaternion as qt
from reference.core.flight import flight_bounds, flight_constants
from tests.conftest import core_model, make_scene
from tests.core_calls import on_the_loops_state
from tests.oracle import flight as oracle_flight
from tests.oracle import quaternion as oracle_qt
from tests.oracle.body import BodyModel


def _spinning_flights(count: int, seed: int):
    """States of a polygon in flight above flat ground: tilt 1e-3 … 0.4 rad,
    spinning fast about its axis (up to 40 rad/s) or tumbling, the circle through the
    vertices 1e-4 … 0.1 a above the ground at the start, falling or rising."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        tilt = 10 ** rng.uniform(-3, math.log10(0.4))
        y = np.zeros(13)
        y[3:7] = qt.from_rotation_vector([tilt, 0.0, rng.uniform(-3, 3)])
        y[2] = math.sin(tilt) + 10 ** rng.uniform(-4, -1)
        y[7:10] = [*rng.normal(size=2) * 0.1, rng.uniform(-0.5, 0.5)]
        spin = rng.choice([rng.uniform(-40, 40), 0.0])
        y[10:13] = rng.normal(size=3) * 0.5 + spin * qt.body_axis(y[3:7])
        yield y


def _oracle_heights(scene, y0, times):
    """Lowest vertex and the circle's lowest point z − a sin α at each time, on the
    oracle's closed-form flight (tests/oracle/flight.py, tests/oracle/body.py)."""
    body = BodyModel.from_scene(scene)
    fc = oracle_flight.flight_constants(body, y0)
    lowest, circle = [], []
    for s in times:
        y = oracle_flight.free_flight(fc, s)
        lowest.append(body.rim_gaps(y).min())
        e3 = oracle_qt.body_axis(y[3:7])
        circle.append(y[2] - scene.body.radius * math.hypot(e3[0], e3[1]))
    return np.array(lowest), np.array(circle)


@pytest.mark.parametrize("seed", range(2))
def test_rim_at_gives_the_oracle_flights_axis_and_its_rate(seed):
    """The circle's centre height and rate and a E, a Ė of `rim_at` (e3's horizontal
    part, precessing in closed form about L̂) are the oracle flight's at 1 … 0.3 s, to
    1e-12 (Ė against a central difference of the oracle's e3, to 1e-6 relative); the
    second difference of E never exceeds the bound Ω²|c| that `axis_cone` gives."""
    from reference.core.rim import axis_cone, rim_at

    scene = make_scene(n=100)
    model, _ = core_model(scene)
    i1, _, i3 = scene.body.inertia_diag
    body = BodyModel.from_scene(scene)
    for y in _spinning_flights(30, seed):
        cone = axis_cone(y, flight_constants(y, i1, i3))
        ofc = oracle_flight.flight_constants(body, y)
        for s in (1e-3, 0.02, 0.3):
            z, vz, ex, ey, dx, dy = rim_at(y, cone, model, s)
            yo = oracle_flight.free_flight(ofc, s)
            e3 = qt.body_axis(yo[3:7])
            assert abs(z - yo[2]) <= 1e-12 and abs(vz - yo[9]) <= 1e-12
            assert abs(ex - e3[0]) <= 1e-12 and abs(ey - e3[1]) <= 1e-12
            h = 1e-6
            ep = qt.body_axis(oracle_flight.free_flight(ofc, s + h)[3:7])
            em = qt.body_axis(oracle_flight.free_flight(ofc, s - h)[3:7])
            rate = (ep[:2] - em[:2]) / (2 * h)
            assert np.allclose([dx, dy], rate, rtol=1e-6, atol=1e-9)
            second = (ep[:2] - 2 * e3[:2] + em[:2]) / h**2
            assert np.linalg.norm(second) <= cone[7] * (1 + 1e-3) + 1e-3


# seeds 1 and 2 repeat seed 0's check on other flights (≈ 1.5 s each): `-m slow`
RIM_SEEDS = [0, *(pytest.param(s, marks=pytest.mark.slow) for s in (1, 2))]


@pytest.mark.parametrize("seed", RIM_SEEDS)
def test_rim_descent_never_passes_a_vertex_and_ends_near_the_ground(seed):
    """From states with the circle through a 100-gon's vertices clear of the ground
    (`rim_clear`), the descent's step keeps every vertex and the circle's lowest point
    above the ground at 300 times over it on the oracle's flight, and in at least
    95 % of the cases ends with that point within the four sags `rim_clear` allows (or
    at the horizon): where the vertices are examined."""
    from reference.core.rim import rim_clear, rim_descent

    scene = make_scene(n=100)
    model, pts = core_model(scene)
    i1, _, i3 = scene.body.inertia_diag
    a = scene.body.radius
    body = BodyModel.from_scene(scene)
    checked = ended_near = 0
    for y in _spinning_flights(60, seed):
        fc = flight_constants(y, i1, i3)
        e3 = qt.body_axis(y[3:7])
        if not rim_clear(y[2], a * math.hypot(e3[0], e3[1]), model):
            continue
        depth = on_the_loops_state(flight_bounds, y, fc, model, pts, math.inf).depth
        horizon = 5.0
        step = on_the_loops_state(rim_descent, y, fc, model, depth, horizon, 0.0)
        # 300 times: a step 0.5 % too long fails on 50-55 of a seed's 60 flights, and 2 %
        # too long on 57-59, at 100 times as at 1,000 (seeds 0-2; the end of the step is
        # where the body is lowest)
        lowest, circle = _oracle_heights(scene, y, np.linspace(0.0, min(step, horizon), 300))
        assert step > 0.0 and np.all(lowest > -1e-14) and np.all(circle > -1e-14)
        end = oracle_flight.free_flight(oracle_flight.flight_constants(body, y), step)
        e3 = qt.body_axis(end[3:7])
        ended_near += step >= horizon or not rim_clear(end[2], a * math.hypot(*e3[:2]), model)
        checked += 1
    assert checked >= 30
    assert ended_near >= 0.95 * checked
