"""How a run stops: its status, the time, and the contacts it names (records.STATE's
status, info_t and info)."""

from .jit import hot_inline


@hot_inline
def end_run(state, status, contacts, n):
    """Stop with `status` at the current time, naming contacts[:n].  Inlined: its ~20
    callers pass a status constant and contact arrays of several types, each of which
    would be a signature of its own."""
    state.status = status
    state.info_t = state.t_hi
    state.n_info = min(n, state.info.shape[0])
    for i in range(state.n_info):
        state.info[i] = contacts[i]
