"""Oracle: unit quaternions, scalar first (w, x, y, z); rotations act body → world.

Small rotations are formed from sin(θ/2)/θ with a series near 0, so that rotation
vectors of 1e-12 keep all their digits (no 1 - cos differences).

The formulas work on the components as Python floats (`components`): numpy's scalars
and its calls on 4-element arrays cost far more than the arithmetic.  Each formula is
written once, on floats (`product`, `exp_components`, `rotation_rows`, `axis`,
`unit`); the functions that take and return arrays wrap it.
"""

from __future__ import annotations

import math

import numpy as np


def components(q) -> list[float]:
    """The components of a quaternion or vector (an array or a sequence) as Python floats."""
    return q.tolist() if isinstance(q, np.ndarray) else [float(c) for c in q]


def product(a, b) -> tuple[float, float, float, float]:
    """Hamilton product a ⊗ b of two quaternions given as sequences of floats."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a ⊗ b."""
    return np.array(product(components(a), components(b)))


def half_sinc(theta: float) -> float:
    """sin(θ/2)/θ, accurate for θ → 0."""
    if abs(theta) < 1e-4:
        t2 = theta * theta
        return 0.5 - t2 / 48.0 + t2 * t2 / 3840.0
    return math.sin(0.5 * theta) / theta


def exp_components(p0: float, p1: float, p2: float) -> tuple[float, float, float, float]:
    """exp of the rotation vector φ = (p0, p1, p2) (floats): angle |φ| about φ/|φ|."""
    theta = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
    s = half_sinc(theta)
    return (math.cos(0.5 * theta), s * p0, s * p1, s * p2)


def from_rotation_vector(phi) -> np.ndarray:
    """exp of the rotation vector φ: angle |φ| about φ/|φ|."""
    return np.array(exp_components(*components(phi)))


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


def rotation_rows(q) -> tuple[tuple[float, float, float], ...]:
    """The rows of the rotation matrix R of q (floats w, x, y, z); its third column is
    the symmetry axis R ẑ (`axis`)."""
    w, x, y, z = q
    e0, e1, e2 = axis(q)
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), e0),
        (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), e1),
        (2 * (x * z - w * y), 2 * (y * z + w * x), e2),
    )


def to_matrix(q: np.ndarray) -> np.ndarray:
    return np.array(rotation_rows(components(q)))


def axis(q) -> tuple[float, float, float]:
    """The body's symmetry axis e3 = R ẑ in world coordinates, of q (floats w, x, y, z),
    small x, y kept exact."""
    w, x, y, z = q
    return (2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y))


def body_axis(q: np.ndarray) -> np.ndarray:
    """World coordinates of the body's symmetry axis e3 = R ẑ (small x, y kept exact)."""
    return np.array(axis(components(q)))


def unit(q) -> tuple[float, ...]:
    """q / |q| of a quaternion given as floats."""
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    return (w / n, x / n, y / n, z / n)


def normalize(q: np.ndarray) -> np.ndarray:
    return np.array(unit(components(q)))


def angle_between(q1: np.ndarray, q2: np.ndarray) -> float:
    """Rotation angle of q1⁻¹ q2 in [0, π], computed from the vector part (no acos)."""
    d = multiply(np.array([q1[0], -q1[1], -q1[2], -q1[3]]), q2)
    return 2.0 * math.atan2(math.sqrt(float(d[1:] @ d[1:])), abs(d[0]))


def inclination(q: np.ndarray) -> float:
    """Angle α between the body's symmetry axis and the vertical, without 1 - cos loss:
    sin α = |(e3x, e3y)| with e3 = R ẑ."""
    e3 = body_axis(q)
    return math.atan2(math.hypot(e3[0], e3[1]), e3[2])
