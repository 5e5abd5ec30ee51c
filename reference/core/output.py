"""What the loop writes: samples, impacts, phases and chatter accumulation times, into
arrays the caller owns (`Output`).  The loop checks before each step that the rows it
may write are free (else it returns and the caller grows the arrays), so the overflow
flag is only a guard (`simulate` raises if it is ever set, rather than return a
trajectory with rows missing).  Samples beyond `max_samples` are dropped."""

from collections import namedtuple

from .inertia import kinetic_energy, potential_energy
from .jit import copy_into, hot
from .records import N_ACCUMULATIONS, N_IMPACTS, N_PHASES, N_SAMPLES, OVERFLOW

Output = namedtuple(
    "Output",
    [
        "sample_t",  # (cap, 2): t_hi, t_lo
        "sample_y",  # (cap, 13)
        "sample_e",  # (cap, 2): kinetic, potential energy
        "impacts",  # (cap, 6): reference.core.records.IMPACT_COLUMNS
        "phases",  # (cap, 6): reference.core.records.PHASE_COLUMNS
        "accumulations",  # (cap,): chatter accumulation times
        "counts",  # int64 (5,)
    ],
)


@hot
def push_sample(out, t_hi, t_lo, y, model, max_samples):
    """Record state y at time t_hi + t_lo with its energies."""
    n = out.counts[N_SAMPLES]
    if n >= max_samples:
        return
    if n >= out.sample_t.shape[0]:
        out.counts[OVERFLOW] = 1
        return
    out.sample_t[n, 0] = t_hi
    out.sample_t[n, 1] = t_lo
    copy_into(out.sample_y[n], y)
    out.sample_e[n, 0] = kinetic_energy(y, model.mass, model.i1, model.i3)
    out.sample_e[n, 1] = potential_energy(y, model.mass, model.gravity)
    out.counts[N_SAMPLES] = n + 1


@hot
def push_impact(out, t_hi, t_lo, contact, impulse, u_pre, u_post):
    n = out.counts[N_IMPACTS]
    if n >= out.impacts.shape[0]:
        out.counts[OVERFLOW] = 1
        return
    row = out.impacts[n]
    row[0], row[1], row[2], row[3], row[4], row[5] = t_hi, t_lo, contact, impulse, u_pre, u_post
    out.counts[N_IMPACTS] = n + 1


@hot
def push_phase(out, t_start, t_end, kind, held, n_held):
    n = out.counts[N_PHASES]
    if n >= out.phases.shape[0]:
        out.counts[OVERFLOW] = 1
        return
    row = out.phases[n]
    row[0], row[1], row[2] = t_start, t_end, kind
    for i in range(3):
        row[3 + i] = held[i] if i < n_held else -1
    out.counts[N_PHASES] = n + 1


@hot
def push_accumulation(out, t):
    n = out.counts[N_ACCUMULATIONS]
    if n >= out.accumulations.shape[0]:
        out.counts[OVERFLOW] = 1
        return
    out.accumulations[n] = t
    out.counts[N_ACCUMULATIONS] = n + 1
