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
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..trajectory import ImpactEvent, Phase, Status, Trajectory
from . import kernel as K
from .domain import cut_at_exit, first_exit
from .model import LinearModel, full_states, linear_state

if TYPE_CHECKING:
    from ..scene import Scene

# Passes of the linear event loop per call of the compiled kernel: Python regains control
# (Ctrl-C) every few tens of milliseconds (one pass is ~0.1-3 µs).
LOOP_BUDGET = 50_000

STATUS = {
    K.T_END: Status.T_END,
    K.SINGULARITY: Status.SINGULARITY,
    K.SIMULTANEOUS: Status.SIMULTANEOUS_IMPACT,
    K.MAX_IMPACTS: Status.MAX_IMPACTS,
    K.FAILED: Status.FAILED,
}


@dataclass(frozen=True)
class LinearRun:
    """Events of one linear run (row 0 is the initial state, the last row the stop).

    Per event: kind (kernel.INITIAL/IMPACT/ACCUMULATION/END), contact (and contact2 for a
    two-contact accumulation), dt (true interval since the previous event), t_hi + t_lo
    (double-double time), impulse, normal velocity before/after, energy before/after,
    log2 of the energy after, states before/after (q, p), the constant acceleration of
    the segment that follows and the contacts held on it (−1 = none).  `dt` underflows
    to 0 for intervals below 1e-308; `log2_dt` keeps them."""

    model: LinearModel
    status: Status
    reason: int
    message: str
    n_impacts: int
    kind: np.ndarray
    contact: np.ndarray
    contact2: np.ndarray
    held: np.ndarray
    dt: np.ndarray
    log2_dt: np.ndarray
    t_hi: np.ndarray
    t_lo: np.ndarray
    impulse: np.ndarray
    v_pre: np.ndarray
    v_post: np.ndarray
    energy_pre: np.ndarray
    energy_post: np.ndarray
    log2_energy: np.ndarray
    q_pre: np.ndarray | None
    p_pre: np.ndarray | None
    q_post: np.ndarray | None
    p_post: np.ndarray | None
    acc: np.ndarray | None
    wall_time_s: float
    impact_law: str = "paper"  # the law of simultaneous impacts applied (laws.py)
    simultaneity_window: float = 0.0  # contacts reached within it count as one impact

    @property
    def impact_rows(self) -> np.ndarray:
        return np.flatnonzero(self.kind == K.IMPACT)

    @property
    def t_final(self) -> float:
        return float(self.t_hi[-1] + self.t_lo[-1])


_REASONS = {
    K.REASON_SIMULTANEOUS: "two contacts reached at once",
    K.REASON_PUSHED: "an impact would drive a resting contact into the ground (paper §2.3)",
    K.REASON_NO_ENERGY: "energy exhausted",
    K.REASON_ENERGY_EXHAUSTED: "energy fell below the floor",
    K.REASON_CHATTER_SIMULTANEOUS: "a contact is at the ground when a chatter sequence accumulates",
    K.REASON_CHATTER2_SIMULTANEOUS: (
        "a contact is at the ground when a two-contact chatter accumulates"
    ),
    K.REASON_SINGULARITY: "all contacts down",
    K.REASON_FAILED_LCP: "no admissible set of held contacts",
    K.REASON_BUFFER_FULL: "event buffer full",
    K.REASON_FAILED_NO_ADVANCE: "no further event and no end time",
    K.REASON_WINDOW: "contacts reached within the simultaneity window of each other",
}


