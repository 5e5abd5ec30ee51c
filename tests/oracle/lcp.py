"""Oracle: Moreau's frictionless impact law over k touching contacts, by enumeration.

0 ≤ Λ ⊥ w = q + WΛ ≥ 0 with q = u⁻ + γ min(u⁻, 0), W = J M⁻¹ Jᵀ (docs/laws.md,
"The laws").  Every support A ⊆ {0..k−1} is tried: the least-squares (minimum-norm)
solution of W_AA Λ_A = −q_A is a solution of the LCP when the system is consistent,
Λ_A ≥ 0 and w ≥ 0 off A.  All solutions found must give the same u⁺ (the law's
uniqueness); the least-norm impulses are then the smallest of the minimum-norm
solutions of W[:, A] Λ_A = u⁺ − u⁻ that are non-negative, over every support A (the
least-norm point of the solution polytope is the minimum-norm point of the affine set
on its own support).  numpy only; shares nothing with reference.core.impact_laws.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .body import BodyModel, Q, state


@dataclass(frozen=True)
class LcpSolution:
    impulses: np.ndarray  # the least-norm Λ
    u_post: np.ndarray  # u⁻ + WΛ
    all_u_post: list[np.ndarray]  # u⁺ of every basic solution found (all equal)
    unique_impulses: bool  # W definite on the support: Λ unique


def delassus(model: BodyModel, y: np.ndarray, contacts: list[int]) -> tuple[np.ndarray, ...]:
    """(J, M⁻¹, W = J M⁻¹ Jᵀ, u⁻ = J(v, ω)) of the contacts at state y."""
    s = state(y)
    cs = model.contact_list(s, contacts)
    W = np.array(model.delassus(s, cs)).reshape(len(cs), len(cs))
    return (
        model.jacobian([c.normal for c in cs], [c.lever for c in cs]),
        model.mass_matrix_inv(y[Q]),
        W,
        np.array([c.vn for c in cs]),
    )


def moreau_lcp(W: np.ndarray, u_pre: np.ndarray, gamma: float, tol: float = 1e-9) -> LcpSolution:
    """Every basic solution of Moreau's LCP by enumerating supports; the least-norm Λ."""
    k = len(u_pre)
    q = u_pre + gamma * np.minimum(u_pre, 0.0)
    scale = max(np.abs(q).max(), 1e-300)
    found = []
    for size in range(k + 1):
        for A in itertools.combinations(range(k), size):
            lam = _solve_on(W[np.ix_(A, A)], -q[list(A)], A, k)
            if lam is None:
                continue
            w = q + W @ lam
            if lam.min() * W.diagonal().max() >= -tol * scale and w.min() >= -tol * scale:
                found.append(np.maximum(lam, 0.0))
    if not found:
        raise ValueError("no solution of the LCP found")
    all_u = [u_pre + W @ lam for lam in found]
    u_post = all_u[0]
    lam_min = _least_norm(W, u_post - u_pre, u_post + gamma * np.minimum(u_pre, 0.0), tol, scale)
    support = lam_min > tol * scale
    definite = np.linalg.matrix_rank(W[np.ix_(support, support)]) == support.sum()
    return LcpSolution(lam_min, u_pre + W @ lam_min, all_u, bool(definite and len(found) == 1))


def _solve_on(Waa, rhs, A, k):
    lam = np.zeros(k)
    if not A:
        return lam
    x, *_ = np.linalg.lstsq(Waa, rhs, rcond=1e-12)
    if np.abs(Waa @ x - rhs).max() > 1e-9 * max(np.abs(rhs).max(), 1e-300):
        return None
    lam[list(A)] = x
    return lam


def _least_norm(W, d, w, tol, scale):
    """The smallest non-negative Λ with WΛ = d supported where w = 0."""
    free = [i for i in range(len(d)) if w[i] <= tol * scale]
    best = None
    for size in range(len(free) + 1):
        for A in itertools.combinations(free, size):
            lam = np.zeros(len(d))
            if A:
                x, *_ = np.linalg.lstsq(W[:, A], d, rcond=1e-12)
                lam[list(A)] = x
            if np.abs(W @ lam - d).max() > 1e-9 * max(np.abs(d).max(), 1e-300):
                continue
            if lam.min() < -tol * scale / W.diagonal().max():
                continue
            if best is None or np.linalg.norm(lam) < np.linalg.norm(best) - 1e-14:
                best = np.maximum(lam, 0.0)
    return best
