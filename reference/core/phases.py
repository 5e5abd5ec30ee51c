"""One step of the loop in each kind of phase: a free flight up to its event, or one
chunk of a contact phase (or the event that ends it).  A step that needs more output
rows than are free returns NEEDS_ROWS before it changes anything, so the caller can
grow the arrays and redo it identically."""

import math

import numpy as np

from .candidates import (
    certified_horizon,
    is_held,
    set_aside_approaching,
    touching_candidates,
)
from .clock import grid_time, time_until, two_sum_add
from .contacts import (
    approaching_contacts,
    contact_frame,
    contact_kind,
    length_rate,
    length_scale,
    rate_noise,
    reached_together,
    rim_jet,
    time_resolution,
    velocity_scale,
)
from .dop853 import (
    INT_CROSSING,
    INT_FAILED,
    INT_LIFT_OFF,
    heun_euler_step,
    initial_step,
    integrate_held,
)
from .ending import end_run
from .events import activate, hold, resolve_impact
from .flight import flight_constants, free_flight
from .floor import below_floor, floor_gap, floor_horizon, floor_reach, has_floor
from .held import held_forces, held_rhs, project_held
from .horizon import force_trend_limit
from .inertia import kinetic_energy, potential_energy
from .jit import FALSE, TRUE, ZERO, copy_into, hot, hot_inline
from .law_event import law_event
from .layout import VX, VY, VZ, WX, WY, WZ
from .output import push_phase, push_sample
from .records import (
    EVENT_ACTIVATION,
    EVENT_NONE,
    EVENT_STUCK,
    N_SAMPLES,
    PHASE_CONTACT,
    PHASE_FLIGHT,
    STATUS_BELOW_FLOOR,
    STATUS_FAILED_INTEGRATION,
    STATUS_FAILED_NO_ADVANCE,
    STATUS_FAILED_STUCK,
)
from .search import flight_event
from .tolerances import (
    BRACKET_ITERATIONS,
    CONTACT_GAP_RES,
    EPS,
    HEUN_STEP_RATIO,
    MAX_SEARCH_ITERATIONS,
    TINY,
    WINDOW_MAX,
)
from .window import use_window, vertex_window

DONE, NEEDS_ROWS = 0, 1


@hot
def _first_grid_point(t_hi, t_lo, dt):
    """k of the first sample-grid point k·dt after the clock t_hi + t_lo (its local time
    `clock.grid_time` tested > 0)."""
    k = math.floor(t_hi / dt) + 1
    while grid_time(k, dt, t_hi, t_lo) <= 0:
        k += 1
    return k


@hot
def grid_count(t_hi, t_lo, s_end, dt):
    """Number of sample-grid times k·dt inside (t, t + s_end): from the first
    (`_first_grid_point`), one per dt (an upper bound `grid_times` enumerates)."""
    if not s_end > 0.0:
        return 0
    first = grid_time(_first_grid_point(t_hi, t_lo, dt), dt, t_hi, t_lo)
    if first >= s_end:
        return 0
    return int(math.ceil((s_end - first) / dt)) + 1


@hot
def grid_times(t_hi, t_lo, s_end, dt, limit):
    """The sample-grid points inside (0, s_end) of local time from t (from
    `_first_grid_point`, each time tested; at most `limit`): (k, dt, n), the points
    (k + i)·dt, i < n, as `dop853.integrate_held` reads them (`clock.grid_time`)."""
    kk = _first_grid_point(t_hi, t_lo, dt)
    n = 0
    while n < limit and grid_time(kk + n, dt, t_hi, t_lo) < s_end:
        n += 1
    return kk, dt, n


NO_GRID = (ZERO, 1.0, ZERO)  # grid_times' (k, dt, n) of no sample points


@hot
def _needed(n_grid, out, opts):
    """Whether n_grid samples (and a few event samples) do not fit in the free rows
    (counting only what max_samples still admits)."""
    n = out.counts[N_SAMPLES]
    need = min(n_grid + 4, max(opts.max_samples - n, 0))
    return need > out.sample_t.shape[0] - n


