"""Runs continued past undecidable states under an explicit impact law
(docs/laws.md).

The compiled loop applies the paper's rule: where several contacts touch at an impact
(two reached within its time resolution, or an impact that would push a held contact)
it stops with `simultaneous_impact`, on the state just before that impact.  Under the
`moreau` or `sequential` law the run goes on from there (`continue_run`):

1. the contacts of the impact: every contact touching (gap within roundoff of the
   ground, `touching_contacts`) and not separating (under `compliant`, the separating
   ones too: the others can push them back);
2. the law's impulses on them (reference.core.multi_impact, the laws of
   reference.core.impact_laws), one impact row per contact that took an impulse, all at
   the impact's time;
3. a body landing flat (every contact in the impact, all leaving at one speed u⁺ > 0,
   γ > 0) bounces flat for ever after, each flight 2u/g and each landing γ times
   slower: the series is completed in closed form and the run ends at rest at
   t_f = t + 2u⁺/(g(1 − γ)) (`flat_bounce_end`), like the chatter completion;
4. otherwise the loop resumes from the state after the impact (its start step holds
   the contacts left at zero normal velocity: the existing contact phases), with the
   energy floor kept relative to the run's initial excess energy.

The sequential law that does not settle ends the run `simultaneous_impact`, saying so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .core import layout as L
from .core import records as R
from .core.law_codes import (
    LAW_NAMES,
    MAX_LAW_CONTACTS,
    MAX_SEQUENTIAL_IMPACTS,
    NOT_SETTLED,
    SINGULAR,
    TOO_MANY,
)
from .core.tolerances import EPS, GAP_NOISE_ULPS, RATE_NOISE_ULPS
from .geometry import contact_kinematics, excess_energy
from .quaternion import from_rotation_vector, multiply

# touching: gap within this many roundoff bands of the ground (the loop reaches a
# contact to a few ulps of |z| + a; two reached "together" are within its resolution)
TOUCH_ULPS = 4 * GAP_NOISE_ULPS
# a flat bounce: post-impact normal velocities equal to this relative spread
FLAT_SPREAD = 1e-9


@dataclass
class LawImpact:
    """One simultaneous impact resolved by a law."""

    contacts: np.ndarray
    impulses: np.ndarray
    u_pre: np.ndarray
    u_post: np.ndarray
    status: int  # impact_laws.SETTLED / NOT_SETTLED / SINGULAR / TOO_MANY
    single_impacts: int
    completed: bool = False  # the bounces were small: completed (taken plastic)


def touching_contacts(
    scene, y: np.ndarray, always: list[int], separating: bool = False
) -> np.ndarray:
    """Contacts touching the ground at state y and not separating: gap ≤ TOUCH_ULPS ε
    (|z| + a) and normal velocity ≤ its roundoff, plus `always` (the contacts the loop
    named); `separating`: the touching ones that separate too (the compliant law, in
    which the others can push them back)."""
    gap, vn = contact_kinematics(y, scene.contacts)
    gap, vn = gap[0], vn[0]
    a = scene.body.radius
    gap_tol = TOUCH_ULPS * EPS * (abs(y[L.Z]) + a)
    v_scale = np.linalg.norm(y[L.VELOCITY]) + a * np.linalg.norm(y[L.ANGULAR_VELOCITY])
    v_tol = RATE_NOISE_ULPS * EPS * v_scale
    mask = (gap <= gap_tol) & ((vn <= v_tol) | separating)
    mask[list(always)] = True
    return np.flatnonzero(mask)


def apply_law(
    scene,
    y: np.ndarray,
    contacts: np.ndarray,
    law: str,
    order: tuple[int, ...] | None = None,
    chatter_tol: float = 1e-6,
) -> LawImpact:
    """In place on y: the impact of `contacts` under `law` (`moreau` or `sequential`;
    `order`: the sequential law's order of contacts, None the fastest first; bounces all
    below chatter_tol × V completed, multi_impact.law_impact)."""
    from .compiled import function
    from .simulate import model_record

    k = len(contacts)
    pts = np.ascontiguousarray(scene.contacts.points, dtype=float)
    cs = np.ascontiguousarray(contacts, dtype=np.int64)
    pos = {int(c): i for i, c in enumerate(cs)}
    ordered = [pos[c] for c in (order or ()) if c in pos]
    if order:  # touching contacts the order does not name come after, by index
        ordered += [i for i in range(k) if i not in ordered]
    order_idx = np.array(ordered, dtype=np.int64)
    W, chol = np.zeros((k, k)), np.zeros((k, k))
    u_pre, lam, u_post = np.zeros(k), np.zeros(k), np.zeros(k)
    from .core.compliant import work_size  # here: the compiled core imports numba

    vec = np.zeros(max(2 * k, work_size(k)))  # the laws' scratch (compliant's the largest)
    active, result = np.zeros(k, dtype=np.int64), np.zeros(3, dtype=np.int64)
    function("multi_impact")(
        y, model_record(scene), pts, LAW_NAMES.index(law), cs, k, order_idx, len(order_idx),
        MAX_SEQUENTIAL_IMPACTS, chatter_tol,
        W, u_pre, lam, u_post, chol, vec, active, result,
    )  # fmt: skip
    return LawImpact(cs, lam, u_pre, u_post, int(result[0]), int(result[1]), bool(result[2]))


def flat_bounce_end(scene, impact: LawImpact) -> float | None:
    """The time from the impact to the end of a Zeno series of flat bounces, 2u⁺/(g(1 −
    γ)), when every contact took part and all leave at one speed u⁺ > 0 (γ > 0, g > 0);
    None otherwise."""
    g, gamma = scene.gravity, scene.restitution
    if len(impact.contacts) != scene.n_contacts or not (g > 0 and 0 < gamma < 1):
        return None
    u = impact.u_post
    if u.min() <= 0 or u.max() - u.min() > FLAT_SPREAD * u.max():
        return None
    return 2.0 * float(u.mean()) / (g * (1.0 - gamma))


def rest_state(y: np.ndarray, dt: float) -> np.ndarray:
    """The body lying flat at rest after dt of Zeno bounces: the normal motion gone, the
    horizontal drift and the spin about the vertical (untouched by normal impulses)
    carried on for dt."""
    out = np.array(y, dtype=float)
    out[L.X : L.Y + 1] += y[L.VX : L.VY + 1] * dt
    out[L.VZ] = 0.0
    out[L.WX : L.WY + 1] = 0.0
    turn = from_rotation_vector((0.0, 0.0, y[L.WZ] * dt))
    out[L.QUATERNION] = multiply(turn, y[L.QUATERNION])
    return out


def law_contacts(state) -> list[int]:
    """The contacts the loop named when it stopped undecidable: the hit ones (or the
    hitting one and those it pushes) and the held ones."""
    named = [int(c) for c in state["info"][: int(state["n_info"])]]
    if int(state["status"]) == R.STATUS_PUSHED:
        named.append(int(state["info_contact"]))
    named += [int(c) for c in state["active"][: min(int(state["n_active"]), 3)]]
    return sorted(set(named))


def undecidable(state) -> bool:
    return int(state["status"]) in (R.STATUS_SIMULTANEOUS, R.STATUS_PUSHED)


def energy_floor_for(scene, y: np.ndarray, excess0: float, floor: float) -> float:
    """The loop's energy floor after a restart from y: its start takes y's excess energy
    as the initial one; the floor stays `floor` × the run's initial excess."""
    now = float(excess_energy(scene, y)[0])
    if not (now > 0 and excess0 > 0):
        return floor
    return floor * excess0 / now


