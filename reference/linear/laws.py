"""The linear model past undecidable states, under the exact reference's impact laws
(docs/laws.md; the registry reference.core.laws; the exact core resolves them inside its
loop, reference.core.law_event).

The linear kernel applies the paper's rule: where several contacts touch at an impact
(two reached at once, an impact that would push a held contact, a contact at the ground
when a chatter accumulates) it stops `simultaneous_impact` on the state before the
impact.  Under `moreau` or `sequential` the run goes on from there (`run_under_law`):

1. the contacts of the impact: every contact touching the ground within roundoff and
   not separating (`kernel.law_contacts`; held contacts included), and those the
   kernel found reached within the simultaneity window (their gaps, at most T|u|, are
   not closed: as in the exact core);
2. their Delassus matrix in the linear model, W = F_S Θ⁻¹ F_Sᵀ (w_ab = f_aᵀΘ⁻¹f_b, the
   change of contact a's normal velocity per unit impulse at b: `kernel._contact_products`,
   from Θ Δp = Σ f_b λ_b of the linearised Newton–Euler equations, paper eqs. Theta,
   impactequ) and normal velocities u⁻ = F_S p⁻, given to the SAME law functions as the
   exact core's (reference.core.impact_laws: `moreau_impulses`, `sequential_impulses`);
   p⁺ = p⁻ + Θ⁻¹ F_Sᵀ Λ.  With one contact this is the kernel's own impact, bit for bit
   (eq. F; `single_impulse` is `impact.impact_impulse`'s formula);
3. bounces too small to follow (every contact that leaves leaves below decouple_tol ×
   the velocity scale V, the kernel's threshold for completions without proof) are
   completed as after a single impact: the impact is taken plastic (γ = 0) and the
   contacts stay held;
4. a body landing flat (every contact in the impact, all leaving at one speed u⁺ > 0,
   0 < γ < 1) bounces flat for ever: the series is completed in closed form and the run
   ends at rest (`singularity`, all contacts down) at t + 2u⁺/(g(1 − γ))
   (`bounce_series`);
5. otherwise the kernel restarts from the state after the impact (its start closes the
   contacts left at zero normal velocity: the held-contact phases), with t_end,
   max_impacts and the energy floor kept those of the whole run.

The rows of the run: one IMPACT row per contact that took an impulse, all at the
impact's time (the first carries the interval before it, the others 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.impact_laws import (
    MAX_SEQUENTIAL_IMPACTS,
    NOT_SETTLED,
    SETTLED,
    SINGULAR,
    TOO_MANY,
)
from ..core.law_event import LAW_MAX_REPEATS as MAX_RESTARTS_AT_ONE_TIME
from ..core.laws import LAW_PAPER, LAWS, law_code, law_of, resolving_laws, work_floats
from ..core.records import LawWork
from ..core.tolerances import EPS
from ..trajectory import Status
from . import kernel as K
from .segment import LinearRun, run_message, run_segment

# the fields of a LinearRun that have one entry per event row
ROW_FIELDS = (
    "kind", "contact", "contact2", "held", "dt", "log2_dt", "t_hi", "t_lo", "impulse",
    "v_pre", "v_post", "energy_pre", "energy_post", "log2_energy",
)  # fmt: skip
STATE_FIELDS = ("q_pre", "p_pre", "q_post", "p_post", "acc")
# a contact leaves an impact when its u⁺ exceeds this many ulps of the velocity scale
LEAVING_ULPS = 64.0


def law_impulses(W, u_pre, gamma, law: int):
    """(status, Λ, u⁺, single impacts) of `law` (a code of the law registry,
    reference.core.laws; the sequential law takes the fastest approach first) on k
    contacts of Delassus matrix W and normal velocities u⁻: the exact core's law
    functions, dispatched as the exact core dispatches them (law_dispatch.solve_law)."""
    from ..core.law_dispatch import solve_law

    if law == LAW_PAPER or law not in {x.code for x in LAWS}:
        raise ValueError(f"no law function for law code {law}")
    k = len(u_pre)
    W = np.ascontiguousarray(W, dtype=float)
    u_pre = np.ascontiguousarray(u_pre, dtype=float)
    lam, u_post = np.zeros(k), np.zeros(k)
    vec = np.zeros(work_floats(law_of(law), k))
    work = LawWork(np.zeros((k, k)), vec, np.zeros(k, dtype=np.int64),
                   np.zeros(0, dtype=np.int64), 0, MAX_SEQUENTIAL_IMPACTS)  # fmt: skip
    status, hits = solve_law(law, W, u_pre, float(gamma), k, lam, u_post, work)
    return int(status), lam, u_post, int(hits)


def delassus(F, theta, contacts):
    """W = F_S Θ⁻¹ F_Sᵀ of the contacts S (the linear model's Delassus matrix) and, for
    convenience, Θ⁻¹ = 1/theta."""
    tinv = 1.0 / np.asarray(theta, dtype=float)
    w = K._contact_products(np.ascontiguousarray(F, dtype=float), tinv)[0]
    s = np.asarray(contacts, dtype=np.int64)
    return w[np.ix_(s, s)], tinv


def apply_law(F, theta, gamma, p, contacts, law: int, complete_below: float = 0.0):
    """In place on p: the impact of `contacts` under `law`; p⁺ = p⁻ + Θ⁻¹F_SᵀΛ (contact
    by contact, as the kernel's `_apply_impulse`).  With 0 < γ < 1, when every contact
    that leaves leaves at u⁺ ≤ `complete_below` (and some does), the impact is taken
    plastic (γ = 0): the bounces that would follow are completed.  Returns (status, Λ,
    u⁻, u⁺, single impacts, completed); p is unchanged unless the law settled."""
    W, tinv = delassus(F, theta, contacts)
    Fs = np.asarray(F, dtype=float)[np.asarray(contacts, dtype=np.int64)]
    u_pre = np.array([K._dot(F, int(c), p) for c in contacts])
    status, lam, u_post, hits = law_impulses(W, u_pre, gamma, law)
    completed = False
    if status == SETTLED and 0.0 < gamma < 1.0 and complete_below > 0.0:
        noise = LEAVING_ULPS * EPS * complete_below
        leaving = u_post > noise
        if leaving.any() and np.all(u_post[leaving] <= complete_below):
            status, lam, u_post, hits = law_impulses(W, u_pre, 0.0, law)
            completed = True
    if status == SETTLED:
        for i in range(len(contacts)):
            if lam[i] != 0.0:
                p += tinv * Fs[i] * lam[i]
    return status, lam, u_pre, u_post, hits, completed


# a bounce series is self-similar when p⁺ and the acceleration after are parallel and
# the law maps −p⁺ to γp⁺, each to this relative residual (roundoff: ~1e-15 measured)
SELF_SIMILAR_TOL = 1e-9


@dataclass(frozen=True)
class BounceSeries:
    """A Zeno series of self-similar bounces (`bounce_series`), in the kernel's
    normalised units: the first flight 2/κ, the whole series' duration 2/(κ(1 − γ)),
    and the first landing's impulses and normal velocities (bounce k: × γ^(k−1))."""

    flight: float
    duration: float
    lam: np.ndarray
    u_pre: np.ndarray
    u_post: np.ndarray
    held: tuple[int, ...]


def bounce_series(model, p_post, contacts, u_post, law: int, vfl: float, g: float):
    """The Zeno series of self-similar bounces an impact at q = 0 (every contact
    touching) starts, or None when it starts none (p_post, u_post, vfl, gravity g and
    the times in the kernel's normalised units).

    With B the contacts resting after the impact (u⁺ = 0) held, the acceleration a is
    constant (model.held_acceleration, forces η ≥ 0).  If a = −κ p⁺ (κ > 0), the motion
    is q(s) = p⁺(s − κs²/2): every gap f_cᵀq is f_cᵀp⁺ ≥ 0 times one bouncing-ball
    profile, and at s = 2/κ the body is back at q = 0 with p = −p⁺.  If the law maps
    −p⁺ to γp⁺ (it does when the contacts leave the body one degree of freedom: a
    triangle's vertex bouncing beside its held edge; or when p⁺ ∝ e_z: a polygon landing
    flat), the next flight is γ times shorter, and so on: the series ends at rest (q =
    p = 0 in the coordinates the contacts see) after T = 2/(κ(1 − γ))."""
    from .model import held_acceleration

    gamma = model.restitution
    if not (0.0 < gamma < 1.0 and g > 0.0) or len(contacts) < model.n_contacts:
        return None
    noise = LEAVING_ULPS * EPS * vfl
    rest = [int(c) for c, u in zip(contacts, u_post, strict=True) if abs(u) <= noise]
    if len(rest) >= model.rank or not np.any(u_post > noise):
        return None
    theta = model.theta
    f_rest = model.F[rest] if rest else np.zeros((0, 3))
    acc, eta = held_acceleration(f_rest, theta, model.mass, g)
    if np.any(eta < 0.0):
        return None
    norm2 = float(p_post @ (theta * p_post))
    kappa = -float(acc @ (theta * p_post)) / norm2
    resid = acc + kappa * p_post
    if not kappa > 0.0 or float(resid @ (theta * resid)) > SELF_SIMILAR_TOL**2 * kappa**2 * norm2:
        return None
    p_next = -p_post
    status, lam, u_pre, u_next, _, _ = apply_law(model.F, theta, gamma, p_next, contacts, law)
    miss = p_next - gamma * p_post
    if status != SETTLED or float(miss @ (theta * miss)) > SELF_SIMILAR_TOL**2 * norm2:
        return None
    flight = 2.0 / kappa
    return BounceSeries(flight, flight / (1.0 - gamma), lam, u_pre, u_next, tuple(rest))


def _series_rows(model, series: BounceSeries, contacts, kv: int, kq: int, t_hi: float,
                 t_lo: float, q, p_post, e_floor: float, budget: int, record: bool):  # fmt: skip
    """The bounces of a self-similar series as IMPACT rows (one per contact that takes
    an impulse; closed form: bounce k at t + (2/κ)(1 − γ^k)/(1 − γ), everything else
    × γ^(k−1)) while the energy before a bounce is above e_floor and at most `budget`
    rows, then the END row at rest at t + 2/(κ(1 − γ)).  Inputs q, p_post in true
    units, series in normalised ones; the rows' values in true units."""
    gamma = model.restitution
    flight = math.ldexp(series.flight, kq - kv)
    took = np.flatnonzero(series.lam > 0.0)
    held = np.full(2, -1, dtype=np.int64)
    held[: min(len(series.held), 2)] = series.held[:2]
    acc = held_acceleration_of(model, series.held)
    cols: dict[str, list] = {f: [] for f in ROW_FIELDS + STATE_FIELDS}
    q = np.zeros(3)  # every contact at the ground: q = 0 (the impact's q within roundoff)
    k, n = 1, 0
    while n + len(took) <= budget:
        r = gamma ** (k - 1)
        e_pre = model.energy(q, -r * p_post)
        if not (e_pre > e_floor and flight * r > 0.0):
            break
        e_post = model.energy(q, gamma * r * p_post)
        since = flight * (1.0 - gamma**k) / (1.0 - gamma)
        tk_hi, tk_lo = _shift(np.array([since]), np.zeros(1), t_hi, t_lo)
        for i, c in enumerate(took):
            row = dict(
                kind=K.IMPACT, contact=contacts[c], contact2=-1, held=held,
                dt=flight * r if i == 0 else 0.0,
                log2_dt=math.log2(flight * r) if i == 0 else -math.inf,
                t_hi=tk_hi[0], t_lo=tk_lo[0], impulse=math.ldexp(series.lam[c] * r, kv),
                v_pre=math.ldexp(series.u_pre[c] * r, kv),
                v_post=math.ldexp(series.u_post[c] * r, kv), energy_pre=e_pre,
                energy_post=e_post, log2_energy=math.log2(e_post),
                q_pre=q, p_pre=-r * p_post, q_post=q, p_post=gamma * r * p_post, acc=acc,
            )  # fmt: skip
            for f, v in row.items():
                cols[f].append(v)
        n += len(took)
        k += 1
    rows = {f: np.array(v) if v else np.zeros((0, 3) if f in STATE_FIELDS else 0)
            for f, v in cols.items()}  # fmt: skip
    if not record:
        rows.update(q_pre=None, p_pre=None, q_post=None, p_post=None, acc=None)
    rows["held"] = rows["held"].reshape(-1, 2)
    for f in ("kind", "contact", "contact2", "held"):
        rows[f] = rows[f].astype(np.int64)
    return [rows]


def held_acceleration_of(model, held) -> np.ndarray:
    """The constant acceleration with the contacts `held` held (model.held_acceleration)
    in true units."""
    from .model import held_acceleration

    f = model.F[list(held)] if held else np.zeros((0, 3))
    return held_acceleration(f, model.theta, model.mass, model.gravity)[0]


def _shift(t_hi, t_lo, o_hi: float, o_lo: float):
    """(o_hi + o_lo) + (t_hi + t_lo) as double-doubles (two-sum)."""
    s = o_hi + t_hi
    bb = s - o_hi
    err = (o_hi - (s - bb)) + (t_hi - bb) + (t_lo + o_lo)
    hi = s + err
    return hi, err - (hi - s)


def _rows(run, lo: int, hi: int, o_hi: float, o_lo: float) -> dict:
    """Rows lo:hi of a segment, its times shifted by the offset."""
    rows = {f: getattr(run, f)[lo:hi].copy() for f in ROW_FIELDS}
    rows["t_hi"], rows["t_lo"] = _shift(rows["t_hi"], rows["t_lo"], o_hi, o_lo)
    for f in STATE_FIELDS:
        x = getattr(run, f)
        rows[f] = None if x is None else x[lo:hi].copy()
    return rows


def _law_rows(model, end_row: dict, contacts, lam, u_pre, u_post, kv: int,
              q_true, p_pre_true, p_post_true, e_pre: float, e_post: float) -> dict:  # fmt: skip
    """One IMPACT row per contact that took an impulse, at the time of `end_row` (the
    stop row it replaces: the first takes its interval before, the others 0)."""
    took = np.flatnonzero(lam > 0.0)
    m = len(took)
    first = np.arange(m) == 0
    rows = {
        "kind": np.full(m, K.IMPACT, dtype=np.int64),
        "contact": np.asarray(contacts, dtype=np.int64)[took],
        "contact2": np.full(m, -1, dtype=np.int64),
        "held": np.repeat(end_row["held"][:1], m, axis=0),
        "dt": np.where(first, end_row["dt"][0], 0.0),
        "log2_dt": np.where(first, end_row["log2_dt"][0], -np.inf),
        "t_hi": np.full(m, end_row["t_hi"][0]),
        "t_lo": np.full(m, end_row["t_lo"][0]),
        "impulse": np.ldexp(lam[took], kv),
        "v_pre": np.ldexp(u_pre[took], kv),
        "v_post": np.ldexp(u_post[took], kv),
        "energy_pre": np.full(m, e_pre),
        "energy_post": np.full(m, e_post),
        "log2_energy": np.full(m, math.log2(e_post) if e_post > 0 else -math.inf),
    }
    if end_row["q_pre"] is not None:
        rows["q_pre"] = np.repeat(q_true[None, :], m, axis=0)
        rows["q_post"] = rows["q_pre"].copy()
        rows["p_pre"] = np.repeat(p_pre_true[None, :], m, axis=0)
        rows["p_post"] = np.repeat(p_post_true[None, :], m, axis=0)
        rows["acc"] = np.repeat(end_row["acc"][:1], m, axis=0)
    else:
        rows.update(q_pre=None, p_pre=None, q_post=None, p_post=None, acc=None)
    return rows


def _concat(parts: list[dict]) -> dict:
    out = {}
    for f in ROW_FIELDS + STATE_FIELDS:
        xs = [p[f] for p in parts if len(p["kind"])]
        out[f] = None if xs and xs[0] is None else np.concatenate(xs)
    return out


def _rest_row(model, row: dict, t_hi: float, t_lo: float, tail: float, q, p, contacts):
    """The END row of a completed bounce series: at rest at t + tail on all contacts
    (the coordinates the contacts see are 0; the rod's roll about its axis, which they
    do not see, carried on for the tail); its interval is from the last row (`row`)."""
    F, tinv = model.F, 1.0 / model.theta
    idx = np.asarray(contacts[:3], dtype=np.int64)
    q_r = np.asarray(q, dtype=float) + np.asarray(p, dtype=float) * tail
    p_r = np.array(p, dtype=float)
    K._project(q_r, F, tinv, idx, len(idx))
    K._project(p_r, F, tinv, idx, len(idx))
    e = model.energy(q_r, p_r)
    t_f_hi, t_f_lo = _shift(np.array([tail]), np.zeros(1), t_hi, t_lo)
    rows = {f: row[f][-1:].copy() for f in ROW_FIELDS}
    dt = float((t_f_hi[0] - row["t_hi"][-1]) + (t_f_lo[0] - row["t_lo"][-1]))
    rows.update(
        kind=np.array([K.END]), contact=np.array([-1]), contact2=np.array([-1]),
        dt=np.array([dt]), log2_dt=np.array([math.log2(dt) if dt > 0 else -math.inf]),
        t_hi=t_f_hi, t_lo=t_f_lo, impulse=np.zeros(1), v_pre=np.zeros(1), v_post=np.zeros(1),
        energy_pre=np.array([e]), energy_post=np.array([e]),
        log2_energy=np.array([math.log2(e) if e > 0 else -math.inf]),
    )  # fmt: skip
    if row["q_pre"] is not None:
        for f, x in (("q_pre", q_r), ("q_post", q_r), ("p_pre", p_r), ("p_post", p_r)):
            rows[f] = x[None, :].copy()
        rows["acc"] = np.zeros((1, 3))
    else:
        rows.update(q_pre=None, p_pre=None, q_post=None, p_post=None, acc=None)
    return rows, float(t_f_hi[0] + t_f_lo[0])


def _law_failure(status: int, hits: int, law: str, contacts, t: float) -> str:
    """The message of a law that did not resolve the impact (the run ends undecidable)."""
    cs = [int(c) for c in contacts]
    if status == NOT_SETTLED:
        return (f"the {law} law did not settle after {hits} single impacts at t = {t:.17g} "
                f"(contacts {cs}): undecidable")  # fmt: skip
    if status == SINGULAR:
        return f"a contact of {cs} takes no impulse at t = {t:.17g}"
    if status == TOO_MANY:
        return f"{len(cs)} contacts touch at t = {t:.17g}: more than the impact laws take"
    return f"the {law} law failed at t = {t:.17g} (contacts {cs})"


def _stop_state(model, loop):
    """The kernel's state at its stop: normalised q, p, their roundoff scales, the
    scale exponents kv, kq (q = 2^kq q̃, p = 2^kv p̃), normalised gravity and energy,
    and the velocity scale V (kernel._velocity_scale)."""
    q, p, qs, ps = (np.array(x) for x in loop[:4])
    si, sf = loop[7], loop[8]
    kv, kq, gt = int(si[K.SI_KV]), int(si[K.SI_KQ]), float(sf[K.SF_GRAVITY])
    e = float(K._energy(q, p, model.theta, model.mass, gt))
    w, wmax = K._contact_products(model.F, 1.0 / model.theta)
    return q, p, qs, ps, kv, kq, gt, e, math.sqrt(2.0 * max(e, 0.0) * wmax)


def _true_state(loop):
    """(q, p) of the kernel's loop state in true units (exact: powers of two)."""
    si = loop[7]
    return np.ldexp(loop[0], int(si[K.SI_KQ])), np.ldexp(loop[1], int(si[K.SI_KV]))


def _approaching(F, q, p, ps, contacts, vfl) -> bool:
    """Whether a contact of `contacts` approaches beyond roundoff (kernel._approaching)."""
    return any(K._dot(F, int(c), p) < -K._tol(F, int(c), ps, vfl) for c in contacts)


def run_under_law(
    model, q0, p0, law: str, *, t_end: float, max_impacts: int, energy_floor: float,
    chatter_tol: float, decouple_tol: float, record_states: bool, window: float = 0.0,
):  # fmt: skip
    """`simulate.run_linear` under `law` (`moreau` or `sequential`): kernel segments
    under the paper's rule, each undecidable stop resolved by the law and the kernel
    restarted after it (module docstring).  Returns one LinearRun over all segments."""

    resolving = [x.name for x in resolving_laws()]
    if law not in resolving:
        raise ValueError(f"impact law must be one of {', '.join(resolving)} here, got {law!r}")
    law_id = law_code(law)
    F, theta, gamma = model.F, model.theta, model.restitution
    q, p = np.array(q0, dtype=float), np.array(p0, dtype=float)
    e_init = model.energy(q, p)
    parts: list[dict] = []
    o_hi = o_lo = 0.0
    n_imp, wall, same_time, last_t, e_last = 0, 0.0, 0, None, math.inf
    while True:
        e_now = model.energy(q, p)
        floor = energy_floor * e_init / e_now if e_init > 0 and e_now > 0 else energy_floor
        t_left = max(t_end - (o_hi + o_lo), 0.0) if math.isfinite(t_end) else math.inf
        seg, loop = run_segment(model, q, p, t_left, max(max_impacts - n_imp, 0), floor,
                                chatter_tol, decouple_tol, record_states, window)  # fmt: skip
        wall += seg.wall_time_s
        n_imp += seg.n_impacts
        first = 1 if parts else 0  # a restart's INITIAL row: its held set goes to the last
        if first:
            _hand_over(parts, seg)
        n = len(seg.kind)
        status, reason = seg.status, seg.reason
        if status is not Status.SIMULTANEOUS_IMPACT:
            parts.append(_rows(seg, first, n, o_hi, o_lo))
            t = float(parts[-1]["t_hi"][-1] + parts[-1]["t_lo"][-1])
            message = run_message(status, reason, t, n_imp)
            break
        parts.append(_rows(seg, first, n - 1, o_hi, o_lo))
        end_row = _rows(seg, n - 1, n, o_hi, o_lo)
        t_hi, t_lo = float(end_row["t_hi"][0]), float(end_row["t_lo"][0])
        e_stop = model.energy(*_true_state(loop))
        # progress: the time moves on, or the energy falls (a cascade of simultaneous
        # impacts whose intervals are below the clock's resolution)
        if t_hi == last_t and not e_stop < 0.5 * e_last:
            same_time += 1
        else:
            same_time, last_t, e_last = 0, t_hi, e_stop
        qn, pn, qs, ps, kv, kq, gt, e_n, vfl = _stop_state(model, loop)
        idx = np.zeros(model.n_contacts, dtype=np.int64)
        contacts = idx[: K.law_contacts(F, qn, pn, qs, ps, vfl, idx)]
        if seg.reason == K.REASON_WINDOW:  # with those reached within the window
            contacts = np.union1d(contacts, np.flatnonzero(loop[12]))
        contacts = np.array(contacts, dtype=np.int64)
        if same_time >= MAX_RESTARTS_AT_ONE_TIME:
            parts.append(end_row)
            message = f"the {law} law made no progress at t = {t_hi:.17g}: stopped (undecidable)"
            break
        p_post = pn.copy()
        if _approaching(F, qn, pn, ps, contacts, vfl):
            res, lam, u_pre, u_post, hits, _ = apply_law(
                F, theta, gamma, p_post, contacts, law_id, decouple_tol * vfl
            )
            if res != SETTLED:
                parts.append(end_row)
                message = _law_failure(res, hits, law, contacts, t_hi)
                break
            q_true = np.ldexp(qn, kq)
            e_pre = model.energy(q_true, np.ldexp(pn, kv))
            e_post = model.energy(q_true, np.ldexp(p_post, kv))
            rows = _law_rows(model, end_row, contacts, lam, u_pre, u_post, kv, q_true,
                             np.ldexp(pn, kv), np.ldexp(p_post, kv), e_pre, e_post)  # fmt: skip
            parts.append(rows)
            n_imp += len(rows["kind"])
            if not e_post > energy_floor * e_init:  # the kernel's test after an impact
                status = Status.SINGULARITY
                reason = K.REASON_ENERGY_EXHAUSTED if e_post > 0 else K.REASON_NO_ENERGY
                message = run_message(status, reason, t_hi, n_imp)
                break
            series = bounce_series(model, p_post, contacts, u_post, law_id, vfl, gt)
            tail = None if series is None else math.ldexp(series.duration, kq - kv)
            if tail is not None and t_hi + tail <= t_end:
                p_true = np.ldexp(p_post, kv)
                bounces = _series_rows(model, series, contacts, kv, kq, t_hi, t_lo, q_true,
                                       p_true, energy_floor * e_init, max_impacts - n_imp,
                                       record_states)  # fmt: skip
                parts += bounces
                n_imp += len(bounces[0]["kind"])
                last = bounces[0] if len(bounces[0]["kind"]) else rows
                rest, t_f = _rest_row(model, last, t_hi, t_lo, tail, q_true, p_true, contacts)
                parts.append(rest)
                status, reason = Status.SINGULARITY, K.REASON_SINGULARITY
                message = (
                    f"self-similar bounces from t = {t_hi:.17g} completed in closed form "
                    f"(t_f = t + 2/(kappa (1 - gamma))): at rest on all contacts at t = "
                    f"{t_f:.17g}"
                )
                break
        q, p = np.ldexp(qn, kq), np.ldexp(p_post, kv)
        o_hi, o_lo = t_hi, t_lo
    rows = _concat(parts)
    return LinearRun(
        model=model, status=status, reason=reason, message=message, n_impacts=n_imp,
        wall_time_s=wall, impact_law=law, simultaneity_window=float(window), **rows,
    )  # fmt: skip


def _hand_over(parts: list[dict], seg) -> None:
    """A restart's INITIAL row is dropped; the held set and the acceleration the kernel
    recorded on it (the segment after the impact) go to the last row before it."""
    for part in reversed(parts):
        if len(part["kind"]):
            part["held"][-1] = seg.held[0]
            if part["acc"] is not None and seg.acc is not None:
                part["acc"][-1] = seg.acc[0]
            return
