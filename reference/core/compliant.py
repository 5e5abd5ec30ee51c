"""The compliant impact law: the rigid limit of a linear spring and dashpot at every
touching contact (docs/laws.md).

Model.  During the impact the configuration is frozen and gravity is negligible; each
touching contact i has a penetration dᵢ (ḋᵢ = −uᵢ, dᵢ = 0 at the start) and pushes
with the force

    fᵢ = max(0, k dᵢ − cᵢ uᵢ)   while dᵢ > 0 (or dᵢ = 0 and uᵢ < 0), else 0,

no adhesion; the normal velocities move as u̇ = W f (W = J M⁻¹ Jᵀ, the Delassus matrix
of the laws in reference.core.impact_laws) and the impulses as Λ̇ = f, so that
u = u⁻ + WΛ at every instant.  The impact ends when no contact pushes and none
approaches (every uᵢ ≥ 0: then no dᵢ grows again and no force can reappear).

Stiffness and damping.  The same k at every contact.  Contact i alone (effective mass
1/Wᵢᵢ) is the damped oscillator d̈ + 2ζωd + ω²d = 0, ω² = kWᵢᵢ, cᵢ = 2ζ√(k/Wᵢᵢ).
Starting from d = 0, ḋ = v₀ > 0 it leaves force-wise when k d − c u = 0, i.e.
d + (2ζ/ω) ḋ = 0, before d returns to 0.  With ζ = cos α (ζ < 1) the motion is
d ∝ e^(−ζωt) sin(ω√(1−ζ²) t) and the force vanishes at ω√(1−ζ²) t_e = 2α, where
ḋ = −ωd/(2ζ), hence its restitution (eq. F: u⁺ = −e u⁻)

    e(ζ) = exp(−2ζ acos ζ / √(1 − ζ²))      (ζ < 1),
    e(ζ) = exp(−2ζ acosh ζ / √(ζ² − 1))     (ζ > 1),   e(1) = e⁻²,

decreasing from e(0) = 1 (undamped) to e → 1/(4ζ²) → 0.  `damping_ratio` inverts it
by bisection to adjacent floats; every contact gets the ζ of the scene's γ, so that
contact i alone leaves with u⁺ = −γu⁻.  γ = 0 is the limit ζ → ∞: on the time scale
of the dashpots the springs vanish, fᵢ = cᵢ max(−uᵢ, 0), cᵢ ∝ 1/√Wᵢᵢ, and the motion
of a pushing set decays to rest (`plastic`).

The outcome does not depend on k (time scales as 1/√k).  In the units used here
(W̃ = W / max Wᵢᵢ, u in units of max|u⁻|, Λ̃ = Λ max Wᵢᵢ / max|u⁻|, time in
1/√(k max Wᵢᵢ)) the force is f̃ᵢ = κᵢ dᵢ − c̃ᵢ ũᵢ with κᵢ = 1, c̃ᵢ = 2ζ/√W̃ᵢᵢ (κᵢ = 0,
c̃ᵢ = 1/√W̃ᵢᵢ for γ = 0).

Stiffness in the effective mass (`compliant_mass_impulses`, the law `compliant-mass`):
kᵢ = k max Wᵢᵢ / Wᵢᵢ, so that every contact alone oscillates at one frequency, the way
per-constraint impedances scale (MuJoCo's solref time constant, Drake's SAP
regularisation); κᵢ = 1/W̃ᵢᵢ, c̃ᵢ = 2ζ/W̃ᵢᵢ (γ = 0: κᵢ = 0, c̃ᵢ = 1/W̃ᵢᵢ).

Exact per pushing set.  With a fixed set A of pushing contacts, z = (d, Λ̃, 1) obeys
the linear system ż = B_A z with constant coefficients: ḋ = −ũ⁻ − W̃Λ̃, Λ̃ᵢ' = f̃ᵢ
(i ∈ A), 0 otherwise.  It is stepped with the exact propagator exp(B_A h), its Taylor
series to roundoff (‖B_A h‖∞ ≤ STEP_NORM); at each step's end the switch conditions
are tested: a pushing contact whose force is negative, a free one with dᵢ > 0 and
f̃ᵢ > 0; the first switch is located to adjacent floats by bisection on the exact
solution z(τ) = exp(B_A τ) z, the set changes there and stepping goes on.  With no
contact pushing the flight is free (ũ constant) and the next contact to touch
(dᵢ = 0, ũᵢ < 0) is found in closed form.  A release happens where fᵢ = 0, so u̇ and
Λ̇ are continuous there: the outcome is insensitive to roundoff in that instant.

Functions of plain arrays, allocation-free: the caller passes `work`
(`work_size(k)` floats) and `active` (k integers)."""

import math

