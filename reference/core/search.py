"""The next event of a free flight, never missed (conservative advancement).

Each step finds, for every contact that can bind it, the first root of the lower bound
max(P2, P3) of its gap (`roots.safe_step`) and advances the closed-form flight by the
smallest.  A contact is reached when its gap is within roundoff while approaching
faster than a graze could (an impact, its time then Newton-polished), or while at rest
and pressing into the ground (an activation: it starts to be held).  Contacts whose
zeros are within their time resolution of the first one's are reached together
(`collect_together`): the model cannot order them.

A ground's rim vertices (contacts 0 … n_rim − 1, kind RIM_VERTEX_ON_PLANE) are searched
as a family; its other contacts one by one.  Far from the ground, the circle through
the vertices bounds them all at once,
for any n (reference.core.rim: a step from the rim's jet, then its lowest point followed
in closed form down to two sags above the ground).  Nearer, large polygons (n > SMALL_N)
examine only the vertices that can touch within the step: a vertex's gap, rate and
acceleration are linear in its body-frame position a(cos θ, sin θ), so its quadratic
bound over a step δ is a sinusoid in θ and only an angular window around the lowest
direction can reach the ground within δ (`vertex_window`).  The cost per step does not
grow with n."""

import math

import numpy as np

from .contacts import (
    contact_jet,
    contact_kind,
    frame_and_rate,
    normal_acceleration,
    rate_noise,
    reached_together,
    rim_jet,
    time_resolution,
)
from .flight import bound_segment, flight_acceleration, flight_bounds, free_flight
from .jit import ZERO, copy_into, hot
from .layout import VZ, Z
from .records import (
    EVENT_ACTIVATION,
    EVENT_IMPACT,
    EVENT_NONE,
    EVENT_STUCK,
    FLOOR_POINT_ON_FACE,
    RIM_VERTEX_ON_PLANE,
    FlightEvent,
    Jet,
)
from .rim import circle_step, far_from_ground, lands_near, rim_descent, rim_step
from .roots import (
    p2_positive_at,
    quadratic_first_root,
    quadratic_taylor_root,
    safe_step,
    zero_bracket_end,
)
from .rotation import rotation_columns_xy
from .tolerances import (
    BRACKET_ITERATIONS,
    EPS,
    GRAZE_FACTOR,
    MIN_STEP_REL,
    POLISH_ITERATIONS,
    POLISH_REL_TOL,
    SEARCH_SHRINK,
    SEARCH_WINDOW_GROW,
    TINY,
)
from .window import use_window, vertex_window, window_offsets

# res[...] of `examine`: the smallest safe step and the contact that sets it, the
# earliest hit's time and contact, a contact landing at rest
STEP, STEP_K, HIT_DS, HIT_K, LAND_K = range(5)


@hot
def _safe_side_gap(gap, noise):
    """A touching contact's gap bounded from the safe side: max(g, 0) + its roundoff."""
    return max(gap, 0.0) + noise


@hot
def examine(y, acc, cols, kind, pts, k, K, B, vnoise, res):
    """Examine contact k at state y (cols: R's first two columns, formed once for all
    the contacts of a step): update res with its safe step, or record it as hit
    (touching and approaching faster than a graze) or landing (touching at rest,
    accelerating into the ground).  A contact clear of the ground whose P2 is still
    positive at the step found so far does not bind it (`roots.safe_step` would return
    that step): passed over before its acceleration is formed."""
    f, rate = frame_and_rate(y, cols, kind, pts, k)
    if f.gap > f.noise and p2_positive_at(f.gap, rate, K, res[STEP]):
        return
    j = Jet(f.gap, rate, normal_acceleration(y, f, acc, kind, pts, k), f.noise)
    g = j.gap
    if g <= j.noise:
        graze = GRAZE_FACTOR * math.sqrt(2.0 * max(j.accel, 0.0) * j.noise)
        if j.rate < -max(vnoise, graze):
            ds = -g / j.rate
            if ds < res[HIT_DS]:
                res[HIT_DS] = ds
                res[HIT_K] = k
            return
        if j.rate <= vnoise and j.accel < 0:
            res[LAND_K] = k
        g = _safe_side_gap(g, j.noise)  # touching, not approaching
    d = safe_step(g, j.rate, j.accel, K, B, res[STEP])
    if d < res[STEP]:
        res[STEP] = d
        res[STEP_K] = k


@hot
def next_index(k, n):
    """k + 1 mod n, for 0 ≤ k < n (a comparison, not a division)."""
    return k + 1 if k + 1 < n else 0


