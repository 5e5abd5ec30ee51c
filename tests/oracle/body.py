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

Each formula is written once, on components (`rim_contact`, `bump_contact`, `dot3`,
`cross3`, `_axisymmetric`): Python floats for one contact (the held contacts of a
contact phase, a few contacts: numpy's per-call cost on such tiny arrays is far above
the arithmetic), or numpy arrays with one entry per contact for many at once
(`contact_arrays` on every vertex of a large polygon).  Both give the same doubles: the
elementwise operations are the same, in the same order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np

from reference.geometry import contact_points
from reference.geometry import initial_state as geometry_initial_state
from reference.scene import Ground, Scene

from . import quaternion as qt

EPS = np.finfo(float).eps

X, Q, V, W = slice(0, 3), slice(3, 7), slice(7, 10), slice(10, 13)

E_Z = (0.0, 0.0, 1.0)
# up to this many contacts, contact_arrays evaluates them one by one on floats (faster
# than numpy's per-call cost on arrays that short)
FEW_CONTACTS = 8
_UNIT = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def dot3(a, b):
    """a·b of 3-vectors given by components: floats, or arrays (one entry per contact)."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross3(a, b):
    """a × b of 3-vectors given by components: floats, or arrays (one entry per contact)."""
    a0, a1, a2 = a
    b0, b1, b2 = b
    return (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)


def combine(vectors, weights) -> tuple[float, float, float]:
    """Σ_k w_k u_k of 3-vectors u_k (floats)."""
    s0 = s1 = s2 = 0.0
    for (u0, u1, u2), wk in zip(vectors, weights, strict=True):
        s0 += wk * u0
        s1 += wk * u1
        s2 += wk * u2
    return (s0, s1, s2)


class State(NamedTuple):
    """A 13-component state's parts as Python floats, with the symmetry axis e3 = R ẑ."""

    x: list[float]
    q: list[float]
    v: list[float]
    w: list[float]
    e3: tuple[float, float, float]


def state(y) -> State:
    """The parts of state y (an array or a sequence) as Python floats."""
    c = qt.components(y)
    q = c[3:7]
    return State(c[0:3], q, c[7:10], c[10:13], qt.axis(q))


class Contact(NamedTuple):
    """Kinematics of one contact, or of k contacts at once: gap, normal n, lever r, the
    Jacobian row's angular part r × n, normal velocity n·(v + ω × r), the gap's roundoff
    level (a few ulps of the terms that form it) and the velocity-product part of the
    normal acceleration (bias).  Scalars are floats, or (k,) arrays; vectors are their
    three components, each a float or a (k,) array."""

    gap: Any
    normal: Any
    lever: Any
    row: Any
    vn: Any
    noise: Any
    bias: Any


def rim_contact(s: State, R, p0, p1) -> Contact:
    """Vertex p = (p0, p1, 0) (body frame) on the plane z = 0, R the rotation's rows:
    lever r = R p (r_z from R's z-row (2(xz − wy), 2(yz + wx)): the quaternion's small
    terms directly), gap z + r_z, normal e_z, normal velocity v_z + (ω × r)_z, roundoff
    8ε(|z| + |r_z|), bias (ω × (ω × r))_z = (ω·r) ω_z − |ω|² r_z."""
    r = (
        R[0][0] * p0 + R[0][1] * p1,
        R[1][0] * p0 + R[1][1] * p1,
        R[2][0] * p0 + R[2][1] * p1,
    )
    z, w = s.x[2], s.w
    return Contact(
        gap=z + r[2],
        normal=E_Z,
        lever=r,
        row=cross3(r, E_Z),
        vn=s.v[2] + (w[0] * r[1] - w[1] * r[0]),
        noise=8 * EPS * (abs(z) + abs(r[2])),
        bias=dot3(r, w) * w[2] - dot3(w, w) * r[2],
    )


def bump_contact(s: State, b0, b1, b2) -> Contact:
    """World bump b under the face, d = x − b: gap d·e3, normal e3, lever r = gap e3 − d
    (the in-plane part of b − x), normal velocity v·e3 + (ω × r)·e3, roundoff
    8ε |d|·|e3|, bias 2 v·(ω × e3) + d·(ω × (ω × e3))."""
    x, e3, v, w = s.x, s.e3, s.v, s.w
    d = (x[0] - b0, x[1] - b1, x[2] - b2)
    gap = dot3(d, e3)
    r = (gap * e3[0] - d[0], gap * e3[1] - d[1], gap * e3[2] - d[2])
    we3 = cross3(w, e3)
    return Contact(
        gap=gap,
        normal=e3,
        lever=r,
        row=cross3(r, e3),
        vn=dot3(v, e3) + dot3(cross3(w, r), e3),
        noise=8 * EPS * dot3([abs(c) for c in d], [abs(c) for c in e3]),
        bias=2.0 * dot3(v, we3) + dot3(d, cross3(w, we3)),
    )


def row_dot(c: Contact, lin, ang):
    """J_k [lin; ang] = n·lin + (r × n)·ang (floats, or arrays over contacts)."""
    return dot3(c.normal, lin) + dot3(c.row, ang)


