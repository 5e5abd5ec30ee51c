"""Impact matching: a run's impact sequence against the reference's, with the stated
tolerances (windows, chatter tails); the `compare` row's impacts_matched and
impact_time_error."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.trajectory import Trajectory

# Window = absolute = absolute + relative·t, capped (see `impact_windows`).
STEPS_TIME_TOLERANCE = 3.0  # fixed-step runs: absolute part, in timesteps
EVENT_TIME_TOLERANCE = 1e-9  # event-driven runs (dt None): absolute part, seconds
RELATIVE_TIME_TOLERANCE = 1e-2  # relative part, × t (drift of a 1 % restitution error)
# Slow impacts (`slow_impact_speed`): approach speed below
# max(SLOW_IMPACT_GRAVITY_STEPS · g · dt, SLOW_IMPACT_RELATIVE_SPEED · fastest approach)
# are left out of the effective restitution and may be skipped as chatter tails.
SLOW_IMPACT_GRAVITY_STEPS = 10.0
SLOW_IMPACT_RELATIVE_SPEED = 1e-2


# ----------------------------------------------------------------------------- windows


def common_window(run: Trajectory, reference: Trajectory) -> tuple[float, float] | None:
    """[max(t0_run, t0_ref), min(t_last_run, t_last_ref)], or None when either run has
    no samples or the two do not overlap."""
    if run.n_samples == 0 or reference.n_samples == 0:
        return None
    t0 = max(float(run.t[0]), float(reference.t[0]))
    t1 = min(float(run.t[-1]), float(reference.t[-1]))
    return (t0, t1) if t1 >= t0 else None


@dataclass(frozen=True)
class MatchTolerance:
    """How run impacts are matched to the reference's (`match_impacts`).

    absolute, relative: time window |t_run − t_ref| ≤ absolute + relative·t_ref (s),
    capped per impact by `impact_windows`;
    tail_speed: a chatter-tail impact (`chatter_tail`) approaching slower than this may
    be missing from the other sequence."""

    absolute: float
    relative: float
    tail_speed: float

    def window(self, t: np.ndarray | float) -> np.ndarray:
        return self.absolute + self.relative * np.abs(np.asarray(t, dtype=float))

    def describe(self) -> str:
        return (
            f"|dt| <= {self.absolute:.3g} s + {self.relative:.3g}*t, at most half the gap to "
            "the reference's neighbouring impacts at that contact; chatter-tail impacts "
            f"slower than {self.tail_speed:.3g} may be absent from either sequence"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "absolute": self.absolute,
            "relative": self.relative,
            "tail_speed": self.tail_speed,
            "rule": self.describe(),
        }


def slow_impact_speed(dt: float | None, gravity: float, fastest: float) -> float:
    """Approach speed below which an impact is not resolved as a collision:
    max(SLOW_IMPACT_GRAVITY_STEPS · g · dt, SLOW_IMPACT_RELATIVE_SPEED · fastest)
    = max(10 g dt, 1 % of the fastest approach); dt = 0 for event-driven runs.

    10 g dt: a contact point resting on the ground re-activates with an approach speed
    of a few g·dt (one step of gravity), and a bounce much slower than that lasts only a
    few steps, so a fixed-step engine cannot tell it from sustained contact.  1 % of the
    fastest approach: such an impact carries 1e-4 of the kinetic energy of the fastest,
    is dominated by the other contacts' forces and, in a chatter sequence, is one of
    infinitely many that every simulator truncates somewhere."""
    step = SLOW_IMPACT_GRAVITY_STEPS * gravity * (float(dt) if dt is not None else 0.0)
    return max(step, SLOW_IMPACT_RELATIVE_SPEED * fastest)


def match_tolerance(run: Trajectory, reference: Trajectory, gravity: float) -> MatchTolerance:
    """The stated impact-matching tolerance for a run.

    Time window, fixed-step runs (run.dt set): 3·dt + 1e-2·t.  Why:
    - 3·dt: an engine sees an impact only as the onset of contact activity in some step;
      the adapter interpolates the gap's zero crossing, but the step size still limits
      where the crossing can be, the state it interpolates is one step of semi-implicit
      integration off (gravity alone displaces the flight by O(g·dt·t)), and a soft or
      split-impulse contact resolves over one to a few steps.  Three steps covers these
      without accepting a different impact.
    - 1e-2·t: errors in impact times accumulate.  A restitution error δ changes each
      following flight time by the relative amount δ, so after time t the impacts drift
      by about δ·t.  1 % is the acceptance level for an engine's effective restitution
      (docs/engines.md, "The restitution contract"), so a run that passes that test is
      not declared diverged by drift alone.
    Event-driven runs (dt None: reference, linear): 1e-9 s + 1e-2·t.  The absolute part
    is event-location roundoff; the relative part gives the linear model room for its
    linearisation error, which is O(α) relative in time (terms of order ω² ~ α against
    O(1) accelerations in the paper's scaling), so it matches the full model where the
    inclination α stays ≲ 1e-2 and stops matching where the linearisation breaks down.
    `impact_windows` caps each window at half the gap to the reference's previous and
    next impact at the same contact, so that a run impact is never matched to a
    reference impact when another one of the same contact is as close.

    Chatter tails: with 0 < γ < 1 a contact (or a pair of contacts, alternately) can
    bounce infinitely often before coming to rest.  Every simulator lists only the first
    bounces of such a sequence: the exact ones complete it in closed form below their
    own threshold, an engine merges bounces shorter than a few steps into sustained
    contact.  Where the two sequences would next disagree, the earlier impact is skipped
    instead of ending the match if it is a *tail* impact (`chatter_tail`: slower than
    tail_speed = `chatter_tail_speed`(reference, g, run.dt), at a contact
    already in the chatter episode).  A skipped impact is not counted as matched."""
    tail = chatter_tail_speed(reference, gravity, run.dt)
    if run.dt is not None:
        return MatchTolerance(STEPS_TIME_TOLERANCE * float(run.dt), RELATIVE_TIME_TOLERANCE, tail)
    return MatchTolerance(EVENT_TIME_TOLERANCE, RELATIVE_TIME_TOLERANCE, tail)


def chatter_tail_speed(reference: Trajectory, gravity: float, dt: float | None) -> float:
    """The speed below which an impact of a run at step dt (None: event-driven) can be a
    chatter tail (`chatter_tail`): `slow_impact_speed` of the reference's fastest
    approach, max_i −v_pre,i (0 without impacts)."""
    approach = -reference.impact_column("v_normal_pre")
    fastest = float(approach.max()) if approach.size else 0.0
    return slow_impact_speed(dt, gravity, max(fastest, 0.0))


def impact_windows(reference: Trajectory, tolerance: MatchTolerance) -> np.ndarray:
    """Half-width of the matching window of every reference impact:
    w_i = min(absolute + relative·t_i, ½ min(t_i − t_prev, t_next − t_i)) where t_prev,
    t_next are the reference's neighbouring impacts *at the same contact*."""
    t = reference.impact_times().astype(float)
    c = reference.impact_contacts()
    w = tolerance.window(t) if t.size else np.zeros(0)
    for k in np.unique(c):
        idx = np.flatnonzero(c == k)
        gaps = np.diff(t[idx])
        left = np.concatenate([[np.inf], gaps])
        right = np.concatenate([gaps, [np.inf]])
        w[idx] = np.minimum(w[idx], 0.5 * np.minimum(left, right))
    return w


def chatter_tail(traj: Trajectory, speed: float) -> np.ndarray:
    """Mask of tail impacts: approach speed |v_pre| below `speed`, at a contact that
    already took part in the current chatter episode: one of the last two impacts that
    were not slow, or an earlier slow impact since then.  This covers chatter at one
    contact (c c c ...) and accumulations that alternate between two contacts
    (c d c d ..., c c d d d c ...); a slow impact at a contact new to the episode is not
    a tail."""
    c = traj.impact_contacts()
    slow = np.abs(traj.impact_column("v_normal_pre")) < speed
    tail = np.zeros(len(c), dtype=bool)
    fast: list[int] = []  # contacts of the last two impacts that were not slow
    episode: set[int] = set()
    for k in range(len(c)):
        if not slow[k]:
            fast = [*fast[-1:], int(c[k])]
            episode = set(fast)
            continue
        tail[k] = int(c[k]) in episode
        episode.add(int(c[k]))
    return tail


# ----------------------------------------------------------------------------- impacts


@dataclass(frozen=True)
class Mismatch:
    """Where two impact sequences first disagree (`match_impacts`).

    kind: "contact" (a different contact hit), "time" (same contact, outside the time
    window), "missed" (the run has no impact where the reference has one) or "spurious"
    (the run has an impact the reference does not); ref_index / run_index: the impacts
    compared (None where there is none); t_ref, t_run their times; contact_ref,
    contact_run their contacts; window: the reference impact's time window (s)."""

    kind: str
    t: float
    ref_index: int | None
    run_index: int | None
    t_ref: float | None
    t_run: float | None
    contact_ref: int | None
    contact_run: int | None
    window: float | None

    @property
    def time_offset(self) -> float | None:
        """t_run − t_ref (s) where both exist."""
        if self.t_ref is None or self.t_run is None:
            return None
        return self.t_run - self.t_ref

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "t": self.t,
            "reference_impact": self.ref_index,
            "run_impact": self.run_index,
            "t_reference": self.t_ref,
            "t_run": self.t_run,
            "contact_reference": self.contact_ref,
            "contact_run": self.contact_run,
            "window": self.window,
        }