# restarts at one instant without the time advancing before the run is given up
MAX_RESTARTS_AT_ONE_TIME = 64


def continue_run(
    scene, problem, kernel, law: str, order, floor: float, run_problem, chatter_tol: float
) -> str | None:
    """Resume `problem` (the loop stopped undecidable) under `law` until it ends
    otherwise; returns a message that replaces the loop's, or None."""
    st = problem.state
    excess0 = float(st["excess0"][0])
    same_time, last_t = 0, None
    while undecidable(st[0]):
        t_hi, t_lo = float(st["t_hi"][0]), float(st["t_lo"][0])
        # the time is a double-double: a cascade below one ulp of t advances in t_lo
        same_time = same_time + 1 if (t_hi, t_lo) == last_t else 0
        last_t = (t_hi, t_lo)
        if same_time >= MAX_RESTARTS_AT_ONE_TIME:
            return f"the {law} law made no progress at t = {t_hi:.17g}: stopped (undecidable)"
        y = np.array(st["y"][0], dtype=float)
        contacts = touching_contacts(
            scene, y, law_contacts(st[0]), separating=law.startswith("compliant")
        )
        impact = apply_law(scene, y, contacts, law, order, chatter_tol)
        if impact.status == NOT_SETTLED:
            return (
                f"the {law} law did not settle after {impact.single_impacts} single impacts "
                f"at t = {t_hi:.17g} (contacts {contacts.tolist()}): undecidable"
            )
        if impact.status == SINGULAR:
            return f"a contact of {contacts.tolist()} takes no impulse at t = {t_hi:.17g}"
        if impact.status == TOO_MANY:
            return (
                f"{len(contacts)} contacts touch at t = {t_hi:.17g}: more than the "
                f"{MAX_LAW_CONTACTS} the impact laws take (undecidable)"
            )
        _push_impacts(problem, t_hi, t_lo, impact)
        tail = flat_bounce_end(scene, impact)
        if tail is not None and t_hi + tail <= float(problem.options["t_end"][0]):
            return _end_at_rest(scene, problem, y, t_hi, t_lo, tail)
        _restart(problem, y, energy_floor_for(scene, y, excess0, floor))
        run_problem(kernel, problem)
    return None


