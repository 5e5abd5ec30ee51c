"""Steps safe for every vertex at once, from the circle through them (flat ground).

Every vertex of the polygon lies on the circle of radius a about the centre, in the
plane normal to e3, so none is lower than the circle's lowest point, a sin α below the
centre; and none is more than a sag, a sin α (1 − cos π/n), above it.  Far from the
ground (`rim_clear`) a lower bound on that point's height is a lower bound on every
vertex's, for any n (reference.core.search)."""

import math

from .flight import centre_height, precession_axis, rodrigues_parts
from .jit import ZERO, hot
from .layout import VZ, Z
from .roots import quadratic_first_root
from .rotation import body_axis
from .tolerances import (
    CIRCLE_STEP_REL_TOL,
    EPS,
    RIM_DESCENT_STEPS,
    RIM_NEWTON_STEPS,
    TINY,
)


@hot
def _circle_F(x, z, vz, g, B, px, py, qx, qy, rn):
    """F(x) = Z3(x) − |p + x q| − x²|r|/2 (`circle_step`)."""
    ux, uy = px + x * qx, py + x * qy
    return (
        z + x * (vz - x * (0.5 * g + x * B / 6.0)) - math.sqrt(ux * ux + uy * uy) - 0.5 * x * x * rn
    )


@hot
def _circle_slope(x, vz, g, B, px, py, qx, qy, rn):
    """F′(x) (`_circle_F`)."""
    ux, uy = px + x * qx, py + x * qy
    un = math.sqrt(ux * ux + uy * uy)
    d = vz - x * (g + 0.5 * x * B + rn)
    return d - (ux * qx + uy * qy) / un if un > 0.0 else d


@hot
def _circle_bracket(f0, vz, g, B, px, py, qx, qy, rn):
    """A first step past F's root: the root of F(0) + F′(0) h − (g + |r|) h²/2 ≥ F(h)
    (Z3 below its Taylor quadratic, the norm below its tangent); without gravity and
    rising, a guess for `circle_step` to double."""
    d0 = _circle_slope(0.0, vz, g, B, px, py, qx, qy, rn)
    h = quadratic_first_root(f0, d0, g + rn)
    if not h < math.inf:
        h = f0 / max(abs(d0) + math.sqrt(qx * qx + qy * qy), TINY)
    return max(h, TINY)


@hot
def far_from_ground(y, jet, model):
    """Whether the circle through the vertices is far from the ground (`rim_clear`), its
    lowest point z − |p| with |p| = a sin α (`circle_step`)."""
    px, py = jet[0], jet[1]
    return rim_clear(y[Z], math.sqrt(px * px + py * py), model)


@hot
def rim_clear(z, depth, model):
    """Whether the circle through the vertices, its centre at height z and its lowest
    point `depth` = a sin α below it, has that point more than four sags above the
    ground (a sag, a sin α (1 − cos π/n), is the most a vertex sits above that point):
    the circle's step then bounds them all at the price of one root; nearer, the
    vertices are examined."""
    allowance = 4.0 * depth * model.sag + 64.0 * EPS * (abs(z) + model.radius)
    return z - depth > allowance


@hot
def circle_step(y, jet, g, B):
    """A step safe for every vertex at once, from the circle through them.

    A vertex's P3 bound is linear in its body direction c: P3_c(δ) = Z3(δ) + c·u3(δ),
    Z3 = z + v_z δ − g δ²/2 − B δ³/6, u3 = p + δ q + δ² r/2 with p, q, r the height,
    rate and acceleration of the body points (a, 0), (0, a) less the centre's.  Over
    |c| = 1, P3_c ≥ F(δ) = Z3(δ) − |p + δ q| − δ²|r|/2 (`circle_root`)."""
    px, py, qx, qy, rx, ry = jet
    return circle_root(y[Z], y[VZ], g, B, px, py, qx, qy, math.sqrt(rx * rx + ry * ry))


