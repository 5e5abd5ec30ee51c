"""The impact law: single-point Newtonian impacts (paper §2.3, eqs. utk1–utk3, F, ω⁺,
v⁺), for the exact core and the linear model alike.

An impulse ζ along contact k's normal changes (v, ω) by ζ M⁻¹Jᵀ and its normal
velocity u by ζ w (w = J M⁻¹ Jᵀ, `inertia.impulse_response`).  Newton's law fixes u⁺
(`post_impact_velocity`), so ζ = (u⁺ − u⁻)/w = −(1 + γ) u⁻ / w: the paper's eq. F
(`impact_impulse`).  With other contacts held, the single-impact law stands only if it
leaves every held contact separating or resting (`pushed_contacts`); otherwise the
outcome is undecidable in this model.  Changing the impact law is an edit of
`post_impact_velocity` alone: the impulse (`impact_impulse`), the chatter series and the
capture of a γ = 0 contact (reference.core.chatter, events; `bounce_ratio`,
`chatter_impulse`) follow from it, in the exact core and in the linear model
(reference.linear.kernel, reference.linear.model.impact_matrix), which call these
functions."""

from .contacts import approaching_contacts, contact_frame, contact_kind, normal_velocity
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
def impact_impulse(u_pre, w, gamma):
    """The normal impulse of an impact (paper eq. F): ζ = (u⁺ − u⁻)/w takes the
    contact's normal velocity from u⁻ to the law's u⁺ (`post_impact_velocity`), w being
    the change of that velocity per unit impulse (J M⁻¹ Jᵀ; fᵀΘ⁻¹f in the linear
    model)."""
    return (post_impact_velocity(u_pre, gamma) - u_pre) / w


@hot
def chatter_impulse(u_post, w, gamma):
    """The total impulse of the bounces still to come after one leaving at u⁺ > 0 under
    a constant normal acceleration (a chatter sequence): each bounce's impulse is
    (1 + r) times its landing speed, the speeds a geometric series of ratio
    r = `bounce_ratio`, so Λ = (1 + r) u⁺ / (w (1 − r))."""
    r = bounce_ratio(gamma)
    return (1.0 + r) * u_post / (w * (1.0 - r))


@hot
def impact(y, model, pts, k):
    """In place: the impact of contact k on state y (positions unchanged)."""
    kind = contact_kind(pts, k)
    f = contact_frame(y, kind, pts, k)
    u_pre = normal_velocity(y, f, kind)
    resp = impulse_response(y, f, model.mass, model.i1, model.i3)
    zeta = impact_impulse(u_pre, resp.w, model.gamma)
    apply_impulse(y, resp, zeta)
    return ImpactOutcome(zeta, u_pre, normal_velocity(y, f, kind))


@hot
def pushed_contacts(y, model, pts, held, n_held, vnoise, out):
    """The paper's rule beside held contacts: the held contacts that the impact just
    applied to y leaves approaching the ground (normal velocity < −vnoise) go to `out`;
    returns their number (0: the single-impact law stands)."""
    return approaching_contacts(y, model, pts, held, n_held, vnoise, out)
