"""Compiled (numba) contact kinematics over flat ground, for `reference.body.BodyModel`
and `reference.contact.contact_system`: the same formulas as their array expressions,
without numpy's per-call overhead on the handful of contacts an event touches
(tests/test_reference_body_kernel.py checks them against the array expressions)."""

from __future__ import annotations

from numba import njit

from .flight_kernel import free_angular_acceleration, rotation_xy

EPS = 2.220446049250313e-16


@njit(cache=True)
def contacts_flat(y, pts, gap, lever, vn, noise):
    """Vertex k at body position pts[k]: lever r = R p (its z from the small quaternion
    terms directly), gap = z + r_z, v_n = v_z + (ω × r)_z, noise = 8 ε (|z| + |r_z|)
    (body-frame vertices lie in the plane z = 0)."""
    R00, R01, R10, R11, R20, R21 = rotation_xy(y)
    for k in range(pts.shape[0]):
        px, py = pts[k, 0], pts[k, 1]
        rx = R00 * px + R01 * py
        ry = R10 * px + R11 * py
        rz = R20 * px + R21 * py
        lever[k, 0], lever[k, 1], lever[k, 2] = rx, ry, rz
        gap[k] = y[2] + rz
        vn[k] = y[9] + (y[10] * ry - y[11] * rx)
        noise[k] = 8 * EPS * (abs(y[2]) + abs(rz))


@njit(cache=True)
def contact_system_flat(y, pts, mass, i1, i3, g, A, b, J, Minv, acc_free):
    """(A, b, J, M⁻¹, acc_free) of reference.contact.contact_system for the vertices
    pts held on flat ground: J_k = [e_z, r_k × e_z], M⁻¹ = diag(1/m, I_w⁻¹),
    acc_free = (0, 0, −g, −I_w⁻¹(ω × I_w ω)), A = J M⁻¹ Jᵀ,
    b = J acc_free + (ω·r) ω_z − |ω|² r_z."""
    ax0, ay0, az0, e3x, e3y, e3z = free_angular_acceleration(y, i1, i3)
    e3 = (e3x, e3y, e3z)
    fi = 1.0 / i3 - 1.0 / i1
    for r in range(6):
        for c in range(6):
            Minv[r, c] = 0.0
    for r in range(3):
        Minv[r, r] = 1.0 / mass
        for c in range(3):
            Minv[3 + r, 3 + c] = fi * e3[r] * e3[c] + (1.0 / i1 if r == c else 0.0)
    acc_free[0], acc_free[1], acc_free[2] = 0.0, 0.0, -g
    acc_free[3], acc_free[4], acc_free[5] = ax0, ay0, az0
    R00, R01, R10, R11, R20, R21 = rotation_xy(y)
    wx, wy, wz = y[10], y[11], y[12]
    ww = wx * wx + wy * wy + wz * wz
    m = pts.shape[0]
    for k in range(m):
        px, py = pts[k, 0], pts[k, 1]
        rx = R00 * px + R01 * py
        ry = R10 * px + R11 * py
        rz = R20 * px + R21 * py
        J[k, 0], J[k, 1], J[k, 2] = 0.0, 0.0, 1.0
        J[k, 3], J[k, 4], J[k, 5] = ry, -rx, 0.0
        bk = 0.0
        for c in range(6):
            bk += J[k, c] * acc_free[c]
        b[k] = bk + (rx * wx + ry * wy + rz * wz) * wz - ww * rz
    for i in range(m):
        for j in range(m):
            s = 0.0
            for r in range(6):
                for c in range(6):
                    s += J[i, r] * Minv[r, c] * J[j, c]
            A[i, j] = s
