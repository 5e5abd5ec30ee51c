"""Agreement of a full simulator with the linearised model as α → 0 (paper §2.4–2.6;
docs/glossary.md, ε).

A scene given by (q, p) is scaled by ε (q → ε² q, p → ε p, hence α = O(ε²)) and run with
the full simulator; by the scaling invariance the linear model's answer is the unscaled
run with times × ε, q × ε², p × ε.  `scaled_agreement` returns the relative errors of
the scaled impact times, impulses and normal velocities and of the state at a time
between two impacts; `fit_order` fits the rate err ∝ ε^k above the roundoff floor.

Expected order: the terms the linearisation drops are all O(α²) = O(ε⁴) relative.
With φ = O(ε²), ω, v = O(ε), t = O(ε):
- the second-order part of a vertex height, ½ (φ × (φ × r))_z = ½ (φ_z (φ·r) − |φ|² r_z),
  vanishes: r_z = 0 (thin body) and φ_z = 0 at leading order; the third-order part is
  O(|φ|³) (relative O(ε⁴));
- the world inertia I1 + (I3 − I1) e3 e3ᵀ differs from diag(I1, I1, I3) by O(φ) only in
  its xz, yz entries, so horizontal torques (impacts, contact forces) produce O(φ)
  relative yaw rate ω_z = O(ε³), and likewise the tilt of the `three_point` normal e3
  only adds a yaw torque; yaw feeds back into gaps and (ωx, ωy) only through products
  φ_z (ω·r), ω_z ω = O(ε⁴) relative;
- gyroscopic and centripetal terms, (I3 − I1)(e3·ω)(ω × e3) and (ω × (ω × R r))_z, are
  O(ε⁴) against the O(1) accelerations (e3·ω = O(ε³)); the kinematic map φ̇ = ω +
  ½ φ × ω + … adds O(ε⁴) relative.
So scaled times, impulses and states agree to O(ε⁴) = O(α²), down to roundoff.
"""

from __future__ import annotations

import numpy as np

from .. import quaternion as qt
from ..trajectory import Status
from .model import LinearModel, linear_state
from .simulate import run_linear


def scaled_agreement(scene, eps: float, n_impacts: int, simulate_full) -> dict:
    """Full simulator (`simulate_full(scene, t_end=...) -> Trajectory`) on
    scene.scaled(eps) against the exact linear run of the unscaled scene.

    Runs to halfway between the linear run's impacts n_impacts and n_impacts + 1
    (scaled), compares the first n_impacts impacts (contact sequence, t/ε, impulse/ε,
    pre-impact normal velocity/ε) and the final state mapped back to (q/ε², p/ε).
    Relative errors are max |full − linear| / max |linear| per quantity."""
    model = LinearModel.from_scene(scene)
    q0, p0 = linear_state(scene)
    lin = run_linear(model, q0, p0, max_impacts=n_impacts + 1, energy_floor=0.0)
    rows = lin.impact_rows
    if len(rows) < n_impacts + 1:
        raise ValueError("the linear run has fewer impacts than asked for")
    r, r_next = rows[:n_impacts], rows[n_impacts]
    t_stop = 0.5 * (lin.t_hi[rows[n_impacts - 1]] + lin.t_hi[r_next])
    # linear state at t_stop: on the last segment starting before it
    last = int(np.flatnonzero(lin.t_hi <= t_stop)[-1])
    s = t_stop - lin.t_hi[last]
    q_lin = lin.q_post[last] + lin.p_post[last] * s + 0.5 * lin.acc[last] * s * s
    p_lin = lin.p_post[last] + lin.acc[last] * s

    tr = simulate_full(scene.scaled(eps), t_end=eps * t_stop)
    imp = tr.impacts[:n_impacts]
    contacts = np.array([e.contact for e in imp], dtype=int)
    same = len(imp) == n_impacts and np.array_equal(contacts, lin.contact[r])
    out = {
        "eps": eps,
        "alpha": eps * eps * float(np.hypot(q0[0], q0[1])),
        "status": tr.status.value,
        "same_sequence": bool(same),
        "n_compared": len(imp),
    }
    if not same:
        return out

    def rel(a, b):
        a, b = np.asarray(a, float), np.asarray(b, float)
        return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))

    out["time_error"] = rel([e.t / eps for e in imp], lin.t_hi[r])
    out["impulse_error"] = rel([e.impulse / eps for e in imp], lin.impulse[r])
    out["velocity_error"] = rel([e.v_normal_pre / eps for e in imp], lin.v_pre[r])
    if tr.status is Status.T_END:
        fs = tr.final_state()
        qw = np.array(fs["quaternion_wxyz"])
        rv = qt.to_rotation_vector(qw)
        q_full = np.array([rv[0], rv[1], fs["position"][2]]) / eps**2
        w, v = fs["angular_velocity"], fs["velocity"]
        p_full = np.array([w[0], w[1], v[2]]) / eps
        out["state_error"] = max(rel(q_full, q_lin), rel(p_full, p_lin))
    return out


def fit_order(eps, err, floor: float = 1e-13) -> dict:
    """Slope k of log err against log ε over the points with err > floor (the power-law
    regime above the roundoff floor), and the decades of ε those points span."""
    eps = np.asarray(eps, float)
    err = np.asarray(err, float)
    ok = np.isfinite(err) & (err > floor)
    if ok.sum() < 3:
        return {"order": None, "decades": 0.0, "n": int(ok.sum())}
    x, y = np.log10(eps[ok]), np.log10(err[ok])
    k, b = np.polyfit(x, y, 1)
    resid = y - (k * x + b)
    return {
        "order": float(k),
        "decades": float(np.ptp(x)),
        "n": int(ok.sum()),
        "max_residual_decades": float(np.max(np.abs(resid))),
        "floor_reached": bool(np.any(err[np.isfinite(err)] <= floor)),
        "min_error": float(np.min(err[np.isfinite(err)])),
        "log10_prefactor": float(b),
    }
