"""The canonical landings of `harness branches --suite`: bodies that start exactly on
several contacts (the first undecidable state at t = 0), made here so that their
touching contacts are on the ground to roundoff (the lowest contact's gap is 0)."""

from __future__ import annotations

import numpy as np

from reference import quaternion as qt
from reference.core import layout as L
from reference.geometry import scene_contact_kinematics
from reference.scene import Body, Ground, InitialState, RunSettings, Scene

from ..horizon.state import scene_at

# the square's edge from vertex 0 to vertex 1 (vertices at angles 2πk/n)
_EDGE = (-np.sin(np.pi / 4), np.cos(np.pi / 4), 0.0)

# name: (n, ground, rotation vector, velocity, angular velocity, description)
LANDINGS = {
    "landing-triangle-spin": (3, "flat", (0, 0, 0.2), (0.1, 0.0, -1.0), (0.2, -0.1, 3.0),
                              "a flat triangle landing with spin"),
    "landing-square-edge": (4, "flat", tuple(0.3 * np.array(_EDGE)), (0.1, 0.0, -0.8),
                            (0.3, -0.2, 0.5), "a square landing on an edge"),
    "landing-hexagon": (6, "flat", (0, 0, 0.1), (0.2, 0.0, -1.0), (0.3, -0.4, 0.7),
                        "a flat hexagon landing on six vertices"),
    "landing-separating": (3, "flat", (0, 0, 0), (0.0, 0.0, -0.5), (0.0, -1.0, 0.5),
                           "a flat triangle landing with vertex 0 separating"),
    "landing-three-bumps": (64, "three_point", (0, 0, 0), (0.05, 0.03, -0.8),
                            (0.2, -0.1, 0.5), "a disk landing flat on three bumps"),
    "landing-offset-bumps": (64, "three_point", (0, 0, 0), (0.05, 0.03, -0.8),
                             (0.2, -0.1, 0.5), "a disk landing flat on three bumps, its "
                             "centre off theirs: unequal effective masses"),
}  # fmt: skip
# the disk's centre off the bumps' centre (x, y), so that the bumps' Wᵢᵢ differ
_OFFSET = {"landing-offset-bumps": (0.25, 0.1)}


def landing(name: str, gamma: float = 0.5, gyration: float = 0.5, t_end: float = 1.0) -> Scene:
    """The landing `name` of LANDINGS, its lowest contacts on the ground."""
    n, ground, rot, v, w, text = LANDINGS[name]
    y = np.zeros(13)
    y[L.QUATERNION] = qt.from_rotation_vector(np.asarray(rot, dtype=float))
    y[L.VELOCITY], y[L.ANGULAR_VELOCITY] = v, w
    y[L.X], y[L.Y] = _OFFSET.get(name, (0.0, 0.0))
    base = Scene(name=name, description=text, body=Body(n=n, gyration=gyration),
                 ground=Ground(kind=ground), restitution=gamma,
                 initial=InitialState((0, 0, 0), (0, 0, 0), (0, 0, 0), (0, 0, 0)), gravity=1.0,
                 run=RunSettings(t_end=t_end, max_impacts=100_000))  # fmt: skip
    gap, _ = scene_contact_kinematics(base, y[None, :])
    y[L.Z] -= float(gap.min())
    return scene_at(base, y, t_end, 100_000)


def suite() -> list[Scene]:
    return [landing(name) for name in LANDINGS]
