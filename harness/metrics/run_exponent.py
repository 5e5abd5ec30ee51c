"""The energy exponent c of a run, only where the run reached the end of the motion.

The estimator is reference.exponent (regression of log E before each impact on
log(t_f − t), E the energy above the resting level, with its standard error); this
module decides which t_f a run may use:

- a run with status `singularity` uses its own t_singularity;
- a run that followed the reference to the reference's singularity (the reference ended
  `singularity`, every reference impact was matched or skipped as a chatter tail, and
  the run went on at least as long) uses the reference's t_f: it is the same motion;
- any other run has no c: an engine stopped by t_end, an undecidable simultaneous impact
  or a budget never reached a singularity, and its last impact is not one.
"""

from __future__ import annotations

from reference.exponent import ExponentFit, excess_energy_of, trajectory_exponent
from reference.scene import Scene
from reference.trajectory import Status, Trajectory

from .matching import ImpactMatch


def followed_to_singularity(run: Trajectory, reference: Trajectory, match: ImpactMatch) -> bool:
    """Whether `run` followed `reference` to its singularity (module docstring)."""
    return (
        reference.status is Status.SINGULARITY
        and reference.t_singularity is not None
        and match.mismatch is None
        and match.n_matched + match.skipped_reference == match.n_reference > 0
        and run.n_samples > 0
        and float(run.t[-1]) >= float(reference.t[-1])
    )


def run_exponent(
    run: Trajectory,
    scene: Scene,
    reference: Trajectory | None = None,
    match: ImpactMatch | None = None,
) -> ExponentFit:
    """c of `run` on the scene's energy above rest (module docstring for when)."""
    if run.status is Status.SINGULARITY:
        return trajectory_exponent(run, excess_energy_of(run, scene))
    if reference is not None and match is not None:
        if followed_to_singularity(run, reference, match):
            return trajectory_exponent(
                run,
                excess_energy_of(run, scene),
                t_singularity=reference.t_singularity,
                from_reference=True,
            )
    why = f"ended {run.status.value} at t = {run.t_final:.6g} s, not at a singularity"
    if reference is not None and reference.status is Status.SINGULARITY and match is not None:
        why += " (it left the reference)" if match.mismatch else " (short of t_f)"
    return ExponentFit(reason=why)
