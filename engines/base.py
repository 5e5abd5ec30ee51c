"""What every engine adapter shares: the impact sequence derived from contact activity,
and assembly of a `Trajectory` in the reference's conventions.

Engines have no impact events.  An adapter records, per step and per contact point k,
the normal impulse the engine applied (force × dt); a contact is *active* in a step when
that impulse is positive.  An impact is the onset of activity of a contact that was
inactive in the previous step.  Its

- time is where the geometric gap (computed from the engine's own poses with the
  reference's contact geometry) crosses zero, interpolated linearly inside the step
  before the onset (the onset step's start when no crossing is seen);
- impulse is the sum of the contact's impulses from the onset while the contact point
  is still approaching or being pushed apart, i.e. until its normal velocity stops
  increasing or the contact goes inactive (the compression + restitution phase), capped
  at `max_impact_steps` steps so a sustained contact does not count as one long impact;
- pre/post normal velocities are the contact point's normal velocity in the sample
  before the onset and at the end of that window.
"""

from __future__ import annotations

import numpy as np

from reference.body import BodyModel
from reference.scene import Scene
from reference.trajectory import ImpactEvent, Status, Trajectory


def contact_kinematics(scene: Scene, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gap and normal velocity of every contact for states (N, 13) → two (N, k) arrays."""
    model = BodyModel.from_scene(scene)
    gaps = np.empty((len(states), model.n_contacts))
    vns = np.empty_like(gaps)
    for i, y in enumerate(states):
        g, _, _, vn, _ = model.contacts(y)
        gaps[i], vns[i] = g, vn
    return gaps, vns


def impacts_from_contact_activity(
    t: np.ndarray,
    impulses: np.ndarray,
    gaps: np.ndarray,
    vn: np.ndarray,
    max_impact_steps: int = 50,
) -> list[ImpactEvent]:
    """Impacts from per-step contact impulses (N, k), gaps (N, k), normal velocities (N, k).

    Row j of `impulses` is the impulse applied during the step that ends at t[j]."""
    active = impulses > 0.0
    events: list[ImpactEvent] = []
    n_steps, n_contacts = impulses.shape
    for k in range(n_contacts):
        onsets = np.flatnonzero(active[1:, k] & ~active[:-1, k]) + 1
        if n_steps and active[0, k]:
            onsets = np.concatenate([[0], onsets])
        for j in onsets:
            # time: zero crossing of the gap in the step before the onset
            tj = t[j - 1] if j > 0 else t[0]
            if j > 0 and gaps[j - 1, k] > 0.0 and gaps[j, k] <= 0.0:
                g0, g1 = gaps[j - 1, k], gaps[j, k]
                tj = t[j - 1] + (t[j] - t[j - 1]) * g0 / (g0 - g1)
            end = j
            total = 0.0
            while end < n_steps and active[end, k] and end - j < max_impact_steps:
                total += impulses[end, k]
                if end > j and vn[end, k] <= vn[end - 1, k]:
                    break
                end += 1
            end = min(end, n_steps - 1)
            pre = vn[j - 1, k] if j > 0 else vn[0, k]
            events.append(
                ImpactEvent(
                    t=float(tj),
                    contact=int(k),
                    impulse=float(total),
                    v_normal_pre=float(pre),
                    v_normal_post=float(vn[end, k]),
                )
            )
    events.sort(key=lambda e: (e.t, e.contact))
    return events


def build_trajectory(
    scene: Scene,
    engine: str,
    dt: float,
    t: np.ndarray,
    states: np.ndarray,
    impulses: np.ndarray,
    status: Status,
    message: str,
    stats: dict,
    sample_every: int = 1,
) -> Trajectory:
    """Assemble a Trajectory from per-step engine output.

    `states` (N, 13) in the reference's conventions (x, q wxyz, v, ω world) and
    `impulses` (N, k) are per step; samples keep every `sample_every`-th step (and the
    last), impacts use every step."""
    model = BodyModel.from_scene(scene)
    gaps, vns = contact_kinematics(scene, states)
    impacts = impacts_from_contact_activity(t, impulses, gaps, vns)
    keep = np.arange(0, len(t), max(1, sample_every))
    if len(t) and keep[-1] != len(t) - 1:
        keep = np.append(keep, len(t) - 1)
    S = states[keep]
    ke = np.array([model.kinetic_energy(y) for y in S])
    pe = np.array([model.potential_energy(y) for y in S])
    stats = dict(stats)
    stats["min_gap"] = float(gaps.min()) if gaps.size else None
    return Trajectory(
        engine=engine,
        scene=scene.name,
        t=t[keep],
        position=S[:, 0:3],
        quaternion=S[:, 3:7],
        velocity=S[:, 7:10],
        angular_velocity=S[:, 10:13],
        kinetic_energy=ke,
        potential_energy=pe,
        impacts=impacts,
        status=status,
        message=message,
        t_final=float(t[-1]) if len(t) else 0.0,
        stats=stats,
        dt=dt,
    )
