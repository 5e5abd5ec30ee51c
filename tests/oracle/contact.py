"""Oracle: sustained contact (paper §2.2, eqs. rollF, rollM, rollc).

With a set C of contacts held (gap 0, normal velocity 0), the normal accelerations are
a_n = A λ + b with A = J M⁻¹ Jᵀ and b = J M⁻¹ f + bias (gravity, gyroscopic term and
velocity products).  The forces solve the acceleration-level complementarity problem
λ ≥ 0, a_n ≥ 0, λ·a_n = 0, solved exactly by enumerating the (at most 2³) active sets.

The motion between events is integrated with DOP853 (scipy) at tight tolerances; after
every chunk the state is projected back onto the constraints (positions, then velocities
by normal impulses), so there is no drift.  A force reaching zero is a lift-off event.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy.integrate import solve_ivp

from . import quaternion as qt
from .body import BodyModel, Contact, Q, State, V, W, X, row_dot, solve, state


def held_system(model: BodyModel, s: State, contacts) -> tuple[list[Contact], list, list, list]:
    """(contacts, A, b, acc_free) for the contacts held at state s, as floats: their
    kinematics, A = J M⁻¹ Jᵀ, b = J M⁻¹ f + bias and M⁻¹ f (gravity and the gyroscopic
    term)."""
    cs = model.contact_list(s, contacts)
    acc_free = model.free_acc(s)
    lin, ang = acc_free[:3], acc_free[3:]
    b = [row_dot(c, lin, ang) + c.bias for c in cs]
    return cs, model.delassus(s, cs), b, acc_free


def held_motion(model: BodyModel, s: State, contacts) -> tuple[list[float], list[float]]:
    """([v̇; ω̇], λ) with the contacts held as bilateral constraints (eqs. rollF, rollM,
    rollc): λ = −A⁻¹ b, [v̇; ω̇] = M⁻¹ f + M⁻¹ Jᵀ λ (floats)."""
    cs, A, b, acc_free = held_system(model, s, contacts)
    lam = solve(A, [-bk for bk in b])
    d = model.response(s, cs, lam)
    return [a + da for a, da in zip(acc_free, d, strict=True)], lam


def contact_system(model: BodyModel, y: np.ndarray, contacts: list[int]):
    """(A, b, J, Minv, acc_free) for the contacts held, at state y (arrays)."""
    cs, A, b, acc_free = held_system(model, state(y), contacts)
    Minv = model.mass_matrix_inv(y[Q])
    return (
        np.array(A),
        np.array(b),
        model.jacobian([c.normal for c in cs], [c.lever for c in cs]),
        Minv,
        np.array(acc_free),
    )


def solve_contact_lcp(
    model: BodyModel, y: np.ndarray, candidates: list[int], tol: float = 0.0
) -> tuple[list[int], np.ndarray]:
    """Active set and forces among `candidates` (contacts with gap 0 and normal velocity 0).

    Returns the active contacts (λ > 0) and their forces.  Enumerates active sets from
    the largest; the first satisfying λ ≥ 0 and a_n ≥ −tol for the others is returned
    (unique when A is positive definite; at roundoff-level ties the larger set, i.e.
    holding the contact, wins)."""
    if not candidates:
        return [], np.zeros(0)
    _, A, b, _ = held_system(model, state(y), candidates)
    m = len(candidates)
    if m <= 2:
        return _lcp_small(candidates, A, b, tol)
    A, b = np.array(A), np.array(b)
    best = None
    for size in range(m, -1, -1):
        for S in itertools.combinations(range(m), size):
            S = list(S)
            lam = np.zeros(m)
            if S:
                try:
                    lam[S] = np.linalg.solve(A[np.ix_(S, S)], -b[S])
                except np.linalg.LinAlgError:
                    continue
            if np.any(lam[S] < -tol * (1 + np.abs(lam[S]))):
                continue
            an = A @ lam + b
            others = [i for i in range(m) if i not in S]
            if np.all(an[others] >= 0.0):
                best = (S, lam)
                break
        if best is not None:
            break
    if best is None:
        raise RuntimeError("contact complementarity problem has no solution")
    S, lam = best
    active = [candidates[i] for i in S if lam[i] > 0.0]
    return active, np.array([lam[i] for i in S if lam[i] > 0.0])


def _lcp_small(candidates: list[int], a: list, bb: list, tol: float):
    """solve_contact_lcp's enumeration written out for one or two candidates (A = a and
    b = bb as floats), in the same order (both, then each alone, then none), with
    Cramer's rule for the 2 × 2."""

    def ok(lam: float) -> bool:
        return lam >= -tol * (1 + abs(lam))

    def result(pairs):
        active = [c for c, lam in pairs if lam > 0.0]
        return active, np.array([lam for _, lam in pairs if lam > 0.0])

    if len(candidates) == 1:
        lam = -bb[0] / a[0][0]
        if ok(lam):
            return result([(candidates[0], lam)])
        if bb[0] >= 0.0:
            return [], np.zeros(0)
        raise RuntimeError("contact complementarity problem has no solution")
    try:
        both = solve(a, [-bb[0], -bb[1]])
    except np.linalg.LinAlgError:  # det = 0: not with both held
        both = None
    if both is not None and ok(both[0]) and ok(both[1]):
        return result(list(zip(candidates, both, strict=True)))
    for i, j in ((0, 1), (1, 0)):
        if a[i][i] == 0.0:
            continue
        lam = -bb[i] / a[i][i]
        if ok(lam) and a[j][i] * lam + bb[j] >= 0.0:
            return result([(candidates[i], lam)])
    if bb[0] >= 0.0 and bb[1] >= 0.0:
        return [], np.zeros(0)
    raise RuntimeError("contact complementarity problem has no solution")


