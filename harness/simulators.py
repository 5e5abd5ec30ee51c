"""Simulator registry: every engine is an entry point in the group `harness.engines`.

An entry point names an `engines.interface.Engine`: a callable `simulate(scene, *, dt,
t_end) -> Trajectory` whose optional attributes (`fixed_step`, `library`,
`max_vertices`, `reports_progress`) are read with their defaults by
`engines.interface.attribute`.  This package registers
its own engines the same way (pyproject.toml), so nothing here names an engine and an
engine installed from another package is used exactly like a built-in one
(docs/engines.md).

The names this package registers itself (engines.builtin.BUILTIN_ENGINES) are its
built-in engines, loaded without reading any metadata (a plug-in cannot take one of
these names).  Discovery reads only the installed distributions' metadata; an entry
point is loaded
(its module imported) when the engine is checked or run, so `harness simulate --engine
reference` never imports MuJoCo, PyBullet or Drake.  An engine that is not installed, or
whose entry point fails to load (import error, exception at import, not callable), is a
`SceneError` (bad input: exit status 2 with its name and the reason).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

from engines import builtin
from engines.builtin import BUILTIN_ENGINES
from engines.interface import attribute
from reference.checks import run_horizon
from reference.scene import Scene, SceneError
from reference.trajectory import Trajectory

GROUP = "harness.engines"
DEFAULT_DT = 1e-4
# Steps a fixed-step run may take unless --max-steps says otherwise: MuJoCo keeps about
# 0.6 kB per step (696 MB measured for 1e6 steps), so 1e7 steps stay within ~6 GB.
DEFAULT_MAX_STEPS = 10_000_000
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


class EngineNotInstalled(EngineLoadError):
    """A registered engine whose physics library is not installed: its pip extra was
    not chosen (exit status 2 when it is asked to run; `harness engines` lists it)."""


def install_hint(extra: str) -> str:
    """The command that installs an extra of this package."""
    return f"pip install 'euler-disk-harness[{extra}]'"


def _check_library(name: str, obj: Callable) -> None:
    """EngineNotInstalled when the engine names the extra of a library that is missing."""
    library, extra = attribute(obj, "library"), attribute(obj, "extra")
    if library is None or extra is None:
        return
    from importlib import metadata  # here: its import costs every command's start-up

    try:
        metadata.version(library)
    except metadata.PackageNotFoundError:
        raise EngineNotInstalled(
            f"engine {name!r} needs {library}, which is not installed: {install_hint(extra)}"
        ) from None


@functools.cache
def _discovered() -> dict[str, EngineInfo]:
    from importlib import metadata  # here: its import costs every command's start-up

    found: dict[str, EngineInfo] = {}
    for ep in metadata.entry_points(group=GROUP):
        if ep.name in BUILTIN_ENGINES and ep.value != _builtin_target(ep.name):
            continue  # another package's engine under a built-in name: not used
        dist = getattr(ep, "dist", None)
        package = dist.metadata["Name"] if dist is not None else None
        version = dist.version if dist is not None else None
        # the first registration of a name wins (sys.path order), as for console scripts
        found.setdefault(ep.name, EngineInfo(ep.name, ep.value, package, version))
    return found


def _builtin_target(name: str) -> str:
    return f"{builtin.__name__}:{BUILTIN_ENGINES[name]}"


@functools.cache
def _loaded(name: str) -> Callable:
    if name in BUILTIN_ENGINES:  # this package's own: no metadata to read (start-up)
        return getattr(builtin, BUILTIN_ENGINES[name])
    info = _discovered().get(name)
    if info is None:
        raise EngineLoadError(
            f"unknown engine {name!r}; installed: {', '.join(engine_names()) or 'none'}"
        )
    from importlib import metadata

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
    fixed = attribute(obj, "fixed_step")
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


def entry_point(name: str) -> Callable:
    """The engine's entry point, loaded, whether or not its library is installed
    (EngineLoadError if it is not registered or broken)."""
    return _loaded(name)


def load_engine(name: str) -> Callable:
    """The engine's `simulate` callable (EngineLoadError if missing or broken,
    EngineNotInstalled when its library, from a pip extra, is missing)."""
    obj = _loaded(name)
    _check_library(name, obj)
    return obj


def is_fixed_step(name: str) -> bool:
    """Whether `--dt` applies to the simulator (its `fixed_step` attribute, default True)."""
    return bool(attribute(load_engine(name), "fixed_step"))


def check_engine(name: str) -> str:
    """The name, after making sure the engine is installed and loads."""
    load_engine(name)
    return name


def run_simulator(
    engine: str,
    scene: Scene | str,
    dt: float | None = None,
    t_end: float | None = None,
    *,
    max_steps: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Run one simulator on one scene (a Scene, a file or a built-in name).  `dt`
    applies to fixed-step engines only, which get DEFAULT_DT when it is None; other
    engines get dt = None.

    Before the run, `check_run` (SceneError on bad input).  `progress(done, total)`
    reaches engines that report progress (their `reports_progress` attribute).  After
    the run, harness.guard: a sample that is no valid state (NaN, a quaternion far from
    unit norm, a body through the ground) ends the run `failed` there.  An engine that
    raises once its inputs passed `check_run` (e.g. MuJoCo refusing a mass below its
    1e-15 floor, a plug-in raising SceneError for a scene it does not take) gives a
    `failed` run with the error as its message and the traceback's end in
    stats["error"]: one engine's failure is its own rows' status, never the end of a
    study over several engines."""
    from reference.scenes import as_scene

    from .guard import guard_trajectory

    scene = as_scene(scene)
    simulate = load_engine(engine)
    step = check_run(engine, scene, dt, t_end, max_steps)
    extra = {}
    if progress is not None and attribute(simulate, "reports_progress"):
        extra["progress"] = progress
    try:
        traj = simulate(scene, dt=step, t_end=t_end, **extra)
    except Exception as exc:  # the engine broke on (or refused) this scene: a result
        traj = Trajectory.failed(
            engine, scene.name, step, f"{engine} raised {type(exc).__name__}: {exc}"
        )
        traj.stats = {"error": _error_text(exc)}
    if not isinstance(traj, Trajectory):
        raise TypeError(f"engine {engine!r} returned {type(traj).__name__}, not a Trajectory")
    return guard_trajectory(scene, traj)


