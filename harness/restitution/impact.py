"""One impact read from a run's rows: e_eff = −u⁺/u⁻, the energy change against the
exact loss, penetration and contact duration of the watched contact.

Rows (the reference's state convention) give the watched point's gap g and normal
velocity u (`reference.geometry.contact_kinematics`).  The impact's window:

- entry: the first row where the point is below its ground (g < 0) or already moving
  away (u > 0: an event-driven run's post-impact row, or a bounce before touching);
- pre = the row before it; post = the first row from the entry on that is at or above
  the ground and moving away.

u⁻ and u⁺ are the normal velocities of the free flights before and after at touch-down
t_in and lift-off t_out (g's zero crossings, interpolated linearly between rows):
u(t_in) = u(pre) + ü (t_in − t_pre), u(t_out) = u(post) − ü (t_post − t_out), with ü the
free flight's normal acceleration at that row (the reference's `normal_acceleration` of
`free_acceleration`: gravity and the rotation), so that an engine is not charged for
where its rows fall.  What happens between t_in and t_out (gravity during a finite
contact, the rotation) is the engine's.  An event-driven run records the states just
before and just after its impact at the same time: its window is those two rows and
u⁻, u⁺ are exact.

Energy: ΔE = E(post) − E(pre) with E kinetic + potential (conserved in flight).  Newton's
law at one contact loses exactly

    ΔE_exact = −(1 − γ²) · ½ u⁻² / w,   w = J M⁻¹ Jᵀ      (paper §2.3, eq. F)

(the impulse ζ = −(1 + γ) u⁻/w does work ζ (u⁻ + u⁺)/2), with w the reference's own
`impulse_response` at the pre row.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from reference.geometry import contact_kinematics, energies
from reference.scene import Scene
from reference.trajectory import Trajectory

# ΔE above this fraction of the impact's kinetic energy scale ½ u⁻²/w counts as energy
# gained (not roundoff: the reference's ΔE errs by ~1e-15 of it).
GAIN_TOLERANCE = 1e-9


@dataclass(frozen=True)
class ImpactReading:
    """What one run says about its first impact of the watched contact.  `outcome`:
    "ok", "no contact" (never touched), "no separation" (still touching at the end;
    e_eff the last row's −u/u⁻), or the run's status when it ended otherwise."""

    outcome: str
    u_pre: float | None = None
    u_post: float | None = None
    e_eff: float | None = None
    energy_change: float | None = None  # ΔE = E(post) − E(pre)
    energy_loss_exact: float | None = None  # (1 − γ²) ½ u⁻²/w  (> 0)
    energy_gained: bool = False
    penetration: float | None = None  # deepest −g in the window (≥ 0)
    contact_time: float | None = None  # time with g < 0 (zero crossings interpolated)
    w: float | None = None

    def to_dict(self) -> dict:
        return asdict(self)


def watched_contact(points: np.ndarray, flat: bool):
    """The watched point as a one-contact ground (reference.contact_kinds): a rim point
    on the plane when `flat`, else a floor point under the face."""
    from reference.contact_kinds import GroundContacts

    points = np.ascontiguousarray(points, dtype=float)
    return GroundContacts(points, np.full(len(points), _kind(flat), dtype=np.int64))


def _kind(flat: bool) -> int:
    from reference.core.records import FLOOR_POINT_ON_FACE, RIM_VERTEX_ON_PLANE

    return RIM_VERTEX_ON_PLANE if flat else FLOOR_POINT_ON_FACE


def contact_compliance(scene: Scene, state: np.ndarray, points: np.ndarray, flat: bool) -> float:
    """w = J M⁻¹ Jᵀ of the contact at points[0] in `state`: the reference's own
    `impulse_response` (the normal velocity's change per unit normal impulse)."""
    from reference.core.contacts import contact_frame
    from reference.core.inertia import impulse_response

    i1, _, i3 = scene.body.inertia_diag
    y = np.ascontiguousarray(state, dtype=float)
    frame = contact_frame(y, _kind(flat), np.ascontiguousarray(points, dtype=float), 0)
    return float(impulse_response(y, frame, scene.body.mass, i1, i3).w)


def free_normal_acceleration(
    scene: Scene, state: np.ndarray, points: np.ndarray, flat: bool
) -> float:
    """ü of the contact at points[0] in free flight: the reference's
    `normal_acceleration` of its `free_acceleration` (gravity and the rotation)."""
    from reference.core.contacts import contact_frame, normal_acceleration
    from reference.core.inertia import free_acceleration

    i1, _, i3 = scene.body.inertia_diag
    y = np.ascontiguousarray(state, dtype=float)
    pts = np.ascontiguousarray(points, dtype=float)
    acc = free_acceleration(y, i1, i3, scene.gravity)
    kind = _kind(flat)
    return float(normal_acceleration(y, contact_frame(y, kind, pts, 0), acc, kind, pts, 0))


def exact_energy_loss(gamma: float, u_pre: float, w: float) -> float:
    """(1 − γ²) · ½ u⁻² / w: the kinetic energy Newton's law takes from one impact."""
    return (1.0 - gamma * gamma) * 0.5 * u_pre * u_pre / w


def read_impact(scene: Scene, traj: Trajectory, points: np.ndarray, flat: bool) -> ImpactReading:
    """The first impact of the watched contact (module docstring)."""
    states = trajectory_states(traj)
    if len(states) < 2:
        return ImpactReading(_ended(traj))
    gap, un = (c[:, 0] for c in contact_kinematics(states, watched_contact(points, flat)))
    entry = _first(np.flatnonzero((gap[1:] < 0.0) | (un[1:] > 0.0)) + 1)
    if entry is None:
        return ImpactReading("no contact" if traj.status.value == "t_end" else _ended(traj))
    pre = entry - 1
    leave = _first(np.flatnonzero((gap[entry:] >= 0.0) & (un[entry:] > 0.0)) + entry)
    post = leave if leave is not None else len(states) - 1
    t = traj.t
    t_in, t_out = _touch_down_lift_off(t, gap, pre, post)
    u_pre = float(un[pre]) + free_normal_acceleration(scene, states[pre], points, flat) * (
        t_in - t[pre]
    )
    u_post = float(un[post])
    if leave is not None:
        acc = free_normal_acceleration(scene, states[post], points, flat)
        u_post -= acc * (t[post] - t_out)
    w = contact_compliance(scene, states[pre], points, flat)
    loss = exact_energy_loss(scene.restitution, u_pre, w)
    ke, pe = energies(scene, states[[pre, post]])
    change = float((ke[1] + pe[1]) - (ke[0] + pe[0]))
    return ImpactReading(
        outcome="ok" if leave is not None else _unfinished(traj),
        u_pre=u_pre,
        u_post=u_post,
        e_eff=-u_post / u_pre,
        energy_change=change,
        energy_loss_exact=loss,
        energy_gained=bool(change > GAIN_TOLERANCE * 0.5 * u_pre * u_pre / w),
        penetration=float(max(0.0, -gap[entry : post + 1].min())),
        contact_time=float(t_out - t_in),
        w=w,
    )


def trajectory_states(traj: Trajectory) -> np.ndarray:
    """(N, 13) rows of a trajectory."""
    return np.column_stack([traj.position, traj.quaternion, traj.velocity, traj.angular_velocity])


def _touch_down_lift_off(t: np.ndarray, gap: np.ndarray, pre: int, post: int) -> tuple:
    """(t_in, t_out): where g crosses zero into and out of the ground between the pre
    and post rows (interpolated linearly); the pre and post rows' times when no row
    between them is below the ground (an event-driven impact, or a bounce before
    touching)."""
    below = np.flatnonzero(gap[pre : post + 1] < 0.0) + pre
    if not below.size:
        return float(t[pre]), float(t[post])
    first, last = int(below[0]), int(below[-1])
    t_out = _crossing(t, gap, last, last + 1) if last + 1 <= post else float(t[last])
    return _crossing(t, gap, first - 1, first), t_out


def _crossing(t: np.ndarray, gap: np.ndarray, i: int, j: int) -> float:
    g0, g1 = gap[i], gap[j]
    if g0 == g1:
        return float(t[j])
    return float(t[i] + (t[j] - t[i]) * g0 / (g0 - g1))


def _first(idx: np.ndarray) -> int | None:
    return int(idx[0]) if idx.size else None


def _ended(traj: Trajectory) -> str:
    return f"run {traj.status.value}: {traj.message}" if traj.message else traj.status.value


def _unfinished(traj: Trajectory) -> str:
    return "no separation" if traj.status.value in ("t_end", "max_impacts") else _ended(traj)


def relative_error(e_eff: float | None, gamma: float) -> float | None:
    """e_eff/γ − 1 (None when there is no e_eff or γ = 0)."""
    if e_eff is None or gamma == 0 or not math.isfinite(e_eff):
        return None
    return e_eff / gamma - 1.0
