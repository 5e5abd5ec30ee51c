"""The floor plane under a ground without rim contacts: a model limit, not a contact.

The three-point ground holds the face on its floor points (bumps, tops at z = 0) and
has no contact for the rim: a floor at z = −d (model.floor_depth, d > 0; inf for the
grounds whose rim vertices have the plane z = 0 as contacts, which do not get this
limit) is not modelled.  The body's lowest point is the face's rim's: the circle of
radius a about the centre, in the plane normal to e3 (the face the bumps touch,
`contacts.off_face`), whose lowest point is at

    H = z + d − a|E|   above the floor, E = (e3x, e3y) the axis's horizontal part

(|E| = sin α; reference.core.rim).  H reaching zero ends the run `left_model`
(records.STATUS_BELOW_FLOOR).  It is located like a contact's zero: in flight on H's
closed form (`floor_reach`: the rim's lower bound of `rim.rim_descent`, then Newton
steps), in a contact phase by a chunk horizon that keeps H's quadratic bound positive
(`floor_horizon`, as free gaps are kept) and, should a chunk still end below the floor,
the zero found inside it (reference.core.phases)."""

import math

from .flight import precession_axis, rim_depth_bound
from .jit import hot
from .layout import VZ, Z
from .rim import axis_cone, circle_root, rim_at, rim_root
from .roots import safe_step
from .rotation import body_axis
from .tolerances import EPS, GAP_NOISE_ULPS, POLISH_ITERATIONS, POLISH_REL_TOL, TINY

# Conservative steps of `floor_reach` before it gives up on certifying the flight
# (each a cosine, a sine and a root; a transversal zero takes a handful, a graze more).
FLOOR_STEPS = 10_000


@hot
def has_floor(model):
    """Whether the ground has the floor plane as a model limit (a finite depth)."""
    return model.floor_depth < math.inf


@hot
def floor_noise(z, model):
    """Roundoff of H = z + d − a|E|: GAP_NOISE_ULPS ε (|z| + d + a)."""
    return GAP_NOISE_ULPS * EPS * (abs(z) + model.floor_depth + model.radius)


@hot
def floor_gap(y, model):
    """H = z + d − a|E| at state y: the rim's lowest point above the floor plane."""
    ex, ey, _ = body_axis(y)
    return y[Z] + model.floor_depth - model.radius * math.sqrt(ex * ex + ey * ey)


@hot
def below_floor(y, model):
    """Whether the rim's lowest point is below the floor plane beyond H's roundoff."""
    return has_floor(model) and floor_gap(y, model) < -floor_noise(y[Z], model)


@hot
def _rate(at_s):
    """H′ = v_z − (aE · aĖ)/(a|E|) from `rim.rim_at`'s (z, v_z, aE, aĖ)."""
    _, vz, ex, ey, dx, dy = at_s
    e = math.sqrt(ex * ex + ey * ey)
    return vz - (ex * dx + ey * dy) / e if e > 0.0 else vz


@hot
def floor_reach(y0, fc, model, horizon):
    """The first time s in [0, horizon] of the free flight from y0 (constants fc) at
    which the rim's lowest point reaches the floor plane, or −1 if it stays above.

    From s, with aE, aĖ exact there and |aË| ≤ aΩ²|c| (`rim.axis_cone`),
    H(s + δ) ≥ z + d + v_z δ − g δ²/2 − |aE + δ aĖ| − aΩ²|c| δ²/2, whose first root
    (`rim.circle_root`) is a safe step, as is the time the centre takes to fall to
    d less the rim's deepest reach over the flight (`rim.rim_root`): conservative
    advancement, never past the zero, until H is within its roundoff; then Newton
    steps on H polish the time (a transversal zero; a graze stays at its first point
    within roundoff)."""
    if not has_floor(model):
        return -1.0
    cone = axis_cone(y0, fc)
    d, a, g = model.floor_depth, model.radius, model.gravity
    Lx, Ly, Lz = precession_axis(fc)
    depth = rim_depth_bound(y0, Lx, Ly, Lz, a)
    s = 0.0
    for _ in range(FLOOR_STEPS):
        at_s = rim_at(y0, cone, model, s)
        z, vz, ex, ey, dx, dy = at_s
        h = z + d - math.sqrt(ex * ex + ey * ey)
        if h <= floor_noise(z, model):
            return _polish(y0, cone, model, s, horizon)
        step = max(
            circle_root(z + d, vz, g, 0.0, ex, ey, dx, dy, a * cone[7]),
            rim_root(z + d, vz, g, depth, a),
        )
        s += max(step, TINY)
        if s > horizon:
            return -1.0
    return s  # (not certified further: the limit taken where the steps stalled)


@hot
def _polish(y0, cone, model, s, horizon):
    """Newton steps on H from s (H within its roundoff there), kept in [0, horizon]."""
    d = model.floor_depth
    for _ in range(POLISH_ITERATIONS):
        at_s = rim_at(y0, cone, model, s)
        z, _, ex, ey, _, _ = at_s
        rate = _rate(at_s)
        if not rate < 0.0:  # (a graze: its first point within roundoff stands)
            break
        corr = -(z + d - math.sqrt(ex * ex + ey * ey)) / rate
        nxt = min(max(s + corr, 0.0), horizon)
        if abs(nxt - s) <= POLISH_REL_TOL * max(s, TINY):
            break
        s = nxt
    return s


@hot
def floor_horizon(y, acc, jet, model, K, h):
    """h shortened, in a contact phase, to the first root of max(P2, T2) of H (as a free
    gap's, `horizon.safe_horizon`): from the rim jet (`contacts.rim_jet`: heights p,
    rates q and accelerations r of the body points (a, 0), (0, a) less the centre's)
    H = z + d − |p|, H′ = v_z + c·q and H″ = v̇_z + c·r − (q·c⊥)²/|p| with
    c = −p/|p| the lowest direction (the envelope of z + c·p over |c| = 1)."""
    if not has_floor(model):
        return h
    px, py, qx, qy, rx, ry = jet
    pn = math.sqrt(px * px + py * py)
    gap = y[Z] + model.floor_depth - pn
    if pn > 0.0:
        cx, cy = -px / pn, -py / pn
        turn = qy * cx - qx * cy  # q·c⊥
        rate = y[VZ] + cx * qx + cy * qy
        accel = acc[2] + cx * rx + cy * ry - turn * turn / pn
    else:
        rate, accel = y[VZ] - math.sqrt(qx * qx + qy * qy), acc[2] - math.sqrt(rx * rx + ry * ry)
    return safe_step(max(gap, floor_noise(y[Z], model)), rate, accel, K, 0.0, h)
