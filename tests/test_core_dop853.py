"""The contact-phase integrator (reference.core.dop853) is scipy's DOP853: the same
tableau, and on a held motion the same steps (right-hand-side evaluations) and end
state as `solve_ivp(method="DOP853")` at the same tolerances."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.integrate._ivp import dop853_coefficients as scipy_dop

from reference import quaternion as qt
from reference.core import dop853_tableau as tab
from reference.core.contacts import contact_frame, vertex_lever
from reference.core.dop853 import INT_CROSSING, INT_DONE
from reference.core.records import RIM_VERTEX_ON_PLANE
from tests.conftest import core_model, make_scene
from tests.core_calls import (
    held_rhs_as_the_loop_does,
    heun_euler_step_as_the_loop_does,
    integrate_held_as_the_loop_does,
)


def test_tableau_is_scipys():
    n = scipy_dop.N_STAGES
    assert tab.N_STAGES == n
    np.testing.assert_array_equal(tab.A, scipy_dop.A[:n, :n])
    np.testing.assert_array_equal(tab.B, scipy_dop.B)
    np.testing.assert_array_equal(tab.C, scipy_dop.C[:n])
    np.testing.assert_array_equal(tab.E3, scipy_dop.E3)
    np.testing.assert_array_equal(tab.E5, scipy_dop.E5)
    np.testing.assert_array_equal(tab.A_EXTRA, scipy_dop.A[n + 1 :])
    np.testing.assert_array_equal(tab.C_EXTRA, scipy_dop.C[n + 1 :])
    np.testing.assert_array_equal(tab.D, scipy_dop.D)


def _held_state(two: bool):
    """Vertex 0 (and 1 when `two`) of a pentagon on the ground at zero normal velocity,
    the body rocking."""
    y = np.zeros(13)
    if two:
        # rotate about the edge between vertices 0 and 1 so both are at the same height
        edge = np.array([np.cos(0.4 * np.pi) - 1.0, np.sin(0.4 * np.pi), 0.0])
        y[3:7] = qt.from_rotation_vector(0.2 * edge / np.linalg.norm(edge))
        y[10:13] = [0.0, 0.0, 0.0]
    else:
        y[3:7] = qt.from_rotation_vector([0.02, 0.25, 0.1])
        y[10:13] = [0.1, 1.2, 0.4]
    rx, ry, rz = vertex_lever(y, 1.0, 0.0)
    y[2] = -rz
    y[9] = -(y[10] * ry - y[11] * rx)
    return y


def _held_motion(model, pts, idx, m):
    """f(t, y) of the held motion of contacts idx[:m], for solve_ivp."""

    def rhs(_t, y):
        dy = np.empty(13)
        held_rhs_as_the_loop_does(np.ascontiguousarray(y), model, pts, idx, m, dy)
        return dy

    return rhs


def _rocking_pentagon():
    """(model, pts, idx, m, y0, f) of a pentagon rocking on its held vertex 0."""
    model, pts = core_model(make_scene(n=5, rho=0.45))
    idx, m = np.array([0, 0, 0]), 1
    return model, pts, idx, m, _held_state(False), _held_motion(model, pts, idx, m)


@pytest.mark.parametrize("two", [False, True])
def test_integration_is_scipys_dop853_step_for_step(two):
    scene = make_scene(n=5, rho=0.45)
    model, pts = core_model(scene)
    idx = np.array([0, 1, 0]) if two else np.array([0, 0, 0])
    m = 2 if two else 1
    y0 = _held_state(two)
    rtol = 1e-12
    atol = np.full(13, 1e-14)
    rhs = _held_motion(model, pts, idx, m)

    ref = solve_ivp(rhs, (0.0, 0.3), y0, method="DOP853", rtol=rtol, atol=atol)
    y = y0.copy()
    r = integrate_held_as_the_loop_does(y, 0.3, model, pts, idx, m, rtol, atol)
    assert r.status == INT_DONE
    assert r.nfev == ref.nfev
    np.testing.assert_allclose(y, ref.y[:, -1], rtol=0, atol=1e-13)


def test_crossing_is_located_where_scipys_event_finds_it():
    """A free vertex of a pentagon rocking on one held vertex reaches the ground at the
    time scipy's solve_ivp event location gives (DOP853 dense output, brentq)."""
    model, pts, idx, m, y0, rhs = _rocking_pentagon()
    rtol, atol = 1e-12, np.full(13, 1e-14)

    def gap_event(k):
        def gap(_t, y):
            return contact_frame(np.ascontiguousarray(y), RIM_VERTEX_ON_PLANE, pts, k).gap

        gap.terminal, gap.direction = True, -1
        return gap

    events = [gap_event(k) for k in range(1, 5)]
    ref = solve_ivp(rhs, (0.0, 2.0), y0, method="DOP853", rtol=rtol, atol=atol, events=events)
    t_ref = min(te[0] for te in ref.t_events if len(te))
    first = [k + 1 for k, te in enumerate(ref.t_events) if len(te) and te[0] == t_ref]
    y = y0.copy()
    watch = np.arange(1, 5, dtype=np.int64)
    r = integrate_held_as_the_loop_does(y, 2.0, model, pts, idx, m, rtol, atol, watch)
    assert r.status == INT_CROSSING
    assert abs(r.s - t_ref) < 1e-10
    assert abs(contact_frame(y, RIM_VERTEX_ON_PLANE, pts, first[0]).gap) < 1e-12


def test_heun_euler_step_is_the_motion_to_roundoff_on_a_short_step_and_rejects_a_long_one():
    """heun_euler_step (order 2, Euler's difference as its estimate): over 1e-7 s of a
    pentagon rocking on one held vertex it agrees with scipy's DOP853 at rtol 1e-13 to
    roundoff and accepts at rtol 1e-12; its estimate grows as h² (×100 for 10× the
    step) and rejects a step of 1e-3 s."""
    model, pts, idx, m, y0, rhs = _rocking_pentagon()
    rtol, atol = 1e-12, np.full(13, 1e-14)

    def step(h):
        f0, y1 = rhs(0.0, y0), np.empty(13)
        err = heun_euler_step_as_the_loop_does(y0, f0, h, rtol, atol, model, pts, idx, m, y1)
        return err, y1

    err, y1 = step(1e-7)
    ref = solve_ivp(rhs, (0.0, 1e-7), y0, method="DOP853", rtol=1e-13, atol=1e-16)
    assert err <= 1.0
    np.testing.assert_allclose(y1, ref.y[:, -1], rtol=0, atol=4e-16)
    assert step(1e-6)[0] / err == pytest.approx(100.0, rel=1e-3)
    assert step(1e-3)[0] > 1.0
