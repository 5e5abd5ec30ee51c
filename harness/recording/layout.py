"""The recording's blueprint (rerun 0.41 `rerun.blueprint`): what opens on screen.

Left, one column per simulator (reference first), rows sharing the time axis:

    3D view        the body posed at the cursor time, tilt and heights × the exaggeration
                   k(t) written on the ground (geometry.exaggeration_schedule)
    log10 α        inclination (rad)
    heading ψ      direction of the lowest point of the rim (turns, unwrapped)
    log10 (E − E_rest)   energy above the resting level (J)

    impacts        the raster: y = contact index, marker size ~ log impulse (raster.py)

Every engine's plot also shows the reference (grey, thinner; in the raster, small faint
markers) behind it.  Right: the two log-log plots against t_f − t (energy with the
exponent fits, and α), and the summary / impact log.  Every time-series view opens on
the same time range (`focus_range`): from just before the reference's first impact
(the flight before it is a parabola; the impacts are the part to compare) to where the
data end, the reference's end + 10 %; zooming out shows the whole run.  The time panel
opens collapsed and paused at t = 0; the side panels collapsed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from .plot2d import Axes
from .raster import BEHIND, RASTER, bump_path
from .rows import SIM_TIME
from .runs import RunView
from .singularity import ALPHA, ENERGY

SUMMARY = "/summary"
READING = "/reading"


@dataclass(frozen=True)
class RowRanges:
    """y ranges shared by one row's plots (so the columns compare at a glance)."""

    log_alpha: tuple[float, float] | None
    heading: tuple[float, float] | None
    log_excess: tuple[float, float] | None
    raster: tuple[float, float]


def value_range(
    values: list[np.ndarray], max_span: float | None = None, pad: float = 0.05
) -> tuple[float, float] | None:
    """[lo, hi] over the finite values, padded by `pad` of the span; with `max_span`, the
    lower end is raised to hi − max_span (a log row shows its top decades, where the
    motion is, not the roundoff floor)."""
    v = np.concatenate([np.asarray(x, float) for x in values]) if values else np.zeros(0)
    v = v[np.isfinite(v)]
    if len(v) == 0:
        return None
    lo, hi = float(v.min()), float(v.max())
    if max_span is not None:  # a log row: the top `max_span` decades
        lo = max(lo, hi - max_span)
    span = max(hi - lo, 1e-9)
    return lo - pad * span, hi + pad * span


def _axis(r: tuple[float, float] | None) -> rrb.ScalarAxis | None:
    return None if r is None else rrb.ScalarAxis(range=r, zoom_lock=False)


FOCUS_MARGIN = 0.05  # of the focused span, before the first impact


def focus_range(reference_impact_times: np.ndarray, t_max: float) -> tuple[float, float]:
    """[t0, t_max]: t0 = FOCUS_MARGIN of the span before the reference's first impact
    (0 without impacts, or when that impact is at the start)."""
    times = np.asarray(reference_impact_times, dtype=float)
    times = times[np.isfinite(times) & (times < t_max)]
    if len(times) == 0:
        return 0.0, float(t_max)
    first = float(times.min())
    return max(0.0, first - FOCUS_MARGIN * (t_max - first)), float(t_max)


def time_axis(span: tuple[float, float]) -> rrb.TimeAxis:
    """The shared time axis: every row opens on `span` (rerun 0.41 ignores a view range
    on axes linked to the global one, so each view gets the same range)."""
    return rrb.TimeAxis(
        view_range=rr.TimeRange(
            start=rrb.TimeRangeBoundary.absolute(seconds=float(span[0])),
            end=rrb.TimeRangeBoundary.absolute(seconds=float(span[1])),
        )
    )


def _row(
    runs: list[RunView],
    leaf: str,
    title: str,
    y: tuple[float, float] | None,
    span: tuple[float, float],
) -> rrb.Horizontal:
    """One row: a time-series view per simulator with the reference behind the engines."""
    ref = runs[0]
    views = []
    key = leaf.split("/")[-1]
    for run in runs:
        contents = [f"/{run.name}/{leaf}", f"/{run.name}/divergence/{key}"]
        name = f"{title} · {run.label}"
        if not run.is_reference:
            contents.append(f"/{ref.name}/{leaf}")
        views.append(
            rrb.TimeSeriesView(
                origin="/",
                contents=contents,
                name=name,
                axis_x=time_axis(span),
                axis_y=_axis(y),
                plot_legend=rrb.PlotLegend(visible=False),
            )
        )
    return rrb.Horizontal(*views, name=title)


