"""The `bumpy` ground (issue 32): the floor plane z = 0 with fixed bumps above it.

The paper models the two imperfections apart (Baranyai & Várkonyi, sections 3 and 4): a
polygonal rim on a flat floor, and a flat disk on three bumps.  On this ground both act
at once, so the transition between them can be followed:

- contacts 0 … n−1 (kind `rim`): vertex k of the n-gon on the plane, as on `flat`
  ground: gap z + (R p_k)_z, normal e_z;
- contacts n … n+m−1 (kind `bump`): bump j at the fixed world point
  a (x_j, y_j, h_j) under the body's lower face, as on `three_point` ground:
  gap (x − b_j)·e3, normal e3, lever the in-plane part of b_j − x; a bump outside the
  face (|lever| > a) is not a contact of the model (the run ends `left_model`, as on
  `three_point` ground).

The bumps are given in units of the body's radius a, like `bump_radius` on
`three_point` ground: by default three at radius b and equal height Δ,
b_j = (b cos 2πj/3, b sin 2πj/3, Δ) (the paper's sketch), or any list `bumps`.

This module holds the ground's description (`BumpyGround`), its scene-file table
(`bumpy_ground`), the contact kinds and the vectorised contact kinematics of arrays of
states (the rim part and the bump part are `reference.geometry.contact_kinematics` of
the flat and the face kind).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .geometry import contact_kinematics, contact_points, energies
from .scene import MIN_BUMP_RADIUS, Ground, SceneError

if TYPE_CHECKING:
    from .scene import Scene

BUMPY = "bumpy"
RIM, BUMP = "rim", "bump"
# Default bump height Δ/a: the paper's estimate puts the takeover at a tilt α ≈ Δ/d, so
# 1e-3 a (Δ = 5e-5 m on the paper's d = 0.1 m disk) lies inside its range 1e-5 … 1e-4 m.
DEFAULT_BUMP_HEIGHT = 1e-3
# A bump at height ≥ a would hold the disk above its own radius: no longer "a floor with
# small bumps"; the heights are imperfections of the floor, Δ ≪ a.
MAX_BUMP_HEIGHT = 1.0
MAX_BUMPS = 64
_KEYS = {"kind", "bump_radius", "bump_height", "bumps"}


@dataclass(frozen=True)
class BumpyGround(Ground):
    """The floor plane z = 0 plus bumps (x, y, height) in units of the body radius:
    `bumps` when given, else three at `bump_radius` of equal `bump_height`."""

    kind: str = BUMPY
    bump_radius: float = 0.5
    bump_height: float = DEFAULT_BUMP_HEIGHT
    bumps: tuple[tuple[float, float, float], ...] | None = None

    def bump_table(self) -> tuple[tuple[float, float, float], ...]:
        """(x, y, height) of every bump, in units of the body radius."""
        if self.bumps is not None:
            return self.bumps
        b, h = self.bump_radius, self.bump_height
        return tuple(
            (b * math.cos(2 * math.pi * j / 3), b * math.sin(2 * math.pi * j / 3), h)
            for j in range(3)
        )


def is_bumpy(scene: Scene) -> bool:
    return scene.ground.kind == BUMPY


def bump_positions(ground: BumpyGround, radius: float) -> np.ndarray:
    """(m, 3) world positions a (x_j, y_j, h_j) of the bumps."""
    return radius * np.asarray(ground.bump_table(), dtype=float).reshape(-1, 3)


def contact_kinds(scene: Scene) -> tuple[str, ...]:
    """The kind of each contact in the contact numbering: n `rim`, then m `bump`."""
    m = len(scene.ground.bump_table())
    return (RIM,) * scene.body.n + (BUMP,) * m


def n_contacts(scene: Scene) -> int:
    return scene.body.n + len(scene.ground.bump_table())


def bumpy_contact_kinematics(scene: Scene, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gap and normal velocity (N, n + m) of every contact: the rim vertices on the plane,
    then the bumps under the face."""
    vertices = contact_points(scene.body, Ground(kind="flat"))
    bumps = bump_positions(scene.ground, scene.body.radius)
    g_rim, v_rim = contact_kinematics(states, vertices, True)
    g_bump, v_bump = contact_kinematics(states, bumps, False)
    return np.concatenate([g_rim, g_bump], axis=1), np.concatenate([v_rim, v_bump], axis=1)


