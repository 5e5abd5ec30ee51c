"""The contact kinds: the geometry of one contact at a state (the model of Baranyai &
Várkonyi, section 2).  A ground is a list of contacts, each of a kind
(`records.RIM_VERTEX_ON_PLANE`, `records.FLOOR_POINT_ON_FACE`), stored with the
contact: `pts[k, :3]` is contact k's point (body-frame for a rim vertex, world for a
floor point), `pts[k, KIND_COLUMN]` its kind (`contact_kind`).  Its rim vertices come
first, contacts 0 … model.n_rim − 1 in order round the rim (the searches' windows
over vertex indices rely on it), then its floor points.

- RIM_VERTEX_ON_PLANE: the body point p_k = a(cos 2πk/n, sin 2πk/n, 0) against the
  plane z = 0; lever r = R p_k, gap g = z + r_z, normal n = e_z (paper eq. rig, exact
  in α);
- FLOOR_POINT_ON_FACE: the fixed world point b_k under the body's face (normal
  e3 = R ẑ through the centre of mass): with d = x − b_k, gap g = d·e3, normal
  n = e3, lever r = −d + g e3 (the in-plane part of b_k − x); the model has no such
  contact once the point is outside the face's rim (`off_face`).

Either way the normal velocity is g′ = n·(v + ω × r) and the normal acceleration is
g″ = J (v̇, ω̇) + bias with J = [nᵀ, (r × n)ᵀ] (paper eq. rollc); the impulse response
is the kind-free `inertia.impulse_response` of the frame.  Each function below takes
the contact's kind and branches on it, the only place the core asks for it; the
derivative bounds of the event search per kind are in reference.core.flight, and the
circle step and vertex windows of the rim vertices in reference.core.rim and window.
Accelerations `acc` are tuples (v̇x, v̇y, v̇z, ω̇x, ω̇y, ω̇z)."""

import math

from .jit import hot, hot_inline
from .layout import VX, VY, VZ, WX, WY, WZ, X, Y, Z
from .records import KIND_COLUMN, RIM_VERTEX_ON_PLANE, Frame, Jet
from .rotation import body_axis, rotation_columns_xy
from .tolerances import EPS, GAP_NOISE_ULPS, RATE_NOISE_ULPS, SIMULTANEOUS_FACTOR, TINY


@hot
def contact_kind(pts, k):
    """The kind of contact k, stored with its point: pts[k, KIND_COLUMN]
    (records.KIND_COLUMN)."""
    return int(pts[k, KIND_COLUMN])


@hot
def vertex_lever(y, px, py):
    """r = R p of the body point p = (px, py, 0) at state y (`lever_of_columns`)."""
    return lever_of_columns(rotation_columns_xy(y), px, py)


@hot
def lever_of_columns(cols, px, py):
    """r = R p of the body point p = (px, py, 0): its position from the centre of mass in
    the world frame, from R's first two columns (`rotation.rotation_columns_xy`: r_z
    from the small quaternion components, tilts keep their digits)."""
    R00, R01, R10, R11, R20, R21 = cols
    return R00 * px + R01 * py, R10 * px + R11 * py, R20 * px + R21 * py


@hot
def vertex_frame(y, cols, px, py):
    """Frame of the body point (px, py, 0) over flat ground (cols: R's first two columns
    at state y): gap z + r_z, normal e_z, lever r, roundoff GAP_NOISE_ULPS ε (|z| +
    |r_z|)."""
    rx, ry, rz = lever_of_columns(cols, px, py)
    return Frame(y[Z] + rz, 0.0, 0.0, 1.0, rx, ry, rz, vertex_gap_noise(y[Z], rz))


@hot
def vertex_gap_noise(z, rz):
    """Roundoff of a vertex gap z + r_z: GAP_NOISE_ULPS ε (|z| + |r_z|) (|r_z| ≤ a bounds
    it for every vertex)."""
    return GAP_NOISE_ULPS * EPS * (abs(z) + abs(rz))


@hot
def bump_frame(y, bx, by, bz):
    """Frame of the ground bump b under the body's face (`bump_frame_on_axis`)."""
    return bump_frame_on_axis(y, body_axis(y), bx, by, bz)


@hot
def bump_frame_on_axis(y, e3, bx, by, bz):
    """Frame of the ground bump b under the body's face, e3 = R ẑ the body's axis at
    state y: gap d·e3 (d = x − b), normal e3, lever −d + gap e3, roundoff
    GAP_NOISE_ULPS ε Σ|d_j e3_j|."""
    ex, ey, ez = e3
    dx, dy, dz = y[X] - bx, y[Y] - by, y[Z] - bz
    gap = dx * ex + dy * ey + dz * ez
    noise = GAP_NOISE_ULPS * EPS * (abs(dx * ex) + abs(dy * ey) + abs(dz * ez))
    return Frame(gap, ex, ey, ez, -dx + gap * ex, -dy + gap * ey, -dz + gap * ez, noise)


