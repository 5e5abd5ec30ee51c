"""What every engine adapter shares: the impact sequence derived from contact activity,
the scene's numbers an adapter needs (contact points, effective contact mass, a typical
impact speed), the impact budget (`scene.run.max_impacts`) and assembly of a `Trajectory`
in the reference's conventions.  An adapter for a new engine builds the scene's body and
ground, steps it, and hands per-step states and contact impulses to `build_trajectory`
(docs/engines.md; examples/toy-engine is a complete adapter in ~100 lines).

State convention (the reference's, `reference.geometry`): rows of 13 numbers, centre of
mass x (3), quaternion q = (w, x, y, z) body → world (4), velocity v (3) and angular
velocity ω in the **world** frame (3).  The body frame is the principal frame: vertex k
of a flat scene at a(cos 2πk/n, sin 2πk/n, 0), inertia m(ρa)² diag(1, 1, 2).

Engines have no impact events.  An adapter records, per step and per contact point k,
the normal impulse the engine applied (force × dt); a contact is *active* in a step when
that impulse is positive.  An impact is the onset of activity of a contact that was
inactive in the previous step.  Its

- time is where the geometric gap (computed from the engine's own poses with the
  reference's contact geometry) crosses zero, interpolated linearly in the interval
  where it crosses (searched up to two intervals before the onset, since engines see a
  contact only once it penetrates; the onset row's time when no crossing is seen);
- impulse is the sum of the contact's impulses from the onset while the contact point
  is still being pushed apart, i.e. until its normal velocity stops increasing or the
  contact goes inactive (the compression + restitution phase), capped by a time window
  so that a sustained contact does not count as one long impact;
- pre/post normal velocities are the contact point's normal velocity in the last row
  before the contact went active and its largest value over that window (+1 row).
"""

from __future__ import annotations

import math

import numpy as np

from reference.geometry import contact_points, energies, excess_energy, initial_state
from reference.geometry import scene_contact_kinematics as contact_kinematics
from reference.scene import Scene
from reference.trajectory import ImpactEvent, Status, Trajectory

__all__ = [
    "build_trajectory",
    "contact_kinematics",
    "contact_points",
    "effective_contact_mass",
    "energies",
    "impacts_from_contact_activity",
    "initial_state",
    "scene_points",
    "typical_impact_speed",
]


def scene_points(scene: Scene) -> np.ndarray:
    """(k, 3) contact points of the scene (`GroundContacts.points`): body-frame rim
    vertices, then world floor points, in the scene's contact numbering."""
    return contact_points(scene.body, scene.ground)


def effective_contact_mass(scene: Scene) -> float:
    """Mass a unit normal impulse at one contact sees when the body lies flat:
    1/m_eff = 1/m + |r × n|²/I₁ with |r × n| the lever arm of contact 0
    (`GroundContacts.lever`: a for a rim vertex, b for a floor point)
    and I₁ = m(ρa)², i.e. m_eff = m/(1 + (r/(ρa))²) (the paper's η/g for a vertex).  For
    the small tilts of these scenes the true value differs by O(α²)."""
    b = scene.body
    lever = scene.contacts.lever(0)
    return b.mass / (1.0 + (lever / (b.gyration * b.radius)) ** 2)


def typical_impact_speed(scene: Scene) -> float:
    """A scale of the scene's impact speeds: √(E_x/(2 m_eff)), half the normal speed one
    contact would reach if the whole excess energy E_x (above the resting level) went into
    it.  On the built-in scenes (pentagon-bounce, triangle-chatter, three-point-disk,
    elastic-hexagon) the first impacts come at 0.45–1.5 of this value; later ones are
    slower, down to zero at the singularity.  √(g a) when the scene starts with no excess
    energy."""
    ex = float(excess_energy(scene, initial_state(scene.initial)[None])[0])
    v = math.sqrt(0.5 * max(ex, 0.0) / effective_contact_mass(scene))
    return v if v > 0 else math.sqrt(scene.gravity * scene.body.radius)


def impacts_from_contact_activity(
    t: np.ndarray,
    impulses: np.ndarray,
    gaps: np.ndarray,
    vn: np.ndarray,
    max_impact_time: float | None = None,
) -> list[ImpactEvent]:
    """Impacts from per-step contact impulses (N, k), gaps (N, k), normal velocities (N, k).

    Row j of `impulses` is the impulse the engine applied in the step that produced the
    state of row j (MuJoCo and PyBullet detect a contact only once it penetrates, so the
    gap may already be ≤ 0 at the onset row: the zero crossing is searched up to two
    intervals back).  The impact window ends when the contact goes inactive, when its
    normal velocity stops increasing, or after `max_impact_time` (default: 50 steps or
    0.05 s, whichever is longer: soft default contacts last ~0.02 s); v⁺ is the largest
    normal velocity over the window and the row after it (engines book the impulse on
    the row before or after the step that applies it; the bounce peaks either way)."""
    return [event for event, _ in _impact_windows(t, impulses, gaps, vn, max_impact_time)]


