"""The linear model's multi-contact impact under the exact reference's impact laws
(docs/laws.md, "The linear model under the laws"; the registry reference.core.laws),
on its own: the compiled functions the kernel's loop runs at a simultaneous impact
(kernel._law_event), callable from Python.

The Delassus matrix of the linear model is W = F_S Θ⁻¹ F_Sᵀ (w_ab = f_aᵀΘ⁻¹f_b, the
change of contact a's normal velocity per unit impulse at b, from Θ Δp = Σ f_b λ_b of
the linearised Newton–Euler equations, paper eqs. Theta, impactequ); with the normal
velocities u⁻ = F_S p⁻ it goes to the SAME law functions as the exact core's, through
its dispatch (law_dispatch.solve_law), and p⁺ = p⁻ + Θ⁻¹ F_Sᵀ Λ.  With one contact this
is the kernel's own impact, bit for bit (eq. F).
"""

from __future__ import annotations

import numpy as np

from ..core.laws import law_of
from ..core.laws import work_floats as law_work_floats
from . import kernel as K


def delassus(F, theta, contacts):
    """W = F_S Θ⁻¹ F_Sᵀ of the contacts S (the linear model's Delassus matrix) and, for
    convenience, Θ⁻¹ = 1/theta."""
    tinv = 1.0 / np.asarray(theta, dtype=float)
    w = K._contact_products(np.ascontiguousarray(F, dtype=float), tinv)[0]
    s = np.asarray(contacts, dtype=np.int64)
    return w[np.ix_(s, s)], tinv


def apply_law(F, theta, gamma, p, contacts, law: int, complete_below: float = 0.0):
    """In place on p: the impact of `contacts` under `law` (a code of the law registry),
    as the kernel's loop makes it: p⁺ = p⁻ + Θ⁻¹F_SᵀΛ (contact by contact).  With
    0 < γ < 1, when every contact that leaves leaves at u⁺ ≤ `complete_below` (and some
    does), the impact is taken plastic (γ = 0): the bounces that would follow are
    completed.  Returns (status, Λ, u⁻, u⁺, single impacts, completed); p is unchanged
    unless the law settled (status impact_laws.SETTLED)."""
    from ..core.impact_laws import SETTLED

    F = np.ascontiguousarray(F, dtype=float)
    nc = F.shape[0]
    tinv = 1.0 / np.asarray(theta, dtype=float)
    w, wmax = K._contact_products(F, tinv)
    model = (F, np.asarray(theta, dtype=float), tinv, w, wmax, 1.0, float(gamma), 3)
    lawws = K.new_law_scratch(nc, law_work_floats(law_of(law), nc))
    cs = lawws[2][:nc]
    k = len(contacts)
    cs[:k] = np.asarray(contacts, dtype=np.int64)
    status, hits = K._law_impulses(model, law, p, cs, k, float(gamma), lawws)
    u_post = lawws[1][2 * nc : 3 * nc]
    completed = False
    if status == SETTLED and K._law_completes(u_post, k, float(gamma), float(complete_below)):
        status, hits = K._law_impulses(model, law, p, cs, k, 0.0, lawws)
        completed = True
    lam, u_pre = lawws[1][nc : 2 * nc], lawws[1][:nc]
    if status == SETTLED:
        K._add_law_impulses(F, tinv, cs, k, lam, p)
    return int(status), lam[:k].copy(), u_pre[:k].copy(), u_post[:k].copy(), int(hits), completed
