"""Near the singularity: two log-log plots against the time to go, t_f − t.

- `/singularity/energy`: the paper's plot.  The energy above rest just before each
  impact, E_i, against t_f − t_i, drawn as the staircase E(t) is (constant between
  impacts); for every run that reached the end of the motion its fit window (two
  horizontal lines at the window's energies), the points inside it and the fitted line
  E = a (t_f − t)^c, with c ± its standard error in the legend (reference.exponent).
- `/singularity/alpha`: the inclination α against t_f − t (log10 α over log10(t_f − t)),
  which a linear timeline squeezes into its last pixel.

t_f: a run with an exponent fit uses the t_f of that fit (its own singularity, or the
reference's when it followed the reference to it).  Every other run is drawn against the
reference's end: its t_singularity, or when it has none (an undecidable impact, t_end)
its last impact, said so in the title.  Time to go keeps the low parts of double-double
times (Trajectory.t_lo, ImpactEvent.t_lo): t_f − t = (t_f − t_hi) − t_lo, exact when t
is close to t_f (Sterbenz).  A marker on each curve follows the time cursor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import rerun as rr

from reference.exponent import pre_impact_samples
from reference.trajectory import Status, Trajectory

from .plot2d import Axes, decade_bounds, draw_axes, legend
from .rows import shade, time_column
from .runs import RunView

ENERGY = "/singularity/energy"
ALPHA = "/singularity/alpha"
MAX_CURVE_POINTS = 4000  # α curves are thinned to about this many points per run


@dataclass(frozen=True)
class EndTime:
    """t_f = hi + lo and what it is (for titles)."""

    hi: float
    lo: float
    what: str


def _run_line(run: RunView, points) -> rr.LineStrips2D:
    """A run's curve in the log-log plots: its colour, the reference drawn thinner."""
    return rr.LineStrips2D(
        [points],
        colors=[run.color],
        radii=rr.Radius.ui_points(1.0 if run.is_reference else 1.4),
        draw_order=2.0,
    )


def end_time(reference: RunView) -> EndTime | None:
    """The reference's t_f: its fit's, its t_singularity, else its last impact."""
    traj = reference.trajectory
    if reference.fit.t_f is not None:
        return EndTime(reference.fit.t_f, 0.0, "t_f = the reference's singularity")
    if traj.t_singularity is not None and math.isfinite(traj.t_singularity):
        return EndTime(float(traj.t_singularity), 0.0, "t_f = the reference's singularity")
    if traj.impacts:
        last = max(traj.impacts, key=lambda e: (e.t, e.t_lo))
        what = f"t_f = the reference's last impact ({traj.status.value})"
        return EndTime(float(last.t), float(last.t_lo), what)
    return None


def _run_end(run: RunView, ref_end: EndTime) -> EndTime:
    if run.fit.t_f is not None:
        return EndTime(run.fit.t_f, 0.0, "")
    return ref_end


def _ttg(t: np.ndarray, t_lo: np.ndarray | None, end: EndTime) -> np.ndarray:
    lo = np.zeros(len(t)) if t_lo is None else np.asarray(t_lo, float)
    return (end.hi - np.asarray(t, float)) + (end.lo - lo)


def impact_points(run: RunView, end: EndTime) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t_i, t_f − t_i, E_i) of the impacts before t_f with E_i > 0: the fit's own
    points when the run has a fit, else from the run's impacts and samples."""
    traj = run.trajectory
    if run.fit.t_f is not None and len(run.fit.time_to_go):
        ttg, E = run.fit.time_to_go, run.fit.energy
        t = traj.impact_column("t")[: len(ttg)]
    else:
        if not traj.impacts or traj.n_samples == 0:
            return np.zeros(0), np.zeros(0), np.zeros(0)
        t, lo = traj.impact_column("t"), traj.impact_column("t_lo")
        ttg = _ttg(t, lo, end)
        idx = pre_impact_samples(traj)
        E = np.where(idx >= 0, run.excess[np.maximum(idx, 0)], np.nan)
    k = min(len(t), len(ttg))
    t, ttg, E = t[:k], ttg[:k], E[:k]
    ok = (ttg > 0) & np.isfinite(E) & (E > 0)
    return t[ok], ttg[ok], E[ok]


