"""Integration of the held motion in a contact phase: DOP853 (Hairer's 8(5,3) pair) with
scipy's coefficients, initial step, error norm and step control (scipy.integrate's
`DOP853`), so that a chunk is the step sequence `solve_ivp(method="DOP853")` takes.

Grid samples inside a chunk are taken by one DOP853 step from the start of the accepted
step that contains them (a shorter step: no less accurate).  With `watch_forces` the
held forces λ (known at every step end: the FSAL derivative computes them) are watched,
and the gaps of the contacts in `watch`: when one turns negative inside a step, its zero
is located there on the step's dense output (scipy's 7th-order interpolant, three more
stages), to LOCATE_XTOL of the chunk (`locate_in_step`): a lift-off or a crossing, as
solve_ivp locates its events."""

import math
from collections import namedtuple

import numpy as np

from . import dop853_tableau as tab
from .clock import grid_time, two_sum_add
from .contacts import contact_frame, contact_kind
from .held import held_derivative, held_forces, held_rhs
from .jit import ZERO, copy_into, hot, hot_inline
from .layout import STATE_SIZE
from .output import push_sample
from .tolerances import EPS, LOCATE_ITERATIONS, LOCATE_XTOL

N_STAGES = tab.N_STAGES
DOP_A = np.ascontiguousarray(tab.A)
DOP_B = np.ascontiguousarray(tab.B)
DOP_C = np.ascontiguousarray(tab.C)
DOP_E3 = np.ascontiguousarray(tab.E3)
DOP_E5 = np.ascontiguousarray(tab.E5)
DOP_A_EXTRA = np.ascontiguousarray(tab.A_EXTRA)
DOP_D = np.ascontiguousarray(tab.D)
N_STAGES_EXTRA = tab.N_STAGES_EXTENDED - tab.N_STAGES - 1
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0  # scipy's step control
ERROR_EXPONENT = -1.0 / 8.0  # error estimator of order 7

INT_DONE, INT_LIFT_OFF, INT_FAILED, INT_CROSSING = 0, 1, 2, 3
# status; s: where the integration stopped (the chunk's end, the lift-off or the
# crossing); nfev; leaving: index (into the held list) of the contact whose force reached
# zero; h_next: the step the integration would take next (`_next_step`)
Integration = namedtuple("Integration", ["status", "s", "nfev", "leaving", "h_next"])

# `st` in this module is a records.SCRATCH record: stages K (13 rows: 12 stages and
# f(y_new)) of the steps taken and Ks of one-step evaluations, state and scale vectors,
# the held forces at the current state (lam_cur) and at the end of the step just
# accepted (lam_new).  The held functions use the same record as their `work`.


@hot
def dop853_step(y, f0, h, model, pts, idx, m, work, K, y_new, tmp):
    """One DOP853 step of size h from (y, f0 = f(y)) into y_new; K receives the stages
    and f(y_new) as its last row (work.lam: the held forces at y_new).  Returns the
    number of right-hand-side evaluations."""
    copy_into(K[0], f0)
    for s in range(1, N_STAGES):
        stage_state(y, h, DOP_A[s], K, s, tmp)
        held_derivative(tmp, model, pts, idx, m, work, K[s])
    stage_state(y, h, DOP_B, K, N_STAGES, y_new)
    held_derivative(y_new, model, pts, idx, m, work, K[N_STAGES])
    return N_STAGES


@hot_inline
def stage_state(y, h, weights, K, s, out):
    """out = y + h Σ_{j<s} weights[j] K[j]: a Runge–Kutta stage's state.  The sum runs
    over stages j in order, row by row (STATE_SIZE contiguous components at a time, zero
    weights skipped): for each component the same additions in the same order as a
    column-wise sum, so the same bits (measured: one-impact run 11.78 → 11.51 µs; a
    column-wise sum in a local variable, a zero test per component and stage, takes
    1.7 times the step's perf samples).  Inlined where it is called (numba's IR
    inlining), as the stages' right-hand side (`dop853_step`): a step is one call."""
    for c in range(STATE_SIZE):
        out[c] = 0.0
    for j in range(s):
        w = weights[j]
        if w != 0.0:
            for c in range(STATE_SIZE):
                out[c] += w * K[j, c]
    for c in range(STATE_SIZE):
        out[c] = y[c] + h * out[c]


