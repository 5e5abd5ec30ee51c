"""Sustained contact (paper §2.2, eqs. rollF, rollM, rollc): contacts held at zero gap
and zero normal velocity.

With the set S held, the normal accelerations are a_n = A λ + b with A = J M⁻¹ Jᵀ and
b = J a_free + bias (`contact_system`); held contacts need a_n = 0 (`held_forces`,
`held_rhs`).  Which contacts to hold solves the acceleration-level complementarity
problem λ ≥ 0, a_n ≥ 0, λ·a_n = 0, exactly, by enumerating the active sets
(`solve_lcp`).  After each integrated chunk the state is projected back onto the
constraints (`project_held`): positions by Gauss–Newton steps in the mass metric,
velocities by normal impulses (`zero_normal_velocities`), so the constraints never
drift.  Impulses act along the normals: on flat ground horizontal momentum and the
vertical angular momentum are untouched."""

import numpy as np

from .contacts import contact_frame, contact_kind, frame_at, normal_acceleration, normal_velocity
from .inertia import free_acceleration, response_on_axis
from .jit import ZERO, hot, hot_inline
from .layout import QW, QX, QY, QZ, VX, VY, VZ, WX, WY, WZ, X, Y, Z
from .linalg import solve_small
from .records import SCRATCH
from .rotation import body_axis, quaternion_rate, rotate_attitude, rotation_columns_xy
from .tolerances import PROJECTION_PASSES

# `work` in this module is a records.SCRATCH record: A (3 × 3), b, r, lam (3),
# resp (3 × 7: M⁻¹J_iᵀ and w_i), geo (3 × 6: normal and lever) of up to three contacts.


def new_work():
    """A scratch record for calls from Python (tests): keep the array, pass its [0]."""
    return np.zeros(1, dtype=SCRATCH)


@hot
def _row_dot(geo, i, resp, j):
    """J_i M⁻¹ J_jᵀ from contact i's normal and lever (geo row) and contact j's response."""
    nx, ny, nz, rx, ry, rz = geo[i, 0], geo[i, 1], geo[i, 2], geo[i, 3], geo[i, 4], geo[i, 5]
    cx, cy, cz = ry * nz - rz * ny, rz * nx - rx * nz, rx * ny - ry * nx
    return (
        nx * resp[j, 0]
        + ny * resp[j, 1]
        + nz * resp[j, 2]
        + cx * resp[j, 3]
        + cy * resp[j, 4]
        + cz * resp[j, 5]
    )


@hot_inline
def contact_system(y, model, pts, idx, m, acc, work):
    """work.A = J M⁻¹ Jᵀ, work.b = J acc + bias (normal accelerations without contact
    forces when acc is the free acceleration), work.resp rows = M⁻¹J_iᵀ and w_i, for
    the contacts idx[:m] (the attitude's terms once for all: `contacts.frame_at`).
    Inlined where it is called (numba's IR inlining), as the functions of the held
    motion's right-hand side below it: an evaluation is one call (calls between them
    made `triangle-chatter` under `moreau`, a run of 37 contact phases, 11 % slower;
    benchmarks/law_speed.py).  The attitude's terms and the mass properties are read
    before the loop stores anything: LLVM cannot tell the stores into `work` from the
    state and the model (one record), and would read and compute them again per
    contact."""
    cols, e3 = rotation_columns_xy(y), body_axis(y)
    mass, i1, i3 = model.mass, model.i1, model.i3
    for i in range(m):
        kind = contact_kind(pts, idx[i])
        f = frame_at(y, cols, e3, kind, pts, idx[i])
        rsp = response_on_axis(f, e3, mass, i1, i3)
        work.resp[i, 0], work.resp[i, 1], work.resp[i, 2] = rsp.dvx, rsp.dvy, rsp.dvz
        work.resp[i, 3], work.resp[i, 4], work.resp[i, 5] = rsp.dwx, rsp.dwy, rsp.dwz
        work.resp[i, 6] = rsp.w
        work.geo[i, 0], work.geo[i, 1], work.geo[i, 2] = f.nx, f.ny, f.nz
        work.geo[i, 3], work.geo[i, 4], work.geo[i, 5] = f.rx, f.ry, f.rz
        work.b[i] = normal_acceleration(y, f, acc, kind, pts, idx[i])
    for i in range(m):
        for j in range(m):
            work.A[i, j] = work.resp[i, 6] if i == j else _row_dot(work.geo, i, work.resp, j)


@hot_inline
def held_forces(y, model, pts, idx, m, work):
    """Normal forces λ (into work.lam) that keep contacts idx[:m] at zero normal
    acceleration: A λ = −b.  Returns the free acceleration and whether A was regular."""
    acc = free_acceleration(y, model.i1, model.i3, model.gravity)
    contact_system(y, model, pts, idx, m, acc, work)
    for i in range(m):
        work.r[i] = -work.b[i]
    return acc, solve_small(work.A, work.r, m, work.lam)


@hot_inline
def held_acceleration(y, model, pts, idx, m, work):
    """(v̇, ω̇) with contacts idx[:m] held (forces may be negative: that is the lift-off
    signal); the free acceleration when m = 0."""
    acc, _ = held_forces(y, model, pts, idx, m, work)
    return add_responses(acc, work, m)


@hot_inline
def add_responses(start, work, m):
    """start + Σ_i work.lam[i] M⁻¹J_iᵀ over the first m contacts of the contact system
    (their responses in work.resp): the change of (v, ω) that normal impulses λ_i make,
    or of (v̇, ω̇) that normal forces make, added to `start` (6 numbers)."""
    ax, ay, az, bx, by, bz = start
    for i in range(m):
        lam = work.lam[i]
        ax += lam * work.resp[i, 0]
        ay += lam * work.resp[i, 1]
        az += lam * work.resp[i, 2]
        bx += lam * work.resp[i, 3]
        by += lam * work.resp[i, 4]
        bz += lam * work.resp[i, 5]
    return ax, ay, az, bx, by, bz