def offers_batch(engine: str) -> bool:
    """Whether the engine offers `simulate_batch` (engines.interface.Engine)."""
    return attribute(load_engine(engine), "simulate_batch") is not None


def run_batch(
    engine: str, scenes: list[Scene], dt: float | None = None, t_end: float | None = None
) -> list[Trajectory]:
    """Run many scenes at one dt: through the engine's `simulate_batch` when it offers
    one, serially through `run_simulator` otherwise.  Every scene is checked first
    (`check_run`) and every result guarded, as `run_simulator` does; t_end None: each
    scene's own run.t_end.  A batch that raises falls back to the serial runs."""
    from reference.scenes import as_scene

    from .guard import guard_trajectory

    scenes = [as_scene(s) for s in scenes]
    batch = attribute(load_engine(engine), "simulate_batch")
    if batch is None or not scenes:
        return [run_simulator(engine, s, dt, t_end) for s in scenes]
    steps = {check_run(engine, s, dt, t_end) for s in scenes}
    try:
        trajs = batch(scenes, dt=steps.pop(), t_end=t_end)
    except Exception:  # the batch broke or refused: each scene on its own says why
        return [run_simulator(engine, s, dt, t_end) for s in scenes]
    return [guard_trajectory(s, tr) for s, tr in zip(scenes, trajs, strict=True)]


def _error_text(exc: BaseException, limit: int = 2000) -> str:
    """The last frames of an engine's traceback, for the run's stats."""
    import traceback

    text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__, limit=-4))
    return text.strip()[-limit:]


# The simulators that resolve simultaneous impacts under an impact law and a window.
LAW_ENGINES = ("reference", "linear")


def check_law_options(engine: str, impact_law: str | None, window: float | None) -> None:
    """SceneError (exit 2) when --impact-law or --simultaneity-window is given for an
    engine that does not read them (every engine but LAW_ENGINES resolves contacts with
    its own solver): an option is applied or refused, never silently ignored."""
    given = [
        name
        for name, value in (("--impact-law", impact_law), ("--simultaneity-window", window))
        if value is not None
    ]
    if given and engine not in LAW_ENGINES:
        verb = "applies" if len(given) == 1 else "apply"
        raise SceneError(
            f"{' and '.join(given)} {verb} to the {' and '.join(LAW_ENGINES)} engines only; "
            f"{engine} resolves its contacts with its own solver"
        )


def engine_step(engine: str, dt: float | None) -> float | None:
    """The timestep an engine runs with: `dt` (DEFAULT_DT when None) for a fixed-step
    engine, None for an event-driven one."""
    return (dt or DEFAULT_DT) if is_fixed_step(engine) else None


def check_run(
    engine: str,
    scene: Scene,
    dt: float | None = None,
    t_end: float | None = None,
    max_steps: int | None = None,
) -> float | None:
    """Everything a run needs, checked before it starts (SceneError, exit status 2):
    t_end in the scene's range (and the scene's speed group with that t_end), the
    engine's vertex limit and grounds (`max_vertices`, `ground_kinds` attributes of its
    entry point), and for
    fixed-step engines 0 < dt <= t_end and t_end / dt <= max_steps
    (DEFAULT_MAX_STEPS).  Returns the timestep the engine gets (None: not fixed-step)."""
    simulate = load_engine(engine)
    if dt is not None and not (math.isfinite(dt) and dt > 0):
        raise SceneError(f"dt must be > 0, got {dt}")
    # t_end (or the scene's own) in range, with the speed group, like [run]: the one
    # check the Python API makes too (reference.checks)
    horizon = run_horizon(scene, t_end)
    if t_end is not None:
        scene = scene.with_run(t_end=horizon)
    grounds = attribute(simulate, "ground_kinds")
    if grounds is not None and scene.ground.kind not in grounds:
        raise SceneError(
            f"engine {engine!r} takes {' and '.join(grounds)} grounds, not {scene.ground.kind}"
        )
    limit = attribute(simulate, "max_vertices")
    if limit is not None and scene.body.n > limit:
        raise SceneError(
            f"engine {engine!r} takes polygons of at most {limit} vertices, got n = {scene.body.n}"
        )
    step = engine_step(engine, dt)
    if step is None:
        return None
    horizon = scene.run.t_end
    if step > horizon:
        raise SceneError(f"dt ({step:g} s) must not exceed t_end ({horizon:g} s)")
    ceiling = DEFAULT_MAX_STEPS if max_steps is None else max_steps
    steps = horizon / step
    if steps > ceiling:
        raise SceneError(
            f"t_end / dt = {horizon:g} / {step:g} = {steps:.3g} steps exceeds the ceiling of "
            f"{ceiling:g} steps; use a larger dt or a shorter t_end"
            + ("" if max_steps is None else " (or raise --max-steps)")
        )
    return step


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
    step = engine_step(engine, dt)
    t_short = WARM_UP_STEPS * step if step else WARM_UP_FRACTION * scene.run.t_end
    try:
        run_simulator(engine, scene, dt=step, t_end=min(t_short, scene.run.t_end))
    except Exception:  # noqa: BLE001  (the timed run checks its input and reports it)
        pass
    _warm.add(engine)
    return time.perf_counter() - start