@hot
def heun_euler_step(y, f0, h, rtol, atol, model, pts, idx, m, work, st, y_new):
    """One step of the Heun–Euler pair from (y, f0 = f(y)) into y_new: the explicit
    trapezoid y + h/2 (f0 + f(y + h f0)), of order 2, with Euler's difference
    h/2 (f(y + h f0) − f0) as its error estimate, measured as scipy measures DOP853's
    (`_rms` against atol + rtol max(|y|, |y_new|)); when that passes, the order-2
    result is more accurate still (local extrapolation, as DOP853's own).  For steps
    far below the integrator's (`phases._short_chunk`), where a DOP853 step's 12
    evaluations buy nothing.  Returns the error norm (≤ 1: accepted)."""
    f1 = st.f1
    for c in range(STATE_SIZE):
        st.ys[c] = y[c] + h * f0[c]
    held_rhs(st.ys, model, pts, idx, m, work, f1)
    for c in range(STATE_SIZE):
        y_new[c] = y[c] + 0.5 * h * (f0[c] + f1[c])
        st.tmp[c] = 0.5 * h * (f1[c] - f0[c])
    step_scale(y, y_new, rtol, atol, st.scale)
    return _rms(st.tmp, st.scale)


@hot_inline
def step_scale(y, y_new, rtol, atol, scale):
    """scale = atol + rtol max(|y|, |y_new|): what a step's error is measured against
    (scipy's rk.RungeKutta._step_impl)."""
    for c in range(STATE_SIZE):
        scale[c] = atol[c] + max(abs(y[c]), abs(y_new[c])) * rtol


@hot
def _rms(v, scale):
    s = 0.0
    for i in range(v.shape[0]):
        s += (v[i] / scale[i]) ** 2
    return math.sqrt(s / v.shape[0])


@hot_inline
def error_norm(K, h, scale):
    """scipy's DOP853 error norm (rk.DOP853._estimate_error_norm).  Inlined where it
    is called (numba's IR inlining), as `step_scale`: the step control's arithmetic
    in the accepted step's own function (`_accepted_step`)."""
    e5 = 0.0
    e3 = 0.0
    for c in range(STATE_SIZE):
        a5 = 0.0
        a3 = 0.0
        for j in range(N_STAGES + 1):
            a5 += K[j, c] * DOP_E5[j]
            a3 += K[j, c] * DOP_E3[j]
        e5 += (a5 / scale[c]) ** 2
        e3 += (a3 / scale[c]) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * STATE_SIZE)


@hot
def initial_step(y, f, s_end, rtol, atol, model, pts, idx, m, work, st):
    """scipy.integrate._ivp.common.select_initial_step for order 7.  Returns (h, nfev)."""
    for c in range(STATE_SIZE):
        st.scale[c] = atol[c] + abs(y[c]) * rtol
    d0 = _rms(y, st.scale)
    d1 = _rms(f, st.scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, s_end)
    for c in range(STATE_SIZE):
        st.ys[c] = y[c] + h0 * f[c]
    held_rhs(st.ys, model, pts, idx, m, work, st.tmp)
    d2 = 0.0
    for c in range(STATE_SIZE):
        d2 += ((st.tmp[c] - f[c]) / st.scale[c]) ** 2
    d2 = math.sqrt(d2 / STATE_SIZE) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100 * h0, h1, s_end), 1


@hot
def dense_output(y, y_new, h, model, pts, idx, m, work, st):
    """scipy's DOP853 dense output of the step y → y_new of size h (stages in st.K, f(y)
    its first row and f(y_new) its last): three more stages into st.K[13:16] and the
    interpolant's coefficients into st.F (rk.DOP853._dense_output_impl).  The held
    forces in work.lam are those at y_new again on return.  Returns the number of
    right-hand-side evaluations."""
    K, F = st.K, st.F
    for s in range(N_STAGES_EXTRA):
        row = N_STAGES + 1 + s
        stage_state(y, h, DOP_A_EXTRA[s], K, row, st.tmp)
        held_rhs(st.tmp, model, pts, idx, m, work, K[row])
    for c in range(STATE_SIZE):
        dy = y_new[c] - y[c]
        F[0, c] = dy
        F[1, c] = h * K[0, c] - dy
        F[2, c] = 2.0 * dy - h * (K[N_STAGES, c] + K[0, c])
        for p in range(DOP_D.shape[0]):
            acc = 0.0
            for j in range(N_STAGES + 1 + N_STAGES_EXTRA):
                acc += DOP_D[p, j] * K[j, c]
            F[3 + p, c] = h * acc
    for i in range(m):
        work.lam[i] = st.lam_new[i]
    return N_STAGES_EXTRA


