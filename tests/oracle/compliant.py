"""Oracle: the compliant impact law by numerical integration (scipy's DOP853 at tight
tolerance with event location), independent of the core's closed form
(reference.core.compliant).

Each touching contact is a linear spring kᵢ and dashpot cᵢ in parallel, no adhesion:
fᵢ = kᵢ dᵢ − cᵢ uᵢ while the contact pushes, 0 otherwise; ḋ = −u, Λ̇ = f, u = u⁻ + WΛ.
A pushing contact stops when its force reaches 0 (downwards), a free one starts when
its penetration and its force are both positive (min(dᵢ, fᵢ) crosses 0 upwards).  The
dashpot of contact i is cᵢ = 2ζ√(kᵢ/Wᵢᵢ) (kᵢ = k, or kᵢ ∝ 1/Wᵢᵢ) with ζ found here by
integrating the single oscillator d̈ + 2ζḋ + d = 0 from d = 0, ḋ = 1 until d + 2ζḋ = 0 and solving
−ḋ(t_e) = γ for ζ with brentq (no closed form).  γ in (0, 1]."""

from __future__ import annotations

import functools

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

RTOL = 1e-13


def single_restitution(zeta: float) -> float:
    """−ḋ(t_e)/ḋ(0) of d̈ + 2ζḋ + d = 0 from d = 0, ḋ = 1, t_e: d + 2ζḋ = 0 (downwards)."""

    def rhs(t, y):
        return [y[1], -2.0 * zeta * y[1] - y[0]]

    def release(t, y):
        return y[0] + 2.0 * zeta * y[1]

    release.terminal, release.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 100.0), [0.0, 1.0], method="DOP853", rtol=RTOL, atol=1e-16,
                    events=release)  # fmt: skip
    return float(-sol.y_events[0][0][1])


@functools.lru_cache(maxsize=64)
def damping_ratio(gamma: float) -> float:
    """ζ whose single contact leaves at −γ u⁻ (γ in (0, 1])."""
    if gamma >= 1.0:
        return 0.0
    hi = 1.0
    while single_restitution(hi) > gamma:
        hi *= 2.0
    return brentq(lambda z: single_restitution(z) - gamma, 0.0, hi, xtol=1e-15, rtol=1e-15)


def _rhs(t, y, W, u_pre, k_spring, c, a):
    """(ḋ, Λ̇) = (−u, f on the pushing contacts a)."""
    m = len(u_pre)
    u = u_pre + W @ y[m:]
    return np.concatenate([-u, np.where(a, k_spring * y[:m] - c * u, 0.0)])


def _events(W, u_pre, k_spring, c, active):
    m = len(u_pre)

    def force(y, i):
        u = u_pre[i] + W[i] @ y[m:]
        return k_spring[i] * y[i] - c[i] * u

    evs = []
    for i in range(m):
        if active[i]:
            ev = functools.partial(lambda t, y, i: force(y, i), i=i)
            ev.direction = -1
        else:
            ev = functools.partial(lambda t, y, i: min(y[i], force(y, i)), i=i)
            ev.direction = 1
        ev.terminal = True
        evs.append(ev)
    return evs


def compliant_impulses(W, u_pre, gamma: float, mass: bool = False, max_switches: int = 500):
    """(Λ, u⁺) of the compliant law on Delassus matrix W and normal velocities u⁻ (the
    outcome does not depend on the stiffness's scale: integrated in units of max Wᵢᵢ and
    max|u⁻ᵢ|, k = 1); `mass`: stiffness kᵢ = 1/Wᵢᵢ (in those units) instead of 1."""
    W0, u0 = np.asarray(W, dtype=float), np.asarray(u_pre, dtype=float)
    wmax, scale = float(np.diag(W0).max()), float(np.abs(u0).max())
    Ws = W0 / wmax
    k_spring = 1.0 / np.diag(Ws) if mass else np.ones(len(u0))
    lam = _scaled(Ws, u0 / scale, gamma, k_spring, max_switches) * scale / wmax
    return lam, u0 + W0 @ lam


def _scaled(W, u_pre, gamma, k_spring, max_switches):
    """Λ of the law for max Wᵢᵢ = 1, max|u⁻ᵢ| = 1."""
    m = len(u_pre)
    c = 2.0 * damping_ratio(gamma) * np.sqrt(k_spring / np.diag(W))
    active = u_pre < 0.0
    period = 2.0 * np.pi / np.sqrt((k_spring * np.diag(W)).min())
    y = np.zeros(2 * m)
    for _ in range(max_switches):
        u = u_pre + W @ y[m:]
        if not active.any() and (u >= -1e-12).all():
            return y[m:]

        rhs = functools.partial(_rhs, W=W, u_pre=u_pre, k_spring=k_spring, c=c, a=active.copy())

        sol = solve_ivp(rhs, (0.0, 1e3 * period), y, method="DOP853", rtol=RTOL,
                        atol=1e-16,
                        events=_events(W, u_pre, k_spring, c, active))  # fmt: skip
        y = sol.y[:, -1]
        hit = [i for i in range(m) if len(sol.t_events[i])]
        if not hit:
            raise RuntimeError("no switch within 1000 periods")
        first = min(hit, key=lambda i: sol.t_events[i][0])
        y = sol.y_events[first][0]
        active[first] = not active[first]
    raise RuntimeError("too many switches")