def _push_impacts(problem, t_hi: float, t_lo: float, impact: LawImpact) -> None:
    """One impact row per contact that took an impulse, all at the same time."""
    took = np.flatnonzero(impact.impulses > 0.0)
    n = int(problem.counts[R.N_IMPACTS])
    need = n + len(took) + R.STEP_ROWS
    if need > len(problem.impacts):
        grown = np.empty((max(need, 2 * len(problem.impacts)), 6))
        grown[:n] = problem.impacts[:n]
        problem.impacts = grown
        problem._arguments = None
    for i in took:
        problem.impacts[n] = (t_hi, t_lo, impact.contacts[i], impact.impulses[i],
                              impact.u_pre[i], impact.u_post[i])  # fmt: skip
        n += 1
    problem.run["counts"][0][R.N_IMPACTS] = n


def _restart(problem, y: np.ndarray, floor: float) -> None:
    """The loop's state set to resume from y at the same time: its start step resolves
    the contacts touching there (holds those at rest)."""
    st = problem.state
    st["y"][0] = y
    st["status"] = R.STATUS_RUNNING
    st["started"] = False
    st["in_contact"] = False
    st["n_active"] = 0
    st["has_trend"] = False
    st["h_next"] = 0.0
    st["info_contact"] = -1
    st["n_info"] = 0
    st["stall_steps"] = 0
    problem.options["energy_floor"] = floor


def _end_at_rest(scene, problem, y, t_hi: float, t_lo: float, tail: float) -> str:
    """The Zeno series of flat bounces completed: at rest at t + tail (within t_end)."""
    st = problem.state
    t_f = t_hi + tail
    rest = rest_state(y, tail)
    st["y"][0] = rest
    st["t_hi"], st["t_lo"] = t_f, t_lo + ((t_hi - t_f) + tail)
    st["status"] = R.STATUS_AT_REST
    st["t_singularity"] = t_f
    _push_sample(scene, problem, t_f, float(st["t_lo"][0]), rest)
    return (
        f"flat bounces from t = {t_hi:.17g} completed in closed form (t_f = t + 2u/(g(1 - "
        f"gamma))): at rest on all contacts at t = {t_f:.17g}"
    )


def _push_sample(scene, problem, t_hi: float, t_lo: float, y: np.ndarray) -> None:
    from .geometry import energies

    n = int(problem.counts[R.N_SAMPLES])
    if n >= len(problem.sample_t):
        for name in ("sample_t", "sample_y", "sample_e"):
            arr = getattr(problem, name)
            grown = np.empty((len(arr) + 1, *arr.shape[1:]))
            grown[:n] = arr[:n]
            setattr(problem, name, grown)
        problem._arguments = None
    ke, pe = energies(scene, y)
    problem.sample_t[n] = (t_hi, t_lo)
    problem.sample_y[n] = y
    problem.sample_e[n] = (ke[0], pe[0])
    problem.run["counts"][0][R.N_SAMPLES] = n + 1
