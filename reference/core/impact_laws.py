"""Impact laws for several touching contacts at once (paper §2.3 generalised).

Plain functions of plain data: the k touching contacts enter only through their
Delassus matrix W = J M⁻¹ Jᵀ (k × k, symmetric positive semi-definite: an impulse
vector Λ ≥ 0 along the normals changes the normal velocities by WΛ) and their normal
velocities u⁻ before the impact.  They return the impulses Λ and u⁺ = u⁻ + WΛ; the
caller applies (v, ω) += M⁻¹JᵀΛ.  They allocate nothing: the caller passes the scratch
(`W`, `chol` at least k × k; `lam`, `u_post`, `vec` at least k long, `vec` 2k; `active`
k integers).

Laws (registered in reference.core.laws, which names them and gives their codes):

- `paper`: the paper's rule: one single impact (eq. F) at a time; two contacts reached
  together, or a single impact that pushes a held contact, is undecidable (the run
  ends `simultaneous_impact`).  Not a function here: the core's events do it.
- `moreau` (`moreau_impulses`): Newton's law generalised by Moreau, frictionless:
  0 ≤ Λᵢ ⊥ u⁺ᵢ + γ·min(u⁻ᵢ, 0) ≥ 0 for every touching contact i.  With q = u⁻ +
  γ min(u⁻, 0) this is the LCP w = q + WΛ ≥ 0, Λ ≥ 0, Λᵀw = 0: the optimality
  conditions of the convex problem min ½ΛᵀWΛ + qᵀΛ over Λ ≥ 0.  Solvable whenever no
  non-zero Λ ≥ 0 has JᵀΛ = 0, which holds here (all normals are the same vector, e_z
  or e3, so JᵀΛ has force ΣΛᵢ n).  u⁺ is unique: W = G Gᵀ (G = J M^-½), the objective
  is ½|GᵀΛ|² + qᵀΛ, constant on the convex set of minimisers, so GᵀΛ and WΛ are the
  same for every solution.  Λ is unique only when W is definite; with more than three
  contacts on the flat face (W of rank 3) we choose the **least-norm impulses**: the
  limit of the Tikhonov-regularised problem W + εI as ε → 0.  The active set A comes
  from Murty's least-index principal pivoting on W + εI (finite for a positive
  definite matrix), then Λ_A is the minimum-norm solution of W_AA Λ_A = −q_A by
  iterated Tikhonov from 0 (`_refine`: exact along W's range, ~1e-12 relative along
  its null space).  With one
  contact the law is eq. F exactly (`single_impulse`).  Across the impact
  ΔT = ½Λᵀ(u⁻ + u⁺) = ½ Σ Λᵢ(1 − γ) u⁻ᵢ ≤ 0 when every touching contact approaches or
  rests.
- `sequential` (`sequential_impulses`): single impacts (eq. F, u⁺ᵢ = −γ u⁻ᵢ with the
  current uᵢ) one contact at a time until no touching contact approaches faster than
  SETTLE_REL × max|u⁻|.  Order: the fastest approaching first (`order` empty), or
  sweeps over a given order (each contact of the order that approaches is hit, in
  turn: the orders of `harness branches`).  At most MAX_SEQUENTIAL_IMPACTS single
  impacts; beyond, status NOT_SETTLED.
- `compliant` (reference.core.compliant.compliant_impulses): the rigid limit of a
  linear spring and dashpot at every touching contact, the same stiffness everywhere
  and each dashpot set so that its contact alone obeys eq. F; solved exactly per set
  of pushing contacts.  It needs `vec` of reference.core.compliant.work_size(k).
- `compliant-mass` (compliant_mass_impulses): the same with each contact's stiffness in
  its effective mass, kᵢ ∝ 1/Wᵢᵢ.

No energetic law (Darboux–Keller, Stronge, LZB): see docs/laws.md, "The
laws" (not exact in closed form: an ODE in the impulse with switching, and LZB needs
contact stiffness ratios the rigid model has no value for).
"""

import math

from .impact import post_impact_velocity
from .jit import hot

# Outcomes of a law's solve
SETTLED = 0
NOT_SETTLED = 1  # sequential: MAX_SEQUENTIAL_IMPACTS reached; moreau: pivot cap
SINGULAR = 2  # a contact whose W_ii is not positive (no impulse can move it)
TOO_MANY = 3  # more than MAX_LAW_CONTACTS contacts

