"""Integration of the held motion in a contact phase: DOP853 (Hairer's 8(5,3) pair) with
scipy's coefficients, initial step, error norm and step control (scipy.integrate's
`DOP853`), so that a chunk is the step sequence `solve_ivp(method="DOP853")` takes.

Grid samples inside a chunk are taken by one DOP853 step from the start of the accepted
step that contains them (a shorter step: no less accurate).  With `watch_forces` the
held forces λ (known at every step end: the FSAL derivative computes them) are watched:
when one turns negative inside a step, its zero is located there, on one-step
evaluations, to LOCATE_XTOL of the chunk (`locate_lift_off`): the lift-off."""

import math
from collections import namedtuple

import numpy as np
from numba import njit

from . import dop853_tableau as tab
from .clock import two_sum_add
from .contacts import contact_frame
from .held import held_rhs
from .output import push_sample
from .tolerances import EPS, LOCATE_ITERATIONS, LOCATE_XTOL

N_STAGES = tab.N_STAGES
DOP_A = np.ascontiguousarray(tab.A)
DOP_B = np.ascontiguousarray(tab.B)
DOP_C = np.ascontiguousarray(tab.C)
DOP_E3 = np.ascontiguousarray(tab.E3)
DOP_E5 = np.ascontiguousarray(tab.E5)
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0  # scipy's step control
ERROR_EXPONENT = -1.0 / 8.0  # error estimator of order 7

INT_DONE, INT_LIFT_OFF, INT_FAILED, INT_CROSSING = 0, 1, 2, 3
# status; s: where the integration stopped (the chunk's end, the lift-off or the
# crossing); nfev; leaving: index (into the held list) of the contact whose force reached
# zero
Integration = namedtuple("Integration", ["status", "s", "nfev", "leaving"])

# `st` in this module is a records.SCRATCH record: stages K (13 rows: 12 stages and
# f(y_new)) of the steps taken and Ks of one-step evaluations, state and scale vectors,
# the held forces at the current state (lam_cur) and at the end of the step just
# accepted (lam_new).  The held functions use the same record as their `work`.


@njit(cache=True)
def dop853_step(y, f0, h, model, pts, idx, m, work, K, y_new, tmp):
    """One DOP853 step of size h from (y, f0 = f(y)) into y_new; K receives the stages
    and f(y_new) as its last row (work.lam: the held forces at y_new).  Returns the
    number of right-hand-side evaluations."""
    K[0, :] = f0
    for s in range(1, N_STAGES):
        for c in range(13):
            acc = 0.0
            for j in range(s):
                acc += DOP_A[s, j] * K[j, c]
            tmp[c] = y[c] + h * acc
        held_rhs(tmp, model, pts, idx, m, work, K[s])
    for c in range(13):
        acc = 0.0
        for j in range(N_STAGES):
            acc += DOP_B[j] * K[j, c]
        y_new[c] = y[c] + h * acc
    held_rhs(y_new, model, pts, idx, m, work, K[N_STAGES])
    return N_STAGES


@njit(cache=True)
def _rms(v, scale):
    s = 0.0
    for i in range(v.shape[0]):
        s += (v[i] / scale[i]) ** 2
    return math.sqrt(s / v.shape[0])


@njit(cache=True)
def error_norm(K, h, scale):
    """scipy's DOP853 error norm (rk.DOP853._estimate_error_norm)."""
    e5 = 0.0
    e3 = 0.0
    for c in range(13):
        a5 = 0.0
        a3 = 0.0
        for j in range(N_STAGES + 1):
            a5 += K[j, c] * DOP_E5[j]
            a3 += K[j, c] * DOP_E3[j]
        e5 += (a5 / scale[c]) ** 2
        e3 += (a3 / scale[c]) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * 13)


@njit(cache=True)
def initial_step(y, f, s_end, rtol, atol, model, pts, idx, m, work, st):
    """scipy.integrate._ivp.common.select_initial_step for order 7.  Returns (h, nfev)."""
    for c in range(13):
        st.scale[c] = atol[c] + abs(y[c]) * rtol
    d0 = _rms(y, st.scale)
    d1 = _rms(f, st.scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, s_end)
    for c in range(13):
        st.ys[c] = y[c] + h0 * f[c]
    held_rhs(st.ys, model, pts, idx, m, work, st.tmp)
    d2 = 0.0
    for c in range(13):
        d2 += ((st.tmp[c] - f[c]) / st.scale[c]) ** 2
    d2 = math.sqrt(d2 / 13) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100 * h0, h1, s_end), 1


