"""The single-vertex drop used by the restitution studies of every engine
(engines/*_restitution.py): a pentagon tilted by θ about y (vertex 0 lowest, the next ones
≥ 0.07 a higher) falls without spin at normal speed v0, so that only vertex 0 touches the
ground in the first impact; e = −vₙ(after)/vₙ(before) of that vertex."""

from __future__ import annotations

import math

import numpy as np

from reference.scene import Scene, scene_from_dict

from .base import contact_kinematics


def single_vertex_drop(
    gamma: float, theta: float = 0.1, v0: float = 1.0, h0: float = 0.01, t_end: float = 0.06
) -> Scene:
    return scene_from_dict(
        {
            "name": f"single-vertex-drop-{gamma:g}",
            "gravity": 1.0,
            "restitution": gamma,
            "body": {"n": 5, "radius": 1.0, "mass": 1.0, "gyration": 0.5},
            "ground": {"kind": "flat"},
            "initial": {
                "position": [0.0, 0.0, math.sin(theta) + h0],
                "rotation_vector": [0.0, theta, 0.0],
                "velocity": [0.0, 0.0, -v0],
                "angular_velocity": [0.0, 0.0, 0.0],
            },
            "run": {"t_end": t_end},
        }
    )


def effective_restitution(scene: Scene, states: np.ndarray, k: int = 0) -> float:
    """−vₙ(after)/vₙ(before) of contact k around its first contact; nan if it never
    touches, 0 if it never leaves."""
    gap, vn = contact_kinematics(scene, states)
    down = np.flatnonzero(gap[:, k] <= 0.0)
    if not down.size or down[0] == 0:
        return math.nan
    j0 = int(down[0])
    up = np.flatnonzero(gap[j0:, k] > 0.0)
    if not up.size:
        return 0.0
    return float(-vn[j0 + int(up[0]), k] / vn[j0 - 1, k])