def staircase(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The piecewise-constant E(t) through pre-impact points: E_i holds from the impact
    before i to impact i, so between x_(i−1) and x_i the level is y_i."""
    if len(x) < 2:
        return x, y
    xs = np.repeat(x, 2)[1:]
    ys = np.repeat(y, 2)[:-1]
    return xs, ys


def thin(x: np.ndarray, *others: np.ndarray, resolution: float = 1e-3):
    """Keep the first point in each bin of `resolution` decades of x and at most
    MAX_CURVE_POINTS points."""
    if len(x) == 0:
        return (x, *others)
    span = max(float(np.nanmax(x) - np.nanmin(x)), 1e-12)
    res = max(resolution, span / MAX_CURVE_POINTS)
    _, keep = np.unique(np.floor(x / res), return_index=True)
    keep = np.sort(keep)
    return (x[keep], *(o[keep] for o in others))


@dataclass(frozen=True)
class Plot:
    """What one of the two plots shows: its axes, t_f, and per run (t, x, y) in decades."""

    axes: Axes
    end: EndTime
    curves: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]


def _plot(runs: list[RunView], points) -> Plot | None:
    ref_end = end_time(runs[0])
    if ref_end is None:
        return None
    curves = {run.name: points(run, _run_end(run, ref_end)) for run in runs}
    xs = np.concatenate([c[1] for c in curves.values()])
    if len(xs) == 0:
        return None
    ys = np.concatenate([c[2] for c in curves.values()])
    return Plot(Axes(*decade_bounds(xs), *decade_bounds(ys)), ref_end, curves)


def energy_plot(runs: list[RunView]) -> Plot | None:
    """log10 E_i against log10(t_f − t_i) per run; None if nothing lies before t_f."""

    def points(run, end):
        t, ttg, E = impact_points(run, end)
        return t, np.log10(ttg), np.log10(E)

    return _plot(runs, points)


def alpha_plot(runs: list[RunView]) -> Plot | None:
    """log10 α against log10(t_f − t) per run; None if nothing lies before t_f."""
    return _plot(runs, alpha_points)


# ----------------------------------------------------------------------------- energy


def log_energy_plot(rec: rr.RecordingStream, runs: list[RunView], plot: Plot | None) -> None:
    """The paper's log-log plot of E against t_f − t (module docstring)."""
    if plot is None:
        rec.log(
            f"{ENERGY}/note",
            rr.TextDocument("No impacts before the reference's end: nothing to plot."),
            static=True,
        )
        return
    ax = plot.axes
    draw_axes(rec, ENERGY, ax, "t_f − t [s]  (time runs right to left)", "E − E_rest [J]")
    for run in runs:
        t, x, y = plot.curves[run.name]
        _energy_curve(rec, run, ax, t, x, y)
    legend(rec, ENERGY, energy_legend(runs, plot))


def energy_legend(runs: list[RunView], plot: Plot) -> list[tuple[str, tuple[int, int, int]]]:
    """The lines under the energy plot: what t_f is, then each run's exponent."""
    lines = [(plot.end.what, (190, 190, 190))]
    for run in runs:
        fit = run.fit
        if fit.c is not None:
            text = (
                f"{run.label}: c = {fit.c:.3f} ± {fit.c_stderr:.2g} ({fit.fit_decades:.0f} decades)"
            )
        elif run.trajectory.status is Status.SINGULARITY:
            text = f"{run.label}: no c ({fit.reason})"
        else:
            text = f"{run.label}: no c ({run.trajectory.status.value})"
        lines.append((text, run.color))
    return lines


def _energy_curve(rec, run: RunView, ax: Axes, t, x, y) -> None:
    root = f"{ENERGY}/{run.name}"
    if len(x) == 0:
        return
    sx, sy = staircase(x, y)
    rec.log(f"{root}/staircase", _run_line(run, ax.xy(sx, sy)), static=True)
    _fit_overlay(rec, run, ax, root)
    rec.log(
        f"{root}/now",
        rr.Points2D.from_fields(radii=rr.Radius.ui_points(4.5), colors=[run.color]),
        static=True,
    )
    rec.send_columns(f"{root}/now", [time_column(t)], rr.Points2D.columns(positions=ax.xy(x, y)))


def _fit_overlay(rec, run: RunView, ax: Axes, root: str) -> None:
    """The fit window's two energies, the points used and the fitted line."""
    fit = run.fit
    if fit.c is None or fit.window is None:
        return
    sel = fit.selected
    with np.errstate(divide="ignore", invalid="ignore"):
        px, py = np.log10(fit.time_to_go[sel]), np.log10(fit.energy[sel])
    light = shade(run.color, 0.45)
    bottom, top = fit.window
    rec.log(
        f"{root}/fit_window",
        rr.LineStrips2D(
            [ax.xy([ax.x0, ax.x1], [lv, lv]) for lv in (bottom, top)],
            colors=[(*light, 150)],
            radii=rr.Radius.ui_points(0.8),
            draw_order=1.0,
        ),
        static=True,
    )
    rec.log(
        f"{root}/fit_points",
        rr.Points2D(ax.xy(px, py), colors=[light], radii=rr.Radius.ui_points(2.0), draw_order=3.0),
        static=True,
    )
    ends = np.array([px.min(), px.max()])
    line = fit.c * ends + fit.log_a / math.log(10.0)
    rec.log(
        f"{root}/fit",
        rr.LineStrips2D(
            [ax.xy(ends, line)],
            colors=[light],
            radii=rr.Radius.ui_points(2.0),
            draw_order=4.0,
        ),
        static=True,
    )


# ----------------------------------------------------------------------------- attitude


def alpha_points(run: RunView, end: EndTime) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, log10(t_f − t), log10 α) of the samples before t_f with α > 0, thinned."""
    traj: Trajectory = run.trajectory
    if traj.n_samples == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    ttg = _ttg(traj.t, traj.t_lo, end)
    ok = (ttg > 0) & np.isfinite(run.alpha) & (run.alpha > 0)
    t, x, y = traj.t[ok], np.log10(ttg[ok]), np.log10(run.alpha[ok])
    x, t, y = thin(x, t, y)
    order = np.argsort(t)
    return t[order], x[order], y[order]


def log_alpha_plot(rec: rr.RecordingStream, runs: list[RunView], plot: Plot | None) -> None:
    """log10 α against log10(t_f − t) for every run (module docstring)."""
    if plot is None:
        return
    ax = plot.axes
    draw_axes(rec, ALPHA, ax, "t_f − t [s]", "α [rad]")
    for run in runs:
        t, x, y = plot.curves[run.name]
        if len(x) == 0:
            continue
        root = f"{ALPHA}/{run.name}"
        rec.log(f"{root}/curve", _run_line(run, ax.xy(x, y)), static=True)
        rec.log(
            f"{root}/now",
            rr.Points2D.from_fields(radii=rr.Radius.ui_points(4.5), colors=[run.color]),
            static=True,
        )
        rec.send_columns(
            f"{root}/now", [time_column(t)], rr.Points2D.columns(positions=ax.xy(x, y))
        )
    legend(rec, ALPHA, alpha_legend(runs, plot))


def alpha_legend(runs: list[RunView], plot: Plot) -> list[tuple[str, tuple[int, int, int]]]:
    """The lines under the α plot: what t_f is, then the runs drawn."""
    drawn = [run.label for run in runs if len(plot.curves[run.name][1])]
    return [(plot.end.what, (190, 190, 190)), (" · ".join(drawn), (190, 190, 190))]