@hot_inline
def flight_step(state, model, pts, opts, stats, out, ws, cs):
    """Free flight from the state to its first event (or to t_end), then the event; the
    rim reaching the floor plane first (a ground without rim contacts, `floor.floor_reach`)
    ends the run there, `left_model`.  Inlined where it is called (numba's IR inlining:
    the loop's step, `loop.loop_step`)."""
    y = state.y
    remaining = time_until(state.t_hi, state.t_lo, opts.t_end)
    fc = flight_constants(y, model.i1, model.i3)
    ev = flight_event(
        y, fc, model, pts, opts.window_search, remaining, MAX_SEARCH_ITERATIONS, ws.y_event,
        cs.together, ws.res,
    )  # fmt: skip
    if ev.kind == EVENT_STUCK:
        end_run(state, STATUS_FAILED_STUCK, cs.together, 0)
        return DONE
    s_floor = floor_reach(y, fc, model, ev.s)
    s_end = ev.s
    if s_floor >= 0.0:
        s_end = s_floor
        free_flight(y, fc, model.gravity, s_end, ws.y_event)
    n_grid = grid_count(state.t_hi, state.t_lo, s_end, opts.sample_dt)
    if _needed(n_grid, out, opts):
        return NEEDS_ROWS
    stats.flight_searches += 1
    stats.search_iterations += ev.iterations
    fly_to(state, model, opts, out, ws, fc, s_end, n_grid)
    if s_floor >= 0.0:
        end_run(state, STATUS_BELOW_FLOOR, cs.together, 0)
        return DONE
    if ev.kind == EVENT_NONE:
        return DONE
    if ev.kind == EVENT_ACTIVATION:
        activate(state, model, pts, ws, stats, cs.together, ev.n_together)
        return DONE
    resolve_impact(  # no contact held in flight; one signature of resolve_impact (jit.py)
        state, model, pts, opts, stats, out, ws, cs, cs.together, ev.n_together,
        state.active[:], ZERO,
    )  # fmt: skip
    return DONE


@hot_inline
def _impact_with_held(state, model, pts, opts, stats, out, ws, cs, hitting, n_hit):
    """The impact of hitting[:n_hit] with the contacts held (state.active) as the resting
    ones: those copied to ws.held first, since resolve_impact changes state.active; passed
    as a view, so that resolve_impact has one signature (jit.py)."""
    for i in range(state.n_active):
        ws.held[i] = state.active[i]
    resolve_impact(
        state, model, pts, opts, stats, out, ws, cs, hitting, n_hit, ws.held[:], state.n_active
    )


@hot_inline
def fly_to(state, model, opts, out, ws, fc, s_end, n_grid):
    """The free flight from the state to ws.y_event at s_end: its n_grid grid samples
    (`grid_count`, their rows checked by `_needed`), its phase row, the state and time
    advanced.  Inlined where it is called (numba's IR inlining): a call of its own
    cost `flight_step` 5 % of a bouncing run's instructions."""
    y = state.y
    k, dt, n = grid_times(state.t_hi, state.t_lo, s_end, opts.sample_dt, n_grid + 1)
    for i in range(n):
        s = grid_time(k + i, dt, state.t_hi, state.t_lo)
        free_flight(y, fc, model.gravity, s, ws.y_chunk)
        hi, lo = two_sum_add(state.t_hi, state.t_lo, s)
        push_sample(out, hi, lo, ws.y_chunk, model, opts.max_samples)
    t0 = state.t_hi
    state.t_hi, state.t_lo = two_sum_add(state.t_hi, state.t_lo, s_end)
    copy_into(y, ws.y_event)
    push_phase(out, t0, state.t_hi, np.int64(PHASE_FLIGHT), state.active, ZERO)
    push_sample(out, state.t_hi, state.t_lo, y, model, opts.max_samples)


