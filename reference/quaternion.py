"""Unit quaternions, scalar first (w, x, y, z); rotations act body → world.

Every function takes one quaternion (shape (4,)) or a stack of them (shape (..., 4)) and
broadcasts like numpy; vectors have shape (..., 3).  The formulas are the compiled core's
(reference.core.rotation), applied row by row (reference.core.arrays): small rotations
keep their digits (sin(θ/2)/θ from its series near 0, tilts from the small quaternion
components directly), so rotation vectors of 1e-12 lose nothing.  This is the project's
one quaternion library.
"""

from __future__ import annotations

import numpy as np

from .compiled import function


def _rows(x: np.ndarray, width: int) -> tuple[np.ndarray, tuple[int, ...]]:
    x = np.asarray(x, dtype=float)
    lead = x.shape[:-1]
    return np.ascontiguousarray(x.reshape(-1, width)), lead


def _scalar(out: np.ndarray):
    return float(out) if out.ndim == 0 else out


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a ⊗ b."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    ra, lead = _rows(a, 4)
    rb, _ = _rows(b, 4)
    out = np.empty_like(ra)
    function("quaternion_product_rows")(ra, rb, out)
    return out.reshape(*lead, 4)


def conjugate(q: np.ndarray) -> np.ndarray:
    """q⁻¹ of a unit quaternion: (w, −x, −y, −z)."""
    return np.asarray(q, dtype=float) * np.array([1.0, -1.0, -1.0, -1.0])


def from_rotation_vector(phi: np.ndarray) -> np.ndarray:
    """exp of the rotation vector φ: angle |φ| about φ/|φ|."""
    r, lead = _rows(phi, 3)
    out = np.empty((len(r), 4))
    function("quaternion_exp_rows")(r, out)
    return out.reshape(*lead, 4)


def to_rotation_vector(q: np.ndarray) -> np.ndarray:
    """log of a unit quaternion: the rotation vector, angle in [0, π] (q and −q alike)."""
    r, lead = _rows(q, 4)
    out = np.empty((len(r), 3))
    function("quaternion_log_rows")(r, out)
    return out.reshape(*lead, 3)


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """R(q) v."""
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
    lead = np.broadcast_shapes(q.shape[:-1], v.shape[:-1])
    rq, _ = _rows(np.broadcast_to(q, (*lead, 4)), 4)
    rv, _ = _rows(np.broadcast_to(v, (*lead, 3)), 3)
    out = np.empty((len(rq), 3))
    function("rotate_rows")(rq, rv, out)
    return out.reshape(*lead, 3)


def body_axis(q: np.ndarray) -> np.ndarray:
    """World coordinates of the body's symmetry axis e3 = R ẑ."""
    r, lead = _rows(q, 4)
    out = np.empty((len(r), 3))
    function("axis_rows")(r, out)
    return out.reshape(*lead, 3)


def normalize(q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    return q / np.sqrt(np.sum(q * q, axis=-1, keepdims=True))


def angle_between(q1: np.ndarray, q2: np.ndarray):
    """Rotation angle of q1⁻¹ q2 in [0, π] (the same for q and −q)."""
    rv = to_rotation_vector(multiply(conjugate(q1), q2))
    return _scalar(np.sqrt(np.sum(rv * rv, axis=-1)))


def inclination(q: np.ndarray):
    """Angle α between the body's symmetry axis and the vertical, without 1 − cos loss."""
    r, lead = _rows(q, 4)
    out = np.empty(len(r))
    function("tilt_rows")(r, out)
    return _scalar(out.reshape(lead))


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
