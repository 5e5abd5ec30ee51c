"""Oracle: single-point Newtonian impacts (paper §2.3, eqs. utk1–utk3, F, ω⁺, v⁺).

An impulse ζ n at lever r changes (v, ω) by M⁻¹ Jᵀ ζ with J = [nᵀ, (r × n)ᵀ]; the
Newtonian law u⁺ = −γ u⁻ for the contact's normal velocity u = J (v, ω) gives

    ζ = −(1 + γ) u⁻ / (J M⁻¹ Jᵀ),

the paper's eq. (F) with u_zᵀ[m⁻¹ I − R× θ⁻¹ R×] u_z = J M⁻¹ Jᵀ.  With another contact j
resting, the single-impact law is kept only if it leaves j separating or resting,
u_j⁺ ≥ 0 (the paper's rule); otherwise the outcome is undecidable in this model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .body import BodyModel, Q, V, W


@dataclass(frozen=True)
class ImpactResult:
    y_post: np.ndarray
    impulse: float
    u_pre: float
    u_post: float
    others_post: np.ndarray  # normal velocities of all contacts after the impact


def impact_impulse(
    model: BodyModel, y: np.ndarray, k: int, gamma: float, watch: list[int] | None = None
) -> ImpactResult:
    """Apply the Newtonian impact at contact k to state y (positions unchanged):
    impulse ζ = −(1 + γ) u⁻ / (J_k M⁻¹ J_kᵀ) along J_k, so that u⁺ = −γ u⁻.

    `others_post` holds the post-impact normal velocities of the contacts in `watch`
    (all contacts when None; NaN for the unwatched), so a caller that needs only the
    resting ones does not pay for every vertex of a large polygon."""
    idx = np.arange(model.n_contacts) if watch is None else np.array([k, *watch], dtype=int)
    gap, normal, lever, vn, _ = model.contacts(y, idx)
    J = model.jacobian(normal, lever)
    Minv = model.mass_matrix_inv(y[Q])
    row = k if watch is None else 0
    jk = J[row]
    w = float(jk @ Minv @ jk)
    u_pre = float(vn[row])
    zeta = -(1.0 + gamma) * u_pre / w
    dq = Minv @ jk * zeta
    y_post = np.array(y, dtype=float)
    y_post[V] += dq[:3]
    y_post[W] += dq[3:]
    vn_idx = J @ np.concatenate([y_post[V], y_post[W]])
    vn_post = np.full(model.n_contacts, np.nan)
    vn_post[idx] = vn_idx
    return ImpactResult(y_post, zeta, u_pre, float(vn_idx[row]), vn_post)


def apply_normal_impulses(
    model: BodyModel, y: np.ndarray, contacts: list[int], target_vn: np.ndarray
) -> np.ndarray:
    """Impulses at `contacts` (normal directions) that set their normal velocities to
    `target_vn` exactly: Δu = M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁻¹ (target − u).  Used to project the
    velocity onto a constraint set; the impulses are along the normals, so horizontal
    momentum and vertical angular momentum are untouched on flat ground."""
    if not contacts:
        return y
    gap, normal, lever, vn, _ = model.contacts(y, np.asarray(contacts, dtype=int))
    J = model.jacobian(normal, lever)
    Minv = model.mass_matrix_inv(y[Q])
    A = J @ Minv @ J.T
    mu = np.linalg.solve(A, np.asarray(target_vn) - vn)
    dq = Minv @ J.T @ mu
    out = np.array(y, dtype=float)
    out[V] += dq[:3]
    out[W] += dq[3:]
    return out
