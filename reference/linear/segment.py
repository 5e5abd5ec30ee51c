"""One run of the linear model's compiled kernel (`run_segment`), its rows as a
`LinearRun`, and its one-line message: what `simulate.run_linear` returns.  The run's
impact law resolves a simultaneous impact inside the kernel's loop (kernel._law_event)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..core.law_message import undecided_message
from ..core.laws import law_of_name, work_floats
from ..trajectory import Status
from . import kernel as K
from .model import LinearModel

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
    wall_time_s: float  # the run, without compile_s
    compile_s: float  # the kernel's compilation or loading before it (0: in this process)
    impact_law: str = "paper"  # the law of simultaneous impacts (reference.core.laws)
    simultaneity_window: float = 0.0  # contacts reached within it count as one impact
    simultaneous_impacts: int = 0  # the simultaneous impacts the law resolved in the loop

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
    K.REASON_LAW_UNDECIDED: "the impact law left a simultaneous impact undecided",
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
    impact_law: str = "paper",
) -> tuple[LinearRun, tuple]:
    """`run_linear`: the kernel's run from (q0, p0) under `impact_law` (a name of the
    law registry, reference.core.laws), with its loop state at the stop
    (kernel.new_loop_state: the normalised q, p, their roundoff scales, ..., si, sf)."""
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
    law = law_of_name(impact_law)
    law_scratch = K.new_law_scratch(F.shape[0], work_floats(law, F.shape[0]))
    start_args = (
        *consts, model.gravity, model.restitution, model.rank, q0, p0, bool(record_states),
        out_i, out_f, out_s, info, *loop[:9],
    )  # fmt: skip
    continue_args = (
        *consts, model.restitution, model.rank, float(t_end), int(max_impacts),
        float(log2_floor), float(chatter_tol), float(decouple_tol), float(window),
        int(law.code), bool(record_states),
        out_i, out_f, out_s, info, *loop, *law_scratch, LOOP_BUDGET,
    )  # fmt: skip
    compile_s = K.load_entry_points(start_args, continue_args)  # not part of the run's time
    t0 = time.perf_counter()
    done = K.start_kernel(*start_args)
    while not done:  # back in Python every LOOP_BUDGET events: Ctrl-C works
        done = K.continue_kernel(*continue_args) >= 0
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
        if info[K.INFO_SERIES]:  # at rest on every contact at the series' end
            states["acc"][-1] = 0.0
    else:
        states = dict(q_pre=None, p_pre=None, q_post=None, p_post=None, acc=None)
    dtn = of[:, K.F_DTN]
    with np.errstate(divide="ignore"):
        log2_dt = np.where(dtn > 0, np.log2(np.where(dtn > 0, dtn, 1.0)), -np.inf) + oi[:, K.I_DTE]
    t_stop = of[n - 1, K.F_THI] + of[n - 1, K.F_TLO] if n else 0.0
    msg = run_message(status, reason, t_stop, int(info[2]), (int(info[3]), int(info[4])))
    if reason == K.REASON_LAW_UNDECIDED:
        contacts = [int(c) for c in np.flatnonzero(loop[12])]
        msg = undecided_message(impact_law, int(info[K.INFO_LAW_OUTCOME]), t_stop, contacts,
                                int(info[K.INFO_LAW_HITS]))  # fmt: skip
    elif info[K.INFO_SERIES]:
        msg = (f"self-similar bounces from t = {float(loop[8][K.SF_SERIES_T]):.17g} completed "
               "in closed form (t_f = t + 2/(kappa (1 - gamma))): at rest on all contacts at "
               f"t = {t_stop:.17g}")  # fmt: skip
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
        compile_s=compile_s,
        impact_law=impact_law,
        simultaneity_window=float(window),
        simultaneous_impacts=int(info[K.INFO_LAW_IMPACTS]),
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
