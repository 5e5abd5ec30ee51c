"""Metrics of one simulator run against the reference (CONTRACT.md, `compare`).

Every function here is a plain function of Trajectories: `run` (an engine, the linear
model, or the reference itself) and `reference` (the exact event-driven solution).  They
compare the two over their *common window* [max of the first sample times, min of the
last sample times]: the reference may stop early (singularity, undecidable simultaneous
impact) and an engine may fail.

Facts of the exact model that the definitions rely on (DESIGN.md §2):
- the attitude is continuous in time (impacts change velocities only), so it can be
  interpolated across impacts;
- the energy is constant in flight and in frictionless sustained contact and jumps down
  at each impact (γ < 1), so it must be interpolated *within* a phase, never across an
  impact, and a run whose impact comes a little before or after the reference's must not
  be charged the whole jump for that timing offset (impact timing is its own metric).

Tolerances and thresholds are module constants, stated in each docstring and echoed in
the `compare` document.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.trajectory import Trajectory

# Impact matching: window = absolute + relative·t, capped (see `impact_windows`).
STEPS_TIME_TOLERANCE = 3.0  # fixed-step runs: absolute part, in timesteps
EVENT_TIME_TOLERANCE = 1e-9  # event-driven runs (dt None): absolute part, seconds
RELATIVE_TIME_TOLERANCE = 1e-2  # relative part, × t (drift of a 1 % restitution error)
# Energy: samples within this many timesteps of an impact are not compared.
ENERGY_GUARD_STEPS = 3.0
# Divergence: attitude error above this fraction of the reference's largest tilt.
DIVERGENCE_TILT_FRACTION = 0.1
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
      (issue 4), so a run that passes that test is not declared diverged by drift alone.
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
    tail_speed = `slow_impact_speed`(run.dt, g, fastest reference approach), at a contact
    already in the chatter episode).  A skipped impact is not counted as matched."""
    fastest = max((-e.v_normal_pre for e in reference.impacts), default=0.0)
    tail = slow_impact_speed(run.dt, gravity, max(fastest, 0.0))
    if run.dt is not None:
        return MatchTolerance(STEPS_TIME_TOLERANCE * float(run.dt), RELATIVE_TIME_TOLERANCE, tail)
    return MatchTolerance(EVENT_TIME_TOLERANCE, RELATIVE_TIME_TOLERANCE, tail)


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
    slow = np.array([abs(e.v_normal_pre) < speed for e in traj.impacts], dtype=bool)
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
class ImpactMatch:
    """Result of matching a run's impact sequence against the reference's.

    pairs: (reference index, run index) of the matched impacts, in order;
    time_errors: t_run − t_ref of those (signed); mismatch_time: when the sequences
    first disagree inside the common window (None if they agree as far as both go);
    reason: what disagreed; n_reference: reference impacts inside the common window;
    skipped_reference / skipped_run: chatter-tail impacts passed over."""

    pairs: np.ndarray
    time_errors: np.ndarray
    mismatch_time: float | None
    reason: str | None
    n_reference: int
    skipped_reference: int
    skipped_run: int

    @property
    def n_matched(self) -> int:
        return len(self.pairs)