@hot
def flat_flight_step(state, model, pts, opts, stats, out, ws, cs):
    """The flight after a flat bounce (law_event): the body left every contact at one
    speed u = state.flat_u, flat, so it lands flat again after 2u/g (its height returns
    in closed form; its attitude, turning about the vertical, stays flat), where the
    law resolves the landing on all its contacts.  The run's end (t_end) comes first
    when it is sooner."""
    y = state.y
    s_end = 2.0 * state.flat_u / model.gravity
    remaining = time_until(state.t_hi, state.t_lo, opts.t_end)
    landing = s_end <= remaining
    if not landing:
        s_end = remaining
    n_grid = grid_count(state.t_hi, state.t_lo, s_end, opts.sample_dt)
    if _needed(n_grid, out, opts):
        return NEEDS_ROWS
    fc = flight_constants(y, model.i1, model.i3)
    free_flight(y, fc, model.gravity, s_end, ws.y_event)
    fly_to(state, model, opts, out, ws, fc, s_end, n_grid)
    state.flat_u = 0.0
    if landing:
        for i in range(model.n_contacts):
            cs.near[i] = i
        law_event(state, model, pts, opts, stats, out, ws, cs, cs.near, model.n_contacts)
    return DONE


@hot
def phase_gap_res(y, model, opts):
    """The gap resolution of a contact phase at state y: the integrator's tolerance on
    the positions, CONTACT_GAP_RES × rtol × the length scale L = |z| + a sin α."""
    return CONTACT_GAP_RES * opts.contact_rtol * length_scale(y, model.radius)


@hot
def begin_contact_phase(state, model, opts):
    """Enter a contact phase with the held contacts: its start, energy and gap
    resolution (`phase_gap_res` at the start; from the first chunk's end when it
    starts exactly flat, `_end_chunk`)."""
    y = state.y
    state.in_contact = True
    state.phase_t0 = state.t_hi
    state.gap_res = phase_gap_res(y, model, opts)
    state.phase_energy0 = kinetic_energy(y, model.mass, model.i1, model.i3) + potential_energy(
        y, model.mass, model.gravity
    )
    state.has_trend = False
    state.h_next = 0.0


@hot
def close_contact_phase(state, model, stats, out):
    """Record the contact phase that ends now and its energy drift."""
    y = state.y
    push_phase(
        out, state.phase_t0, state.t_hi, np.int64(PHASE_CONTACT), state.active, state.n_active
    )
    e = kinetic_energy(y, model.mass, model.i1, model.i3) + potential_energy(
        y, model.mass, model.gravity
    )
    e0 = state.phase_energy0
    stats.contact_energy_drift_max = max(
        stats.contact_energy_drift_max, abs(e - e0) / max(abs(e0), TINY)
    )
    stats.contact_phases += 1
    state.in_contact = False


@hot
def _touching_event(state, model, pts, opts, stats, out, ws, cs, n_cand, gap_res):
    """A free contact touching while approaching (gap within its roundoff: an impact with
    the held ones, and with every other approaching contact `reached_together` with it,
    as in flight) or at rest accelerating into the ground (gap within max(noise,
    gap_res): an activation) ends the phase.  Returns True if so."""
    vnoise = rate_noise(state.y, model.radius)
    n_hit = n_land = ZERO
    hitting = cs.hitting
    first = np.int64(-1)
    for i in range(n_cand):
        if cs.gap[i] > max(cs.noise[i], gap_res):
            continue
        if cs.rate[i] < -vnoise:
            if cs.gap[i] <= cs.noise[i]:
                hitting[n_hit] = cs.cand[i]
                n_hit += 1
                first = i if first < 0 else first
        elif cs.rate[i] <= vnoise and cs.accel[i] < 0:
            cs.together[n_land] = cs.cand[i]
            n_land += 1
    if n_hit:
        n_hit = _add_reached_together(
            cs, n_cand, first, n_hit, vnoise, gap_res, model.window_per_speed
        )
        close_contact_phase(state, model, stats, out)
        _impact_with_held(state, model, pts, opts, stats, out, ws, cs, hitting, n_hit)
        return True
    if n_land:
        close_contact_phase(state, model, stats, out)
        activate(state, model, pts, ws, stats, cs.together, n_land)
        return True
    return False


