"""Oracle: the event-driven loop of the exact reference, in plain Python and numpy/scipy.

This is the specification the compiled core (reference.core) was written from, kept as
an independent test oracle: it runs end to end without compiled code (numpy contact
kinematics, scipy's solve_ivp for contact phases, brentq for lift-offs, the all-contact
event search with the original derivative bounds).  tests/test_oracle.py compares the
product with it impact by impact.

The model (as in the product):

Phases alternate between closed-form free flight (`flight`), sustained contact with one
or two points (`contact`), and instantaneous events: single-point Newtonian impacts
(`impact`), lift-off (a contact force reaching zero), chatter completion and the end of
the motion.  The run stops with an explicit `Status` and never guesses:

- two contacts reached within the time resolution, or an impact that would drive a
  resting contact into the ground (the paper's rule), end the run with
  `simultaneous_impact`, naming the contacts and the time;
- all contacts down, or the energy above the resting level exhausted down to
  `energy_floor` of its initial value, end it with `singularity` and `t_singularity`
  (extrapolated from the geometric sequence of the last impact intervals).

Time is kept as a double-double (t_hi + t_lo) and every phase is computed in its own
local time, so that intervals near the singularity keep all their digits.

Chatter (0 < γ < 1, docs/architecture.md): after an impact whose post-impact normal velocity u
is below `chatter_tol` times the body's velocity scale V while the contact point falls
back (normal acceleration a_n < 0), the remaining infinite sequence of impacts is
completed: u is removed by a normal impulse and the contact is held.  The exact sequence
accumulates at t + 2u / (|a_n| (1 − γ)) and delivers, to leading order, the same total
impulse as the completion (−m u + 2 m u / (1 − γ) = m u (1 + γ) / (1 − γ) per unit
effective mass), only spread over that window, so the completion changes the state at
the accumulation time by O((u / V)²) relative: (chatter_tol)² = 1e-12 for the default
1e-6.  Bounces lower than the gap's roundoff band (u < 4 √(2 |a_n| ε z)) cannot be
resolved one by one at all; completion always takes over there.
tests/test_reference_chatter.py measures it against a run that resolves the impacts one
by one down to that floor.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from reference.scene import Scene
from reference.trajectory import ImpactEvent, ImpactLog, Phase, Status, Trajectory

from . import quaternion as qt
from .body import BodyModel, Q, V, W, initial_state
from .contact import (
    chunk_horizon,
    constrained_acceleration,
    contact_forces,
    integrate_chunk,
    project_velocities,
    solve_contact_lcp,
)
from .events import gap_jet, next_flight_event
from .flight import flight_constants, free_flight
from .impact import apply_normal_impulses, impact_impulse


@dataclass(frozen=True)
class ReferenceOptions:
    sample_dt: float | None = None  # flight/contact sample spacing; default t_end / 2000
    chatter_tol: float = 1e-6  # complete chatter when u ≤ chatter_tol · V
    contact_rtol: float = 1e-12  # DOP853 tolerance in contact phases
    energy_floor: float = 1e-18  # singularity when excess energy ≤ floor · initial excess
    max_samples: int = 500_000


class SampleBuffer:
    """Accumulates samples of a run in growing arrays (doubling capacity), one row at a
    time from Python or a block at a time from the compiled loop, then freezes them into
    a Trajectory's arrays."""

    def __init__(self, capacity: int = 1024) -> None:
        self.n = 0
        self._t = np.empty((capacity, 2))  # t_hi, t_lo
        self._y = np.empty((capacity, 13))
        self._e = np.empty((capacity, 2))  # kinetic, potential

    def __len__(self) -> int:
        return self.n

    def _reserve(self, k: int) -> None:
        need = self.n + k
        if need <= len(self._t):
            return
        cap = max(need, 2 * len(self._t))
        for name in ("_t", "_y", "_e"):
            old = getattr(self, name)
            new = np.empty((cap, old.shape[1]))
            new[: self.n] = old[: self.n]
            setattr(self, name, new)

    def add(self, t_hi: float, t_lo: float, y: np.ndarray, ke: float, pe: float) -> None:
        self._reserve(1)
        i = self.n
        self._t[i] = (t_hi, t_lo)
        self._y[i] = y
        self._e[i] = (ke, pe)
        self.n = i + 1

    def extend(self, t: np.ndarray, y: np.ndarray, e: np.ndarray) -> None:
        """Append k rows: t (k, 2) = (t_hi, t_lo), y (k, 13) states, e (k, 2) = (KE, PE)."""
        k = len(t)
        self._reserve(k)
        self._t[self.n : self.n + k] = t
        self._y[self.n : self.n + k] = y
        self._e[self.n : self.n + k] = e
        self.n += k

    def arrays(self) -> dict[str, np.ndarray]:
        """Copies of the samples so far: t, t_lo, states (n, 13), kinetic and potential
        energy."""
        n = self.n
        return {
            "t": self._t[:n, 0].copy(),
            "t_lo": self._t[:n, 1].copy(),
            "states": self._y[:n].copy(),
            "kinetic_energy": self._e[:n, 0].copy(),
            "potential_energy": self._e[:n, 1].copy(),
        }


