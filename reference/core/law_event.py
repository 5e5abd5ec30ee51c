"""A simultaneous impact resolved by the run's impact law, inside the loop.

Where the paper's rule stops (two contacts reached together, or a single impact that
would push a held contact), a run under a law with a function (reference.core.laws)
goes on at the same time, on the state before the impact:

1. the contacts of the impact (`touching_set`): the ones the event named and every
   contact touching (gap within TOUCH_ULPS roundoff bands of |z| + a) and not
   separating (a separating contact pulled down by the others' impulses would gain
   energy under Moreau's law; turned round by the impact it is the next event);
2. their Delassus matrix W and normal velocities u⁻ (multi_impact.delassus_system), the
   law's impulses Λ (law_dispatch.solve_law), (v, ω) += M⁻¹JᵀΛ, one impact row per
   contact that took an impulse;
3. bounces too small to follow are completed as after a single impact: when every
   contact that leaves, leaves below its chatter completion speed, the impact is taken
   plastic (γ = 0), except for a body landing flat (below);
4. a body landing flat (every contact of the ground in the impact, all leaving at one
   speed u⁺ > 0, 0 < γ < 1) bounces flat: while u⁺ is above the completion speed the
   next step flies to the next flat landing, 2u⁺/g later (phases.flat_flight_step), and
   the law resolves it on every contact; below it the rest of the series is completed
   in closed form and the run ends at rest at the accumulation time t + 2u⁺/(g(1 − γ))
   (`complete_flat_bounces`), pushed as a chatter accumulation time;
5. the loop's next step resolves the contacts touching after the impact as its start
   does (`state.recheck`: holds those at rest, a contact turned round is a new impact).

A law that does not settle, a contact no impulse can move, more contacts than the
scratch holds, or LAW_MAX_REPEATS law impacts at one time end the run
STATUS_LAW_UNDECIDED, state.law_outcome saying which."""

import math

from .chatter import completion_speed
from .clock import two_sum_add
from .contacts import contact_frame, contact_kind, normal_velocity, rate_noise
from .ending import end_run
from .impact_laws import MAX_SEQUENTIAL_IMPACTS, SETTLED, TOO_MANY
from .jit import FALSE, TRUE, ZERO, hot, hot_inline, sort_prefix
from .law_dispatch import solve_law
from .layout import QW, QX, QY, QZ, VX, VY, VZ, WX, WY, WZ, X, Y
from .multi_impact import apply_impulses, delassus_system
from .output import push_accumulation, push_impact, push_sample
from .records import STATUS_FLAT_REST, STATUS_LAW_UNDECIDED, LawWork
from .rotation import qmul, rotation_vector_quaternion
from .tolerances import EPS, GAP_NOISE_ULPS

# touching: gap within this many roundoff bands of |z| + a (the loop reaches a contact
# to a few ulps of it; two reached together are within its resolution)
TOUCH_ULPS = 4.0 * GAP_NOISE_ULPS
# a flat bounce: post-impact normal velocities equal to this relative spread
FLAT_SPREAD = 1e-9
# law impacts at one time (t_hi, t_lo) before the run is given up (no progress)
LAW_MAX_REPEATS = 64
# state.law_outcome beyond impact_laws' SETTLED … TOO_MANY
NO_PROGRESS = 4