@hot
def _add_reached_together(cs, n_cand, first, n_hit, vnoise, gap_res, window_per_speed):
    """Append to cs.hitting the approaching contacts above their roundoff that are
    `reached_together` with the touching cs.cand[first], each gap known to
    max(its roundoff, gap_res) (the integrator's resolution of positions in a contact
    phase); returns the new count."""
    tres0 = time_resolution(max(cs.noise[first], gap_res), cs.rate[first])
    for i in range(n_cand):
        if cs.gap[i] > cs.noise[i] and cs.rate[i] < -vnoise:
            gap_i = max(cs.noise[i], gap_res)
            if reached_together(
                cs.gap[i], cs.rate[i], gap_i, tres0, cs.rate[first], window_per_speed
            ):
                cs.hitting[n_hit] = cs.cand[i]
                n_hit += 1
    return n_hit


@hot
def _set_tolerances(y, model, scale_x, rtol, atol, h):
    """Absolute tolerances of a chunk of length h: rtol × scale_x for positions (over a
    for the quaternion), rtol × the velocity scale V for velocities (over a for ω).  A
    body exactly at rest (V = 0) takes the speed g h gravity gives it over the chunk: on
    rtol × TINY, a denormal, the roundoff of the velocities that stay near zero was an
    error above tolerance at every step (a polygon released at rest on one vertex
    failed at t = 0, "step size below roundoff")."""
    scale_x += TINY
    scale_v = velocity_scale(y, model.radius)
    if scale_v == 0.0:
        scale_v = model.gravity * h
    scale_v += TINY
    for c in range(3):
        atol[c] = rtol * scale_x
        atol[7 + c] = rtol * scale_v
        atol[10 + c] = rtol * scale_v / model.radius
    for c in range(3, 7):
        atol[c] = rtol * scale_x / model.radius


@hot
def _chunk_tolerances(y, model, opts, atol, h):
    """A chunk's absolute tolerances (`_set_tolerances`, positions on the length scale L
    of state y; a chunk of length h from a body exactly flat at z = 0, L = 0, on the
    extent U h its positions may reach, as `_first_step`: on rtol × TINY, a denormal,
    the roundoff of components that stay near zero, e.g. q_z without spin, was an error
    above tolerance at every step size, and the chunk never ended); returns the scale."""
    L = length_scale(y, model.radius)
    if L == 0.0:
        L = length_rate(y, model.radius) * h
    _set_tolerances(y, model, L, opts.contact_rtol, atol, h)
    return L


@hot
def _prepare_chunk(state, model, pts, opts, stats, ws, h):
    """The chunk's tolerances (ws.atol, `_chunk_tolerances`) and its first step: the
    previous chunk's h_next, or `_first_step`."""
    h_start = state.h_next
    if not h_start > 0.0:
        L = length_scale(state.y, model.radius)
        h_start, nfev = _first_step(state, model, pts, opts, ws, h, L)
        stats.contact_rhs_evals += nfev
    _chunk_tolerances(state.y, model, opts, ws.atol, h)
    return h_start


@hot
def _first_step(state, model, pts, opts, ws, h, L):
    """The first integrator step of a chunk of length h that follows no other: scipy's
    estimate (`dop853.initial_step`, f(y) in ws.f) with the extent L + U h the positions
    may cover as their scale (`length_rate`).  With L alone (the chunk's tolerance) a
    body passing flat while moving, L → 0, would start 1e-20 of the chunk short and take
    dozens of steps to grow.  Returns (h, nfev)."""
    y = state.y
    scale_x = L + length_rate(y, model.radius) * h
    _set_tolerances(y, model, scale_x, opts.contact_rtol, ws.atol, h)
    return initial_step(y, ws.f, h, opts.contact_rtol, ws.atol, model, pts, state.active,
                        state.n_active, ws, ws)  # fmt: skip


