"""Level (a) of the horizon: the best a fixed-step engine can do at its timestep.

The grid model is the exact model with every impact applied at the next boundary of a
step grid t = φ + k·dt (φ, the grid's phase, uniform in [0, dt)), otherwise exact.  It
is built on the public reference, impact by impact:

1. the reference runs from the current state to its next impact (`state.run_from`,
   one impact);
2. the state just before that impact is carried on by the reference's closed-form free
   flight (`reference.core.flight.free_flight`) to the next grid boundary, δ ∈ [0, dt)
   later: the contact is then below the ground by about |u⁻| δ, as in an engine that
   notices the contact at the end of its step;
3. that depth is removed by lifting the body along the contact normal
   (`state.lifted`, the position projection engines make; velocities unchanged, the
   potential energy raised by m g × depth), which puts the contact on the ground,
   still approaching;
4. the reference restarts from there: its start resolves a contact at the ground that
   approaches as an impact at t = 0 (reference.core.events.start → resolve_impact),
   so the impact law, the paper's rule beside held contacts and the chatter completion
   are the reference's own, applied at the grid time.

Chatter-tail impacts, those `compare` may skip (`harness.metrics.chatter_tail`: slower
than `slow_impact_speed`, 10 g dt or 1 % of the fastest, at a contact already in the
current chatter episode), are applied exactly, undelayed: an engine merges such bounces
into sustained contact, and delaying every bounce of a chatter sequence by up to a step
would make it last for ever (the bounce speed tends to g·dt/(1 − γ) instead of zero).
A slow impact at a contact new to the episode is delayed like any other.  Contact
phases (held contacts, γ = 0 or after a chatter completion) are the reference's,
undelayed: they are not impacts.

What this model is not: an engine also integrates flights with O(dt) errors and
resolves impacts over steps; the grid model keeps only the timing error that no
fixed-step engine can avoid, so its matched counts are an upper band for any engine at
that dt (docs/fidelity.md, "Horizon").
"""

from __future__ import annotations

import math

import numpy as np

from reference import Status, Trajectory
from reference.scene import Scene
from reference.trajectory import ImpactEvent

from ..metrics import chatter_tail
from .state import flown, lifted, pre_impact_state, run_from, start_state

GRID_MODEL = (
    "exact model, each impact applied at the next boundary of a step grid of width dt "
    "(random phase) after closed-form flight into the ground, the depth removed by "
    "lifting along the normal; chatter-tail impacts (compare's rule) exact"
)


def next_boundary(t: float, dt: float, phase: float) -> float:
    """The first grid time φ + k·dt at or after t."""
    return phase + dt * math.ceil((t - phase) / dt)


def delayed_state(scene: Scene, y_pre: np.ndarray, delay: float) -> tuple[np.ndarray, float]:
    """The pre-impact state carried by the reference's closed-form free flight `delay`
    further (into the ground), then lifted onto it (`state.lifted`); and the depth."""
    return lifted(scene, flown(scene, y_pre, delay))


class GridRun:
    """One run of the grid model, grown impact by impact (module docstring)."""

    def __init__(self, scene: Scene, dt: float, phase: float, t_end: float, slow: float):
        self.scene, self.dt, self.phase, self.t_end, self.slow = scene, dt, phase, t_end, slow
        self.y, self.t, self.delayed = start_state(scene), 0.0, False
        self.times: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        self.impacts: list[ImpactEvent] = []
        self.status: Status | None = None
        self.message = ""
        self.max_depth = 0.0

    def step(self) -> bool:
        """Run to the next impact and apply it at the grid; False once the run ended."""
        if self.status is not None:
            return False
        first = 1 if self.delayed else 0  # a restart at a delayed impact records it first
        sub = run_from(self.scene, self.y, self.t_end - self.t, first + 1)
        imps = list(sub.impacts)
        if sub.status is not Status.MAX_IMPACTS or len(imps) <= first:
            self._keep(sub, len(imps))
            self.status, self.message = sub.status, sub.message
            return False
        last = imps[-1]
        if self.dt == 0.0 or self._is_tail(last):  # exact
            self._keep(sub, len(imps))
            self.y, self.t, self.delayed = _last_state(sub), self.t + last.t, False
            return True
        t_hit = self.t + last.t
        t_grid = next_boundary(t_hit, self.dt, self.phase)
        self._keep(sub, len(imps) - 1, until=last.t)
        if t_grid >= self.t_end:
            self.status, self.message = Status.T_END, f"reached t_end = {self.t_end:g}"
            return False
        self.y, depth = delayed_state(
            self.scene, pre_impact_state(sub, len(imps) - 1), t_grid - t_hit
        )
        self.max_depth = max(self.max_depth, depth)
        self.t, self.delayed = t_grid, True
        return True

    def _is_tail(self, event: ImpactEvent) -> bool:
        """Whether `event`, after the impacts so far, is a chatter tail (compare's rule,
        harness.metrics.chatter_tail, at this run's tail speed)."""
        if abs(event.v_normal_pre) >= self.slow:
            return False
        events = [*self.impacts, event]
        empty = np.zeros(0)
        traj = Trajectory.from_states(
            "grid", self.scene.name, empty, np.zeros((0, 13)), empty, empty, events, Status.T_END
        )
        return bool(chatter_tail(traj, self.slow)[-1])

    def _keep(self, sub: Trajectory, n_impacts: int, until: float | None = None) -> None:
        """Append the sub-run's first n_impacts impacts and its samples (those before
        `until`, when given), shifted to the run's time."""
        for e in list(sub.impacts)[:n_impacts]:
            self.impacts.append(
                ImpactEvent(self.t + e.t, e.contact, e.impulse, e.v_normal_pre, e.v_normal_post)
            )
        keep = np.ones(len(sub.t), bool) if until is None else sub.t < until
        self.times.append(self.t + sub.t[keep])
        self.states.append(_sample_states(sub)[keep])

    def trajectory(self) -> Trajectory:
        """The run so far as a Trajectory (dt = the grid's width, for the matching)."""
        t = np.concatenate(self.times) if self.times else np.zeros(0)
        s = np.concatenate(self.states) if self.states else np.zeros((0, 13))
        zeros = np.zeros(len(t))
        return Trajectory.from_states(
            "grid", self.scene.name, t, s, zeros, zeros, list(self.impacts),
            self.status or Status.T_END, message=self.message or "stopped",
            t_final=float(t[-1]) if len(t) else 0.0, dt=self.dt,
        )  # fmt: skip


def _sample_states(traj: Trajectory) -> np.ndarray:
    return np.concatenate(
        [traj.position, traj.quaternion, traj.velocity, traj.angular_velocity], axis=1
    )


def _last_state(traj: Trajectory) -> np.ndarray:
    return _sample_states(traj)[-1]