@hot
def law_event(state, model, pts, opts, stats, out, ws, cs, named, n_named):
    """The simultaneous impact of the contacts touching with named[:n_named], under the
    run's law, at the current time (module docstring).  Returns False when it ended
    the run."""
    if not _progress(state):
        return _undecided(state, NO_PROGRESS, named, n_named)
    y = state.y
    K = cs.law_mats.shape[1]  # the scratch's contacts (ContactLists.law_mats)
    contacts = cs.law_ints[:K]
    k = touching_set(y, model, pts, named, n_named, contacts, model.law_separating)
    if k < 0:
        return _undecided(state, TOO_MANY, named, n_named)
    W, chol = cs.law_mats[:K], cs.law_mats[K:]
    v = cs.law_vecs
    u_pre, lam, u_post, vec = v[:K], v[K : 2 * K], v[2 * K : 3 * K], v[3 * K :]
    active, order_pos, order = (
        cs.law_ints[K : 2 * K],
        cs.law_ints[2 * K : 3 * K],
        cs.law_ints[3 * K :],
    )
    delassus_system(y, model, pts, contacts, k, W, u_pre)
    n_order = order_positions(contacts, k, order, opts.n_order, order_pos)
    work = LawWork(chol, vec, active, order_pos, n_order, MAX_SEQUENTIAL_IMPACTS)
    status, _ = solve_law(model.law, W, u_pre, model.gamma, k, lam, u_post, work)
    if status != SETTLED:
        return _undecided(state, status, contacts, k)
    vnoise = rate_noise(y, model.radius)
    flat = _flat_leaving(model, k, u_post, vnoise)
    if _bounces_are_small(y, model, pts, opts, contacts, k, u_post, vnoise):
        if flat:
            return _finish(
                state, model, pts, opts, stats, out, contacts, k, lam, u_pre, u_post, TRUE, TRUE
            )
        status, _ = solve_law(model.law, W, u_pre, 0.0, k, lam, u_post, work)
        if status != SETTLED:
            return _undecided(state, status, contacts, k)
        stats.chatter_completions += 1
    return _finish(
        state, model, pts, opts, stats, out, contacts, k, lam, u_pre, u_post, flat, FALSE
    )


@hot
def _finish(state, model, pts, opts, stats, out, contacts, k, lam, u_pre, u_post, flat, flat_end):
    """Apply the impulses, push the rows; then the flat series completed (flat_end), the
    flight to the next flat landing (flat) or the touching contacts resolved at the
    next step."""
    y = state.y
    apply_impulses(y, model, pts, contacts, k, lam)
    stats.simultaneous_impacts += 1
    u = 0.0
    for i in range(k):
        u += u_post[i] / k
        if lam[i] > 0.0:
            push_impact(out, state.t_hi, state.t_lo, contacts[i], lam[i], u_pre[i], u_post[i])
    if flat_end:
        complete_flat_bounces(state, model, opts, stats, out, u)
        return False
    push_sample(out, state.t_hi, state.t_lo, y, model, opts.max_samples)
    if flat:
        state.flat_u = u  # the next step flies to the next flat landing
    else:
        state.recheck = True
    return True


@hot
def _progress(state):
    """Whether the time has advanced since the last law impact, or fewer than
    LAW_MAX_REPEATS law impacts happened at this time (a cascade below one ulp of t
    advances in t_lo)."""
    if state.t_hi != state.law_t_hi or state.t_lo != state.law_t_lo:
        state.law_t_hi, state.law_t_lo, state.law_repeats = state.t_hi, state.t_lo, 0
    state.law_repeats += 1
    return state.law_repeats <= LAW_MAX_REPEATS


@hot_inline
def _undecided(state, outcome, contacts, n):
    """End the run STATUS_LAW_UNDECIDED (the law's outcome kept), naming contacts[:n]."""
    end_run(state, STATUS_LAW_UNDECIDED, contacts, n)
    state.law_outcome = outcome
    return False


@hot_inline
def _named(contacts, m, c):
    for i in range(m):
        if contacts[i] == c:
            return True
    return False