def resting_height(scene: Scene) -> float:
    """Height of the centre when the disk lies flat on its bumps: a times the mean of the
    three highest bump heights (exact for equal heights, the default)."""
    heights = sorted((h for _, _, h in scene.ground.bump_table()), reverse=True)[:3]
    return scene.body.radius * float(np.mean(heights))


def bumpy_excess_energy(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N,) E − ½ I3 ω3² − m g z_rest: the energy above the three-point rest on the bumps
    (z_rest = `resting_height`), the level the bumps-only motion ends at (ω3 is conserved
    there, every force being along e3).  While the rim touches the floor ω3 is not
    conserved and this is only an energy scale, positive while the centre is above z_rest."""
    S = np.asarray(states, dtype=float).reshape(-1, 13)
    ke, pe = energies(scene, S)
    i3 = scene.body.inertia_diag[2]
    w = S[:, 10:13]
    q = S[:, 3:7]
    # e3 = R ẑ from the quaternion (w, x, y, z)
    e3 = np.stack(
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


# --------------------------------------------------------------------------- scene file


def bumpy_ground(table: Mapping[str, Any]) -> BumpyGround:
    """The `[ground]` table of a scene with kind = "bumpy" (docs/contract.md): either
    `bump_radius` and `bump_height` (units of the radius) or `bumps = [[x, y, height], …]`."""
    unknown = sorted(set(table) - _KEYS)
    if unknown:
        raise SceneError(
            f"[ground] has unknown key(s) {unknown}; a bumpy ground takes {sorted(_KEYS)}"
        )
    if "bumps" in table:
        if "bump_radius" in table or "bump_height" in table:
            raise SceneError(
                "[ground] give either bumps = [[x, y, height], …] or bump_radius and "
                "bump_height, not both"
            )
        return BumpyGround(bumps=_bump_list(table["bumps"]))
    b = _number("bump_radius", table.get("bump_radius", 0.5))
    if not MIN_BUMP_RADIUS <= b < 1.0:
        raise SceneError(
            f"[ground] bump_radius = {b:g} must lie in [{MIN_BUMP_RADIUS:g}, 1) "
            "(units of the radius)"
        )
    h = _number("bump_height", table.get("bump_height", DEFAULT_BUMP_HEIGHT))
    _check_height("bump_height", h)
    return BumpyGround(bump_radius=b, bump_height=h)


def _number(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise SceneError(f"[ground] {name} must be a finite number, got {value!r}")
    return float(value)


def _check_height(name: str, h: float) -> None:
    if not 0.0 <= h < MAX_BUMP_HEIGHT:
        raise SceneError(
            f"[ground] {name} = {h:g} must lie in [0, {MAX_BUMP_HEIGHT:g}) (units of the radius)"
        )


def _bump_list(value: Any) -> tuple[tuple[float, float, float], ...]:
    if not isinstance(value, list) or not 1 <= len(value) <= MAX_BUMPS:
        raise SceneError(
            f"[ground] bumps must be a list of 1 to {MAX_BUMPS} [x, y, height] triples"
        )
    out = []
    for j, item in enumerate(value):
        if not isinstance(item, list) or len(item) != 3:
            raise SceneError(f"[ground] bumps[{j}] must be [x, y, height], got {item!r}")
        x, y, h = (_number(f"bumps[{j}]", v) for v in item)
        if math.hypot(x, y) >= 1.0:
            raise SceneError(
                f"[ground] bumps[{j}] lies {math.hypot(x, y):g} radii from the axis: a bump "
                "must lie under the disk (less than 1 radius)"
            )
        _check_height(f"bumps[{j}] height", h)
        out.append((x, y, h))
    return tuple(out)
