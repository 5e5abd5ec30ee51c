"""Instantaneous events of the loop: an impact (with the chatter completion and the
contacts it leaves held; several contacts at once under an impact law,
reference.core.law_event), an activation (contacts landing at rest start to be held),
and the start of the run.  Each returns False when it ended the run (state.status
set), True otherwise."""

from .chatter import accumulation_time, completion_speed
from .contacts import (
    contact_frame,
    contact_jet,
    contact_kind,
    normal_velocity,
    off_face,
    rate_noise,
    velocity_scale,
)
from .ending import end_run
from .floor import below_floor
from .held import held_acceleration, solve_lcp, zero_normal_velocities
from .impact import bounce_ratio, impact, pushed_contacts
from .inertia import excess_energy
from .jit import ONE, ZERO, copy_into, hot, sort_prefix
from .law_event import law_event
from .laws import LAW_PAPER
from .output import push_accumulation, push_impact, push_sample
from .records import (
    STATUS_AT_REST,
    STATUS_BELOW_FLOOR,
    STATUS_FAILED_LCP,
    STATUS_OFF_FACE,
    STATUS_PUSHED,
    STATUS_SIMULTANEOUS,
    STATUS_SINGULARITY,
)


@hot
def hold(state, model, pts, ws, cand, m):
    """Zero the normal velocities of cand[:m] and hold the contacts the LCP keeps.  More
    than three candidates are the body lying down: all of them are held (the loop then
    ends the motion)."""
    if m == 0:
        state.n_active = 0
        return True
    if m > 3:
        state.n_active = m
        for i in range(3):
            state.active[i] = cand[i]
        return True
    if not zero_normal_velocities(state.y, model, pts, cand, m, ws):
        end_run(state, STATUS_FAILED_LCP, cand, m)
        return False
    n = solve_lcp(state.y, model, pts, cand, m, ws, ws.active)
    if n < 0:
        end_run(state, STATUS_FAILED_LCP, cand, m)
        return False
    state.n_active = n
    for i in range(n):
        state.active[i] = ws.active[i]
    return True


@hot
def _completes(state, model, pts, ws, k, m, u, vnoise):
    """Whether contact k, separating at u ≤ the completion speed with cand[:m] held,
    falls back (a_n < 0) or is at rest: then its chatter is completed."""
    acc = held_acceleration(state.y, model, pts, ws.cand, m, ws)
    a_n = contact_jet(state.y, contact_kind(pts, k), pts, k, acc).accel
    return a_n < 0 or u <= vnoise, a_n


@hot
def _law_impact(state, model, pts, opts, stats, out, ws, cs, hitting, n_hit, resting, n_rest):
    """The impact of hitting[:n_hit] with resting[:n_rest] and every contact touching
    them, under the run's impact law (law_event)."""
    named = cs.near  # (free at an event; n long: the contacts named are distinct)
    m = ZERO
    for i in range(n_hit):
        named[m] = hitting[i]
        m += 1
    for i in range(n_rest):
        named[m] = resting[i]
        m += 1
    return law_event(state, model, pts, opts, stats, out, ws, cs, named, m)


@hot
def resolve_impact(state, model, pts, opts, stats, out, ws, cs, hitting, n_hit, resting, n_rest):
    """The impact of hitting[0] with resting[:n_rest] held (paper §2.3), then the
    contacts to hold: resting ones left at rest or separating slower than the completion
    speed, and the hit one if its chatter is completed."""
    y = state.y
    for i in range(n_hit):  # a bump beside the body: the model ends there
        if off_face(y, model, pts, hitting[i]):
            end_run(state, STATUS_OFF_FACE, hitting[i:], 1)
            return False
    if n_hit > 1:
        if model.law != LAW_PAPER:
            return _law_impact(state, model, pts, opts, stats, out, ws, cs, hitting, n_hit,
                               resting, n_rest)  # fmt: skip
        end_run(state, STATUS_SIMULTANEOUS, hitting, n_hit)
        return False
    k = hitting[0]
    stats.max_penetration = max(
        stats.max_penetration, -contact_frame(y, contact_kind(pts, k), pts, k).gap
    )
    vnoise = rate_noise(y, model.radius)
    copy_into(ws.y_start, y)
    out_imp = impact(y, model, pts, k)
    n_pushed = pushed_contacts(y, model, pts, resting, n_rest, vnoise, ws.before)
    if n_pushed > 0:
        copy_into(y, ws.y_start)
        if model.law != LAW_PAPER:
            return _law_impact(state, model, pts, opts, stats, out, ws, cs, hitting, ONE,
                               resting, n_rest)  # fmt: skip
        state.info_contact = k
        end_run(state, STATUS_PUSHED, ws.before, n_pushed)
        return False
    push_impact(out, state.t_hi, state.t_lo, k, out_imp.impulse, out_imp.u_pre, out_imp.u_post)
    small = completion_speed(y, model, pts, k, opts.chatter_tol, vnoise)
    m = ZERO
    vs = velocity_scale(y, model.radius)
    for i in range(n_rest):
        kind = contact_kind(pts, resting[i])
        vn = normal_velocity(y, contact_frame(y, kind, pts, resting[i]), kind)
        if vn <= small:
            ws.cand[m] = resting[i]
            m += 1
            if vn > vnoise:
                stats.max_completion_u_rel = max(stats.max_completion_u_rel, vn / vs)
    u = out_imp.u_post
    t_completed = -1.0  # accumulation time of the chatter completed here (none: < 0)
    if u <= vnoise and bounce_ratio(model.gamma) == 0.0:  # a plastic contact stays
        ws.cand[m] = k
        m += 1
    elif u <= small:
        completes, a_n = _completes(state, model, pts, ws, k, m, u, vnoise)
        if completes:
            stats.chatter_completions += 1
            stats.max_completion_u_rel = max(stats.max_completion_u_rel, u / vs)
            t_completed = accumulation_time(state.t_hi, u, a_n, model.gamma)
            push_accumulation(out, t_completed)
            ws.cand[m] = k
            m += 1
    if not hold(state, model, pts, ws, ws.cand, m):
        return False
    push_sample(out, state.t_hi, state.t_lo, y, model, opts.max_samples)
    if t_completed >= 0.0 and state.n_active >= model.all_down:
        # the completed chatter lays the body down: the motion ends at rest at its
        # accumulation time, not at the impact that began it
        end_run(state, STATUS_SINGULARITY, state.active, min(state.n_active, 3))
        state.t_singularity = t_completed
        return False
    return True


