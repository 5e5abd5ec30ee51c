"""Exact reference model of a thin polygonal disk with frictionless unilateral point
contacts and Newtonian impacts (Baranyai & Várkonyi), plus the paper's linearised model
in `reference.linear`.  Pure numerics: no I/O, no CLI."""

from .scene import Body, Ground, InitialState, RunSettings, Scene, SceneError, load_scene
from .trajectory import ImpactEvent, Phase, Status, Trajectory

__all__ = [
    "Body",
    "Ground",
    "ImpactEvent",
    "InitialState",
    "Phase",
    "RunSettings",
    "Scene",
    "SceneError",
    "Status",
    "Trajectory",
    "load_scene",
]
