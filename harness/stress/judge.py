"""Judging one stress run: measurements (NaN, energy gain, penetration, missed and
spurious impacts) and the verdict."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from engines.base import contact_kinematics
from reference.geometry import initial_state
from reference.geometry import length_scale as state_length_scale
from reference.scene import Scene
from reference.trajectory import Status, Trajectory

from ..metrics import (
    MatchTolerance,
    chatter_tail,
    common_window,
    impact_windows,
    match_impacts,
    match_tolerance,
)

# Verdict thresholds.  Energy gain relative to |E0|; penetration relative to L.
FAILED_ENERGY_GAIN = 0.1
FAILED_PENETRATION = 0.5
# (energy gain, penetration) above which a run is degraded: the exact reference must
# keep both at roundoff level; approximate simulators (engines, the linear model, whose
# gaps are the linearised ones) get 1e-3 of the energy and 1 % of the length scale.
TOLERANCES = {"reference": (1e-9, 1e-9), "approximate": (1e-3, 1e-2)}
# Physics statuses that end a run legitimately before t_end.
STOPS = {Status.SINGULARITY, Status.SIMULTANEOUS_IMPACT, Status.MAX_IMPACTS, Status.LEFT_MODEL}
# Statuses of a run that ended without finishing: the simulator broke, or stopped
# advancing (the reference's progress check).
BROKEN = {Status.FAILED, Status.STALLED}


# ----------------------------------------------------------------------------- judging


def has_nan(run: Trajectory) -> bool:
    """A non-finite value in the samples, or a failure message that reports one."""
    arrays = (
        run.t,
        run.position,
        run.quaternion,
        run.velocity,
        run.angular_velocity,
        run.kinetic_energy,
        run.potential_energy,
    )
    if any(a.size and not np.all(np.isfinite(a)) for a in arrays):
        return True
    msg = run.message.lower()
    return run.status is Status.FAILED and ("nan" in msg or "non-finite" in msg)


def energy_gain(run: Trajectory) -> float | None:
    """max over samples of (E − E0)/|E0|, clipped at 0 (NaN samples ignored); None
    without samples.  |E0| = 0 falls back to the largest |E|."""
    e = run.energy
    if e.size == 0:
        return None
    e0 = float(e[0])
    scale = abs(e0)
    if not (scale > 0 and math.isfinite(scale)):
        finite = np.abs(e[np.isfinite(e)])
        scale = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
    d = (e - e0) / scale
    d = d[np.isfinite(d)]
    return max(0.0, float(d.max())) if d.size else None


def max_penetration(run: Trajectory, scene: Scene) -> float | None:
    """Deepest contact below the ground, max(0, −min gap), over the run's samples
    (reference contact geometry) and whatever the simulator measured itself
    (`stats["min_gap"]` of engine adapters: every step; `stats["max_penetration"]` of
    the reference: at impacts)."""
    depth = []
    if run.n_samples:
        states = np.concatenate(
            [run.position, run.quaternion, run.velocity, run.angular_velocity], axis=1
        )
        ok = np.all(np.isfinite(states), axis=1)
        if np.any(ok):
            gap, _ = contact_kinematics(scene, states[ok])
            depth.append(-float(gap.min()))
    g = run.stats.get("min_gap")
    if g is not None and math.isfinite(g):
        depth.append(-float(g))
    p = run.stats.get("max_penetration")
    if p is not None and math.isfinite(p):
        depth.append(float(p))
    return max(0.0, *depth) if depth else None


def length_scale(scene: Scene) -> float:
    """Height of the centre plus the rim's vertical extent at t = 0 (the case's length
    unit for penetration), the radius if that is 0."""
    L = float(state_length_scale(scene, initial_state(scene.initial))[0])
    return L if L > 0 else scene.body.radius


def unmatched_impacts(
    run: Trajectory, reference: Trajectory, tol: MatchTolerance
) -> tuple[int, int, int] | None:
    """(missed, spurious, counted) impacts of `run` against `reference` over their
    common window; `counted` is the number of reference impacts that take part.

    One-to-one matching per contact, order-free: a run impact and a reference impact at
    the same contact match when |t_run − t_ref| ≤ the reference impact's window
    (`metrics.impact_windows` with `tol`, `metrics.match_tolerance`), closest pairs first.
    Missed: reference impacts in the window left unmatched; spurious: run impacts in
    the window left unmatched (run impacts up to one window past its end may match, as
    in `metrics.match_impacts`).  Chatter-tail impacts (`metrics.chatter_tail`), which
    every simulator truncates somewhere, are not counted.  After the runs diverge
    (chaotic motions do) every later impact counts, so read these with the first
    mismatch.  None when the runs have no common window."""
    window = common_window(run, reference)
    if window is None:
        return None
    t0, t1 = window
    tr = reference.impact_times().astype(float)
    cr = reference.impact_contacts()
    wr = impact_windows(reference, tol)
    te = run.impact_times().astype(float)
    ce = run.impact_contacts()
    keep_r = (tr >= t0) & (tr <= t1) & ~chatter_tail(reference, tol.tail_speed)
    reach = t1 + float(tol.window(t1))
    keep_e = (te >= t0) & (te <= reach) & ~chatter_tail(run, tol.tail_speed)
    used_r = np.zeros(len(tr), dtype=bool)
    used_e = np.zeros(len(te), dtype=bool)
    for k in np.union1d(cr[keep_r], ce[keep_e]):
        ir = np.flatnonzero(keep_r & (cr == k))
        ie = np.flatnonzero(keep_e & (ce == k))
        if not ir.size or not ie.size:
            continue
        for i, j in _closest_first(tr, wr, ir, te, ie):
            if not used_r[i] and not used_e[j]:
                used_r[i] = used_e[j] = True
    missed = int(np.sum(keep_r & ~used_r))
    spurious = int(np.sum(keep_e & ~used_e & (te <= t1)))
    return missed, spurious, int(np.sum(keep_r))


def _closest_first(tr, wr, ir, te, ie) -> list[tuple[int, int]]:
    """Every pair (i, j) of a reference impact i in `ir` and a run impact j in `ie` (one
    contact's, each in time order) with |te[j] − tr[i]| ≤ wr[i], closest first (ties:
    by i, then j)."""
    tek = te[ie]
    lo = np.searchsorted(tek, tr[ir] - wr[ir], side="left")
    hi = np.searchsorted(tek, tr[ir] + wr[ir], side="right")
    n = np.maximum(hi - lo, 0)
    i = np.repeat(ir, n)
    # the positions lo … hi − 1 in tek of each reference impact, one after the other
    within = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    j = ie[np.repeat(lo, n) + within]
    order = np.lexsort((j, i, np.abs(te[j] - tr[i])))
    return list(zip(i[order].tolist(), j[order].tolist(), strict=True))


def _impact_comparison(run: Trajectory, reference: Trajectory, scene: Scene) -> dict[str, Any]:
    """The impact fields of a row: unmatched counts (`unmatched_impacts`) and the
    in-order match of `metrics.match_impacts` against the reference."""
    row: dict[str, Any] = {}
    tol = match_tolerance(run, reference, scene.gravity)
    counts = unmatched_impacts(run, reference, tol)
    if counts is not None:
        row["missed_impacts"], row["spurious_impacts"], counted = counts
        row["reference_impacts_counted"] = counted
    m = match_impacts(run, reference, tol)
    row["reference_impacts"] = m.n_reference
    row["impacts_matched"] = m.n_matched
    row["first_mismatch"] = m.reason
    return row


def _run_failures(
    run: Trajectory, row: dict[str, Any], reached: bool, error: str | None
) -> list[str]:
    """Why a run failed by itself: the exception it raised, NaN, status failed or
    stalled, or stopping before t_end without a physics reason."""
    failed = []
    if error is not None:
        failed.append(f"raised {error}")
    if row["nan"]:
        failed.append("NaN in the state")
    if not row["finished"] and error is None:
        if run.status in BROKEN:
            failed.append(f"status {run.status.value}: {run.message}")
        elif not reached:
            failed.append(f"stopped at t={run.t_final:.6g} before t_end={row['t_target']:.6g}")
    return failed


def _measurement_problems(row: dict[str, Any], exact: bool) -> tuple[list[str], list[str]]:
    """(failed, degraded) reasons from the measurements: energy gain and penetration
    against the thresholds (TOLERANCES for degraded), and impacts against the reference."""
    failed, degraded = [], []
    gain, depth, L = row["energy_gain"], row["max_penetration"], row["length_scale"]
    gain_tol, depth_tol = TOLERANCES["reference" if exact else "approximate"]
    if gain is not None and gain > FAILED_ENERGY_GAIN:
        failed.append(f"energy gain {gain:.3g} > {FAILED_ENERGY_GAIN:g}")
    elif gain is not None and gain > gain_tol:
        degraded.append(f"energy gain {gain:.3g} > {gain_tol:g}")
    if depth is not None and depth > FAILED_PENETRATION * L:
        failed.append(f"penetration {depth:.3g} > {FAILED_PENETRATION:g} L (L={L:.3g})")
    elif depth is not None and depth > depth_tol * L:
        degraded.append(f"penetration {depth:.3g} = {depth / L:.3g} L > {depth_tol:g} L")
    missed, spurious = row["missed_impacts"], row["spurious_impacts"]
    counted = row.get("reference_impacts_counted")
    if counted and missed == counted and row["finished"]:
        failed.append(f"matched none of the reference's {counted} impacts")
    if missed or spurious:
        text = f"{missed} missed, {spurious} spurious impacts"
        if row["first_mismatch"]:
            text += f" (first mismatch: {row['first_mismatch']})"
        degraded.append(text)
    return failed, degraded


def assess(
    run: Trajectory,
    reference: Trajectory | None,
    scene: Scene,
    t_target: float,
    exact: bool = False,
    error: str | None = None,
) -> dict[str, Any]:
    """Measurements and verdict of one run (module docstring).  `exact`: judge with the
    reference's tolerances.  `error`: the exception the run raised, if any."""
    nan = has_nan(run)
    # fixed-step runs take whole steps: up to one step short of t_end counts as reached
    slack = max(float(run.dt or 0.0), 1e-9 * t_target)
    reached = run.t_final >= t_target - slack
    finished = (
        error is None and run.status not in BROKEN and not nan and (reached or run.status in STOPS)
    )
    gain = energy_gain(run)
    depth = max_penetration(run, scene)
    L = length_scale(scene)
    row: dict[str, Any] = {
        "status": run.status.value,
        "message": error or run.message,
        "finished": finished,
        "nan": nan,
        "energy_gain": gain,
        "max_penetration": depth,
        "penetration_relative": None if depth is None else depth / L,
        "length_scale": L,
        "t_final": run.t_final,
        "t_target": t_target,
        "impacts": len(run.impacts),
        "missed_impacts": None,
        "spurious_impacts": None,
        "reference_impacts": None,
        "impacts_matched": None,
        "first_mismatch": None,
        "reference_impacts_counted": None,
    }
    if reference is not None and reference.n_samples and run.n_samples:
        row.update(_impact_comparison(run, reference, scene))
    failed, degraded = _measurement_problems(row, exact)
    failed = _run_failures(run, row, reached, error) + failed
    notes = []
    if run.status is Status.SIMULTANEOUS_IMPACT:
        notes.append("stopped undecidable (simultaneous impact)")
    row["verdict"] = "failed" if failed else "degraded" if degraded else "ok"
    row["reason"] = "; ".join(failed or degraded or notes)
    return row
