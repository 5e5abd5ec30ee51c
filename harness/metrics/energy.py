"""Energy error of a run against the reference, interpolated within phases only."""

from __future__ import annotations

import numpy as np

from reference.trajectory import Trajectory

from .matching import MatchTolerance, common_window, match_impacts

# Energy: samples within this many timesteps of an impact are not compared.
ENERGY_GUARD_STEPS = 3.0


# ----------------------------------------------------------------------------- energy


def energy_guard(run: Trajectory) -> float:
    """How long after an impact a run's energy is not read (s): ENERGY_GUARD_STEPS·dt
    (3 steps) for fixed-step runs, 0 for event-driven ones."""
    return ENERGY_GUARD_STEPS * float(run.dt) if run.dt is not None else 0.0


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
        guard = energy_guard(run)
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
