"""Exact simulation of the linearised model, as a `Trajectory` or as raw event arrays.

`run_linear` drives the compiled event loop of `kernel.py` (motion between events is
quadratic in time, events are roots of quadratics, impacts are the maps U_k) and returns
the events with true (unscaled) states.  `simulate_linear` turns a scene into such a run
and maps it to full states (docs/contract.md): attitude = rotation vector (φx, φy, 0), centre
(0, 0, h), velocity (0, 0, v), ω = (ωx, ωy, 0).  `run_linear_exponent` is the one-sample
energy-exponent run of the paper's section 4.3.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..trajectory import ImpactEvent, Phase, Status, Trajectory
from . import kernel as K
from .domain import cut_at_exit, first_exit
from .model import LinearModel, full_states, linear_state
from .segment import LinearRun, run_segment

if TYPE_CHECKING:
    from ..scene import Scene


def run_linear(
    model: LinearModel,
    q0,
    p0,
    t_end: float = math.inf,
    max_impacts: int = 100_000,
    energy_floor: float = 1e-24,
    chatter_tol: float = 1e-7,
    decouple_tol: float = 1e-6,
    record_states: bool = True,
    impact_law: str = "paper",
    simultaneity_window: float = 0.0,
) -> LinearRun:
    """Run the linear model from (q0, p0) at t = 0 until t_end, the singularity (all
    contacts down, or energy below `energy_floor` × initial), an undecidable impact, or
    `max_impacts` impacts.

    Chatter at one contact is completed in closed form once it is provably alone and its
    post-impact normal velocity is ≤ `chatter_tol` × the velocity scale √(2E max f Θ⁻¹f)
    (`math.inf`: as soon as it is provably alone); `decouple_tol` is the same threshold
    for completing without the proof and for two-contact accumulations (kernel.py).

    `impact_law`: `paper` (an undecidable impact ends the run `simultaneous_impact`),
    or a law of the registry (reference.core.laws: `moreau`, `sequential`, `compliant`,
    ...): the kernel's loop resolves the impact under that law and goes on
    (kernel._law_event; the run's `simultaneous_impacts` counts them).
    `simultaneity_window`: open contacts reaching the ground within this time of the
    first are reached together with it (0: strictly sequential)."""
    return run_segment(
        model, q0, p0, t_end, max_impacts, energy_floor, chatter_tol, decouple_tol,
        record_states, simultaneity_window, impact_law,
    )[0]  # fmt: skip


# ----------------------------------------------------------------------------- scene

# The linear model's simultaneity window when the scene sets none: 0.  The model is
# scale-invariant (q → ε²q, p → εp, t → εt: section 2.6) and runs to its singularity
# through every scale, so an absolute window would merge the late impacts of every run
# (measured: the default linear sweep's 35 runs reaching the singularity all end
# `simultaneous_impact` under 1e-11); the exact reference's default is
# reference.scene.DEFAULT_SIMULTANEITY_WINDOW.
LINEAR_DEFAULT_WINDOW = 0.0


def linear_window(scene: Scene) -> float:
    """The scene's simultaneity window, else LINEAR_DEFAULT_WINDOW."""
    w = scene.simultaneity_window
    return LINEAR_DEFAULT_WINDOW if w is None else w


def simulate_linear(
    scene,
    t_end: float | None = None,
    sample_dt: float | None = None,
    energy_floor: float = 1e-24,
    chatter_tol: float = 1e-7,
) -> Trajectory:
    """Exact event-driven simulation of the paper's linearised model for a scene (a
    Scene, a scene file or a built-in name).

    Initial state: the scene's [initial] q/p, or read off its full state (rotation
    vector x/y, position z, angular velocity x/y, velocity z).  Samples: every event
    (the post-event state) plus a uniform grid of spacing `sample_dt` (default
    t_end/2000), evaluated exactly on the quadratic segments.

    Energies are the linear model's own quadratic form, KE = ½ pᵀΘp and PE = m g h,
    because it is the quantity the linear dynamics conserves exactly between impacts
    (so energy-drift metrics see the model, not the mapping); it differs from
    reference.geometry.energies of the mapped full state by ½ (I3 − I1)(ω·e3)²
    with ω·e3 = ωx φy − ωy φx, i.e. by O(α²) relative.

    Status as the reference: left_model once the tilt leaves the model's small-tilt
    domain (domain.TILT_LIMIT; the run is cut there), simultaneous_impact when
    undecidable, singularity when all contacts are down (t_singularity exact) or the
    energy fell below `energy_floor` of its initial value (t_singularity extrapolated
    from the last energy decades, see exponent.extrapolate_time_to_go), t_end,
    max_impacts. Chatter sequences are completed in closed form (kernel.py); they are
    listed in stats["accumulations"], not as impacts.  The scene's `impact_law` and
    `simultaneity_window` apply (kernel._law_event; docs/laws.md, "The linear model under the
    laws")."""
    from ..checks import check_linear_options, run_horizon
    from ..scenes import as_scene
    from .exponent_estimates import extrapolate_time_to_go

    scene = as_scene(scene)
    t_end = run_horizon(scene, t_end)  # SceneError before any work (reference.checks)
    check_linear_options(sample_dt, energy_floor, chatter_tol)
    model = LinearModel.from_scene(scene)
    q0, p0 = linear_state(scene)
    run = run_linear(
        model,
        q0,
        p0,
        t_end=t_end,
        max_impacts=scene.run.max_impacts,
        energy_floor=energy_floor,
        chatter_tol=chatter_tol,
        impact_law=scene.impact_law,
        simultaneity_window=linear_window(scene),
    )
    exit_at = first_exit(run)
    if exit_at is not None:  # beyond the small tilts the model holds for (domain.py)
        run = cut_at_exit(run, *exit_at)
    t_sing = None
    t_final = run.t_final
    if run.status is Status.SINGULARITY:
        if run.reason == K.REASON_SINGULARITY:
            t_sing = t_final
        else:
            rem = extrapolate_time_to_go(run.log2_dt, run.log2_energy)
            t_sing = t_final + 2.0**rem if rem is not None else None
    return trajectory_from_run(run, scene.name, t_end, sample_dt, t_sing)


def trajectory_from_run(
    run: LinearRun,
    scene_name: str,
    t_end: float,
    sample_dt: float | None = None,
    t_singularity: float | None = None,
) -> Trajectory:
    """Map a recorded LinearRun to a Trajectory (samples at events and on a grid)."""
    m = run.model
    t_ev = run.t_hi + run.t_lo
    t_final = run.t_final
    span = t_final if t_final > 0 else t_end
    dt_grid = sample_dt if sample_dt else (t_end / 2000.0 if math.isfinite(t_end) else span / 2000)
    grid = np.arange(0.0, t_final, dt_grid) if dt_grid > 0 and t_final > 0 else np.zeros(0)
    # segment of each grid time: the last event at or before it
    seg = np.searchsorted(t_ev, grid, side="right") - 1
    seg = np.clip(seg, 0, len(t_ev) - 1)
    s = (grid - run.t_hi[seg]) - run.t_lo[seg]
    qg = run.q_post[seg] + run.p_post[seg] * s[:, None] + 0.5 * run.acc[seg] * (s * s)[:, None]
    pg = run.p_post[seg] + run.acc[seg] * s[:, None]
    # merge event samples and grid samples, events winning ties
    t_all = np.concatenate([t_ev, grid])
    lo_all = np.concatenate([run.t_lo, np.zeros_like(grid)])
    q_all = np.concatenate([run.q_post, qg])
    p_all = np.concatenate([run.p_post, pg])
    key = np.concatenate([np.zeros(len(t_ev)), np.ones(len(grid))])
    order = np.lexsort((key, t_all))
    t_all, lo_all, q_all, p_all, key = (
        t_all[order],
        lo_all[order],
        q_all[order],
        p_all[order],
        key[order],
    )
    # drop grid samples that coincide with an event time
    keep = np.ones(len(t_all), dtype=bool)
    dup = np.flatnonzero(np.diff(t_all) == 0.0) + 1
    keep[dup[key[dup] == 1]] = False
    t_all, lo_all, q_all, p_all = t_all[keep], lo_all[keep], q_all[keep], p_all[keep]
    Y = full_states(q_all, p_all)
    th = m.theta
    ke = 0.5 * np.sum(p_all * p_all * th[None, :], axis=1)
    pe = m.mass * m.gravity * q_all[:, 2]

    impacts = [
        ImpactEvent(
            t=float(run.t_hi[i]),
            contact=int(run.contact[i]),
            impulse=float(run.impulse[i]),
            v_normal_pre=float(run.v_pre[i]),
            v_normal_post=float(run.v_post[i]),
            t_lo=float(run.t_lo[i]),
        )
        for i in run.impact_rows
    ]
    phases = []
    for i in range(len(t_ev) - 1):
        if t_ev[i + 1] <= t_ev[i]:
            continue
        held = tuple(int(c) for c in run.held[i] if c >= 0)
        phases.append(
            Phase(float(t_ev[i]), float(t_ev[i + 1]), "contact" if held else "flight", held)
        )
    acc_rows = np.flatnonzero(run.kind == K.ACCUMULATION)
    accumulations = [
        {
            "t": float(run.t_hi[i]),
            "contacts": [int(run.contact[i])]
            + ([int(run.contact2[i])] if run.contact2[i] >= 0 else []),
            "duration": float(run.dt[i]),
        }
        for i in acc_rows
    ]
    stats = {
        "wall_time_s": run.wall_time_s,
        "compile_s": run.compile_s,
        "n_events": int(len(run.kind)),
        "accumulations": accumulations,
        "simultaneous_impacts": run.simultaneous_impacts,
        "energy_model": "linear quadratic form: KE = 1/2 p^T Theta p, PE = m g h",
        "linear_final": {"q": run.q_post[-1].tolist(), "p": run.p_post[-1].tolist()},
    }
    return Trajectory.from_states(
        "linear",
        scene_name,
        t_all,
        Y,
        ke,
        pe,
        impacts,
        run.status,
        message=run.message,
        t_final=t_final,
        t_singularity=t_singularity,
        phases=phases,
        stats=stats,
        t_lo=lo_all,
        impact_law=run.impact_law,
        simultaneity_window=run.simultaneity_window,
    )


def run_linear_exponent(
    n: int,
    rho: float,
    gamma: float,
    q0,
    p0,
    g: float = 1.0,
    max_impacts: int = 20000,
    energy_floor: float = 1e-24,
    impact_law: str = "paper",
    simultaneity_window: float = 0.0,
) -> dict:
    """One run of the paper's exponent study (section 4.3): the n-gon (a = m = 1) from
    (q0, p0) with gravity g until the singularity, an undecidable impact or
    `max_impacts`, then c from the regression of log E on log(t_f − t) (exponent.py).

    Returns status (Status value), c (None when no exponent can be fitted: undecidable
    runs, as in the paper, or fewer than 6 decades of energy in the fit window),
    c_stderr, t_singularity (None unless the singularity was reached), n_impacts, and
    the cross-check estimates c_decades (durations of energy decades, no t_f needed) and
    c_period (ratios over one period of a periodic impact pattern, when there is one).
    `impact_law`, `simultaneity_window`: as for `run_linear` (under `paper` an
    undecidable run has no c, as in the paper)."""
    from .exponent_estimates import exponent_of_run

    base = {
        "status": Status.FAILED.value,
        "c": None,
        "c_stderr": None,
        "t_singularity": None,
        "n_impacts": 0,
        "c_decades": None,
        "c_period": None,
        "message": "",
    }
    if not (rho > 0 and 0 <= gamma <= 1 and n >= 2):
        base["message"] = f"no linear model for n={n}, rho={rho}, gamma={gamma}"
        return base
    model = LinearModel.polygon(n, rho, gamma, gravity=g)
    run = run_linear(
        model,
        q0,
        p0,
        max_impacts=max_impacts,
        energy_floor=energy_floor,
        chatter_tol=math.inf,
        record_states=False,
        impact_law=impact_law,
        simultaneity_window=simultaneity_window,
    )
    out = dict(base)
    out.update(
        status=run.status.value,
        n_impacts=run.n_impacts,
        message=run.message,
        wall_time_s=run.wall_time_s,
    )
    if run.status is Status.SIMULTANEOUS_IMPACT or run.status is Status.FAILED:
        return out
    ex = exponent_of_run(run)
    if run.status is Status.SINGULARITY:
        if run.reason == K.REASON_SINGULARITY:
            out["t_singularity"] = run.t_final
        elif ex["log2_time_remaining"] is not None:
            out["t_singularity"] = run.t_final + 2.0 ** ex["log2_time_remaining"]
    out.update(
        c=ex["c"],
        c_stderr=ex["c_stderr"],
        c_spread=ex["c_spread"],
        c_decades=ex["c_decades"],
        c_decades_spread=ex["c_decades_spread"],
        c_period=ex["c_period"],
        period=ex["period"],
        fit_decades=ex["fit_decades"],
        log10_energy_drop=ex["log10_energy_drop"],
    )
    return out
