"""A small log-log plot drawn in a rerun 2D view (rerun's time-series views plot against a
timeline only, so a plot against log(t_f − t) is drawn by hand): a frame of width W and
height H in view units, decade grid lines, tick labels, axis titles and a title.

Data coordinates are decades (log10 of the value); `Axes.xy` maps them into the frame.
2D views point y down, so larger values are drawn higher by flipping y.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import rerun as rr

W, H = 1.6, 1.0  # frame size in view units (a wide panel)
GRID = (70, 70, 70)
TEXT = (190, 190, 190)


@dataclass(frozen=True)
class Axes:
    """A frame showing decades x0..x1 (horizontal) and y0..y1 (vertical)."""

    x0: float
    x1: float
    y0: float
    y1: float

    def xy(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """(N, 2) view positions of data points (decades)."""
        X = (np.asarray(x, float) - self.x0) / (self.x1 - self.x0) * W
        Y = H - (np.asarray(y, float) - self.y0) / (self.y1 - self.y0) * H
        return np.stack([X, Y], axis=1)

    def visual_bounds(self, legend_lines: int = 0) -> tuple[list[float], list[float]]:
        """x_range, y_range of the view: the frame plus room for the tick labels, the
        axis titles and the legend lines under the frame."""
        return [-0.16 * W, 1.05 * W], [-0.16 * H, legend_y(legend_lines) + 0.06 * H]


def legend_y(k: int) -> float:
    """y (view units) of legend line k, under the frame and its x title."""
    return (1.24 + 0.085 * k) * H


def decade_bounds(values: np.ndarray, pad: float = 0.0) -> tuple[float, float]:
    """Whole decades covering finite values (at least one decade)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if len(v) == 0:
        return 0.0, 1.0
    lo, hi = math.floor(v.min() - pad), math.ceil(v.max() + pad)
    return float(lo), float(max(hi, lo + 1))


def decade_step(span: float) -> int:
    """Tick spacing in decades so that a span has at most ~8 ticks."""
    for step in (1, 2, 5, 10, 20, 50, 100):
        if span / step <= 8:
            return step
    return 200


def draw_axes(
    rec: rr.RecordingStream,
    root: str,
    ax: Axes,
    x_title: str,
    y_title: str,
) -> None:
    """Frame, grid, tick labels ('1e-3') and axis titles under `root` (static)."""
    frame = ax.xy([ax.x0, ax.x1, ax.x1, ax.x0, ax.x0], [ax.y0, ax.y0, ax.y1, ax.y1, ax.y0])
    sx, sy = decade_step(ax.x1 - ax.x0), decade_step(ax.y1 - ax.y0)
    xt = np.arange(sx * math.ceil(ax.x0 / sx), ax.x1 + 0.5, sx)
    yt = np.arange(sy * math.ceil(ax.y0 / sy), ax.y1 + 0.5, sy)
    grid = [ax.xy([x, x], [ax.y0, ax.y1]) for x in xt]
    grid += [ax.xy([ax.x0, ax.x1], [y, y]) for y in yt]
    rec.log(
        f"{root}/axes/grid",
        rr.LineStrips2D(grid, colors=[GRID], radii=rr.Radius.ui_points(0.5), draw_order=0.0),
        static=True,
    )
    rec.log(
        f"{root}/axes/frame",
        rr.LineStrips2D([frame], colors=[TEXT], radii=rr.Radius.ui_points(0.8), draw_order=0.1),
        static=True,
    )
    yt = yt[yt > ax.y0]  # the bottom-left corner is the x axis's first label
    below = ax.xy(xt, np.full(len(xt), ax.y0)) + [0.0, 0.045 * H]
    left = ax.xy(np.full(len(yt), ax.x0), yt) - [0.07 * W, 0.0]
    pos = np.concatenate([below, left])
    labels = [f"1e{int(x)}" for x in xt] + [f"1e{int(y)}" for y in yt]
    pos = np.concatenate([pos, [[0.5 * W, 1.13 * H], [0.0, -0.1 * H]]])
    labels += [x_title, y_title]
    rec.log(
        f"{root}/axes/labels",
        rr.Points2D(pos, labels=labels, radii=rr.Radius.ui_points(0.0), colors=[TEXT]),
        static=True,
    )


def legend(
    rec: rr.RecordingStream,
    root: str,
    lines: list[tuple[str, tuple[int, int, int]]],
) -> None:
    """Coloured text lines stacked under the frame, centred (rerun centres a label on
    its point), one entity each so that every line keeps its colour."""
    for k, (text, color) in enumerate(lines):
        rec.log(
            f"{root}/legend/{k}",
            rr.Points2D(
                [[0.5 * W, legend_y(k)]],
                labels=[text],
                colors=[color],
                radii=rr.Radius.ui_points(0.0),
                draw_order=10.0,
            ),
            static=True,
        )