def _impact_windows(
    t: np.ndarray,
    impulses: np.ndarray,
    gaps: np.ndarray,
    vn: np.ndarray,
    max_impact_time: float | None = None,
) -> list[tuple[ImpactEvent, int]]:
    """`impacts_from_contact_activity` with, for each impact, the row where its v⁺ was
    read (the end of the impact), sorted by time."""
    active = impulses > 0.0
    events: list[tuple[ImpactEvent, int]] = []
    n_steps, n_contacts = impulses.shape
    if n_steps == 0:
        return events
    dt = float(np.median(np.diff(t))) if n_steps > 1 else 0.0
    window = max_impact_time if max_impact_time is not None else max(50 * dt, 0.05)
    for k in range(n_contacts):
        onsets = np.flatnonzero(active[1:, k] & ~active[:-1, k]) + 1
        if active[0, k]:
            onsets = np.concatenate([[0], onsets])
        for j in onsets:
            tj = t[j]
            for i in (j, j - 1, j - 2):  # crossing between rows i−1 and i
                if i >= 1 and gaps[i - 1, k] > 0.0 and gaps[i, k] <= 0.0:
                    g0, g1 = gaps[i - 1, k], gaps[i, k]
                    tj = t[i - 1] + (t[i] - t[i - 1]) * g0 / (g0 - g1)
                    break
            last = j
            total = impulses[j, k]
            i = j + 1
            while i < n_steps and active[i, k] and t[i] - t[j] <= window:
                if vn[i, k] <= vn[i - 1, k]:
                    break
                total += impulses[i, k]
                last = i
                i += 1
            # v⁺: the largest normal velocity over the window and the row after it (the
            # bounce peaks there whichever row an engine books the impulse on)
            hi_row = min(last + 1, n_steps - 1)
            post_row = j + int(np.argmax(vn[j : hi_row + 1, k]))
            pre_row = max(j - 1, 0)
            for r in (j - 1, j - 2):  # the last row that was still approaching freely
                if r >= 0 and not active[r, k]:
                    pre_row = r
                    break
            event = ImpactEvent(
                t=float(tj),
                contact=int(k),
                impulse=float(total),
                v_normal_pre=float(vn[pre_row, k]),
                v_normal_post=float(vn[post_row, k]),
            )
            events.append((event, int(post_row)))
    events.sort(key=lambda e: (e[0].t, e[0].contact))
    return events


def impact_budget_end(windows: list[tuple[ImpactEvent, int]], max_impacts: int) -> int | None:
    """Last row to keep when the run has more impacts than `max_impacts` (the end of the
    max_impacts-th impact), None when the budget is not exhausted.  The reference stops
    right after that impact with status max_impacts; engines are cut there the same way."""
    if len(windows) <= max_impacts:
        return None
    if max_impacts == 0:
        return 0
    return max(row for _, row in windows[:max_impacts])


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
    last), impacts use every step.  A run with more impacts than the scene's
    `run.max_impacts` ends after the max_impacts-th one with status `max_impacts`
    (`impact_budget_end`), as the reference does."""
    gaps, vns = contact_kinematics(scene, states)
    windows = _impact_windows(t, impulses, gaps, vns)
    end = impact_budget_end(windows, scene.run.max_impacts)
    if end is not None:
        n_kept = scene.run.max_impacts
        t, states, gaps = t[: end + 1], states[: end + 1], gaps[: end + 1]
        windows = windows[:n_kept]
        status, message = Status.MAX_IMPACTS, f"reached max_impacts = {n_kept}"
    impacts = [event for event, _ in windows]
    keep = np.arange(0, len(t), max(1, sample_every))
    if len(t) and keep[-1] != len(t) - 1:
        keep = np.append(keep, len(t) - 1)
    S = states[keep]
    ke, pe = energies(scene, S)
    stats = dict(stats)
    stats["min_gap"] = float(gaps.min()) if gaps.size else None
    return Trajectory.from_states(
        engine,
        scene.name,
        t[keep],
        S,
        ke,
        pe,
        impacts,
        status,
        message=message,
        t_final=float(t[-1]) if len(t) else 0.0,
        stats=stats,
        dt=dt,
    )