@hot
def contact_frame(y, kind, pts, k):
    """Gap, normal, lever and gap roundoff of contact k (of kind `kind`) at state y."""
    if kind == RIM_VERTEX_ON_PLANE:
        return vertex_frame(y, rotation_columns_xy(y), pts[k, 0], pts[k, 1])
    return bump_frame(y, pts[k, 0], pts[k, 1], pts[k, 2])


@hot_inline
def frame_at(y, cols, e3, kind, pts, k):
    """`contact_frame` from R's first two columns and e3 at state y (cols:
    `rotation.rotation_columns_xy`, e3: `rotation.body_axis`), computed once for the
    contacts of a contact system: the same numbers, the attitude's terms not repeated
    per contact.  Inlined where it is called (numba's IR inlining), as the contact
    system's other per-contact functions (`normal_acceleration`), which LLVM left as
    calls on the held motion's right-hand side."""
    if kind == RIM_VERTEX_ON_PLANE:
        return vertex_frame(y, cols, pts[k, 0], pts[k, 1])
    return bump_frame_on_axis(y, e3, pts[k, 0], pts[k, 1], pts[k, 2])


@hot
def off_face(y, model, pts, k):
    """Whether contact k has left the model: a floor point meeting the face's plane
    outside its rim, |lever| > a, beside the body, not under it (the model's contact
    does not exist there: the body has left the bumps).  Never a rim vertex, a point of
    the body itself."""
    if contact_kind(pts, k) == RIM_VERTEX_ON_PLANE:
        return False
    f = bump_frame(y, pts[k, 0], pts[k, 1], pts[k, 2])
    return f.rx * f.rx + f.ry * f.ry + f.rz * f.rz > model.radius * model.radius


@hot
def normal_velocity(y, f, kind):
    """g′ = n·(v + ω × r) of the contact with frame f (a rim vertex: v_z + (ω × r)_z)."""
    wx, wy, wz = y[WX], y[WY], y[WZ]
    if kind == RIM_VERTEX_ON_PLANE:
        return y[VZ] + (wx * f.ry - wy * f.rx)
    cx = wy * f.rz - wz * f.ry
    cy = wz * f.rx - wx * f.rz
    cz = wx * f.ry - wy * f.rx
    return f.nx * (y[VX] + cx) + f.ny * (y[VY] + cy) + f.nz * (y[VZ] + cz)


@hot
def vertex_normal_acceleration(y, f, acc):
    """g″ = v̇_z + (ω̇ × r)_z + (ω × (ω × r))_z of a vertex over flat ground, with
    (ω × (ω × r))_z = (ω·r) ω_z − |ω|² r_z."""
    wx, wy, wz = y[WX], y[WY], y[WZ]
    return (
        acc[2]
        + (acc[3] * f.ry - acc[4] * f.rx)
        + (wx * f.rx + wy * f.ry + wz * f.rz) * wz
        - (wx * wx + wy * wy + wz * wz) * f.rz
    )


@hot
def bump_normal_acceleration(y, f, acc, bx, by, bz):
    """g″ = n·v̇ + (r × n)·ω̇ + 2 v·(ω × e3) + d·(ω × (ω × e3)) of a bump, d = x − b."""
    wx, wy, wz = y[WX], y[WY], y[WZ]
    nx, ny, nz = f.nx, f.ny, f.nz
    cx, cy, cz = f.ry * nz - f.rz * ny, f.rz * nx - f.rx * nz, f.rx * ny - f.ry * nx
    lin = nx * acc[0] + ny * acc[1] + nz * acc[2] + cx * acc[3] + cy * acc[4] + cz * acc[5]
    ux, uy, uz = wy * nz - wz * ny, wz * nx - wx * nz, wx * ny - wy * nx  # ω × e3
    vx, vy, vz = wy * uz - wz * uy, wz * ux - wx * uz, wx * uy - wy * ux  # ω × (ω × e3)
    dx, dy, dz = y[X] - bx, y[Y] - by, y[Z] - bz
    return lin + 2.0 * (y[VX] * ux + y[VY] * uy + y[VZ] * uz) + dx * vx + dy * vy + dz * vz


@hot_inline
def normal_acceleration(y, f, acc, kind, pts, k):
    """g″ of contact k (of kind `kind`, frame f) for accelerations acc."""
    if kind == RIM_VERTEX_ON_PLANE:
        return vertex_normal_acceleration(y, f, acc)
    return bump_normal_acceleration(y, f, acc, pts[k, 0], pts[k, 1], pts[k, 2])


@hot
def frame_and_rate(y, cols, kind, pts, k):
    """Contact k's frame and normal velocity, without its acceleration (cols: R's
    first two columns, `rotation.rotation_columns_xy`, used by a rim vertex)."""
    if kind == RIM_VERTEX_ON_PLANE:
        f = vertex_frame(y, cols, pts[k, 0], pts[k, 1])
    else:  # FLOOR_POINT_ON_FACE
        f = bump_frame(y, pts[k, 0], pts[k, 1], pts[k, 2])
    return f, normal_velocity(y, f, kind)