@dataclass(frozen=True)
class ImpactMatch:
    """Result of matching a run's impact sequence against the reference's.

    pairs: (reference index, run index) of the matched impacts, in order;
    time_errors: t_run − t_ref of those (signed); mismatch_time: when the sequences
    first disagree inside the common window (None if they agree as far as both go);
    reason: what disagreed; n_reference: reference impacts inside the common window;
    skipped_reference / skipped_run: chatter-tail impacts passed over; mismatch: the
    first disagreement in detail; skipped_reference_indices: which reference impacts
    were passed over."""

    pairs: np.ndarray
    time_errors: np.ndarray
    mismatch_time: float | None
    reason: str | None
    n_reference: int
    skipped_reference: int
    skipped_run: int
    mismatch: Mismatch | None = None
    skipped_reference_indices: tuple[int, ...] = ()

    @property
    def n_matched(self) -> int:
        return len(self.pairs)


def match_impacts(
    run: Trajectory,
    reference: Trajectory,
    tolerance: MatchTolerance,
    start: tuple[int, int] = (0, 0),
) -> ImpactMatch:
    """Leading impacts matched.  The two sequences are walked in order; the next run
    impact matches the next reference impact when both have the same contact index and
    |t_run − t_ref| ≤ w_i (`impact_windows`).  When they do not match and the earlier of
    the two is a chatter-tail impact (`chatter_tail`, `match_tolerance`), that one is
    skipped and the walk goes on (inside a chatter episode slow bounces are not compared
    one by one: the sequence that lists a bounce the other has truncated or merged has
    it first).  Otherwise matching stops at this first mismatch: a different contact, a
    time outside the window, a reference impact the run does not have (missed) or a run
    impact the reference does not have (spurious).  Two impacts
    in swapped order are a mismatch even when both are within the window: which point
    hits first decides the motion after it.  Only impacts inside the common window take
    part (run impacts up to one window past its end, so a late match at the very end
    still counts, but never as spurious).  `start` = (i, j): the walk begins at reference
    impact i and run impact j (the impacts after a given time, harness.branches.follow);
    chatter tails are still judged on the whole sequences."""
    window = common_window(run, reference)
    if window is None:
        return ImpactMatch(np.zeros((0, 2), int), np.zeros(0), None, None, 0, 0, 0)
    t_end = window[1]
    tr = reference.impact_times().astype(float)
    n_r = int(np.sum(tr <= t_end))
    cr, wr = reference.impact_contacts(), impact_windows(reference, tolerance)
    tail_r = chatter_tail(reference, tolerance.tail_speed)
    te = run.impact_times().astype(float)
    n_e = int(np.sum(te <= t_end + float(tolerance.window(t_end))))
    ce, tail_e = run.impact_contacts(), chatter_tail(run, tolerance.tail_speed)
    pairs: list[tuple[int, int]] = []
    skipped_r: list[int] = []
    skipped_e = 0
    mismatch: Mismatch | None = None
    i, j = start
    while i < n_r or (j < n_e and te[j] <= t_end):
        if i < n_r and j < n_e:
            if ce[j] == cr[i] and abs(te[j] - tr[i]) <= wr[i]:
                pairs.append((i, j))
                i, j = i + 1, j + 1
                continue
            if tr[i] <= te[j] and tail_r[i]:  # the earlier one is a tail: skip it
                skipped_r.append(i)
                i += 1
                continue
            if te[j] < tr[i] and tail_e[j]:
                j, skipped_e = j + 1, skipped_e + 1
                continue
            kind = "contact" if ce[j] != cr[i] else "time"
            mismatch = Mismatch(
                kind, float(min(te[j], tr[i])), i, j, tr[i], te[j], cr[i], ce[j], wr[i]
            )
        elif i < n_r:
            if tail_r[i]:
                skipped_r.append(i)
                i += 1
                continue
            mismatch = Mismatch("missed", float(tr[i]), i, None, tr[i], None, cr[i], None, wr[i])
        else:
            if tail_e[j]:
                j, skipped_e = j + 1, skipped_e + 1
                continue
            mismatch = Mismatch("spurious", float(te[j]), None, j, None, te[j], None, ce[j], None)
        break
    p = np.array(pairs, dtype=int).reshape(-1, 2)
    errors = te[p[:, 1]] - tr[p[:, 0]]
    return ImpactMatch(
        p,
        errors,
        None if mismatch is None else mismatch.t,
        None if mismatch is None else mismatch_reason(mismatch),
        n_r,
        len(skipped_r),
        skipped_e,
        mismatch,
        tuple(skipped_r),
    )


