"""The free contacts a contact step examines, and the chunk they certify.

Small polygons and the three-point ground: every free contact, with the horizon's
curvature K = `horizon_bound` of their largest |g″|.  Large polygons
(`window.use_window`): K = `horizon_bound` of |v̇_z| + |r|, which bounds |g″| of every
rim point (`contacts.rim_jet`), and first the vertices touching or about to (the window
of δ = 0 lifted by the touching tolerance, WINDOW_MAX more on each side); once their
horizon h is known, the vertices of window(h) not yet examined are added (WINDOW_GROW
at most at a time) or h is shortened until window(h) is covered: every vertex left out
is then safe over the chunk by P2 with the same K.  The cost of a step does not grow
with n."""

import math
from collections import namedtuple

import numpy as np

from .contacts import contact_jet, contact_kind, rim_jet, vertex_gap_noise
from .horizon import horizon_bound, local_time_cap, safe_horizon
from .jit import ZERO, hot
from .layout import Z
from .roots import quadratic_taylor_root
from .tolerances import WINDOW_GROW, WINDOW_MAX, WINDOW_ROUNDS
from .window import use_window, vertex_window, window_offsets

# n: how many are listed in cs.cand; K: the horizon's curvature; the examined vertices
# are k0 + lo … k0 + hi (mod n) when `windowed`
Examined = namedtuple("Examined", ["n", "K", "k0", "lo", "hi", "windowed"])


@hot
def is_held(state, k):
    """Whether contact k is held."""
    for i in range(state.n_active):
        if state.active[i] == k:
            return True
    return False


@hot
def _list_free(state, cs, first, count, n, m):
    """Append to cs.cand[m:] the free contacts among first, first + 1, … (count of them,
    mod n); returns the new length."""
    for i in range(count):
        k = (first + i) % n
        if not is_held(state, k):
            cs.cand[m] = k
            m += 1
    return m


@hot
def _jets(y, model, pts, acc, cs, i0, i1):
    """Jets of cs.cand[i0:i1] with the held acceleration acc."""
    for i in range(i0, i1):
        j = contact_jet(y, contact_kind(pts, cs.cand[i]), pts, cs.cand[i], acc)
        cs.gap[i], cs.rate[i], cs.accel[i], cs.noise[i] = j.gap, j.rate, j.accel, j.noise


@hot
def touching_candidates(state, model, pts, opts, acc, cs, touch):
    """List and jet the contacts to examine first: every free one, or (windowed) the
    vertices whose gap may be within `touch` of the ground and WINDOW_MAX more on each
    side.  Returns Examined."""
    y = state.y
    n = pts.shape[0]
    if not use_window(model, opts.window_search):
        m = _list_free(state, cs, ZERO, n, n, ZERO)
        _jets(y, model, pts, acc, cs, ZERO, m)
        acc_scale = 0.0
        for i in range(m):
            acc_scale = max(acc_scale, abs(cs.accel[i]))
        return Examined(m, horizon_bound(acc_scale, model.gravity), 0, 0, n - 1, False)
    _, _, _, _, rx, ry = rim_jet(y, acc, model.radius)
    K = horizon_bound(abs(acc[2]) + math.sqrt(rx * rx + ry * ry), model.gravity)
    lift = max(touch, vertex_gap_noise(y[Z], model.radius))
    k0, half = vertex_window(y, model.radius, n, K, 0.0, np.int64(WINDOW_MAX), lift)
    m = _list_free(state, cs, k0 - half, min(2 * half + 1, n), n, ZERO)
    _jets(y, model, pts, acc, cs, ZERO, m)
    return Examined(m, K, k0, -half, half, 2 * half + 1 < n)


@hot
def _grow(state, model, pts, acc, cs, ex, lo, hi, m, nlo, nhi, h):
    """Examine the vertices of offsets nlo … lo − 1 and hi + 1 … nhi from ex.k0; returns
    (h shortened by their safe steps, the new list length)."""
    n = pts.shape[0]
    m0 = m
    if nhi > hi:
        m = _list_free(state, cs, ex.k0 + hi + 1, nhi - hi, n, m)
    if nlo < lo:
        m = _list_free(state, cs, ex.k0 + nlo, lo - nlo, n, m)
    _jets(state.y, model, pts, acc, cs, m0, m)
    return safe_horizon(cs, m0, m, ex.K, h), m


@hot
def certified_horizon(state, model, pts, acc, cs, ex, h):
    """The chunk no free contact should reach the ground within, at most h: the horizon
    of the examined contacts, and (windowed) grown or shortened until window(h) has
    been examined.  Returns (h, how many contacts were examined).

    The chunk is capped by the local time scale (`local_time_cap`) or, when longer, by
    the step the integrator proposed at the end of the last chunk (state.h_next): its
    error control measures the time the state takes to change (at the default
    contact_rtol = 1e-12 a step is a few per cent of it), where L and V can only guess,
    e.g. a disk rocking slowly over the bumps of the three-point ground."""
    cap = max(local_time_cap(state.y, model, ex.K), state.h_next)
    h = safe_horizon(cs, ZERO, ex.n, ex.K, min(h, cap))
    if not ex.windowed:
        return h, ex.n
    n = pts.shape[0]
    lo, hi, m = ex.lo, ex.hi, ex.n
    for _ in range(WINDOW_ROUNDS):
        nlo, nhi = window_offsets(state.y, model.radius, n, ex.K, h, ZERO, ex.k0)
        if nlo >= lo and nhi <= hi:
            return h, m
        nlo, nhi = min(nlo, lo), max(nhi, hi)
        if nhi - nlo + 1 >= n:
            break
        if (nhi - hi) + (lo - nlo) > WINDOW_GROW:
            h *= 0.25
            continue
        h, m = _grow(state, model, pts, acc, cs, ex, lo, hi, m, nlo, nhi, h)
        lo, hi = nlo, nhi
    # every vertex (the window reaches round, or no window settled): the rest, once
    return _grow(state, model, pts, acc, cs, ex, lo, hi, m, lo, lo + n - 1, h)


@hot
def set_aside_approaching(cs, ex, vnoise, gap_res):
    """Move the examined contacts approaching the ground (rate < −vnoise) within the gap
    resolution but above its roundoff (noise < gap ≤ gap_res) from cs.cand to cs.near:
    the chunk is integrated up to where their gap is zero (an impact time to the
    integrator's precision, not gap_res / |rate|).  Returns (Examined without them, how
    many, a chunk length that reaches their zero: twice the first root of their Taylor
    quadratic)."""
    m = n_near = 0
    t_near = math.inf
    for i in range(ex.n):
        g, rate = cs.gap[i], cs.rate[i]
        if cs.noise[i] < g <= gap_res and rate < -vnoise:
            cs.near[n_near] = cs.cand[i]
            n_near += 1
            t_near = min(t_near, 2.0 * quadratic_taylor_root(g, rate, cs.accel[i]))
            continue
        cs.cand[m], cs.gap[m], cs.rate[m], cs.accel[m], cs.noise[m] = (
            cs.cand[i],
            g,
            rate,
            cs.accel[i],
            cs.noise[i],
        )
        m += 1
    return Examined(m, ex.K, ex.k0, ex.lo, ex.hi, ex.windowed), n_near, t_near
