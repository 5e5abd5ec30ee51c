"""Core functions called from Python with the argument types the event loop passes them.

numba compiles a function, and everything it calls, once per combination of argument
types.  The loop passes states, contact lists and tolerances as fields of its records
(numba's NestedArray); a test that passes NumPy arrays instead gets another compilation
of the function and its callees (seconds for the integrator and the flight search), of a
specialisation the loop never runs.  These wrappers copy the test's arrays into the
fields of a run record (reference.core.records.RUN) and call the function as the loop
does (reference/core/phases.py and search.py), so that the machine code tested is
the loop's, loaded from numba's cache where the core's build left it."""

from __future__ import annotations

import functools

import numpy as np
from numba import njit

from reference.core.dop853 import heun_euler_step, integrate_held
from reference.core.held import held_rhs, project_held, solve_lcp, zero_normal_velocities
from reference.core.jit import FALSE, ZERO, copy_into
from reference.core.output import Output
from reference.core.phases import NO_GRID
from reference.core.records import RUN
from reference.core.search import examine_range, find_flight_event

MAX_ITERATIONS = 100_000  # the flight search's cap, as the loop passes it (a constant)


def new_run():
    """A zeroed run record for the wrappers below: keep the array, pass its [0]."""
    return np.zeros(1, dtype=RUN)


def held_list(idx) -> np.ndarray:
    """The held contacts idx as the loop's list of three (state.active), zero-padded."""
    active = np.zeros(3, dtype=np.int64)
    active[: len(idx)] = idx
    return active


@functools.cache
def _on_state(fn):
    """fn(state.y, *args) compiled once per fn, y copied in and out (on_the_loops_state)."""

    @njit
    def call(y, run, *args):
        state = run.state
        copy_into(state.y, y)
        result = fn(state.y, *args)
        copy_into(y, state.y)
        return result

    return call


@functools.cache
def _on_held_contacts(fn):
    """fn(state.y, model, pts, state.active, m, scratch) compiled once per fn: the held
    contacts' functions of reference.core.held, called as the loop calls them."""

    @njit
    def call(y, model, pts, idx, m, run):
        state = run.state
        copy_into(state.y, y)
        copy_into(state.active, idx)
        result = fn(state.y, model, pts, state.active, m, run.scratch)
        copy_into(y, state.y)
        return result

    return call


def on_the_loops_state(fn, y, *args):
    """fn(y, *args), y (updated in place) passed as the loop passes a state: a 13-vector
    field of its run record.  For the core functions whose only array the loop passes
    from its records is the state, their first argument."""
    run = new_run()
    return _on_state(fn)(y, run[0], *args)


@njit
def _integrate(y, s_end, model, pts, idx, m, rtol, atol, run, watch, n_watch, rows):
    ws, state = run.scratch, run.state
    copy_into(ws.y_chunk, y)
    copy_into(ws.atol, atol)
    copy_into(state.active, idx)
    out = Output(rows[0], rows[1], rows[2], rows[3], rows[4], rows[5], run.counts)
    r = integrate_held(
        ws.y_chunk, s_end, model, pts, state.active, m, rtol, ws.atol, ws, ws, NO_GRID, out,
        (0.0, 0.0), ZERO, FALSE, watch, n_watch, 0.0, FALSE,
    )  # fmt: skip
    copy_into(y, ws.y_chunk)
    return r


def integrate_held_as_the_loop_does(y, s_end, model, pts, idx, m, rtol, atol, watch=None):
    """dop853.integrate_held from y (updated in place) over [0, s_end], with no samples,
    lift-off not watched, and the gaps of `watch` (contacts) watched when given."""
    watch = np.zeros(0, dtype=np.int64) if watch is None else watch
    run = new_run()
    # the output's rows (none written: no samples), allocated here: np.zeros inside the
    # wrapper would compile numba's allocation for it
    rows = (np.zeros((1, 2)), np.zeros((1, 13)), np.zeros((1, 2)), np.zeros((1, 6)),
            np.zeros((1, 6)), np.zeros(1))  # fmt: skip
    return _integrate(
        y, s_end, model, pts, held_list(idx), m, rtol, atol, run[0], watch, len(watch), rows
    )


