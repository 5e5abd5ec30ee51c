"""Simulator registry: engine name → function(scene, dt, t_end) → Trajectory.

Engines are imported lazily so that `harness simulate --engine reference` never pays for
importing MuJoCo or PyBullet.
"""

from __future__ import annotations

from collections.abc import Callable

from reference.scene import Scene, SceneError
from reference.trajectory import Trajectory

ENGINES = (
    "reference",
    "linear",
    "mujoco",
    "mujoco-default",
    "pybullet",
    "pybullet-default",
)
FIXED_STEP = {"mujoco", "mujoco-default", "pybullet", "pybullet-default"}
DEFAULT_DT = 1e-4


def _reference(scene: Scene, dt: float | None, t_end: float | None) -> Trajectory:
    from reference.simulate import simulate

    return simulate(scene, t_end=t_end)


def _linear(scene: Scene, dt: float | None, t_end: float | None) -> Trajectory:
    from reference.linear.simulate import simulate_linear

    return simulate_linear(scene, t_end=t_end)


def _mujoco(profile: str) -> Callable:
    def run(scene: Scene, dt: float | None, t_end: float | None) -> Trajectory:
        from engines.mujoco import simulate_mujoco

        return simulate_mujoco(scene, dt=dt or DEFAULT_DT, t_end=t_end, profile=profile)

    return run


def _pybullet(profile: str) -> Callable:
    def run(scene: Scene, dt: float | None, t_end: float | None) -> Trajectory:
        from engines.pybullet import simulate_pybullet

        return simulate_pybullet(scene, dt=dt or DEFAULT_DT, t_end=t_end, profile=profile)

    return run


_RUNNERS: dict[str, Callable] = {
    "reference": _reference,
    "linear": _linear,
    "mujoco": _mujoco("tuned"),
    "mujoco-default": _mujoco("default"),
    "pybullet": _pybullet("tuned"),
    "pybullet-default": _pybullet("default"),
}


def engine_names() -> list[str]:
    """Every simulator that can run here, in a stable order (reference first)."""
    return list(ENGINES)


def is_fixed_step(name: str) -> bool:
    """Whether `--dt` applies to the simulator (fixed-step engines) or not (event-driven)."""
    return name in FIXED_STEP


def check_engine(name: str) -> str:
    if name not in _RUNNERS:
        raise SceneError(f"unknown engine {name!r}; choose from {', '.join(ENGINES)}")
    return name


def run_simulator(
    engine: str, scene: Scene, dt: float | None = None, t_end: float | None = None
) -> Trajectory:
    """Run one simulator on one scene.  `dt` applies to fixed-step engines only."""
    check_engine(engine)
    if dt is not None and not dt > 0:
        raise SceneError(f"--dt must be > 0, got {dt}")
    if t_end is not None and not t_end > 0:
        raise SceneError(f"--t-end must be > 0, got {t_end}")
    return _RUNNERS[engine](scene, dt, t_end)
