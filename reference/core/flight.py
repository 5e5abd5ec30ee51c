"""Free flight in closed form (paper eqs. acc1free–acc2free) and the bounds on the gaps'
derivatives that make the event search safe.

The centre of mass follows a parabola, x(s) = x0 + v0 s − ½ g s² e_z.  The body is
axisymmetric (I1 = I2 = A, I3 = C), so torque-free rotation is regular precession: L is
constant, and

    R(s) = Rot(L̂, Ω s) · R0 · Rot(ẑ, λ s),   Ω = |L|/A,  λ = (1/C − 1/A)(L·e3),
    ω(s) = L/A + λ e3(s),   ω̇ = λ (L/A) × e3.
"""

import math

from .contacts import speed
from .jit import hot
from .layout import QW, QX, QY, QZ, VX, VY, VZ, WX, WY, WZ, X, Y, Z
from .records import Bounds, FlightConstants
from .rotation import body_axis, qmul, rotation_columns_xy, rotation_vector_quaternion
from .tolerances import BOUND_MARGIN, BOUND_ULPS, EPS, TINY


@hot
def flight_constants(y, i1, i3):
    """L/A, λ, |ω| and Ω of the free flight starting at state y."""
    e3x, e3y, e3z = body_axis(y)
    w3 = y[WX] * e3x + y[WY] * e3y + y[WZ] * e3z
    lax = y[WX] - w3 * e3x + (i3 / i1) * w3 * e3x
    lay = y[WY] - w3 * e3y + (i3 / i1) * w3 * e3y
    laz = y[WZ] - w3 * e3z + (i3 / i1) * w3 * e3z
    lam = (1.0 / i3 - 1.0 / i1) * i3 * w3
    wabs = math.sqrt(y[WX] ** 2 + y[WY] ** 2 + y[WZ] ** 2)
    return FlightConstants(lax, lay, laz, lam, wabs, math.sqrt(lax * lax + lay * lay + laz * laz))


@hot
def free_flight(y0, fc, gravity, s, out):
    """The state after a free flight of duration s from y0, into `out` (closed form)."""
    out[X] = y0[X] + y0[VX] * s
    out[Y] = y0[Y] + y0[VY] * s
    out[Z], out[VZ] = centre_height(y0[Z], y0[VZ], gravity, s)
    out[VX] = y0[VX]
    out[VY] = y0[VY]
    p0, p1, p2, p3 = rotation_vector_quaternion(fc.lax * s, fc.lay * s, fc.laz * s)
    a = qmul(p0, p1, p2, p3, y0[QW], y0[QX], y0[QY], y0[QZ])
    half = 0.5 * fc.lam * s
    b = qmul(a[0], a[1], a[2], a[3], math.cos(half), 0.0, 0.0, math.sin(half))
    nrm = math.sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3])
    out[QW], out[QX], out[QY], out[QZ] = b[0] / nrm, b[1] / nrm, b[2] / nrm, b[3] / nrm
    e3x, e3y, e3z = body_axis(out)
    out[WX] = fc.lax + fc.lam * e3x
    out[WY] = fc.lay + fc.lam * e3y
    out[WZ] = fc.laz + fc.lam * e3z


@hot
def centre_height(z, vz, gravity, s):
    """Height and vertical velocity of the centre of mass after a flight of s from
    (z, v_z): the parabola z + v_z s − g s²/2 and v_z − g s."""
    return z + vz * s - 0.5 * gravity * s * s, vz - gravity * s


@hot
def precession_axis(fc):
    """L̂, the axis e3 precesses about (ẑ for a body that does not rotate: any axis
    serves, e3 then stays put)."""
    om = fc.omega
    if om > 0.0:
        return fc.lax / om, fc.lay / om, fc.laz / om
    return 0.0, 0.0, 1.0


@hot
def rodrigues_parts(fx, fy, fz, Lx, Ly, Lz):
    """A body axis f split about L̂ so that Rot(L̂, θ) f = u + cos θ c + sin θ w
    (Rodrigues): u = (L̂·f) L̂, c = f − u, w = L̂ × f, as (ux, uy, uz, cx, cy, cz, wx, wy,
    wz)."""
    lf = Lx * fx + Ly * fy + Lz * fz
    ux, uy, uz = lf * Lx, lf * Ly, lf * Lz
    return (
        ux, uy, uz, fx - ux, fy - uy, fz - uz,
        Ly * fz - Lz * fy, Lz * fx - Lx * fz, Lx * fy - Ly * fx,
    )  # fmt: skip


