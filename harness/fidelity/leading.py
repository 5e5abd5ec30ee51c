"""The reference's leading impacts at one scale, and how long an engine runs to cover them.

Leading impacts: the reference's first N impacts that are not chatter tails, N =
`FidelityCriteria.leading` (default 10).  A chatter tail (harness.metrics.chatter_tail)
is a bounce slower than 1 % of the reference's fastest approach at a contact already in
the current chatter episode: one of the infinitely many bounces every simulator
truncates somewhere.  The threshold is `slow_impact_speed(None, g, fastest)`, the
metrics' slow-impact rule without its timestep part: speeds scale with ε like the
fastest approach, so the same impacts are leading at every ε (the dt-dependent part,
10 g dt, belongs to the run being judged, not to the definition of the test).

Why the first N and not all of them: the reference's own end is chaotic (the pentagon's
last impacts move between versions of the code at roundoff level, README), and an O(dt)
error of an engine grows through every impact after it.  The first N impacts are the
motion every simulator should reproduce; a run that gets them right and diverges later
is faithful over that horizon, and a larger N (--leading) asks for a longer one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.trajectory import Trajectory

from ..metrics import (
    EVENT_TIME_TOLERANCE,
    RELATIVE_TIME_TOLERANCE,
    STEPS_TIME_TOLERANCE,
    chatter_tail,
    chatter_tail_speed,
)


@dataclass(frozen=True)
class LeadingImpacts:
    """indices: the reference's leading impacts (indices into reference.impacts, in
    time order); t_last: the time of the last of them; t_next: the time of the
    reference's next impact after it (any contact; None when there is none);
    tail_speed: approach speed below which a repeated bounce is a chatter tail."""

    indices: np.ndarray
    t_last: float | None
    t_next: float | None
    tail_speed: float

    @property
    def n(self) -> int:
        return len(self.indices)


def leading_impacts(reference: Trajectory, n: int, gravity: float) -> LeadingImpacts:
    """The reference's first `n` impacts that are not chatter tails (module docstring)."""
    speed = chatter_tail_speed(reference, gravity, None)
    tail = chatter_tail(reference, speed)
    idx = np.flatnonzero(~tail)[:n]
    if len(idx) == 0:
        return LeadingImpacts(idx, None, None, speed)
    t = reference.impact_times().astype(float)
    last = int(idx[-1])
    t_next = float(t[last + 1]) if last + 1 < len(t) else None
    return LeadingImpacts(idx, float(t[last]), t_next, speed)


def run_end(
    leading: LeadingImpacts,
    reference_end: float,
    scene_end: float,
    dt: float | None,
    window: str,
) -> float:
    """How long an engine runs at this scale: a margin past a time t_w, never past the
    scaled scene's end ε·t_end.

    window "leading": t_w = the last leading impact.  window "whole": t_w = the
    reference's end (its singularity, undecidable impact or t_end): the whole motion,
    which an exponent c needs (only a run to the end of the motion has one).  The margin
    is the matching window of harness.metrics.match_tolerance, 3·dt + 1 %·t_w (so that a
    run impact late by up to it still counts), and for "leading" at least half the gap
    to the reference's next impact.  Both ends scale with ε like the motion."""
    if leading.t_last is None and window == "leading":
        return scene_end
    t = leading.t_last if window == "leading" else reference_end
    absolute = STEPS_TIME_TOLERANCE * dt if dt is not None else EVENT_TIME_TOLERANCE
    margin = absolute + RELATIVE_TIME_TOLERANCE * t
    if window == "leading" and leading.t_next is not None:
        margin = max(margin, 0.5 * (leading.t_next - t))
    return min(scene_end, t + margin)


def inclination_scale(reference: Trajectory, t_last: float | None) -> float:
    """α of the motion at this scale: the reference's largest inclination (angle between
    the body axis and the vertical, radians) up to the last leading impact (the whole run
    when there is none).  Under the scaling it is ε² times that of the unscaled scene up
    to O(α) (the tilt is a component of q)."""
    incl = reference.inclination
    if incl.size == 0:
        return float("nan")
    if t_last is not None:
        incl = incl[reference.t <= t_last]
    return float(np.max(incl)) if incl.size else float(reference.inclination[0])
