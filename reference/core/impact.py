"""Single-point Newtonian impacts (paper §2.3, eqs. utk1–utk3, F, ω⁺, v⁺).

An impulse ζ along contact k's normal changes (v, ω) by ζ M⁻¹Jᵀ and its normal
velocity u by ζ w (w = J M⁻¹ Jᵀ, `inertia.impulse_response`).  Newton's law fixes u⁺
(`post_impact_velocity`), so ζ = (u⁺ − u⁻)/w = −(1 + γ) u⁻ / w: the paper's eq. F.
With other contacts held, the single-impact law stands only if it leaves every held
contact separating or resting (`pushed_contacts`); otherwise the outcome is
undecidable in this model.  Changing the impact law is an edit of
`post_impact_velocity` alone: the chatter series and the capture of a γ = 0 contact
(reference.core.chatter, events) use the ratio it gives (`bounce_ratio`)."""

from .contacts import contact_frame, contact_kind, normal_velocity
from .inertia import apply_impulse, impulse_response
from .jit import hot
from .records import ImpactOutcome


@hot
def post_impact_velocity(u_pre, gamma):
    """Newton's impact law (paper eq. utk3): the contact's normal velocity after the
    impact is −γ times the one before."""
    return -gamma * u_pre


@hot
def bounce_ratio(gamma):
    """u⁺/|u⁻| of the impact law: the factor by which a contact's rebound speed shrinks
    from one bounce to the next (γ for Newton's law).  The chatter series (a geometric
    series of bounces) assumes it does not depend on the speed."""
    return post_impact_velocity(-1.0, gamma)


@hot
def impact(y, model, pts, k):
    """In place: the impact of contact k on state y (positions unchanged)."""
    kind = contact_kind(model, k)
    f = contact_frame(y, kind, pts, k)
    u_pre = normal_velocity(y, f, kind)
    resp = impulse_response(y, f, model.mass, model.i1, model.i3)
    zeta = (post_impact_velocity(u_pre, model.gamma) - u_pre) / resp.w
    apply_impulse(y, resp, zeta)
    return ImpactOutcome(zeta, u_pre, normal_velocity(y, f, kind))


@hot
def pushed_contacts(y, model, pts, held, n_held, vnoise, out):
    """The paper's rule beside held contacts: the held contacts that the impact just
    applied to y leaves approaching the ground (normal velocity < −vnoise) go to `out`;
    returns their number (0: the single-impact law stands)."""
    n = 0
    for i in range(n_held):
        kind = contact_kind(model, held[i])
        if normal_velocity(y, contact_frame(y, kind, pts, held[i]), kind) < -vnoise:
            out[n] = held[i]
            n += 1
    return n