def _raster_row(
    runs: list[RunView], contact_word: str, y: tuple[float, float], span: tuple[float, float]
) -> rrb.Horizontal:
    """The impacts under each column; an engine's view has the reference's behind."""
    ref = runs[0]
    views = []
    for run in runs:
        contents = [
            f"{RASTER}/{run.name}",
            bump_path(f"{RASTER}/{run.name}"),
            f"{RASTER}/{run.name}/first_mismatch",
            f"{RASTER}/{run.name}/horizon_band",
        ]
        if not run.is_reference:
            contents += [f"{BEHIND}/{ref.name}", bump_path(f"{BEHIND}/{ref.name}")]
        views.append(
            rrb.TimeSeriesView(
                origin="/",
                contents=contents,
                name=f"impacts · {run.label} · y = {contact_word}",
                axis_x=time_axis(span),
                axis_y=_axis(y),
                plot_legend=rrb.PlotLegend(visible=False),
            )
        )
    return rrb.Horizontal(*views, name="impacts")


def _scenes(runs: list[RunView], radius: float) -> rrb.Horizontal:
    eye = rrb.EyeControls3D(
        position=[1.45 * radius, -1.95 * radius, 0.95 * radius],
        look_target=[0.0, 0.0, 0.05 * radius],
        eye_up=[0.0, 0.0, 1.0],
    )
    return rrb.Horizontal(
        *[
            rrb.Spatial3DView(
                origin=f"/{run.name}/scene",
                name=f"{run.label} · 3D, exaggerated",
                eye_controls=eye,
                line_grid=rrb.LineGrid3D(visible=False),
            )
            for run in runs
        ],
        name="3D",
    )


def _plot2d(origin: str, name: str, axes: Axes | None, lines: int) -> rrb.Spatial2DView:
    bounds = None
    if axes is not None:
        xr, yr = axes.visual_bounds(lines)
        bounds = rrb.VisualBounds2D(x_range=xr, y_range=yr)
    return rrb.Spatial2DView(origin=origin, name=name, visual_bounds=bounds)


def build_blueprint(
    runs: list[RunView],
    radius: float,
    ranges: RowRanges,
    energy_axes: Axes | None,
    alpha_axes: Axes | None,
    focus: tuple[float, float],
    contact_word: str = "vertex",
) -> rrb.Blueprint:
    """The layout in the module docstring; `contact_word` names the raster's y axis
    ("vertex" or "bump"), `focus` is the time range every row opens on."""
    columns = rrb.Vertical(
        _scenes(runs, radius),
        _row(runs, "attitude/log10_alpha", "log10 α [rad]", ranges.log_alpha, focus),
        _row(runs, "attitude/heading", "heading ψ [turns]", ranges.heading, focus),
        _row(runs, "energy/log10_excess", "log10(E − E_rest) [J]", ranges.log_excess, focus),
        _raster_row(runs, contact_word, ranges.raster, focus),
        row_shares=[1.35, 1.0, 1.0, 1.0, 0.9],
        name="simulators side by side",
    )
    side = rrb.Vertical(
        _plot2d(
            ENERGY, "E − E_rest before each impact against t_f − t", energy_axes, len(runs) + 1
        ),
        _plot2d(ALPHA, "α against t_f − t", alpha_axes, 2),
        rrb.Tabs(
            rrb.TextDocumentView(origin=SUMMARY, name="summary"),
            rrb.TextDocumentView(origin=READING, name="how to read"),
            rrb.TextLogView(
                origin="/",
                contents=[f"/{run.name}/impacts/log" for run in runs],
                name="impact log",
            ),
            name="summary",
        ),
        row_shares=[1.1, 0.9, 1.5],
        name="near the singularity",
    )
    return rrb.Blueprint(
        rrb.Horizontal(columns, side, column_shares=[3.0, 1.3]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(timeline=SIM_TIME, state="collapsed", play_state="paused"),
    )
