"""The impact raster: every impact of every simulator as a marker at its time, one lane
per simulator (the reference on top), the contact index within the lane, the marker's
size growing with the impulse, and the first impact that disagrees with the reference
marked by a red cross in that simulator's lane.  On a ground with both contact kinds
(`bumpy`: the rim vertices, then the bumps above them in the lane) the bump impacts are
diamonds in their own series, so the kind that took each impulse shows at a glance.

    /impacts/<sim>                  SeriesPoints, y = lane base + contact index
    /impacts/<sim>/bump             the bump impacts (diamonds), on a bumpy ground
    /impacts/lanes/<sim>            a faint guide line under the lane
    /impacts/<sim>/first_mismatch   one red cross at the first mismatch (if any)
    /<sim>/impacts/log              one TextLog line per impact (contact, time, impulse,
                                    normal velocity before → after)

Lane k (0 = reference) occupies y = base_k … base_k + n_contacts − 1 with
base_k = (lanes − 1 − k)(n_contacts + 1): a blank row separates the lanes.
"""

from __future__ import annotations

import math

import numpy as np
import rerun as rr

from reference.contact_kinds import GroundContacts

from .rows import time_column
from .runs import RunView, mismatch_marker

RASTER = "/impacts"
IMPULSE_DECADES = 4.0  # marker size spans this many decades of impulse
SIZE_MIN, SIZE_MAX = 1.5, 5.5  # marker radius in UI points


def lane_base(k: int, lanes: int, n_contacts: int) -> float:
    """y of contact 0 in lane k (0 = top lane)."""
    return float((lanes - 1 - k) * (n_contacts + 1))


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


def log_raster(
    rec: rr.RecordingStream, runs: list[RunView], contacts: GroundContacts, t_max: float
) -> None:
    """Every lane, its guide line and the mismatch markers (module docstring)."""
    biggest = largest_impulse(runs)
    n_contacts = contacts.n
    both = 0 < contacts.n_rim < contacts.n  # rim vertices and bumps: draw the kinds apart
    for k, run in enumerate(runs):
        base = lane_base(k, len(runs), n_contacts)
        _log_lane_guide(rec, run, base, t_max)
        path = f"{RASTER}/{run.name}"
        rec.log(
            path,
            rr.SeriesPoints(
                colors=[run.color],
                names=[f"{run.label} (contacts at {base:g} + k)"],
                markers=["circle"],
            ),
            static=True,
        )
        if both:
            rec.log(
                f"{path}/bump",
                rr.SeriesPoints(
                    colors=[run.color],
                    names=[f"{run.label} bump impacts"],
                    markers=["diamond"],
                ),
                static=True,
            )
        imps = run.trajectory.impacts
        if imps:
            traj = run.trajectory
            contact = traj.impact_contacts()
            on_bump = contact >= contacts.n_rim if both else np.zeros(len(contact), dtype=bool)
            t = traj.impact_times()
            y = base + contact.astype(float)
            sizes = marker_sizes(traj.impact_column("impulse"), biggest)
            for sel, where in ((~on_bump, path), (on_bump, f"{path}/bump")):
                if sel.any():
                    rec.send_columns(
                        where,
                        [time_column(t[sel])],
                        [
                            *rr.Scalars.columns(scalars=y[sel]),
                            *rr.SeriesPoints.columns(marker_sizes=sizes[sel]),
                        ],
                    )
        _log_mismatch(rec, run, base)
        _log_impact_text(rec, run, contacts)


def _log_lane_guide(rec: rr.RecordingStream, run: RunView, base: float, t_max: float) -> None:
    """A faint line in the lane's colour under its contact 0, from t = 0 to t_max."""
    path = f"{RASTER}/lanes/{run.name}"
    rec.log(
        path,
        rr.SeriesLines(colors=[(*run.color, 90)], names=[f"{run.label} lane"], widths=[1.0]),
        static=True,
    )
    rec.send_columns(
        path, [time_column([0.0, t_max])], rr.Scalars.columns(scalars=[base - 0.5, base - 0.5])
    )


def _log_mismatch(rec: rr.RecordingStream, run: RunView, base: float) -> None:
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
    rec.send_columns(path, [time_column([t])], rr.Scalars.columns(scalars=[base + float(contact)]))


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


def raster_range(lanes: int, n_contacts: int) -> tuple[float, float]:
    """y range that shows every lane with a margin."""
    top = lane_base(0, lanes, n_contacts) + n_contacts - 1
    return -0.8, top + 0.8 if math.isfinite(top) else 1.0
