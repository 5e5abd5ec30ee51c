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
    """Largest safe chunk from the free contacts' jets (held[k]: contact k is held).

    Quadratic lower bound with K = HORIZON_ACC_FACTOR max|g″| + g over the free
    contacts (a margin on their current second derivatives), and at most
    LOCAL_TIME_FRACTION of min(√(L/K), ROTATION_TIME_FACTOR a/V)."""
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
