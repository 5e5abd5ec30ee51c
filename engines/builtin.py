"""The entry points of the engines this package ships (group `harness.engines`, registered
in pyproject.toml like any third-party engine; docs/engines.md).

This module imports nothing heavy: each callable imports its engine when it runs, so that
listing the engines or running the reference never imports MuJoCo, PyBullet, Drake, DART
or JAX.  MuJoCo and PyBullet are core dependencies; every other engine names the pip extra
that installs its library (`extra`).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from reference.scene import Scene
from reference.trajectory import Trajectory

from .interface import engine_entry

# Largest polygon the engines and the linear model take.  Engines: one contact sphere per
# vertex; at n = 1e5 MuJoCo needs 18 s for its first ten steps (building the model) and
# PyBullet 136 s for two (measured); at 1e4 both run (0.8 s and 3.2 s for 100 steps).
# Linear model: O(n^2) memory, 0.93 GB at n = 1e4.
MAX_VERTICES = 10_000
# The linear model's grounds (reference.linear.model.NO_MIXED_GROUND: not bumpy).
LINEAR_GROUNDS = ("flat", "three_point")


def _profile(
    module: str,
    function: str,
    profile: str,
    library: str,
    doc: str,
    progress: bool = False,
    extra: str | None = None,
    ground_kinds: tuple[str, ...] | None = None,
) -> Callable:
    """An entry point that runs `module.function(scene, dt, t_end=…, profile=…)` (and
    passes `progress` on when the adapter reports it); `extra`: the pip extra that installs
    `library` (None for the core engines)."""

    @engine_entry(
        fixed_step=True,
        library=library,
        max_vertices=MAX_VERTICES,
        reports_progress=progress,
        extra=extra,
        ground_kinds=ground_kinds,
    )
    def simulate(
        scene: Scene, *, dt: float, t_end: float | None = None, progress=None
    ) -> Trajectory:
        run = getattr(importlib.import_module(module), function)
        extra = {"progress": progress} if progress is not None else {}
        return run(scene, dt, t_end=t_end, profile=profile, **extra)

    simulate.__doc__ = doc
    simulate.__qualname__ = simulate.__name__ = f"{function}[{profile}]"
    return simulate


@engine_entry(fixed_step=False)
def reference(scene: Scene, *, dt: float | None = None, t_end: float | None = None) -> Trajectory:
    """The exact event-driven reference (dt does not apply)."""
    from reference.simulate import simulate

    return simulate(scene, t_end=t_end)


@engine_entry(fixed_step=False, max_vertices=MAX_VERTICES, ground_kinds=LINEAR_GROUNDS)
def linear(scene: Scene, *, dt: float | None = None, t_end: float | None = None) -> Trajectory:
    """The paper's linear model, exact event-driven (dt does not apply)."""
    from reference.linear.simulate import simulate_linear

    return simulate_linear(scene, t_end=t_end)


mujoco = _profile(
    "engines.mujoco",
    "simulate_mujoco",
    "tuned",
    "mujoco",
    "MuJoCo, tuned contact (engines/mujoco_model.py)",
    progress=True,
)
mujoco_default = _profile(
    "engines.mujoco",
    "simulate_mujoco",
    "default",
    "mujoco",
    "MuJoCo, defaults + documented dampratio",
    progress=True,
)
pybullet = _profile(
    "engines.pybullet",
    "simulate_pybullet",
    "tuned",
    "pybullet",
    "PyBullet, tuned split-impulse contact",
    progress=True,
)
pybullet_default = _profile(
    "engines.pybullet",
    "simulate_pybullet",
    "default",
    "pybullet",
    "PyBullet, defaults + restitution",
    progress=True,
)
drake = _profile(
    "engines.drake",
    "simulate_drake",
    "sap",
    "drake",
    "Drake, discrete plant with the SAP solver",
    extra="drake",
)
drake_continuous = _profile(
    "engines.drake",
    "simulate_drake",
    "continuous",
    "drake",
    "Drake, continuous plant, error-controlled RK3 (dt = its maximum step)",
    extra="drake",
)
# DART's grounds (engines.dart.GROUND_KINDS: bumpy needs per-shape collision masks).
DART_GROUNDS = ("flat", "three_point")
dart = _profile(
    "engines.dart",
    "simulate_dart",
    "tuned",
    "dartpy",
    "DART, LCP contact: restitution gamma, units scaled past its rebound cut-off",
    progress=True,
    extra="dart",
    ground_kinds=DART_GROUNDS,
)
dart_default = _profile(
    "engines.dart",
    "simulate_dart",
    "default",
    "dartpy",
    "DART, defaults + restitution sqrt(gamma) per shape (cut-off 0.1)",
    progress=True,
    extra="dart",
    ground_kinds=DART_GROUNDS,
)


def _mjx(precision: str, name: str, doc: str) -> Callable:
    """An MJX entry point (float64 or float32) that also offers `simulate_batch`."""

    @engine_entry(fixed_step=True, library="mujoco-mjx", max_vertices=MAX_VERTICES, extra="mjx")
    def simulate(scene: Scene, *, dt: float, t_end: float | None = None, progress=None):
        from engines.mjx import simulate_mjx

        return simulate_mjx(scene, dt, t_end=t_end, precision=precision, progress=progress)

    def simulate_batch(scenes, *, dt: float, t_end: float | None = None):
        from engines.mjx import simulate_mjx_batch

        return simulate_mjx_batch(scenes, dt=dt, t_end=t_end, precision=precision)

    simulate.reports_progress = True
    simulate.simulate_batch = simulate_batch
    simulate.__doc__ = doc
    simulate.__qualname__ = simulate.__name__ = name
    return simulate


mjx = _mjx("float64", "mjx", "MJX (MuJoCo XLA) on JAX, float64: the mujoco model, diagexact off")
mjx_f32 = _mjx("float32", "mjx_f32", "MJX (MuJoCo XLA) on JAX, float32: the mujoco model")

# The entry points this package registers (pyproject.toml, group harness.engines), name →
# attribute of this module: `harness.simulators` loads these names from here without
# reading every installed distribution's metadata (start-up); tests/test_plugin_engine.py
# checks that the two lists agree.
BUILTIN_ENGINES = {
    "reference": "reference",
    "linear": "linear",
    "mujoco": "mujoco",
    "mujoco-default": "mujoco_default",
    "pybullet": "pybullet",
    "pybullet-default": "pybullet_default",
    "drake": "drake",
    "drake-continuous": "drake_continuous",
    "dart": "dart",
    "dart-default": "dart_default",
    "mjx": "mjx",
    "mjx-f32": "mjx_f32",
}
