"""The runs a recording shows: names, colours, the common time span, and per run what the
views need (its attitude and energy series, its impacts matched against the reference,
its energy exponent).  Plain data; nothing here talks to rerun."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from reference.exponent import ExponentFit, excess_energy_of
from reference.scene import Scene
from reference.trajectory import Trajectory

from ..metrics import ImpactMatch, RunMetrics, evaluate, run_exponent
from ..text import run_label
from .geometry import headings, inclinations

# One colour per simulator in every view: the reference mid grey (context, never on top
# of the others), then the tab10 colours without red (red marks the first mismatch).
REFERENCE_COLOR = (150, 150, 150)
PALETTE = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (148, 103, 189),
    (227, 119, 194),
    (188, 189, 34),
    (23, 190, 207),
    (140, 86, 75),
]
MISMATCH_COLOR = (230, 40, 40)


def mismatch_marker(label: str, size: float):
    """The red cross that marks a run's first mismatch or divergence in every view."""
    import rerun as rr

    return rr.SeriesPoints(
        colors=[MISMATCH_COLOR], names=[label], markers=["cross"], marker_sizes=[size]
    )


TIME_MARGIN = 0.1  # the recording runs to the reference's end × (1 + TIME_MARGIN)


@dataclass
class RunView:
    """One simulator in the recording.

    name: its entity-path part; label: what views call it; trajectory: trimmed to the
    recording's time span; metrics: harness.metrics.evaluate against the reference on
    the whole run (None for the reference itself), match: its impacts against the
    reference's; fit: its energy exponent (c only if it reached the singularity);
    alpha, psi, excess: inclination (rad), heading of the lowest point (turns) and
    energy above rest per sample."""

    name: str
    label: str
    color: tuple[int, int, int]
    trajectory: Trajectory
    is_reference: bool
    fit: ExponentFit
    metrics: RunMetrics | None
    alpha: np.ndarray
    psi: np.ndarray
    excess: np.ndarray

    @property
    def match(self) -> ImpactMatch | None:
        return None if self.metrics is None else self.metrics.match


def entity_names(trajs: list[Trajectory]) -> list[str]:
    """One unique entity-path part per trajectory: engine name, `_dt<dt>` for fixed-step
    runs, `_2`, `_3`, ... when still repeated; characters outside [A-Za-z0-9_-] become `_`."""
    names: list[str] = []
    for traj in trajs:
        base = re.sub(r"[^A-Za-z0-9_\-]", "_", traj.engine) or "simulator"
        if traj.dt is not None:
            base += f"_dt{traj.dt:.0e}"
        name, k = base, 2
        while name in names or name in ("impacts", "behind", "singularity", "summary", "reading"):
            name, k = f"{base}_{k}", k + 1
        names.append(name)
    return names


def reference_end(reference: Trajectory) -> float:
    """Where the reference's motion ends: its t_singularity, else its last sample."""
    ends = [float(reference.t[-1])] if reference.n_samples else [0.0]
    if reference.t_singularity is not None and math.isfinite(reference.t_singularity):
        ends.append(float(reference.t_singularity))
    return max(ends)


def time_span(reference: Trajectory) -> float:
    """The recording's end: the reference's end plus TIME_MARGIN of it (an engine that
    keeps rocking after the reference stopped is shown for a tenth longer)."""
    end = reference_end(reference)
    return end * (1.0 + TIME_MARGIN) if end > 0 else math.inf


def trimmed(traj: Trajectory, t_max: float) -> Trajectory:
    """The run's samples and impacts up to t_max (the same object if nothing is cut)."""
    if traj.n_samples == 0 or float(traj.t[-1]) <= t_max:
        return traj
    k = int(np.searchsorted(traj.t, t_max, side="right"))
    cut = {
        f: getattr(traj, f)[:k]
        for f in (
            "t",
            "position",
            "quaternion",
            "velocity",
            "angular_velocity",
            "kinetic_energy",
            "potential_energy",
        )
    }
    return Trajectory(
        engine=traj.engine,
        scene=traj.scene,
        impacts=[e for e in traj.impacts if e.t <= t_max],
        status=traj.status,
        message=traj.message,
        t_final=traj.t_final,
        t_singularity=traj.t_singularity,
        phases=traj.phases,
        stats=traj.stats,
        t_lo=None if traj.t_lo is None else traj.t_lo[:k],
        dt=traj.dt,
        **cut,
    )


def build_runs(
    trajs: list[Trajectory],
    scene: Scene,
    metrics: list[RunMetrics | None] | None = None,
    fits: list[ExponentFit] | None = None,
) -> list[RunView]:
    """RunViews for trajectories whose first is the reference.  `metrics` and `fits`
    (one per trajectory) are computed here when not given (harness.metrics)."""
    reference = trajs[0]
    t_max = time_span(reference)
    names = entity_names(trajs)
    runs = []
    for k, (name, traj) in enumerate(zip(names, trajs, strict=True)):
        if metrics is not None:
            m = metrics[k]
        else:
            m = None if k == 0 else evaluate(traj, reference, scene.gravity)
        match = None if m is None else m.match
        fit = fits[k] if fits is not None else run_exponent(traj, scene, reference, match)
        shown = trimmed(traj, t_max)
        with np.errstate(invalid="ignore"):
            excess = excess_energy_of(shown, scene)
        runs.append(
            RunView(
                name=name,
                label=run_label(traj.engine, traj.dt),
                color=REFERENCE_COLOR if k == 0 else PALETTE[(k - 1) % len(PALETTE)],
                trajectory=shown,
                is_reference=k == 0,
                fit=fit,
                metrics=m,
                alpha=inclinations(shown.quaternion) if shown.n_samples else np.zeros(0),
                psi=headings(shown.quaternion) if shown.n_samples else np.zeros(0),
                excess=excess,
            )
        )
    return runs