from .jit import FALSE, TRUE, hot

SETTLED = 0
NOT_SETTLED = 1
SINGULAR = 2
TOO_MANY = 3
MAX_COMPLIANT_CONTACTS = 64

# ‖B h‖∞ of a step: the Taylor series of exp(Bτ), τ ≤ h, has converged to roundoff
# after TAYLOR_TERMS terms (0.5²⁴/24! ≈ 1e-31)
STEP_NORM = 0.5
TAYLOR_TERMS = 24
# velocities within this many ulps of max|u⁻| count as zero (roundoff of u⁻ + WΛ)
REST_ULPS = 256.0
EPS = 2.220446049250313e-16
# caps: switches of the pushing set, and steps (a γ = 0 decay, a near-singular W)
MAX_SWITCHES_PER_CONTACT = 64
MAX_STEPS = 4_000_000


@hot
def restitution_of_damping(zeta):
    """e(ζ) of one contact (module docstring): exp(−2ζ acos ζ/√(1−ζ²)), its
    continuation exp(−2ζ acosh ζ/√(ζ²−1)) above 1, e⁻² at ζ = 1."""
    if zeta == 1.0:
        return math.exp(-2.0)
    if zeta < 1.0:
        return math.exp(-2.0 * zeta * math.acos(zeta) / math.sqrt((1.0 - zeta) * (1.0 + zeta)))
    return math.exp(-2.0 * zeta * math.acosh(zeta) / math.sqrt((zeta - 1.0) * (zeta + 1.0)))


@hot
def damping_ratio(gamma):
    """ζ with restitution_of_damping(ζ) = γ, by bisection to adjacent floats (e is
    decreasing); 0 for γ ≥ 1, inf for γ ≤ 0."""
    if gamma >= 1.0:
        return 0.0
    if gamma <= 0.0:
        return math.inf
    lo, hi = 0.0, 1.0
    while restitution_of_damping(hi) > gamma:
        lo, hi = hi, 2.0 * hi
    for _ in range(2000):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if restitution_of_damping(mid) > gamma:
            lo = mid
        else:
            hi = mid
    return (
        hi
        if abs(restitution_of_damping(hi) - gamma) <= abs(restitution_of_damping(lo) - gamma)
        else lo
    )


def work_size(k):
    """Floats of scratch `compliant_impulses` needs for k contacts."""
    n = 2 * k + 1
    return 4 * n * n + 5 * n + 2 * k


@hot
def _force(W, u_pre, wbar, ubar, spring, damp, z, k, i):
    """f̃ᵢ = κᵢ dᵢ − c̃ᵢ ũᵢ at state z (scaled units)."""
    return spring[i] * z[i] - damp[i] * _velocity(W, u_pre, wbar, ubar, z, k, i)


@hot
def _velocity(W, u_pre, wbar, ubar, z, k, i):
    """ũᵢ = ũ⁻ᵢ + (W̃Λ̃)ᵢ at state z."""
    s = u_pre[i] / ubar
    for j in range(k):
        s += W[i, j] / wbar * z[k + j]
    return s


@hot
def _build(W, u_pre, wbar, ubar, spring, damp, active, k, B):
    """B_A (n × n, row-major in B, n = 2k + 1) of the pushing set `active`; returns
    ‖B_A‖∞ over its linear block."""
    n = 2 * k + 1
    for p in range(n * n):
        B[p] = 0.0
    norm = 0.0
    for i in range(k):
        row = 0.0
        for j in range(k):
            B[i * n + k + j] = -W[i, j] / wbar
            row += abs(W[i, j]) / wbar
        B[i * n + 2 * k] = -u_pre[i] / ubar
        norm = max(norm, row)
        if active[i]:
            r = (k + i) * n
            B[r + i] = spring[i]
            for j in range(k):
                B[r + k + j] = -damp[i] * W[i, j] / wbar
            B[r + 2 * k] = -damp[i] * u_pre[i] / ubar
            norm = max(norm, spring[i] + damp[i] * row)
    return norm


@hot
def _matvec(M, x, n, out):
    """out = M x (M row-major n × n)."""
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += M[i * n + j] * x[j]
        out[i] = s


@hot
def _propagate(B, tau, z, n, out, term, tmp):
    """out = exp(Bτ) z by its Taylor series (‖Bτ‖∞ ≤ STEP_NORM)."""
    for i in range(n):
        term[i] = z[i]
        out[i] = z[i]
    for j in range(1, TAYLOR_TERMS + 1):
        _matvec(B, term, n, tmp)
        f = tau / j
        for i in range(n):
            term[i] = tmp[i] * f
            out[i] += term[i]


