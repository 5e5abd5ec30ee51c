"""Compiled (numba) event search for free flight over flat ground: the hot loop.

Same mathematics as `reference.events.next_flight_event` (closed-form flight of
`reference.flight`, the lower bounds P2/P3 of `reference.events`, Newton polishing),
written in scalar form so numba can compile it.  The Python version stays the readable
specification; tests/test_reference_kernel.py checks that both find the same events.

Only the vertices that can touch next are examined (n > 32): a vertex's gap, rate and
acceleration are linear in its body-frame position a(cos θ, sin θ), so the quadratic
lower bound over a step δ is a sinusoid in θ and only an angular window around its
minimum can reach the ground within δ (`_window`).  The cost per step grows with the
number of vertices in that window, not with n.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

EPS = 2.220446049250313e-16


@njit(cache=True)
def _qmul(a0, a1, a2, a3, b0, b1, b2, b3):
    return (
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    )


@njit(cache=True)
def rotation_xy(y):
    """The first two columns of R (body → world) of state y: (R00, R01, R10, R11, R20,
    R21), the z row from the small quaternion terms directly."""
    w, x, yq, z = y[3], y[4], y[5], y[6]
    return (
        1 - 2 * (yq * yq + z * z),
        2 * (x * yq - w * z),
        2 * (x * yq + w * z),
        1 - 2 * (x * x + z * z),
        2 * (x * z - w * yq),
        2 * (yq * z + w * x),
    )


@njit(cache=True)
def free_angular_acceleration(y, i1, i3):
    """ω̇ without contact forces, −I⁻¹(ω × Iω) for the axisymmetric body, and the body
    axis e3: (ω̇x, ω̇y, ω̇z, e3x, e3y, e3z)."""
    w, x, yq, z = y[3], y[4], y[5], y[6]
    e3x = 2 * (x * z + w * yq)
    e3y = 2 * (yq * z - w * x)
    e3z = 1 - 2 * (x * x + yq * yq)
    wx, wy, wz = y[10], y[11], y[12]
    w3 = wx * e3x + wy * e3y + wz * e3z
    Lx = i1 * wx + (i3 - i1) * w3 * e3x
    Ly = i1 * wy + (i3 - i1) * w3 * e3y
    Lz = i1 * wz + (i3 - i1) * w3 * e3z
    gx = wy * Lz - wz * Ly
    gy = wz * Lx - wx * Lz
    gz = wx * Ly - wy * Lx
    f = 1.0 / i3 - 1.0 / i1
    eg = e3x * gx + e3y * gy + e3z * gz
    return (
        -(gx / i1 + f * eg * e3x),
        -(gy / i1 + f * eg * e3y),
        -(gz / i1 + f * eg * e3z),
        e3x,
        e3y,
        e3z,
    )


@njit(cache=True)
def flight_state(y0, LA, lam, g, s, out):
    """Closed-form free flight (reference.flight.free_flight) into `out`."""
    out[0] = y0[0] + y0[7] * s
    out[1] = y0[1] + y0[8] * s
    out[2] = y0[2] + y0[9] * s - 0.5 * g * s * s
    out[7] = y0[7]
    out[8] = y0[8]
    out[9] = y0[9] - g * s
    px, py, pz = LA[0] * s, LA[1] * s, LA[2] * s
    th = math.sqrt(px * px + py * py + pz * pz)
    if th < 1e-4:
        t2 = th * th
        hs = 0.5 - t2 / 48.0 + t2 * t2 / 3840.0
    else:
        hs = math.sin(0.5 * th) / th
    c = math.cos(0.5 * th)
    a = _qmul(c, hs * px, hs * py, hs * pz, y0[3], y0[4], y0[5], y0[6])
    half = 0.5 * lam * s
    b = _qmul(a[0], a[1], a[2], a[3], math.cos(half), 0.0, 0.0, math.sin(half))
    nrm = math.sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3])
    w, x, y, z = b[0] / nrm, b[1] / nrm, b[2] / nrm, b[3] / nrm
    out[3], out[4], out[5], out[6] = w, x, y, z
    e3x = 2 * (x * z + w * y)
    e3y = 2 * (y * z - w * x)
    e3z = 1 - 2 * (x * x + y * y)
    out[10] = LA[0] + lam * e3x
    out[11] = LA[1] + lam * e3y
    out[12] = LA[2] + lam * e3z


@njit(cache=True)
def vertex_jet(y, LA, lam, g, px, py):
    """Gap, rate, acceleration and roundoff of the vertex at body (px, py, 0)."""
    w, x, yq, z = y[3], y[4], y[5], y[6]
    rx = (1 - 2 * (yq * yq + z * z)) * px + 2 * (x * yq - w * z) * py
    ry = 2 * (x * yq + w * z) * px + (1 - 2 * (x * x + z * z)) * py
    rz = 2 * (x * z - w * yq) * px + 2 * (yq * z + w * x) * py
    wx, wy, wz = y[10], y[11], y[12]
    gap = y[2] + rz
    rate = y[9] + (wx * ry - wy * rx)
    e3x = 2 * (x * z + w * yq)
    e3y = 2 * (yq * z - w * x)
    e3z = 1 - 2 * (x * x + yq * yq)
    # ω̇ = λ (L/A) × e3
    ax = lam * (LA[1] * e3z - LA[2] * e3y)
    ay = lam * (LA[2] * e3x - LA[0] * e3z)
    # (ω̇ × r)_z + (ω × (ω × r))_z = ax ry − ay rx + (ω·r) ω_z − |ω|² r_z
    acc = (
        -g
        + (ax * ry - ay * rx)
        + (wx * rx + wy * ry + wz * rz) * wz
        - (wx * wx + wy * wy + wz * wz) * rz
    )
    noise = 8 * EPS * (abs(y[2]) + abs(rz))
    return gap, rate, acc, noise


@njit(cache=True)
def _cubic(c0, c1, c2, c3):
    """First positive root of c0 + c1 d + c2 d² + c3 d³ (c0 > 0, c3 ≤ 0), 1e-3 relative."""
    a, b, c = 3.0 * c3, 2.0 * c2, c1
    # critical points of the cubic, sorted (scalars: no allocation in the hot loop)
    m = 0
    cr0, cr1 = 0.0, 0.0
    if a == 0.0:
        if b != 0.0:
            cr0 = -c / b
            m = 1
    else:
        disc = b * b - 4 * a * c
        if disc >= 0:
            sq = math.sqrt(disc)
            qq = -0.5 * (b + math.copysign(sq, b))
            if qq != 0:
                cr0, cr1 = qq / a, c / qq
                m = 2
    if m == 2 and cr1 < cr0:
        cr0, cr1 = cr1, cr0
    lo = 0.0
    for i in range(m + 1):
        if i < m:
            hi = cr0 if i == 0 else cr1
            if hi <= lo:
                continue
        else:
            if c3 < 0 or (c3 == 0 and (c2 < 0 or (c2 == 0 and c1 < 0))):
                hi = max(lo, 1.0)
                while c0 + hi * (c1 + hi * (c2 + hi * c3)) > 0:
                    hi *= 2.0
                    if hi > 1e300:
                        return math.inf
            else:
                return math.inf
        if c0 + hi * (c1 + hi * (c2 + hi * c3)) <= 0.0:
            # the cubic is monotone on [lo, hi] and changes sign: safeguarded Newton.
            # Newton approaches a root from one side only, so once its step is below
            # the tolerance it is pushed a little past the root: the bracket closes.
            x = 0.5 * (lo + hi)
            for _ in range(200):
                f = c0 + x * (c1 + x * (c2 + x * c3))
                if f > 0.0:
                    lo = x
                else:
                    hi = x
                tol = 1e-3 * hi
                if hi - lo <= tol:
                    break
                d = c1 + x * (2.0 * c2 + 3.0 * x * c3)
                nxt = x - f / d if d != 0.0 else 0.5 * (lo + hi)
                if abs(nxt - x) < 0.25 * tol:
                    nxt += math.copysign(0.25 * tol, nxt - x)
                if not lo < nxt < hi:
                    nxt = 0.5 * (lo + hi)
                x = nxt
            return lo
        lo = hi
    return math.inf


@njit(cache=True)
def _cubic_positive_on(c0, c1, c2, c3, T):
    """Whether c0 + c1 d + c2 d² + c3 d³ (c0 > 0, c3 ≤ 0) stays positive on [0, T]:
    positive at T and at its local minimum (the smaller critical point when c3 < 0,
    where the derivative turns from negative to positive) if that lies inside."""
    if c0 + T * (c1 + T * (c2 + T * c3)) <= 0.0:
        return False
    a, b, c = 3.0 * c3, 2.0 * c2, c1
    if a == 0.0:
        if b <= 0.0:
            return True  # concave or linear: the ends decide
        dm = -c / b
    else:
        disc = b * b - 4.0 * a * c
        if disc <= 0.0:
            return True  # derivative never positive: decreasing, the ends decide
        sq = math.sqrt(disc)
        r1, r2 = (-b + sq) / (2.0 * a), (-b - sq) / (2.0 * a)  # a < 0: r1 < r2
        dm = min(r1, r2)
    if 0.0 < dm < T:
        return c0 + dm * (c1 + dm * (c2 + dm * c3)) > 0.0
    return True


@njit(cache=True)
def safe_step(g, g1, g2, K, B, cap=math.inf):
    """First positive root of max(P2, P3) (reference.events.first_root_lower_bound).

    When P2's root is already ≥ `cap` (the smallest step found so far), or P3 stays
    positive up to `cap`, the vertex does not bind the step and P3 is not solved: a
    value ≥ cap is returned."""
    if g <= 0.0:
        return 0.0
    if K > 0.0:
        sq = math.sqrt(g1 * g1 + 2.0 * K * g)
        d2 = (g1 + sq) / K if g1 >= 0.0 else 2.0 * g / (sq - g1)
    elif g1 < 0.0:
        d2 = g / -g1
    else:
        d2 = math.inf
    if d2 >= cap:
        return d2
    if cap < math.inf and _cubic_positive_on(g, g1, 0.5 * g2, -B / 6.0, cap):
        return cap  # P3 has no root before cap: this vertex does not bind either
    d3 = _cubic(g, g1, 0.5 * g2, -B / 6.0)
    return max(d2, d3)


@njit(cache=True)
def gap_jet_flat(y, pts, acc6, gap, rate, accel, noise):
    """Gap, rate, normal acceleration and gap roundoff of every vertex over flat ground
    (reference.events.gap_jet for n = e_z) into the given arrays: with r = R p,
    g = z + r_z, g′ = v_z + (ω × r)_z, g″ = a_z + (ω̇ × r)_z + (ω·r) ω_z − |ω|² r_z."""
    R00, R01, R10, R11, R20, R21 = rotation_xy(y)
    wx, wy, wz = y[10], y[11], y[12]
    ww = wx * wx + wy * wy + wz * wz
    for k in range(pts.shape[0]):
        px, py = pts[k, 0], pts[k, 1]
        rx = R00 * px + R01 * py
        ry = R10 * px + R11 * py
        rz = R20 * px + R21 * py
        gap[k] = y[2] + rz
        rate[k] = y[9] + (wx * ry - wy * rx)
        accel[k] = (
            acc6[2] + (acc6[3] * ry - acc6[4] * rx) + (wx * rx + wy * ry + wz * rz) * wz - ww * rz
        )
        noise[k] = 8 * EPS * (abs(y[2]) + abs(rz))


@njit(cache=True)
def min_safe_step(gap, rate, accel, noise, skip, K, B):
    """min over contacts k with not skip[k] of safe_step(max(gap_k, noise_k), rate_k,
    accel_k, K, B): the step no listed contact can reach the ground within."""
    h = math.inf
    for k in range(gap.shape[0]):
        if skip[k]:
            continue
        d = safe_step(max(gap[k], noise[k]), rate[k], accel[k], K, B, h)
        if d < h:
            h = d
    return h


@njit(cache=True)
def _window(y, radius, n, K, delta, margin):
    """The vertices that can reach the ground within `delta` (the others are safe by the
    quadratic bound P2): an index range k0 − half … k0 + half (mod n) centred on the
    lowest direction.  O(1): nothing is enumerated.

    The P2 bound of vertex k at δ is gap_k + rate_k δ − Kδ²/2 = Z(δ) + a c_k·u(δ), with
    c_k = (cos θ_k, sin θ_k), Z = z + v_z δ − Kδ²/2 and u = (R20, R21) + δ (A, B), since
    a vertex's height and rate are linear in its body-frame position.  P2 is concave in
    δ, so vertex k is safe over [0, δ] when P2 > 0 at 0 and at δ, i.e. when
    a |u| cos(θ_k − ∠u) > −Z: outside an arc of half-width π − acos(−Z / (a|u|))
    around ∠u + π.  Returns (k0, half); half = n // 2 means every vertex."""
    R00, R01, R10, R11, R20, R21 = rotation_xy(y)
    A = y[10] * R10 - y[11] * R00
    B = y[10] * R11 - y[11] * R01
    ux, uy = R20 + A * delta, R21 + B * delta
    U = math.sqrt(ux * ux + uy * uy)
    Z = y[2] + y[9] * delta - 0.5 * K * delta * delta
    dth = 2.0 * math.pi / n
    centre = math.atan2(uy, ux) + math.pi
    if radius * U <= 0.0 or -Z / (radius * U) <= -1.0:
        half = 0
    else:
        c = -Z / (radius * U)
        W = math.pi if c >= 1.0 else math.pi - math.acos(c)
        half = int(math.ceil(W / dth))
    half = min(half + margin, n // 2)
    k0 = int(math.floor(centre / dth + 0.5))
    return k0, half


@njit(cache=True)
def _circle_F(x, z, vz, g, B, px, py, qx, qy, rn):
    """F(x) of _circle_step."""
    ux, uy = px + x * qx, py + x * qy
    return (
        z + x * (vz - x * (0.5 * g + x * B / 6.0)) - math.sqrt(ux * ux + uy * uy) - 0.5 * x * x * rn
    )


@njit(cache=True)
def _circle_step(y, LA, lam, g, radius, B):
    """A step safe for every vertex at once, from the circle through them (n > SMALL_N).

    A vertex's P3 bound is linear in its body-frame direction c (height, rate and
    acceleration of a body point are linear in its position):
    P3_c(δ) = Z3(δ) + c·u3(δ), Z3 = z + v_z δ − g δ²/2 − B δ³/6,
    u3 = p + δ q + δ² r / 2, with p, q, r the height, rate and acceleration of the body
    points (a, 0) and (0, a) less those of the centre.  Over all |c| = 1,
    P3_c ≥ F(δ) = Z3(δ) − |p + δ q| − δ² |r| / 2, and F is concave on δ ≥ 0 (each
    term is), so its first root is bracketed from below by chords from δ = 0 and from
    above by Newton steps.  Returns (root to 1e-3 relative, taken from below; the
    circle's lowest point F(0) = z − |p|; |p| = a sin α)."""
    z, vz = y[2], y[9]
    gx, rx, ax, _ = vertex_jet(y, LA, lam, g, radius, 0.0)
    gy, ry, ay, _ = vertex_jet(y, LA, lam, g, 0.0, radius)
    px, py = gx - z, gy - z
    qx, qy = rx - vz, ry - vz
    rn = math.sqrt((ax + g) ** 2 + (ay + g) ** 2)
    pn = math.sqrt(px * px + py * py)
    f0 = z - pn
    if f0 <= 0.0:
        return 0.0, f0, pn
    lo, flo = 0.0, f0
    # an upper end: F → −∞ (g > 0); double until F < 0
    hi = max(f0 / max(abs(vz) + math.sqrt(qx * qx + qy * qy), 1e-300), 1e-300)
    for _ in range(2000):
        fhi = _circle_F(hi, z, vz, g, B, px, py, qx, qy, rn)
        if fhi < 0.0:
            break
        lo, flo = hi, fhi
        hi *= 2.0
    for _ in range(100):
        if hi - lo <= 1e-3 * hi:
            break
        # chord from (lo, F(lo)) to (hi, F(hi)): below F on [lo, hi] (concavity);
        # then Newton from the upper end: the tangent lies above F, so it stays above
        # the root
        ux, uy = px + hi * qx, py + hi * qy
        un = math.sqrt(ux * ux + uy * uy)
        d = vz - hi * (g + 0.5 * hi * B) - hi * rn
        if un > 0.0:
            d -= (ux * qx + uy * qy) / un
        newton = hi - fhi / d if d < 0.0 else -1.0
        for x in (lo + (hi - lo) * flo / (flo - fhi), newton):
            if lo < x < hi:
                fx = _circle_F(x, z, vz, g, B, px, py, qx, qy, rn)
                if fx >= 0.0:
                    lo, flo = x, fx
                else:
                    hi, fhi = x, fx
    return lo, f0, pn


# for n > SMALL_N each step examines the vertices near the lowest direction and
# WINDOW_MAX more on each side, then at most WINDOW_MAX more that could touch within it
SMALL_N = 32
WINDOW_MAX = 3


@njit(cache=True)
def _vertex_step(y, g, LA, lam, pts, k, K, B, rate_noise, res):
    """Examine vertex k: res = (step, hit_ds, hit_k, land_k) updated in place (the
    smallest safe step, the earliest touching-and-approaching vertex, a touching vertex
    at rest and pressing in)."""
    gk, rk, ak, nk = vertex_jet(y, LA, lam, g, pts[k, 0], pts[k, 1])
    if gk <= nk:
        graze = 4.0 * math.sqrt(2.0 * max(ak, 0.0) * nk)
        if rk < -max(rate_noise, graze):
            ds = -gk / rk
            if ds < res[1]:
                res[1] = ds
                res[2] = k
            return
        if rk <= rate_noise and ak < 0:
            res[3] = k
        gk = max(gk, 0.0) + nk
    d = safe_step(gk, rk, ak, K, B, res[0])
    if d < res[0]:
        res[0] = d


@njit(cache=True)
def _window_step(y, g, LA, lam, pts, n, K, B, k0, half, rate_noise, res):
    """Examine vertices k0 − half … k0 + half (mod n, each once) with _vertex_step,
    centre first, then outwards (k0, k0 − 1, k0 + 1, …): the lowest vertices usually
    bind the step, and a small step found early spares the others' P3."""
    for j in range(min(2 * half + 1, n)):
        off = (j + 1) // 2
        k = (k0 - off if j % 2 else k0 + off) % n
        _vertex_step(y, g, LA, lam, pts, k, K, B, rate_noise, res)


@njit(cache=True)
def _near_vertices_step(y, g, LA, lam, pts, radius, n, K, B, left, last_dlt, rate_noise, res):
    """Examine the vertices near the lowest direction (n > SMALL_N) into res (see
    _vertex_step) and return the cap on the step they certify (inf when none is needed).

    The touching/lowest vertices and WINDOW_MAX more on each side come first.  The step
    they allow, δ, holds for all other vertices if those outside window(δ) are safe by P2
    and those inside have been examined: at most WINDOW_MAX more are examined, δ being
    shortened (from 4× the last certified step) until that suffices."""
    k0, h0 = _window(y, radius, n, K, 0.0, 2)
    h = min(h0 + WINDOW_MAX, n // 2)
    _window_step(y, g, LA, lam, pts, n, K, B, k0, h, rate_noise, res)
    if res[2] >= 0 or res[3] >= 0 or 2 * h + 1 >= n:
        return math.inf
    dlt = min(res[0], left, 4.0 * last_dlt)
    while True:
        k1, h1 = _window(y, radius, n, K, dlt, 3)
        d = (k1 - k0) % n
        if d > n // 2:
            d -= n
        lo1, hi1 = d - h1, d + h1  # window(δ) in offsets from k0
        extra = max(hi1 - h, 0) + max(-h - lo1, 0)
        if 2 * h1 + 1 < n and extra <= WINDOW_MAX:
            break
        dlt *= 0.25
    for off in range(h + 1, hi1 + 1):
        _vertex_step(y, g, LA, lam, pts, (k0 + off) % n, K, B, rate_noise, res)
    for off in range(lo1, -h):
        _vertex_step(y, g, LA, lam, pts, (k0 + off) % n, K, B, rate_noise, res)
    return dlt


@njit(cache=True)
def search_flat(y0, LA, lam, g, pts, radius, K, B, vscale, horizon, max_iter, out_y):
    """First vertex reached (approaching) in a free flight of at most `horizon`.

    Returns (s, k, iterations, n_simultaneous, k2, kind) with k = −1 when nothing is
    reached; kind 0 = impact, 1 = activation (touching at rest, pressing in).  `out_y`
    receives the state at s.  For n > SMALL_N only the window of vertices that can
    touch within the step is examined (see _window): the step is first bounded from
    the vertices near the lowest direction (the touching ones and WINDOW_MAX more on each
    side), then shortened until every vertex that could touch within it by P2 (its
    window, see _window) has been examined, with at most WINDOW_MAX more examined.
    The cost per step therefore does not grow with n."""
    n = pts.shape[0]
    y = out_y
    flight_state(y0, LA, lam, g, 0.0, y)
    s = 0.0
    rate_noise = 64 * EPS * vscale
    small_n = n <= SMALL_N
    res = np.empty(4)  # step, hit_ds, hit_k, land_k
    last_dlt = math.inf  # the last window-certified step (a start for the next)
    for it in range(max_iter):
        res[0], res[1], res[2], res[3] = math.inf, math.inf, -1.0, -1.0
        cap_step = math.inf
        d_c = 0.0
        if small_n:
            k0, h0 = _window(y, radius, n, K, 0.0, 0)
            _window_step(y, g, LA, lam, pts, n, K, B, k0, n // 2, rate_noise, res)
        else:
            # far from the ground the circle through the vertices gives the step at
            # once; within a few sags (a sin α (1 − cos π/n), the most a vertex can sit
            # above the circle's lowest point) of it, the vertices near the lowest
            # direction must be examined
            d_c, f0, pn = _circle_step(y, LA, lam, g, radius, B)
            if f0 > 4.0 * pn * (1.0 - math.cos(math.pi / n)) + 64.0 * EPS * (abs(y[2]) + radius):
                cap_step = 0.0  # no vertex examined: the circle's step alone
            else:
                cap_step = _near_vertices_step(
                    y, g, LA, lam, pts, radius, n, K, B, horizon - s, last_dlt, rate_noise, res
                )
                if cap_step < math.inf:
                    last_dlt = cap_step
        hit_k, land_k = int(res[2]), int(res[3])
        if hit_k >= 0:
            s_hit = s + res[1]
            flight_state(y0, LA, lam, g, s_hit, y)
            for _ in range(3):
                gk, rk, ak, nk = vertex_jet(y, LA, lam, g, pts[hit_k, 0], pts[hit_k, 1])
                corr = -gk / rk
                if not math.isfinite(corr) or abs(corr) <= 1e-16 * max(abs(s_hit), 1e-300):
                    break
                s_hit += corr
                flight_state(y0, LA, lam, g, s_hit, y)
            # simultaneous: another approaching vertex within the time resolution (only
            # vertices in the window around the lowest direction can be touching)
            gk0, rk0, ak0, nk0 = vertex_jet(y, LA, lam, g, pts[hit_k, 0], pts[hit_k, 1])
            tres0 = (nk0 + 1e-300) / max(-rk0, 1e-300)
            if small_n:
                k0, h0 = 0, n // 2
            else:
                k0, h0 = _window(y, radius, n, K, 0.0, 3)
            n_sim = 1
            k2 = -1
            for j in range(min(2 * h0 + 1, n)):
                k = (k0 - h0 + j) % n
                if k == hit_k:
                    continue
                gk, rk, ak, nk = vertex_jet(y, LA, lam, g, pts[k, 0], pts[k, 1])
                if rk >= -rate_noise:
                    continue
                if gk / -rk <= 4.0 * ((nk + 1e-300) / max(-rk, 1e-300) + tres0):
                    n_sim += 1
                    k2 = k
            return s_hit, hit_k, it, n_sim, k2, 0
        if land_k >= 0:
            return s, land_k, it, 1, -1, 1
        # two certificates, each for every vertex: the examined ones with the window
        # (min(res[0], cap_step)) and the circle (d_c)
        step = max(min(res[0], cap_step), d_c)
        step = max(step, 1e-15 * max(s, 1e-300))
        if s + step >= horizon:
            flight_state(y0, LA, lam, g, horizon, y)
            return horizon, -1, it, 0, -1, 0
        s += step
        flight_state(y0, LA, lam, g, s, y)
    return s, -2, max_iter, 0, -1, 0


# ------------------------------------------------------------------ compiled bounce loop

EXIT_T_END = 0  # reached the horizon in flight (state at the horizon)
EXIT_SPECIAL = 1  # an event Python must resolve (state just before it, vertex in k)
EXIT_MAX = 2  # impact budget reached
EXIT_FULL = 3  # buffers full: call again
EXIT_STUCK = 4  # the search did not converge


@njit(cache=True)
def _two_sum_add(hi, lo, s):
    h = hi + s
    bb = h - hi
    err = (hi - (h - bb)) + (s - bb)
    lo2 = lo + err
    hi2 = h + lo2
    return hi2, lo2 - (hi2 - h)


@njit(cache=True)
def _record_sample(y, hi, lo, mass, i1, i3, g, st, sy, se, ns):
    st[ns, 0] = hi
    st[ns, 1] = lo
    sy[ns, :] = y
    w, x, yq, z = y[3], y[4], y[5], y[6]
    e3x = 2 * (x * z + w * yq)
    e3y = 2 * (yq * z - w * x)
    e3z = 1 - 2 * (x * x + yq * yq)
    w3 = y[10] * e3x + y[11] * e3y + y[12] * e3z
    ww = y[10] ** 2 + y[11] ** 2 + y[12] ** 2
    se[ns, 0] = 0.5 * mass * (y[7] ** 2 + y[8] ** 2 + y[9] ** 2) + 0.5 * (
        i1 * (ww - w3 * w3) + i3 * w3 * w3
    )
    se[ns, 1] = mass * g * y[2]
    return ns + 1


@njit(cache=True)
def bounce_loop(
    y_in,
    mass,
    i1,
    i3,
    g,
    gamma,
    pts,
    radius,
    chatter_tol,
    t_hi,
    t_lo,
    t_end,
    max_impacts,
    sample_dt,
    max_iter,
    imp,
    st,
    sy,
    se,
):
    """Flight → single impact → flight … over flat ground, compiled.

    The same steps as reference.simulate's flight phase + _resolve for an impact with no
    resting contact and a post-impact speed above the completion threshold; anything
    else (no event, activation, simultaneous contacts, completion candidates, γ = 0)
    exits to Python with the state just before it.  Impacts go to `imp` rows
    (t_hi, t_lo, contact, impulse, u_pre, u_post), samples to st/sy/se.
    Returns (code, y, t_hi, t_lo, n_impacts, n_samples, iterations, k)."""
    y = y_in.copy()
    out = np.empty(13)
    ys = np.empty(13)
    n_imp = 0
    ns = 0
    iters = 0
    cap_imp = imp.shape[0]
    cap_s = st.shape[0]
    LA = np.empty(3)
    while True:
        if n_imp >= max_impacts:
            return EXIT_MAX, y, t_hi, t_lo, n_imp, ns, iters, -1
        if n_imp >= cap_imp or ns + 4 >= cap_s:
            return EXIT_FULL, y, t_hi, t_lo, n_imp, ns, iters, -1
        # flight constants (reference.flight.flight_constants)
        w, x, yq, z = y[3], y[4], y[5], y[6]
        e3x = 2 * (x * z + w * yq)
        e3y = 2 * (yq * z - w * x)
        e3z = 1 - 2 * (x * x + yq * yq)
        w3 = y[10] * e3x + y[11] * e3y + y[12] * e3z
        LA[0] = y[10] - w3 * e3x + (i3 / i1) * w3 * e3x
        LA[1] = y[11] - w3 * e3y + (i3 / i1) * w3 * e3y
        LA[2] = y[12] - w3 * e3z + (i3 / i1) * w3 * e3z
        lam = (1.0 / i3 - 1.0 / i1) * i3 * w3
        wabs = math.sqrt(y[10] ** 2 + y[11] ** 2 + y[12] ** 2)
        Om = math.sqrt(LA[0] ** 2 + LA[1] ** 2 + LA[2] ** 2)
        wd, wdd = abs(lam) * Om, abs(lam) * Om * Om
        K = 1.0001 * (g + radius * (wabs * wabs + wd))
        B = 1.0001 * radius * (wdd + 3 * wabs * wd + wabs**3)
        vscale = math.sqrt(y[7] ** 2 + y[8] ** 2 + y[9] ** 2) + radius * wabs
        remaining = (t_end - t_hi) - t_lo
        if remaining <= 0:
            return EXIT_T_END, y, t_hi, t_lo, n_imp, ns, iters, -1
        s, k, it, n_sim, k2, kind = search_flat(
            y, LA, lam, g, pts, radius, K, B, vscale, remaining, max_iter, out
        )
        iters += it
        if k == -2:
            return EXIT_STUCK, y, t_hi, t_lo, n_imp, ns, iters, -1
        # grid samples inside the flight
        kk = math.floor(t_hi / sample_dt) + 1
        while ns + 4 < cap_s:
            sg = kk * sample_dt - t_hi - t_lo
            if sg >= s:
                break
            if sg > 0:
                flight_state(y, LA, lam, g, sg, ys)
                h2, l2 = _two_sum_add(t_hi, t_lo, sg)
                ns = _record_sample(ys, h2, l2, mass, i1, i3, g, st, sy, se, ns)
            kk += 1
        t_hi, t_lo = _two_sum_add(t_hi, t_lo, s)
        y[:] = out
        if k == -1:
            return EXIT_T_END, y, t_hi, t_lo, n_imp, ns, iters, -1
        if kind == 1 or n_sim > 1 or gamma == 0.0:
            return EXIT_SPECIAL, y, t_hi, t_lo, n_imp, ns, iters, k
        # the impact at vertex k (reference.impact.impact_impulse for n = e_z)
        w, x, yq, z = y[3], y[4], y[5], y[6]
        px, py = pts[k, 0], pts[k, 1]
        rx = (1 - 2 * (yq * yq + z * z)) * px + 2 * (x * yq - w * z) * py
        ry = 2 * (x * yq + w * z) * px + (1 - 2 * (x * x + z * z)) * py
        rz = 2 * (x * z - w * yq) * px + 2 * (yq * z + w * x) * py
        u_pre = y[9] + (y[10] * ry - y[11] * rx)
        e3x = 2 * (x * z + w * yq)
        e3y = 2 * (yq * z - w * x)
        e3z = 1 - 2 * (x * x + yq * yq)
        # c = r × e_z = (r_y, −r_x, 0); I⁻¹ c = c / i1 + (1/i3 − 1/i1)(e3·c) e3
        cx, cy = ry, -rx
        e3c = e3x * cx + e3y * cy
        f = 1.0 / i3 - 1.0 / i1
        icx = cx / i1 + f * e3c * e3x
        icy = cy / i1 + f * e3c * e3y
        icz = f * e3c * e3z
        w_eff = 1.0 / mass + cx * icx + cy * icy
        u_post_pred = -gamma * u_pre
        if gamma < 1.0:
            noise = 8 * EPS * (abs(y[2]) + abs(rz))
            a_scale = g + radius * (y[10] ** 2 + y[11] ** 2 + y[12] ** 2)
            vs = math.sqrt(y[7] ** 2 + y[8] ** 2 + y[9] ** 2) + radius * wabs
            small = max(chatter_tol * vs, 100.0 * math.sqrt(2.0 * a_scale * noise))
            small = max(small, 64 * EPS * vs)
            if u_post_pred <= small:
                return EXIT_SPECIAL, y, t_hi, t_lo, n_imp, ns, iters, k
        ns = _record_sample(y, t_hi, t_lo, mass, i1, i3, g, st, sy, se, ns)
        zeta = -(1.0 + gamma) * u_pre / w_eff
        y[9] += zeta / mass
        y[10] += icx * zeta
        y[11] += icy * zeta
        y[12] += icz * zeta
        u_post = y[9] + (y[10] * ry - y[11] * rx)
        imp[n_imp, 0] = t_hi
        imp[n_imp, 1] = t_lo
        imp[n_imp, 2] = k
        imp[n_imp, 3] = zeta
        imp[n_imp, 4] = u_pre
        imp[n_imp, 5] = u_post
        n_imp += 1
        ns = _record_sample(y, t_hi, t_lo, mass, i1, i3, g, st, sy, se, ns)
