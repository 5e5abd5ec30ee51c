"""The horizon band in each engine's impact raster (raster.py): where
the exact model with its impacts on that run's step grid stops matching the reference
(harness.horizon, level (a): the 10 % … 90 % matched counts), drawn as a thick bar in
the raster's blank row above its contacts (y = n_contacts), from the time of the
reference's impact at the 10 % count to that at the 90 % count.  A run whose red ×
(first mismatch) lies left of its bar diverged before its timestep forces it to.

    /impacts/<sim>/horizon_band     SeriesLines, two points (band start, band end)
"""

from __future__ import annotations

import numpy as np
import rerun as rr

from ..horizon.verdict import Horizon
from .raster import RASTER
from .rows import time_column
from .runs import RunView

BAND_WIDTH = 5.0  # UI points
BAND_ALPHA = 110


def band_times(reference_times: np.ndarray, quantiles: list[float]) -> tuple[float, float] | None:
    """[t of the reference impact at the 10 % count, t at the 90 % count] (the impact
    where the grid model's runs stop matching); one impact interval wide when both are
    the same impact; None without reference impacts."""
    n = len(reference_times)
    if n == 0:
        return None
    lo = int(min(round(quantiles[0]), n - 1))
    hi = int(min(round(quantiles[2]), n - 1))
    t0, t1 = float(reference_times[lo]), float(reference_times[hi])
    if t1 <= t0:
        t1 = float(reference_times[hi + 1]) if hi + 1 < n else t0 * 1.01 + 1e-9
    return t0, t1


def log_horizon_bands(
    rec: rr.RecordingStream,
    runs: list[RunView],
    horizons: list[Horizon | None],
    n_contacts: int,
) -> None:
    """One band per run that has a level-(a) horizon (module docstring); `horizons` is
    aligned with `runs` (None for the reference and event-driven runs)."""
    t_ref = runs[0].trajectory.impact_times().astype(float)
    for run, h in zip(runs, horizons, strict=True):
        if h is None or h.matched_quantiles is None:
            continue
        span = band_times(t_ref, h.matched_quantiles)
        if span is None:
            continue
        q = h.matched_quantiles
        y = float(n_contacts)
        path = f"{RASTER}/{run.name}/horizon_band"
        verdict = "within" if h.within else "below"
        rec.log(
            path,
            rr.SeriesLines(
                colors=[(*run.color, BAND_ALPHA)],
                widths=[BAND_WIDTH],
                names=[
                    f"{run.label}: exact model on its step grid matches {q[0]:.0f}–{q[2]:.0f} "
                    f"impacts (10–90 %); the run's {h.matched} is {verdict}"
                ],
            ),
            static=True,
        )
        rec.send_columns(path, [time_column(list(span))], rr.Scalars.columns(scalars=[y, y]))
