"""Oracle: event location that never misses a root (docs/events.md).

Each contact's gap g(s) is smooth.  From its value, first and second derivative at the
current time and bounds on its second and third derivatives over the search horizon, two
polynomials bound it from below:

    P2(δ) = g + g′δ − K δ²/2          (K ≥ max |g″|)
    P3(δ) = g + g′δ + g″δ²/2 − B δ³/6  (B ≥ max |g‴|)

g stays positive until the first positive root of max(P2, P3), so advancing by that
root can never step over a contact (conservative advancement).  Near a transversal root
the step tends to g/|g′| (Newton from the safe side: quadratic convergence); near a
grazing minimum P3 lets the search pass it in a few steps.  A contact is reached when
g ≤ its roundoff level while approaching; its time is then polished by Newton steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import quaternion as qt
from .body import EPS, BodyModel, V, X, row_dot, state
from .flight import FlightConstants, flight_acceleration, free_flight


@dataclass(frozen=True)
class GapJet:
    """Gaps with first and second time derivatives and their roundoff levels."""

    gap: np.ndarray
    rate: np.ndarray
    accel: np.ndarray
    noise: np.ndarray
    rate_noise: np.ndarray


def gap_jet(model: BodyModel, y: np.ndarray, acc6: np.ndarray, idx=None) -> GapJet:
    """g, g′ = J u, g″ = J [v̇; ω̇] + bias for the contacts `idx` (every contact by
    default), at state y with accelerations acc6."""
    s = state(y)
    c = model.contact_arrays(s, idx)
    a = qt.components(acc6)
    accel = row_dot(c, a[:3], a[3:]) + c.bias
    vscale = model.velocity_scale(y)
    return GapJet(c.gap, c.vn, accel, c.noise, np.full_like(c.vn, 64 * EPS * vscale))


def first_root_lower_bound(g: float, g1: float, g2: float, K: float, B: float) -> float:
    """First positive root of max(P2, P3) (see module doc); inf if none; 0 if g ≤ 0."""
    return _raised_by_cubic(quadratic_root_lower_bound(g, g1, K), g, g1, g2, B)


def _raised_by_cubic(d2: float, g: float, g1: float, g2: float, B: float) -> float:
    """max(d2, P3's first positive root), d2 being P2's (0 if g ≤ 0)."""
    if g <= 0.0:
        return 0.0
    c2, c3 = 0.5 * g2, -B / 6.0
    if g + d2 * (g1 + d2 * (c2 + d2 * c3)) <= 0.0:
        return d2  # P3(0) > 0 ≥ P3(d2): P3's first root is at most d2
    return max(d2, _first_root_cubic(g, g1, c2, c3))


def quadratic_root_lower_bound(g: float, g1: float, K: float) -> float:
    """First positive root of P2(δ) = g + g1 δ − K δ²/2 (inf if none; 0 if g ≤ 0), in
    the cancellation-free branch for g1's sign: a lower bound on max(P2, P3)'s."""
    if g <= 0.0:
        return 0.0
    if K > 0.0:
        sq = math.sqrt(g1 * g1 + 2.0 * K * g)
        return (g1 + sq) / K if g1 >= 0.0 else 2.0 * g / (sq - g1)
    return g / -g1 if g1 < 0.0 else math.inf


def _first_root_cubic(c0: float, c1: float, c2: float, c3: float) -> float:
    """First positive root of c0 + c1 δ + c2 δ² + c3 δ³ with c0 > 0, c3 ≤ 0 (inf if none).

    The cubic's critical points split (0, ∞) into monotone pieces; the first piece whose
    end value is ≤ 0 holds the root, found by safeguarded bisection + Newton."""

    def p(d: float) -> float:
        return c0 + d * (c1 + d * (c2 + d * c3))

    def dp(d: float) -> float:
        return c1 + d * (2.0 * c2 + 3.0 * d * c3)

    # critical points: 3 c3 d² + 2 c2 d + c1 = 0
    crit: list[float] = []
    a, b, c = 3.0 * c3, 2.0 * c2, c1
    if a == 0.0:
        if b != 0.0:
            crit.append(-c / b)
    else:
        disc = b * b - 4 * a * c
        if disc >= 0:
            sq = math.sqrt(disc)
            qq = -0.5 * (b + math.copysign(sq, b))
            if qq != 0:
                crit.extend([qq / a, c / qq])
    crit = sorted(d for d in crit if d > 0)
    lo = 0.0
    ends = crit + [math.inf]
    for hi in ends:
        if hi == math.inf:
            if c3 < 0 or (c3 == 0 and (c2 < 0 or (c2 == 0 and c1 < 0))):
                # grows without bound downward: find a finite end
                hi = max(lo, 1.0)
                while p(hi) > 0:
                    hi *= 2.0
                    if hi > 1e300:
                        return math.inf
            else:
                return math.inf
        if p(hi) <= 0.0:
            return _bracketed_root(p, dp, lo, hi)
        lo = hi
    return math.inf


def _bracketed_root(p, dp, lo: float, hi: float, rel: float = 1e-3) -> float:
    """A point below the root of a monotone p on [lo, hi] with p(lo) > 0 ≥ p(hi), within
    `rel` of it: a safe step needs no more (near a real contact the quadratic bound
    already gives the Newton-like step).

    Newton steps from the last point, a bisection wherever a step leaves the bracket.
    Newton approaches the root from one side; once its step is below rel/4 of the point,
    a probe rel/4 across the root closes the bracket."""
    x, px = lo, p(lo)
    for _ in range(200):
        d = dp(x)
        nxt = x - px / d if d != 0.0 else math.nan
        if not lo < nxt < hi:
            nxt = 0.5 * (lo + hi)
        small = abs(nxt - x) <= 0.25 * rel * nxt
        x, px = nxt, p(nxt)
        lo, hi = (x, hi) if px > 0.0 else (lo, x)
        if small and hi - lo > rel * hi:
            probe = x * (1.0 + 0.25 * rel) if px > 0.0 else x * (1.0 - 0.25 * rel)
            if lo < probe < hi:
                lo, hi = (probe, hi) if p(probe) > 0.0 else (lo, probe)
        if hi - lo <= rel * hi:
            break
    return lo


# ------------------------------------------------------------------- derivative bounds


def flight_bounds(model: BodyModel, fc: FlightConstants, horizon: float) -> tuple[float, float]:
    """(K, B): bounds on |g″| and |g‴| of every contact gap over a flight of `horizon`.

    rim vertex:  g″ = −g + (ω̇×r + ω×(ω×r))_z,  |r| = a
           K = g + a(|ω|² + |ω̇|),  B = a(|ω̈| + 3|ω||ω̇| + |ω|³)
    bump: g = (x − b)·e3, e3 precessing at Ω about L:
           g″ = a·e3 + 2 v·ė3 + (x − b)·ë3,  g‴ = 3 a·ė3 + 3 v·ë3 + (x − b)·e3‴
           |ė3| ≤ Ω, |ë3| ≤ Ω², |e3‴| ≤ Ω³, |v| ≤ |v0| + g H, |x − b| ≤ D0 + |v0| H + g H²/2.
    On a ground with both kinds (bumpy), the larger of each.
    """
    K, B = 0.0, 0.0
    if model.n_rim:
        K, B = _rim_bounds(model, fc)
    if len(model.bumps):
        Kb, Bb = _bump_bounds(model, fc, horizon)
        K, B = max(K, Kb), max(B, Bb)
    return 1.0001 * K, 1.0001 * B


def _rim_bounds(model: BodyModel, fc: FlightConstants) -> tuple[float, float]:
    g = fc.gravity
    w, wd, wdd = fc.omega_abs, fc.wdot_bound, fc.wddot_bound
    a = model.radius
    return g + a * (w * w + wd), a * (wdd + 3 * w * wd + w**3)


def _bump_bounds(model: BodyModel, fc: FlightConstants, horizon: float) -> tuple[float, float]:
    g = fc.gravity
    y0 = fc.y0
    H = horizon if math.isfinite(horizon) else 1e300
    v0 = float(np.linalg.norm(y0[V]))
    V_ = v0 + g * H
    D = float(np.max(np.linalg.norm(y0[X][None, :] - model.bumps, axis=1))) + v0 * H
    D += 0.5 * g * H * H
    Om = fc.Omega
    return g + 2 * V_ * Om + D * Om * Om, 3 * g * Om + 3 * V_ * Om * Om + D * Om**3


# ------------------------------------------------------------------- flight search


@dataclass(frozen=True)
class FlightEvent:
    s: float  # time from the start of the flight
    contacts: tuple[int, ...]  # the contact(s) reached; more than one = simultaneous
    y: np.ndarray  # state at s (pre-impact)
    iterations: int
    kind: str = "impact"  # or "activation": touching at rest and pressing in (no impact)


def next_flight_event(
    model: BodyModel,
    fc: FlightConstants,
    horizon: float,
    max_iter: int = 100_000,
) -> FlightEvent | None:
    """First contact reached (approaching) within `horizon` of free flight, or None.

    Contacts currently touching but separating (g ≈ 0, g′ > 0, just after an impact)
    are not events; the lower bounds carry the search past them."""
    K, B = flight_bounds(model, fc, horizon)
    s = 0.0
    y = fc.y0
    for it in range(max_iter):
        jet = gap_jet(model, y, flight_acceleration(fc, y))
        touching = jet.gap <= jet.noise
        # A double root (graze) cannot be told from a hit slower than the speed a convex
        # gap reaches inside its roundoff band, √(2 g″ noise): such a touch is a graze.
        graze_speed = np.sqrt(2.0 * np.maximum(jet.accel, 0.0) * jet.noise) * 4.0
        hit = np.flatnonzero(touching & (jet.rate < -np.maximum(jet.rate_noise, graze_speed)))
        if hit.size:
            return _polish(model, fc, s, jet, hit, horizon, it)
        landing = np.flatnonzero(touching & (jet.rate <= jet.rate_noise) & (jet.accel < 0))
        if landing.size:
            return FlightEvent(s, tuple(int(k) for k in landing), y, it, kind="activation")
        step = _safe_step(jet, K, B)
        # a contact resting with g′≈0 and g″≈0 would stall: leave at roundoff pace
        step = max(step, 1e-15 * max(s, 1e-300))
        if s + step >= horizon:
            return None
        s += step
        y = free_flight(fc, s)
    raise RuntimeError("event search did not converge (max_iter)")


def _safe_step(jet: GapJet, K: float, B: float) -> float:
    """The smallest first_root_lower_bound over the contacts.  They are visited in the
    order of their quadratic roots, which bound it from below: once one is at least the
    smallest step found, no later contact can lower it."""
    # touching and not approaching: bound from the positive-rate side
    gaps = np.where(jet.gap <= jet.noise, np.maximum(jet.gap, 0.0) + jet.noise, jet.gap)
    # the scalar root finding on Python floats (numpy's scalars are slow; same doubles)
    gaps, rate, accel = gaps.tolist(), jet.rate.tolist(), jet.accel.tolist()
    lower = [quadratic_root_lower_bound(g, r, K) for g, r in zip(gaps, rate, strict=True)]
    step = math.inf
    for k in sorted(range(len(lower)), key=lower.__getitem__):
        if lower[k] >= step:
            break
        step = min(step, _raised_by_cubic(lower[k], gaps[k], rate[k], accel[k], B))
    return step


def _polish(model, fc, s, jet: GapJet, hit: np.ndarray, horizon: float, it: int) -> FlightEvent:
    """Newton-polish the earliest reached contact and collect simultaneous ones."""
    # time to reach zero for each reached contact (≤ a few ulps of the gap)
    ds = {int(k): -jet.gap[k] / jet.rate[k] for k in hit}
    k0 = min(ds, key=ds.get)
    s_hit = s + ds[k0]
    y = free_flight(fc, s_hit)
    for _ in range(3):
        j2 = gap_jet(model, y, flight_acceleration(fc, y))
        corr = -j2.gap[k0] / j2.rate[k0]
        if abs(corr) <= 1e-16 * max(abs(s_hit), 1e-300) or not math.isfinite(corr):
            break
        s_hit += corr
        y = free_flight(fc, s_hit)
    j2 = gap_jet(model, y, flight_acceleration(fc, y))
    # simultaneous: another approaching contact whose zero is within the time resolution
    t_res = lambda k: (j2.noise[k] + 1e-300) / max(-j2.rate[k], 1e-300)  # noqa: E731
    together = [k0]
    for k in range(len(j2.gap)):
        if k == k0 or j2.rate[k] >= -j2.rate_noise[k]:
            continue
        if j2.gap[k] / -j2.rate[k] <= 4.0 * (t_res(k) + t_res(k0)):
            together.append(k)
    return FlightEvent(s=s_hit, contacts=tuple(sorted(together)), y=y, iterations=it)