@hot
def flight_acceleration(fc, y, gravity):
    """(v̇, ω̇) in flight: (0, 0, −g) and λ (L/A) × e3."""
    e3x, e3y, e3z = body_axis(y)
    lam = fc.lam
    return (
        0.0,
        0.0,
        -gravity,
        lam * (fc.lay * e3z - fc.laz * e3y),
        lam * (fc.laz * e3x - fc.lax * e3z),
        lam * (fc.lax * e3y - fc.lay * e3x),
    )


@hot
def _height_terms(fx, fy, fz, Lx, Ly, Lz):
    """For a body axis f: the constant, cosine and sine parts of (Rot(L̂, θ) f)_z
    (`rodrigues_parts`' z components)."""
    parts = rodrigues_parts(fx, fy, fz, Lx, Ly, Lz)
    return parts[2], parts[5], parts[8]


@hot
def vertex_height_bounds(y0, fc, radius, gravity):
    """Bounds (K, B) ≥ max over the flight and over every rim vertex (contact kind
    RIM_VERTEX_ON_PLANE) of |g″| and |g‴|, and the rim's deepest reach below the centre
    (`rim_depth_bound`).

    A vertex at body angle θ has height z(s) + a (Rot(L̂, Ωs) w(s))_z with
    w = cos φ f1 + sin φ f2, φ = θ + λs, f1, f2 = R0 ê1, R0 ê2.  With (α_i, β_i, γ_i)
    the constant, cosine and sine parts of (Rot(L̂, Ωs) f_i)_z, the height's rotating
    part is a sum of three sinusoids in s, of frequencies |λ|, |λ + Ω|, |λ − Ω| and
    amplitudes a|(α1, α2)|, ½a|(β1 − γ2, γ1 + β2)|, ½a|(β1 + γ2, β2 − γ1)| whatever θ.
    So |g″| ≤ g + Σ A_j ω_j² and |g‴| ≤ Σ A_j ω_j³ (z‴ = 0): bounds that shrink with the
    tilt, where a(|ω|² + …) would not."""
    om, lam = fc.omega, fc.lam
    Lx, Ly, Lz = precession_axis(fc)
    R00, R01, R10, R11, R20, R21 = rotation_columns_xy(y0)
    a1, b1, g1 = _height_terms(R00, R10, R20, Lx, Ly, Lz)
    a2, b2, g2 = _height_terms(R01, R11, R21, Lx, Ly, Lz)
    amp0 = radius * math.sqrt(a1 * a1 + a2 * a2)
    amp_p = 0.5 * radius * math.sqrt((b1 - g2) ** 2 + (g1 + b2) ** 2)
    amp_m = 0.5 * radius * math.sqrt((b1 + g2) ** 2 + (b2 - g1) ** 2)
    w0, wp, wm = abs(lam), abs(lam + om), abs(lam - om)
    K = gravity + amp0 * w0**2 + amp_p * wp**2 + amp_m * wm**2
    B = amp0 * w0**3 + amp_p * wp**3 + amp_m * wm**3
    slack = BOUND_ULPS * EPS * radius
    return Bounds(
        BOUND_MARGIN * K + slack * (w0**2 + wp**2 + wm**2),
        BOUND_MARGIN * B + slack * (w0**3 + wp**3 + wm**3),
        rim_depth_bound(y0, Lx, Ly, Lz, radius),
    )