class _Clock:
    """Double-double time: hi + lo with |lo| ≤ ulp(hi)/2 (Knuth's two-sum)."""

    def __init__(self) -> None:
        self.hi, self.lo = 0.0, 0.0

    def add(self, s: float) -> None:
        hi = self.hi + s
        bb = hi - self.hi
        err = (self.hi - (hi - bb)) + (s - bb)
        lo = self.lo + err
        self.hi = hi + lo
        self.lo = lo - (self.hi - hi)

    def minus(self, other_hi: float, other_lo: float = 0.0) -> float:
        """self − other as a float, exact to the last bit of the difference."""
        return (self.hi - other_hi) + (self.lo - other_lo)


@dataclass
class _Run:
    model: BodyModel
    gamma: float
    t_end: float
    opts: ReferenceOptions
    clock: _Clock = field(default_factory=_Clock)
    buf: SampleBuffer = field(default_factory=SampleBuffer)
    impacts: ImpactLog = field(default_factory=ImpactLog)
    phases: list[Phase] = field(default_factory=list)
    stats: dict = field(default_factory=dict)
    max_impacts: int = 100_000
    # the accumulation time of a chatter whose completion laid the body down (the motion
    # ends there, not at the impact that began it); None otherwise
    laid_down_at: float | None = None

    def sample(self, y: np.ndarray, s: float = 0.0) -> None:
        """Record state y at local time s after the clock."""
        if len(self.buf) >= self.opts.max_samples:
            return
        c = _Clock()
        c.hi, c.lo = self.clock.hi, self.clock.lo
        if s:
            c.add(s)
        m = self.model
        self.buf.add(c.hi, c.lo, y, m.kinetic_energy(y), m.potential_energy(y))


def excess_energy(model: BodyModel, y: np.ndarray) -> float:
    """Energy above the lowest level the invariants allow (body flat on the ground):
    flat ground: E − ½ m |v_h|² − L_z² / (2 I3); three_point: E − ½ m |v_h|² − ½ I3 ω3²
    (ω3 is kept, and the flat body slides freely on the bumps); bumpy:
    E − ½ I3 ω3² − m g z_rest (z_rest: the centre lying flat on the bumps; ω3 is
    conserved once only the bumps push)."""
    E = model.energy(y)
    if model.n_rim and len(model.bumps):
        w3 = float(y[W] @ qt.body_axis(y[Q]))
        return E - 0.5 * model.i3 * w3 * w3 - model.mass * model.gravity * model.rest_height
    if model.flat:
        v = y[V]
        Lz = float(model.angular_momentum(y)[2])
        return E - 0.5 * model.mass * (v[0] ** 2 + v[1] ** 2) - Lz * Lz / (2 * model.i3)
    w3 = float(y[W] @ qt.body_axis(y[Q]))
    v = y[V]
    return E - 0.5 * model.mass * (v[0] ** 2 + v[1] ** 2) - 0.5 * model.i3 * w3 * w3


