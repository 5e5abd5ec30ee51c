"""What a recording draws, as plain arrays (vectorised over samples): the body's outline,
the ground, the attitude angles, and the pose with its tilt exaggerated.

Conventions are the reference's (reference.geometry, reference.quaternion): quaternions
(w, x, y, z) body → world; `flat` ground is z = 0 with contact k at vertex k,
a (cos 2πk/n, sin 2πk/n, 0); `three_point` ground has bump k at
b (cos 2πk/3, sin 2πk/3, 0) touching the body's face (normal e3 = R ẑ).

Attitude: e3 = (sin α cos ψ, sin α sin ψ, cos α).  α is the inclination; ψ is the
heading of the lowest point of the rim: the rim point lowest above the ground is
a (cos α cos ψ, cos α sin ψ, −sin α) from the centre, so it lies in the direction ψ,
and ψ(t) turns once per revolution of the wobble (the precession angle).
"""

from __future__ import annotations

import math

import numpy as np

from reference import geometry as G
from reference import quaternion as qt
from reference.core.records import RIM_VERTEX_ON_PLANE
from reference.scene import Scene

TILT_TARGET = 0.35  # rad (20°): the exaggerated largest tilt of the reference
TILT_CAP = 1.4  # rad: no drawn tilt beyond this (an engine may tilt far more than the reference)


def quaternion_xyzw(quaternion_wxyz: np.ndarray) -> np.ndarray:
    """Reorder (N, 4) quaternions from our (w, x, y, z) to rerun's (x, y, z, w)."""
    q = np.asarray(quaternion_wxyz, dtype=float)
    return np.concatenate([q[:, 1:4], q[:, 0:1]], axis=1)


def inclinations(quaternion_wxyz: np.ndarray) -> np.ndarray:
    """α per sample (reference.quaternion.inclination: no 1 − cos loss)."""
    return np.atleast_1d(qt.inclination(np.asarray(quaternion_wxyz, dtype=float)))


def headings(quaternion_wxyz: np.ndarray) -> np.ndarray:
    """ψ per sample in turns, unwrapped (continuous across ±π): the direction of the
    lowest point of the rim, atan2(e3y, e3x)/(2π); NaN where the body lies exactly flat
    (α = 0, no lowest point).  Sampling coarser than half a turn of ψ cannot be
    unwrapped uniquely (near the singularity ψ turns ever faster)."""
    e3 = qt.body_axis(np.asarray(quaternion_wxyz, dtype=float))
    flat = (e3[:, 0] == 0) & (e3[:, 1] == 0)
    psi = np.arctan2(e3[:, 1], e3[:, 0])
    out = np.full(len(psi), np.nan)
    if (~flat).any():
        out[~flat] = np.unwrap(psi[~flat]) / (2 * math.pi)
    return out


def polygon_outline(n: int, radius: float) -> np.ndarray:
    """Closed outline of the regular n-gon in the body frame: (n + 1, 3), last = first."""
    ang = 2.0 * np.pi * np.arange(n + 1) / n
    return radius * np.stack([np.cos(ang), np.sin(ang), np.zeros(n + 1)], axis=1)