@hot
def point_jet(y, px, py, acc):
    """Gap, rate, acceleration and roundoff of the body point (px, py, 0) against the
    plane z = 0 (a rim vertex)."""
    f = vertex_frame(y, rotation_columns_xy(y), px, py)
    rate = normal_velocity(y, f, RIM_VERTEX_ON_PLANE)
    return Jet(f.gap, rate, vertex_normal_acceleration(y, f, acc), f.noise)


@hot
def rim_jet(y, acc, radius):
    """Height, rate and acceleration of the body points (a, 0) and (0, a) less the
    centre's: (px, py, qx, qy, rx, ry).  A vertex at body direction c = (cos θ, sin θ)
    has gap z + c·p, rate v_z + c·q and acceleration v̇_z + c·r (all linear in c), so
    |g″| ≤ |v̇_z| + |r| for every point of the rim."""
    jx = point_jet(y, radius, 0.0, acc)
    jy = point_jet(y, 0.0, radius, acc)
    z, vz = y[Z], y[VZ]
    return jx.gap - z, jy.gap - z, jx.rate - vz, jy.rate - vz, jx.accel - acc[2], jy.accel - acc[2]


@hot
def contact_jet(y, kind, pts, k, acc):
    """Gap, rate, acceleration and gap roundoff of contact k (of kind `kind`) for
    accelerations acc."""
    if kind == RIM_VERTEX_ON_PLANE:
        return point_jet(y, pts[k, 0], pts[k, 1], acc)
    bx, by, bz = pts[k, 0], pts[k, 1], pts[k, 2]  # FLOOR_POINT_ON_FACE
    f = bump_frame(y, bx, by, bz)
    accel = bump_normal_acceleration(y, f, acc, bx, by, bz)
    return Jet(f.gap, normal_velocity(y, f, kind), accel, f.noise)


@hot
def speed(y):
    """|v|, the speed of the centre of mass."""
    return math.sqrt(y[VX] ** 2 + y[VY] ** 2 + y[VZ] ** 2)


@hot
def velocity_scale(y, radius):
    """V = |v| + a|ω|: the largest speed of a rim point (the local velocity unit)."""
    return speed(y) + radius * math.sqrt(y[WX] ** 2 + y[WY] ** 2 + y[WZ] ** 2)


@hot
def rate_noise(y, radius):
    """Roundoff level of a normal velocity: RATE_NOISE_ULPS ε V."""
    return RATE_NOISE_ULPS * EPS * velocity_scale(y, radius)


@hot
def length_scale(y, radius):
    """L = |z| + a sin α: the height of the centre plus the rim's vertical extent."""
    ex, ey, _ = body_axis(y)
    return abs(y[Z]) + radius * math.sqrt(ex * ex + ey * ey)


@hot
def length_rate(y, radius):
    """U = |ż| + a|ω × e3| ≥ |L′|: how fast L = |z| + a sin α may change (a spin about
    the body's axis leaves it)."""
    ex, ey, ez = body_axis(y)
    wx, wy, wz = y[WX], y[WY], y[WZ]
    ux, uy, uz = wy * ez - wz * ey, wz * ex - wx * ez, wx * ey - wy * ex
    return abs(y[VZ]) + radius * math.sqrt(ux * ux + uy * uy + uz * uz)


@hot
def time_resolution(noise, rate):
    """noise / |rate|: how finely the zero of a gap approaching at `rate` can be timed."""
    return (noise + TINY) / max(-rate, TINY)


@hot
def reached_together(gap, rate, noise, tres0, rate0, window_per_speed):
    """Whether a contact approaching (rate < 0) reaches the ground together with one
    reached now at normal velocity rate0 whose time resolution is tres0: its zero,
    gap/|rate| away, is within SIMULTANEOUS_FACTOR × the sum of their time resolutions
    (the model cannot order them) plus the simultaneity window on the motion's scale,
    T |rate0|/U (model.window_per_speed = T/U, U the scene's velocity unit; T = 0:
    strictly sequential).  Scaled by the speed, the window keeps apart the late impacts
    of a cascade, whose intervals shrink with the speeds (docs/laws.md, "The
    simultaneity window")."""
    window = window_per_speed * abs(rate0)
    return gap / -rate <= SIMULTANEOUS_FACTOR * (time_resolution(noise, rate) + tres0) + window


@hot
def approaching_contacts(y, model, pts, contacts, n, vnoise, out):
    """The contacts[:n] approaching the ground at y, normal velocity g′ < −vnoise, to
    `out`; returns how many (the paper's pushed contacts after an impact, the contacts
    that hit when a contact phase reaches several together)."""
    m = 0
    for i in range(n):
        kind = contact_kind(pts, contacts[i])
        if normal_velocity(y, contact_frame(y, kind, pts, contacts[i]), kind) < -vnoise:
            out[m] = contacts[i]
            m += 1
    return m