@hot
def likely_binding(y, jet, pts, n, K, first, count, radius, best_d):
    """The vertex of first … first + count − 1 (mod n) whose P2 has the first root, if
    before best_d (the step found so far; else `first`): the likeliest to bind the step.
    Gaps and rates from the rim jet (linear in the body direction, `contacts.rim_jet`):
    an ordering only, the examination is exact."""
    px, py, qx, qy, _, _ = jet
    inv_a = 1.0 / radius
    best = k = first % n
    for _ in range(count):
        cx, cy = pts[k, 0] * inv_a, pts[k, 1] * inv_a
        g = max(y[Z] + cx * px + cy * py, TINY)
        g1 = y[VZ] + cx * qx + cy * qy
        if not p2_positive_at(g, g1, K, best_d):  # (else it cannot come first)
            d = quadratic_first_root(g, g1, K)
            if d < best_d:
                best, best_d = k, d
        k = next_index(k, n)
    return best


@hot
def examine_range(y, acc, jet, pts, n, K, B, first, count, vnoise, res, radius):
    """Examine vertices first … first + count − 1 (mod n, count ≤ n), the likeliest to
    bind the step first (`likely_binding`): its step, found early, spares the others
    their cubic (`roots.safe_step` solves it only when it would shorten the step)."""
    if count <= 0:
        return
    cols = rotation_columns_xy(y)
    lead = likely_binding(y, jet, pts, n, K, first, count, radius, res[STEP])
    examine(y, acc, cols, RIM_VERTEX_ON_PLANE, pts, lead, K, B, vnoise, res)
    k = first % n
    for _ in range(count):
        if k != lead:
            examine(y, acc, cols, RIM_VERTEX_ON_PLANE, pts, k, K, B, vnoise, res)
        k = next_index(k, n)


@hot
def examine_window(y, acc, jet, pts, n, K, B, k0, half, vnoise, res, radius):
    """Examine vertices k0 − half … k0 + half (mod n, each once)."""
    examine_range(y, acc, jet, pts, n, K, B, k0 - half, min(2 * half + 1, n), vnoise, res, radius)


@hot
def near_vertices_step(y, acc, jet, pts, radius, n, K, B, left, last_dlt, vnoise, res):
    """Examine the vertices near the lowest direction into res and return the cap on the
    step they certify (inf when none is needed).  The vertices that can be at the
    ground now (window(0), two more on each side) come first; the step δ they allow
    holds for the others if those outside window(δ) are safe by P2 and those inside have
    been examined: at most SEARCH_WINDOW_GROW more are, δ being shortened by
    SEARCH_SHRINK (from 4× the last certified step) until that suffices."""
    k0, h = vertex_window(y, radius, n, K, 0.0, np.int64(2), 0.0)
    examine_window(y, acc, jet, pts, n, K, B, k0, h, vnoise, res, radius)
    if res[HIT_K] >= 0 or res[LAND_K] >= 0 or 2 * h + 1 >= n:
        return math.inf
    dlt = min(res[STEP], left, 4.0 * last_dlt)
    while True:
        lo1, hi1 = window_offsets(y, radius, n, K, dlt, np.int64(3), k0)
        if hi1 - lo1 + 1 < n and max(hi1 - h, 0) + max(-h - lo1, 0) <= SEARCH_WINDOW_GROW:
            break
        dlt *= SEARCH_SHRINK
    examine_range(y, acc, jet, pts, n, K, B, k0 + h + 1, hi1 - h, vnoise, res, radius)
    examine_range(y, acc, jet, pts, n, K, B, k0 + lo1, -h - lo1, vnoise, res, radius)
    return dlt


