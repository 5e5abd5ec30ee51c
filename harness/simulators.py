"""Simulator registry: every engine is an entry point in the group `harness.engines`.

An entry point names a callable `simulate(scene, *, dt, t_end) -> Trajectory`; its
attribute `fixed_step` (default True) says whether `--dt` applies.  This package registers
its own engines the same way (pyproject.toml), so nothing here names an engine and an
engine installed from another package is used exactly like a built-in one
(docs/engines.md).

Discovery reads only the installed distributions' metadata; an entry point is loaded
(its module imported) when the engine is checked or run, so `harness simulate --engine
reference` never imports MuJoCo, PyBullet or Drake.  An engine that is not installed, or
whose entry point fails to load (import error, exception at import, not callable), is a
`SceneError` (bad input: exit status 2 with its name and the reason).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata

from reference.scene import Scene, SceneError
from reference.trajectory import Trajectory

GROUP = "harness.engines"
DEFAULT_DT = 1e-4
# Listed first, in this order, when installed; everything else follows by name.
_FIRST = ("reference", "linear")


@dataclass(frozen=True)
class EngineInfo:
    """What the metadata says about one engine, without loading it."""

    name: str
    target: str  # "module:attribute"
    package: str | None  # the distribution that registers it
    version: str | None


class EngineLoadError(SceneError):
    """An engine that is missing or cannot be loaded (exit status 2)."""


@functools.cache
def _discovered() -> dict[str, EngineInfo]:
    found: dict[str, EngineInfo] = {}
    for ep in metadata.entry_points(group=GROUP):
        dist = getattr(ep, "dist", None)
        package = dist.metadata["Name"] if dist is not None else None
        version = dist.version if dist is not None else None
        # the first registration of a name wins (sys.path order), as for console scripts
        found.setdefault(ep.name, EngineInfo(ep.name, ep.value, package, version))
    return found


@functools.cache
def _loaded(name: str) -> Callable:
    info = _discovered().get(name)
    if info is None:
        raise EngineLoadError(
            f"unknown engine {name!r}; installed: {', '.join(engine_names()) or 'none'}"
        )
    ep = metadata.EntryPoint(name=name, value=info.target, group=GROUP)
    try:
        obj = ep.load()
    except Exception as exc:  # an engine that cannot load is the user's input problem
        raise EngineLoadError(
            f"engine {name!r} ({info.target}, from {info.package}) failed to load: "
            f"{type(exc).__name__}: {exc}"
        ) from None
    if not callable(obj):
        raise EngineLoadError(f"engine {name!r} ({info.target}) is not callable")
    fixed = getattr(obj, "fixed_step", True)
    if not isinstance(fixed, bool):
        raise EngineLoadError(
            f"engine {name!r} ({info.target}): fixed_step must be True or False, got {fixed!r}"
        )
    return obj


def refresh() -> None:
    """Forget what was discovered and loaded (after installing an engine at run time)."""
    _discovered.cache_clear()
    _loaded.cache_clear()


def engine_infos() -> list[EngineInfo]:
    """Every installed engine's metadata, reference first (see `engine_names`)."""
    found = _discovered()
    return [found[n] for n in engine_names()]


def engine_names() -> list[str]:
    """Every installed simulator, in a stable order: reference, linear, then by name."""
    names = set(_discovered())
    first = [n for n in _FIRST if n in names]
    return first + sorted(names - set(first))


def load_engine(name: str) -> Callable:
    """The engine's `simulate` callable (EngineLoadError if missing or broken)."""
    return _loaded(name)


def is_fixed_step(name: str) -> bool:
    """Whether `--dt` applies to the simulator (its `fixed_step` attribute, default True)."""
    return bool(getattr(load_engine(name), "fixed_step", True))


def check_engine(name: str) -> str:
    """The name, after making sure the engine is installed and loads."""
    load_engine(name)
    return name


def run_simulator(
    engine: str, scene: Scene, dt: float | None = None, t_end: float | None = None
) -> Trajectory:
    """Run one simulator on one scene.  `dt` applies to fixed-step engines only, which
    get DEFAULT_DT when it is None; other engines get dt = None."""
    simulate = load_engine(engine)
    if dt is not None and not dt > 0:
        raise SceneError(f"--dt must be > 0, got {dt}")
    if t_end is not None and not t_end > 0:
        raise SceneError(f"--t-end must be > 0, got {t_end}")
    step = (dt or DEFAULT_DT) if is_fixed_step(engine) else None
    traj = simulate(scene, dt=step, t_end=t_end)
    if not isinstance(traj, Trajectory):
        raise TypeError(f"engine {engine!r} returned {type(traj).__name__}, not a Trajectory")
    return traj


# Warm-up run: this many steps of a fixed-step engine, or this fraction of the scene's
# time for an event-driven one (enough to import, compile or load everything it uses).
WARM_UP_STEPS = 20
WARM_UP_FRACTION = 1e-3
_warm: set[str] = set()


def warm_up(engine: str, scene: Scene, dt: float | None = None) -> float:
    """Run the simulator once briefly on the scene so that one-time costs (imports,
    compilation, loading compiled code, first-call set-up) are paid before anything is
    timed; once per engine and process.  Returns the seconds it took (0 when already
    warm); a failure is left for the timed run to report."""
    if engine in _warm:
        return 0.0
    import time

    start = time.perf_counter()
    step = (dt or DEFAULT_DT) if is_fixed_step(engine) else None
    t_short = WARM_UP_STEPS * step if step else WARM_UP_FRACTION * scene.run.t_end
    try:
        run_simulator(engine, scene, dt=step, t_end=min(t_short, scene.run.t_end))
    except SceneError:
        raise
    except Exception:  # noqa: BLE001  (the timed run reports it)
        pass
    _warm.add(engine)
    return time.perf_counter() - start
