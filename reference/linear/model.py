"""The paper's linearised model (sections 2.4-2.6) in plain functions of plain data.

Coordinates q = (φx, φy, h), p = dq/dt = (ωx, ωy, v).  Contact k sits in the ground plane
at (x_k, y_k) (vertex k of the n-gon, or bump k of the `three_point` ground); to first
order in α its gap and normal velocity are

    gap_k = f_kᵀ q,   v_k = f_kᵀ p,   f_k = (y_k, −x_k, 1)                    (eq. fi)

because the rotation vector φ moves a point r of the plane up by (φ × r)_z = φx y − φy x.
The generalised inertia is Θ = diag(m(ρa)², m(ρa)², m) (eq. Theta) and the energy is the
quadratic form E = ½ pᵀΘp + m g h.  Between events the acceleration is constant:

    free flight:           ṗ = −g u3                                          (eq. paccfree)
    contacts B held:       ṗ = Θ⁻¹(F_Bᵀη − m g u3),  F_B Θ⁻¹ F_Bᵀ η = g 1     (eq. pacccontact)

(for one contact η = m g / (1 + |r_k|²/(ρa)²), the paper's η with |r_k| = a).  An impact
at contact k maps p⁻ to p⁺ = U_k p⁻ with

    U_k = I − (1 + γ) Θ⁻¹ f_k f_kᵀ / (f_kᵀ Θ⁻¹ f_k)                            (eq. impactequ)

and normal impulse λ = −(1 + γ) f_kᵀp⁻ / (f_kᵀΘ⁻¹f_k) (so Θ Δp = f_k λ).  The n-fold
symmetry is R = rotation by 2π/n about z acting on (φx, φy) (eq. R): R f_k = f_{k+1},
hence U_{k+1} = R U_k R⁻¹.  Scaling invariance (eqs. scaleq, scalep): if (q(t), p(t)) is
a motion, so is (β² q(t/β), β p(t/β)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

from ..core import layout as L
from ..scene import SceneError

U3 = np.array([0.0, 0.0, 1.0])

# Both kinds are linear in (q, p) near the flat state, but with different offsets: a
# rim vertex's gap is h + a (φ × e_k)_z, a bump's h − Δ_j + (φ × b_j)_z, so the two are
# never both near zero unless Δ is of the order of the tilt.  Not extended here.
NO_MIXED_GROUND = (
    "the linear model covers flat and three_point grounds, not bumpy ground (rim vertices "
    "and bumps at once): use the reference"
)


def polygon_points(n: int, radius: float = 1.0) -> np.ndarray:
    """(n, 2) positions a(cos 2πk/n, sin 2πk/n); values below 1e-15 a set to exactly 0
    so that symmetric configurations (rod, square, ...) stay exactly symmetric."""
    ang = 2.0 * np.pi * np.arange(n) / n
    pts = radius * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    pts[np.abs(pts) < 1e-15 * radius] = 0.0
    return pts


def contact_vectors(points: np.ndarray) -> np.ndarray:
    """Rows f_k = (y_k, −x_k, 1) (eq. fi)."""
    points = np.asarray(points, dtype=float)
    return np.column_stack([points[:, 1], -points[:, 0], np.ones(len(points))])


@lru_cache(maxsize=256)
def _contact_geometry(points: bytes, n_points: int) -> tuple[np.ndarray, int]:
    """(F, rank F) of the contact points given as the bytes of their (n, 2) float array:
    they depend on the points alone, and the analyses form thousands of models on the
    same polygon (a sweep map's CC and PCC regions: 5,429 (ρ, γ) cells)."""
    F = contact_vectors(np.frombuffer(points).reshape(n_points, 2))
    return F, int(np.linalg.matrix_rank(F))


def rotation(n: int) -> np.ndarray:
    """R of eq. (R): rotation by 2π/n about z, acting on (φx, φy) and leaving h."""
    c, s = math.cos(2.0 * math.pi / n), math.sin(2.0 * math.pi / n)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def theta_diag(mass: float, inertia: float) -> np.ndarray:
    """Diagonal of Θ = diag(I1, I1, m) with I1 = m (ρ a)² (eq. Theta)."""
    return np.array([inertia, inertia, mass], dtype=float)


def impact_matrix(f: np.ndarray, theta: np.ndarray, gamma: float) -> np.ndarray:
    """U with p⁺ = U p⁻ for an impact at the contact of row f (eq. impactequ; `theta` is
    diag(Θ)): p⁺ = p⁻ + Θ⁻¹ f λ with the exact core's impulse λ(u⁻) of the normal
    velocity u⁻ = fᵀp⁻ and w = fᵀ Θ⁻¹ f (reference.core.impact.impact_impulse), linear
    in u⁻ (Newton's law), so U = I + λ(1) Θ⁻¹ f fᵀ = I − (1+γ) Θ⁻¹ f fᵀ / (fᵀ Θ⁻¹ f)."""
    from ..core.impact import impact_impulse  # (numba: imported when an impact is formed)

    tf = f / theta
    return np.eye(3) + impact_impulse(1.0, float(f @ tf), gamma) * np.outer(tf, f)


def free_acceleration(gravity: float) -> np.ndarray:
    """ṗ = −g u3 in free flight (eq. paccfree)."""
    return -gravity * U3


def held_acceleration(
    f_held: np.ndarray, theta: np.ndarray, mass: float, gravity: float
) -> tuple[np.ndarray, np.ndarray]:
    """(ṗ, η) with the contacts of the rows of `f_held` held at zero normal acceleration:
    F Θ⁻¹ Fᵀ η = m g F Θ⁻¹ u3 = g 1, ṗ = Θ⁻¹(Fᵀη − m g u3) (eq. pacccontact).  The forces
    may come out negative: whether the set is admissible is the caller's question."""
    f_held = np.atleast_2d(f_held)
    if len(f_held) == 0:
        return free_acceleration(gravity), np.zeros(0)
    W = (f_held / theta) @ f_held.T
    eta = np.linalg.solve(W, gravity * np.ones(len(f_held)))
    acc = (f_held.T @ eta) / theta - gravity * U3
    return acc, eta


def contact_acceleration(f: np.ndarray, theta: np.ndarray, mass: float, gravity: float):
    """a_contact of eq. (pacccontact): one contact held, η = m g/(1 + |r|²/(ρa)²)."""
    return held_acceleration(f[None, :], theta, mass, gravity)[0]


def energy(q, p, theta, mass: float, gravity: float) -> float:
    """E = ½ pᵀΘp + m g h: exactly conserved by the linear flight and contact phases.
    Plain arithmetic on the three components, so that the linear kernel compiles this
    same function (kernel._energy)."""
    return 0.5 * (theta[0] * p[0] * p[0] + theta[1] * p[1] * p[1] + theta[2] * p[2] * p[2]) + (
        mass * gravity * q[2]
    )


@dataclass(frozen=True)
class LinearModel:
    """Everything the linear simulator and the analyses need about a body on its ground.

    `points` are the contact positions in the ground plane, `symmetry` the order n of the
    rotation R that maps contact k to k+1 (n for an n-gon, 3 for the three bumps)."""

    points: np.ndarray
    mass: float
    inertia: float  # I1 = m (ρ a)²
    gravity: float
    restitution: float
    symmetry: int

    @classmethod
    def polygon(
        cls,
        n: int,
        gyration: float,
        restitution: float,
        gravity: float = 1.0,
        mass: float = 1.0,
        radius: float = 1.0,
    ) -> LinearModel:
        """Regular n-gon of circumradius a on flat ground, I1 = m (ρ a)²."""
        if n < 2:
            raise ValueError(f"n must be >= 2, got {n}")
        if not gyration > 0:
            raise ValueError(f"gyration must be > 0, got {gyration}")
        return cls(
            points=polygon_points(n, radius),
            mass=float(mass),
            inertia=float(mass * (gyration * radius) ** 2),
            gravity=float(gravity),
            restitution=float(restitution),
            symmetry=n,
        )

    @classmethod
    def from_scene(cls, scene) -> LinearModel:
        """Flat ground: vertices of the n-gon.  `three_point`: the bumps at radius b,
        with the body's inertia m (ρ a)² (a = body radius): in units of b the gyration
        is ρ a / b (docs/glossary.md, ρ)."""
        body = scene.body
        i1 = body.inertia_diag[0]
        contacts = scene.contacts
        if contacts.has_plane and len(contacts.floor_points):
            raise SceneError(NO_MIXED_GROUND)
        if contacts.has_plane:
            pts, sym = polygon_points(body.n, body.radius), body.n
        else:
            floor = contacts.floor_points
            pts, sym = polygon_points(len(floor), contacts.lever(0)), len(floor)
        return cls(
            points=pts,
            mass=float(body.mass),
            inertia=float(i1),
            gravity=float(scene.gravity),
            restitution=float(scene.restitution),
            symmetry=sym,
        )

    @property
    def n_contacts(self) -> int:
        return len(self.points)

    # The matrices below are formed once per model: the analyses ask for them thousands
    # of times.  They stay writeable (a read-only array is another type to the compiled
    # kernel, which takes F and Θ), and no caller writes into them.
    @cached_property
    def F(self) -> np.ndarray:
        return self._geometry[0]

    @cached_property
    def _geometry(self) -> tuple[np.ndarray, int]:
        """(F, rank F), shared by the models on the same contact points."""
        points = np.ascontiguousarray(self.points, dtype=float)
        return _contact_geometry(points.tobytes(), len(points))

    @cached_property
    def theta(self) -> np.ndarray:
        return theta_diag(self.mass, self.inertia)

    @cached_property
    def R(self) -> np.ndarray:
        return rotation(self.symmetry)

    def U(self, k: int = 0) -> np.ndarray:
        k = int(k)
        if k not in self._impact_matrices:
            self._impact_matrices[k] = impact_matrix(self.F[k], self.theta, self.restitution)
        return self._impact_matrices[k]

    @cached_property
    def _impact_matrices(self) -> dict[int, np.ndarray]:
        """U(k) of the contacts asked for so far, by k."""
        return {}

    def a_contact(self, k: int = 0) -> np.ndarray:
        return contact_acceleration(self.F[k], self.theta, self.mass, self.gravity)

    @property
    def a_free(self) -> np.ndarray:
        return free_acceleration(self.gravity)

    def energy(self, q, p) -> float:
        return float(energy(np.asarray(q), np.asarray(p), self.theta, self.mass, self.gravity))

    @cached_property
    def rank(self) -> int:
        """Rank of the contact vectors: 3 for n >= 3 (three contacts down ⇒ q = 0), 2 for
        the rod (φx, the roll about the rod's own axis, is invisible to its contacts)."""
        return self._geometry[1]


def linear_state(scene) -> tuple[np.ndarray, np.ndarray]:
    """(q, p) of a scene: its [initial] q/p when given, else read off the full state:
    q = (rotation vector x, y, position z), p = (ω x, ω y, velocity z)."""
    ini = scene.initial
    if ini.q is not None and ini.p is not None:
        return np.array(ini.q, dtype=float), np.array(ini.p, dtype=float)
    rv, x, w, v = ini.rotation_vector, ini.position, ini.angular_velocity, ini.velocity
    return np.array([rv[0], rv[1], x[2]]), np.array([w[0], w[1], v[2]])


def full_states(q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(N, 13) full states [x, quaternion wxyz, v, ω world] of linear states (N, 3) each:
    attitude = rotation vector (φx, φy, 0), centre (0, 0, h), velocity (0, 0, v),
    ω = (ωx, ωy, 0) (docs/contract.md)."""
    q = np.atleast_2d(q)
    p = np.atleast_2d(p)
    N = len(q)
    y = np.zeros((N, L.STATE_SIZE))
    y[:, L.Z] = q[:, 2]
    theta = np.hypot(q[:, 0], q[:, 1])
    small = theta < 1e-4
    t2 = theta * theta
    with np.errstate(invalid="ignore", divide="ignore"):
        hs = np.where(small, 0.5 - t2 / 48.0 + t2 * t2 / 3840.0, np.sin(0.5 * theta) / theta)
    y[:, L.QW] = np.cos(0.5 * theta)
    y[:, L.QX] = hs * q[:, 0]
    y[:, L.QY] = hs * q[:, 1]
    y[:, L.VZ] = p[:, 2]
    y[:, L.WX] = p[:, 0]
    y[:, L.WY] = p[:, 1]
    return y