def polygon_fan(n: int, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Filled n-gon as a triangle fan: vertices (n + 1, 3) (centre first), triangles (n, 3)."""
    verts = np.concatenate([np.zeros((1, 3)), polygon_outline(n, radius)[:-1]])
    k = np.arange(n)
    triangles = np.stack([np.zeros(n, dtype=int), 1 + k, 1 + (k + 1) % n], axis=1)
    return verts, triangles.astype(np.uint32)


def ground_square(half_width: float, z: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """A square of the plane z = const: vertices (4, 3), two triangles (2, 3)."""
    h = half_width
    verts = np.array([[-h, -h, z], [h, -h, z], [h, h, z], [-h, h, z]], dtype=float)
    return verts, np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)


def bump_positions(scene: Scene) -> np.ndarray:
    """World positions (m, 3) of the ground's floor points, the bumps' tips
    (`GroundContacts.floor_points`)."""
    return np.array(scene.contacts.floor_points)


def pose_states(position: np.ndarray, quaternion_wxyz: np.ndarray) -> np.ndarray:
    """(N, 13) states with the given pose and zero velocities (for contact geometry)."""
    n = len(position)
    return np.concatenate(
        [np.asarray(position, float), np.asarray(quaternion_wxyz, float), np.zeros((n, 6))],
        axis=1,
    )


def contact_points(
    scene: Scene, position: np.ndarray, quaternion_wxyz: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World positions (N, k, 3) of the contact points and their gaps (N, k), gaps from
    reference.geometry.scene_contact_kinematics.

    A rim vertex: x + R r_k (gap = its height); a floor point: the point of the face
    above it, b_k + gap_k e3."""
    x = np.asarray(position, dtype=float)
    q = np.asarray(quaternion_wxyz, dtype=float)
    gap, _ = G.scene_contact_kinematics(scene, pose_states(x, q))
    contacts = scene.contacts
    pts = np.array(contacts.points)
    rim = contacts.of_kind(RIM_VERTEX_ON_PLANE)
    world = np.empty((len(x), contacts.n, 3))
    world[:, rim] = x[:, None, :] + qt.rotate(q[:, None, :], pts[None, rim, :])
    world[:, ~rim] = pts[None, ~rim, :] + gap[:, ~rim, None] * qt.body_axis(q)[:, None, :]
    return world, gap


def tilt_exaggeration(alpha_max: float) -> float:
    """A round factor k (1, 2 or 5 × 10^m, at least 1) with k·alpha_max ≤ TILT_TARGET:
    the reference's largest tilt drawn at up to 20°, so that a tilt of 0.02 rad shows."""
    if not (alpha_max > 0 and math.isfinite(alpha_max)):
        return 1.0
    raw = TILT_TARGET / alpha_max
    if raw <= 1:
        return 1.0
    decade = 10.0 ** math.floor(math.log10(raw))
    return max(m * decade for m in (1, 2, 5) if m * decade <= raw)


def exaggeration_schedule(t: np.ndarray, alpha: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """When the exaggeration changes and to what: (times, factors), factor k_j from
    times[j] on.  k(t) = `tilt_exaggeration` of the largest tilt still to come,
    max α(s ≥ t): it never decreases, so the drawing zooms in step by step (1, 2, 5 ×
    10^m) as the motion dies down, and the largest tilt still ahead is drawn at up to
    20°.  Computed from the reference so that every simulator is drawn alike."""
    a = np.asarray(alpha, float)
    if len(a) == 0:
        return np.zeros(1), np.ones(1)
    env = np.maximum.accumulate(np.where(np.isfinite(a), a, 0.0)[::-1])[::-1]
    k = np.array([tilt_exaggeration(x) for x in env])
    change = np.concatenate([[0], np.flatnonzero(np.diff(k)) + 1])
    return np.asarray(t, float)[change], k[change]


def factor_at(schedule: tuple[np.ndarray, np.ndarray], t: np.ndarray) -> np.ndarray:
    """The exaggeration factor at times t (the first before the schedule starts)."""
    times, factors = schedule
    j = np.searchsorted(times, np.asarray(t, float), side="right") - 1
    return factors[np.clip(j, 0, len(factors) - 1)]


def exaggerated_pose(
    scene: Scene,
    position: np.ndarray,
    quaternion_wxyz: np.ndarray,
    factor: float | np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """The pose drawn with its tilt and its heights above the ground × `factor` (one
    number, or one per sample).

    Attitude: the extra rotation by (α' − α) about the horizontal tilt axis
    u = ẑ × e3/|ẑ × e3| turns e3 from inclination α to α' = min(factor·α, TILT_CAP) and
    keeps the heading ψ and the spin about e3.  Position: the same horizontal position;
    the height chosen so that the lowest contact's gap is `factor` × the real one
    (a body resting on a vertex is drawn resting on it, a bounce is drawn `factor`
    times higher).  The gap is affine in the height z with slope dg/dz (1 on flat
    ground, e3z on three_point), so z' = (factor·g_min − g'_min(z = 0)) / (dg/dz)."""
    x = np.asarray(position, dtype=float)
    q = np.asarray(quaternion_wxyz, dtype=float)
    factor = np.broadcast_to(np.asarray(factor, dtype=float), (len(x),))
    if len(x) == 0 or np.all(factor == 1.0):
        return x.copy(), q.copy()
    e3 = qt.body_axis(q)
    s = np.hypot(e3[:, 0], e3[:, 1])  # sin α, from the small components
    alpha = np.arctan2(s, e3[:, 2])
    extra = np.minimum(factor * alpha, TILT_CAP) - alpha
    safe = np.where(s > 0, s, 1.0)
    u = np.stack([-e3[:, 1] / safe, e3[:, 0] / safe, np.zeros(len(s))], axis=1)
    u[s == 0] = 0.0
    q2 = qt.multiply(qt.from_rotation_vector(u * extra[:, None]), q)
    gap, _ = G.scene_contact_kinematics(scene, pose_states(x, q))
    x0 = x.copy()
    x0[:, 2] = 0.0
    gap0, _ = G.scene_contact_kinematics(scene, pose_states(x0, q2))
    slope = 1.0 if scene.contacts.rim_only else qt.body_axis(q2)[:, 2]
    x2 = x.copy()
    x2[:, 2] = (factor * gap.min(axis=1) - gap0.min(axis=1)) / slope
    return x2, q2
