"""The compiled dispatch of the impact laws on their code (reference.core.laws): a
chain of tests, one per law with a function, built from the registry."""

import importlib

from .impact_laws import NOT_SETTLED
from .jit import hot, hot_inline
from .laws import LAWS


def law_function(law):
    """The compiled impulse function of a registry entry ("module:function" under
    reference.core, or a function itself)."""
    if callable(law.impulses):
        return law.impulses
    module, name = law.impulses.split(":")
    return getattr(importlib.import_module(f"reference.core.{module}"), name)


def dispatcher(laws=LAWS):
    """The compiled `solve(code, W, u_pre, gamma, k, lam, u_post, work)` of the laws
    with a function; (NOT_SETTLED, 0) for a code without one."""
    solve = _no_law
    for law in laws:
        if law.impulses is not None:
            solve = _link(law.code, law_function(law), solve)
    return solve


@hot
def _no_law(code, W, u_pre, gamma, k, lam, u_post, work):
    return NOT_SETTLED, 0


def _link(code, impulses, rest):
    # inlined by numba (its IR): the chain is one function in its caller, so each law
    # function is linked into the caller once, not once more per link of the chain
    @hot_inline
    def solve(law, W, u_pre, gamma, k, lam, u_post, work):
        if law == code:
            return impulses(W, u_pre, gamma, k, lam, u_post, work)
        return rest(law, W, u_pre, gamma, k, lam, u_post, work)

    return solve


solve_law = dispatcher()
