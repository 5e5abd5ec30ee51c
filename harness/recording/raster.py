"""The impact rasters: under each simulator's column, its impacts as markers at their
times, y = the contact's index (vertex k on flat ground, bump k on three bumps), the
marker's size growing with the impulse; in an engine's raster the reference's impacts
are drawn behind, small and faint, so a missed, extra or shifted impact shows where
the two differ; the first impact that disagrees with the reference is marked by a red
cross.  On a ground with both contact kinds (`bumpy`: the rim vertices, then the bumps
above them) the bump impacts are diamonds in their own series, so the kind that took
each impulse shows at a glance.

    /impacts/<sim>                  SeriesPoints, y = contact index
    /impacts/<sim>/bump             the bump impacts (diamonds), on a bumpy ground
    /impacts/behind/<reference>     the reference's impacts again, faint (engines' views)
    /impacts/<sim>/first_mismatch   one red cross at the first mismatch (if any)
    /<sim>/impacts/log              one TextLog line per impact (contact, time, impulse,
                                    normal velocity before → after)
"""

from __future__ import annotations

import numpy as np
import rerun as rr

from reference.contact_kinds import GroundContacts
from reference.core.records import FLOOR_POINT_ON_FACE

from .rows import time_column
from .runs import RunView, mismatch_marker

RASTER = "/impacts"
IMPULSE_DECADES = 4.0  # marker size spans this many decades of impulse
SIZE_MIN, SIZE_MAX = 1.5, 5.5  # marker radius in UI points


BEHIND = f"{RASTER}/behind"
BEHIND_ALPHA = 110  # of 255: the reference behind an engine's impacts
BEHIND_SCALE = 0.6  # its markers' size relative to its own raster's


def marker_sizes(impulse: np.ndarray, largest: float) -> np.ndarray:
    """Marker radius per impact: SIZE_MIN at IMPULSE_DECADES below the largest impulse
    of the recording (and under), SIZE_MAX at the largest, linear in log10 impulse."""
    j = np.abs(np.asarray(impulse, dtype=float))
    if not largest > 0:
        return np.full(len(j), SIZE_MIN)
    with np.errstate(divide="ignore"):
        level = np.log10(np.where(j > 0, j, 0.0) / largest)
    frac = np.clip(1.0 + level / IMPULSE_DECADES, 0.0, 1.0)
    return SIZE_MIN + (SIZE_MAX - SIZE_MIN) * frac


def largest_impulse(runs: list[RunView]) -> float:
    return max(
        (abs(e.impulse) for run in runs for e in run.trajectory.impacts),
        default=0.0,
    )


def log_raster(rec: rr.RecordingStream, runs: list[RunView], contacts: GroundContacts) -> None:
    """Every simulator's impacts, the reference's faint copy and the mismatch markers
    (module docstring)."""
    biggest = largest_impulse(runs)
    ref = runs[0]
    behind = f"{BEHIND}/{ref.name}"
    _log_impacts(rec, behind, ref, contacts, biggest, BEHIND_ALPHA, BEHIND_SCALE)
    for run in runs:
        _log_impacts(rec, f"{RASTER}/{run.name}", run, contacts, biggest)
        _log_mismatch(rec, run)
        _log_impact_text(rec, run, contacts)


def bump_path(path: str) -> str:
    """Where a raster's bump impacts go on a ground with both kinds."""
    return f"{path}/bump"


def _log_impacts(
    rec: rr.RecordingStream,
    path: str,
    run: RunView,
    contacts: GroundContacts,
    biggest: float,
    alpha: int = 255,
    scale: float = 1.0,
) -> None:
    """The run's impacts at `path`; on a ground with both kinds its bump impacts apart,
    as diamonds at bump_path(path)."""
    traj = run.trajectory
    k = traj.impact_contacts().astype(int) if traj.impacts else np.zeros(0, dtype=int)
    bump = contacts.of_kind(FLOOR_POINT_ON_FACE)
    both = bool(bump.any() and not bump.all())
    on_bump = bump[k] if both else np.zeros(len(k), dtype=bool)
    series = [(path, ~on_bump, "circle", run.label)]
    if both:
        series.append((bump_path(path), on_bump, "diamond", f"{run.label} bump impacts"))
    sizes = scale * marker_sizes(traj.impact_column("impulse"), biggest) if len(k) else k
    for where, keep, marker, name in series:
        rec.log(
            where,
            rr.SeriesPoints(colors=[(*run.color, alpha)], names=[name], markers=[marker]),
            static=True,
        )
        if not keep.any():
            continue
        rec.send_columns(
            where,
            [time_column(traj.impact_times()[keep])],
            [
                *rr.Scalars.columns(scalars=k[keep].astype(float)),
                *rr.SeriesPoints.columns(marker_sizes=sizes[keep]),
            ],
        )


def _log_mismatch(rec: rr.RecordingStream, run: RunView) -> None:
    x = None if run.match is None else run.match.mismatch
    if x is None:
        return
    contact = x.contact_run if x.contact_run is not None else x.contact_ref
    path = f"{RASTER}/{run.name}/first_mismatch"
    rec.log(
        path,
        mismatch_marker(f"{run.label}: first mismatch ({x.kind}), t = {x.t:.6g} s", SIZE_MAX + 3),
        static=True,
    )
    t = x.t_run if x.t_run is not None else x.t_ref
    rec.send_columns(path, [time_column([t])], rr.Scalars.columns(scalars=[float(contact)]))


def _log_impact_text(rec: rr.RecordingStream, run: RunView, contacts: GroundContacts) -> None:
    """One line per impact in the run's impact log, naming the contact and its kind
    ('v2' rim vertex 2, 'b1' bump 1)."""
    imps = run.trajectory.impacts
    if not imps:
        return
    lines = [
        f"{run.label} impact {i}: contact {e.contact} ({contacts.label(e.contact)}) "
        f"at t = {float(e.t)!r}"
        + (f" (lo {float(e.t_lo):+.3g})" if e.t_lo else "")
        + f", impulse {e.impulse:.6g}, v_n {e.v_normal_pre:.6g} → {e.v_normal_post:.6g}"
        for i, e in enumerate(imps)
    ]
    rec.send_columns(
        f"/{run.name}/impacts/log",
        [time_column(run.trajectory.impact_times())],
        rr.TextLog.columns(text=lines, level=["INFO"] * len(lines)),
    )


def raster_range(n_contacts: int) -> tuple[float, float]:
    """y range that shows every contact with a margin, and the row y = n_contacts above
    them where the horizon band is drawn (horizon.py)."""
    return -0.6, n_contacts + 0.6