def constrained_rhs(model: BodyModel, contacts: list[int]):
    """dy/dt with the contacts held as bilateral constraints (forces may go negative:
    that is the lift-off signal); q̇ = ½ [0, ω] ⊗ q.  On floats (`held_motion`)."""
    held = list(contacts)

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        s = state(y)
        acc, _ = held_motion(model, s, held)
        w0, w1, w2 = s.w
        dq = qt.product((0.0, w0, w1, w2), s.q)
        return np.array([*s.v, *(0.5 * c for c in dq), *acc])

    return rhs


def contact_forces(model: BodyModel, y: np.ndarray, contacts: list[int]) -> np.ndarray:
    return np.array(held_motion(model, state(y), contacts)[1])


def constrained_acceleration(model: BodyModel, y: np.ndarray, contacts: list[int]) -> np.ndarray:
    if not contacts:
        return model.free_acceleration(y)
    return np.array(held_motion(model, state(y), contacts)[0])


def project_positions(model: BodyModel, y: np.ndarray, contacts: list[int]) -> np.ndarray:
    """Move the body (translation along the normals' span and a small rotation, in the
    mass metric) so the held contacts have gap 0.  Two Gauss–Newton passes."""
    out = np.array(y, dtype=float)
    for _ in range(2):
        s = state(out)
        cs = model.contact_list(s, contacts)
        d = model.response(s, cs, solve(model.delassus(s, cs), [-c.gap for c in cs]))
        out[X] += d[:3]
        out[Q] = qt.unit(qt.product(qt.exp_components(*d[3:]), s.q))
    return out


def project_velocities(model: BodyModel, y: np.ndarray, contacts: list[int]) -> np.ndarray:
    from .impact import apply_normal_impulses

    return apply_normal_impulses(model, y, contacts, np.zeros(len(contacts)))


def integrate_chunk(
    model: BodyModel, y: np.ndarray, contacts: list[int], s: float, rtol: float, dense=False
):
    """Integrate the constrained motion for time s (DOP853) and project onto the
    constraints.  Returns (state, ODE solution or None, number of RHS evaluations)."""
    scale_x = model.length_scale(y) + 1e-300
    scale_v = model.velocity_scale(y) + 1e-300
    atol = np.empty(13)
    atol[X] = rtol * scale_x
    atol[Q] = rtol * scale_x / model.radius
    atol[V] = rtol * scale_v
    atol[W] = rtol * scale_v / model.radius
    sol = solve_ivp(
        constrained_rhs(model, contacts),
        (0.0, s),
        y,
        method="DOP853",
        rtol=rtol,
        atol=atol,
        dense_output=dense,
    )
    if not sol.success:
        raise RuntimeError(f"contact integration failed: {sol.message}")
    out = sol.y[:, -1].copy()
    out[Q] = qt.normalize(out[Q])
    out = project_positions(model, out, contacts)
    out = project_velocities(model, out, contacts)
    return out, (sol.sol if dense else None), int(sol.nfev)


def chunk_horizon(model: BodyModel, y: np.ndarray, jet, held: np.ndarray) -> float:
    """Largest safe chunk: no contact other than the `held` ones (a mask) can reach the
    ground (quadratic lower bound with K = 2 max(|g″|) + g over them, a factor-2 margin
    on the current second derivatives), and the chunk stays short against the local
    time scale √(length / acceleration)."""
    from .events import first_root_lower_bound

    g = model.gravity
    free = ~held
    acc_scale = float(np.max(np.abs(jet.accel[free]))) if free.any() else 0.0
    K = 2.0 * acc_scale + g + 1e-300
    h = math.inf
    for k in np.flatnonzero(free):
        g_k = max(float(jet.gap[k]), float(jet.noise[k]))
        h = min(h, first_root_lower_bound(g_k, float(jet.rate[k]), float(jet.accel[k]), K, 0.0))
    L = model.length_scale(y)
    T_local = math.sqrt(max(L, 1e-300) / K)
    vs = model.velocity_scale(y)
    if vs > 0:
        T_local = min(T_local, 0.2 * model.radius / vs * 10)
    return min(h, 0.25 * T_local)