def simulate(
    scene: Scene, t_end: float | None = None, options: ReferenceOptions | None = None
) -> Trajectory:
    """Run the exact reference on `scene` until t_end (default scene.run.t_end)."""
    opts = options or ReferenceOptions()
    wall0 = time.perf_counter()
    model = BodyModel.from_scene(scene)
    t_end = float(t_end if t_end is not None else scene.run.t_end)
    run = _Run(model, scene.restitution, t_end, opts, max_impacts=scene.run.max_impacts)
    run.stats.update(
        flight_search_iterations=0,
        contact_chunks=0,
        contact_rhs_evals=0,
        chatter_completions=0,
        max_completion_u_rel=0.0,
        contact_energy_drift_max=0.0,
        max_penetration=0.0,
        lift_offs=0,
    )
    y = initial_state(scene)
    run.sample(y)
    try:
        status, message, t_sing = _loop(run, y, scene.run.max_impacts)
    except (RuntimeError, np.linalg.LinAlgError, FloatingPointError) as exc:
        status, message, t_sing = Status.FAILED, f"{exc} (at t = {run.clock.hi:.17g})", None
    arrays = run.buf.arrays()
    run.stats["wall_time_s"] = time.perf_counter() - wall0
    run.stats["n_impacts"] = len(run.impacts)
    n = len(run.impacts)
    run.stats["impacts_per_s"] = n / run.stats["wall_time_s"] if n else 0.0
    return Trajectory.from_states(
        "reference",
        scene.name,
        arrays["t"],
        arrays["states"],
        arrays["kinetic_energy"],
        arrays["potential_energy"],
        run.impacts,
        status,
        t_lo=arrays["t_lo"],
        phases=run.phases,
        message=message,
        t_final=run.clock.hi,
        t_singularity=t_sing,
        stats=run.stats,
    )


# ----------------------------------------------------------------------------- loop


def _loop(run: _Run, y: np.ndarray, max_impacts: int):
    model = run.model
    E0 = excess_energy(model, y)
    gap, _, _, vn, noise = model.contacts(y)
    vnoise = _rate_noise(model, y)
    touching = [k for k in range(model.n_contacts) if gap[k] <= noise[k]]
    hitting = [k for k in touching if vn[k] < -vnoise]
    resting = [k for k in touching if abs(vn[k]) <= vnoise]  # the rest are separating
    active: list[int] = []
    if hitting:
        out = _resolve(run, y, hitting, resting)
        if isinstance(out, tuple) and isinstance(out[0], Status):
            return out
        y, active = out
    elif resting:
        y = project_velocities(model, y, resting)
        active, _ = solve_contact_lcp(model, y, resting)

    while True:
        if len(run.impacts) >= max_impacts:
            return Status.MAX_IMPACTS, f"reached max_impacts = {max_impacts}", None
        if _all_down(model, active):
            t = run.clock.hi
            t_f = t if run.laid_down_at is None else run.laid_down_at
            return Status.SINGULARITY, f"all contacts down at t = {t:.17g}", t_f
        if E0 > 0 and abs(excess_energy(model, y)) <= run.opts.energy_floor * E0:
            t_f = _extrapolate_singularity(run)
            return (
                Status.SINGULARITY,
                f"energy exhausted to {run.opts.energy_floor:g} of its initial excess; "
                f"t_singularity extrapolated from the impact intervals",
                t_f,
            )
        remaining = run.clock.minus(run.t_end)
        remaining = -remaining
        if remaining <= 0:
            return Status.T_END, f"reached t_end = {run.t_end}", None
        if active:
            out = _contact_phase(run, y, active, remaining)
        else:
            out = _flight_phase(run, y, remaining)
        if out is None:
            return Status.T_END, f"reached t_end = {run.t_end}", None
        if isinstance(out[0], Status):
            return out
        y, active = out
        if not np.all(np.isfinite(y)):
            return Status.FAILED, f"non-finite state at t = {run.clock.hi}", None


def _rate_noise(model: BodyModel, y: np.ndarray) -> float:
    return 64 * np.finfo(float).eps * model.velocity_scale(y)


def _all_down(model: BodyModel, active: list[int]) -> bool:
    need = 2 if (model.flat and model.n_contacts == 2) else 3
    return len(active) >= need