def match_impacts(run: Trajectory, reference: Trajectory, tolerance: MatchTolerance) -> ImpactMatch:
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
    still counts, but never as spurious)."""
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
    skipped_r = skipped_e = 0
    mismatch_time: float | None = None
    reason: str | None = None
    i = j = 0
    while i < n_r or (j < n_e and te[j] <= t_end):
        if i < n_r and j < n_e:
            d = te[j] - tr[i]
            if ce[j] == cr[i] and abs(d) <= wr[i]:
                pairs.append((i, j))
                i, j = i + 1, j + 1
                continue
            if tr[i] <= te[j] and tail_r[i]:  # the earlier one is a tail: skip it
                i, skipped_r = i + 1, skipped_r + 1
                continue
            if te[j] < tr[i] and tail_e[j]:
                j, skipped_e = j + 1, skipped_e + 1
                continue
            mismatch_time = float(min(te[j], tr[i]))
            if ce[j] != cr[i]:
                reason = (
                    f"reference impact {i}: contact {cr[i]} at t={tr[i]:.6g}, "
                    f"run contact {ce[j]} at t={te[j]:.6g}"
                )
            else:
                reason = (
                    f"reference impact {i} (contact {cr[i]}): t={tr[i]:.6g}, run "
                    f"t={te[j]:.6g}, |dt|={abs(d):.3g} > window {wr[i]:.3g}"
                )
        elif i < n_r:
            if tail_r[i]:
                i, skipped_r = i + 1, skipped_r + 1
                continue
            mismatch_time = float(tr[i])
            reason = f"reference impact {i} (contact {cr[i]}, t={tr[i]:.6g}) missed"
        else:
            if tail_e[j]:
                j, skipped_e = j + 1, skipped_e + 1
                continue
            mismatch_time = float(te[j])
            reason = f"spurious run impact {j} at contact {ce[j]}, t={te[j]:.6g}"
        break
    p = np.array(pairs, dtype=int).reshape(-1, 2)
    errors = te[p[:, 1]] - tr[p[:, 0]]
    return ImpactMatch(p, errors, mismatch_time, reason, n_r, skipped_r, skipped_e)


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


# ----------------------------------------------------------------------------- energy


def energy_error_series(
    run: Trajectory,
    reference: Trajectory,
    tolerance: MatchTolerance,
    guard: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(t, |E_run(t) − E_ref(t)| / E_ref(0)) at the run's sample times that can be compared.

    E_ref(t) is interpolated linearly between reference samples of the same phase only:
    phases are the intervals between consecutive reference impacts, and reference samples
    taken at an impact time (pre- or post-impact values) are not used.  A run time whose
    phase holds no reference sample strictly inside it is skipped; before the first or
    after the last sample of its phase, the nearest sample of the phase is used (exact
    for the model's piecewise-constant energy).

    Run samples are skipped near impacts, where E is not comparable:
    - for each matched impact pair (`match_impacts`), the interval
      [min(t_run, t_ref) − g, max(t_run, t_ref) + g] (the timing offset itself is
      `impact_time_error`'s business);
    - for every other impact of either run (skipped, after a mismatch), [t − g, t + g];
    with guard g = ENERGY_GUARD_STEPS·dt (3 steps) for fixed-step runs and 0 for
    event-driven ones.  A compliant contact that stays in contact longer than 3 steps
    shows the energy it stores elastically as an energy error: during that time the
    body's mechanical energy really is not the reference's.

    Normalised by E_ref(0) (by the largest |E_ref| if E_ref(0) = 0)."""
    window = common_window(run, reference)
    if window is None:
        return np.zeros(0), np.zeros(0)
    if guard is None:
        guard = ENERGY_GUARD_STEPS * float(run.dt) if run.dt is not None else 0.0
    t = run.t
    inside = (t >= window[0]) & (t <= window[1])
    excluded = _impact_exclusion(run, reference, tolerance, guard)
    keep = inside & ~_in_intervals(t, excluded)
    t = t[keep]
    e_ref = _energy_within_phases(reference, t)
    e_run = run.energy[keep]
    scale = _energy_scale(reference)
    ok = np.isfinite(e_ref)
    return t[ok], np.abs(e_run[ok] - e_ref[ok]) / scale


def energy_error(
    run: Trajectory,
    reference: Trajectory,
    tolerance: MatchTolerance,
    guard: float | None = None,
) -> float | None:
    """max |E − E_ref| / E_ref(0) over the common window (definition and exclusions:
    `energy_error_series`); None when no sample can be compared."""
    _, err = energy_error_series(run, reference, tolerance, guard)
    return float(err.max()) if err.size else None


def _energy_scale(reference: Trajectory) -> float:
    e = reference.energy
    e0 = float(e[0])
    if e0 > 0:
        return e0
    m = float(np.max(np.abs(e)))
    return m if m > 0 else 1.0


def _impact_exclusion(
    run: Trajectory, reference: Trajectory, tolerance: MatchTolerance, guard: float
) -> np.ndarray:
    """Closed intervals (k, 2) around impacts where energies are not compared."""
    m = match_impacts(run, reference, tolerance)
    tr, te = reference.impact_times().astype(float), run.impact_times().astype(float)
    a, b = tr[m.pairs[:, 0]], te[m.pairs[:, 1]]
    lo = np.minimum(a, b) - guard
    hi = np.maximum(a, b) + guard
    rest = np.concatenate([np.delete(tr, m.pairs[:, 0]), np.delete(te, m.pairs[:, 1])])
    return np.stack(
        [np.concatenate([lo, rest - guard]), np.concatenate([hi, rest + guard])], axis=1
    )


