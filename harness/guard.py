"""The run-time guard every simulator's result passes (harness.simulators.run_simulator).

A simulator may return a state that is no motion at all: a NaN or an infinite value, a
quaternion that is no longer a rotation, or a body that has passed through the ground.
Whatever the engine, such a run ends `failed` at the first such sample, with a message
naming the time and what was wrong; the samples and impacts before it are kept, those
from it on are dropped, so that nothing non-finite reaches a summary, a file or a plot.

Tolerances:

- QUATERNION_NORM_TOLERANCE = 1e-6: engines and the reference keep | |q| − 1 | at
  roundoff (measured ≤ 3e-13 over the built-in scenes); a millionth means the attitude
  is no longer integrated as a rotation.
- PENETRATION_TOLERANCE = 0.05 (of the body radius a): the depth past which the engine
  adapters already declare a fall-through (PyBullet's contact face is 0.05 a thick, a
  deeper vertex has crossed it; MuJoCo's three_point face is 0.1 a thick).  Soft
  contacts penetrate by design, far less than this at any timestep that resolves an
  impact; accuracy within it is for the metrics (`max_penetration` in stress) to judge.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from reference import geometry
from reference import quaternion as qt
from reference.core import layout as L
from reference.scene import Scene
from reference.trajectory import Status, Trajectory

QUATERNION_NORM_TOLERANCE = 1e-6
PENETRATION_TOLERANCE = 0.05
# rows per exact contact evaluation (bounds the (rows, n) arrays to ~16 MB each)
_CHUNK_CELLS = 2_000_000


def guard_trajectory(scene: Scene, traj: Trajectory) -> Trajectory:
    """`traj` unchanged when every sample and impact is a valid state; else the run cut
    at the first invalid one, status `failed` (module docstring)."""
    found = first_invalid_sample(scene, traj)
    bad_impact = _first_invalid_impact(traj)
    if bad_impact is not None and (found is None or bad_impact[0] < traj.t[found[0]]):
        t_bad, why = bad_impact
        cut = int(np.searchsorted(traj.t, t_bad, side="left"))
        found = (cut, why)
    if found is None:
        if traj.n_samples == 0 and traj.status not in (Status.FAILED, Status.STALLED):
            return dataclasses.replace(
                traj, status=Status.FAILED, message="the simulator returned no samples"
            )
        return traj
    index, why = found
    return cut_trajectory(traj, index, why)


def first_invalid_sample(scene: Scene, traj: Trajectory) -> tuple[int, str] | None:
    """(index, reason) of the first sample that is not a valid state, or None."""
    if traj.n_samples == 0:
        return None
    states = _states(traj)
    finite = (
        np.isfinite(traj.t)
        & np.isfinite(states).all(axis=1)
        & np.isfinite(traj.kinetic_energy)
        & np.isfinite(traj.potential_energy)
    )
    norm = np.linalg.norm(np.where(finite[:, None], states[:, L.QUATERNION], 1.0), axis=1)
    unit = np.abs(norm - 1.0) <= QUATERNION_NORM_TOLERANCE
    checks = [
        (finite, "a non-finite value (NaN or infinity)"),
        (unit, "a quaternion of norm far from 1"),
    ]
    first = _first_false(finite & unit)
    depth = -PENETRATION_TOLERANCE * scene.body.radius
    below = _first_below(scene, states, depth, stop=first)
    candidates = [(i, why) for ok, why in checks if (i := _first_false(ok)) is not None]
    if below is not None:
        i, gap, k = below
        candidates.append(
            (i, f"contact {k} {-gap / scene.body.radius:.3g} body radii below the ground")
        )
    return min(candidates) if candidates else None


def cut_trajectory(traj: Trajectory, index: int, why: str) -> Trajectory:
    """The run up to (not including) sample `index`, status failed, with the reason."""
    t_bad = float(traj.t[index]) if np.isfinite(traj.t[index]) else float("nan")
    when = f"t = {t_bad:.9g}" if np.isfinite(t_bad) else f"sample {index}"
    keep = slice(0, index)
    times = traj.impact_times() if len(traj.impacts) else np.zeros(0)
    last_t = float(traj.t[index - 1]) if index > 0 else 0.0
    kept = [traj.impacts[int(i)] for i in np.flatnonzero(np.isfinite(times) & (times <= last_t))]
    earlier = f"; before that: {traj.message}" if traj.message else ""
    stats = dict(traj.stats)
    stats["guard"] = {"sample": int(index), "reason": why}
    return dataclasses.replace(
        traj,
        t=traj.t[keep],
        position=traj.position[keep],
        quaternion=traj.quaternion[keep],
        velocity=traj.velocity[keep],
        angular_velocity=traj.angular_velocity[keep],
        kinetic_energy=traj.kinetic_energy[keep],
        potential_energy=traj.potential_energy[keep],
        t_lo=None if traj.t_lo is None else traj.t_lo[keep],
        impacts=kept,
        status=Status.FAILED,
        message=f"{traj.engine} produced {why} at {when}; the run is cut there{earlier}",
        t_final=last_t,
        t_singularity=None,
        stats=stats,
    )


# ----------------------------------------------------------------------------- helpers


def _states(traj: Trajectory) -> np.ndarray:
    return np.concatenate(
        [traj.position, traj.quaternion, traj.velocity, traj.angular_velocity], axis=1
    )


def _first_false(ok: np.ndarray) -> int | None:
    bad = np.flatnonzero(~ok)
    return int(bad[0]) if bad.size else None


def _first_below(
    scene: Scene, states: np.ndarray, depth: float, stop: int | None
) -> tuple[int, float, int] | None:
    """(row, gap, contact) of the first row (before `stop`) with a contact gap below
    `depth`.  On a ground of rim vertices alone the lowest point of the body's circumcircle,
    z − a |(e3x, e3y)|, bounds every vertex gap from below, so only rows where that
    bound dips below `depth` need the exact gaps (reference.geometry): O(rows) for any n
    in a sane run."""
    rows = states[:stop] if stop is not None else states
    if scene.contacts.rim_only:
        e3 = qt.body_axis(qt.normalize(rows[:, L.QUATERNION]))
        bound = rows[:, L.Z] - scene.body.radius * np.hypot(e3[:, 0], e3[:, 1])
        candidates = np.flatnonzero(bound < depth)
    else:
        candidates = np.arange(len(rows))
    chunk = max(1, _CHUNK_CELLS // scene.n_contacts)
    for start in range(0, len(candidates), chunk):
        idx = candidates[start : start + chunk]
        gaps = geometry.scene_contact_kinematics(scene, rows[idx])[0]
        low = gaps.min(axis=1)
        hit = np.flatnonzero(low < depth)
        if hit.size:
            j = int(hit[0])
            return int(idx[j]), float(low[j]), int(np.argmin(gaps[j]))
    return None


def _first_invalid_impact(traj: Trajectory) -> tuple[float, str] | None:
    """(time, reason) of the first impact with a non-finite time or impulse."""
    if not len(traj.impacts):
        return None
    times = traj.impact_times()
    impulses = traj.impact_column("impulse")
    bad = ~(np.isfinite(times) & np.isfinite(impulses))
    if not bad.any():
        return None
    i = int(np.flatnonzero(bad)[0])
    last = float(traj.t[-1]) if traj.n_samples else 0.0
    t = float(times[i]) if np.isfinite(times[i]) else last
    return t, f"an impact with a non-finite time or impulse (impact {i})"