@hot
def _crossed(y, state, model, pts, opts, cs, gap_res):
    """Free contacts below the ground beyond their resolution at y: how many (listed in
    cs.together).  For large polygons only the window of vertices below the ground at y
    is looked at (`vertex_window` with K = δ = 0 is exact: the others are above)."""
    n = pts.shape[0]
    first, count = 0, n
    if use_window(model, opts.window_search):
        k0, half = vertex_window(y, model.radius, n, 0.0, 0.0, np.int64(WINDOW_MAX), 0.0)
        first, count = k0 - half, min(2 * half + 1, n)
    m = ZERO
    for i in range(count):
        k = (first + i) % n
        if is_held(state, k):
            continue
        f = contact_frame(y, contact_kind(pts, k), pts, k)
        if f.gap < -max(f.noise, gap_res):
            cs.together[m] = k
            m += 1
    return m


@hot
def _touching_now(state, model, pts, opts, stats, out, ws, cs, s_star, n_crossed):
    """Crossed contacts (cs.together[:n_crossed]) reached below the clock's resolution:
    touching now.  Approaching ones (a chunk cut where one reached the ground a roundoff
    short of its noise band) are an impact with the held ones, as in `_touching_event`
    (held instead, a triangle's third vertex landing at speed beside a held edge ended
    the motion "all contacts down" with its energy); the others, with no approach speed
    and no downward acceleration (a tie the LCP cannot see) whose gaps still fall,
    land, held with the others."""
    _cut_chunk(state, ws, s_star)
    close_contact_phase(state, model, stats, out)
    n_hit = _approaching(state.y, model, pts, cs.together, n_crossed, cs.hitting)
    if n_hit:
        _impact_with_held(state, model, pts, opts, stats, out, ws, cs, cs.hitting, n_hit)
        return DONE
    activate(state, model, pts, ws, stats, cs.together, n_crossed)
    return DONE


@hot
def _approaching(y, model, pts, contacts, n, out):
    """The contacts[:n] approaching the ground at y (normal velocity below its roundoff)
    to out; returns how many."""
    return approaching_contacts(y, model, pts, contacts, n, rate_noise(y, model.radius), out)


@hot
def _locate_crossing(state, model, pts, opts, stats, out, ws, cs, h, n_crossed):
    """The first time in (0, h] the crossed contacts (cs.together[:n_crossed]) reach the
    ground: the chunk integrated again from its start watching their gaps, the zero
    located inside the step that holds it (dop853.locate_crossing); ws.y_chunk ends
    there, projected.  The horizon's backstop: its Taylor part is not a bound."""
    copy_into(ws.y_chunk, ws.y_start)
    r = integrate_held(
        ws.y_chunk, h, model, pts, state.active, state.n_active, opts.contact_rtol, ws.atol,
        ws, ws, NO_GRID, out, (state.t_hi, state.t_lo), opts.max_samples, FALSE, cs.together,
        n_crossed, 0.0, FALSE,
    )  # fmt: skip
    stats.contact_rhs_evals += r.nfev
    project_held(ws.y_chunk, model, pts, state.active, state.n_active, ws)
    return r.s