# Tikhonov weight ε = REGULARISATION × max Wᵢᵢ: the regularised matrix has condition
# ≤ 1e8, so its solve is good to ~1e-8 relative along W's near-null directions (the
# impulses' non-unique part) and the refinement makes u⁺ exact to roundoff.
REGULARISATION = 1e-8
# the refinement's regularisation, and its cap on passes (near-singular definite W, e.g.
# two adjacent vertices of a 1000-gon, λ ≈ 4e-5 max Wᵢᵢ, converge by ~0.7 per pass)
REFINE_REGULARISATION = 1e-4
MAX_REFINE_PASSES = 400
# the laws take at most this many contacts (Moreau's pivoting costs O(k⁴) at worst): a
# larger polygon landing flat ends the run undecidable, saying so
MAX_LAW_CONTACTS = 64
# complementarity tolerance of the pivoting, relative to the largest |qᵢ| (roundoff)
PIVOT_TOL = 64.0 * 2.220446049250313e-16
# the sequential law has settled when no contact approaches faster than this × max|u⁻|:
# below the loop's velocity roundoff (RATE_NOISE_ULPS ε V, V ≥ |u|), so that the loop
# takes what is left for rest, not for a new impact an instant later
SETTLE_REL = 16.0 * 2.220446049250313e-16
MAX_SEQUENTIAL_IMPACTS = 100_000


@hot
def moreau_target(u_pre, gamma):
    """qᵢ = u⁻ᵢ + γ·min(u⁻ᵢ, 0): Moreau's law asks u⁺ᵢ ≥ −γ·min(u⁻ᵢ, 0), i.e. w = u⁺ + γ
    min(u⁻, 0) ≥ 0, and w = q + WΛ."""
    return u_pre + gamma * min(u_pre, 0.0)


@hot
def single_impulse(u_pre, w, gamma):
    """The impulse of one contact, eq. F: ζ = (u⁺ − u⁻)/w with u⁺ = −γu⁻ (a contact that
    does not approach takes none)."""
    if u_pre >= 0.0:
        return 0.0
    return (post_impact_velocity(u_pre, gamma) - u_pre) / w


@hot
def post_velocities(W, u_pre, lam, k, u_post):
    """u⁺ = u⁻ + WΛ."""
    for i in range(k):
        s = u_pre[i]
        for j in range(k):
            s += W[i, j] * lam[j]
        u_post[i] = s


@hot
def energy_change(u_pre, u_post, lam, k):
    """ΔT = ½Λᵀ(u⁻ + u⁺): the kinetic energy an impulse Λ adds (≤ 0 for the laws here)."""
    s = 0.0
    for i in range(k):
        s += lam[i] * (u_pre[i] + u_post[i])
    return 0.5 * s


@hot
def _cholesky_solve(W, eps, active, k, chol, rhs, out):
    """out[A] = (W_AA + εI)⁻¹ rhs[A] over the contacts with active[i] = 1 (Cholesky;
    positive definite for ε > 0); out is 0 elsewhere.  Returns False if a pivot is not
    positive (roundoff beyond ε)."""
    m = _cholesky(W, eps, active, k, chol)
    if m < 0:
        return False
    _solve_factored(active, k, chol, m, rhs, out)
    return True


@hot
def _solve_factored(active, k, chol, m, rhs, out):
    """out[A] = (L Lᵀ)⁻¹ rhs[A] with L = chol[:m, :m] (`_cholesky`); 0 elsewhere."""
    for i in range(k):
        out[i] = 0.0
    r = 0  # forward: L y = rhs_A (y kept in out at the active positions)
    for i in range(k):
        if active[i]:
            s = rhs[i]
            c = 0
            for j in range(i):
                if active[j]:
                    s -= chol[r, c] * out[j]
                    c += 1
            out[i] = s / chol[r, r]
            r += 1
    r = m - 1  # backward: Lᵀ x = y
    for i in range(k - 1, -1, -1):
        if active[i]:
            s = out[i]
            c = m - 1
            for j in range(k - 1, i, -1):
                if active[j]:
                    s -= chol[c, r] * out[j]
                    c -= 1
            out[i] = s / chol[r, r]
            r -= 1


@hot
def _cholesky(W, eps, active, k, chol):
    """chol[:m, :m] = L with L Lᵀ = W_AA + εI over the m active contacts (in index
    order); returns m, or −1 if a pivot is not positive."""
    m = 0
    for i in range(k):
        if not active[i]:
            continue
        mj = 0
        for j in range(i + 1):
            if not active[j]:
                continue
            s = W[i, j] + (eps if i == j else 0.0)
            for p in range(mj):
                s -= chol[m, p] * chol[mj, p]
            if i != j:
                chol[m, mj] = s / chol[mj, mj]
            elif s <= 0.0:
                return -1
            else:
                chol[m, m] = math.sqrt(s)
            mj += 1
        m += 1
    return m


