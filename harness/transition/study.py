"""`harness transition`: run the study's scene and assemble its JSON document.

The document (docs/contract.md, "harness transition"): the scene and simulator, the
run's status, the end used as t_f, the regimes (harness.transition.regimes) with their
exponents, the takeover tilts against Δ/a, the paper's estimate (α ≈ Δ/d, "the last
0.1 … 1 second") and, for the plot, the energy against the time to the singularity at
each impact with its kind.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from reference.bumpy import is_bumpy
from reference.scene import Scene, SceneError
from reference.trajectory import Trajectory

from .regimes import classify, takeover

PAPER_ESTIMATE = {
    "takeover_tilt": "alpha ~ Delta/d",
    "last_seconds": [0.1, 1.0],
    "source": "Baranyai & Varkonyi, conclusion: the triangle model describes the motion "
    "once the tilt drops well below Delta/d, during the last 0.1 ... 1 second (Leine's "
    "experiments)",
}
# Impacts kept for the plot's points: every impact up to this many, else an even thinning
# (the last impacts, which carry the end of the motion, are always kept).
MAX_PLOT_POINTS = 20_000


def check_bumpy(scene: Scene) -> None:
    if not is_bumpy(scene):
        raise SceneError(
            f'harness transition needs a bumpy ground ([ground] kind = "bumpy"); '
            f"scene {scene.name!r} has {scene.ground.kind!r}"
        )


def transition_document(traj: Trajectory, scene: Scene, engine: str) -> dict[str, Any]:
    """The study's document for one run."""
    series, act, regimes = classify(traj, scene)
    points = _plot_points(series)
    return {
        "scene": scene.name,
        "engine": engine,
        "status": traj.status.value,
        "message": traj.message,
        "n": scene.body.n,
        "gyration": scene.body.gyration,
        "restitution": scene.restitution,
        "radius": scene.body.radius,
        "gravity": scene.gravity,
        "initial_tilt": series.at(series.tilt, float(series.t[0])) if len(series.t) else None,
        "t_f": series.t_f,
        "t_f_source": series.t_f_source,
        "energy_model": "E - I3 w3^2/2 - m g z_rest (energy above the rest flat on the bumps)",
        "regimes": regimes,
        "takeover": takeover(series, act, scene),
        "paper_estimate": PAPER_ESTIMATE,
        "impacts": points,
    }


def _plot_points(series) -> dict[str, list]:
    n = len(series.impact_t)
    keep = np.arange(n)
    if n > MAX_PLOT_POINTS:
        keep = np.unique(np.concatenate([np.linspace(0, n - 1, MAX_PLOT_POINTS).astype(int)]))
    return {
        "t": series.impact_t[keep].tolist(),
        "time_to_singularity": series.impact_ttg[keep].tolist(),
        "energy": series.impact_energy[keep].tolist(),
        "kind": series.impact_kind[keep].tolist(),
    }


def run_transition(
    scene: Scene,
    engine: str,
    dt: float | None,
    t_end: float | None,
    run: Callable[..., Trajectory],
    progress: Callable[[int, int], None] | None = None,
) -> tuple[Trajectory, dict[str, Any]]:
    """Run `engine` on the scene (through `run`, harness.simulators.run_simulator) and
    build the document."""
    check_bumpy(scene)
    traj = run(engine, scene, dt, t_end, progress=progress)
    return traj, transition_document(traj, scene, engine)