def _in_intervals(t: np.ndarray, intervals: np.ndarray) -> np.ndarray:
    """Mask of t inside any closed interval [a, b] of `intervals` (k, 2)."""
    if len(intervals) == 0:
        return np.zeros(len(t), dtype=bool)
    order = np.argsort(intervals[:, 0])
    a = intervals[order, 0]
    b = np.maximum.accumulate(intervals[order, 1])  # furthest end among starts ≤ a_j
    j = np.searchsorted(a, t, side="right") - 1
    return (j >= 0) & (t <= b[np.maximum(j, 0)])


def _energy_within_phases(reference: Trajectory, t: np.ndarray) -> np.ndarray:
    """E_ref at times t, interpolated inside phases only (NaN where impossible)."""
    tr, er = reference.t, reference.energy
    impacts = np.unique(reference.impact_times().astype(float))
    if impacts.size == 0:
        return np.interp(t, tr, er)
    # reference samples at an impact time (within a few ulps) belong to no phase
    j = np.searchsorted(impacts, tr)
    near = np.full(len(tr), np.inf)
    for jj in (j - 1, j):
        ok = (jj >= 0) & (jj < len(impacts))
        near[ok] = np.minimum(near[ok], np.abs(tr[ok] - impacts[jj[ok]]))
    interior = near > 4 * np.spacing(np.abs(tr) + 1.0)
    ti, ei = tr[interior], er[interior]
    pi = np.searchsorted(impacts, ti, side="right")  # phase index of each sample
    pt = np.searchsorted(impacts, t, side="right")
    out = np.full(len(t), np.nan)
    if ti.size == 0:
        return out
    right = np.searchsorted(ti, t, side="right")
    left = right - 1
    left_ok = (left >= 0) & (pi[np.clip(left, 0, len(ti) - 1)] == pt)
    right_ok = (right < len(ti)) & (pi[np.clip(right, 0, len(ti) - 1)] == pt)
    li, ri = np.clip(left, 0, len(ti) - 1), np.clip(right, 0, len(ti) - 1)
    both = left_ok & right_ok
    h = ti[ri] - ti[li]
    s = np.where(both & (h > 0), (t - ti[li]) / np.where(h > 0, h, 1.0), 0.0)
    out[both] = (ei[li] + s * (ei[ri] - ei[li]))[both]
    only_left = left_ok & ~right_ok
    out[only_left] = ei[li][only_left]
    only_right = right_ok & ~left_ok
    out[only_right] = ei[ri][only_right]
    return out


# ----------------------------------------------------------------------------- attitude


