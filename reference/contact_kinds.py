"""A ground as a list of contacts of kinds: the description the reference core, the
geometry, the metrics, the recordings and the engine adapters build their models from.

The kinds (reference.core.records; their geometry is reference.core.contacts):

- RIM_VERTEX_ON_PLANE: a body-frame rim vertex a(cos 2πk/n, sin 2πk/n, 0) against the
  plane z = 0, normal +z (engines: a sphere on the body above a plane);
- FLOOR_POINT_ON_FACE: a fixed world point touching the body's face, normal e3 (engines:
  a sphere on the ground below a thin box on the body).

Each contact's kind is stored with it (`GroundContacts.kinds`; the core's points carry
it in a column, `core_points`), read by the core, the guard and the recordings alike.
A ground lists its rim vertices first (contacts 0 … n_rim − 1, in order round the
rim), then its floor points; `reference.scene.Ground.contacts` builds the list from a
scene's [ground] table, and is the one place that reads `ground.kind`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .core.records import (
    FLOOR_POINT_ON_FACE,
    KEEPS_PLANE_MOMENTA,
    KEEPS_SPIN,
    KIND_COLUMN,
    POINT_COLUMNS,
    RIM_VERTEX_ON_PLANE,
)

# What each kind is called in text (a contact's label: 'v2', 'b1'), and the invariants
# of the motion its contact force keeps (records.KEEPS_*: vertical forces keep the
# horizontal momentum and L_z, forces along e3 the spin ω3).
KIND_LABEL = {RIM_VERTEX_ON_PLANE: "v", FLOOR_POINT_ON_FACE: "b"}
KIND_KEEPS = {RIM_VERTEX_ON_PLANE: KEEPS_PLANE_MOMENTA, FLOOR_POINT_ON_FACE: KEEPS_SPIN}


@dataclass(frozen=True, eq=False)
class GroundContacts:
    """The contacts of a ground: `points` (n, 3), read-only, rows 0 … n_rim − 1 the rim
    vertices' body-frame points, the rest the floor points' world points; `kinds` (n,)
    each contact's kind."""

    points: np.ndarray
    kinds: np.ndarray

    @property
    def n_rim(self) -> int:
        """How many rim vertices (they come first)."""
        return int(np.count_nonzero(self.kinds == RIM_VERTEX_ON_PLANE))

    @functools.cached_property
    def core_points(self) -> np.ndarray:
        """(n, POINT_COLUMNS) C-contiguous: the points and, in column KIND_COLUMN, the
        kinds: what the compiled core reads (contacts.contact_kind)."""
        out = np.zeros((self.n, POINT_COLUMNS))
        out[:, :3] = self.points
        out[:, KIND_COLUMN] = self.kinds
        out.setflags(write=False)
        return out

    def of_kind(self, kind: int) -> np.ndarray:
        """(n,) bool: which contacts are of `kind`."""
        return self.kinds == kind

    @property
    def n(self) -> int:
        return len(self.points)

    @property
    def rim_points(self) -> np.ndarray:
        """(n_rim, 3) body-frame rim vertices (kind RIM_VERTEX_ON_PLANE)."""
        return self.points[: self.n_rim]

    @property
    def floor_points(self) -> np.ndarray:
        """(m, 3) world floor points (kind FLOOR_POINT_ON_FACE)."""
        return self.points[self.n_rim :]

    @property
    def has_plane(self) -> bool:
        """Whether the ground has the plane z = 0 (its rim vertices touch it)."""
        return bool(np.any(self.of_kind(RIM_VERTEX_ON_PLANE)))

    @property
    def rim_only(self) -> bool:
        """Whether every contact is a rim vertex on the plane (then the circle through
        the vertices bounds every gap from below: z − a sin α)."""
        return bool(np.all(self.of_kind(RIM_VERTEX_ON_PLANE)))

    def kind(self, k: int) -> int:
        """The kind of contact k (`reference.core.contacts.contact_kind`)."""
        return int(self.kinds[k])

    def label(self, k: int) -> str:
        """'v2' (rim vertex 2) or 'b1' (floor point 1: numbered among the contacts of its
        kind); '#k' for a number that is no contact of this ground."""
        if not 0 <= k < self.n:
            return f"#{k}"
        kind = self.kind(k)
        return f"{KIND_LABEL[kind]}{int(np.count_nonzero(self.kinds[:k] == kind))}"

    def lever(self, k: int) -> float:
        """Contact k's distance from the symmetry axis when the body lies flat on the
        ground, centred: a for a rim vertex, the floor point's radius b."""
        return float(np.hypot(self.points[k, 0], self.points[k, 1]))

    @property
    def invariants(self) -> int:
        """The records.KEEPS_* bits every contact force keeps (inertia.excess_energy)."""
        keeps = KEEPS_PLANE_MOMENTA | KEEPS_SPIN
        for kind in set(self.kinds.tolist()):
            keeps &= KIND_KEEPS[kind]
        return keeps

    @property
    def all_down(self) -> int:
        """How many contacts held together end the motion: all of them, at most three
        (the rod lies on its two vertices; three contacts fix the body)."""
        return min(self.n, 3)


@functools.lru_cache(maxsize=64)
def ground_contacts(n_rim: int, radius: float, n_floor: int, floor_radius: float):
    """GroundContacts of n_rim rim vertices a(cos 2πk/n_rim, sin 2πk/n_rim, 0) then
    n_floor floor points b(cos 2πk/n_floor, sin 2πk/n_floor, 0) (shared between calls
    with the same geometry)."""
    parts = [_regular_points(n_rim, radius), _regular_points(n_floor, floor_radius)]
    pts = np.concatenate(parts) if n_rim and n_floor else parts[0] if n_rim else parts[1]
    pts.setflags(write=False)
    return GroundContacts(pts, _kinds(n_rim, n_floor))


def _kinds(n_rim: int, n_floor: int) -> np.ndarray:
    """(n_rim + n_floor,) read-only: n_rim rim vertices, then n_floor floor points."""
    kinds = np.array([RIM_VERTEX_ON_PLANE] * n_rim + [FLOOR_POINT_ON_FACE] * n_floor)
    kinds = kinds.astype(np.int64)
    kinds.setflags(write=False)
    return kinds


@functools.lru_cache(maxsize=64)
def listed_contacts(
    n_rim: int, radius: float, floor_points: tuple[tuple[float, float, float], ...]
) -> GroundContacts:
    """GroundContacts of n_rim rim vertices a(cos 2πk/n_rim, sin 2πk/n_rim, 0) then the
    floor points given (world (x, y, z), e.g. bumps above the plane: the bumpy ground)."""
    pts = np.concatenate(
        [_regular_points(n_rim, radius), np.asarray(floor_points, dtype=float).reshape(-1, 3)]
    )
    pts.setflags(write=False)
    return GroundContacts(pts, _kinds(n_rim, len(pts) - n_rim))


def _regular_points(k: int, r: float) -> np.ndarray:
    """(k, 3): r (cos 2πi/k, sin 2πi/k, 0)."""
    ang = 2.0 * np.pi * np.arange(k) / k
    return r * np.stack([np.cos(ang), np.sin(ang), np.zeros(k)], axis=1)
