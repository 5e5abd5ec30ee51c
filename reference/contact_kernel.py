"""Compiled (numba) contact phase over flat ground: chunks of held motion, the hot loop.

The same steps as the Python contact phase of `reference.simulate` (its specification,
tested against it in tests/test_reference_contact_kernel.py) for one or two vertices
held on flat ground: chunk horizon from the other vertices' quadratic lower bounds,
DOP853 with scipy's coefficients, error norm and step control at the same tolerances,
projection onto the constraints (positions by two Gauss–Newton passes in the mass
metric, velocities by normal impulses) after every chunk, grid samples.  Everything
that is an event goes back to Python, which owns events:

- a vertex touching at the chunk's start (hitting or landing): EXIT_EVENT, the state
  there;
- a force turning negative or another vertex crossing the ground within a chunk:
  EXIT_REDO, the state at the chunk's start; Python redoes that chunk with its dense
  output and root finding (lift-off time, crossing);
- the horizon: EXIT_T_END; a full sample buffer: EXIT_FULL; an integration failure:
  EXIT_FAIL (Python redoes the chunk and reports the failure its way).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.integrate._ivp import dop853_coefficients as _dop

from .flight_kernel import (
    EPS,
    _record_sample,
    _two_sum_add,
    free_angular_acceleration,
    gap_jet_flat,
    min_safe_step,
    rotation_xy,
)

# DOP853 (Hairer's 8(5,3)), the tableau scipy uses: 12 stages + the final derivative
N_STAGES = _dop.N_STAGES
DOP_A = np.ascontiguousarray(_dop.A[:N_STAGES, :N_STAGES])
DOP_B = np.ascontiguousarray(_dop.B)
DOP_C = np.ascontiguousarray(_dop.C[:N_STAGES])
DOP_E3 = np.ascontiguousarray(_dop.E3)
DOP_E5 = np.ascontiguousarray(_dop.E5)
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0  # scipy's step control
ERROR_EXPONENT = -1.0 / 8.0  # error estimator of order 7

EXIT_T_END = 0
EXIT_EVENT = 1
EXIT_REDO = 2
EXIT_FULL = 3
EXIT_FAIL = 4


@njit(cache=True)
def held_rhs(y, held, mass, i1, i3, g, dy, lam):
    """dy/dt with the body-frame vertices `held` (1 or 2 rows) kept on flat ground, and
    their normal forces λ (reference.contact.constrained_rhs): a_n = A λ + b = 0 in
    closed form, A = J M⁻¹ Jᵀ with J_k = [e_z, r_k × e_z]."""
    ax0, ay0, az0, e3x, e3y, e3z = free_angular_acceleration(y, i1, i3)
    R00, R01, R10, R11, R20, R21 = rotation_xy(y)
    wx, wy, wz = y[10], y[11], y[12]
    f = 1.0 / i3 - 1.0 / i1
    m = held.shape[0]
    c0x = c0y = c1x = c1y = 0.0
    i0x = i0y = i0z = i1x = i1y = i1z = 0.0
    b0 = b1 = 0.0
    ww = wx * wx + wy * wy + wz * wz
    for i in range(m):
        px, py = held[i, 0], held[i, 1]
        rx = R00 * px + R01 * py
        ry = R10 * px + R11 * py
        rz = R20 * px + R21 * py
        cx, cy = ry, -rx  # r × e_z
        ec = e3x * cx + e3y * cy
        bi = -g + cx * ax0 + cy * ay0 + (wx * rx + wy * ry + wz * rz) * wz - ww * rz
        if i == 0:
            c0x, c0y, b0 = cx, cy, bi
            i0x, i0y, i0z = cx / i1 + f * ec * e3x, cy / i1 + f * ec * e3y, f * ec * e3z
        else:
            c1x, c1y, b1 = cx, cy, bi
            i1x, i1y, i1z = cx / i1 + f * ec * e3x, cy / i1 + f * ec * e3y, f * ec * e3z
    A00 = 1.0 / mass + c0x * i0x + c0y * i0y
    if m == 1:
        lam0, lam1 = -b0 / A00, 0.0
    else:
        A11 = 1.0 / mass + c1x * i1x + c1y * i1y
        A01 = 1.0 / mass + c0x * i1x + c0y * i1y
        det = A00 * A11 - A01 * A01
        lam0 = (-b0 * A11 + b1 * A01) / det
        lam1 = (-b1 * A00 + b0 * A01) / det
    lam[0], lam[1] = lam0, lam1
    w, x, yq, z = y[3], y[4], y[5], y[6]
    dy[0], dy[1], dy[2] = y[7], y[8], y[9]
    dy[3] = 0.5 * (-wx * x - wy * yq - wz * z)
    dy[4] = 0.5 * (wx * w + wy * z - wz * yq)
    dy[5] = 0.5 * (-wx * z + wy * w + wz * x)
    dy[6] = 0.5 * (wx * yq - wy * x + wz * w)
    dy[7] = 0.0
    dy[8] = 0.0
    dy[9] = -g + (lam0 + lam1) / mass
    dy[10] = ax0 + i0x * lam0 + i1x * lam1
    dy[11] = ay0 + i0y * lam0 + i1y * lam1
    dy[12] = az0 + i0z * lam0 + i1z * lam1


@njit(cache=True)
def _impulse_directions(y, held, mass, i1, i3, cols, A):
    """Columns M⁻¹ J_kᵀ (6 each) of the held vertices into cols, A = J M⁻¹ Jᵀ."""
    w, x, yq, z = y[3], y[4], y[5], y[6]
    e3x = 2 * (x * z + w * yq)
    e3y = 2 * (yq * z - w * x)
    e3z = 1 - 2 * (x * x + yq * yq)
    f = 1.0 / i3 - 1.0 / i1
    m = held.shape[0]
    cxs = np.empty(2)
    cys = np.empty(2)
    for i in range(m):
        px, py = held[i, 0], held[i, 1]
        rx = (1 - 2 * (yq * yq + z * z)) * px + 2 * (x * yq - w * z) * py
        ry = 2 * (x * yq + w * z) * px + (1 - 2 * (x * x + z * z)) * py
        cx, cy = ry, -rx
        ec = e3x * cx + e3y * cy
        cols[i, 0] = 0.0
        cols[i, 1] = 0.0
        cols[i, 2] = 1.0 / mass
        cols[i, 3] = cx / i1 + f * ec * e3x
        cols[i, 4] = cy / i1 + f * ec * e3y
        cols[i, 5] = f * ec * e3z
        cxs[i], cys[i] = cx, cy
    for i in range(m):
        for j in range(m):
            A[i, j] = 1.0 / mass + cxs[i] * cols[j, 3] + cys[i] * cols[j, 4]


@njit(cache=True)
def _solve_held(A, r, m, out):
    """out = A⁻¹ r for m = 1 or 2."""
    if m == 1:
        out[0] = r[0] / A[0, 0]
        out[1] = 0.0
    else:
        det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
        out[0] = (r[0] * A[1, 1] - r[1] * A[0, 1]) / det
        out[1] = (r[1] * A[0, 0] - r[0] * A[1, 0]) / det


@njit(cache=True)
def project_held(y, held, mass, i1, i3):
    """Project y onto the constraints of the held vertices, in place
    (reference.contact.project_positions then project_velocities): two Gauss–Newton
    passes moving the body by M⁻¹ Jᵀ A⁻¹ (−gap) (translation, then a rotation applied
    as a quaternion), then normal impulses M⁻¹ Jᵀ A⁻¹ (−v_n)."""
    m = held.shape[0]
    cols = np.empty((2, 6))
    A = np.empty((2, 2))
    r = np.empty(2)
    mu = np.empty(2)
    for _ in range(2):
        w, x, yq, z = y[3], y[4], y[5], y[6]
        for i in range(m):
            px, py = held[i, 0], held[i, 1]
            rz = 2 * (x * z - w * yq) * px + 2 * (yq * z + w * x) * py
            r[i] = -(y[2] + rz)
        _impulse_directions(y, held, mass, i1, i3, cols, A)
        _solve_held(A, r, m, mu)
        d = np.zeros(6)
        for i in range(m):
            for c in range(6):
                d[c] += cols[i, c] * mu[i]
        y[0] += d[0]
        y[1] += d[1]
        y[2] += d[2]
        th = math.sqrt(d[3] * d[3] + d[4] * d[4] + d[5] * d[5])
        if th > 0.0:
            s = math.sin(0.5 * th) / th
            a0, a1, a2, a3 = math.cos(0.5 * th), s * d[3], s * d[4], s * d[5]
            b0, b1, b2, b3 = y[3], y[4], y[5], y[6]
            q0 = a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3
            q1 = a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2
            q2 = a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1
            q3 = a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0
            nq = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
            y[3], y[4], y[5], y[6] = q0 / nq, q1 / nq, q2 / nq, q3 / nq
    # velocities: zero normal velocity at the held vertices
    normal_impulses(y, held, mass, i1, i3, np.zeros(m))


@njit(cache=True)
def normal_impulses(y, held, mass, i1, i3, target):
    """Normal impulses at the held vertices (1 or 2) that set their normal velocities to
    `target`, in place (reference.impact.apply_normal_impulses for flat ground):
    Δ(v, ω) = M⁻¹ Jᵀ A⁻¹ (target − v_n)."""
    m = held.shape[0]
    cols = np.empty((2, 6))
    A = np.empty((2, 2))
    r = np.empty(2)
    mu = np.empty(2)
    R00, R01, R10, R11, R20, R21 = rotation_xy(y)
    for i in range(m):
        px, py = held[i, 0], held[i, 1]
        rx = R00 * px + R01 * py
        ry = R10 * px + R11 * py
        r[i] = target[i] - (y[9] + (y[10] * ry - y[11] * rx))
    _impulse_directions(y, held, mass, i1, i3, cols, A)
    _solve_held(A, r, m, mu)
    for i in range(m):
        y[9] += cols[i, 2] * mu[i]
        y[10] += cols[i, 3] * mu[i]
        y[11] += cols[i, 4] * mu[i]
        y[12] += cols[i, 5] * mu[i]


@njit(cache=True)
def impact_flat(y, pts, mass, i1, i3, gamma, vn_post):
    """Newtonian impact of the vertex pts[0] on flat ground, in place
    (reference.impact.impact_impulse): ζ = −(1 + γ) u⁻ / (J M⁻¹ Jᵀ) along J = [e_z,
    r × e_z]; vn_post receives the normal velocities of all rows of pts afterwards.
    Returns (ζ, u⁻)."""
    cols = np.empty((2, 6))
    A = np.empty((2, 2))
    R00, R01, R10, R11, R20, R21 = rotation_xy(y)
    px, py = pts[0, 0], pts[0, 1]
    rx = R00 * px + R01 * py
    ry = R10 * px + R11 * py
    u_pre = y[9] + (y[10] * ry - y[11] * rx)
    _impulse_directions(y, pts[:1], mass, i1, i3, cols, A)
    zeta = -(1.0 + gamma) * u_pre / A[0, 0]
    y[9] += cols[0, 2] * zeta
    y[10] += cols[0, 3] * zeta
    y[11] += cols[0, 4] * zeta
    y[12] += cols[0, 5] * zeta
    for j in range(pts.shape[0]):
        px, py = pts[j, 0], pts[j, 1]
        rx = R00 * px + R01 * py
        ry = R10 * px + R11 * py
        vn_post[j] = y[9] + (y[10] * ry - y[11] * rx)
    return zeta, u_pre


@njit(cache=True)
def _rms(v, scale):
    s = 0.0
    for i in range(v.shape[0]):
        s += (v[i] / scale[i]) ** 2
    return math.sqrt(s / v.shape[0])


@njit(cache=True)
def dop853_step(y, f0, h, held, mass, i1, i3, g, K, y_new, lam):
    """One DOP853 step of size h from (y, f0 = f(y)); K (13 × 13) receives the stages
    and f(y_new) as its last row.  Returns the number of RHS evaluations (12)."""
    tmp = np.empty(13)
    K[0, :] = f0
    for s in range(1, N_STAGES):
        for c in range(13):
            acc = 0.0
            for j in range(s):
                acc += DOP_A[s, j] * K[j, c]
            tmp[c] = y[c] + h * acc
        held_rhs(tmp, held, mass, i1, i3, g, K[s], lam)
    for c in range(13):
        acc = 0.0
        for j in range(N_STAGES):
            acc += DOP_B[j] * K[j, c]
        y_new[c] = y[c] + h * acc
    held_rhs(y_new, held, mass, i1, i3, g, K[N_STAGES], lam)
    return N_STAGES


@njit(cache=True)
def _error_norm(K, h, scale):
    """scipy's DOP853 error norm (rk.DOP853._estimate_error_norm)."""
    e5 = 0.0
    e3 = 0.0
    for c in range(13):
        a5 = 0.0
        a3 = 0.0
        for j in range(N_STAGES + 1):
            a5 += K[j, c] * DOP_E5[j]
            a3 += K[j, c] * DOP_E3[j]
        e5 += (a5 / scale[c]) ** 2
        e3 += (a3 / scale[c]) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * 13)