@hot
def _search_step(y, fc, acc, model, pts, bounds, vnoise, windowed, left, last_dlt, res):
    """One iteration's certified step (res holds hits and landings): the ground's
    contacts other than rim vertices one by one (every contact of a ground without rim
    vertices), then its rim vertices as a family: far from the ground, the circle
    through them (its step from the rim's jet, then `rim.rim_descent`), else every
    vertex for small n, or the vertices near the lowest direction; the shorter step of
    the two kept (`_shorter`).  Returns (step, last certified window step)."""
    n, n_rim = pts.shape[0], model.n_rim
    K, B = bounds.K, bounds.B
    res[STEP], res[STEP_K], res[HIT_DS], res[HIT_K], res[LAND_K] = (
        math.inf,
        -1.0,
        math.inf,
        -1.0,
        -1.0,
    )
    other, other_k = math.inf, -1.0
    if n_rim < n:
        cols = rotation_columns_xy(y)  # (unused by a floor point's frame)
        for k in range(n_rim, n):  # the floor points, after the rim vertices: their
            # kind as a constant keeps `examine` inlined for it (docs/performance.md,
            # "Event search"); GroundContacts lists each kind in one range
            examine(y, acc, cols, FLOOR_POINT_ON_FACE, pts, k, K, B, vnoise, res)
        if n_rim == 0:
            return res[STEP], last_dlt
        other, other_k = res[STEP], res[STEP_K]
        res[STEP], res[STEP_K] = math.inf, -1.0
    jet = rim_jet(y, acc, model.radius)  # shared by the circle step and the orderings
    rim = rim_step(y, model.gravity, bounds.depth, model.radius)
    if far_from_ground(y, jet, model):
        d_c = max(circle_step(y, jet, model.gravity, B), rim)
        if not lands_near(jet, B, d_c, model):
            d_c = rim_descent(y, fc, model, bounds.depth, left, d_c)
        return _shorter(d_c, other, other_k, res), last_dlt
    if not windowed:
        examine_range(y, acc, jet, pts, n_rim, K, B, ZERO, n_rim, vnoise, res, model.radius)
        return _shorter(max(res[STEP], rim), other, other_k, res), last_dlt
    cap = near_vertices_step(
        y, acc, jet, pts, model.radius, n_rim, K, B, left, last_dlt, vnoise, res
    )
    if cap < math.inf:
        last_dlt = cap
    return _shorter(max(min(res[STEP], cap), rim), other, other_k, res), last_dlt


@hot
def _shorter(step, other, other_k, res):
    """The shorter of the rim vertices' step and the other contacts' (`other`, set by
    contact other_k; inf when the ground has none), res[STEP] and res[STEP_K] those of
    the other contact when it sets it (the rim's step may exceed its examined vertices'
    by `rim.rim_step`, which bounds the rim vertices alone)."""
    if other < step:
        res[STEP], res[STEP_K] = other, other_k
        return other
    return step


@hot
def _others_safe_time(y, acc, model, pts, k, end, floor, K, B, windowed, vnoise):
    """How long every contact but k certainly stays above the ground, up to end: the
    least root of their lower bounds max(P2, P3) (`roots.safe_step`); a touching
    contact moving away faster than the rate noise counts from the safe side as
    `examine` bounds it (`_safe_side_gap`), any other touching contact gives 0.  Once
    that time is at most `floor` (where the caller has no use for it) it is returned
    without examining the rest.  With the window search only the vertices of
    window(end) are examined: the others are safe over [0, end] by P2
    (`vertex_window`)."""
    n = pts.shape[0]
    first, half = 0, n // 2
    if windowed:
        first, half = vertex_window(y, model.radius, n, K, end, np.int64(3), 0.0)
    t = end
    cols = rotation_columns_xy(y)
    nxt = (first - half) % n
    for _ in range(min(2 * half + 1, n)):
        nxt, j = next_index(nxt, n), nxt
        if j == k:
            continue
        kind = contact_kind(pts, j)
        f, rate = frame_and_rate(y, cols, kind, pts, j)
        g = f.gap
        if g <= f.noise:
            if not rate > vnoise:
                return 0.0
            g = _safe_side_gap(g, f.noise)
        if p2_positive_at(g, rate, K, t):
            continue  # safe_step would return t: its acceleration is not needed
        t = min(t, safe_step(g, rate, normal_acceleration(y, f, acc, kind, pts, j), K, B, t))
        if not t > floor:
            return t
    return t


@hot
def _newton_in_bracket(y0, fc, gravity, kind, pts, k, lo, hi, x, y):
    """Contact k's single zero in [lo, hi] (gap > 0 at lo, ≤ 0 at hi, decreasing):
    Newton steps from x in the bracket kept strictly inside the shrinking bracket
    (bisection otherwise), until
    a step or the bracket is within two ulps; y ends at the zero, which is returned.
    Near the zero the computed gap is roundoff, and a Newton step from one end of the
    bracket can land on the other: evaluated again, it would send the next step back
    (observed on the grazing-contact scene: 60 evaluations alternating between two times
    6 ulps apart, the cap), so a step onto a bracket end bisects instead."""
    for _ in range(BRACKET_ITERATIONS):
        free_flight(y0, fc, gravity, x, y)
        j = contact_jet(y, kind, pts, k, flight_acceleration(fc, y, gravity))
        if j.gap > 0.0:
            lo = x
        else:
            hi = x
        nxt = x - j.gap / j.rate if j.rate < 0.0 else 0.5 * (lo + hi)
        if not (lo < nxt < hi or nxt == x):  # (x is now lo or hi: nxt == x, converged)
            nxt = 0.5 * (lo + hi)
        if abs(nxt - x) <= 2.0 * EPS * abs(x) or hi - lo <= 2.0 * EPS * hi:
            return x  # converged to the last bits: y is the state at x
        x = nxt
    free_flight(y0, fc, gravity, x, y)
    return x