@hot
def dense_state(y, F, x, out):
    """The interpolated state at the fraction x ∈ [0, 1] of the step from y
    (Dop853DenseOutput._call_impl)."""
    n_pow = F.shape[0]
    for c in range(STATE_SIZE):
        v = 0.0
        for i in range(n_pow):
            v += F[n_pow - 1 - i, c]
            v *= x if i % 2 == 0 else 1.0 - x
        out[c] = v + y[c]


@hot
def _lowest_gap(y, model, pts, watch, n_watch):
    """The smallest gap among contacts watch[:n_watch] at y."""
    g = math.inf
    for i in range(n_watch):
        g = min(g, contact_frame(y, contact_kind(pts, watch[i]), pts, watch[i]).gap)
    return g


@hot
def _watched_at(y, sigma, h, model, pts, idx, m, work, st, leaving, watch, n_watch):
    """At local time σ of the step (its dense output, state into st.ys): held force
    `leaving` if ≥ 0, else the lowest gap of watch[:n_watch]."""
    dense_state(y, st.F, sigma / h, st.ys)
    if leaving >= 0:
        held_forces(st.ys, model, pts, idx, m, work)
        return work.lam[leaving]
    return _lowest_gap(st.ys, model, pts, watch, n_watch)


@hot
def locate_in_step(y, h, v0, vh, model, pts, idx, m, work, st, leaving, watch, n_watch, xtol):
    """σ in (0, h] where the watched value (held force `leaving`, or the lowest watched
    gap: v0 > 0 at the step's start, vh ≤ 0 at its end) reaches zero, on the step's
    dense output: Illinois regula falsi with bisection steps, to xtol + 4ε σ, or (a
    gap) to a trial point where the gap is exactly zero (a zero found: near it the gap
    is roundoff, and narrowing the bracket further follows noise).  Returns (σ,
    right-hand-side-like evaluations: the held forces'); st.ys holds the state there."""
    lo, flo, hi, fhi = 0.0, v0, h, vh
    side = 0
    it = 0
    for it in range(LOCATE_ITERATIONS):
        if hi - lo <= xtol + 4.0 * EPS * hi:
            break
        x = 0.5 * (lo + hi) if it % 3 == 2 or flo == fhi else hi - fhi * (hi - lo) / (fhi - flo)
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
        fx = _watched_at(y, x, h, model, pts, idx, m, work, st, leaving, watch, n_watch)
        if fx == 0.0 and leaving < 0:
            return x, 0
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
    _watched_at(y, hi, h, model, pts, idx, m, work, st, leaving, watch, n_watch)
    return hi, it + 2 if leaving >= 0 else 0


@hot
def _grid_samples(y, f, t, t_stop, grid, gi, model, pts, idx, m, work, st, out, clock, max_samples):
    """Samples at the grid times in (t, t_stop] (local times), each by one DOP853 step
    from (y, f) at t, stamped clock = (t_hi, t_lo) + the grid time; grid = (k, dt, n):
    the local times of the grid points (k + i)·dt, i < n (`clock.grid_time`).  Returns
    (next grid index, nfev)."""
    nfev = 0
    k, dt, n_grid = grid
    while gi < n_grid:
        s = grid_time(k + gi, dt, clock[0], clock[1])
        if s > t_stop:
            break
        hs = s - t
        if hs > 0.0:
            nfev += dop853_step(y, f, hs, model, pts, idx, m, work, st.Ks, st.ys, st.tmp)
        else:
            copy_into(st.ys, y)
        hi, lo = two_sum_add(clock[0], clock[1], s)
        push_sample(out, hi, lo, st.ys, model, max_samples)
        gi += 1
    return gi, nfev


@hot
def _most_negative(lam, m):
    """Index of the most negative held force, −1 if none is negative."""
    i_min, v_min = -1, 0.0
    for i in range(m):
        if lam[i] < v_min:
            i_min, v_min = i, lam[i]
    return i_min


@hot
def _accepted_step(y, f, t, s_end, h_abs, rtol, atol, model, pts, idx, m, work, st):
    """One accepted DOP853 step from local time t into st.y_new, with scipy's step-size
    control: a rejected step shrinks by max(MIN_FACTOR, SAFETY err^(−1/8)), an accepted
    one grows by at most MAX_FACTOR (not at all right after a rejection).  Returns
    (t + h, h, the next step's h_abs, RHS evaluations); h = 0 when the step would fall below 10
    roundoff units of t or the error norm is not finite."""
    K, y_new, scale = st.K, st.y_new, st.scale
    min_step = 10 * (math.nextafter(t, math.inf) - t)
    rejected = False
    nfev = 0
    while True:
        if h_abs < min_step:
            return t, 0.0, h_abs, nfev
        t_new = min(t + h_abs, s_end)
        h = t_new - t
        nfev += dop853_step(y, f, h, model, pts, idx, m, work, K, y_new, st.tmp)
        step_scale(y, y_new, rtol, atol, scale)
        err = error_norm(K, h, scale)
        if not math.isfinite(err):
            return t, 0.0, h_abs, nfev
        if err < 1.0:
            factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err**ERROR_EXPONENT)
            if rejected:
                factor = min(1.0, factor)
            return t_new, h, h * factor, nfev
        h_abs = h * max(MIN_FACTOR, SAFETY * err**ERROR_EXPONENT)
        rejected = True


