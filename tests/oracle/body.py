"""Oracle: rigid-body model of a scene in numpy (mass, inertia, contact geometry, energy).

State vector (13): position x (3), quaternion q = (w, x, y, z) body → world (4),
velocity v (3), angular velocity ω in the world frame (3).

Contacts (docs/architecture.md, "The model"):
- `flat`: contact k is vertex k, r_k = R a(cos 2πk/n, sin 2πk/n, 0); gap = z + (r_k)_z;
  normal e_z.
- `three_point`: contact k is the bump at b_k = b(cos 2πk/3, sin 2πk/3, 0); the body's
  face (plane through the centre of mass with normal e3 = R ẑ) touches it;
  gap = (x − b_k)·e3; normal e3; lever r_k = in-plane projection of b_k − x.

- `bumpy`: both at once, the n vertices on the plane z = 0 first (contacts
  0 … n−1, as on `flat`), then the bumps under the face (contacts n …, as on
  `three_point`), bump j at (x_j, y_j, h_j) above the plane.

For all, d(gap)/dt = n·(v + ω × r) and the normal acceleration is J_k [v̇; ω̇] + bias_k
with J_k = [nᵀ, (r_k × n)ᵀ].

Elementwise formulas on 3-vectors are written on Python floats (numpy's per-call cost
on such tiny arrays is far above the arithmetic; the same operations in the same order
give the same doubles); dot and matrix products stay numpy's, whose summation order
(BLAS) the results depend on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reference.geometry import contact_points
from reference.geometry import initial_state as geometry_initial_state
from reference.scene import Ground, Scene

from . import quaternion as qt

EPS = np.finfo(float).eps

X, Q, V, W = slice(0, 3), slice(3, 7), slice(7, 10), slice(10, 13)


def _cross3(a, b) -> tuple[float, float, float]:
    """a × b of two 3-vectors given as sequences of floats."""
    a0, a1, a2 = a
    b0, b1, b2 = b
    return (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b for 3-vectors or stacks of them (rows, (k, 3)); a single vector is crossed
    with every row of the other.  Much cheaper than np.cross on such small arrays: the
    components are crossed as Python floats."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.ndim == 1 and b.ndim == 1:
        return np.array(_cross3(a.tolist(), b.tolist()))
    rows_a = a.tolist() if a.ndim == 2 else [a.tolist()] * len(b)
    rows_b = b.tolist() if b.ndim == 2 else [b.tolist()] * len(a)
    rows = [_cross3(r, s) for r, s in zip(rows_a, rows_b, strict=True)]
    return np.array(rows).reshape(-1, 3)


def bumpy_points(scene: Scene) -> np.ndarray:
    """(m, 3) world bump positions of a bumpy ground, from the scene's numbers (lengths):
    `bumps` (x, y, height) when given, else three at bump_radius and bump_height."""
    g = scene.ground
    if g.bumps is not None:
        return np.array(g.bumps, dtype=float).reshape(-1, 3)
    ang = 2.0 * np.pi * np.arange(3) / 3
    b = g.bump_radius
    return np.stack([b * np.cos(ang), b * np.sin(ang), np.full(3, g.bump_height)], axis=1)


def _rim_heights(q: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """(R p)_z of body-frame points p in the plane of the polygon (p_z = 0), formed from
    the quaternion's small terms directly: R's z-row is (2(xz − wy), 2(yz + wx), ·)."""
    wq, xq, yq, zq = qt.components(q)
    return pts[:, 0] * (2 * (xq * zq - wq * yq)) + pts[:, 1] * (2 * (yq * zq + wq * xq))


def _rim_bias(lever: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(ω × (ω × r))_z = (ω·r) ω_z − |ω|² r_z of rim vertices at levers r (rows)."""
    return (lever @ w) * float(w[2]) - float(w @ w) * lever[:, 2]


def _identity_plus_axis(a: float, c: float, e3: np.ndarray) -> np.ndarray:
    """a 1 + c e3 e3ᵀ written out entry by entry, (a δ_ij) + c (e_i e_j), the operations
    of a * np.eye(3) + c * np.outer(e3, e3) (0.0 + … off the diagonal: −0.0 becomes 0.0
    there as in that sum)."""
    e0, e1, e2 = e3.tolist()
    return np.array(
        [
            [a + c * (e0 * e0), 0.0 + c * (e0 * e1), 0.0 + c * (e0 * e2)],
            [0.0 + c * (e1 * e0), a + c * (e1 * e1), 0.0 + c * (e1 * e2)],
            [0.0 + c * (e2 * e0), 0.0 + c * (e2 * e1), a + c * (e2 * e2)],
        ]
    )