@hot
def bracketed_zero(y0, fc, bounds, model, pts, s, step, horizon, acc, vnoise, windowed, res, y):
    """The shortcut of a transversal approach: when the contact that sets the step
    (res[STEP_K]) is approaching with its first zero bracketed in [step, end]
    (roots.zero_bracket_end) and every other contact is safe until that zero
    (`_others_safe_time`: neighbours of a polygon rolling down reach the ground just
    after it, and their bounds may reach end), the zero is the flight's next event:
    returns its time with y there (the impact test of `examine` holds there), or −1
    when the shortcut does not apply (y then undefined)."""
    k = int(res[STEP_K])
    kind = contact_kind(pts, k)
    j = contact_jet(y, kind, pts, k, acc)
    if j.gap <= j.noise:
        return -1.0
    K, B = bounds.K, bounds.B
    end = zero_bracket_end(j.gap, j.rate, j.accel, K, B)
    if not s + end < horizon:
        return -1.0
    safe = _others_safe_time(y, acc, model, pts, k, end, step, K, B, windowed, vnoise)
    taylor = quadratic_taylor_root(j.gap, j.rate, j.accel)  # an estimate of the zero
    if not safe > step or (safe < end and safe < taylor):
        return -1.0  # (Newton would be in vain)
    # Newton starts at the Taylor root (one evaluation fewer than from the bracket's safe
    # end on a spinning 100-gon), or at that end when the root is within the gap's
    # roundoff of it (steps from inside would follow roundoff: 20 evaluations on tiny
    # flights of a chatter)
    x0 = min(max(taylor, step), end)
    if (x0 - step) * abs(j.rate) <= j.noise:
        x0 = step
    x = _newton_in_bracket(y0, fc, model.gravity, kind, pts, k, s + step, s + end, s + x0, y)
    if safe < end and x - s > safe:
        return -1.0
    jr = contact_jet(y, kind, pts, k, flight_acceleration(fc, y, model.gravity))
    graze = GRAZE_FACTOR * math.sqrt(2.0 * max(jr.accel, 0.0) * jr.noise)
    if jr.gap <= jr.noise and jr.rate < -max(vnoise, graze):
        return x
    return -1.0


@hot
def polish_impact(y0, fc, gravity, kind, pts, k, s_hit, y):
    """Newton steps on contact k's gap from s_hit; y ends at the polished time, which is
    returned."""
    free_flight(y0, fc, gravity, s_hit, y)
    for _ in range(POLISH_ITERATIONS):
        acc = flight_acceleration(fc, y, gravity)
        j = contact_jet(y, kind, pts, k, acc)
        corr = -j.gap / j.rate
        if not math.isfinite(corr) or abs(corr) <= POLISH_REL_TOL * max(abs(s_hit), TINY):
            break
        s_hit += corr
        free_flight(y0, fc, gravity, s_hit, y)
    return s_hit


@hot
def _candidates(y, model, pts, bounds, windowed):
    """The contacts that can be at the ground now: (first, half) of an index range
    around the lowest direction, every contact when half = n // 2."""
    n = pts.shape[0]
    if windowed:
        return vertex_window(y, model.radius, n, bounds.K, 0.0, np.int64(3), 0.0)
    return 0, n // 2


@hot
def collect_together(y, model, pts, bounds, windowed, k0, vnoise, together):
    """Contacts reached with k0 at state y (k0 first): approaching, with a zero within
    SIMULTANEOUS_FACTOR × (their time resolution + k0's).  Returns how many."""
    cols = rotation_columns_xy(y)
    f0, rate0 = frame_and_rate(y, cols, contact_kind(pts, k0), pts, k0)
    tres0 = time_resolution(f0.noise, rate0)
    together[0] = k0
    count = 1
    n = pts.shape[0]
    first, half = _candidates(y, model, pts, bounds, windowed)
    nxt = (first - half) % n
    for _ in range(min(2 * half + 1, n)):
        nxt, k = next_index(nxt, n), nxt
        if k == k0:
            continue
        f, rate = frame_and_rate(y, cols, contact_kind(pts, k), pts, k)
        if rate >= -vnoise:
            continue
        if reached_together(f.gap, rate, f.noise, tres0, rate0, model.window_per_speed):
            together[count] = k
            count += 1
    return count