@hot
def _propagator(B, h, n, P, T, S):
    """P = exp(Bh) by its Taylor series (T, S: n × n scratch)."""
    for p in range(n * n):
        P[p] = 0.0
        T[p] = 0.0
    for i in range(n):
        P[i * n + i] = 1.0
        T[i * n + i] = 1.0
    for j in range(1, TAYLOR_TERMS + 1):
        f = h / j
        for i in range(n):
            for c in range(n):
                s = 0.0
                for q in range(n):
                    s += B[i * n + q] * T[q * n + c]
                S[i * n + c] = s * f
        for p in range(n * n):
            T[p] = S[p]
            P[p] += S[p]


@hot
def _switches(W, u_pre, wbar, ubar, spring, damp, active, z, k, i):
    """Whether contact i's pushing state at z differs from `active`: a pushing contact
    whose force is below −its roundoff, a free one with dᵢ > 0 and a force above it
    (the roundoff band keeps a contact that hovers at zero force from switching on
    noise)."""
    f = _force(W, u_pre, wbar, ubar, spring, damp, z, k, i)
    tol = REST_ULPS * EPS * (spring[i] + damp[i])
    if active[i]:
        return f < -tol
    return z[i] > 0.0 and f > tol


@hot
def _switch_time(W, u_pre, wbar, ubar, spring, damp, active, B, z, h, k, i, zt, term, tmp):
    """The first τ in (0, h] at which contact i switches (it does at h), to adjacent
    floats by bisection on z(τ) = exp(Bτ) z."""
    n = 2 * k + 1
    lo, hi = 0.0, h
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        _propagate(B, mid, z, n, zt, term, tmp)
        if _switches(W, u_pre, wbar, ubar, spring, damp, active, zt, k, i):
            hi = mid
        else:
            lo = mid
    return hi


@hot
def _free_flight(W, u_pre, wbar, ubar, z, k, tol):
    """With no contact pushing (ũ constant): the contact that touches first (dᵢ
    reaches 0 with ũᵢ < −tol), z advanced to that instant; −1 if none approaches."""
    first, t_min = -1, math.inf
    for i in range(k):
        u = _velocity(W, u_pre, wbar, ubar, z, k, i)
        if u < -tol:
            t = max(z[i] / u, 0.0)
            if t < t_min:
                first, t_min = i, t
    if first >= 0:
        for i in range(k):
            z[i] -= _velocity(W, u_pre, wbar, ubar, z, k, i) * t_min
        z[first] = 0.0
    return first


@hot
def _resting(W, u_pre, wbar, ubar, active, z, k, tol):
    """γ = 0 (κ = 0): whether every pushing contact has come to rest (|ũᵢ| ≤ tol): its
    force −c̃ᵢũᵢ is then roundoff, and it is released."""
    for i in range(k):
        if active[i] and abs(_velocity(W, u_pre, wbar, ubar, z, k, i)) > tol:
            return False
    for i in range(k):
        active[i] = 0
    return True


@hot
def _scales(W, u_pre, k):
    """(max Wᵢᵢ, max|u⁻ᵢ|, min Wᵢᵢ)."""
    wbar, ubar, wmin = 0.0, 0.0, math.inf
    for i in range(k):
        wbar = max(wbar, W[i, i])
        wmin = min(wmin, W[i, i])
        ubar = max(ubar, abs(u_pre[i]))
    return wbar, ubar, wmin


@hot
def _setup(W, u_pre, gamma, k, wbar, z, spring, damp, active, mass_scaled):
    """The start: d = 0, Λ̃ = 0, the springs κᵢ and dampers c̃ᵢ (module docstring;
    `mass_scaled`: kᵢ ∝ 1/Wᵢᵢ), the contacts approaching pushing."""
    zeta = damping_ratio(gamma)
    for i in range(k):
        s = math.sqrt(W[i, i] / wbar)
        scale = s * s if mass_scaled else s  # √(kᵢ/Wᵢᵢ) ∝ 1/scale
        spring[i] = 0.0 if gamma <= 0.0 else (1.0 / (s * s) if mass_scaled else 1.0)
        damp[i] = 1.0 / scale if gamma <= 0.0 else 2.0 * zeta / scale
        z[i] = 0.0
        z[k + i] = 0.0
        active[i] = 1 if u_pre[i] < 0.0 else 0
    z[2 * k] = 1.0


@hot
def _first_switch(W, u_pre, wbar, ubar, spring, damp, active, B, z, z1, h, k, zt, term, tmp):
    """The contact that switches first within the step z → z1 (−1: none) and when."""
    first, t_first = -1, math.inf
    for i in range(k):
        if _switches(W, u_pre, wbar, ubar, spring, damp, active, z1, k, i):
            t = _switch_time(W, u_pre, wbar, ubar, spring, damp, active, B, z, h, k, i,
                             zt, term, tmp)  # fmt: skip
            if t < t_first:
                first, t_first = i, t
    return first, t_first