def mismatch_reason(m: Mismatch) -> str:
    """The mismatch as one sentence (the `divergence_reason` of `compare`)."""
    if m.kind == "contact":
        return (
            f"reference impact {m.ref_index}: contact {m.contact_ref} at t={m.t_ref:.6g}, "
            f"run contact {m.contact_run} at t={m.t_run:.6g}"
        )
    if m.kind == "time":
        return (
            f"reference impact {m.ref_index} (contact {m.contact_ref}): t={m.t_ref:.6g}, run "
            f"t={m.t_run:.6g}, |dt|={abs(m.time_offset):.3g} > window {m.window:.3g}"
        )
    if m.kind == "missed":
        return f"reference impact {m.ref_index} (contact {m.contact_ref}, t={m.t_ref:.6g}) missed"
    return f"spurious run impact {m.run_index} at contact {m.contact_run}, t={m.t_run:.6g}"


def impacts_matched(run: Trajectory, reference: Trajectory, tolerance: MatchTolerance) -> int:
    """Number of leading impacts whose contact and time agree with the reference's
    (rule and tolerance: `match_impacts`, `match_tolerance`)."""
    return match_impacts(run, reference, tolerance).n_matched


def impact_time_error(
    run: Trajectory, reference: Trajectory, tolerance: MatchTolerance
) -> float | None:
    """max |t_run − t_ref| over the matched impacts (seconds); None if none matched."""
    m = match_impacts(run, reference, tolerance)
    return float(np.max(np.abs(m.time_errors))) if m.n_matched else None