@hot
def collect_landing(y, acc, model, pts, bounds, windowed, vnoise, together):
    """Contacts touching at rest and accelerating into the ground at state y."""
    count = ZERO
    n = pts.shape[0]
    first, half = _candidates(y, model, pts, bounds, windowed)
    nxt = (first - half) % n
    for _ in range(min(2 * half + 1, n)):
        nxt, k = next_index(nxt, n), nxt
        j = contact_jet(y, contact_kind(pts, k), pts, k, acc)
        if j.gap <= j.noise and j.rate <= vnoise and j.accel < 0:
            together[count] = k
            count += 1
    return count


@hot
def flight_event(y0, fc, model, pts, window_search, horizon, max_iter, y, together, res):
    """The first event of the free flight from y0 within `horizon`, searched segment by
    segment: each with the bounds (`flight.flight_bounds`) of its own length from the
    state at its start (`flight.bound_segment`: the whole horizon on a ground of rim vertices, whose
    bounds hold for ever; on the three-point ground bounds over the whole horizon would
    grow with its square and cube).  FlightEvent as `find_flight_event`, its iterations
    summed over the segments."""
    s0 = 0.0
    iterations = 0
    copy_into(y, y0)  # the state at s0 (find_flight_event leaves y at its segment's end)
    while True:
        end = min(horizon, s0 + bound_segment(y, model, pts))
        bounds = flight_bounds(y, fc, model, pts, end - s0)
        ev = find_flight_event(
            y0, fc, bounds, model, pts, window_search, s0, end, max_iter, y, together, res
        )
        iterations += ev.iterations
        if ev.kind != EVENT_NONE or not end < horizon:
            return FlightEvent(ev.kind, ev.s, ev.contact, ev.n_together, iterations)
        s0 = end


@hot
def find_flight_event(
    y0, fc, bounds, model, pts, window_search, s_start, horizon, max_iter, y, together, res
):
    """The first event of the free flight from y0 in (s_start, horizon] (bounds valid
    there; y holds the state at s_start on entry): FlightEvent with y at its time (at
    the horizon when there is none) and the contacts reached in together[:n_together]
    (res: 5 floats of scratch)."""
    g = model.gravity
    windowed = use_window(model, window_search)
    s = s_start
    vnoise = rate_noise(y0, model.radius)  # of the flight's state: |ω| is constant
    last_dlt = math.inf
    for it in range(max_iter):
        acc = flight_acceleration(fc, y, g)
        step, last_dlt = _search_step(
            y, fc, acc, model, pts, bounds, vnoise, windowed, horizon - s, last_dlt, res
        )
        if res[HIT_K] >= 0:
            k = int(res[HIT_K])
            kind = contact_kind(pts, k)
            s = polish_impact(y0, fc, g, kind, pts, k, s + res[HIT_DS], y)
            m = collect_together(y, model, pts, bounds, windowed, k, vnoise, together)
            return FlightEvent(EVENT_IMPACT, s, k, m, it)
        if res[LAND_K] >= 0:
            m = collect_landing(y, acc, model, pts, bounds, windowed, vnoise, together)
            return FlightEvent(EVENT_ACTIVATION, s, together[0], m, it)
        if res[STEP_K] >= 0 and res[STEP] == step:
            s_root = bracketed_zero(
                y0, fc, bounds, model, pts, s, step, horizon, acc, vnoise, windowed, res, y
            )
            if s_root >= 0.0:
                k = int(res[STEP_K])
                m = collect_together(y, model, pts, bounds, windowed, k, vnoise, together)
                return FlightEvent(EVENT_IMPACT, s_root, k, m, it)
            free_flight(y0, fc, g, s, y)
        step = max(step, MIN_STEP_REL * max(s, TINY))
        if s + step >= horizon:
            free_flight(y0, fc, g, horizon, y)
            return FlightEvent(EVENT_NONE, horizon, -1, 0, it)
        s += step
        free_flight(y0, fc, g, s, y)
    return FlightEvent(EVENT_STUCK, s, -1, 0, max_iter)
