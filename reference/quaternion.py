"""Unit quaternions, scalar first (w, x, y, z); rotations act body → world.

Every function takes one quaternion (shape (4,)) or a stack of them (shape (..., 4)) and
broadcasts; vectors have shape (..., 3).  Small rotations are formed from sin(θ/2)/θ
with a series near 0 (`half_sinc`), and tilts from the small quaternion components
directly, so rotation vectors of 1e-12 keep all their digits (no 1 − cos differences).

This is the project's one quaternion library for arrays (metrics, engines, recordings,
analyses); the compiled event loop uses the scalar forms in `reference.core.rotation`,
which the tests check against these.
"""

from __future__ import annotations

import numpy as np

# |θ| below which sin(θ/2)/θ is taken from its series: the next term, θ⁶/645120, is
# below 1e-30 there, and the series has no cancellation.
HALF_SINC_SERIES_BELOW = 1e-4


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a ⊗ b."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def conjugate(q: np.ndarray) -> np.ndarray:
    """q⁻¹ of a unit quaternion: (w, −x, −y, −z)."""
    return np.asarray(q, dtype=float) * np.array([1.0, -1.0, -1.0, -1.0])


def half_sinc(theta):
    """sin(θ/2)/θ, accurate for θ → 0 (series 1/2 − θ²/48 + θ⁴/3840 below 1e-4)."""
    theta = np.asarray(theta, dtype=float)
    t2 = theta * theta
    series = 0.5 - t2 / 48.0 + t2 * t2 / 3840.0
    small = np.abs(theta) < HALF_SINC_SERIES_BELOW
    safe = np.where(small, 1.0, theta)
    out = np.where(small, series, np.sin(0.5 * safe) / safe)
    return float(out) if out.ndim == 0 else out


def from_rotation_vector(phi: np.ndarray) -> np.ndarray:
    """exp of the rotation vector φ: angle |φ| about φ/|φ|."""
    phi = np.asarray(phi, dtype=float)
    theta = np.sqrt(np.sum(phi * phi, axis=-1))
    s = np.asarray(half_sinc(theta))
    return np.concatenate([np.cos(0.5 * theta)[..., None], s[..., None] * phi], axis=-1)


def to_rotation_vector(q: np.ndarray) -> np.ndarray:
    """log of a unit quaternion: the rotation vector of angle in [0, π]
    (q and −q give the same vector)."""
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., :1] < 0, -q, q)
    v = q[..., 1:]
    s = np.sqrt(np.sum(v * v, axis=-1))
    angle = 2.0 * np.arctan2(s, q[..., 0])
    # angle/s → 2/w (1 + s²/(3 w²)) as s → 0
    small = s < 1e-8
    w = np.where(small, q[..., 0], 1.0)
    series = 2.0 / w * (1.0 + s * s / (3.0 * w * w))
    scale = np.where(small, series, angle / np.where(small, 1.0, s))
    return v * scale[..., None]


def to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix R (..., 3, 3) with R v = q v q⁻¹."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=float), -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """R(q) v: v + 2w (u × v) + 2 u × (u × v), u the vector part."""
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
    w, u = q[..., :1], q[..., 1:]
    uv = np.cross(u, v)
    return v + 2.0 * w * uv + 2.0 * np.cross(u, uv)


def body_axis(q: np.ndarray) -> np.ndarray:
    """World coordinates of the body's symmetry axis e3 = R ẑ (small x, y kept exact)."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=float), -1, 0)
    return np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], axis=-1)


def normalize(q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    return q / np.sqrt(np.sum(q * q, axis=-1, keepdims=True))


def angle_between(q1: np.ndarray, q2: np.ndarray):
    """Rotation angle of q1⁻¹ q2 in [0, π], from the vector part (no acos), the same for
    q and −q."""
    d = multiply(conjugate(q1), q2)
    out = 2.0 * np.arctan2(np.sqrt(np.sum(d[..., 1:] ** 2, axis=-1)), np.abs(d[..., 0]))
    return float(out) if np.ndim(out) == 0 else out


def inclination(q: np.ndarray):
    """Angle α between the body's symmetry axis and the vertical, without 1 − cos loss:
    α = atan2(|(e3x, e3y)|, e3z) with e3 = R ẑ."""
    e3 = body_axis(q)
    out = np.arctan2(np.hypot(e3[..., 0], e3[..., 1]), e3[..., 2])
    return float(out) if np.ndim(out) == 0 else out


def slerp_at(t_samples: np.ndarray, q_samples: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Slerp (rotation at constant rate) of sampled unit quaternions at times t, held
    constant outside the samples: q0 ⊗ exp(s log(q0⁻¹ q1)) on the shortest way."""
    t_samples = np.asarray(t_samples, dtype=float)
    n = len(t_samples)
    j = np.searchsorted(t_samples, t, side="right")
    i0, i1 = np.clip(j - 1, 0, n - 1), np.clip(j, 0, n - 1)
    h = t_samples[i1] - t_samples[i0]
    s = np.where(h > 0, (t - t_samples[i0]) / np.where(h > 0, h, 1.0), 0.0)
    s = np.clip(s, 0.0, 1.0)
    q0, q1 = q_samples[i0], q_samples[i1]
    step = to_rotation_vector(multiply(conjugate(q0), q1)) * s[:, None]
    return multiply(q0, from_rotation_vector(step))
