"""An impact law applied to a state: the touching contacts' Delassus matrix and normal
velocities from the contact kinematics (reference.core.contacts, inertia), the law's
impulses (reference.core.impact_laws), and (v, ω) += M⁻¹JᵀΛ.  Positions are unchanged
(paper §2.3: impacts are instantaneous)."""

from .contacts import contact_frame, normal_velocity
from .impact_laws import (
    LAW_MOREAU,
    LAW_SEQUENTIAL,
    NOT_SETTLED,
    SETTLED,
    moreau_impulses,
    sequential_impulses,
)
from .inertia import apply_impulse, impulse_response, response_rate
from .jit import hot


@hot
def delassus_system(y, flat, pts, mass, i1, i3, contacts, k, W, u):
    """W[:k, :k] = J M⁻¹ Jᵀ and u[:k] = J (v, ω) for the contacts[:k] at state y."""
    for i in range(k):
        fi = contact_frame(y, flat, pts, contacts[i])
        u[i] = normal_velocity(y, fi, flat)
        resp = impulse_response(y, fi, mass, i1, i3)
        W[i, i] = resp.w
        for j in range(i):
            fj = contact_frame(y, flat, pts, contacts[j])
            W[i, j] = W[j, i] = response_rate(fj, resp)


@hot
def apply_impulses(y, flat, pts, mass, i1, i3, contacts, k, lam):
    """In place: (v, ω) += Σ Λᵢ M⁻¹Jᵢᵀ."""
    for i in range(k):
        if lam[i] != 0.0:
            f = contact_frame(y, flat, pts, contacts[i])
            apply_impulse(y, impulse_response(y, f, mass, i1, i3), lam[i])


@hot
def multi_impact(
    y, flat, pts, mass, i1, i3, gamma, law, contacts, k, order, n_order, max_hits,
    W, u_pre, lam, u_post, chol, vec, active, result,
):  # fmt: skip
    """In place: the impact of contacts[:k] on state y under `law` (LAW_MOREAU or
    LAW_SEQUENTIAL; order[:n_order] the sequential law's order, empty: the fastest
    first).  Fills u_pre, lam, u_post (per contact) and result[:2] = (status, number of
    single impacts: 1 for Moreau); y changes only when the law settled."""
    delassus_system(y, flat, pts, mass, i1, i3, contacts, k, W, u_pre)
    if law == LAW_MOREAU:
        status = moreau_impulses(W, u_pre, gamma, k, lam, u_post, chol, vec, active)
        hits = 1
    elif law == LAW_SEQUENTIAL:
        status, hits = sequential_impulses(
            W, u_pre, gamma, k, order, n_order, lam, u_post, max_hits
        )
    else:
        status, hits = NOT_SETTLED, 0
    result[0], result[1] = status, hits
    if status == SETTLED:  # else y stays the state before the impact
        apply_impulses(y, flat, pts, mass, i1, i3, contacts, k, lam)
