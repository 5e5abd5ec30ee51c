"""When a chatter sequence (0 < γ < 1: impacts accumulating at a finite time) is
completed instead of resolved one impact at a time.

After an impact whose post-impact normal velocity u is below `completion_speed` while
the contact point falls back (normal acceleration a_n < 0 with the other contacts
held), the remaining infinite sequence is completed: u is removed by a normal impulse
and the contact is held.  The exact sequence accumulates at t + 2u/(|a_n|(1 − γ))
(`accumulation_time`) and delivers, to leading order, the same total impulse, only
spread over that window, so the completion changes the state at the accumulation time
by O((u/V)²) relative: chatter_tol² = 1e-12 for the default chatter_tol = 1e-6."""

import math

from .contacts import contact_frame, contact_kind, velocity_scale
from .impact import bounce_ratio
from .jit import hot
from .layout import WX, WY, WZ
from .tolerances import CHATTER_BOUNCE_FLOOR, TINY


@hot
def completion_speed(y, model, pts, k, chatter_tol, vnoise):
    """u below which a separation of contact k (just hit) is completed: chatter_tol × V,
    and at least CHATTER_BOUNCE_FLOOR √(2 |a| noise) (a bounce lower than 1e4 roundoff
    bands of its gap, |a| = g + a|ω|², cannot be resolved); for γ = 1 only the roundoff
    level vnoise (an elastic contact never accumulates impacts)."""
    if bounce_ratio(model.gamma) >= 1.0:
        return vnoise
    small = chatter_tol * velocity_scale(y, model.radius)
    noise = contact_frame(y, contact_kind(pts, k), pts, k).noise
    a_scale = model.gravity + model.radius * (y[WX] ** 2 + y[WY] ** 2 + y[WZ] ** 2)
    return max(small, CHATTER_BOUNCE_FLOOR * math.sqrt(2.0 * a_scale * noise), vnoise)


@hot
def accumulation_time(t, u, a_n, gamma):
    """When the bounces of speed u under normal acceleration a_n < 0 accumulate:
    t + 2u / (|a_n| (1 − r)) with r = bounce_ratio(γ) (a bouncing ball: the flight
    times 2u rᵏ/|a_n| summed)."""
    r = bounce_ratio(gamma)
    return t + 2.0 * max(u, 0.0) / (max(-a_n, TINY) * (1.0 - r))
