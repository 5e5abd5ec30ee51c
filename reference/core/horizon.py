"""How long a contact chunk may be: no free contact may reach the ground inside it, it
stays short against the local time scales, and a held force falling to zero is not
overshot by much (the lift-off is then located inside the chunk)."""

import math

from numba import njit

from .contacts import length_scale, velocity_scale
from .roots import safe_step
from .tolerances import (
    FORCE_TREND_FACTOR,
    HORIZON_ACC_FACTOR,
    LOCAL_TIME_FRACTION,
    ROTATION_TIME_FACTOR,
    TINY,
)


@njit(cache=True)
def chunk_horizon(y, model, gap, rate, accel, noise, held):
    """A chunk no free contact should reach the ground within (held[k]: contact k is
    held): the first root of max(P2, T2) of each free gap, P2 its quadratic lower bound
    with K = HORIZON_ACC_FACTOR max|g″| + g over the free contacts (a margin on their
    current second derivatives) and T2 its Taylor quadratic (not a bound: long chunks
    where the gaps curve away; a crossing it lets through is found after the chunk and
    located inside it, `phases.contact_step`), and at most LOCAL_TIME_FRACTION of
    min(√(L/K), ROTATION_TIME_FACTOR a/V)."""
    acc_scale = 0.0
    for k in range(gap.shape[0]):
        if not held[k]:
            acc_scale = max(acc_scale, abs(accel[k]))
    K = HORIZON_ACC_FACTOR * acc_scale + model.gravity + TINY
    h = math.inf
    for k in range(gap.shape[0]):
        if held[k]:
            continue
        d = safe_step(max(gap[k], noise[k]), rate[k], accel[k], K, 0.0, h)
        if d < h:
            h = d
    t_local = math.sqrt(max(length_scale(y, model.radius), TINY) / K)
    vs = velocity_scale(y, model.radius)
    if vs > 0:
        t_local = min(t_local, ROTATION_TIME_FACTOR * model.radius / vs)
    return min(h, LOCAL_TIME_FRACTION * t_local)


@njit(cache=True)
def force_trend_limit(h, lam, lam_prev, h_prev, m):
    """h shortened so that a held force falling at its rate over the previous chunk
    reaches zero only after FORCE_TREND_FACTOR × its current value / rate."""
    for i in range(m):
        r = (lam[i] - lam_prev[i]) / h_prev
        if r < 0 and lam[i] > 0:
            h = min(h, FORCE_TREND_FACTOR * lam[i] / -r)
    return h
