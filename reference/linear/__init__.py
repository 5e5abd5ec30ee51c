"""The paper's linearised model (sections 2.4-4 and appendices) and its analyses.

- model:       f_k, Θ, U_k, R, a_contact, energy; LinearModel (n-gon or three bumps)
- kernel:      compiled exact event loop (quadratic motion, roots of quadratics)
- simulate:    run_linear (raw events), simulate_linear (Trajectory), run_linear_exponent
- laws:        the run past undecidable states under the core's impact laws (moreau, sequential)
- selfsimilar: self-similar motion: β, feasibility, stability of the reduced map C̄
- chatter:     R⁻¹U0 eigenvalues, CC / PCC, the rod's β_p, β_q, c_lin
- exponent:    the energy exponent c (regression on log(t_f − t), decade durations, period)
- alpha:       agreement of a full simulator with the linear model as α → 0
"""


def __getattr__(name: str):
    """`from reference.linear import simulate_linear` (the public API), loaded on first
    use so that importing the package does not import numba and the linear kernel."""
    if name in ("simulate_linear", "run_linear", "run_linear_exponent"):
        from . import simulate

        return getattr(simulate, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