def _segment_accelerations(model: LinearModel, held: np.ndarray) -> np.ndarray:
    """The constant acceleration after each event, from its held contacts (eq.
    pacccontact; free fall −g u3 when none): a function of the held set alone, so it is
    recomputed in true units rather than converted from the kernel's normalised value
    (whose scale may change between writing a row and setting its acceleration)."""
    from .model import held_acceleration

    acc = np.empty((len(held), 3))
    cache: dict[tuple[int, ...], np.ndarray] = {}
    for i, row in enumerate(held):
        key = tuple(int(c) for c in row if c >= 0)
        if key not in cache:
            f = model.F[list(key)] if key else np.zeros((0, 3))
            cache[key] = held_acceleration(f, model.theta, model.mass, model.gravity)[0]
        acc[i] = cache[key]
    return acc


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
    or `moreau` / `sequential` / `compliant`: the run goes on past it under that law
    (laws.py).
    `simultaneity_window`: open contacts reaching the ground within this time of the
    first are reached together with it (0: strictly sequential)."""
    if impact_law != "paper":
        from .laws import run_under_law

        return run_under_law(
            model, q0, p0, impact_law, t_end=t_end, max_impacts=max_impacts,
            energy_floor=energy_floor, chatter_tol=chatter_tol, decouple_tol=decouple_tol,
            record_states=record_states, window=simultaneity_window,
        )  # fmt: skip
    run = run_segment(
        model, q0, p0, t_end, max_impacts, energy_floor, chatter_tol, decouple_tol,
        record_states, simultaneity_window,
    )[0]  # fmt: skip
    return run


def run_segment(
    model: LinearModel,
    q0,
    p0,
    t_end: float,
    max_impacts: int,
    energy_floor: float,
    chatter_tol: float,
    decouple_tol: float,
    record_states: bool,
    window: float = 0.0,
) -> tuple[LinearRun, tuple]:
    """`run_linear` under the paper's rule, with the kernel's loop state at the stop
    (kernel.new_loop_state: the normalised q, p, their roundoff scales, ..., si, sf):
    where a law continues the run (laws.py)."""
    q0 = np.array(q0, dtype=float)
    p0 = np.array(p0, dtype=float)
    F = model.F
    E0 = model.energy(q0, p0)
    log2_floor = (
        (math.log2(E0) + math.log2(energy_floor)) if E0 > 0 and energy_floor > 0 else -1e300
    )
    cap = 2 * max_impacts + 16
    out_i = np.empty((cap, K.N_ICOLS), dtype=np.int64)
    out_f = np.empty((cap, K.N_FCOLS))
    out_s = np.zeros((cap if record_states else 1, K.N_SCOLS))
    info = np.zeros(K.N_INFO, dtype=np.int64)
    tinv = 1.0 / model.theta
    w, wmax = K._contact_products(F, tinv)
    consts = (F, model.theta, tinv, w, wmax, model.mass)
    loop = K.new_loop_state(F.shape[0])
    t0 = time.perf_counter()
    done = K.start_kernel(
        *consts, model.gravity, model.restitution, model.rank, q0, p0, bool(record_states),
        out_i, out_f, out_s, info, *loop[:9],
    )  # fmt: skip
    while not done:  # back in Python every LOOP_BUDGET events: Ctrl-C works
        n = K.continue_kernel(
            *consts, model.restitution, model.rank, float(t_end), int(max_impacts),
            float(log2_floor), float(chatter_tol), float(decouple_tol), float(window),
            bool(record_states),
            out_i, out_f, out_s, info, *loop, LOOP_BUDGET,
        )  # fmt: skip
        done = n >= 0
    n = int(loop[7][K.SI_EVENTS])
    wall = time.perf_counter() - t0
    status = STATUS[int(info[0])]
    reason = int(info[5])
    oi, of = out_i[:n], out_f[:n]
    kv, kq = oi[:, K.I_KV], oi[:, K.I_KQ]
    if record_states:
        S = out_s[:n]
        eq, ev = kq[:, None], kv[:, None]
        states = dict(
            q_pre=np.ldexp(S[:, 0:3], eq),
            p_pre=np.ldexp(S[:, 3:6], ev),
            q_post=np.ldexp(S[:, 6:9], eq),
            p_post=np.ldexp(S[:, 9:12], ev),
            acc=_segment_accelerations(model, oi[:, [K.I_HELD1, K.I_HELD2]]),
        )
    else:
        states = dict(q_pre=None, p_pre=None, q_post=None, p_post=None, acc=None)
    dtn = of[:, K.F_DTN]
    with np.errstate(divide="ignore"):
        log2_dt = np.where(dtn > 0, np.log2(np.where(dtn > 0, dtn, 1.0)), -np.inf) + oi[:, K.I_DTE]
    t_stop = of[n - 1, K.F_THI] + of[n - 1, K.F_TLO] if n else 0.0
    msg = run_message(status, reason, t_stop, int(info[2]), (int(info[3]), int(info[4])))
    run = LinearRun(
        model=model,
        status=status,
        reason=reason,
        message=msg,
        n_impacts=int(info[2]),
        kind=oi[:, K.I_KIND].copy(),
        contact=oi[:, K.I_CONTACT].copy(),
        contact2=oi[:, K.I_CONTACT2].copy(),
        held=oi[:, [K.I_HELD1, K.I_HELD2]].copy(),
        dt=of[:, K.F_DT].copy(),
        log2_dt=log2_dt,
        t_hi=of[:, K.F_THI].copy(),
        t_lo=of[:, K.F_TLO].copy(),
        impulse=of[:, K.F_IMPULSE].copy(),
        v_pre=of[:, K.F_VPRE].copy(),
        v_post=of[:, K.F_VPOST].copy(),
        energy_pre=np.ldexp(of[:, K.F_EPRE], 2 * kv),
        energy_post=np.ldexp(of[:, K.F_EPOST], 2 * kv),
        log2_energy=of[:, K.F_LOG2E].copy(),
        wall_time_s=wall,
        simultaneity_window=float(window),
        **states,
    )
    return run, loop


def run_message(status: Status, reason: int, t: float, n_imp: int, pair=(-1, -1)) -> str:
    """The message of a run that stopped at t with `status` and `reason` (REASON_*),
    after n_imp impacts; `pair`: the two contacts of an undecidable event."""
    what = _REASONS.get(reason, "")
    if status is Status.SIMULTANEOUS_IMPACT:
        return f"undecidable at t = {t:.17g}: {what} (contacts {pair[0]} and {pair[1]})"
    if status is Status.SINGULARITY:
        return f"{what} at t = {t:.17g} after {n_imp} impacts"
    if status is Status.MAX_IMPACTS:
        return f"stopped after {n_imp} impacts at t = {t:.17g}"
    if status is Status.FAILED:
        return f"failed at t = {t:.17g}: {what}"
    return f"reached t_end = {t:.17g} after {n_imp} impacts"


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
    `simultaneity_window` apply (laws.py; docs/laws.md, "The linear model under the
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
        "n_events": int(len(run.kind)),
        "accumulations": accumulations,
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
