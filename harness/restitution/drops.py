"""The single-impact scenes of the restitution study: a body without spin moving down at
speed v₀ (in units of √(g a)), its watched contact `lead`·v₀ above the ground (lead: a
fraction of a step, the onset phase), so that it hits in the first step with normal
speed ≈ v₀ and nothing else touches first.

Geometries (g = a = m = 1, ρ = ½, tilt θ = 0.1):

- `vertex`: a pentagon tilted about y, vertex 0 lowest (the next ones ≥ 0.07 a higher);
  the watched point is vertex 0;
- `edge`: the pentagon tilted about the axis parallel to its edge 0–1, which lands
  flat-on (both vertices at once); the watched point is the edge's midpoint, whose gap
  and normal velocity are the mean of the two vertices' (a pair of equal impulses is one
  impulse at the midpoint, so the exact outcome is u⁺ = −γu⁻ with the midpoint's w);
- `bump`: a 64-gon over the three_point ground (bumps at b = a/2), tilted about y so that
  bump 0 meets the face first (the other two are 1.5 b sin θ farther); the watched point
  is bump 0 (normal e₃).
"""

from __future__ import annotations

import math

import numpy as np

from reference.geometry import contact_points
from reference.quaternion import from_rotation_vector, rotate
from reference.scene import Body, Ground, Scene, scene_from_dict

GEOMETRIES = ("vertex", "edge", "bump")
TILT = 0.1
PENTAGON = {"n": 5, "radius": 1.0, "mass": 1.0, "gyration": 0.5}
DISK = {"n": 64, "radius": 1.0, "mass": 1.0, "gyration": 0.5}
BUMP_RADIUS = 0.5
# The default onset phase: the watched contact starts this many steps' travel above the
# ground, so it hits within the first step and u⁻ is the initial normal speed (no fall
# under gravity first).
LEAD_STEPS = 0.5


def watched_point(geometry: str) -> tuple[np.ndarray, bool]:
    """(points (1, 3), flat) of the contact the study watches: body-frame point on flat
    ground (vertex 0, or the midpoint of edge 0–1), world bump on three_point."""
    if geometry == "vertex":
        return _pentagon_vertices()[:1], True
    if geometry == "edge":
        v = _pentagon_vertices()
        return 0.5 * (v[:1] + v[1:2]), True
    if geometry == "bump":
        return _bumps()[:1], False
    raise ValueError(f"unknown geometry {geometry!r}; choose from {', '.join(GEOMETRIES)}")


def drop_scene(geometry: str, gamma: float, speed: float, lead: float, t_end: float) -> Scene:
    """The scene of one impact: the watched contact at gap speed·lead, moving down at
    `speed`; the run lasts `t_end` (in √(a/g))."""
    rotation, ground, body = _attitude(geometry)
    q = _quaternion(rotation)
    pts, flat = watched_point(geometry)
    clearance = speed * lead
    if flat:
        z = clearance - _rotate(q, pts[0])[2]  # vertex height z + (R p)_z = clearance
        normal_z = 1.0
    else:  # bump b under the face plane through x with normal e3: (x − b)·e3 = clearance
        e3 = _rotate(q, np.array([0.0, 0.0, 1.0]))
        z = (clearance + pts[0] @ e3) / e3[2]
        normal_z = e3[2]
    return scene_from_dict(
        {
            "name": f"restitution-{geometry}-g{gamma:g}-v{speed:g}",
            "gravity": 1.0,
            "restitution": gamma,
            "body": body,
            "ground": ground,
            "initial": {
                "position": [0.0, 0.0, z],
                "rotation_vector": list(rotation),
                "velocity": [0.0, 0.0, -speed / normal_z],
                "angular_velocity": [0.0, 0.0, 0.0],
            },
            "run": {"t_end": t_end, "max_impacts": 1000},
        }
    )


def _attitude(geometry: str) -> tuple[tuple[float, float, float], dict, dict]:
    if geometry == "vertex":
        return (0.0, TILT, 0.0), {"kind": "flat"}, PENTAGON
    if geometry == "edge":  # about the axis ⟂ the edge midpoint's direction φ = π/5
        phi = math.pi / 5
        axis = (-math.sin(phi) * TILT, math.cos(phi) * TILT, 0.0)
        return axis, {"kind": "flat"}, PENTAGON
    if geometry == "bump":
        ground = {"kind": "three_point", "bump_radius": BUMP_RADIUS}
        return (0.0, TILT, 0.0), ground, DISK
    raise ValueError(f"unknown geometry {geometry!r}; choose from {', '.join(GEOMETRIES)}")


def _pentagon_vertices() -> np.ndarray:
    return contact_points(Body(**PENTAGON), Ground("flat"))


def _bumps() -> np.ndarray:
    return contact_points(Body(**DISK), Ground("three_point", BUMP_RADIUS))


def _quaternion(rotation) -> np.ndarray:
    return from_rotation_vector(np.asarray(rotation, dtype=float))


def _rotate(q: np.ndarray, p: np.ndarray) -> np.ndarray:
    return np.asarray(rotate(q, p), dtype=float)
