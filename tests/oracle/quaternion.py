"""Oracle: unit quaternions, scalar first (w, x, y, z); rotations act body → world.

Small rotations are formed from sin(θ/2)/θ with a series near 0, so that rotation
vectors of 1e-12 keep all their digits (no 1 - cos differences).

The formulas work on the components as Python floats (`components`): numpy's scalars
and its calls on 4-element arrays cost far more than the arithmetic, and the same
operations in the same order give the same doubles.
"""

from __future__ import annotations

import math

import numpy as np


def components(q) -> list[float]:
    """The components of a quaternion or vector (an array or a sequence) as Python floats."""
    return q.tolist() if isinstance(q, np.ndarray) else [float(c) for c in q]


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a ⊗ b."""
    aw, ax, ay, az = components(a)
    bw, bx, by, bz = components(b)
    return np.array(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


def half_sinc(theta: float) -> float:
    """sin(θ/2)/θ, accurate for θ → 0."""
    if abs(theta) < 1e-4:
        t2 = theta * theta
        return 0.5 - t2 / 48.0 + t2 * t2 / 3840.0
    return math.sin(0.5 * theta) / theta


def from_rotation_vector(phi) -> np.ndarray:
    """exp of the rotation vector φ: angle |φ| about φ/|φ|."""
    phi = np.asarray(phi, dtype=float)
    theta = math.sqrt(float(phi @ phi))
    s = half_sinc(theta)
    p0, p1, p2 = phi.tolist()
    return np.array([math.cos(0.5 * theta), s * p0, s * p1, s * p2])


def to_rotation_vector(q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q[0] < 0:
        q = -q
    v = q[1:]
    s = math.sqrt(float(v @ v))
    if s < 1e-8:
        return 2.0 * v / q[0] * (1.0 + s * s / (3.0 * q[0] * q[0]))
    angle = 2.0 * math.atan2(s, q[0])
    return v * (angle / s)


def to_matrix(q: np.ndarray) -> np.ndarray:
    w, x, y, z = components(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def body_axis(q: np.ndarray) -> np.ndarray:
    """World coordinates of the body's symmetry axis e3 = R ẑ (small x, y kept exact)."""
    w, x, y, z = components(q)
    return np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])


def normalize(q: np.ndarray) -> np.ndarray:
    return q / math.sqrt(float(q @ q))


def angle_between(q1: np.ndarray, q2: np.ndarray) -> float:
    """Rotation angle of q1⁻¹ q2 in [0, π], computed from the vector part (no acos)."""
    d = multiply(np.array([q1[0], -q1[1], -q1[2], -q1[3]]), q2)
    return 2.0 * math.atan2(math.sqrt(float(d[1:] @ d[1:])), abs(d[0]))


def inclination(q: np.ndarray) -> float:
    """Angle α between the body's symmetry axis and the vertical, without 1 - cos loss:
    sin α = |(e3x, e3y)| with e3 = R ẑ."""
    e3 = body_axis(q)
    return math.atan2(math.hypot(e3[0], e3[1]), e3[2])