def _extrapolate_singularity(run: _Run, max_period: int = 6, tol: float = 0.05) -> float:
    """t_f from the last impacts assuming geometric intervals with a period of m impacts
    (the smallest m ≤ max_period whose last two block ratios r agree to `tol` with
    r < 1): t_f = t_last + S r/(1 − r), S the last block's duration."""
    imp = run.impacts

    def span(i: int, j: int) -> float:
        return (imp[j].t - imp[i].t) + (imp[j].t_lo - imp[i].t_lo)

    last = len(imp) - 1
    for m in range(1, max_period + 1):
        if len(imp) < 3 * m + 1:
            break
        s1, s0, s_1 = (
            span(last - m, last),
            span(last - 2 * m, last - m),
            span(last - 3 * m, last - 2 * m),
        )
        if not (s0 > 0 and s_1 > 0 and s1 > 0):
            continue
        r, r_before = s1 / s0, s0 / s_1
        if r < 1 and abs(r - r_before) <= tol * r:
            return imp[last].t + (imp[last].t_lo + s1 * r / (1 - r))
    return run.clock.hi


# ----------------------------------------------------------------------------- phases


def _flight_phase(run: _Run, y: np.ndarray, remaining: float):
    model = run.model
    fc = flight_constants(model, y)
    ev = next_flight_event(model, fc, remaining)
    s_end = remaining if ev is None else ev.s
    _sample_grid(run, lambda s: free_flight(fc, s), s_end)
    t0 = run.clock.hi
    if ev is None:
        y = free_flight(fc, remaining)
        run.clock.add(remaining)
        run.sample(y)
        run.phases.append(Phase(t0, run.clock.hi, "flight"))
        return None
    run.stats["flight_search_iterations"] += ev.iterations
    run.clock.add(ev.s)
    run.phases.append(Phase(t0, run.clock.hi, "flight"))
    run.sample(ev.y)
    if ev.kind == "activation":
        return _activate(run, ev.y, list(ev.contacts), [])
    return _resolve(run, ev.y, list(ev.contacts), [])


def _sample_grid(run: _Run, state_at, s_end: float) -> None:
    dt = run.opts.sample_dt or run.t_end / 2000.0
    k0 = math.floor(run.clock.hi / dt) + 1
    while True:
        s = k0 * dt - run.clock.hi - run.clock.lo
        if s >= s_end:
            break
        if s > 0:
            run.sample(state_at(s), s)
        k0 += 1