@hot
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
    out,
    clock,
    max_samples,
    watch_forces,
    watch,
    n_watch,
    h_start,
    f_ready,
):
    """Integrate the held motion from y (in place) over [0, s_end] with scipy's adaptive
    DOP853; grid samples at the grid's local times (grid = (k, dt, n): (k + i)·dt from
    the clock, i < n, ascending, inside (0, s_end)), stamped with clock = (t_hi, t_lo) +
    the local time.  With watch_forces, stop where a
    held force reaches zero (INT_LIFT_OFF, y = the state there); with n_watch > 0, where
    the lowest gap of contacts watch[:n_watch] reaches zero (INT_CROSSING).  The first
    step is h_start when positive (the previous chunk's h_next), else scipy's estimate;
    f_ready: st.f and st.lam_cur hold f(y) and the held forces already."""
    f = st.f
    nfev = 0
    if not f_ready:
        held_rhs(y, model, pts, idx, m, work, f)
        nfev = 1
        for i in range(m):
            st.lam_cur[i] = work.lam[i]
    if watch_forces:
        i = _most_negative(st.lam_cur, m)
        if i >= 0:
            return Integration(INT_LIFT_OFF, 0.0, nfev, i, 0.0)
    if h_start > 0.0:
        h_abs = min(h_start, s_end)
    else:
        h_abs, n0 = initial_step(y, f, s_end, rtol, atol, model, pts, idx, m, work, st)
        nfev += n0
    t = 0.0
    gi = ZERO
    K, y_new = st.K, st.y_new
    h_next = h_abs
    while t < s_end:
        h_try = h_abs
        t_new, h, h_abs, n_step = _accepted_step(
            y, f, t, s_end, h_abs, rtol, atol, model, pts, idx, m, work, st
        )
        nfev += n_step
        if h == 0.0:
            return Integration(INT_FAILED, t, nfev, -1, 0.0)
        h_next = _next_step(h_abs, h_try, h, n_step)
        for i in range(m):
            st.lam_new[i] = work.lam[i]
        leaving = _most_negative(st.lam_new, m) if watch_forces else -1
        v0, vh, status = 0.0, 0.0, INT_DONE
        if leaving >= 0:
            v0, vh, status = st.lam_cur[leaving], st.lam_new[leaving], INT_LIFT_OFF
        elif n_watch > 0:
            v0 = _lowest_gap(y, model, pts, watch, n_watch)
            vh = _lowest_gap(y_new, model, pts, watch, n_watch)
            status = INT_CROSSING
        if leaving >= 0 or (n_watch > 0 and vh <= 0.0):
            nfev += dense_output(y, y_new, h, model, pts, idx, m, work, st)
            sigma, nf = locate_in_step(
                y, h, v0, vh, model, pts, idx, m, work, st, leaving, watch, n_watch,
                LOCATE_XTOL * s_end,
            )  # fmt: skip
            copy_into(y_new, st.ys)
            gi, nf2 = _grid_samples(
                y, f, t, t + sigma, grid, gi, model, pts, idx, m, work, st, out,
                clock, max_samples,
            )  # fmt: skip
            copy_into(y, y_new)
            return Integration(status, t + sigma, nfev + nf + nf2, leaving, h_next)
        gi, nf = _grid_samples(
            y, f, t, t_new, grid, gi, model, pts, idx, m, work, st, out, clock, max_samples
        )
        nfev += nf
        copy_into(y, y_new)
        copy_into(f, K[N_STAGES])
        for i in range(m):
            st.lam_cur[i] = st.lam_new[i]
        t = t_new
    return Integration(INT_DONE, s_end, nfev, -1, h_next)


@hot
def _next_step(h_abs, h_try, h, n_step):
    """The step to start the next chunk with: the controller's proposal, or, when the
    last step was cut short to end the chunk (h < h_try) at its first try (n_step = one
    step's stages), the uncut step it had proposed (a step cut to fit says nothing
    against its full length)."""
    if h < h_try and n_step == N_STAGES:
        return max(h_abs, h_try)
    return h_abs
