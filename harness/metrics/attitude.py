"""Attitude error of a run against the reference, and the first divergence."""

from __future__ import annotations

import numpy as np

from reference import quaternion as qt
from reference.trajectory import Trajectory

from .matching import MatchTolerance, common_window, match_impacts

# Divergence: attitude error above this fraction of the reference's largest tilt.
DIVERGENCE_TILT_FRACTION = 0.1


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
    q_ref = qt.slerp_at(reference.t, reference.quaternion, t)
    return t, qt.angle_between(q_ref, run.quaternion[keep])


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