@dataclass(frozen=True)
class BodyModel:
    mass: float
    i1: float  # inertia about in-plane axes, m (ρ a)²
    i3: float  # inertia about the symmetry axis, 2 m (ρ a)²
    radius: float
    gravity: float
    vertices: np.ndarray  # body-frame rim vertices on the plane, contacts 0 … n−1; (0, 3): none
    bumps: np.ndarray  # world bump positions under the face, the contacts after; (0, 3): none
    rest_height: float = 0.0  # height of the centre lying flat on the bumps

    @classmethod
    def from_scene(cls, scene: Scene) -> BodyModel:
        i1, _, i3 = scene.body.inertia_diag
        none = np.zeros((0, 3))
        kind = scene.ground.kind
        if kind == "bumpy":
            vertices = contact_points(scene.body, Ground(kind="flat"))
            bumps = bumpy_points(scene)
        elif kind == "flat":
            vertices, bumps = contact_points(scene.body, scene.ground), none
        else:
            vertices, bumps = none, contact_points(scene.body, scene.ground)
        heights = np.sort(bumps[:, 2])[::-1][:3]
        return cls(
            mass=scene.body.mass,
            i1=i1,
            i3=i3,
            radius=scene.body.radius,
            gravity=scene.gravity,
            vertices=vertices,
            bumps=bumps,
            rest_height=float(heights.mean()) if len(heights) else 0.0,
        )

    @property
    def flat(self) -> bool:
        """Only rim vertices on the plane (the `flat` ground)."""
        return len(self.bumps) == 0

    @property
    def n_rim(self) -> int:
        return len(self.vertices)

    @property
    def n_contacts(self) -> int:
        return len(self.vertices) + len(self.bumps)

    def is_bump(self, k: int) -> bool:
        return k >= self.n_rim

    # ------------------------------------------------------------------ inertia
    def inertia_world(self, q: np.ndarray) -> np.ndarray:
        """I_w = i1 1 + (i3 − i1) e3 e3ᵀ (axisymmetric body)."""
        return _identity_plus_axis(self.i1, self.i3 - self.i1, qt.body_axis(q))

    def inv_inertia_world(self, q: np.ndarray) -> np.ndarray:
        """I_w⁻¹ = 1/i1 + (1/i3 − 1/i1) e3 e3ᵀ."""
        e3 = qt.body_axis(q)
        return _identity_plus_axis(1.0 / self.i1, 1.0 / self.i3 - 1.0 / self.i1, e3)

    # ------------------------------------------------------------------ contacts
    def contacts(self, y: np.ndarray, idx=None):
        """Gap, normal, lever and normal velocity of the contacts `idx` (all by default)
        at state y.

        Returns (gap (k,), normal (k,3), lever (k,3), vn (k,), noise (k,)) where `noise`
        is the roundoff level of the gap (a few ulps of the terms that form it)."""
        idx = np.arange(self.n_contacts) if idx is None else np.asarray(idx, dtype=int)
        rim = idx < self.n_rim
        if rim.all():
            return self._rim_contacts(y, self.vertices[idx])
        if not rim.any():
            return self._bump_contacts(y, self.bumps[idx - self.n_rim])
        parts = (
            self._rim_contacts(y, self.vertices[idx[rim]]),
            self._bump_contacts(y, self.bumps[idx[~rim] - self.n_rim]),
        )
        out = []
        for a, b in zip(*parts, strict=True):
            full = np.empty((len(idx), *a.shape[1:]))
            full[rim], full[~rim] = a, b
            out.append(full)
        return tuple(out)

    def rim_gaps(self, y: np.ndarray) -> np.ndarray:
        """The gaps z + (R p)_z of every rim vertex at state y (`contacts`' first result
        for the rim contacts, without the rest)."""
        return y[2] + _rim_heights(y[Q], self.vertices)

    def _rim_contacts(self, y: np.ndarray, pts: np.ndarray):
        """Vertices (body frame) on the plane z = 0: gap z + (R p)_z, normal e_z."""
        q = y[Q]
        z, vz, w0, w1 = float(y[2]), float(y[9]), float(y[10]), float(y[11])
        lever = pts @ qt.to_matrix(q).T
        rz = _rim_heights(q, pts)
        lever[:, 2] = rz
        gap = z + rz
        normal = np.zeros(lever.shape)
        normal[:, 2] = 1.0
        vn = vz + (w0 * lever[:, 1] - w1 * lever[:, 0])
        noise = 8 * EPS * (abs(z) + np.abs(rz))
        return gap, normal, lever, vn, noise

    def _bump_contacts(self, y: np.ndarray, pts: np.ndarray):
        """World bumps under the face: gap (x − b)·e3, normal e3, lever in-plane b − x."""
        x, q, v, w = y[X], y[Q], y[V], y[W]
        e3 = qt.body_axis(q)
        d = x[None, :] - pts  # x − b_k
        gap = d @ e3
        lever = -d + gap[:, None] * e3[None, :]  # in-plane part of b_k − x
        normal = np.empty_like(lever)
        normal[:] = e3
        vn = v @ e3 + cross(w, lever) @ e3
        noise = 8 * EPS * (np.abs(d) @ np.abs(e3))
        return gap, normal, lever, vn, noise

    def jacobian(self, normal: np.ndarray, lever: np.ndarray) -> np.ndarray:
        """Rows J_k = [n_kᵀ, (r_k × n_k)ᵀ] mapping (v, ω) to normal velocities
        (flat ground: n = e_z, r × e_z = (r_y, −r_x, 0))."""
        if self.flat:  # the general row, written out (r × e_z = (r_y, −r_x, 0))
            J = np.zeros((len(lever), 6))
            J[:, 2] = 1.0
            J[:, 3] = lever[:, 1]
            J[:, 4] = -lever[:, 0]
            return J
        return np.concatenate([normal, cross(lever, normal)], axis=1)

    def bias(self, y: np.ndarray, normal: np.ndarray, lever: np.ndarray, idx=None) -> np.ndarray:
        """Velocity-product part of the normal acceleration of each contact.

        rim vertex: (ω × (ω × r))_z = (ω·r) ω_z − |ω|² r_z.
        bump: 2 v·(ω × e3) + (x − b)·(ω × (ω × e3))."""
        idx = np.arange(self.n_contacts) if idx is None else np.asarray(idx, dtype=int)
        rim = idx < self.n_rim
        if rim.all():
            return _rim_bias(lever, y[W])
        if not rim.any():
            return self._bump_bias(y, self.bumps[idx - self.n_rim])
        out = np.empty(len(idx))
        out[rim] = _rim_bias(lever[rim], y[W])
        out[~rim] = self._bump_bias(y, self.bumps[idx[~rim] - self.n_rim])
        return out

    def _bump_bias(self, y: np.ndarray, pts: np.ndarray) -> np.ndarray:
        """bias of the bumps at pts: 2 v·(ω × e3) + (x − b)·(ω × (ω × e3))."""
        v, w = y[V], y[W]
        e3 = qt.body_axis(y[Q])
        we3 = cross(w, e3)
        d = y[X][None, :] - pts
        return 2.0 * (v @ we3) + d @ cross(w, we3)

    def mass_matrix_inv(self, q: np.ndarray) -> np.ndarray:
        """M⁻¹ = diag(1/m, 1/m, 1/m, I_w⁻¹)."""
        Minv = np.zeros((6, 6))
        for i in range(3):
            Minv[i, i] = 1.0 / self.mass
        Minv[3:, 3:] = self.inv_inertia_world(q)
        return Minv

    def free_acceleration(self, y: np.ndarray) -> np.ndarray:
        """[v̇; ω̇] without contact forces: gravity and the gyroscopic term −I⁻¹(ω × Iω)."""
        q, w = y[Q], y[W]
        Iw = self.inertia_world(q)
        wdot = -self.inv_inertia_world(q) @ cross(w, Iw @ w)
        return np.array([0.0, 0.0, -self.gravity, *wdot.tolist()])

    # ------------------------------------------------------------------ energy
    def kinetic_energy(self, y: np.ndarray) -> float:
        v, w, q = y[V], y[W], y[Q]
        e3 = qt.body_axis(q)
        w3 = float(w @ e3)
        wperp2 = float(w @ w) - w3 * w3
        return 0.5 * self.mass * float(v @ v) + 0.5 * (self.i1 * wperp2 + self.i3 * w3 * w3)

    def potential_energy(self, y: np.ndarray) -> float:
        return self.mass * self.gravity * float(y[2])

    def energy(self, y: np.ndarray) -> float:
        return self.kinetic_energy(y) + self.potential_energy(y)

    def angular_momentum(self, y: np.ndarray) -> np.ndarray:
        """About the centre of mass, world frame."""
        return self.inertia_world(y[Q]) @ y[W]

    def velocity_scale(self, y: np.ndarray) -> float:
        """Largest speed of a body point on the rim: |v| + a|ω| (a local velocity unit)."""
        v0, v1, v2, w0, w1, w2 = y[7:13].tolist()
        return math.sqrt(v0 * v0 + v1 * v1 + v2 * v2) + self.radius * math.sqrt(
            w0 * w0 + w1 * w1 + w2 * w2
        )

    def length_scale(self, y: np.ndarray) -> float:
        """Local length unit: height of the centre plus the rim's vertical extent."""
        e3 = qt.body_axis(y[Q])
        return abs(float(y[2])) + self.radius * math.hypot(e3[0], e3[1])


def initial_state(scene: Scene) -> np.ndarray:
    """The scene's initial 13-component state."""
    return geometry_initial_state(scene.initial)