@hot
def held_rhs(y, model, pts, idx, m, work, dy):
    """dy/dt of the held motion into dy (forces in work.lam): `held_derivative` in a
    call of its own."""
    held_derivative(y, model, pts, idx, m, work, dy)


@hot_inline
def held_derivative(y, model, pts, idx, m, work, dy):
    """dy/dt of the held motion into dy (forces in work.lam).  Inlined where it is
    called (numba's IR inlining): the stages of an integrator step
    (dop853.dop853_step); `held_rhs` elsewhere."""
    acc = held_acceleration(y, model, pts, idx, m, work)
    dy[X], dy[Y], dy[Z] = y[VX], y[VY], y[VZ]
    dy[QW], dy[QX], dy[QY], dy[QZ] = quaternion_rate(y)
    for c in range(6):
        dy[7 + c] = acc[c]


@hot
def zero_normal_velocities(y, model, pts, idx, m, work):
    """In place: normal impulses at contacts idx[:m] that set their normal velocities to
    zero, Δ(v, ω) = M⁻¹Jᵀ A⁻¹ (0 − u).  Returns False if A is singular."""
    if m == 0:
        return True
    acc = free_acceleration(y, model.i1, model.i3, model.gravity)
    contact_system(y, model, pts, idx, m, acc, work)
    for i in range(m):
        kind = contact_kind(pts, idx[i])
        work.r[i] = -normal_velocity(y, contact_frame(y, kind, pts, idx[i]), kind)
    if not solve_small(work.A, work.r, m, work.lam):
        return False
    y[VX], y[VY], y[VZ], y[WX], y[WY], y[WZ] = add_responses(
        (y[VX], y[VY], y[VZ], y[WX], y[WY], y[WZ]), work, m
    )
    return True


@hot
def _gaps_settled(y, model, pts, idx, m, work):
    """work.r = −gaps of contacts idx[:m]; whether each is within its roundoff."""
    settled = True
    for i in range(m):
        f = contact_frame(y, contact_kind(pts, idx[i]), pts, idx[i])
        work.r[i] = -f.gap
        if abs(f.gap) > f.noise:
            settled = False
    return settled


@hot
def project_held(y, model, pts, idx, m, work):
    """In place: project y onto the constraints of contacts idx[:m]: up to
    PROJECTION_PASSES Gauss–Newton passes moving the body by M⁻¹Jᵀ A⁻¹ (−gap) (a
    translation and a small rotation), until every gap is within its roundoff; then zero
    normal velocities."""
    for _ in range(PROJECTION_PASSES):
        if _gaps_settled(y, model, pts, idx, m, work):
            break
        acc = free_acceleration(y, model.i1, model.i3, model.gravity)
        contact_system(y, model, pts, idx, m, acc, work)
        if not solve_small(work.A, work.r, m, work.lam):
            return False
        dx, dy, dz, px, py, pz = add_responses((0.0, 0.0, 0.0, 0.0, 0.0, 0.0), work, m)
        y[X] += dx
        y[Y] += dy
        y[Z] += dz
        rotate_attitude(y, px, py, pz)
    return zero_normal_velocities(y, model, pts, idx, m, work)


@hot
def _lcp_admissible(work, m, mask, tol):
    """Whether the active set `mask` (bits over the m candidates) solves the LCP: its
    forces (into work.lam) are ≥ −tol(1 + |λ|) and every other candidate's normal
    acceleration is ≥ 0."""
    sel, As, sol = work.sel, work.As, work.sol
    s = 0
    for i in range(m):
        if mask & (1 << i):
            sel[s] = i
            s += 1
    for a in range(s):
        work.r[a] = -work.b[sel[a]]
        for c in range(s):
            As[a, c] = work.A[sel[a], sel[c]]
    for a in range(3):
        sol[a] = 0.0
    if not solve_small(As, work.r, s, sol):
        return False
    for a in range(s):
        if sol[a] < -tol * (1.0 + abs(sol[a])):
            return False
    for i in range(m):
        if mask & (1 << i):
            continue
        an = work.b[i]
        for a in range(s):
            an += work.A[i, sel[a]] * sol[a]
        if not an >= 0.0:
            return False
    for i in range(m):
        work.lam[i] = 0.0
    for a in range(s):
        work.lam[sel[a]] = sol[a]
    return True


@hot
def solve_lcp(y, model, pts, cand, m, work, active, tol=0.0):
    """Contacts to hold among the candidates cand[:m] (at zero gap and normal velocity):
    the acceleration-level LCP, by enumeration from the largest active set down (sets of
    one size in lexicographic order); the first admissible set wins (unique when A is
    positive definite; at roundoff-level ties the larger set, holding the contact).
    Writes the contacts with λ > 0 to `active` and returns their number, −1 when no
    set is admissible."""
    acc = free_acceleration(y, model.i1, model.i3, model.gravity)
    contact_system(y, model, pts, cand, m, acc, work)
    for size in range(m, -1, -1):
        for mask in range(1 << m):
            if _popcount(mask) != size or not _lcp_admissible(work, m, mask, tol):
                continue
            n = ZERO
            for i in range(m):
                if work.lam[i] > 0.0:
                    active[n] = cand[i]
                    n += 1
            return n
    return -1


@hot
def _popcount(mask):
    c = 0
    while mask:
        c += mask & 1
        mask >>= 1
    return c
