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

from .body import BodyModel, V, W, row_dot, solve, state


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
    idx = range(model.n_contacts) if watch is None else [k, *watch]
    s = state(y)
    cs = model.contact_list(s, idx)
    row = k if watch is None else 0  # contact k's place in cs
    ck = cs[row]
    w = model.delassus(s, [ck])[0][0]  # J_k M⁻¹ J_kᵀ
    u_pre = ck.vn
    zeta = -(1.0 + gamma) * u_pre / w
    dq = model.response(s, [ck], [zeta])
    y_post = np.array(y, dtype=float)
    y_post[V] += dq[:3]
    y_post[W] += dq[3:]
    v, om = y_post[V].tolist(), y_post[W].tolist()
    vn_idx = [row_dot(c, v, om) for c in cs]
    vn_post = np.full(model.n_contacts, np.nan)
    vn_post[list(idx)] = vn_idx
    return ImpactResult(y_post, zeta, u_pre, vn_idx[row], vn_post)


def apply_normal_impulses(
    model: BodyModel, y: np.ndarray, contacts: list[int], target_vn: np.ndarray
) -> np.ndarray:
    """Impulses at `contacts` (normal directions) that set their normal velocities to
    `target_vn` exactly: Δu = M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁻¹ (target − u).  Used to project the
    velocity onto a constraint set; the impulses are along the normals, so horizontal
    momentum and vertical angular momentum are untouched on flat ground."""
    if not contacts:
        return y
    s = state(y)
    cs = model.contact_list(s, contacts)
    target = np.asarray(target_vn, dtype=float).tolist()
    mu = solve(model.delassus(s, cs), [t - c.vn for t, c in zip(target, cs, strict=True)])
    dq = model.response(s, cs, mu)
    out = np.array(y, dtype=float)
    out[V] += dq[:3]
    out[W] += dq[3:]
    return out