@hot
def contact_step(state, model, pts, opts, stats, out, ws, cs):
    """One step of a contact phase: the event that ends it, or one integrated chunk."""
    y = state.y
    gap_res = state.gap_res
    m = state.n_active
    held_rhs(y, model, pts, state.active, m, ws, ws.f)  # the chunk's f(y) too
    for i in range(m):  # the held forces now (ws.lam is reused below)
        ws.lam_chunk[i] = ws.lam[i]
        ws.lam_cur[i] = ws.lam[i]
    acc = (ws.f[VX], ws.f[VY], ws.f[VZ], ws.f[WX], ws.f[WY], ws.f[WZ])
    ex = touching_candidates(state, model, pts, opts, acc, cs, gap_res)
    if _touching_event(state, model, pts, opts, stats, out, ws, cs, ex.n, gap_res):
        return DONE
    ex, n_near, t_near = set_aside_approaching(cs, ex, rate_noise(y, model.radius), gap_res)
    remaining = time_until(state.t_hi, state.t_lo, opts.t_end)
    h, _ = certified_horizon(state, model, pts, acc, cs, ex, min(remaining, t_near))
    if state.has_trend:
        h = force_trend_limit(h, ws.lam_chunk, state.lam_prev, state.h_prev, m)
    if has_floor(model):
        h = floor_horizon(y, acc, rim_jet(y, acc, model.radius), model, ex.K, h)
    if h <= 0:
        close_contact_phase(state, model, stats, out)
        if remaining > 0:
            end_run(state, STATUS_FAILED_NO_ADVANCE, state.active, state.n_active)
        return DONE
    if _short_chunk(state, model, pts, opts, stats, out, ws, cs, h, n_near, t_near, remaining):
        return DONE
    n_grid = grid_count(state.t_hi, state.t_lo, h, opts.sample_dt)
    if _needed(n_grid, out, opts):
        return NEEDS_ROWS
    grid = grid_times(state.t_hi, state.t_lo, h, opts.sample_dt, n_grid + 1)
    h_start = _prepare_chunk(state, model, pts, opts, stats, ws, h)
    copy_into(ws.y_start, y)
    copy_into(ws.y_chunk, y)
    ns0 = out.counts[N_SAMPLES]
    r = integrate_held(
        ws.y_chunk, h, model, pts, state.active, m, opts.contact_rtol, ws.atol, ws,
        ws, grid, out, (state.t_hi, state.t_lo), opts.max_samples, TRUE, cs.near, n_near,
        h_start, TRUE,
    )  # fmt: skip
    stats.contact_rhs_evals += r.nfev
    return _chunk_outcome(state, model, pts, opts, stats, out, ws, cs, r, h, ns0, remaining)


@hot
def _chunk_outcome(state, model, pts, opts, stats, out, ws, cs, r, h, ns0, remaining):
    """What an integrated chunk of length h (its integration r, ws.y_chunk its end)
    leads to: a failure, a lift-off, the rim below the floor plane (before any of the
    chunk's other outcomes: `_floor_in_chunk`), a free contact crossed or reached (its
    impact next), or the chunk's end."""
    m = state.n_active
    if r.status == INT_FAILED:
        end_run(state, STATUS_FAILED_INTEGRATION, state.active, m)
        return DONE
    if r.status != INT_CROSSING:  # a crossing stays where its gap is zero: the impact's state
        project_held(ws.y_chunk, model, pts, state.active, m, ws)
    lift_off = r.status == INT_LIFT_OFF
    if lift_off and not below_floor(ws.y_chunk, model):
        return _lift_off(state, model, pts, opts, stats, out, ws, r)
    s_end = r.s
    n_crossed = 0 if lift_off else _crossed(ws.y_chunk, state, model, pts, opts, cs, state.gap_res)
    if n_crossed:
        stats.horizon_backstops += 1
        s_end = _locate_crossing(state, model, pts, opts, stats, out, ws, cs, r.s, n_crossed)
    if below_floor(ws.y_chunk, model):  # before the chunk's end, its lift-off or crossing
        return _floor_in_chunk(state, model, pts, opts, stats, out, ws, cs, s_end, ns0)
    if n_crossed:
        _drop_samples_after(out, ns0, state, s_end)
        if two_sum_add(state.t_hi, state.t_lo, s_end)[0] == state.t_hi:
            return _touching_now(state, model, pts, opts, stats, out, ws, cs, s_end, n_crossed)
        return _cut_chunk(state, ws, s_end)
    if r.status == INT_CROSSING:  # an approaching contact reached the ground: its impact next
        stats.contact_chunks += 1
        return _cut_chunk(state, ws, r.s)
    return _end_chunk(state, model, opts, stats, out, ws, h, r.h_next, remaining)


