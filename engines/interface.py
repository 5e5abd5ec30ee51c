"""The engine interface, typed: what an entry point of the group `harness.engines` is
(docs/engines.md "Plugging in an engine").

An engine is a callable `simulate(scene, *, dt, t_end) -> Trajectory` with seven optional
attributes; `engine_entry` sets the first six on a function (`simulate_batch` is set by
hand), and `attribute` reads one with its default (harness.simulators reads them only
through it).  A fixed-step adapter usually wraps its engine in an
`engines.stepping.Adapter` and lets `engines.stepping.simulate_fixed_step` drive it (end
time, step count, progress, fall-through checks, Ctrl-C, common stats);
`examples/toy-engine` does both.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

from reference.scene import Scene
from reference.trajectory import Trajectory


@runtime_checkable
class Engine(Protocol):
    """An engine entry point.

    fixed_step        True: `--dt` applies (the step); False: event-driven, dt is None
    library           the distribution of the wrapped physics engine (`harness engines`
                      shows its version), or None
    max_vertices      the largest polygon it takes (larger ones are refused before the
                      run, exit 2), or None for no limit
    reports_progress  True: it accepts `progress=callback(done, total)` and calls it
    ground_kinds      the only ground kinds it takes (`flat`, `three_point`, `bumpy`;
                      others are refused before the run, exit 2), or None for every ground
    extra             the pip extra of this package that installs `library`
                      (`pip install 'euler-disk-harness[EXTRA]'`), or None when `library`
                      is a core dependency (or comes from elsewhere); `harness engines`
                      shows it for an engine whose library is missing
    simulate_batch    optional: `simulate_batch(scenes, *, dt, t_end) -> list[Trajectory]`,
                      many scenes at one dt in one call (t_end None: each scene's own
                      run.t_end), each result the Trajectory the serial call gives;
                      None when the engine offers no batch (`run_batch` in
                      harness.simulators then loops serially)
    """

    fixed_step: bool
    library: str | None
    max_vertices: int | None
    reports_progress: bool
    ground_kinds: tuple[str, ...] | None
    extra: str | None

    def __call__(
        self, scene: Scene, *, dt: float | None = None, t_end: float | None = None
    ) -> Trajectory: ...


# The value of each attribute an entry point leaves unset.
DEFAULTS: dict[str, Any] = {
    "fixed_step": True,
    "library": None,
    "max_vertices": None,
    "reports_progress": False,
    "ground_kinds": None,
    "extra": None,
    "simulate_batch": None,
}


def attribute(engine: Callable, name: str) -> Any:
    """An engine's attribute (`Engine`), its default when the entry point does not set it."""
    return getattr(engine, name, DEFAULTS[name])


def engine_entry(
    fixed_step: bool = True,
    library: str | None = None,
    max_vertices: int | None = None,
    reports_progress: bool = False,
    ground_kinds: tuple[str, ...] | None = None,
    extra: str | None = None,
) -> Callable[[Callable], Engine]:
    """Make a `simulate(scene, *, dt, t_end)` function an `Engine` with these attributes."""

    def mark(fn: Callable) -> Engine:
        fn.fixed_step = fixed_step
        fn.library = library
        fn.max_vertices = max_vertices
        fn.reports_progress = reports_progress
        fn.ground_kinds = ground_kinds
        fn.extra = extra
        return fn  # type: ignore[return-value]

    return mark
