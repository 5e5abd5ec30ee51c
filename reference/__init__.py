"""Exact reference model of a thin polygonal disk with frictionless unilateral point
contacts and Newtonian impacts (Baranyai & Várkonyi, "Imperfections, impacts, and the
singularity of Euler's disk"), plus the paper's linearised model in `reference.linear`.
Pure numerics: no I/O beyond reading scene files, no CLI.

The public API (kept stable; docs/api.md):

    from reference import Scene, load_scene, simulate, Trajectory
    from reference.linear import simulate_linear
"""

from .options import ReferenceOptions
from .scene import (
    Body,
    Ground,
    InitialState,
    RunSettings,
    Scene,
    SceneError,
    scene_from_dict,
)
from .scenes import load_scene
from .simulate import simulate
from .stats import RunStats
from .trajectory import ImpactEvent, Phase, Status, Trajectory

__all__ = [
    "Body",
    "Ground",
    "ImpactEvent",
    "InitialState",
    "Phase",
    "ReferenceOptions",
    "RunSettings",
    "RunStats",
    "Scene",
    "SceneError",
    "Status",
    "Trajectory",
    "load_scene",
    "scene_from_dict",
    "simulate",
]