def _rows(columns, k: int) -> np.ndarray:
    """(k, 3) array of a 3-vector given by components (arrays of k, or floats shared)."""
    out = np.empty((k, 3))
    for i in range(3):
        out[:, i] = columns[i]
    return out


def _axisymmetric(a: float, c: float, e3, u) -> tuple[float, float, float]:
    """(a 1 + c e3 e3ᵀ) u = a u + c (e3·u) e3 (floats)."""
    k = c * dot3(e3, u)
    return (a * u[0] + k * e3[0], a * u[1] + k * e3[1], a * u[2] + k * e3[2])


def solve(A, rhs) -> list[float]:
    """x with A x = rhs, for the small systems of held contacts (A: rows of floats):
    1 × 1 and 2 × 2 in closed form (Cramer's rule), larger ones by LAPACK (numpy).
    np.linalg.LinAlgError when A is exactly singular."""
    k = len(rhs)
    if k > 2:
        return np.linalg.solve(np.array(A), np.array(rhs)).tolist()
    if k == 0:
        return []
    det = A[0][0] if k == 1 else A[0][0] * A[1][1] - A[0][1] * A[1][0]
    if det == 0.0:
        raise np.linalg.LinAlgError("singular matrix")
    if k == 1:
        return [rhs[0] / det]
    return [
        (rhs[0] * A[1][1] - rhs[1] * A[0][1]) / det,
        (rhs[1] * A[0][0] - rhs[0] * A[1][0]) / det,
    ]


