"""The energy exponent c used by the fidelity test: one place to change the estimator.

Today it is the project's one estimator (reference.exponent.trajectory_exponent on the
energy above rest, reference.geometry.excess_energy), with harness.metrics.run_exponent
deciding which t_f a run may use: its own singularity, or the reference's when it
followed the reference there impact for impact; any other run has no c.  A fixed-step
engine stopped at the end of the leading impacts never has one, so the exponent
criterion applies only with `--window whole`, and only to runs that follow the
reference to its singularity.
"""

from __future__ import annotations

from reference.exponent import ExponentFit
from reference.scene import Scene
from reference.trajectory import Trajectory

from ..metrics import ImpactMatch, run_exponent


def exponent_of(
    run: Trajectory,
    scene: Scene,
    reference: Trajectory | None = None,
    match: ImpactMatch | None = None,
) -> ExponentFit:
    """c of `run` on `scene` (module docstring); `reference` and `match` let a run that
    followed the reference to its singularity use the reference's t_f."""
    return run_exponent(run, scene, reference, match)