@hot
def touching_set(y, model, pts, named, n_named, contacts, separating):
    """contacts[:m] = named[:n_named] (without repeats) and every other contact touching
    (gap ≤ TOUCH_ULPS ε (|z| + a)) and not separating (normal velocity ≤ its roundoff;
    `separating`: separating ones too, for a law whose other contacts can push them
    back); returns m, or −1 when they do not fit in `contacts`."""
    cap = contacts.shape[0]
    m = ZERO
    for i in range(n_named):
        if not _named(contacts, m, named[i]):
            if m >= cap:
                return -1
            contacts[m] = named[i]
            m += 1
    n_named_set = m
    gap_tol = TOUCH_ULPS * EPS * (abs(y[2]) + model.radius)
    v_tol = rate_noise(y, model.radius)
    for c in range(pts.shape[0]):
        kind = contact_kind(pts, c)
        f = contact_frame(y, kind, pts, c)
        if f.gap > gap_tol or _named(contacts, n_named_set, c):
            continue
        if separating or normal_velocity(y, f, kind) <= v_tol:
            if m >= cap:
                return -1
            contacts[m] = c
            m += 1
    sort_prefix(contacts, m)
    return m


@hot
def order_positions(contacts, k, order, n_order, pos):
    """pos[:m] = the positions in contacts[:k] of the contacts of order[:n_order] that
    take part, then those of the others by index (none: m = 0, the law's own order)."""
    if n_order == 0:
        return 0
    m = ZERO
    for j in range(n_order):
        for i in range(k):
            if contacts[i] == order[j] and not _named(pos, m, i):
                pos[m] = i
                m += 1
    for i in range(k):
        if not _named(pos, m, i):
            pos[m] = i
            m += 1
    return m


@hot
def _flat_leaving(model, k, u_post, vnoise):
    """Whether every contact of the ground took part and all leave at one speed u⁺ >
    vnoise (to FLAT_SPREAD relative), with 0 < γ < 1 and g > 0: a flat bounce."""
    if k != model.n_contacts or not (0.0 < model.gamma < 1.0 and model.gravity > 0.0):
        return False
    lo, hi = math.inf, -math.inf
    for i in range(k):
        lo, hi = min(lo, u_post[i]), max(hi, u_post[i])
    return lo > vnoise and hi - lo <= FLAT_SPREAD * hi


@hot
def _bounces_are_small(y, model, pts, opts, contacts, k, u_post, vnoise):
    """Whether 0 < γ < 1, some contact leaves and every one that does (u⁺ above the
    velocity roundoff) leaves below its chatter completion speed."""
    if not 0.0 < model.gamma < 1.0:
        return False
    leaving = False
    for i in range(k):
        if u_post[i] > vnoise:
            leaving = True
            small = completion_speed(y, model, pts, contacts[i], opts.chatter_tol, vnoise)
            if u_post[i] > small:
                return False
    return leaving


@hot
def complete_flat_bounces(state, model, opts, stats, out, u):
    """The flat bounces from the state just after a flat impact (every contact leaving
    at speed u⁺ = u) completed in closed form: flights 2u⁺γʲ/g
    summed, t_f = t + 2u⁺/(g(1 − γ)); the body lies at rest there, its horizontal
    drift and its spin about the vertical (which normal impulses do not change)
    carried on for t_f − t.  Ends the run STATUS_FLAT_REST at t_f."""
    y = state.y
    dt = 2.0 * u / (model.gravity * (1.0 - model.gamma))
    t0 = state.t_hi
    state.t_hi, state.t_lo = two_sum_add(state.t_hi, state.t_lo, dt)
    y[X] += y[VX] * dt
    y[Y] += y[VY] * dt
    r0, r1, r2, r3 = rotation_vector_quaternion(0.0, 0.0, y[WZ] * dt)
    y[QW], y[QX], y[QY], y[QZ] = qmul(r0, r1, r2, r3, y[QW], y[QX], y[QY], y[QZ])
    y[VZ] = 0.0
    y[WX] = 0.0
    y[WY] = 0.0
    stats.chatter_completions += 1
    push_accumulation(out, state.t_hi)
    push_sample(out, state.t_hi, state.t_lo, y, model, opts.max_samples)
    state.status = STATUS_FLAT_REST
    state.info_t = t0
    state.n_info = 0
    state.t_singularity = state.t_hi
