"""Rerun recordings (`--record FILE.rrd`): the simulators side by side, built around the
physics, written offline.  docs/recording.md shows and explains the views.

One `.rrd` file; the views are laid out by `layout.build_blueprint`, embedded with
`RecordingStream.save(path, default_blueprint=...)`.  Entities:

    /<sim>/scene/...                3D: ground, disk (tilt exaggerated), contacts, impact
    /<sim>/attitude/{log10_alpha,heading}     rows (rows.py)
    /<sim>/energy/{log10_excess,kinetic,potential}
    /<sim>/impacts/log              text log of the impacts
    /impacts/<sim>[/first_mismatch] the impact raster (raster.py)
    /singularity/{energy,alpha}/... log-log plots against t_f − t (singularity.py)
    /summary                        markdown summary (summary.py)

Everything temporal is on the duration timeline `sim_time`, sent with `send_columns`
(one call per entity).  The data end at the reference's end + 10 % (runs.time_span).
No global recording is created.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import rerun as rr

from reference.scene import Scene
from reference.trajectory import Trajectory

from ..outputs import atomic_write, recording_path
from .geometry import exaggeration_schedule
from .layout import SUMMARY, RowRanges, build_blueprint, value_range
from .raster import log_raster, raster_range
from .rows import SIM_TIME, log10_positive, log_rows, log_scene
from .runs import RunView, build_runs, entity_names, time_span  # noqa: F401
from .singularity import alpha_plot, energy_plot, log_alpha_plot, log_energy_plot
from .summary import summary_markdown

if TYPE_CHECKING:
    from ..compare import CompareResult

APPLICATION_ID = "euler_disk_harness"
# The log rows open on their top 6 decades (a plot ~120 pixels high labels every
# decade of 6, only every tenth of 9); the log-log plots on the right show all decades.
ROW_DECADES = 6.0
__all__ = [
    "APPLICATION_ID",
    "SIM_TIME",
    "entity_names",
    "record_comparison",
    "record_trajectories",
    "recording_path",
]


def record_trajectories(
    trajs: list[Trajectory],
    path: str | Path,
    scene: Scene,
    contact_tolerance: float | None = None,
    force: bool = False,
) -> Path:
    """Write one `.rrd` with the trajectories side by side; the first is the reference
    (the others are matched against it, harness.metrics).  `contact_tolerance`: gap
    below which a contact point is drawn as touching (default 1e-6 × body radius).
    Returns the path written."""
    if not trajs:
        raise ValueError("record_trajectories needs at least one trajectory")
    return _write(build_runs(trajs, scene), scene, path, contact_tolerance, force)


def record_comparison(
    result: CompareResult,
    path: str | Path,
    note: Callable[[str], None] | None = None,
    force: bool = False,
) -> Path:
    """Write the recording of a `harness compare` result, reusing its metrics and
    exponents.  Runs without samples (failed before the first step) are left out, with
    a line to `note`."""
    kept = [r for r in result.runs if r.trajectory.n_samples > 0]
    if note and len(kept) < len(result.runs):
        note(f"recording leaves out {len(result.runs) - len(kept)} run(s) without samples")
    trajs = [result.reference, *[r.trajectory for r in kept]]
    metrics = [None, *[r.metrics for r in kept]]
    fits = [result.reference_exponent, *[r.exponent for r in kept]]
    if fits[0] is None:
        fits = None
    runs = build_runs(trajs, result.scene, metrics=metrics, fits=fits)
    return _write(runs, result.scene, path, force=force)


def _row_ranges(runs: list[RunView], n_contacts: int) -> RowRanges:
    return RowRanges(
        log_alpha=value_range([log10_positive(r.alpha) for r in runs], max_span=ROW_DECADES),
        heading=value_range([r.psi for r in runs]),
        log_excess=value_range([log10_positive(r.excess) for r in runs], max_span=ROW_DECADES),
        raster=raster_range(len(runs), n_contacts),
    )


def _write(
    runs: list[RunView],
    scene: Scene,
    path: str | Path,
    contact_tolerance: float | None = None,
    force: bool = False,
) -> Path:
    out = recording_path(path)
    tol = 1e-6 * scene.body.radius if contact_tolerance is None else contact_tolerance
    ref = runs[0]
    schedule = exaggeration_schedule(ref.trajectory.t, ref.alpha)
    n_contacts = scene.n_contacts
    t_max = min(time_span(ref.trajectory), max(float(r.trajectory.t[-1]) for r in runs))
    e_plot, a_plot = energy_plot(runs), alpha_plot(runs)
    blueprint = build_blueprint(
        runs,
        scene.body.radius,
        _row_ranges(runs, n_contacts),
        None if e_plot is None else e_plot.axes,
        None if a_plot is None else a_plot.axes,
        t_max,
    )
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4())
    if not rr.is_enabled(rec):
        raise RuntimeError("rerun logging is disabled (RERUN=off?): no recording written")
    with atomic_write(out, force) as tmp:
        rec.save(tmp, default_blueprint=blueprint)
        try:
            names = ", ".join(r.label for r in runs)
            rec.send_recording_name(f"{scene.name}: {names}")
            for run in runs:
                log_scene(rec, run, scene, schedule, tol)
                log_rows(rec, run)
            log_raster(rec, runs, scene.contacts, t_max)
            log_energy_plot(rec, runs, e_plot)
            log_alpha_plot(rec, runs, a_plot)
            text = summary_markdown(runs, scene, t_max)
            rec.log(SUMMARY, rr.TextDocument(text, media_type="text/markdown"), static=True)
        finally:
            rec.flush()
            rec.disconnect()  # closes the file sink: footer and manifest are written
    return out
