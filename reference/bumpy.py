"""The `bumpy` ground: the floor plane z = 0 with fixed bumps above it.

The paper models the two imperfections apart (Baranyai & Várkonyi, sections 3 and 4): a
polygonal rim on a flat floor, and a flat disk on three bumps.  On this ground both act
at once, so the transition between them can be followed.  Its contacts
(`reference.scene.Ground.contacts`, reference.contact_kinds):

- contacts 0 … n−1 (kind `rim`, RIM_VERTEX_ON_PLANE): vertex k of the n-gon on the plane,
  as on `flat` ground: gap z + (R p_k)_z, normal e_z;
- contacts n … n+m−1 (kind `bump`, FLOOR_POINT_ON_FACE): bump j at the fixed world point
  (x_j, y_j, h_j) under the body's lower face, as on `three_point` ground:
  gap (x − b_j)·e3, normal e3, lever the in-plane part of b_j − x; a bump outside the
  face (|lever| > a) is not a contact of the model (the run ends `left_model`).

The bumps are lengths in the scene's units, like `bump_radius` on `three_point` ground:
by default three at radius b and equal height Δ, b_j = (b cos 2πj/3, b sin 2πj/3, Δ)
(the paper's sketch), or any list `bumps`.

This module holds what the harness asks of the ground beyond its contacts: the kind
name of each contact and the energy above the three-point rest on the bumps.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .core.records import RIM_VERTEX_ON_PLANE
from .geometry import energies

if TYPE_CHECKING:
    from .scene import Scene

BUMPY = "bumpy"
RIM, BUMP = "rim", "bump"


def is_bumpy(scene: Scene) -> bool:
    return scene.ground.kind == BUMPY


def contact_kind_names(scene: Scene) -> tuple[str, ...]:
    """The kind of each contact in the contact numbering, `rim` or `bump` (on every
    ground: `flat` has only rim vertices, `three_point` only bumps)."""
    contacts = scene.contacts
    rim = contacts.of_kind(RIM_VERTEX_ON_PLANE)
    return tuple(RIM if r else BUMP for r in rim)


def resting_height(scene: Scene) -> float:
    """Height of the centre when the disk lies flat on its bumps: the mean of the three
    highest bump heights (exact for equal heights, the default)."""
    heights = np.sort(np.asarray(scene.contacts.floor_points)[:, 2])[::-1][:3]
    return float(heights.mean()) if len(heights) else 0.0


def bumpy_excess_energy(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N,) E − ½ I3 ω3² − m g z_rest: the energy above the three-point rest on the bumps
    (z_rest = `resting_height`), the level the bumps-only motion ends at (ω3 is conserved
    there, every force being along e3).  While the rim touches the floor ω3 is not
    conserved and this is only an energy scale, positive while the centre is above z_rest."""
    S = np.asarray(states, dtype=float).reshape(-1, 13)
    ke, pe = energies(scene, S)
    i3 = scene.body.inertia_diag[2]
    q, w = S[:, 3:7], S[:, 10:13]
    e3 = np.stack(  # R ẑ from the quaternion (w, x, y, z)
        [
            2 * (q[:, 1] * q[:, 3] + q[:, 0] * q[:, 2]),
            2 * (q[:, 2] * q[:, 3] - q[:, 0] * q[:, 1]),
            1 - 2 * (q[:, 1] ** 2 + q[:, 2] ** 2),
        ],
        axis=1,
    )
    w3 = np.einsum("ij,ij->i", w, e3)
    rest = scene.body.mass * scene.gravity * resting_height(scene)
    return ke + pe - 0.5 * i3 * w3 * w3 - rest