@hot
def _integrate_to(state, model, pts, opts, stats, out, ws, cs, s):
    """ws.y_chunk: the held motion integrated from the chunk's start ws.y_start over s,
    projected, without samples or watched contacts."""
    copy_into(ws.y_chunk, ws.y_start)
    r = integrate_held(
        ws.y_chunk, s, model, pts, state.active, state.n_active, opts.contact_rtol, ws.atol,
        ws, ws, NO_GRID, out, (state.t_hi, state.t_lo), opts.max_samples, FALSE,
        cs.together, ZERO, 0.0, FALSE,
    )  # fmt: skip
    stats.contact_rhs_evals += r.nfev
    project_held(ws.y_chunk, model, pts, state.active, state.n_active, ws)


@hot
def _floor_in_chunk(state, model, pts, opts, stats, out, ws, cs, h, ns0):
    """The chunk of length h ended with the rim below the floor plane (`floor.below_floor`):
    the first time it reached the plane, bisected on the chunk integrated again from its
    start (H = `floor.floor_gap` ≤ 0 at the bracket's right end) until the bracket is
    within two ulps of its end; the run ends there `left_model`, the chunk cut and its
    later samples dropped.  Bisection, not Newton: H along the integrated motion is
    known to the integrator's tolerance, and this runs once per run."""
    lo, hi = 0.0, h
    for _ in range(BRACKET_ITERATIONS):
        mid = 0.5 * (lo + hi)
        if not (lo < mid < hi) or hi - lo <= 2.0 * EPS * hi:
            break
        _integrate_to(state, model, pts, opts, stats, out, ws, cs, mid)
        if floor_gap(ws.y_chunk, model) > 0.0:
            lo = mid
        else:
            hi = mid
    _integrate_to(state, model, pts, opts, stats, out, ws, cs, hi)
    _drop_samples_after(out, ns0, state, hi)
    _cut_chunk(state, ws, hi)
    push_sample(out, state.t_hi, state.t_lo, state.y, model, opts.max_samples)
    close_contact_phase(state, model, stats, out)
    end_run(state, STATUS_BELOW_FLOOR, state.active, 0)
    return DONE


@hot
def _end_chunk(state, model, opts, stats, out, ws, h, h_next, remaining):
    """Advance to the end of a chunk of length h (state ws.y_chunk, projected): its
    forces at the start give the next chunk their trend, h_next its first step.  A
    phase that began with L = 0 (a body exactly flat at z = 0 after a simultaneous
    impact, one vertex leaving beside a held edge) takes its gap resolution here, from
    the first chunk's end (`phase_gap_res`: the positions were integrated on that
    scale); with a resolution of 0, when the vertex came back its gap and the gap's
    roundoff (∝ |z| + |r_z|) shrank together, no chunk found it touching, and the
    chunks shrank geometrically at one time (the phase "cannot advance").  A phase with
    L > 0 keeps its start's resolution: raised as L grows, contacts were reached
    together that the paper's rule resolves one by one."""
    y = state.y
    stats.contact_chunks += 1
    state.t_hi, state.t_lo = two_sum_add(state.t_hi, state.t_lo, h)
    copy_into(y, ws.y_chunk)
    if state.gap_res == 0.0:
        state.gap_res = phase_gap_res(y, model, opts)
    for i in range(state.n_active):  # the next chunk sees the forces' trend
        state.lam_prev[i] = ws.lam_chunk[i]
    state.h_prev = h
    state.has_trend = True
    state.h_next = h_next
    if remaining - h <= 0:
        push_sample(out, state.t_hi, state.t_lo, y, model, opts.max_samples)
        close_contact_phase(state, model, stats, out)
    return DONE


