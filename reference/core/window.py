"""Vertex windows of large polygons: the rim vertices (contact kind
RIM_VERTEX_ON_PLANE) near the ground.

A vertex's gap, rate and acceleration are linear in its body direction c = (cos θ,
sin θ): g = z + a c·u with u = (R20, R21).  So its quadratic lower bound over a step δ,
P2 = g + g′δ − Kδ²/2, is a sinusoid in θ, and only an angular window around the lowest
direction can reach the ground within δ: the flight search (reference.core.search) and
the contact phases (reference.core.candidates) examine those vertices only, at a cost
that does not grow with n."""

import math

from .jit import hot
from .layout import VZ, WX, WY, Z
from .rotation import rotation_columns_xy
from .tolerances import ANGLE_ERROR, SMALL_N

_TAN_PI_12 = 2.0 - math.sqrt(3.0)
_SQRT3 = math.sqrt(3.0)


@hot
def use_window(model, window_search):
    """Whether only the rim vertices near the lowest direction are examined: a ground
    of more than SMALL_N rim vertices (model.n_rim) and no other contacts (the windows
    index the rim vertices alone), unless the window search is turned off."""
    return window_search and model.n_rim > SMALL_N and model.n_rim == model.n_contacts


@hot
def vertex_window(y, radius, n, K, delta, margin, lift):
    """The vertices whose P2 can come within `lift` of the ground within δ (the others
    are safe by P2): the index range k0 − half … k0 + half (mod n) around the lowest
    direction, `margin` more on each side; O(1).

    P2 of vertex k at δ is Z(δ) + a c_k·u(δ) with c_k = (cos θ_k, sin θ_k),
    Z = z + v_z δ − Kδ²/2 and u = (R20, R21) + δ (ω × R)'s z row: a vertex's height and
    rate are linear in its body position.  P2 is concave in δ, so vertex k stays above
    `lift` over [0, δ] when a|u| cos(θ_k − ∠u) > lift − Z: outside an arc of half-width
    π − acos((lift − Z)/(a|u|)) around ∠u + π (∠u to ANGLE_ERROR, `direction_angle`,
    which the half-width takes in).  half = n // 2 means every vertex."""
    R00, R01, R10, R11, R20, R21 = rotation_columns_xy(y)
    A = y[WX] * R10 - y[WY] * R00
    Bq = y[WX] * R11 - y[WY] * R01
    ux, uy = R20 + A * delta, R21 + Bq * delta
    U = math.sqrt(ux * ux + uy * uy)
    Zd = y[Z] + y[VZ] * delta - 0.5 * K * delta * delta - lift
    dth = 2.0 * math.pi / n
    centre = direction_angle(ux, uy) + math.pi
    if radius * U <= 0.0 or -Zd / (radius * U) <= -1.0:
        half = 0
    else:
        c = -Zd / (radius * U)
        W = math.pi if c >= 1.0 else math.pi - math.acos(c)
        half = int(math.ceil((W + ANGLE_ERROR) / dth))
    half = min(half + margin, n // 2)
    return int(math.floor(centre / dth + 0.5)), half


@hot
def direction_angle(x, y):
    """atan2(y, x) to within ANGLE_ERROR (libm's atan2 costs ~110 instructions; this
    ~40): the octant's ratio t = min/max ∈ [0, 1], above tan(π/12) brought below it by
    atan t = π/6 + atan((√3 t − 1)/(t + √3)), then atan's series to t¹³, whose
    remainder is below t¹⁵/15 ≤ 2e-10 (alternating).  0 at the origin."""
    ax, ay = abs(x), abs(y)
    big, small = max(ax, ay), min(ax, ay)
    if not big > 0.0:
        return 0.0
    t = small / big
    base = 0.0
    if t > _TAN_PI_12:
        t = (_SQRT3 * t - 1.0) / (t + _SQRT3)
        base = math.pi / 6.0
    t2 = t * t
    poly = 1.0 / 13.0
    for c in (-1.0 / 11.0, 1.0 / 9.0, -1.0 / 7.0, 1.0 / 5.0, -1.0 / 3.0, 1.0):
        poly = c + t2 * poly
    angle = base + t * poly
    if ay > ax:
        angle = 0.5 * math.pi - angle
    if x < 0.0:
        angle = math.pi - angle
    return -angle if y < 0.0 else angle


@hot
def window_offsets(y, radius, n, K, delta, margin, k0):
    """vertex_window(δ) as offsets (lo, hi) from vertex k0 (in (−n/2, n/2])."""
    k1, h1 = vertex_window(y, radius, n, K, delta, margin, 0.0)
    d = (k1 - k0) % n
    if d > n // 2:
        d -= n
    return d - h1, d + h1