@hot
def circle_root(z, vz, g, B, px, py, qx, qy, rn):
    """The first root of F(δ) = z + v_z δ − g δ²/2 − B δ³/6 − |p + δ q| − δ² rn/2,
    concave on δ ≥ 0 (a parabola and a cubic less a norm and a square), from below
    within CIRCLE_STEP_REL_TOL: bracketed (`_circle_bracket`, else by doubling) and
    closed from below by chords and from above by Newton steps (a Newton step from the
    right of the root of a concave F stays right of it).  A chord within the tolerance
    of the Newton point is returned unevaluated, its ends' values clear of F's
    roundoff: it lies below F, so F is ≥ 0 there (at roundoff level a chord can land
    past the root, and is evaluated)."""
    pn = math.sqrt(px * px + py * py)
    f0 = z - pn
    if f0 <= 0.0:
        return 0.0
    noise = 64.0 * EPS * (z + pn)  # F's roundoff
    lo, flo = 0.0, f0
    hi = _circle_bracket(f0, vz, g, B, px, py, qx, qy, rn)
    for _ in range(2000):
        fhi = _circle_F(hi, z, vz, g, B, px, py, qx, qy, rn)
        if fhi < 0.0:
            break
        lo, flo = hi, fhi
        hi *= 2.0
    push = ZERO
    for _ in range(100):
        if hi - lo <= CIRCLE_STEP_REL_TOL * hi:
            break
        d = _circle_slope(hi, vz, g, B, px, py, qx, qy, rn)
        chord = _pushed_chord(lo, flo, hi, fhi, push)
        newton = hi - fhi / d if d < 0.0 else -1.0
        upper = newton if lo < newton < hi else hi
        if (
            push == 0
            and min(flo, -fhi) > noise
            and lo < chord
            and upper - chord <= CIRCLE_STEP_REL_TOL * upper
        ):
            return chord  # (a chord of the concave F lies below it: F(chord) ≥ 0)
        for x in (chord, newton):
            if lo < x < hi:
                fx = _circle_F(x, z, vz, g, B, px, py, qx, qy, rn)
                if fx >= 0.0:
                    lo, flo = x, fx
                else:
                    hi, fhi = x, fx
                    if x == chord:
                        push += 1
    return lo


@hot
def _pushed_chord(lo, flo, hi, fhi, push):
    """The chord's root on [lo, hi], kept half of CIRCLE_STEP_REL_TOL inside hi once a
    chord has landed past the root (`push` ≥ 1) or rounds onto hi, and at most the
    midpoint once that too has (push ≥ 2).  A chord lies below the concave F, so it
    lands past the root only by roundoff: the root is then within roundoff of hi, where
    chords alone would close the bracket an ulp at a time (observed: 100 evaluations
    for a step of 1e-12 s); the midpoint, for F itself at roundoff level."""
    chord = lo + (hi - lo) * flo / (flo - fhi)
    if push >= 2:
        return min(chord, 0.5 * (lo + hi))
    if push == 1 or not chord < hi:
        return min(chord, hi - 0.5 * CIRCLE_STEP_REL_TOL * hi)
    return chord


@hot
def lands_near(jet, B, step, model):
    """Whether the circle step `step` (the root of its bound F, `circle_step`) ends with
    the circle's lowest point within four sags of the ground, so that a descent would
    not go further: the point's height there exceeds F = 0 by at most the bound's loss
    δ²|r| + Bδ³/3 (its square and cubic terms taken from both sides), compared with
    four sags of the depth at the start.  A guess at where to spend work, not a bound
    anything relies on."""
    px, py, _, _, rx, ry = jet
    loss = step * step * (math.sqrt(rx * rx + ry * ry) + B * step / 3.0)
    return loss <= 4.0 * model.sag * math.sqrt(px * px + py * py)


@hot
def rim_step(y, gravity, depth, radius):
    """A step safe for every vertex at once for the rest of the flight: no vertex is more
    than `depth` (Bounds.depth) below the centre, whose height is a parabola, so none
    touches before z + v_z δ − g δ²/2 = depth (`rim_root`).  Near the exact landing
    time of a spinning disk, whose rim's lowest point does not move with the spin."""
    return rim_root(y[Z], y[VZ], gravity, depth, radius)


@hot
def rim_root(z, vz, gravity, depth, radius):
    """The first root of z + v_z δ − g δ²/2 = depth (`roots.quadratic_first_root`), with
    a few ulps of margin; 0 when the centre is that low already."""
    h = z - depth - 64.0 * EPS * (abs(z) + radius)
    if not h > 0.0:
        return 0.0
    return quadratic_first_root(h, vz, gravity)


@hot
def axis_cone(y, fc):
    """The symmetry axis over a free flight from state y, in closed form: e3 precesses
    about L̂ at Ω (regular precession, `flight`), so its horizontal part is
    E(s) = u + cos(Ωs) c + sin(Ωs) w (`flight.rodrigues_parts`: u the part along L̂, c
    the rest, w = L̂ × e3; their x, y components) and |Ë3| = Ω²|c| at every s.  Returns
    (ux, uy, cx, cy, wx, wy, Ω, Ω²|c|)."""
    e3x, e3y, e3z = body_axis(y)
    Lx, Ly, Lz = precession_axis(fc)
    ux, uy, _, cx, cy, cz, wx, wy, _ = rodrigues_parts(e3x, e3y, e3z, Lx, Ly, Lz)
    om = fc.omega
    return ux, uy, cx, cy, wx, wy, om, om * om * math.sqrt(cx * cx + cy * cy + cz * cz)