# The oracle keeps the contact-phase algorithm in one piece, to be read against the paper.
def _contact_phase(run: _Run, y: np.ndarray, active: list[int], remaining: float):  # noqa: C901
    model = run.model
    t0 = run.clock.hi
    E_start = model.energy(y)
    lam_prev, h_prev = None, None
    s_done = 0.0
    # Gap resolution in a contact phase: roundoff, or the integrator's tolerance on the
    # positions (it resolves gaps only to ~rtol of the phase's length scale).
    gap_res = 16 * run.opts.contact_rtol * model.length_scale(y)
    while True:
        acc = constrained_acceleration(model, y, active)
        jet = gap_jet(model, y, acc)
        vnoise = _rate_noise(model, y)
        held = np.zeros(model.n_contacts, dtype=bool)
        held[active] = True
        touching = ~held & (jet.gap <= np.maximum(jet.noise, gap_res))
        hitting = np.flatnonzero(touching & (jet.rate < -vnoise)).tolist()
        if hitting:
            _close_contact_phase(run, t0, active, E_start, y)
            return _resolve(run, y, hitting, list(active))
        landing = np.flatnonzero(touching & (jet.rate <= vnoise) & (jet.accel < 0)).tolist()
        if landing:
            _close_contact_phase(run, t0, active, E_start, y)
            return _activate(run, y, landing, list(active))
        lam = contact_forces(model, y, active)
        h = chunk_horizon(model, y, jet, held)
        if lam_prev is not None and h_prev:
            rate = (lam - lam_prev) / h_prev
            for i in range(len(lam)):
                if rate[i] < 0 and lam[i] > 0:
                    h = min(h, 1.5 * lam[i] / -rate[i])
        h = min(h, remaining - s_done)
        if h <= 0:
            _close_contact_phase(run, t0, active, E_start, y)
            if remaining - s_done <= 0:
                return None
            # a zero chunk before t_end: some contact sits on the ground with no event
            # the model recognises; say so rather than end as if t_end were reached
            return (
                Status.FAILED,
                f"contact phase cannot advance at t = {run.clock.hi:.17g} "
                f"(chunk horizon {h:g} with contacts {active} held)",
                None,
            )
        y_new, sol, nfev = integrate_chunk(model, y, active, h, run.opts.contact_rtol, dense=True)
        run.stats["contact_chunks"] += 1
        run.stats["contact_rhs_evals"] += nfev
        lam_new = contact_forces(model, y_new, active)
        # penetration guard for the other contacts (must not happen: conservative horizon)
        below = np.flatnonzero(~held)
        gap_new, _, _, _, noise_new = model.contacts(y_new, below)
        crossed = below[gap_new < -np.maximum(noise_new, gap_res)].tolist()
        if crossed:
            # the horizon bound was not enough: find the first crossing on the dense
            # output and stop there (counted: the bound should make this rare)
            run.stats["horizon_backstops"] = run.stats.get("horizon_backstops", 0) + 1

            def min_gap(s, sol=sol, crossed=crossed):
                return float(np.min(model.contacts(sol(s), crossed)[0]))

            s_star = _first_zero(min_gap, h)
            y, _, nfev = integrate_chunk(model, y, active, s_star, run.opts.contact_rtol)
            _sample_grid(run, sol, s_star)
            run.clock.add(s_star)
            s_done += s_star
            lam_prev, h_prev = None, None
            continue
        if np.any(lam_new < 0):
            i = int(np.argmin(lam_new))

            def lam_i(s, i=i, sol=sol):
                return contact_forces(model, sol(s), active)[i]

            s_star = _first_zero(lam_i, h)
            if s_star > 0:
                y, _, nfev = integrate_chunk(model, y, active, s_star, run.opts.contact_rtol)
                run.stats["contact_rhs_evals"] += nfev
            _sample_grid(run, sol, s_star)
            run.clock.add(s_star)
            run.sample(y)
            run.stats["lift_offs"] += 1
            _close_contact_phase(run, t0, active, E_start, y)
            leaving = active[i]
            rest = [k for k in active if k != leaving]
            if rest:
                y = project_velocities(model, y, rest)
                rest, _ = solve_contact_lcp(model, y, rest)
            return y, rest
        _sample_grid(run, sol, h)
        run.clock.add(h)
        s_done += h
        y = y_new
        lam_prev, h_prev = lam_new, h
        if remaining - s_done <= 0:
            run.sample(y)
            _close_contact_phase(run, t0, active, E_start, y)
            return None


def _first_zero(f, h: float) -> float:
    """Root of f on [0, h] (brentq); 0 when f(0) ≤ 0 already (a force that is zero or
    pulling at the start of the chunk lifts off at once); h when the dense output has
    not crossed yet at h (the projected end state has: the crossing is within the
    interpolation error of the chunk end)."""
    if f(0.0) <= 0.0:
        return 0.0
    if f(h) >= 0.0:
        return h
    return brentq(f, 0.0, h, xtol=1e-15 * h, rtol=4 * np.finfo(float).eps)


def _close_contact_phase(run: _Run, t0, active, E_start, y) -> None:
    run.phases.append(Phase(t0, run.clock.hi, "contact", tuple(active)))
    E = run.model.energy(y)
    drift = abs(E - E_start) / max(abs(E_start), 1e-300)
    run.stats["contact_energy_drift_max"] = max(run.stats["contact_energy_drift_max"], drift)


# ----------------------------------------------------------------------------- impacts


def _activate(run: _Run, y: np.ndarray, landing: list[int], held: list[int]):
    """Contacts touching with no approach speed whose normal acceleration points into
    the ground start to be held (no impulse beyond zeroing roundoff-level velocities)."""
    candidates = sorted(set(held) | set(landing))
    y = apply_normal_impulses(run.model, y, candidates, np.zeros(len(candidates)))
    active, _ = solve_contact_lcp(run.model, y, candidates)
    run.stats["activations"] = run.stats.get("activations", 0) + 1
    if sorted(active) == sorted(held):
        # the LCP does not hold them (roundoff tie): hold them anyway, the force check
        # of the contact phase releases them if they pull
        active = candidates
    return y, active


