"""An impact law applied to a state: the touching contacts' Delassus matrix and normal
velocities from the contact kinds (reference.core.contacts, inertia), the law's
impulses (reference.core.impact_laws), and (v, ω) += M⁻¹JᵀΛ.  Positions are unchanged
(paper §2.3: impacts are instantaneous)."""

from .chatter import completion_speed
from .contacts import contact_frame, contact_kind, normal_velocity, rate_noise
from .impact_laws import SETTLED
from .inertia import apply_impulse, impulse_response, response_rate
from .jit import hot
from .law_dispatch import solve_law
from .records import LawWork


@hot
def delassus_system(y, model, pts, contacts, k, W, u):
    """W[:k, :k] = J M⁻¹ Jᵀ and u[:k] = J (v, ω) for the contacts[:k] at state y."""
    for i in range(k):
        ki = contact_kind(pts, contacts[i])
        fi = contact_frame(y, ki, pts, contacts[i])
        u[i] = normal_velocity(y, fi, ki)
        resp = impulse_response(y, fi, model.mass, model.i1, model.i3)
        W[i, i] = resp.w
        for j in range(i):
            fj = contact_frame(y, contact_kind(pts, contacts[j]), pts, contacts[j])
            W[i, j] = W[j, i] = response_rate(fj, resp)


@hot
def apply_impulses(y, model, pts, contacts, k, lam):
    """In place: (v, ω) += Σ Λᵢ M⁻¹Jᵢᵀ."""
    for i in range(k):
        if lam[i] != 0.0:
            f = contact_frame(y, contact_kind(pts, contacts[i]), pts, contacts[i])
            apply_impulse(y, impulse_response(y, f, model.mass, model.i1, model.i3), lam[i])


@hot
def law_impact(
    y, model, pts, law, contacts, k, order, n_order, max_hits, chatter_tol,
    W, u_pre, lam, u_post, chol, vec, active, result,
):  # fmt: skip
    """In place: the impact of contacts[:k] on state y under `law` (a code of
    reference.core.laws; order[:n_order] the sequential law's order as positions in
    contacts, empty: the fastest first), restitution model.gamma.  Fills u_pre, lam,
    u_post (per contact) and result[:3] = (status, number of single impacts: 1 for
    Moreau, 1 if the bounces were completed); y changes only when the law settled.

    Chatter completion, as for a single impact (reference.core.chatter): when every
    contact that leaves, leaves slower than its `completion_speed`, the bounces that
    would follow are completed: the impact is taken plastic (γ = 0), so that the
    contacts stay at rest and the loop's start holds those its complementarity problem
    keeps (the others, not pushed back, are released there)."""
    delassus_system(y, model, pts, contacts, k, W, u_pre)
    _solve_law(model.gamma, law, k, order, n_order, max_hits, W, u_pre, lam, u_post,
               chol, vec, active, result)  # fmt: skip
    result[2] = 0
    if result[0] == SETTLED and 0.0 < model.gamma < 1.0:
        if _bounces_are_small(y, model, pts, contacts, k, u_post, chatter_tol):
            _solve_law(0.0, law, k, order, n_order, max_hits, W, u_pre, lam, u_post,
                       chol, vec, active, result)  # fmt: skip
            result[2] = 1
    if result[0] == SETTLED:  # else y stays the state before the impact
        apply_impulses(y, model, pts, contacts, k, lam)


@hot
def _bounces_are_small(y, model, pts, contacts, k, u_post, chatter_tol):
    """Whether some contact leaves and every one that does (u⁺ above the velocity
    roundoff) leaves below its chatter completion speed."""
    vnoise = rate_noise(y, model.radius)
    leaving = False
    for i in range(k):
        if u_post[i] > vnoise:
            leaving = True
            if u_post[i] > completion_speed(y, model, pts, contacts[i], chatter_tol, vnoise):
                return False
    return leaving


@hot
def _solve_law(
    gamma, law, k, order, n_order, max_hits, W, u_pre, lam, u_post, chol, vec, active, result
):
    """The law's impulses for restitution gamma: result[:2] = (status, single impacts)."""
    work = LawWork(chol, vec, active, order, n_order, max_hits)
    status, hits = solve_law(law, W, u_pre, gamma, k, lam, u_post, work)
    result[0], result[1] = status, hits


@hot
def multi_impact(
    y, model_rec, pts, law, contacts, k, order, n_order, max_hits, chatter_tol,
    W, u_pre, lam, u_post, chol, vec, active, result,
):  # fmt: skip
    """`law_impact` with the model as a one-element records.MODEL array (the form an
    exported function takes from Python)."""
    law_impact(
        y, model_rec[0], pts, law, contacts, k, order, n_order, max_hits, chatter_tol,
        W, u_pre, lam, u_post, chol, vec, active, result,
    )  # fmt: skip
