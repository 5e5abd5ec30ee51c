"""What a recording draws in 3D, as plain arrays: the body's outline, the ground, and the
world positions of the contact points at every sample (vectorised over samples).

Conventions are the reference's (reference.geometry): quaternions (w, x, y, z)
body → world; `flat` ground is z = 0 with contact k at vertex k,
r_k = a (cos 2πk/n, sin 2πk/n, 0); `three_point` ground has bump k at
b_k = b (cos 2πk/3, sin 2πk/3, 0) touching the body's face (normal e3 = R ẑ).
"""

from __future__ import annotations

import numpy as np

from reference.geometry import contact_points as scene_points
from reference.scene import Scene


def quaternion_xyzw(quaternion_wxyz: np.ndarray) -> np.ndarray:
    """Reorder (N, 4) quaternions from our (w, x, y, z) to rerun's (x, y, z, w)."""
    q = np.asarray(quaternion_wxyz, dtype=float)
    return np.concatenate([q[:, 1:4], q[:, 0:1]], axis=1)


def rotation_matrices(quaternion_wxyz: np.ndarray) -> np.ndarray:
    """(N, 3, 3) rotation matrices R(q) body → world for (N, 4) unit quaternions (w, x, y, z)."""
    w, x, y, z = np.asarray(quaternion_wxyz, dtype=float).T
    R = np.empty((len(w), 3, 3))
    R[:, 0, 0] = 1 - 2 * (y * y + z * z)
    R[:, 0, 1] = 2 * (x * y - w * z)
    R[:, 0, 2] = 2 * (x * z + w * y)
    R[:, 1, 0] = 2 * (x * y + w * z)
    R[:, 1, 1] = 1 - 2 * (x * x + z * z)
    R[:, 1, 2] = 2 * (y * z - w * x)
    R[:, 2, 0] = 2 * (x * z - w * y)
    R[:, 2, 1] = 2 * (y * z + w * x)
    R[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def inclinations(quaternion_wxyz: np.ndarray) -> np.ndarray:
    """α per sample: angle between e3 = R ẑ and the vertical, as atan2(|(e3x, e3y)|, e3z)
    (the same cancellation-free form as reference.quaternion.inclination)."""
    w, x, y, z = np.asarray(quaternion_wxyz, dtype=float).T
    e3x = 2 * (x * z + w * y)
    e3y = 2 * (y * z - w * x)
    e3z = 1 - 2 * (x * x + y * y)
    return np.arctan2(np.hypot(e3x, e3y), e3z)


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
    """World positions (3, 3) of the three bumps' tips, b_k = b (cos 2πk/3, sin 2πk/3, 0)."""
    ang = 2.0 * np.pi * np.arange(3) / 3
    b = scene.ground.bump_radius
    return b * np.stack([np.cos(ang), np.sin(ang), np.zeros(3)], axis=1)


def contact_points(
    scene: Scene, position: np.ndarray, quaternion_wxyz: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World positions (N, k, 3) of the contact points and their gaps (N, k).

    flat: the vertices, p_k = x + R r_k, gap_k = (p_k)_z.
    three_point: the point of the face above bump k, p_k = b_k + gap_k e3 with
    gap_k = (x − b_k)·e3 (reference.geometry)."""
    points = scene_points(scene.body, scene.ground)
    x = np.asarray(position, dtype=float)
    R = rotation_matrices(quaternion_wxyz)
    if scene.ground.kind == "flat":
        pts = x[:, None, :] + np.matmul(R, points.T).transpose(0, 2, 1)
        return pts, pts[:, :, 2].copy()
    e3 = R[:, :, 2]
    d = x[:, None, :] - points[None, :, :]
    gap = np.matmul(d, e3[:, :, None])[:, :, 0]
    pts = points[None, :, :] + gap[:, :, None] * e3[:, None, :]
    return pts, gap