@njit
def _heun_euler(y, f0, h, rtol, atol, model, pts, idx, m, run, y_new):
    ws, state = run.scratch, run.state
    copy_into(state.y, y)
    copy_into(ws.f, f0)
    copy_into(ws.atol, atol)
    copy_into(state.active, idx)
    err = heun_euler_step(
        state.y, ws.f, h, rtol, ws.atol, model, pts, state.active, m, ws, ws, ws.y_chunk
    )
    copy_into(y_new, ws.y_chunk)
    return err


def heun_euler_step_as_the_loop_does(y, f0, h, rtol, atol, model, pts, idx, m, y_new):
    """dop853.heun_euler_step from (y, f0 = f(y)) into y_new; returns its error estimate."""
    run = new_run()
    return _heun_euler(y, f0, h, rtol, atol, model, pts, held_list(idx), m, run[0], y_new)


@njit
def _held_rhs(y, model, pts, idx, m, run, dy):
    ws, state = run.scratch, run.state
    copy_into(state.y, y)
    copy_into(state.active, idx)
    held_rhs(state.y, model, pts, state.active, m, ws, ws.f)
    copy_into(dy, ws.f)


def held_rhs_as_the_loop_does(y, model, pts, idx, m, dy):
    """held.held_rhs: f(y) of the motion holding contacts idx[:m], into dy."""
    run = new_run()
    _held_rhs(y, model, pts, held_list(idx), m, run[0], dy)


def project_held_as_the_loop_does(y, model, pts, idx, m):
    """held.project_held: y (updated in place) projected onto the constraints of contacts
    idx[:m]; False where its linear solve failed."""
    return _on_held_contacts(project_held)(y, model, pts, held_list(idx), m, new_run()[0])


@njit
def _find_flight_event(y0, fc, bounds, model, pts, window, s_start, horizon, y, together, run):
    ws = run.scratch
    copy_into(ws.y_start, y0)
    copy_into(ws.y_event, y)
    ev = find_flight_event(
        ws.y_start, fc, bounds, model, pts, window, s_start, horizon, MAX_ITERATIONS,
        ws.y_event, together, ws.res,
    )  # fmt: skip
    copy_into(y, ws.y_event)
    return ev


def find_flight_event_as_the_loop_does(y0, fc, bounds, model, pts, window, s_start, horizon, y,
                                       together):  # fmt: skip
    """search.find_flight_event from y0 (y: the state at s_start, left at the event)."""
    run = new_run()
    return _find_flight_event(
        y0, fc, bounds, model, pts, window, s_start, horizon, y, together, run[0]
    )


@njit
def _examine_range(y, acc, jet, pts, n, K, B, first, count, vnoise, res, radius, run):
    ws, state = run.scratch, run.state
    copy_into(state.y, y)
    copy_into(ws.res, res)
    examine_range(state.y, acc, jet, pts, n, K, B, first, count, vnoise, ws.res, radius)
    copy_into(res, ws.res)


def examine_range_as_the_loop_does(y, acc, jet, pts, n, K, B, first, count, vnoise, res,
                                   radius):  # fmt: skip
    """search.examine_range of vertices first … first + count − 1 (mod n) into res (the
    search's five numbers, updated in place)."""
    run = new_run()
    _examine_range(y, acc, jet, pts, n, K, B, first, count, vnoise, res, radius, run[0])


def zero_normal_velocities_as_the_loop_does(y, model, pts, idx, m):
    """held.zero_normal_velocities of contacts idx[:m] on y (updated in place); False
    where its linear solve failed."""
    call = _on_held_contacts(zero_normal_velocities)
    return call(y, model, pts, held_list(idx), m, new_run()[0])


@njit
def _solve_lcp(y, model, pts, cand, m, run, active):
    ws, state = run.scratch, run.state
    copy_into(state.y, y)
    copy_into(ws.cand, cand)
    n = solve_lcp(state.y, model, pts, ws.cand, m, ws, ws.active)
    copy_into(active, ws.active)
    return n


def solve_lcp_as_the_loop_does(y, model, pts, cand, m, active):
    """held.solve_lcp of candidates cand[:m]: the contacts it holds into active[:n] (an
    array of four), n returned (−1: no admissible set)."""
    run = new_run()
    padded = np.zeros(4, dtype=np.int64)
    padded[:m] = cand[:m]
    return _solve_lcp(y, model, pts, padded, m, run[0], active)