@hot
def rim_at(y, cone, model, s):
    """The circle's centre height and rate and a E, a Ė at time s of the flight from y
    (`axis_cone`): (z, v_z, ex, ey, dx, dy)."""
    ux, uy, cx, cy, wx, wy, om, _ = cone
    a = model.radius
    co, si = math.cos(om * s), math.sin(om * s)
    z, vz = centre_height(y[Z], y[VZ], model.gravity, s)
    return (
        z,
        vz,
        a * (ux + co * cx + si * wx),
        a * (uy + co * cy + si * wy),
        a * om * (co * wx - si * cx),
        a * om * (co * wy - si * cy),
    )


@hot
def rim_target(y, cone, model, s, at_s):
    """A time s_t > s where the circle's lowest point is two sags above the ground,
    H = 2 sag a|E| to within a sag (Newton steps on H − 2 sag a|E| from s, where the
    circle is at_s, `rim_at`; from a rising H Newton starts where a parabola with its
    rate and −g falls to that height), and the span before s_t over which H stays
    positive: the first root of the backward bound
    H(s_t − δ) ≥ z_t − v_z δ − g δ²/2 − a|E_t − δĖ_t| − a Ω²|c| δ²/2 (`circle_root`).
    (−1, 0) when Newton does not settle on a falling H."""
    k = 1.0 + 2.0 * model.sag
    z, vz, ex, ey, dx, dy = at_s
    s0 = s
    for i in range(RIM_NEWTON_STEPS):
        e = math.sqrt(ex * ex + ey * ey)
        f = z - k * e
        if i > 0 and abs(f) <= model.sag * e:  # within a sag of the target: s_t
            back = circle_root(z, -vz, model.gravity, 0.0, ex, ey, -dx, -dy, model.radius * cone[7])
            return s, back
        slope = vz - k * (ex * dx + ey * dy) / e if e > 0.0 else vz
        if slope < 0.0:
            s += f / -slope
        elif i == 0:  # rising: start from the fall of a parabola with its rate and g
            s += quadratic_first_root(f, slope, model.gravity)
        else:
            return -1.0, 0.0
        if not s > s0:
            return -1.0, 0.0
        z, vz, ex, ey, dx, dy = rim_at(y, cone, model, s)
    return -1.0, 0.0


@hot
def rim_descent(y, fc, model, depth, left, s):
    """A step safe for every vertex at once, from the circle through them, followed on
    its closed form from s (itself safe: the caller's circle step) until its lowest
    point comes within `rim_clear` of the ground.

    The lowest point of the circle is at H(s) = z(s) − a|E(s)| (|E| = sin α, the axis's
    horizontal part, `axis_cone`), below every vertex.  From s, with E, Ė exact there
    and |Ë| ≤ Ω²|c|, H(s + δ) ≥ z + v_z δ − g δ²/2 − a|E + δĖ| − a Ω²|c| δ²/2, whose
    first root (`circle_root`) is a safe step, as is the time the centre takes to fall
    to the rim's deepest reach over the flight (`rim_root`, `depth`).  The steps are
    repeated (each costs a cosine, a sine and a root, not a state) up to
    RIM_DESCENT_STEPS times, or `left`, and end at the Newton-found time s_t two sags
    above the ground (`rim_target`, sought again from each step's start while none lies
    ahead) once they reach the span before it that its backward bound certifies."""
    cone = axis_cone(y, fc)
    s_t, back = -1.0, 0.0
    for _ in range(RIM_DESCENT_STEPS):
        at_s = rim_at(y, cone, model, s)
        z, vz, ex, ey, dx, dy = at_s
        if not rim_clear(z, math.sqrt(ex * ex + ey * ey), model):
            break
        if not s_t > s:
            s_t, back = rim_target(y, cone, model, s, at_s)
            if s_t - back <= s < s_t:  # [0, s] and [s_t − back, s_t] are safe
                return s_t
        d = max(
            circle_root(z, vz, model.gravity, 0.0, ex, ey, dx, dy, model.radius * cone[7]),
            rim_root(z, vz, model.gravity, depth, model.radius),
        )
        s += d
        if s_t - back <= s < s_t:
            return s_t
        if not (d > 0.0 and s < left):
            break
    return s