def attitude_error_series(run: Trajectory, reference: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """(t, angle) at the run's sample times in the common window: angle (rad, in [0, π])
    of the rotation q_ref(t)⁻¹ q_run(t), sign-invariant (q and −q are one attitude).

    q_ref(t) is the slerp (constant-rate rotation) between the neighbouring reference
    samples; the attitude is continuous across impacts, so no phase split is needed.
    Its interpolation error is at most about h²|ω̇|/8 for reference sample spacing h."""
    window = common_window(run, reference)
    if window is None:
        return np.zeros(0), np.zeros(0)
    keep = (run.t >= window[0]) & (run.t <= window[1])
    t = run.t[keep]
    q_ref = _slerp_at(reference.t, reference.quaternion, t)
    return t, _angle_between(q_ref, run.quaternion[keep])


def attitude_error(run: Trajectory, reference: Trajectory) -> float | None:
    """Largest angle (rad) between run and reference attitudes over the common window
    (`attitude_error_series`); None when the runs do not overlap."""
    _, a = attitude_error_series(run, reference)
    return float(a.max()) if a.size else None


def largest_tilt(reference: Trajectory, window: tuple[float, float] | None = None) -> float:
    """max over the window of the reference's inclination α (angle of the body axis from
    the vertical), computed as atan2(|(e3x, e3y)|, e3z) without 1 − cos loss."""
    q = reference.quaternion
    if window is not None:
        q = q[(reference.t >= window[0]) & (reference.t <= window[1])]
    if len(q) == 0:
        return 0.0
    w, x, y, z = q.T
    e3x, e3y = 2 * (x * z + w * y), 2 * (y * z - w * x)
    e3z = 1 - 2 * (x * x + y * y)
    return float(np.max(np.arctan2(np.hypot(e3x, e3y), e3z)))


def attitude_threshold(run: Trajectory, reference: Trajectory) -> float:
    """Attitude error that counts as divergence: DIVERGENCE_TILT_FRACTION (0.1) × the
    reference's largest inclination over the common window.  The tilt is the scale of
    the motion that decides which point hits next; an attitude off by a tenth of it
    (tilt, or spin about the vertical, which moves the lowest point) is a different
    motion.  Relative, so it is invariant under the paper's scaling (q → ε²q)."""
    return DIVERGENCE_TILT_FRACTION * largest_tilt(reference, common_window(run, reference))


def first_divergence_time(
    run: Trajectory,
    reference: Trajectory,
    tolerance: MatchTolerance,
    threshold: float | None = None,
) -> tuple[float | None, str | None]:
    """Earliest of (a) the first time the attitude error exceeds `threshold`
    (default `attitude_threshold`) and (b) the time of the first mismatched impact
    (`match_impacts`).  Returns (time, reason); (None, None) if neither happens in the
    common window."""
    if threshold is None:
        threshold = attitude_threshold(run, reference)
    m = match_impacts(run, reference, tolerance)
    t, a = attitude_error_series(run, reference)
    over = np.flatnonzero(a > threshold)
    candidates: list[tuple[float, str]] = []
    if over.size:
        i = over[0]
        candidates.append(
            (float(t[i]), f"attitude error {a[i]:.3g} rad > {threshold:.3g} rad at t={t[i]:.6g}")
        )
    if m.mismatch_time is not None:
        candidates.append((m.mismatch_time, m.reason or "impact mismatch"))
    if not candidates:
        return None, None
    return min(candidates, key=lambda c: c[0])


# ----------------------------------------------------------------------------- restitution


@dataclass(frozen=True)
class RestitutionEstimate:
    """Effective restitution e_i = −v_post / v_pre of a run's own impacts."""

    median: float | None
    quartiles: tuple[float, float] | None
    range: tuple[float, float] | None
    n: int
    speed_threshold: float


def effective_restitution(traj: Trajectory, gravity: float) -> RestitutionEstimate:
    """Median (and quartiles, range) of e_i = −v_normal_post / v_normal_pre over the
    trajectory's impacts that approach faster than the threshold

        v_pre < −max(10·g·dt, 0.01 · max_i |v_pre,i|)    (dt = 0 for event-driven runs)

    (`slow_impact_speed`: slower "impacts" are solver contact flicker or late chatter,
    dominated by resolution and by the other contacts' forces; they say nothing about
    the impact law)."""
    pre = np.array([e.v_normal_pre for e in traj.impacts], dtype=float)
    post = np.array([e.v_normal_post for e in traj.impacts], dtype=float)
    fastest = float(np.max(-pre)) if pre.size else 0.0
    v_min = slow_impact_speed(traj.dt, gravity, max(fastest, 0.0))
    use = pre < -v_min
    if not np.any(use):
        return RestitutionEstimate(None, None, None, 0, v_min)
    e = -post[use] / pre[use]
    q1, med, q3 = np.percentile(e, [25, 50, 75])
    return RestitutionEstimate(
        float(med), (float(q1), float(q3)), (float(e.min()), float(e.max())), int(e.size), v_min
    )


# ----------------------------------------------------------------------------- all of them


@dataclass(frozen=True)
class RunMetrics:
    """Every metric of one run against the reference (the `compare` row's numbers)."""

    impacts: int
    reference_impacts: int
    impacts_matched: int
    impact_time_error: float | None
    energy_error: float | None
    energy_samples: int
    attitude_error: float | None
    energy_error_agreeing: float | None
    attitude_error_agreeing: float | None
    attitude_threshold: float
    first_divergence_time: float | None
    divergence_reason: str | None
    tolerance: MatchTolerance
    skipped_reference: int
    skipped_run: int
    common_window: tuple[float, float] | None
    restitution: RestitutionEstimate

    def to_dict(self) -> dict[str, Any]:
        r = self.restitution
        return {
            "impacts": self.impacts,
            "reference_impacts": self.reference_impacts,
            "impacts_matched": self.impacts_matched,
            "impact_time_error": self.impact_time_error,
            "energy_error": self.energy_error,
            "energy_samples": self.energy_samples,
            "attitude_error": self.attitude_error,
            "energy_error_agreeing": self.energy_error_agreeing,
            "attitude_error_agreeing": self.attitude_error_agreeing,
            "attitude_threshold": self.attitude_threshold,
            "first_divergence_time": self.first_divergence_time,
            "divergence_reason": self.divergence_reason,
            "time_tolerance": self.tolerance.to_dict(),
            "skipped_reference_impacts": self.skipped_reference,
            "skipped_run_impacts": self.skipped_run,
            "common_window": list(self.common_window) if self.common_window else None,
            "effective_restitution": r.median,
            "effective_restitution_quartiles": list(r.quartiles) if r.quartiles else None,
            "effective_restitution_range": list(r.range) if r.range else None,
            "effective_restitution_n": r.n,
            "restitution_speed_threshold": r.speed_threshold,
        }


def evaluate(run: Trajectory, reference: Trajectory, gravity: float) -> RunMetrics:
    """All metrics of `run` against `reference` with the stated default tolerances.

    Besides the contract's maxima over the whole common window, `*_agreeing` are the
    same maxima over the part before the first divergence (all of it if none): once
    the runs are in different motions the whole-window numbers measure that difference,
    while the agreeing ones measure the run's accuracy while it follows the reference."""
    tol = match_tolerance(run, reference, gravity)
    m = match_impacts(run, reference, tol)
    t_e, e_err = energy_error_series(run, reference, tol)
    t_a, a_err = attitude_error_series(run, reference)
    threshold = attitude_threshold(run, reference)
    t_div, why = first_divergence_time(run, reference, tol, threshold)
    cut = math.inf if t_div is None else t_div
    return RunMetrics(
        impacts=len(run.impacts),
        reference_impacts=m.n_reference,
        impacts_matched=m.n_matched,
        impact_time_error=float(np.max(np.abs(m.time_errors))) if m.n_matched else None,
        energy_error=_max_or_none(e_err),
        energy_samples=int(e_err.size),
        attitude_error=_max_or_none(a_err),
        energy_error_agreeing=_max_or_none(e_err[t_e < cut]),
        attitude_error_agreeing=_max_or_none(a_err[t_a < cut]),
        attitude_threshold=threshold,
        first_divergence_time=t_div,
        divergence_reason=why,
        tolerance=tol,
        skipped_reference=m.skipped_reference,
        skipped_run=m.skipped_run,
        common_window=common_window(run, reference),
        restitution=effective_restitution(run, gravity),
    )


def _max_or_none(x: np.ndarray) -> float | None:
    return float(x.max()) if x.size else None


# ----------------------------------------------------------------------------- quaternions


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise Hamilton product of (N, 4) arrays, scalar first."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=1,
    )


