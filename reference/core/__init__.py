"""The compiled core of the exact reference: every physics rule once, as a scalar numba
function, and the event loop that calls them.

    tolerances  named tolerances and factors (one place)
    records     the named results (namedtuples) and the record layouts shared with Python
    rotation    quaternion primitives (scalar)
    contacts    contact geometry: gap, normal, lever, normal velocity and acceleration
    inertia     inverse inertia, impulse response M⁻¹Jᵀ and effective mass, energies
    impact      Newton's impact law and the paper's rule beside a held contact
    held        sustained contact: held right-hand side, complementarity, projection
    dop853      the integrator of contact phases (scipy's DOP853, step for step)
    flight      closed-form free flight and the derivative bounds K, B of the gaps
    roots       first roots of the lower bounds P2, P3 (conservative advancement)
    search      the next event of a free flight
    chatter     when a chatter sequence is completed
    horizon     how long a contact chunk may be
    loop        the event loop: phases, events, end of the motion

Python reaches the core through `loop.run_events` only (reference.simulate); the
tests reach the primitives directly.
"""