@hot
def _short_chunk(state, model, pts, opts, stats, out, ws, cs, h, n_near, t_near, remaining):
    """A chunk far shorter than the integrator's step (≤ HEUN_STEP_RATIO state.h_next)
    in one step of the Heun–Euler pair (`dop853.heun_euler_step`, 2 evaluations where a
    DOP853 chunk spends 12 or more): the chunk h, or with contacts
    approaching within the gap resolution (cs.near) the first one's Taylor landing
    time s = t_near/2 (`set_aside_approaching`), whose end, gap zero to roundoff, is
    its impact's state.  Taken only if the pair accepts it at the chunk's tolerances,
    no sample falls inside (and rows for the run's last one are free), no held force is
    negative at either end and no free contact has crossed: else the DOP853 chunk,
    which locates those.  Returns True if taken."""
    s = 0.5 * t_near if n_near else h
    if not (s <= h and s <= HEUN_STEP_RATIO * state.h_next):
        return False
    if grid_count(state.t_hi, state.t_lo, s, opts.sample_dt) > 0 or _needed(ZERO, out, opts):
        return False
    y, m = state.y, state.n_active
    _chunk_tolerances(y, model, opts, ws.atol, s)
    err = heun_euler_step(y, ws.f, s, opts.contact_rtol, ws.atol, model, pts, state.active, m,
                          ws, ws, ws.y_chunk)  # fmt: skip
    held_forces(ws.y_chunk, model, pts, state.active, m, ws)
    stats.contact_rhs_evals += 2
    if not err <= 1.0 or _negative_force(ws.lam_chunk, m) or _negative_force(ws.lam, m):
        return False
    if _crossed(ws.y_chunk, state, model, pts, opts, cs, state.gap_res):
        return False
    if below_floor(ws.y_chunk, model):  # (the DOP853 chunk locates it)
        return False
    if n_near:
        stats.contact_chunks += 1
        return _cut_chunk(state, ws, s) == DONE
    project_held(ws.y_chunk, model, pts, state.active, m, ws)
    return _end_chunk(state, model, opts, stats, out, ws, s, state.h_next, remaining) == DONE


@hot
def _negative_force(lam, m):
    """Whether any of lam[:m] is negative."""
    for i in range(m):
        if lam[i] < 0.0:
            return True
    return False


@hot
def _cut_chunk(state, ws, s):
    """Advance to local time s of the chunk (state ws.y_chunk), where a free contact
    reached the ground."""
    state.t_hi, state.t_lo = two_sum_add(state.t_hi, state.t_lo, s)
    copy_into(state.y, ws.y_chunk)
    state.has_trend = False
    state.h_next = 0.0
    return DONE


@hot
def _drop_samples_after(out, ns0, state, s_star):
    """Forget the chunk's grid samples at local times ≥ s_star (the chunk was cut)."""
    n = out.counts[N_SAMPLES]
    keep = ns0
    for i in range(ns0, n):
        if time_until(state.t_hi, state.t_lo, out.sample_t[i, 0]) + out.sample_t[i, 1] < s_star:
            keep = i + 1
    out.counts[N_SAMPLES] = keep


@hot
def _lift_off(state, model, pts, opts, stats, out, ws, r):
    """A held force reached zero at r.s: advance there, close the phase, and hold the
    others that the LCP keeps."""
    y = state.y
    stats.lift_offs += 1
    if r.s > 0.0:
        stats.contact_chunks += 1
        state.t_hi, state.t_lo = two_sum_add(state.t_hi, state.t_lo, r.s)
        copy_into(y, ws.y_chunk)
    push_sample(out, state.t_hi, state.t_lo, y, model, opts.max_samples)
    close_contact_phase(state, model, stats, out)
    m = ZERO
    for i in range(state.n_active):
        if i != r.leaving:
            ws.cand[m] = state.active[i]
            m += 1
    hold(state, model, pts, ws, ws.cand, m)
    return DONE