def _conj(q: np.ndarray) -> np.ndarray:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def _angle_between(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Rotation angle of q1⁻¹ q2 per row, from the vector part (no acos), sign-invariant."""
    d = _qmul(_conj(q1), q2)
    return 2.0 * np.arctan2(np.linalg.norm(d[:, 1:], axis=1), np.abs(d[:, 0]))


def _slerp_at(t_samples: np.ndarray, q_samples: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Slerp of sampled unit quaternions at times t (held constant outside the samples)."""
    n = len(t_samples)
    j = np.searchsorted(t_samples, t, side="right")
    i0, i1 = np.clip(j - 1, 0, n - 1), np.clip(j, 0, n - 1)
    h = t_samples[i1] - t_samples[i0]
    s = np.where(h > 0, (t - t_samples[i0]) / np.where(h > 0, h, 1.0), 0.0)
    s = np.clip(s, 0.0, 1.0)
    q0, q1 = q_samples[i0], q_samples[i1]
    d = _qmul(_conj(q0), q1)
    d[d[:, 0] < 0] *= -1.0  # shortest way
    vn = np.linalg.norm(d[:, 1:], axis=1)
    angle = 2.0 * np.arctan2(vn, d[:, 0])  # rotation angle of d, in [0, π]
    axis_scale = np.where(vn > 0, angle / np.where(vn > 0, vn, 1.0), 2.0)
    r = d[:, 1:] * axis_scale[:, None] * s[:, None]  # s × rotation vector of d
    phi = np.linalg.norm(r, axis=1)
    half_sinc = np.where(
        phi < 1e-4,
        0.5 - phi**2 / 48.0 + phi**4 / 3840.0,
        np.sin(0.5 * phi) / np.where(phi > 0, phi, 1.0),
    )
    step = np.concatenate([np.cos(0.5 * phi)[:, None], half_sinc[:, None] * r], axis=1)
    return _qmul(q0, step)