def bumpy_points(scene: Scene) -> np.ndarray:
    """(m, 3) world bump positions of a bumpy ground, from the scene's numbers (lengths):
    `bumps` (x, y, height) when given, else three at bump_radius and bump_height."""
    g = scene.ground
    if g.bumps is not None:
        return np.array(g.bumps, dtype=float).reshape(-1, 3)
    ang = 2.0 * np.pi * np.arange(3) / 3
    b = g.bump_radius
    return np.stack([b * np.cos(ang), b * np.sin(ang), np.full(3, g.bump_height)], axis=1)


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

    @cached_property
    def _points(self) -> list[tuple[float, ...]]:
        """Each contact's point as floats: (p0, p1) of a vertex, (b0, b1, b2) of a bump."""
        return [(p[0], p[1]) for p in self.vertices.tolist()] + [
            tuple(b) for b in self.bumps.tolist()
        ]

    # ------------------------------------------------------------------ inertia
    def inertia(self, e3, u) -> tuple[float, float, float]:
        """I_w u with I_w = i1 1 + (i3 − i1) e3 e3ᵀ (axisymmetric body; floats)."""
        return _axisymmetric(self.i1, self.i3 - self.i1, e3, u)

    def inv_inertia(self, e3, u) -> tuple[float, float, float]:
        """I_w⁻¹ u with I_w⁻¹ = 1/i1 + (1/i3 − 1/i1) e3 e3ᵀ (floats)."""
        return _axisymmetric(1.0 / self.i1, 1.0 / self.i3 - 1.0 / self.i1, e3, u)

    def mass_matrix_inv(self, q: np.ndarray) -> np.ndarray:
        """M⁻¹ = diag(1/m, 1/m, 1/m, I_w⁻¹)."""
        e3 = qt.axis(qt.components(q))
        Minv = np.zeros((6, 6))
        for i in range(3):
            Minv[i, i] = 1.0 / self.mass
        Minv[3:, 3:] = np.array([self.inv_inertia(e3, u) for u in _UNIT]).T
        return Minv

    # ------------------------------------------------------------------ contacts
    def contact_list(self, s: State, idx) -> list[Contact]:
        """The contacts `idx` at state s, one Contact of floats each."""
        n_rim, pts = self.n_rim, self._points
        R = qt.rotation_rows(s.q) if n_rim else None
        return [rim_contact(s, R, *pts[k]) if k < n_rim else bump_contact(s, *pts[k]) for k in idx]

    def contact_arrays(self, s: State, idx=None) -> Contact:
        """The contacts `idx` (all by default) at state s, as one Contact of arrays:
        scalars (k,), vectors as their three components ((k,) arrays, or floats shared
        by all)."""
        idx = np.arange(self.n_contacts) if idx is None else np.asarray(idx, dtype=int)
        if 0 < len(idx) <= FEW_CONTACTS:  # the same formulas on floats: the same doubles
            fields = zip(*self.contact_list(s, idx.tolist()), strict=True)
            return Contact(*(np.array(f).T for f in fields))
        rim = idx < self.n_rim
        if rim.all():
            return self._rim_arrays(s, idx)
        if not rim.any():
            return self._bump_arrays(s, idx)
        a, b = self._rim_arrays(s, idx[rim]), self._bump_arrays(s, idx[~rim])

        def merged(u, v):
            full = np.empty(len(idx))
            full[rim], full[~rim] = u, v
            return full

        return Contact(
            *(
                tuple(map(merged, u, v)) if isinstance(u, tuple) else merged(u, v)
                for u, v in zip(a, b, strict=True)
            )
        )

    def _rim_arrays(self, s: State, idx: np.ndarray) -> Contact:
        pts = self.vertices[idx]
        return rim_contact(s, qt.rotation_rows(s.q), pts[:, 0], pts[:, 1])

    def _bump_arrays(self, s: State, idx: np.ndarray) -> Contact:
        b = self.bumps[idx - self.n_rim]
        return bump_contact(s, b[:, 0], b[:, 1], b[:, 2])

    def contacts(self, y: np.ndarray, idx=None):
        """Gap, normal, lever and normal velocity of the contacts `idx` (all by default)
        at state y.

        Returns (gap (k,), normal (k,3), lever (k,3), vn (k,), noise (k,)) where `noise`
        is the roundoff level of the gap (a few ulps of the terms that form it)."""
        c = self.contact_arrays(state(y), idx)
        k = len(c.gap)
        return c.gap, _rows(c.normal, k), _rows(c.lever, k), c.vn, c.noise

    def rim_gaps(self, y: np.ndarray) -> np.ndarray:
        """The gaps z + (R p)_z of every rim vertex at state y (`contacts`' first result
        for the rim contacts, without the rest)."""
        return self._rim_arrays(state(y), np.arange(self.n_rim)).gap

    def jacobian(self, normal, lever) -> np.ndarray:
        """Rows J_k = [n_kᵀ, (r_k × n_k)ᵀ] mapping (v, ω) to normal velocities, of normals
        and levers given as rows (k, 3) or sequences of 3-vectors."""
        normal = np.asarray(normal, dtype=float).reshape(-1, 3)
        lever = np.asarray(lever, dtype=float).reshape(-1, 3)
        return np.column_stack([normal, *cross3(lever.T, normal.T)])

    def delassus(self, s: State, cs: list[Contact]) -> list[list[float]]:
        """A = J M⁻¹ Jᵀ of the contacts cs at state s: A_ij = n_i·n_j / m
        + (r_i × n_i)·I_w⁻¹(r_j × n_j) (paper eq. F's J M⁻¹ Jᵀ for i = j)."""
        m = self.mass
        iu = [self.inv_inertia(s.e3, c.row) for c in cs]
        return [
            [
                dot3(ci.normal, cj.normal) / m + dot3(ci.row, iuj)
                for cj, iuj in zip(cs, iu, strict=True)
            ]
            for ci in cs
        ]

    def response(self, s: State, cs: list[Contact], lam) -> list[float]:
        """Δ[v; ω] = M⁻¹ Jᵀ λ of normal impulses (or forces) λ at the contacts cs."""
        m = self.mass
        f = combine([c.normal for c in cs], lam)
        dw = self.inv_inertia(s.e3, combine([c.row for c in cs], lam))
        return [f[0] / m, f[1] / m, f[2] / m, *dw]

    def free_acc(self, s: State) -> list[float]:
        """[v̇; ω̇] without contact forces: gravity and the gyroscopic term −I⁻¹(ω × Iω)."""
        wd = self.inv_inertia(s.e3, cross3(s.w, self.inertia(s.e3, s.w)))
        return [0.0, 0.0, -self.gravity, -wd[0], -wd[1], -wd[2]]

    def free_acceleration(self, y: np.ndarray) -> np.ndarray:
        """[v̇; ω̇] without contact forces (`free_acc`) as an array."""
        return np.array(self.free_acc(state(y)))

    # ------------------------------------------------------------------ energy
    def kinetic_energy(self, y: np.ndarray) -> float:
        s = state(y)
        w3 = dot3(s.w, s.e3)
        wperp2 = dot3(s.w, s.w) - w3 * w3
        return 0.5 * self.mass * dot3(s.v, s.v) + 0.5 * (self.i1 * wperp2 + self.i3 * w3 * w3)

    def potential_energy(self, y: np.ndarray) -> float:
        return self.mass * self.gravity * float(y[2])

    def energy(self, y: np.ndarray) -> float:
        return self.kinetic_energy(y) + self.potential_energy(y)

    def angular_momentum(self, y: np.ndarray) -> np.ndarray:
        """About the centre of mass, world frame."""
        s = state(y)
        return np.array(self.inertia(s.e3, s.w))

    def velocity_scale(self, y: np.ndarray) -> float:
        """Largest speed of a body point on the rim: |v| + a|ω| (a local velocity unit)."""
        v0, v1, v2, w0, w1, w2 = y[7:13].tolist()
        return math.sqrt(v0 * v0 + v1 * v1 + v2 * v2) + self.radius * math.sqrt(
            w0 * w0 + w1 * w1 + w2 * w2
        )

    def length_scale(self, y: np.ndarray) -> float:
        """Local length unit: height of the centre plus the rim's vertical extent."""
        e0, e1, _ = qt.axis(y[Q].tolist())
        return abs(float(y[2])) + self.radius * math.hypot(e0, e1)


def initial_state(scene: Scene) -> np.ndarray:
    """The scene's initial 13-component state."""
    return geometry_initial_state(scene.initial)