@hot
def activate(state, model, pts, ws, stats, landing, n_land):
    """Contacts landing at rest (touching, no approach speed, accelerating into the
    ground) start to be held with the held ones: zero their normal velocities (roundoff
    only) and solve the LCP over all of them; if it would keep only the ones already
    held (a roundoff tie), hold them all: the contact phase's force check releases any
    that pull."""
    m = ZERO
    for i in range(state.n_active):
        ws.cand[m] = state.active[i]
        m += 1
    for i in range(n_land):
        new = True
        for j in range(m):
            if ws.cand[j] == landing[i]:
                new = False
        if new and m < ws.cand.shape[0]:
            ws.cand[m] = landing[i]
            m += 1
    sort_prefix(ws.cand, m)
    n_held_before = state.n_active
    for i in range(n_held_before):
        ws.before[i] = state.active[i]
    stats.activations += 1
    if not hold(state, model, pts, ws, ws.cand, m):
        return False
    if _same_set(state.active, state.n_active, ws.before, n_held_before):
        state.n_active = m
        for i in range(m):
            state.active[i] = ws.cand[i]
    return True


@hot
def _same_set(a, na, b, nb):
    if na != nb:
        return False
    for i in range(na):
        found = False
        for j in range(nb):
            if a[i] == b[j]:
                found = True
        if not found:
            return False
    return True


@hot
def start(state, model, pts, opts, stats, out, ws, cs):
    """The run's first step: sample the initial state, then resolve contacts touching at
    t = 0 (hitting: an impact with the resting ones held; resting only: hold them).
    A state below the floor plane of a ground without rim contacts ends `left_model`.
    A body with every contact resting is already at the end of its motion."""
    y = state.y
    state.excess0 = excess_energy(
        y, model.invariants, model.mass, model.i1, model.i3, model.gravity
    )
    push_sample(out, state.t_hi, state.t_lo, y, model, opts.max_samples)
    if below_floor(y, model):  # (a state given below the floor plane: reference.core.floor)
        state.started = True
        end_run(state, STATUS_BELOW_FLOOR, cs.together, ZERO)
        return False
    state.started = True
    return resolve_touching(state, model, pts, opts, stats, out, ws, cs)


@hot
def resolve_touching(state, model, pts, opts, stats, out, ws, cs):
    """The contacts touching at the current time, with no contact held: those hitting
    are an impact with the resting ones held; resting only: hold them (all of them:
    the motion has ended).  The run's start, and the step after a law impact."""
    y = state.y
    state.recheck = False
    state.n_active = 0
    vnoise = rate_noise(y, model.radius)
    n_hit = n_rest = ZERO
    hitting, resting = cs.hitting, cs.together
    for k in range(pts.shape[0]):
        kind = contact_kind(pts, k)
        f = contact_frame(y, kind, pts, k)
        if f.gap > f.noise:
            continue
        vn = normal_velocity(y, f, kind)
        if vn < -vnoise:
            hitting[n_hit] = k
            n_hit += 1
        elif abs(vn) <= vnoise:
            resting[n_rest] = k
            n_rest += 1
    if n_hit:
        return resolve_impact(
            state, model, pts, opts, stats, out, ws, cs, hitting, n_hit, resting, n_rest
        )
    if n_rest >= model.all_down:
        end_run(state, STATUS_AT_REST, resting, n_rest)
        state.t_singularity = state.t_hi  # at rest from the start: the motion ended there
        return False
    for i in range(n_rest):
        ws.cand[i] = resting[i]
    return hold(state, model, pts, ws, ws.cand, n_rest)