@hot
def _any_active(active, k):
    for i in range(k):
        if active[i]:
            return True
    return False


@hot
def compliant_impulses(W, u_pre, gamma, k, lam, u_post, work, active):
    """The compliant law over k touching contacts, the same stiffness at every contact
    (module docstring): impulses lam[:k] and u_post[:k] = u⁻ + WΛ.  Returns SETTLED,
    NOT_SETTLED (a cap reached: Λ is the state there), SINGULAR (a Wᵢᵢ ≤ 0) or
    TOO_MANY."""
    return _impulses(W, u_pre, gamma, k, lam, u_post, work, active, FALSE)


@hot
def compliant_mass_impulses(W, u_pre, gamma, k, lam, u_post, work, active):
    """`compliant_impulses` with each contact's stiffness in its effective mass, kᵢ ∝
    1/Wᵢᵢ (every contact alone oscillates at one frequency)."""
    return _impulses(W, u_pre, gamma, k, lam, u_post, work, active, TRUE)


@hot
def _impulses(W, u_pre, gamma, k, lam, u_post, work, active, mass_scaled):
    if k > MAX_COMPLIANT_CONTACTS:
        return TOO_MANY
    for i in range(k):
        if not W[i, i] > 0.0:
            return SINGULAR
        lam[i] = 0.0
    wbar, ubar, _ = _scales(W, u_pre, k)
    status = SETTLED
    if ubar > 0.0:
        status = _run(W, u_pre, gamma, k, wbar, ubar, work, active, mass_scaled)
        for i in range(k):
            lam[i] = work[4 * (2 * k + 1) ** 2 + k + i] * ubar / wbar
    for i in range(k):
        s = u_pre[i]
        for j in range(k):
            s += W[i, j] * lam[j]
        u_post[i] = s
    return status


@hot
def _run(W, u_pre, gamma, k, wbar, ubar, work, active, mass_scaled):
    """The impact in scaled units; the state z ends in work (see compliant_impulses)."""
    n = 2 * k + 1
    B, P, T, S = (
        work[: n * n],
        work[n * n : 2 * n * n],
        work[2 * n * n : 3 * n * n],
        work[3 * n * n : 4 * n * n],
    )
    o = 4 * n * n
    z, z1, zt, term, tmp = (
        work[o : o + n],
        work[o + n : o + 2 * n],
        work[o + 2 * n : o + 3 * n],
        work[o + 3 * n : o + 4 * n],
        work[o + 4 * n : o + 5 * n],
    )
    damp = work[o + 5 * n : o + 5 * n + k]
    spring = work[o + 5 * n + k : o + 5 * n + 2 * k]
    _setup(W, u_pre, gamma, k, wbar, z, spring, damp, active, mass_scaled)
    tol = REST_ULPS * EPS
    stale, h, switches = True, 0.0, 0
    for _ in range(MAX_STEPS):
        if gamma <= 0.0 and _any_active(active, k):
            _resting(W, u_pre, wbar, ubar, active, z, k, tol)
        if not _any_active(active, k):
            i = _free_flight(W, u_pre, wbar, ubar, z, k, tol)
            if i < 0:
                return SETTLED
            active[i] = 1
            stale = True
        if stale:
            h = STEP_NORM / _build(W, u_pre, wbar, ubar, spring, damp, active, k, B)
            _propagator(B, h, n, P, T, S)
            stale = False
        _matvec(P, z, n, z1)
        i, t = _first_switch(W, u_pre, wbar, ubar, spring, damp, active, B, z, z1, h, k,
                             zt, term, tmp)  # fmt: skip
        if i < 0:
            for p in range(n):
                z[p] = z1[p]
            continue
        _propagate(B, t, z, n, zt, term, tmp)
        for p in range(n):
            z[p] = zt[p]
        active[i] = 1 - active[i]
        stale = True
        switches += 1
        if switches > MAX_SWITCHES_PER_CONTACT * k + 64:
            return NOT_SETTLED
    return NOT_SETTLED


@hot
def compliant_law(W, u_pre, gamma, k, lam, u_post, work):
    """`compliant_impulses` in the registry's signature (reference.core.laws): one
    impact (work.vec: work_size(k) floats)."""
    return compliant_impulses(W, u_pre, gamma, k, lam, u_post, work.vec, work.active), 1


@hot
def compliant_mass_law(W, u_pre, gamma, k, lam, u_post, work):
    """`compliant_mass_impulses` in the registry's signature (reference.core.laws)."""
    status = compliant_mass_impulses(W, u_pre, gamma, k, lam, u_post, work.vec, work.active)
    return status, 1