@hot
def moreau_impulses(W, u_pre, gamma, k, lam, u_post, chol, vec, active):
    """Moreau's law over k touching contacts (module docstring): the least-norm impulses
    lam[:k] and u_post[:k] = u⁻ + WΛ.  Returns SETTLED, NOT_SETTLED (pivot cap: Λ is
    the last iterate) or SINGULAR (a Wᵢᵢ ≤ 0)."""
    if k == 0:
        return SETTLED
    if k > MAX_LAW_CONTACTS:
        return TOO_MANY
    wmax = 0.0
    for i in range(k):
        if not W[i, i] > 0.0:
            return SINGULAR
        wmax = max(wmax, W[i, i])
    if k == 1:
        lam[0] = single_impulse(u_pre[0], W[0, 0], gamma)
        u_post[0] = u_pre[0] + W[0, 0] * lam[0]
        return SETTLED
    q = vec[:k]
    r = vec[k : 2 * k]
    qmax = 0.0
    for i in range(k):
        q[i] = moreau_target(u_pre[i], gamma)
        qmax = max(qmax, abs(q[i]))
        active[i] = 0
        lam[i] = 0.0
    tol = PIVOT_TOL * qmax
    eps = REGULARISATION * wmax
    status = NOT_SETTLED
    for _ in range(8 * k * k + 64):
        for i in range(k):
            r[i] = -q[i]
        if not _cholesky_solve(W, eps, active, k, chol, r, lam):
            return SINGULAR
        post_velocities(W, q, lam, k, u_post)  # w = q + WΛ (u_post as scratch)
        flip = -1
        for i in range(k):
            w_i = u_post[i] + eps * lam[i]
            if (active[i] and lam[i] * W[i, i] < -tol) or (not active[i] and w_i < -tol):
                flip = i
                break
        if flip < 0:
            status = SETTLED
            break
        active[flip] = 1 - active[flip]
    _refine(W, wmax, q, k, lam, u_post, chol, r, active)
    for i in range(k):
        lam[i] = max(lam[i], 0.0)
    post_velocities(W, u_pre, lam, k, u_post)
    return status


@hot
def _refine(W, wmax, q, k, lam, scratch, chol, r, active):
    """Λ_A = the minimum-norm solution of W_AA Λ_A = −q_A, by iterated Tikhonov from 0
    with ε₂ = REFINE_REGULARISATION × max Wᵢᵢ: Λ_A += (W_AA + ε₂I)⁻¹(−q_A − W_AA Λ_A).
    Every iterate lies in W_AA's range (so the limit is the least-norm solution); each
    pass shrinks the residual along an eigenvector of eigenvalue λ by ε₂/(λ + ε₂); the
    passes stop once it no longer shrinks (roundoff), at most MAX_REFINE_PASSES.  The
    moderate ε₂ keeps the roundoff of the solves along W's null space at ~1e-12."""
    m = _cholesky(W, REFINE_REGULARISATION * wmax, active, k, chol)
    if m < 0:
        return
    for i in range(k):
        lam[i] = 0.0
    last = math.inf
    for _ in range(MAX_REFINE_PASSES):
        post_velocities(W, q, lam, k, scratch)
        size = 0.0
        for i in range(k):
            r[i] = -scratch[i] if active[i] else 0.0
            size = max(size, abs(r[i]))
        if not size < last:
            break
        last = size
        _solve_factored(active, k, chol, m, r, scratch)
        for i in range(k):
            lam[i] += scratch[i]


@hot
def sequential_impulses(W, u_pre, gamma, k, order, n_order, lam, u_post, max_hits):
    """The sequential law (module docstring): single impacts (eq. F) until no contact
    approaches faster than SETTLE_REL × max|u⁻|, the fastest first (n_order = 0) or in
    sweeps over order[:n_order]; at most max_hits of them (MAX_SEQUENTIAL_IMPACTS).
    lam[:k] sums each contact's impulses; u_post[:k] the normal velocities after.
    Returns (status, number of single impacts)."""
    if k > MAX_LAW_CONTACTS:
        return TOO_MANY, 0
    umax = 0.0
    for i in range(k):
        if not W[i, i] > 0.0:
            return SINGULAR, 0
        lam[i] = 0.0
        u_post[i] = u_pre[i]
        umax = max(umax, abs(u_pre[i]))
    tol = SETTLE_REL * umax
    hits = 0
    pos = 0
    idle = 0
    while hits < max_hits:
        j = -1
        if n_order == 0:
            lowest = -tol
            for i in range(k):
                if u_post[i] < lowest:
                    lowest = u_post[i]
                    j = i
            if j < 0:
                return SETTLED, hits
        else:
            c = order[pos]
            pos = (pos + 1) % n_order
            if u_post[c] >= -tol:
                idle += 1
                if idle >= n_order:
                    return SETTLED, hits
                continue
            idle = 0
            j = c
        u_j = u_post[j]
        zeta = single_impulse(u_j, W[j, j], gamma)
        lam[j] += zeta
        for i in range(k):
            u_post[i] += W[i, j] * zeta
        u_post[j] = post_impact_velocity(u_j, gamma)  # exactly, as eq. F makes it
        hits += 1
    return NOT_SETTLED, hits


@hot
def moreau_law(W, u_pre, gamma, k, lam, u_post, work):
    """Moreau's law in the registry's signature (reference.core.laws): one impact."""
    status = moreau_impulses(W, u_pre, gamma, k, lam, u_post, work.chol, work.vec, work.active)
    return status, 1


@hot
def sequential_law(W, u_pre, gamma, k, lam, u_post, work):
    """The sequential law in the registry's signature (reference.core.laws)."""
    return sequential_impulses(
        W, u_pre, gamma, k, work.order, work.n_order, lam, u_post, work.max_hits
    )