def _resolve(run: _Run, y: np.ndarray, hitting: list[int], resting: list[int]):
    """Impact of `hitting` (one contact) while `resting` are held.  Returns (y, active)
    or a (Status, message, t_singularity) triple when the model cannot decide."""
    model = run.model
    t = run.clock.hi
    if len(hitting) > 1:
        return (
            Status.SIMULTANEOUS_IMPACT,
            f"contacts {hitting} hit simultaneously at t = {t:.17g}",
            None,
        )
    k = hitting[0]
    gap_k, _, lever_k, _, _ = model.contacts(y, [k])
    if model.is_bump(k) and float(np.linalg.norm(lever_k[0])) > model.radius:
        return (
            Status.LEFT_MODEL,
            f"bump contact {k} meets the face's plane outside the rim at t = {t:.17g}",
            None,
        )
    gap_k = float(gap_k[0])
    run.stats["max_penetration"] = max(run.stats["max_penetration"], -gap_k)
    res = impact_impulse(model, y, k, run.gamma, watch=list(resting))
    vnoise = _rate_noise(model, y)
    pushed = [j for j in resting if res.others_post[j] < -vnoise]
    if pushed:
        return (
            Status.SIMULTANEOUS_IMPACT,
            f"impact at contact {k} at t = {t:.17g} would push resting contact(s) "
            f"{pushed} into the ground (undecidable)",
            None,
        )
    run.impacts.append(
        ImpactEvent(
            t=t,
            t_lo=run.clock.lo,
            contact=k,
            impulse=res.impulse,
            v_normal_pre=res.u_pre,
            v_normal_post=res.u_post,
        )
    )
    y = res.y_post
    # Completion threshold: below it a separation speed is completed (γ < 1 only: an
    # elastic contact never accumulates impacts).
    # A bounce is resolvable only while its height u²/(2|a_n|) stays above the gap's
    # roundoff band: below u_floor = 100 √(2 |a_n| noise) (height 1e4 noise bands, event
    # times good to 1e-4 of a bounce) completion takes over.
    small = run.opts.chatter_tol * model.velocity_scale(y) if run.gamma < 1.0 else vnoise
    if run.gamma < 1.0:
        noise_k = float(model.contacts(y, [k])[4][0])
        a_scale = model.gravity + model.radius * float(y[W] @ y[W])
        small = max(small, 100.0 * math.sqrt(2.0 * a_scale * noise_k))
    small = max(small, vnoise)
    # resting contacts the impact leaves at rest or separating slower than `small`
    # (two-point chatter: the body rocks between two contacts with shrinking speeds)
    candidates = [j for j in resting if res.others_post[j] <= small]
    u = res.u_post
    t_acc = None  # accumulation time of a chatter completed here
    if u <= vnoise and run.gamma == 0.0:
        candidates.append(k)
    elif u <= small:
        # would k fall back?  normal acceleration with the other candidates held
        acc = constrained_acceleration(model, y, candidates)
        a_n = float(gap_jet(model, y, acc, [k]).accel[0])
        if a_n < 0 or u <= vnoise:
            run.stats["chatter_completions"] += 1
            rel = u / model.velocity_scale(y)
            run.stats["max_completion_u_rel"] = max(run.stats["max_completion_u_rel"], rel)
            t_acc = t + 2.0 * max(u, 0.0) / (max(-a_n, 1e-300) * (1.0 - run.gamma))
            run.stats.setdefault("chatter_accumulation_times", []).append(t_acc)
            candidates.append(k)
    for j in candidates:
        if j != k and res.others_post[j] > vnoise:
            rel = res.others_post[j] / model.velocity_scale(y)
            run.stats["max_completion_u_rel"] = max(run.stats["max_completion_u_rel"], rel)
    if candidates:
        y = apply_normal_impulses(model, y, candidates, np.zeros(len(candidates)))
        active, _ = solve_contact_lcp(model, y, candidates)
    else:
        active = []
    run.laid_down_at = t_acc if t_acc is not None and _all_down(model, active) else None
    run.sample(y)
    return y, active
