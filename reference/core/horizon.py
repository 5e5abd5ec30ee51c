"""How long a contact chunk may be: no free contact may reach the ground inside it, it
stays short against the local time scales, and a held force falling to zero is not
overshot by much (the lift-off is then located inside the chunk)."""

import math

from .contacts import length_rate, length_scale, velocity_scale
from .jit import hot
from .roots import safe_step
from .tolerances import (
    FORCE_TREND_FACTOR,
    HORIZON_ACC_FACTOR,
    LOCAL_TIME_FRACTION,
    ROTATION_TIME_FACTOR,
    TINY,
)


@hot
def horizon_bound(acc_scale, gravity):
    """K = HORIZON_ACC_FACTOR × (a scale of |g″|) + g: the curvature the chunk horizon
    allows a free gap (a margin on its current second derivative, not a bound)."""
    return HORIZON_ACC_FACTOR * acc_scale + gravity + TINY


@hot
def local_time_cap(y, model, K):
    """LOCAL_TIME_FRACTION of min(√(L_reach/K), ROTATION_TIME_FACTOR a/V): a chunk stays
    short against the time the body takes to fall the extent it may reach,
    L_reach = L + U²/(2K) (its size now, `length_scale`, and the rise its rate U =
    `length_rate` carries it against K), and the time the rim takes to move its radius.
    The rise keeps the time scale when L passes through zero with the body moving (a
    disk passing flat over the three bumps at an impact beside two held ones)."""
    u = length_rate(y, model.radius)
    reach = length_scale(y, model.radius) + 0.5 * u * u / K
    t_local = math.sqrt(max(reach, TINY) / K)
    vs = velocity_scale(y, model.radius)
    if vs > 0:
        t_local = min(t_local, ROTATION_TIME_FACTOR * model.radius / vs)
    return LOCAL_TIME_FRACTION * t_local


@hot
def safe_horizon(cs, i0, i1, K, h):
    """h shortened to the first root of max(P2, T2) of each examined free gap
    cs.cand[i0:i1] (jets in cs): P2 its quadratic lower bound with curvature K, T2 its
    Taylor quadratic (not a bound: long chunks where the gaps curve away; a crossing it
    lets through is found after the chunk and located inside it,
    `phases.contact_step`)."""
    for i in range(i0, i1):
        d = safe_step(max(cs.gap[i], cs.noise[i]), cs.rate[i], cs.accel[i], K, 0.0, h)
        if d < h:
            h = d
    return h


@hot
def force_trend_limit(h, lam, lam_prev, h_prev, m):
    """h shortened so that a held force falling at its rate over the previous chunk
    reaches zero only after FORCE_TREND_FACTOR × its current value / rate."""
    for i in range(m):
        r = (lam[i] - lam_prev[i]) / h_prev
        if r < 0 and lam[i] > 0:
            h = min(h, FORCE_TREND_FACTOR * lam[i] / -r)
    return h
