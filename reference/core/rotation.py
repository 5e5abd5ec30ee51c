"""Quaternion primitives for one state (scalars, compiled).  Unit quaternions
(w, x, y, z), body → world, at y[QUATERNION] of a state (reference.core.layout).
Small rotations keep their digits: sin(θ/2)/θ from its series near 0, and the tilt
terms of R from the small quaternion components directly (reference.quaternion is the
same library for arrays)."""

import math

from .jit import hot
from .layout import QW, QX, QY, QZ, WX, WY, WZ

HALF_SINC_SERIES_BELOW = 1e-4  # the series' next term, θ⁶/645120, is < 1e-30 there


@hot
def half_sinc(theta):
    """sin(θ/2)/θ, accurate for θ → 0."""
    if abs(theta) < HALF_SINC_SERIES_BELOW:
        t2 = theta * theta
        return 0.5 - t2 / 48.0 + t2 * t2 / 3840.0
    return math.sin(0.5 * theta) / theta


@hot
def qmul(a0, a1, a2, a3, b0, b1, b2, b3):
    """Hamilton product a ⊗ b."""
    return (
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    )


@hot
def rotation_vector_quaternion(px, py, pz):
    """exp of the rotation vector (px, py, pz): angle |p| about p/|p|."""
    th = math.sqrt(px * px + py * py + pz * pz)
    s = half_sinc(th)
    return math.cos(0.5 * th), s * px, s * py, s * pz


@hot
def rotate_attitude(y, px, py, pz):
    """In place: the attitude of state y turned by the world rotation vector p,
    q ← normalize(exp(p) ⊗ q)."""
    a0, a1, a2, a3 = rotation_vector_quaternion(px, py, pz)
    q0, q1, q2, q3 = qmul(a0, a1, a2, a3, y[QW], y[QX], y[QY], y[QZ])
    set_attitude(y, q0, q1, q2, q3)


@hot
def set_attitude(y, q0, q1, q2, q3):
    """In place: y's quaternion ← (q0, q1, q2, q3) normalised."""
    nq = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    y[QW], y[QX], y[QY], y[QZ] = q0 / nq, q1 / nq, q2 / nq, q3 / nq


@hot
def axis_of(w, x, yq, z):
    """e3 = R ẑ of the quaternion (w, x, y, z): the body's symmetry axis in the world
    frame (its tilt components from the small quaternion terms directly)."""
    return 2 * (x * z + w * yq), 2 * (yq * z - w * x), 1 - 2 * (x * x + yq * yq)


@hot
def body_axis(y):
    """e3 of state y."""
    return axis_of(y[QW], y[QX], y[QY], y[QZ])


@hot
def rotation_columns_xy(y):
    """The first two columns of R: (R00, R01, R10, R11, R20, R21); the z row (the tilt
    terms) from the small quaternion components directly."""
    w, x, yq, z = y[QW], y[QX], y[QY], y[QZ]
    return (
        1 - 2 * (yq * yq + z * z),
        2 * (x * yq - w * z),
        2 * (x * yq + w * z),
        1 - 2 * (x * x + z * z),
        2 * (x * z - w * yq),
        2 * (yq * z + w * x),
    )


@hot
def quaternion_rate(y):
    """dq/dt = ½ (0, ω) ⊗ q for the world angular velocity ω = y[ANGULAR_VELOCITY]."""
    wx, wy, wz = y[WX], y[WY], y[WZ]
    w, x, yq, z = y[QW], y[QX], y[QY], y[QZ]
    return (
        0.5 * (-wx * x - wy * yq - wz * z),
        0.5 * (wx * w + wy * z - wz * yq),
        0.5 * (-wx * z + wy * w + wz * x),
        0.5 * (wx * yq - wy * x + wz * w),
    )


@hot
def quaternion_log(q0, q1, q2, q3):
    """The rotation vector of a unit quaternion, angle in [0, π] (q and −q alike):
    2 atan2(|u|, w) u/|u|, with the series 2/w (1 + |u|²/(3w²)) for tiny |u|."""
    if q0 < 0:
        q0, q1, q2, q3 = -q0, -q1, -q2, -q3
    s = math.sqrt(q1 * q1 + q2 * q2 + q3 * q3)
    if s < 1e-8:
        scale = 2.0 / q0 * (1.0 + s * s / (3.0 * q0 * q0))
    else:
        scale = 2.0 * math.atan2(s, q0) / s
    return q1 * scale, q2 * scale, q3 * scale


@hot
def rotate_vector(q0, q1, q2, q3, vx, vy, vz):
    """R(q) v = v + 2w (u × v) + 2 u × (u × v), u the vector part."""
    cx, cy, cz = q2 * vz - q3 * vy, q3 * vx - q1 * vz, q1 * vy - q2 * vx
    dx, dy, dz = q2 * cz - q3 * cy, q3 * cx - q1 * cz, q1 * cy - q2 * cx
    return vx + 2.0 * (q0 * cx + dx), vy + 2.0 * (q0 * cy + dy), vz + 2.0 * (q0 * cz + dz)


@hot
def tilt(w, x, yq, z):
    """The inclination α of the body axis from the vertical, atan2(|(e3x, e3y)|, e3z)
    (no 1 − cos loss)."""
    ex, ey, ez = axis_of(w, x, yq, z)
    return math.atan2(math.sqrt(ex * ex + ey * ey), ez)
