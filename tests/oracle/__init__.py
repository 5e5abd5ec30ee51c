"""An independent implementation of the exact reference, for the tests only.

It is the pure-Python specification the compiled core (reference.core) was rewritten
from: numpy contact kinematics, the all-contact event search with the original
derivative bounds (K = g + a(|ω|² + |ω̇|), B = a(|ω̈| + 3|ω||ω̇| + |ω|³)), scipy's
solve_ivp (DOP853) with dense output for contact phases and brentq for lift-offs.  It
runs end to end without compiled code; tests/test_oracle.py compares the product with
it impact by impact.  It shares only the problem statement (Scene), the result type
(Trajectory) and the named tolerances of the model with the product.

    from tests.oracle.simulate import simulate as oracle_simulate
"""