@njit(cache=True)
def _force_at(y, f, sigma, model, pts, idx, m, work, st, i):
    """Held force i after one DOP853 step of size σ from (y, f) (state into st.ys)."""
    dop853_step(y, f, sigma, model, pts, idx, m, work, st.Ks, st.ys, st.tmp)
    return work.lam[i]


@njit(cache=True)
def locate_lift_off(y, f, h, model, pts, idx, m, work, st, i, lam0, xtol):
    """σ in (0, h] where held force i (lam0 ≥ 0 at σ = 0, negative at h) reaches zero:
    Illinois regula falsi with bisection steps, to xtol + 4ε σ.  Returns (σ, nfev);
    st.ys holds the state there."""
    lo, flo = 0.0, lam0
    hi = h
    fhi = _force_at(y, f, h, model, pts, idx, m, work, st, i)
    nfev = N_STAGES
    side = 0
    for it in range(LOCATE_ITERATIONS):
        if hi - lo <= xtol + 4.0 * EPS * hi:
            break
        if it % 3 == 2 or flo == fhi:
            x = 0.5 * (lo + hi)
        else:
            x = hi - fhi * (hi - lo) / (fhi - flo)
            if not lo < x < hi:
                x = 0.5 * (lo + hi)
        fx = _force_at(y, f, x, model, pts, idx, m, work, st, i)
        nfev += N_STAGES
        if fx > 0.0:
            lo, flo = x, fx
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi = x, fx
            if side == 1:
                flo *= 0.5
            side = 1
    _force_at(y, f, hi, model, pts, idx, m, work, st, i)
    return hi, nfev + N_STAGES


@njit(cache=True)
def _lowest_gap(y, model, pts, watch, n_watch):
    """The smallest gap among contacts watch[:n_watch] at y."""
    g = math.inf
    for i in range(n_watch):
        g = min(g, contact_frame(y, model.flat_ground, pts, watch[i]).gap)
    return g


@njit(cache=True)
def _gap_at(y, f, sigma, model, pts, idx, m, work, st, watch, n_watch):
    """The lowest watched gap after one DOP853 step of size σ from (y, f)."""
    dop853_step(y, f, sigma, model, pts, idx, m, work, st.Ks, st.ys, st.tmp)
    return _lowest_gap(st.ys, model, pts, watch, n_watch)


@njit(cache=True)
def locate_crossing(y, f, h, g0, model, pts, idx, m, work, st, watch, n_watch, xtol):
    """σ in (0, h] where the lowest watched gap (g0 > 0 at σ = 0, ≤ 0 at h) reaches zero:
    Illinois regula falsi with bisection steps on one-step evaluations, as
    `locate_lift_off`.  Returns (σ, nfev); st.ys holds the state there."""
    lo, flo, hi = 0.0, g0, h
    fhi = _gap_at(y, f, h, model, pts, idx, m, work, st, watch, n_watch)
    nfev = N_STAGES
    side = 0
    for it in range(LOCATE_ITERATIONS):
        if hi - lo <= xtol + 4.0 * EPS * hi:
            break
        x = 0.5 * (lo + hi) if it % 3 == 2 or flo == fhi else hi - fhi * (hi - lo) / (fhi - flo)
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
        fx = _gap_at(y, f, x, model, pts, idx, m, work, st, watch, n_watch)
        nfev += N_STAGES
        if fx > 0.0:
            lo, flo = x, fx
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi = x, fx
            if side == 1:
                flo *= 0.5
            side = 1
    _gap_at(y, f, hi, model, pts, idx, m, work, st, watch, n_watch)
    return hi, nfev + N_STAGES


@njit(cache=True)
def _grid_samples(
    y, f, t, t_stop, grid, gi, n_grid, model, pts, idx, m, work, st, out, clock, max_samples
):
    """Samples at the grid times in (t, t_stop] (local times), each by one DOP853 step
    from (y, f) at t, stamped clock = (t_hi, t_lo) + the grid time; returns (next grid
    index, nfev)."""
    nfev = 0
    while gi < n_grid and grid[gi] <= t_stop:
        hs = grid[gi] - t
        if hs > 0.0:
            nfev += dop853_step(y, f, hs, model, pts, idx, m, work, st.Ks, st.ys, st.tmp)
        else:
            st.ys[:] = y
        hi, lo = two_sum_add(clock[0], clock[1], grid[gi])
        push_sample(out, hi, lo, st.ys, model, max_samples)
        gi += 1
    return gi, nfev