@njit(cache=True)
def integrate_held(y0, s_end, held, mass, i1, i3, g, rtol, atol, st, sy, se, ns, grid):
    """Integrate the held motion from y0 over [0, s_end] with scipy's adaptive DOP853
    (same initial step, error norm and step control).  Grid samples at local times
    grid[0] … (ascending, inside (0, s_end)) are taken by one DOP853 step from the start
    of the accepted step that contains them (shorter than it: no less accurate) and
    written with their local time in st[:, 0] (the caller adds the clock).
    Returns (ok, y_end, rhs evaluations, samples written)."""
    K = np.empty((N_STAGES + 1, 13))
    f = np.empty(13)
    lam = np.empty(2)
    y = y0.copy()
    y_new = np.empty(13)
    ys = np.empty(13)
    held_rhs(y, held, mass, i1, i3, g, f, lam)
    nfev = 1
    # initial step (scipy.integrate._ivp.common.select_initial_step, order 7)
    scale = np.empty(13)
    for c in range(13):
        scale[c] = atol[c] + abs(y[c]) * rtol
    d0 = _rms(y, scale)
    d1 = _rms(f, scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, s_end)
    for c in range(13):
        ys[c] = y[c] + h0 * f[c]
    f1 = np.empty(13)
    held_rhs(ys, held, mass, i1, i3, g, f1, lam)
    nfev += 1
    d2 = 0.0
    for c in range(13):
        d2 += ((f1[c] - f[c]) / scale[c]) ** 2
    d2 = math.sqrt(d2 / 13) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    h_abs = min(100 * h0, h1, s_end)
    t = 0.0
    gi = 0
    n_grid = grid.shape[0]
    Ks = np.empty((N_STAGES + 1, 13))
    while t < s_end:
        min_step = 10 * (math.nextafter(t, math.inf) - t)
        rejected = False
        while True:
            if h_abs < min_step:
                return False, y, nfev, ns
            t_new = min(t + h_abs, s_end)
            h = t_new - t
            nfev += dop853_step(y, f, h, held, mass, i1, i3, g, K, y_new, lam)
            for c in range(13):
                scale[c] = atol[c] + max(abs(y[c]), abs(y_new[c])) * rtol
            err = _error_norm(K, h, scale)
            if not math.isfinite(err):
                return False, y, nfev, ns
            if err < 1.0:
                factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err**ERROR_EXPONENT)
                if rejected:
                    factor = min(1.0, factor)
                h_abs = h * factor
                break
            h_abs = h * max(MIN_FACTOR, SAFETY * err**ERROR_EXPONENT)
            rejected = True
        # grid samples inside (t, t_new]
        while gi < n_grid and grid[gi] <= t_new and ns < st.shape[0]:
            hs = grid[gi] - t
            if hs > 0.0:
                nfev += dop853_step(y, f, hs, held, mass, i1, i3, g, Ks, ys, lam)
            else:
                ys[:] = y
            ns = _record_sample(ys, grid[gi], 0.0, mass, i1, i3, g, st, sy, se, ns)
            gi += 1
        y[:] = y_new
        f[:] = K[N_STAGES]
        t = t_new
    return True, y, nfev, ns


