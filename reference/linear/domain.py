"""Where the linear model holds: small tilts.  A run that leaves that domain ends with
status `left_model`, cut where the tilt first reaches the limit.

The linear model (paper §4) replaces sin α by α and cos α by 1 in the contact heights
h − f_k·φ: at a tilt α their relative error is α²/6, and its energies differ from the
rigid body's by O(α²) relative (simulate.simulate_linear).  TILT_LIMIT = 0.2 rad keeps
the heights' error below 0.7 %; the built-in scenes reach at most 0.09 rad, except
grazing-contact (0.6 rad), which the linear model cannot represent.

The motion between events is exactly quadratic in time, φ(s) = q + p s + ½ a s² for the
tilt part (φx, φy) of q, so the first exit is found exactly: each segment's endpoints,
and inside a segment whose bound |q| + |p| s + ½|a| s² can reach the limit, the least
root of the quartic |φ(s)|² = TILT_LIMIT² (`first_exit`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..trajectory import Status
from . import kernel as K

TILT_LIMIT = 0.2  # rad (module docstring)


def first_exit(run, limit: float = TILT_LIMIT) -> tuple[int, float] | None:
    """(k, s): the tilt |φ| first exceeds `limit` at time s after event row k, on the
    segment that row starts; None when the whole run stays within it."""
    if run.q_post is None or len(run.kind) < 1:
        return None
    q, p, a = run.q_post[:, :2], run.p_post[:, :2], run.acc[:, :2]
    if np.hypot(*q[0]) > limit:
        return 0, 0.0
    # the segment after row k lasts until row k + 1 (times as double-doubles)
    span = np.append(np.diff(run.t_hi) + np.diff(run.t_lo), 0.0)
    reach = (
        np.hypot(q[:, 0], q[:, 1])
        + np.hypot(p[:, 0], p[:, 1]) * span
        + 0.5 * np.hypot(a[:, 0], a[:, 1]) * span**2
    )
    for k in np.flatnonzero(reach > limit):
        s = _least_crossing(q[k], p[k], 0.5 * a[k], float(span[k]), limit)
        if s is not None:
            return int(k), s
    return None


def _least_crossing(c, b, a, span: float, limit: float) -> float | None:
    """The least s in [0, span] with |c + b s + a s²| = limit (None if there is none)."""
    coeffs = [
        a @ a,
        2.0 * (a @ b),
        b @ b + 2.0 * (a @ c),
        2.0 * (b @ c),
        c @ c - limit * limit,
    ]
    while coeffs and coeffs[0] == 0.0:
        coeffs = coeffs[1:]
    if len(coeffs) < 2:
        return None
    roots = np.roots(coeffs)
    real = roots[np.abs(roots.imag) <= 1e-9 * (1.0 + np.abs(roots.real))].real
    inside = real[(real >= 0.0) & (real <= span)]
    return float(inside.min()) if len(inside) else None


def cut_at_exit(run, k: int, s: float, limit: float = TILT_LIMIT):
    """The run up to event row k plus a final row at the exit (k's segment advanced by s):
    status `left_model`, the message saying where and why."""
    keep = slice(0, k + 1)
    q = run.q_post[k] + run.p_post[k] * s + 0.5 * run.acc[k] * s * s
    p = run.p_post[k] + run.acc[k] * s
    energy = run.model.energy(q, p)
    t = float(run.t_hi[k]) + float(run.t_lo[k]) + s
    row = {
        "kind": K.END,
        "contact": -1,
        "contact2": -1,
        "held": run.held[k],
        "dt": s,
        "log2_dt": math.log2(s) if s > 0 else -math.inf,
        "t_hi": t,
        "t_lo": 0.0,
        "impulse": 0.0,
        "v_pre": 0.0,
        "v_post": 0.0,
        "energy_pre": energy,
        "energy_post": energy,
        "log2_energy": math.log2(energy) if energy > 0 else -math.inf,
        "q_pre": q,
        "p_pre": p,
        "q_post": q,
        "p_post": p,
        "acc": run.acc[k],
    }
    arrays = {
        name: np.concatenate([getattr(run, name)[keep], np.asarray(value)[None, ...]])
        for name, value in row.items()
    }
    kept_impacts = int(np.count_nonzero(run.kind[keep] == K.IMPACT))
    message = (
        f"the linear model left its small-tilt domain at t = {t:.17g} after {kept_impacts} "
        f"impacts: tilt {math.hypot(q[0], q[1]):.3g} rad, its limit {limit:g} rad "
        "(linear.domain.TILT_LIMIT: the model takes sin α ≈ α, cos α ≈ 1)"
    )
    return dataclasses.replace(
        run, status=Status.LEFT_MODEL, reason=0, message=message, n_impacts=kept_impacts, **arrays
    )