@hot
def rim_depth_bound(y0, Lx, Ly, Lz, radius):
    """The most any vertex can be below the centre of mass during the flight: the rim's
    depth a sin α, with the axis e3 precessing about L̂ (regular precession), so that
    e3_z(s) = c + A cos Ωs + S sin Ωs (`_height_terms`) stays within c ± √(A² + S²):
    sin α ≤ √(1 − m²), m the least |e3_z| over that range (0 if it holds 0).  Bounds
    every vertex at once for the whole flight, however fast the body spins.  The range's
    ends carry a few ulps of roundoff, so m is first lowered by BOUND_ULPS ulps: near
    flat, where e3_z rounds to 1, that keeps a depth of at least a √(2 BOUND_ULPS ε) ≈
    8e-8 a (without it a tilt of 1e-9 spinning about its axis gave 4e-15 a, less than
    its lowest vertex's 1e-9 a); a few ulps more on the result."""
    e3x, e3y, e3z = body_axis(y0)
    c, A, S = _height_terms(e3x, e3y, e3z, Lx, Ly, Lz)
    R = math.sqrt(A * A + S * S)
    lo, hi = c - R, c + R
    m = 0.0 if lo <= 0.0 <= hi else min(abs(lo), abs(hi))
    m = max(m - BOUND_ULPS * EPS, 0.0)
    s_max = math.sqrt(max(1.0 - m * m, 0.0))
    return radius * min(s_max + BOUND_ULPS * EPS, 1.0)


@hot
def bump_gap_bounds(y0, fc, pts, first, gravity, horizon):
    """Bounds (K, B; depth inf) of the floor points pts[first:] (contact kind
    FLOOR_POINT_ON_FACE) over a flight of `horizon`:
    with g = (x − b)·e3 and e3 precessing at Ω about L,
        g″ = a·e3 + 2 v·ė3 + (x − b)·ë3,  g‴ = 3 a·ė3 + 3 v·ë3 + (x − b)·e3‴,
    |ė3| ≤ Ω, |ë3| ≤ Ω², |e3‴| ≤ Ω³, |v| ≤ |v0| + g H, |x − b| ≤ D0 + |v0| H + g H²/2."""
    H = horizon if math.isfinite(horizon) else 1e300
    v0 = speed(y0)
    V = v0 + gravity * H
    D = _farthest_bump(y0, pts, first) + v0 * H + 0.5 * gravity * H * H
    om = fc.omega
    K = gravity + 2 * V * om + D * om * om
    B = 3 * gravity * om + 3 * V * om * om + D * om**3
    return Bounds(BOUND_MARGIN * K, BOUND_MARGIN * B, math.inf)


@hot
def _farthest_bump(y, pts, first):
    """The largest distance from the centre of mass to a floor point pts[first:]."""
    D = 0.0
    for k in range(first, pts.shape[0]):
        d = math.sqrt((y[X] - pts[k, 0]) ** 2 + (y[Y] - pts[k, 1]) ** 2 + (y[Z] - pts[k, 2]) ** 2)
        D = max(D, d)
    return D


@hot
def bound_segment(y, model, pts):
    """How long a flight from state y is searched with one set of bounds: for ever on a
    ground of rim vertices alone (`vertex_height_bounds` does not depend on it); with
    floor points max(|v|, √(2 g D))/g, D the farthest floor point's distance: over it
    the speed at most doubles and the distance to a floor point at most triples (plus
    |v|²/2g), so `bump_gap_bounds` stay near their values at its start (without gravity
    D/|v|: the distance at most doubles)."""
    if model.n_rim == model.n_contacts:
        return math.inf
    g, v, D = model.gravity, speed(y), _farthest_bump(y, pts, model.n_rim)
    if g > 0.0:
        return max(v, math.sqrt(2.0 * g * D), TINY) / g
    return D / v if v > 0.0 else math.inf


@hot
def flight_bounds(y0, fc, model, pts, horizon):
    """Bounds for the ground's contacts: `vertex_height_bounds` of its rim vertices,
    `bump_gap_bounds` of its floor points, the larger K and B of the two when it has
    both (the rim's depth bound stands: it concerns the rim vertices alone)."""
    if model.n_rim == model.n_contacts:
        return vertex_height_bounds(y0, fc, model.radius, model.gravity)
    points = bump_gap_bounds(y0, fc, pts, model.n_rim, model.gravity, horizon)
    if model.n_rim == 0:
        return points
    rim = vertex_height_bounds(y0, fc, model.radius, model.gravity)
    return Bounds(max(rim.K, points.K), max(rim.B, points.B), rim.depth)