@njit(cache=True)
def contact_loop(
    y_in,
    held_idx,
    pts,
    mass,
    i1,
    i3,
    g,
    radius,
    rtol,
    gap_res,
    t_hi,
    t_lo,
    left,
    sample_dt,
    lam_prev,
    h_prev,
    st,
    sy,
    se,
):
    """Chunks of the contact phase with the vertices `held_idx` held, until an event
    (see the module doc).  Mirrors the loop of reference.simulate._contact_phase.

    lam_prev (2,) and h_prev are the forces and length of the previous chunk (h_prev = 0
    when there was none), used to shorten a chunk in which a force is falling to zero;
    they are updated in place (lam_prev) and returned.
    Returns (code, y, t_hi, t_lo, time advanced, chunks, rhs evaluations, samples,
    h_prev)."""
    n = pts.shape[0]
    m = held_idx.shape[0]
    held = np.empty((m, 3))
    is_held = np.zeros(n, dtype=np.bool_)
    for i in range(m):
        held[i, :] = pts[held_idx[i]]
        is_held[held_idx[i]] = True
    y = y_in.copy()
    dy = np.empty(13)
    lam = np.empty(2)
    lam_new = np.empty(2)
    gap = np.empty(n)
    rate = np.empty(n)
    accel = np.empty(n)
    noise = np.empty(n)
    acc6 = np.empty(6)
    atol = np.empty(13)
    grid = np.empty(st.shape[0])
    s_done = 0.0
    chunks = 0
    nfev = 0
    ns = 0
    fresh = False  # lam and the jets are those of y already (from the last chunk's end)
    while True:
        if ns + 8 >= st.shape[0]:
            return EXIT_FULL, y, t_hi, t_lo, s_done, chunks, nfev, ns, h_prev
        if not fresh:
            held_rhs(y, held, mass, i1, i3, g, dy, lam)
            for c in range(6):
                acc6[c] = dy[7 + c]
            gap_jet_flat(y, pts, acc6, gap, rate, accel, noise)
        vs = math.sqrt(y[7] ** 2 + y[8] ** 2 + y[9] ** 2) + radius * math.sqrt(
            y[10] ** 2 + y[11] ** 2 + y[12] ** 2
        )
        vnoise = 64 * EPS * vs
        acc_scale = 0.0
        for k in range(n):
            if is_held[k]:
                continue
            if gap[k] <= max(noise[k], gap_res):
                if rate[k] < -vnoise or (rate[k] <= vnoise and accel[k] < 0):
                    return EXIT_EVENT, y, t_hi, t_lo, s_done, chunks, nfev, ns, h_prev
            acc_scale = max(acc_scale, abs(accel[k]))
        # chunk horizon (reference.contact.chunk_horizon)
        K = 2.0 * acc_scale + g + 1e-300
        h = min_safe_step(gap, rate, accel, noise, is_held, K, 0.0)
        w, x, yq, z = y[3], y[4], y[5], y[6]
        e3x = 2 * (x * z + w * yq)
        e3y = 2 * (yq * z - w * x)
        L = abs(y[2]) + radius * math.sqrt(e3x * e3x + e3y * e3y)
        T_local = math.sqrt(max(L, 1e-300) / K)
        if vs > 0:
            T_local = min(T_local, 0.2 * radius / vs * 10)
        h = min(h, 0.25 * T_local)
        if h_prev > 0.0:
            for i in range(m):
                r = (lam[i] - lam_prev[i]) / h_prev
                if r < 0 and lam[i] > 0:
                    h = min(h, 1.5 * lam[i] / -r)
        h = min(h, left - s_done)
        if h <= 0:
            code = EXIT_T_END if left - s_done <= 0 else EXIT_EVENT
            return code, y, t_hi, t_lo, s_done, chunks, nfev, ns, h_prev
        # tolerances (reference.contact.integrate_chunk)
        scale_x = L + 1e-300
        scale_v = vs + 1e-300
        for c in range(3):
            atol[c] = rtol * scale_x
            atol[7 + c] = rtol * scale_v
            atol[10 + c] = rtol * scale_v / radius
        for c in range(3, 7):
            atol[c] = rtol * scale_x / radius
        # grid times inside (0, h) in local time
        kk = math.floor(t_hi / sample_dt) + 1
        n_grid = 0
        while n_grid < grid.shape[0]:
            sg = kk * sample_dt - t_hi - t_lo
            if sg >= h:
                break
            if sg > 0:
                grid[n_grid] = sg
                n_grid += 1
            kk += 1
        ns0 = ns
        ok, y_new, nf, ns = integrate_held(
            y, h, held, mass, i1, i3, g, rtol, atol, st, sy, se, ns, grid[:n_grid]
        )
        nfev += nf
        if not ok:
            return EXIT_FAIL, y, t_hi, t_lo, s_done, chunks, nfev, ns0, h_prev
        nq = math.sqrt(y_new[3] ** 2 + y_new[4] ** 2 + y_new[5] ** 2 + y_new[6] ** 2)
        for c in range(3, 7):
            y_new[c] /= nq
        project_held(y_new, held, mass, i1, i3)
        held_rhs(y_new, held, mass, i1, i3, g, dy, lam_new)
        redo = False
        for i in range(m):
            if lam_new[i] < 0:
                redo = True
        if not redo:
            # every vertex below the ground at the chunk's end, not held (the jets are
            # the next chunk's too)
            for c in range(6):
                acc6[c] = dy[7 + c]
            gap_jet_flat(y_new, pts, acc6, gap, rate, accel, noise)
            for k in range(n):
                if not is_held[k] and gap[k] < -max(noise[k], gap_res):
                    redo = True
                    break
        if redo:
            return EXIT_REDO, y, t_hi, t_lo, s_done, chunks, nfev, ns0, h_prev
        # the samples get the clock
        for i in range(ns0, ns):
            st[i, 0], st[i, 1] = _two_sum_add(t_hi, t_lo, st[i, 0])
        chunks += 1
        t_hi, t_lo = _two_sum_add(t_hi, t_lo, h)
        s_done += h
        y[:] = y_new
        lam_prev[0], lam_prev[1] = lam_new[0], lam_new[1]
        lam[0], lam[1] = lam_new[0], lam_new[1]
        fresh = True
        h_prev = h
        if left - s_done <= 0:
            return EXIT_T_END, y, t_hi, t_lo, s_done, chunks, nfev, ns, h_prev
