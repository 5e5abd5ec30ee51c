"""The one check of a run's inputs, shared by the command line and the Python API.

`harness simulate/compare/...` (harness.simulators.check_run), `reference.simulate`,
`reference.linear.simulate.simulate_linear` and `harness.simulators.run_simulator` all
call `run_horizon` before any work: the scene, however it was built (a file,
`dataclasses.replace`, the constructors), passes `reference.scene.check_scene`, every
field's type and range as a scene file's key; the run's t_end is checked like a scene
file's `[run] t_end` (a finite number in DIMENSION_RANGE: NaN, 0, negative and
out-of-range values raise SceneError) together with the scene (`Scene.with_run`: the
speed group the t_end implies).  The options of the two exact simulators are checked
here too (`check_reference_options`, `check_linear_options`): their types, their ranges
and the sequential law's order, since a NaN tolerance, a zero work budget or an order
naming no contact would otherwise make a run that never returns, divides by zero or
silently ignores the order.
"""

from __future__ import annotations

import math
from numbers import Integral, Real
from typing import Any

from .scene import IMPACT_LAWS, Scene, SceneError, check_scene, check_t_end

# Largest samples and loop steps between returns to Python a run may be given.
MAX_SAMPLES = 100_000_000
MAX_WORK_BUDGET = 1_000_000_000


def run_horizon(scene: Any, t_end: Any = None) -> float:
    """The run's end time: SceneError unless `scene` is a Scene and the end time (t_end,
    else the scene's own) a number in the range of a scene file's t_end
    (`reference.scene.check_t_end`); a t_end given here is checked with the scene too
    (`Scene.with_run`: the speed group it implies), as the command line's --t-end."""
    if not isinstance(scene, Scene):
        raise SceneError(f"a Scene is needed (reference.scene), got {type(scene).__name__}")
    if t_end is None:
        check_scene(scene)  # however it was built (dataclasses.replace, constructors)
        return float(scene.run.t_end)
    if isinstance(t_end, bool) or not isinstance(t_end, Real):
        raise SceneError(f"t_end must be a number, got {type(t_end).__name__}")
    check_t_end(float(t_end))
    scene.with_run(t_end=float(t_end))  # every field, with this t_end (check_scene)
    return float(t_end)


def check_reference_options(opts: Any, scene: Scene | None = None) -> None:
    """SceneError unless every field of a ReferenceOptions is usable (docstring there):
    the types (True is no number, "1e-11" no window), the ranges, and sequential_order
    distinct indices of the scene's contacts under the `sequential` law (the options'
    law, else the scene's) only."""
    from .options import ReferenceOptions

    if not isinstance(opts, ReferenceOptions):
        raise SceneError(f"options must be a ReferenceOptions, got {type(opts).__name__}")
    _optional_positive("sample_dt", opts.sample_dt)
    _in_interval("chatter_tol", opts.chatter_tol, 0.0, 1.0, closed_low=True)
    _in_interval("contact_rtol", opts.contact_rtol, 1e-16, 1e-2, closed_low=True)
    _in_interval("energy_floor", opts.energy_floor, 0.0, 1.0)
    _count("max_samples", opts.max_samples, 1, MAX_SAMPLES)
    _count("work_budget", opts.work_budget, 1, MAX_WORK_BUDGET)
    if not isinstance(opts.window_search, bool):
        raise SceneError(f"window_search must be true or false, got {opts.window_search!r}")
    if opts.impact_law is not None and opts.impact_law not in IMPACT_LAWS:
        raise SceneError(
            f"impact_law must be one of {', '.join(IMPACT_LAWS)} (or None), got {opts.impact_law!r}"
        )
    w = opts.simultaneity_window
    if w is not None and not (_is_number(w) and math.isfinite(w) and w >= 0.0):
        raise SceneError(f"simultaneity_window must be a finite time >= 0 (or None), got {w!r}")
    law = opts.impact_law if opts.impact_law is not None or scene is None else scene.impact_law
    n_contacts = None if scene is None else scene.n_contacts
    check_sequential_order(opts.sequential_order, law, n_contacts)


def check_sequential_order(order: Any, law: str | None, n_contacts: int | None) -> None:
    """None, or a sequence of distinct contact indices in [0, n_contacts) (the contacts
    touching at an impact are taken in this order; those it does not name follow by
    index), given with the `sequential` law, the only one that reads it."""
    if order is None:
        return
    if isinstance(order, (str, bytes)) or not isinstance(order, (tuple, list)) or not order:
        raise SceneError(
            f"sequential_order must be a non-empty tuple of contact indices, got {order!r}"
        )
    if law is not None and law != "sequential":
        raise SceneError(f"sequential_order applies to impact_law = 'sequential' only, not {law!r}")
    top = n_contacts if n_contacts is not None else math.inf
    for c in order:
        if isinstance(c, bool) or not isinstance(c, Integral) or not 0 <= c < top:
            bound = f"[0, {n_contacts})" if n_contacts is not None else ">= 0"
            raise SceneError(
                f"sequential_order entries must be contact indices in {bound}, got {c!r}"
            )
    if len(set(order)) != len(order):
        raise SceneError(f"sequential_order names a contact twice: {tuple(order)!r}")


def check_linear_options(sample_dt: Any, energy_floor: Any, chatter_tol: Any) -> None:
    """SceneError unless simulate_linear's options are usable: sample_dt None or > 0,
    energy_floor in [0, 1), chatter_tol >= 0 (math.inf: complete chatter at once)."""
    _optional_positive("sample_dt", sample_dt)
    _in_interval("energy_floor", energy_floor, 0.0, 1.0, closed_low=True)
    if not _is_number(chatter_tol) or not chatter_tol >= 0.0:
        raise SceneError(f"chatter_tol must be >= 0, got {chatter_tol!r}")


def _is_number(x: Any) -> bool:
    return isinstance(x, Real) and not isinstance(x, bool)


def _optional_positive(name: str, x: Any) -> None:
    if x is not None and not (_is_number(x) and math.isfinite(x) and x > 0):
        raise SceneError(f"{name} must be a finite number > 0 (or None), got {x!r}")


def _in_interval(name: str, x: Any, lo: float, hi: float, closed_low: bool = False) -> None:
    ok = _is_number(x) and (lo <= x if closed_low else lo < x) and x < hi
    if not ok:
        bracket = "[" if closed_low else "("
        raise SceneError(f"{name} must be in {bracket}{lo:g}, {hi:g}), got {x!r}")


def _count(name: str, x: Any, lo: int, hi: int) -> None:
    if isinstance(x, bool) or not isinstance(x, Integral) or not lo <= x <= hi:
        raise SceneError(f"{name} must be an integer in [{lo}, {hi:.0e}], got {x!r}")