@njit(cache=True)
def _most_negative(lam, m):
    """Index of the most negative held force, −1 if none is negative."""
    i_min, v_min = -1, 0.0
    for i in range(m):
        if lam[i] < v_min:
            i_min, v_min = i, lam[i]
    return i_min


@njit(cache=True)
def integrate_held(
    y,
    s_end,
    model,
    pts,
    idx,
    m,
    rtol,
    atol,
    work,
    st,
    grid,
    n_grid,
    out,
    clock,
    max_samples,
    watch_forces,
    watch,
    n_watch,
):
    """Integrate the held motion from y (in place) over [0, s_end] with scipy's adaptive
    DOP853; grid samples at the local times grid[:n_grid] (ascending, inside (0, s_end)),
    stamped with clock = (t_hi, t_lo) + the local time.  With watch_forces, stop where a
    held force reaches zero (INT_LIFT_OFF, y = the state there); with n_watch > 0, where
    the lowest gap of contacts watch[:n_watch] reaches zero (INT_CROSSING)."""
    f = st.f
    held_rhs(y, model, pts, idx, m, work, f)
    nfev = 1
    for i in range(m):
        st.lam_cur[i] = work.lam[i]
    if watch_forces:
        i = _most_negative(st.lam_cur, m)
        if i >= 0:
            return Integration(INT_LIFT_OFF, 0.0, nfev, i)
    h_abs, n0 = initial_step(y, f, s_end, rtol, atol, model, pts, idx, m, work, st)
    nfev += n0
    t = 0.0
    gi = 0
    K, y_new, scale = st.K, st.y_new, st.scale
    while t < s_end:
        min_step = 10 * (math.nextafter(t, math.inf) - t)
        rejected = False
        while True:
            if h_abs < min_step:
                return Integration(INT_FAILED, t, nfev, -1)
            t_new = min(t + h_abs, s_end)
            h = t_new - t
            nfev += dop853_step(y, f, h, model, pts, idx, m, work, K, y_new, st.tmp)
            for c in range(13):
                scale[c] = atol[c] + max(abs(y[c]), abs(y_new[c])) * rtol
            err = error_norm(K, h, scale)
            if not math.isfinite(err):
                return Integration(INT_FAILED, t, nfev, -1)
            if err < 1.0:
                factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err**ERROR_EXPONENT)
                if rejected:
                    factor = min(1.0, factor)
                h_abs = h * factor
                break
            h_abs = h * max(MIN_FACTOR, SAFETY * err**ERROR_EXPONENT)
            rejected = True
        for i in range(m):
            st.lam_new[i] = work.lam[i]
        if watch_forces:
            i = _most_negative(st.lam_new, m)
            if i >= 0:
                xtol = LOCATE_XTOL * s_end
                sigma, nf = locate_lift_off(
                    y, f, h, model, pts, idx, m, work, st, i, st.lam_cur[i], xtol
                )
                y_new[:] = st.ys
                gi, nf2 = _grid_samples(
                    y, f, t, t + sigma, grid, gi, n_grid, model, pts, idx, m, work, st, out,
                    clock, max_samples,
                )  # fmt: skip
                y[:] = y_new
                return Integration(INT_LIFT_OFF, t + sigma, nfev + nf + nf2, i)
        if n_watch > 0:
            g_new = _lowest_gap(y_new, model, pts, watch, n_watch)
            if g_new <= 0.0:
                g0 = _lowest_gap(y, model, pts, watch, n_watch)
                sigma, nf = locate_crossing(
                    y, f, h, g0, model, pts, idx, m, work, st, watch, n_watch, LOCATE_XTOL * s_end
                )
                y[:] = st.ys
                return Integration(INT_CROSSING, t + sigma, nfev + nf, -1)
        gi, nf = _grid_samples(
            y, f, t, t_new, grid, gi, n_grid, model, pts, idx, m, work, st, out, clock, max_samples
        )
        nfev += nf
        y[:] = y_new
        f[:] = K[N_STAGES]
        for i in range(m):
            st.lam_cur[i] = st.lam_new[i]
        t = t_new
    return Integration(INT_DONE, s_end, nfev, -1)
