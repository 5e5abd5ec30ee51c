"""Rerun recordings (`--record FILE.rrd`): the simulators side by side, built around the
physics, written offline.  docs/recording.md shows and explains the views.

One `.rrd` file; the views are laid out by `layout.build_blueprint`, sent as the
default blueprint.  The recording is encoded into memory (`rr.binary_stream`, no writer
thread on the disk: a full disk cannot stop rerun's thread and hang the run), checked
for the RRD header and footer, and written by harness.outputs.write_bytes (atomic,
fsynced, read back).  Entities:

    /<sim>/scene/...                3D: ground, disk (tilt exaggerated), contacts, impact
    /<sim>/attitude/{log10_alpha,heading}     rows (rows.py)
    /<sim>/energy/{log10_excess,kinetic,potential}
    /<sim>/impacts/log              text log of the impacts
    /impacts/<sim>[/first_mismatch] the impact rasters (raster.py)
    /impacts/<sim>/horizon_band     the horizon band above a raster's contacts (horizon.py)
    /singularity/{energy,alpha}/... log-log plots against t_f − t (singularity.py)
    /summary, /reading              markdown summary, how to read the views (summary.py)

Everything temporal is on the duration timeline `sim_time`, sent with `send_columns`
(one call per entity).  The data end at the reference's end + 10 % (runs.time_span).
No global recording is created.
"""

from __future__ import annotations

import time
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import rerun as rr

from reference.scene import Scene
from reference.trajectory import Trajectory

from ..outputs import OutputError, show, write_bytes
from .geometry import exaggeration_schedule
from .layout import READING, SUMMARY, RowRanges, build_blueprint, focus_range, value_range
from .raster import log_raster, raster_range
from .rows import SIM_TIME, log10_positive, log_rows, log_scene
from .runs import RunView, build_runs, entity_names, time_span  # noqa: F401
from .singularity import alpha_plot, energy_plot, log_alpha_plot, log_energy_plot
from .summary import reading_markdown, summary_markdown

if TYPE_CHECKING:
    from ..compare import CompareResult

APPLICATION_ID = "euler_disk_harness"
# The log rows open on their top 6 decades (a plot ~120 pixels high labels every
# decade of 6, only every tenth of 9); the log-log plots on the right show all decades.
ROW_DECADES = 6.0
# The RRD stream's first bytes and its footer's magic (written last, `rerun rrd verify`).
RRD_HEADER = b"RRF2"
RRD_FOOTER = b"RRF2FOOT"
RRD_FOOTER_TAIL = 64
# Waits on rerun's encoder thread: slices between which Ctrl-C is seen, and their bound.
FLUSH_SLICE_S = 0.25
ENCODE_TIMEOUT_S = 120.0
__all__ = [
    "APPLICATION_ID",
    "SIM_TIME",
    "entity_names",
    "record_comparison",
    "record_trajectories",
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
    horizons = [None, *[r.horizon for r in kept]]
    notes = branch_notes(result)
    return _write(runs, result.scene, path, force=force, horizons=horizons, notes=notes)


def branch_notes(result: CompareResult) -> list[str]:
    """The summary's paragraph on the branches after the reference's undecidable state
    (harness.compare.branch_text), one sentence per run; [] without one."""
    from ..compare.branch_text import branch_sentence

    sentences = [s for s in (branch_sentence(r) for r in result.runs) if s]
    if not sentences:
        return []
    u = result.spread.undecidable
    head = f"After the undecidable state at t_u = {u['t']:.7g} s, the branch each run follows:"
    return [head, *[f"- {s}" for s in sentences]]


def _row_ranges(runs: list[RunView], n_contacts: int) -> RowRanges:
    return RowRanges(
        log_alpha=value_range([log10_positive(r.alpha) for r in runs], max_span=ROW_DECADES),
        heading=value_range([r.psi for r in runs]),
        log_excess=value_range([log10_positive(r.excess) for r in runs], max_span=ROW_DECADES),
        raster=raster_range(n_contacts),
    )


def contact_word(scene: Scene) -> str:
    """What the raster's y axis counts: vertices, bumps, or contacts of both kinds."""
    contacts = scene.contacts
    if contacts.rim_only:
        return "vertex"
    return "contact" if contacts.has_plane else "bump"


def _write(
    runs: list[RunView],
    scene: Scene,
    path: str | Path,
    contact_tolerance: float | None = None,
    force: bool = False,
    horizons: list | None = None,
    notes: list[str] | None = None,
) -> Path:
    out = Path(path)
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
        focus_range(ref.trajectory.impact_times(), t_max),
        contact_word(scene),
    )
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4())
    if not rr.is_enabled(rec):
        raise RuntimeError("rerun logging is disabled (RERUN=off?): no recording written")
    stream = rr.binary_stream(rec)
    try:
        rec.send_blueprint(blueprint, make_active=False, make_default=True)
        names = ", ".join(r.label for r in runs)
        rec.send_recording_name(f"{scene.name}: {names}")
        for run in runs:
            log_scene(rec, run, scene, schedule, tol)
            log_rows(rec, run)
        log_raster(rec, runs, scene.contacts)
        if horizons is not None:
            from .horizon import log_horizon_bands

            log_horizon_bands(rec, runs, horizons, n_contacts)
        log_energy_plot(rec, runs, e_plot)
        log_alpha_plot(rec, runs, a_plot)
        text = summary_markdown(runs, scene, t_max, notes)
        rec.log(SUMMARY, rr.TextDocument(text, media_type="text/markdown"), static=True)
        reading = rr.TextDocument(reading_markdown(), media_type="text/markdown")
        rec.log(READING, reading, static=True)
        data = encoded_bytes(stream, out)
    finally:
        rec.disconnect()
    write_bytes(out, data, force)
    return out


def encoded_bytes(stream: rr.BinaryStream, out: Path, timeout_s: float = ENCODE_TIMEOUT_S) -> bytes:
    """The whole recording as RRD bytes, footer included, from rerun's in-memory sink.

    The encoder thread is waited for in short slices (Ctrl-C is handled between them) and
    for at most `timeout_s` in all; bytes that do not start with the RRD header or end
    with its footer are refused (OutputError) instead of written."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            stream.flush(timeout_sec=FLUSH_SLICE_S)
            break
        except Exception as exc:  # rerun raises a plain exception on a timeout
            if time.monotonic() > deadline:
                raise OutputError(
                    f"cannot write {show(out)}: rerun did not finish encoding the recording "
                    f"within {timeout_s:g} s ({exc})"
                ) from None
    data = stream.read(flush=False) or b""
    if not (data.startswith(RRD_HEADER) and RRD_FOOTER in data[-RRD_FOOTER_TAIL:]):
        raise OutputError(
            f"cannot write {show(out)}: rerun's encoder returned an incomplete recording "
            f"({len(data)} bytes, no RRD footer)"
        )
    return data
    return out
