"""Exact event-driven integration of the linearised model (compiled with numba).

Between events the acceleration a is constant (free flight, or contacts held by constant
forces), so a gap is the quadratic g + v s + ½ a_k s² and every event time is the first
positive root of one; roots are taken in cancellation-free form (`first_hit`).  Events:

- impact at an open contact reaching gap 0 while approaching: p⁺ = U_k p⁻.  A contact
  held at that moment must come out separating or resting (paper §2.3), otherwise the
  impact is undecidable, as are two contacts reached at once (status SIMULTANEOUS);
- accumulation of a chatter sequence (Zeno), completed in closed form (below);
- with a simultaneity window T > 0, open contacts reaching the ground
  within T of the one reached first are reached together with it: status SIMULTANEOUS
  (REASON_WINDOW) on the state where the first is reached, the others flagged in
  `together` (their gaps, at most T|u|, not closed);
- under an impact law (reference.core.laws) other than `paper`, a stop SIMULTANEOUS is
  resolved by the law where it happens, inside the loop (`_law_event`: the exact core's
  law functions on the Delassus matrix F_S Θ⁻¹ F_Sᵀ; a self-similar bounce series
  completed in closed form), and the run goes on;
- at every event the held set is re-solved: forces from F_B Θ⁻¹ F_Bᵀ η = g 1 over the
  subsets B of the closed contacts; the admissible one has η ≥ 0 and no closed contact
  with negative normal acceleration (an LCP by enumeration; rank(F) closed contacts is
  the end of the motion: every coordinate the contacts see is then 0).

Scaling.  The state is kept normalised with two exact powers of two, q = 2^kq q̃,
p = 2^kv p̃, t = 2^(kq−kv) t̃.  The normalised system is the same model with gravity
g̃ = 2^(kq−2kv) g (the scaling invariance of section 2.6 when kq = 2kv; with gravity
negligible, as in gravity-free chatter where gaps shrink faster than p²/g, the two
scales separate).  kv keeps the energy Ẽ = ½ p̃ᵀΘp̃ + m g̃ h̃ (true E = 4^kv Ẽ) in [½, 2),
kq keeps the gaps O(1).  Multiplying by powers of two costs no digits, so runs follow
the energy down any number of decades; intervals are stored as (t̃, kq − kv) and
absolute time as a double-double (t_hi + t_lo).

Chatter completion.  After an impact at contact j in free flight (0 < γ < 1), the gap of
j is a bouncing ball under gravity: its further impacts are at pre-velocities −γ^m v⁺ and
end after T = 2 v⁺ / (g (1 − γ)).  The impulses act along Θ⁻¹ f_j only, so the state at
the accumulation point is exactly the Θ-orthogonal projection of the free-flight state at
T onto f_jᵀq = f_jᵀp = 0 -- provided no other contact is reached within T, which is
checked with the bound gap_c(s) ≥ gap_c − s (|v_c| + g T + |f_cᵀΘ⁻¹f_j| Λ) (Λ = total
remaining impulse).  It is done once v⁺ ≤ `chatter_tol` × the velocity scale
V = √(2E max f Θ⁻¹ f).  When the last six impacts involve only one or two contacts S
and the normal speed is ≤ `decouple_tol` × V, the sequence is completed the same way --
projection onto the constraints of S of the free state after T -- with T from the
geometric decay of the recent intervals per decade of speed; this T is the only
approximation (it moves the state by about decouple_tol × (error of T)/T relative).  If
another contact is then at the ground within roundoff, the accumulation is undecidable.

Code layout.  `start_kernel` sets up, `continue_kernel` runs `_step` (at most a budget of
passes per call, so that Python sees Ctrl-C between calls) until a status is set: an impact
now (`_impact_step`: the impact map, renormalisation, chatter completion), else the held
set and the motion to the next event (`_flight_step`), then, where the paper's rule stopped
undecided under a law, the law's event (`_law_event`).  The helpers share the run through
small tuples and arrays, unpacked at their top:

    model   = (F, thd, tinv, w, wmax, mass, gamma, rank_f)   constants of the body
    limits  = (t_end, max_impacts, log2_energy_floor, chatter_tol, decouple_tol, window,
               together, law)   the run's limits; the simultaneity window T (0: none), the
              contacts it found reached together (those of an impact the law left
              undecided, for the message) and the law's code
    lawws   = (law_mats, law_vecs, law_ints, law_order)   the law's scratch
    state   = (q, p, qs, ps, acc, held, closed)   normalised state, roundoff scales of q
              and p, acceleration of the segment, held contacts, closed contacts
    scratch = (q_pre, p_pre, qn, pn, work, cidx, hidx, sidx)   work vectors, index lists
    ring    = (rb_c, rb_ldt, rb_lu)   recent impacts: contact, log2 interval, log2 speed
    out     = (out_i, out_f, out_s, record_states)   the event rows
    si, sf  = integer and float run state (SI_*, SF_* below); info = the outcome record
"""

from __future__ import annotations

import math
import threading
import time
from contextlib import nullcontext

import numpy as np
from numba import njit, typeof

from ..compiled import clear_stale_jit_cache
from ..core import ir_only
from ..core.clock import time_until
from ..core.impact import bounce_ratio, chatter_impulse, impact_impulse, post_impact_velocity
from ..core.impact_laws import MAX_SEQUENTIAL_IMPACTS, SETTLED
from ..core.law_dispatch import solve_law
from ..core.law_event import LAW_MAX_REPEATS, NO_PROGRESS
from ..core.laws import LAW_PAPER
from ..core.records import LawWork
from ..core.tolerances import EPS  # unit roundoff of a double (one definition)
from .model import energy as model_energy

# numba's cache of this kernel holds the core's functions it calls: dropped when any of
# the core's or the linear model's sources changed (reference.compiled)
clear_stale_jit_cache()

# The event loop's helpers allocate nothing: they are compiled inline into continue_kernel
# (LLVM alwaysinline) and without reference counting (numba's own idiom for allocation-free
# helpers, e.g. numba.misc.mergesort).  Measured: as ordinary njit functions the split
# event loop ran 2.5-3 times slower than the single function it replaced.
_helper = njit(cache=True, forceinline=True, _nrt=False)

# The functions Python calls (`_python_entry`): compiled with machine code and cached.
# Every other function of this module is compiled only into them, to LLVM IR
# (`load_entry_points`); one that Python calls elsewhere (the law event's helpers that
# `laws.apply_law` calls) is compiled on that first call as numba's own, and cached.
PYTHON_ENTRY_POINTS: set[str] = set()


def _python_entry(function):
    """numba's `njit(cache=True)` for a function that Python calls, listed in
    PYTHON_ENTRY_POINTS."""
    PYTHON_ENTRY_POINTS.add(function.__name__)
    return njit(cache=True)(function)


def compiled_into_entry_points(module: str, qualname: str) -> bool:
    """Whether a function numba compiles is one of this module's not decorated
    `_python_entry`: compiled into the entry points only (`reference.core.ir_only`'s
    selection in `load_entry_points`)."""
    return module == __name__ and qualname not in PYTHON_ENTRY_POINTS


_LOADING = threading.Lock()
_entry_points_loaded = False  # by load_entry_points, in this process


def load_entry_points(start_args: tuple, continue_args: tuple) -> float:
    """`start_kernel` and `continue_kernel` compiled for the types of these arguments, or
    loaded from numba's cache, before a run is timed; returns the seconds taken (0 once
    they are in this process: every run passes the same types).  They compile with the
    functions only they call compiled to LLVM IR only (`reference.core.ir_only`): those
    are linked into the entry points' libraries and optimised there once, never turned
    into machine code or cached on their own (numba would optimise each one's library
    whole, its callees linked in, and again in every caller above it).  Where this numba
    lacks the parts `ir_only` replaces, they compile as numba does by default."""
    global _entry_points_loaded
    if _entry_points_loaded:
        return 0.0
    t0 = time.perf_counter()
    with _LOADING, _selecting_helpers():
        for entry, args in ((start_kernel, start_args), (continue_kernel, continue_args)):
            entry.compile(tuple(typeof(arg) for arg in args))
        _entry_points_loaded = True
    return time.perf_counter() - t0


def _selecting_helpers():
    """`ir_only` of the functions compiled into the entry points, the others read from
    numba's cache; nothing where this numba lacks the parts `ir_only` replaces."""
    if not ir_only.available():
        return nullcontext()
    return ir_only.ir_only(compiled_into_entry_points, load_cached=True)


# event kinds
INITIAL, IMPACT, ACCUMULATION, END = 0, 1, 2, 3
# status codes (map to reference.trajectory.Status)
T_END, SINGULARITY, SIMULTANEOUS, MAX_IMPACTS, FAILED = 0, 1, 2, 3, 4
# integer columns
I_KIND, I_CONTACT, I_CONTACT2, I_KV, I_KQ, I_HELD1, I_HELD2, I_DTE = range(8)
N_ICOLS = 8
# float columns
F_DT, F_DTN, F_THI, F_TLO, F_IMPULSE, F_VPRE, F_VPOST, F_EPRE, F_EPOST, F_LOG2E = range(10)
N_FCOLS = 10
# state columns (normalised): q_pre, p_pre, q_post, p_post, acceleration that follows
N_SCOLS = 15
# why a run stopped (info[5]), named like the exact core's statuses
# (reference.core.records.STATUS_*); messages: simulate.REASON_MESSAGES
REASON_NONE = 0  # t_end or max_impacts
REASON_SIMULTANEOUS = 1  # two contacts reached at once
REASON_PUSHED = 2  # an impact would drive a held contact into the ground
REASON_NO_ENERGY = 3  # the energy is exhausted (E ≤ 0)
REASON_ENERGY_EXHAUSTED = 4  # the energy fell below the floor
REASON_CHATTER_SIMULTANEOUS = 5  # a contact at the ground when a chatter accumulates
REASON_CHATTER2_SIMULTANEOUS = 6  # the same for a two-contact chatter
REASON_SINGULARITY = 7  # all contacts down (rank(F) closed)
REASON_FAILED_LCP = 8  # no admissible set of held contacts
REASON_BUFFER_FULL = 9  # the event buffer is full
REASON_FAILED_NO_ADVANCE = 10  # no further event and no end time
REASON_WINDOW = 11  # contacts reached within the simultaneity window of each other
REASON_LAW_UNDECIDED = 12  # the run's impact law left a simultaneous impact undecided
# the outcome record `info`: status, n_events, n_impacts, contact_a, contact_b, reason;
# the law's outcome (impact_laws.SETTLED …, law_event.NO_PROGRESS) and single impacts
# when it left an impact undecided; whether a bounce series ended the run; the
# simultaneous impacts the law resolved
INFO_LAW_OUTCOME, INFO_LAW_HITS, INFO_SERIES, INFO_LAW_IMPACTS = 6, 7, 8, 9
N_INFO = 10
RB = 64  # ring buffer of recent impacts
# integer run state `si`: scale exponents kv, kq; rows written; impacts resolved; ring
# buffer cursor and fill; status (−1 while running) and reason code; law impacts in a
# row without progress (`_law_progress`)
SI_KV, SI_KQ, SI_EVENTS, SI_IMPACTS, SI_RB_POS, SI_RB_N, SI_STATUS, SI_REASON = range(8)
SI_LAW_REPEATS = 8
N_SI = 9
# float run state `sf`: normalised gravity g̃; time t_hi + t_lo; normalised interval
# before the impact about to be resolved; time and true energy of the last law event
# (`_law_progress`); the time a bounce series started (`_bounce_series`)
SF_GRAVITY, SF_T_HI, SF_T_LO, SF_DT_PENDING, SF_LAW_T, SF_LAW_E, SF_SERIES_T = range(7)
N_SF = 7


@_python_entry
def first_hit(g, v, a):
    """First s > 0 with g + v s + a s²/2 = 0 reached while approaching (inf if none).
    g ≥ 0 is the gap now (g ≤ 0 is treated as touching), v its rate, a its acceleration.
    Roots are formed without cancellation: 2g/(√(v²−2ag) − v) for v ≤ 0, and
    (v + √(v²−2ag))/(−a) for v > 0 (a < 0)."""
    if g <= 0.0:
        if v > 0.0 and a < 0.0:
            return -2.0 * v / a
        return math.inf
    if a == 0.0:
        if v < 0.0:
            return g / -v
        return math.inf
    disc = v * v - 2.0 * a * g
    if a < 0.0:
        s = math.sqrt(disc)
        if v <= 0.0:
            if s - v == 0.0:  # v = 0 and a g below the smallest double: √(2g/|a|)
                return math.sqrt(2.0 * g / -a)
            return 2.0 * g / (s - v)
        return (v + s) / -a
    if v >= 0.0 or disc <= 0.0:
        return math.inf
    s = math.sqrt(disc)
    return 2.0 * g / (s - v)


@njit(cache=True)
def _two_sum(a, b):
    s = a + b
    bb = s - a
    err = (a - (s - bb)) + (b - bb)
    return s, err


@njit(cache=True)
def _add_time(t_hi, t_lo, dt):
    s, e = _two_sum(t_hi, dt)
    e += t_lo
    return _two_sum(s, e)


@njit(cache=True)
def _dot(F, c, x):
    return F[c, 0] * x[0] + F[c, 1] * x[1] + F[c, 2] * x[2]


@njit(cache=True)
def _tol(F, c, xs, floor):
    """Roundoff level of f_cᵀx: 64 ulps of the terms |f_ci| xs_i that formed it plus a
    floor at the motion's own scale."""
    return 64.0 * EPS * (abs(F[c, 0]) * xs[0] + abs(F[c, 1]) * xs[1] + abs(F[c, 2]) * xs[2] + floor)


@njit(cache=True)
def _w(F, tinv, a, b):
    return F[a, 0] * tinv[0] * F[b, 0] + F[a, 1] * tinv[1] * F[b, 1] + F[a, 2] * tinv[2] * F[b, 2]


@njit(cache=True)
def _project(x, F, tinv, idx, m):
    """In place: Θ-orthogonal projection of x onto {f_iᵀx = 0, i ∈ idx[:m]},
    x − Θ⁻¹F_Sᵀ (F_S Θ⁻¹ F_Sᵀ)⁻¹ F_S x (m ≤ 2 in closed form; m = 3 independent
    constraints leave x = 0)."""
    if m == 0:
        return
    if m >= 3:
        for i in range(3):
            x[i] = 0.0
        return
    i0 = idx[0]
    r0 = _dot(F, i0, x)
    if m == 1:
        lam0 = r0 / _w(F, tinv, i0, i0)
        for i in range(3):
            x[i] -= tinv[i] * F[i0, i] * lam0
        return
    i1 = idx[1]
    r1 = _dot(F, i1, x)
    a00, a01, a11 = _w(F, tinv, i0, i0), _w(F, tinv, i0, i1), _w(F, tinv, i1, i1)
    det = a00 * a11 - a01 * a01
    if det == 0.0:
        return
    lam0 = (a11 * r0 - a01 * r1) / det
    lam1 = (a00 * r1 - a01 * r0) / det
    for i in range(3):
        x[i] -= tinv[i] * (F[i0, i] * lam0 + F[i1, i] * lam1)


# ½ pᵀΘp + m g h (model.energy, compiled)
_energy = njit(cache=True)(model_energy)


@_helper
def _closed_indices(closed, idx, limit):
    """The first `limit` closed contacts' indices into idx; returns how many."""
    n = 0
    for c in range(closed.shape[0]):
        if closed[c] and n < limit:
            idx[n] = c
            n += 1
    return n


@_helper
def _one_held(F, tinv, g, i0, acc):
    """The force η = g/w₀₀ of contact i0 held alone and the acceleration Θ⁻¹f₀η − g u₃
    into acc (the paper, section 2.5, eq. pacccontact); returns η."""
    e = g / _w(F, tinv, i0, i0)
    for i in range(3):
        acc[i] = tinv[i] * F[i0, i] * e
    acc[2] -= g
    return e


@_helper
def _two_held_forces(F, tinv, g, i0, i1):
    """The forces (η₀, η₁) of contacts i0 and i1 held together, F_BΘ⁻¹F_Bᵀη = g 1;
    (nan, nan) when the pair is singular."""
    a00, a01, a11 = _w(F, tinv, i0, i0), _w(F, tinv, i0, i1), _w(F, tinv, i1, i1)
    det = a00 * a11 - a01 * a01
    if det == 0.0:
        return math.nan, math.nan
    return g * (a11 - a01) / det, g * (a00 - a01) / det


@_helper
def _two_held(F, tinv, g, i0, i1, e0, e1, acc):
    """The acceleration Θ⁻¹(f₀η₀ + f₁η₁) − g u₃ of contacts i0, i1 held with forces
    e0, e1 into acc."""
    for i in range(3):
        acc[i] = tinv[i] * (F[i0, i] * e0 + F[i1, i] * e1)
    acc[2] -= g


@njit(cache=True)
def _held_solve(F, tinv, g, closed_idx, m, acc, held):
    """Admissible held subset B of the closed contacts (m ≤ 2): the LCP
    F_B Θ⁻¹ F_Bᵀ η = g 1, η ≥ 0, and no closed contact outside B with negative normal
    acceleration, solved by enumeration (both, then each alone, then none).  Writes the
    acceleration into acc and the held contacts (−1 padded) into held; returns their
    number, or −1 if no subset is admissible."""
    for i in range(3):
        held[i] = -1
    tol = 1e-12 * g
    if m == 2:
        i0, i1 = closed_idx[0], closed_idx[1]
        e0, e1 = _two_held_forces(F, tinv, g, i0, i1)
        if e0 >= -tol and e1 >= -tol:  # (nan: singular)
            _two_held(F, tinv, g, i0, i1, e0, e1, acc)
            held[0] = i0
            held[1] = i1
            return 2
        for k in range(2):
            ih, io = closed_idx[k], closed_idx[1 - k]
            e = _one_held(F, tinv, g, ih, acc)
            if e >= -tol and _dot(F, io, acc) >= -tol:
                held[0] = ih
                return 1
    elif m == 1:
        ih = closed_idx[0]
        if _one_held(F, tinv, g, ih, acc) >= -tol:
            held[0] = ih
            return 1
    for i in range(3):
        acc[i] = 0.0
    acc[2] = -g
    for a in range(m):
        if _dot(F, closed_idx[a], acc) < -tol:
            return -1
    return 0


@njit(cache=True)
def _scale_q(F, q):
    s = 0.0
    for c in range(F.shape[0]):
        v = abs(F[c, 0] * q[0]) + abs(F[c, 1] * q[1]) + abs(F[c, 2] * q[2])
        if v > s:
            s = v
    return s


# ------------------------------------------------------------------ model and scales


@_python_entry
def _contact_products(F, tinv):
    """W = F Θ⁻¹ Fᵀ, w_ab = f_aᵀΘ⁻¹f_b: the change of contact a's normal velocity per unit
    impulse at contact b (the paper, section 2.5, eq. impactequ), and max_a w_aa."""
    nc = F.shape[0]
    w = np.zeros((nc, nc))
    for a in range(nc):
        for b in range(nc):
            w[a, b] = _w(F, tinv, a, b)
    wmax = 0.0
    for a in range(nc):
        wmax = max(wmax, w[a, a])
    return w, wmax


@_helper
def _velocity_scale(E, wmax):
    """V = √(2E max_a f_aᵀΘ⁻¹f_a): the largest normal speed the energy E allows (the
    energy of the paper, section 2.5, eq. Theta); floor of the velocity tolerances and
    unit of chatter_tol and decouple_tol."""
    return math.sqrt(2.0 * E * wmax)


@_helper
def _time_left(t_end, t_hi, t_lo, kv, kq):
    """Normalised time from t_hi + t_lo to t_end, t = 2^(kq−kv) t̃ (the scaling of the
    paper, section 2.6, eqs. scaleq and scalep); inf without t_end."""
    if math.isfinite(t_end):
        return math.ldexp(time_until(t_hi, t_lo, t_end), kv - kq)
    return math.inf


@_helper
def _scale3(x, k):
    """x ← 2^k x in place (exact: a power of two costs no digits; the scaling of the
    paper, section 2.6)."""
    for i in range(3):
        x[i] = math.ldexp(x[i], k)


@_helper
def _velocity_shift(E):
    """sv with 4^−sv E in [½, 2): the step of kv that renormalises the energy (0 if E ≤ 0)."""
    if E > 0.0:
        return math.frexp(E)[1] // 2
    return 0


@_helper
def _position_shift(F, q, min_shift):
    """sq with 2^−sq max_c |f_cᵀq| in [½, 1): the step of kq that brings the gaps back to
    O(1), or 0 when |sq| < min_shift (gaps still within 2^±min_shift) or q = 0."""
    lq = _scale_q(F, q)
    if lq > 0.0:
        sq = math.frexp(lq)[1]
        if sq >= min_shift or sq <= -min_shift:
            return sq
    return 0


@_helper
def _renormalise(F, q, p, qs, ps, E, si, sf, min_shift):
    """Exact rescaling by the paper's scaling invariance (section 2.6, eqs. scaleq, scalep;
    module docstring, Scaling): p̃ and its roundoff scale ps by 2^−sv so that the energy
    E returns to [½, 2), then q̃ and qs by 2^−sq (`_position_shift`); kv, kq and the
    normalised gravity g̃ = 2^(kq−2kv) g follow.  Returns sv."""
    sv = _velocity_shift(E)
    if sv != 0:
        _scale3(p, -sv)
        _scale3(ps, -sv)
        si[SI_KV] += sv
        sf[SF_GRAVITY] = math.ldexp(sf[SF_GRAVITY], -2 * sv)
    sq = _position_shift(F, q, min_shift)
    if sq != 0:
        _scale3(q, -sq)
        _scale3(qs, -sq)
        si[SI_KQ] += sq
        sf[SF_GRAVITY] = math.ldexp(sf[SF_GRAVITY], sq)
    return sv


# ------------------------------------------------------------------ event rows, outcome


@_helper
def _write_row(
    out, row, kind, c1, c2, kv, kq, held, dtn, t_hi, t_lo,
    imp, vpre, vpost, e_pre, e_post, q_pre, p_pre, q, p, acc,
):  # fmt: skip
    """One event row (columns I_*, F_* and the state columns): normalised inputs, true
    values where the column says so, via the exact scaling of the paper, section 2.6."""
    out_i, out_f, out_s, record = out
    out_i[row, I_KIND] = kind
    out_i[row, I_CONTACT] = c1
    out_i[row, I_CONTACT2] = c2
    out_i[row, I_KV] = kv
    out_i[row, I_KQ] = kq
    out_i[row, I_HELD1] = held[0]
    out_i[row, I_HELD2] = held[1]
    out_i[row, I_DTE] = kq - kv
    out_f[row, F_DTN] = dtn
    out_f[row, F_DT] = math.ldexp(dtn, kq - kv)
    out_f[row, F_THI] = t_hi
    out_f[row, F_TLO] = t_lo
    out_f[row, F_IMPULSE] = math.ldexp(imp, kv)
    out_f[row, F_VPRE] = math.ldexp(vpre, kv)
    out_f[row, F_VPOST] = math.ldexp(vpost, kv)
    out_f[row, F_EPRE] = e_pre
    out_f[row, F_EPOST] = e_post
    out_f[row, F_LOG2E] = math.log2(e_post) + 2 * kv if e_post > 0 else -math.inf
    if record:
        for i in range(3):
            out_s[row, i] = q_pre[i]
            out_s[row, 3 + i] = p_pre[i]
            out_s[row, 6 + i] = q[i]
            out_s[row, 9 + i] = p[i]
            out_s[row, 12 + i] = acc[i]


@_helper
def _write_state_row(out, row, kind, si, held, dtn, t_hi, t_lo, E, q, p, acc):
    """A row without an impact (INITIAL, END): state q, p before and after, energy E."""
    _write_row(out, row, kind, -1, -1, si[SI_KV], si[SI_KQ], held, dtn, t_hi, t_lo,
               0.0, 0.0, 0.0, E, E, q, p, q, p, acc)  # fmt: skip


@_helper
def _record_held_set(out, row, held, acc):
    """The held contacts and the acceleration of the segment after event `row` (the
    paper, section 2.5, eqs. paccfree and pacccontact), known once the set is settled."""
    out_i, out_f, out_s, record = out
    out_i[row, I_HELD1] = held[0]
    out_i[row, I_HELD2] = held[1]
    if record:
        for i in range(3):
            out_s[row, 12 + i] = acc[i]


@_helper
def _stop(si, info, status, reason, c1, c2):
    """End the run with `status` and `reason` (REASON_*); c1, c2 ≥ 0
    are the two contacts of an undecidable event (the paper, section 2.3)."""
    si[SI_STATUS] = status
    si[SI_REASON] = reason
    if c1 >= 0:
        info[3] = c1
        info[4] = c2


@_helper
def _write_info(si, info):
    """The outcome record: status, number of events and impacts, reason (bookkeeping,
    no equation of the paper)."""
    info[0] = si[SI_STATUS]
    info[1] = si[SI_EVENTS]
    info[2] = si[SI_IMPACTS]
    info[5] = si[SI_REASON]


# ------------------------------------------------------------------ contact states


@_helper
def _touching(F, c, q, qs):
    """Contact c at the ground within roundoff: gap f_cᵀq ≤ its roundoff level (the
    paper, section 2.4, eq. hi,vi)."""
    return _dot(F, c, q) <= _tol(F, c, qs, 0.0)


@_helper
def _resting(F, c, q, p, qs, ps, vfl):
    """Contact c touching with normal velocity f_cᵀp zero within roundoff (section 2.4)."""
    return _touching(F, c, q, qs) and abs(_dot(F, c, p)) <= _tol(F, c, ps, vfl)


@_helper
def _closing(F, c, p, ps, vfl):
    """Contact c's normal velocity f_cᵀp below zero beyond roundoff."""
    return _dot(F, c, p) < -_tol(F, c, ps, vfl)


@_helper
def _approaching(F, c, q, p, qs, ps, vfl):
    """Contact c touching and moving into the ground beyond roundoff: an impact now (the
    paper, section 2.3: u_Zᵀr_i = 0, u_Zᵀv_i < 0)."""
    return _touching(F, c, q, qs) and _closing(F, c, p, ps, vfl)


@_helper
def _close_resting_contacts(F, q, p, qs, ps, closed, vfl):
    """Close the contacts resting at the start (sustained contacts, section 2.2)."""
    for c in range(F.shape[0]):
        if _resting(F, c, q, p, qs, ps, vfl):
            closed[c] = True


@_helper
def _impacts_now(F, q, p, qs, ps, closed, vfl):
    """Open contacts approaching at gap 0: (how many, the first, the second; −1 none).
    One is a single impact, two at once are undecidable (the paper, section 2.3)."""
    ncand = 0
    cand = -1
    cand2 = -1
    for c in range(F.shape[0]):
        if closed[c] or not _approaching(F, c, q, p, qs, ps, vfl):
            continue
        ncand += 1
        if cand < 0:
            cand = c
        elif cand2 < 0:
            cand2 = c
    return ncand, cand, cand2


@_helper
def _any_closed(closed):
    """Whether any contact is closed, i.e. the body is not in free flight (the paper,
    section 2.5, eq. paccfree)."""
    for c in range(closed.shape[0]):
        if closed[c]:
            return True
    return False


# ------------------------------------------------------------------ impacts


@_helper
def _apply_impulse(F, tinv, w, gamma, j, q, p, q_pre, p_pre):
    """Impact at contact j (the paper, section 2.5, eqs. impactmap and impactequ): the
    exact core's law, λ = (u⁺ − u⁻)/f_jᵀΘ⁻¹f_j with u⁻ = f_jᵀp⁻
    (reference.core.impact.impact_impulse: −(1+γ) u⁻/w for Newton's law),
    p⁺ = p⁻ + Θ⁻¹f_j λ; q, p before into q_pre, p_pre.  Returns (u⁻, λ)."""
    vpre = _dot(F, j, p)
    lam = impact_impulse(vpre, w[j, j], gamma)
    for i in range(3):
        q_pre[i] = q[i]
        p_pre[i] = p[i]
    _add_impulse(F, tinv, j, lam, p)
    return vpre, lam


@_helper
def _add_impulse(F, tinv, c, lam, p):
    """p ← p + Θ⁻¹f_c λ: an impulse λ at contact c (eq. impactequ)."""
    for i in range(3):
        p[i] += tinv[i] * F[c, i] * lam


@_helper
def _release_held_contacts(F, closed, p_pre, p, work, vfl):
    """The paper's rule for contacts held at an impact (section 2.3): each must come out
    resting (stays closed) or separating (opened here).  Returns the last one driven into
    the ground (the impact is then undecidable), −1 if none."""
    for i in range(3):
        work[i] = abs(p_pre[i]) + abs(p[i])
    bad = -1
    for c in range(F.shape[0]):
        if not closed[c]:
            continue
        vc = _dot(F, c, p)
        tol = _tol(F, c, work, vfl)
        if vc < -tol:
            bad = c
        elif vc > tol:
            closed[c] = False
    return bad


@_helper
def _hold_after_impact(F, tinv, gamma, j, p, closed, hidx):
    """After a plastic impact (γ = 0, the paper, section 2.3, eq. utk3) contact j stays
    down; p is projected onto the closed contacts (at most three; sustained contacts,
    section 2.2), whose normal velocities are then exactly 0."""
    if bounce_ratio(gamma) == 0.0:
        closed[j] = True
    nh = _closed_indices(closed, hidx, 3)
    if nh > 0:
        _project(p, F, tinv, hidx, nh)


@_helper
def _remember_impact(ring, si, j, dtn, vpre):
    """Push the impact at j onto the ring buffer of recent impacts: contact, log2 of the
    true interval before it, log2 of its true approach speed (−1e300 for 0); read by the
    chatter completion (module docstring; the paper, sections 4.1 and 4.3)."""
    rb_c, rb_ldt, rb_lu = ring
    kv, kq = si[SI_KV], si[SI_KQ]
    pos = (si[SI_RB_POS] + 1) % RB
    rb_c[pos] = j
    rb_ldt[pos] = (math.log2(dtn) if dtn > 0 else -1e300) + (kq - kv)
    rb_lu[pos] = (math.log2(abs(vpre)) if vpre != 0.0 else -1e300) + kv
    si[SI_RB_POS] = pos
    si[SI_RB_N] = min(si[SI_RB_N] + 1, RB)


@_helper
def _resolve_impact(model, state, scratch, ring, out, si, sf, info, j, E, vfl):
    """Impact at contact j with energy E before it (the paper, sections 2.3 and 2.5):
    the impact map, the rule for held contacts (else SIMULTANEOUS, REASON_PUSHED, state
    before the impact kept), the IMPACT row, the ring buffer and the renormalisation.
    Returns the approach velocity f_jᵀp⁻ in the new scales."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    q_pre, p_pre, qn, pn, work, cidx, hidx, sidx = scratch
    vpre, lam = _apply_impulse(F, tinv, w, gamma, j, q, p, q_pre, p_pre)
    bad = _release_held_contacts(F, closed, p_pre, p, work, vfl)
    if bad >= 0:
        for i in range(3):
            p[i] = p_pre[i]  # report the state before the undecidable impact
        _stop(si, info, SIMULTANEOUS, REASON_PUSHED, j, bad)
        return vpre
    _hold_after_impact(F, tinv, gamma, j, p, closed, hidx)
    vpost = post_impact_velocity(vpre, gamma) if bounce_ratio(gamma) > 0.0 else _dot(F, j, p)
    for i in range(3):
        ps[i] = abs(p_pre[i]) + abs(p[i])
    si[SI_IMPACTS] += 1
    E_post = _energy(q, p, thd, mass, sf[SF_GRAVITY])
    # the interval before this impact was measured in the scales of the row
    dtn = sf[SF_DT_PENDING]
    _write_row(out, si[SI_EVENTS], IMPACT, j, -1, si[SI_KV], si[SI_KQ], held, dtn,
               sf[SF_T_HI], sf[SF_T_LO], lam, vpre, vpost, E, E_post, q_pre, p_pre, q, p,
               acc)  # fmt: skip
    si[SI_EVENTS] += 1
    _remember_impact(ring, si, j, dtn, vpre)
    sf[SF_DT_PENDING] = 0.0
    sv = _renormalise(F, q, p, qs, ps, E_post, si, sf, 5)
    if sv != 0:
        vpre = math.ldexp(vpre, -sv)
    return vpre


@_helper
def _impact_step(model, limits, state, scratch, ring, out, si, sf, info, j, E, vfl):
    """An impact at contact j now: stop at max_impacts (or a full event buffer), resolve
    the impact, stop once the energy is exhausted (REASON_NO_ENERGY) or below the floor
    (REASON_ENERGY_EXHAUSTED: the singularity, the paper, section 1), then complete a
    chatter sequence in free flight (0 < γ < 1) where possible."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    t_end, max_impacts, log2_energy_floor, chatter_tol, decouple_tol = limits[:5]
    q, p, qs, ps, acc, held, closed = state
    if si[SI_IMPACTS] >= max_impacts or si[SI_EVENTS] + 3 >= out[0].shape[0]:
        _stop(si, info, MAX_IMPACTS, REASON_NONE, -1, -1)
        return
    vpre = _resolve_impact(model, state, scratch, ring, out, si, sf, info, j, E, vfl)
    if si[SI_STATUS] >= 0:
        return
    E = _energy(q, p, thd, mass, sf[SF_GRAVITY])
    if _energy_ended(si, info, E, log2_energy_floor):
        return
    if 0.0 < bounce_ratio(gamma) < 1.0 and not _any_closed(closed):
        _complete_chatter(model, limits, state, scratch, ring, out, si, sf, info, j, E, vpre)


@_helper
def _energy_ended(si, info, E, log2_energy_floor):
    """After an impact: stop the run, a singularity, when the energy E (in the scaled
    units) is gone or below the floor; returns whether it stopped."""
    if not (E > 0.0):
        _stop(si, info, SINGULARITY, REASON_NO_ENERGY, -1, -1)
        return True
    if math.log2(E) + 2 * si[SI_KV] <= log2_energy_floor:
        _stop(si, info, SINGULARITY, REASON_ENERGY_EXHAUSTED, -1, -1)
        return True
    return False


# ------------------------------------------------------------------ chatter completion


@njit(cache=True)
def _remaining_log2_time(rb_c, rb_ldt, rb_lu, pos, n):
    """log2 of the time still to come in a chatter sequence, from the recent impacts:
    with a the latest impact at least 10× faster than the last one and b the latest at
    least 100× faster, r = D(a→last)/D(b→a) and the rest is D(a→last) r/(1 − r)
    (geometric decay per decade of speed).  −inf when there is no estimate."""
    lu_last = rb_lu[pos]
    step = math.log2(10.0)
    ia = -1
    ib = -1
    for b in range(1, n):
        lu = rb_lu[(pos - b) % RB]
        if ia < 0 and lu >= lu_last + step:
            ia = b
        if ib < 0 and lu >= lu_last + 2.0 * step:
            ib = b
            break
    if ia < 0 or ib < 0:
        return -math.inf
    ref = rb_ldt[pos]
    d_a = 0.0
    for b in range(0, ia):
        d_a += math.exp2(rb_ldt[(pos - b) % RB] - ref)
    d_b = 0.0
    for b in range(ia, ib):
        d_b += math.exp2(rb_ldt[(pos - b) % RB] - ref)
    if not (d_b > 0.0):
        return -math.inf
    r = d_a / d_b
    if not (0.0 < r < 1.0):
        return -math.inf
    return math.log2(d_a * r / (1.0 - r)) + ref


@_helper
def _recent_partner(rb_c, pos, j):
    """The contacts of the last six impacts besides j: (the other one, −1 if none; how
    many distinct contacts in all, 3 standing for more than two).  Chatter at one or two
    contacts: the paper, sections 4.1 and 4.3."""
    other = -1
    nset = 1
    for b in range(6):
        c = rb_c[(pos - b) % RB]
        if c != j:
            if other < 0:
                other = c
                nset = 2
            elif c != other:
                nset = 3
    return other, nset


@_helper
def _alone_until_accumulation(F, w, q, p, qs, j, gamma, gt, T, vplus):
    """Whether no contact but j can reach the ground within the remaining duration T of
    j's chatter: gap_c − T (|v_c| + g T + |w_cj| Λ) above roundoff for every other c, with
    Λ the total impulse still to come (reference.core.impact.chatter_impulse: (1+γ) v⁺ /
    (w_jj (1−γ)) for Newton's law; module docstring)."""
    lam_tot = chatter_impulse(vplus, w[j, j], gamma)
    for c in range(F.shape[0]):
        if c == j:
            continue
        vmax = abs(_dot(F, c, p)) + gt * T + abs(w[c, j]) * lam_tot
        if _dot(F, c, q) - T * vmax <= _tol(F, c, qs, 0.0):
            return False
    return True


@_helper
def _decoupled_chatter(ring, si, j, vpre, vplus, fall, T, sidx):
    """Completion without the proof (module docstring): the last six impacts at j alone
    (with gravity; T as given, the bouncing-ball duration) or at j and one other contact
    (into sidx[1]; T from the geometric decay of the recent intervals, else from the fall
    time 2 max(|v⁻|, v⁺)/(g(1−γ))).  Returns (number of contacts, T); 0 for none."""
    rb_c, rb_ldt, rb_lu = ring
    pos = si[SI_RB_POS]
    other, nset = _recent_partner(rb_c, pos, j)
    if nset == 1 and fall > 0.0:
        return 1, T
    if nset == 2:
        sidx[1] = other
        lT = _remaining_log2_time(rb_c, rb_ldt, rb_lu, pos, si[SI_RB_N])
        if lT > -1e300:
            return 2, math.exp2(lT - (si[SI_KQ] - si[SI_KV]))
        if fall > 0.0:
            return 2, 2.0 * max(abs(vpre), vplus) / fall
    return 0, T


@_helper
def _chatter_plan(model, limits, state, sidx, ring, si, sf, j, E, vpre):
    """Whether and how to complete the chatter at j just after its impact (module
    docstring; chatter sequences that end in finite time: the paper, sections 4.1 and
    4.3).  Returns (number of chattering contacts, 0 for not now; their remaining
    normalised duration T; whether the completion is exact) and the contacts in sidx.
    Exact: v⁺ ≤ chatter_tol V, T = 2v⁺/(g(1−γ)) before t_end and j provably alone;
    otherwise `_decoupled_chatter` once |v⁻| ≤ decouple_tol V, if T comes before t_end."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    t_end, max_impacts, log2_energy_floor, chatter_tol, decouple_tol = limits[:5]
    q, p, qs, ps, acc, held, closed = state
    gt = sf[SF_GRAVITY]
    vplus = _dot(F, j, p)
    vel_scale = _velocity_scale(E, wmax)
    rem = _time_left(t_end, sf[SF_T_HI], sf[SF_T_LO], si[SI_KV], si[SI_KQ])
    fall = gt * (1.0 - bounce_ratio(gamma))  # may underflow when gravity is negligible
    T = 2.0 * vplus / fall if fall > 0.0 else math.inf
    sidx[0] = j
    sidx[1] = -1
    if 0.0 < vplus <= chatter_tol * vel_scale and T < math.inf and T <= rem:
        # one contact, provably alone until its accumulation: exact
        if _alone_until_accumulation(F, w, q, p, qs, j, gamma, gt, T, vplus):
            return 1, T, True
    if abs(vpre) <= decouple_tol * vel_scale and si[SI_RB_N] >= 6:
        m_s, T = _decoupled_chatter(ring, si, j, vpre, vplus, fall, T, sidx)
        if m_s > 0 and not T <= rem:
            m_s = 0
        return m_s, T, False
    return 0, T, False


@_helper
def _free_flight(q, p, qs, ps, qn, pn, gt, T):
    """Free flight for T from q, p (the paper, section 2.5, eq. paccfree: ṗ = −g u3)
    into qn, pn; the roundoff scales of the result into qs, ps."""
    for i in range(3):
        qs[i] = abs(q[i]) + abs(p[i]) * T
        ps[i] = abs(p[i])
        qn[i] = q[i] + p[i] * T
        pn[i] = p[i]
    qs[2] += 0.5 * gt * T * T
    ps[2] += gt * T
    qn[2] -= 0.5 * gt * T * T
    pn[2] -= gt * T


@_helper
def _accumulate(model, state, scratch, out, si, sf, j, m_s, T, E, vpre):
    """Jump to the accumulation point of the chatter at sidx[:m_s] after T: the
    Θ-orthogonal projection of the free-flight state onto f_sᵀq = f_sᵀp = 0 (module
    docstring); those contacts close.  Writes the ACCUMULATION row (impulse
    −f_jᵀp(T)/w_jj for one contact, NaN for two) and advances the time."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    q_pre, p_pre, qn, pn, work, cidx, hidx, sidx = scratch
    gt = sf[SF_GRAVITY]
    for i in range(3):
        q_pre[i] = q[i]
        p_pre[i] = p[i]
    _free_flight(q, p, qs, ps, qn, pn, gt, T)
    lam_acc = -_dot(F, j, pn) / w[j, j] if m_s == 1 else math.nan
    for i in range(3):
        q[i] = qn[i]
        p[i] = pn[i]
    _project(q, F, tinv, sidx, m_s)
    _project(p, F, tinv, sidx, m_s)
    kv, kq = si[SI_KV], si[SI_KQ]
    t_hi, t_lo = _add_time(sf[SF_T_HI], sf[SF_T_LO], math.ldexp(T, kq - kv))
    sf[SF_T_HI] = t_hi
    sf[SF_T_LO] = t_lo
    for b in range(m_s):
        closed[sidx[b]] = True
    Ea = _energy(q, p, thd, mass, gt)
    _write_row(out, si[SI_EVENTS], ACCUMULATION, sidx[0], sidx[1] if m_s == 2 else -1, kv,
               kq, held, T, t_hi, t_lo, lam_acc, abs(vpre), 0.0, E, Ea, q_pre, p_pre, q, p,
               acc)  # fmt: skip
    si[SI_EVENTS] += 1
    si[SI_RB_N] = 0


@_helper
def _check_accumulation(F, q, qs, closed, si, info, j, m_s):
    """After a completion without proof: another contact at the ground within roundoff
    makes the accumulation undecidable (SIMULTANEOUS; REASON_CHATTER_SIMULTANEOUS for
    one chattering contact, REASON_CHATTER2_SIMULTANEOUS for two; the last such contact
    is reported)."""
    for c in range(F.shape[0]):
        if closed[c]:
            continue
        if _touching(F, c, q, qs):
            reason = REASON_CHATTER_SIMULTANEOUS if m_s == 1 else REASON_CHATTER2_SIMULTANEOUS
            _stop(si, info, SIMULTANEOUS, reason, j, c)


@_helper
def _complete_chatter(model, limits, state, scratch, ring, out, si, sf, info, j, E, vpre):
    """Complete the chatter sequence at j in closed form when `_chatter_plan` allows it
    (module docstring, Chatter completion)."""
    sidx = scratch[7]
    m_s, T, exact = _chatter_plan(model, limits, state, sidx, ring, si, sf, j, E, vpre)
    if m_s == 0:
        return
    _accumulate(model, state, scratch, out, si, sf, j, m_s, T, E, vpre)
    if not exact:
        q, p, qs, ps, acc, held, closed = state
        _check_accumulation(model[0], q, qs, closed, si, info, j, m_s)


# ------------------------------------------------------------------ held set, flight


@_helper
def _lift_off(F, cidx, ncl, held, acc, closed):
    """Open the closed contacts outside the held set that accelerate away (f_cᵀṗ > 0)."""
    for a in range(ncl):
        c = cidx[a]
        if c != held[0] and c != held[1] and c != held[2] and _dot(F, c, acc) > 0.0:
            closed[c] = False  # closed, not held, accelerating away: lift-off


@_helper
def _touch_down(F, q, p, qs, ps, acc, closed, vfl):
    """Close the open contacts resting at the ground and pushed into it (f_cᵀṗ < 0);
    returns whether any was."""
    added = False
    for c in range(F.shape[0]):
        if closed[c]:
            continue
        if _resting(F, c, q, p, qs, ps, vfl) and _dot(F, c, acc) < 0.0:
            closed[c] = True  # touching at rest and pushed down
            added = True
    return added


@_helper
def _settle_held_set(model, state, cidx, gt, vfl):
    """Re-solve the held set at an event (module docstring; sustained contacts: the
    paper, sections 2.2 and 2.5, eq. pacccontact): held contacts and acceleration into
    state, up to four rounds of lift-off and touch-down.  Returns REASON_NONE, or the
    reason to stop: REASON_SINGULARITY when rank(F) contacts are closed (the body lies on
    the ground, section 2.2), REASON_FAILED_LCP when no held subset is admissible."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    ncl = _closed_indices(closed, cidx, F.shape[0])
    if ncl >= rank_f:
        return REASON_SINGULARITY
    for _it in range(4):
        if _held_solve(F, tinv, gt, cidx, ncl, acc, held) < 0:
            return REASON_FAILED_LCP
        _lift_off(F, cidx, ncl, held, acc, closed)
        if not _touch_down(F, q, p, qs, ps, acc, closed, vfl):
            return REASON_NONE
        ncl = _closed_indices(closed, cidx, F.shape[0])
        if ncl >= rank_f:
            return REASON_SINGULARITY
    return REASON_NONE


@_helper
def _held_indices(held, hidx):
    """The held contacts (the set B of the paper's eq. pacccontact, section 2.5; held is
    −1 padded) into hidx; returns how many."""
    nh = 0
    for b in range(3):
        if held[b] >= 0:
            hidx[nh] = held[b]
            nh += 1
    return nh


@_helper
def _time_to_contact(F, c, q, p, qs, ps, acc, vfl):
    """Time until open contact c reaches the ground on the current quadratic (the
    paper, section 2.4: gap f_cᵀq, velocity f_cᵀp, acceleration f_cᵀṗ); inf if it never
    does or is touching without approaching beyond roundoff (it leaves)."""
    gap = _dot(F, c, q)
    v = _dot(F, c, p)
    ac = _dot(F, c, acc)
    if gap <= _tol(F, c, qs, 0.0):
        if v <= _tol(F, c, ps, vfl):
            return math.inf  # touching, not approaching, not pushed down: leaves
        return first_hit(0.0, v, ac)
    return first_hit(gap, v, ac)


@_helper
def _next_contact(F, q, p, qs, ps, acc, closed, vfl):
    """The first open contact to reach the ground: (time, contact); (inf, −1) if none."""
    tmin = math.inf
    jmin = -1
    for c in range(F.shape[0]):
        if closed[c]:
            continue
        tc = _time_to_contact(F, c, q, p, qs, ps, acc, vfl)
        if tc < tmin:
            tmin = tc
            jmin = c
    return tmin, jmin


@_helper
def _advance(q, p, qs, ps, acc, t):
    """Motion for t under the constant acceleration of the segment (the paper, section
    2.5, eqs. paccfree and pacccontact), with the roundoff scales of the result."""
    for i in range(3):
        qs[i] = abs(q[i]) + abs(p[i]) * t + 0.5 * abs(acc[i]) * t * t
        ps[i] = abs(p[i]) + abs(acc[i]) * t
        q[i] = q[i] + p[i] * t + 0.5 * acc[i] * t * t
        p[i] = p[i] + acc[i] * t


@_helper
def _end_at_t_end(model, state, out, si, sf, t_end, dtn):
    """The run reached t_end, dtn (normalised) after the last event: END row, T_END."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    sf[SF_T_HI] = t_end
    sf[SF_T_LO] = 0.0
    E = _energy(q, p, thd, mass, sf[SF_GRAVITY])
    _write_state_row(out, si[SI_EVENTS], END, si, held, dtn, t_end, 0.0, E, q, p, acc)
    si[SI_EVENTS] += 1
    si[SI_STATUS] = T_END


@_helper
def _flight_step(model, limits, state, scratch, out, si, sf, info, vfl):
    """No impact now: settle the held set, then move on the quadratic segment (held
    contacts kept exactly at the ground) to the next event -- the first open contact
    reaching the ground, whose gap is then set exactly to 0, or t_end."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    t_end = limits[0]
    q, p, qs, ps, acc, held, closed = state
    hidx = scratch[6]
    reason = _settle_held_set(model, state, scratch[5], sf[SF_GRAVITY], vfl)
    if reason != REASON_NONE:
        status = SINGULARITY if reason == REASON_SINGULARITY else FAILED
        _stop(si, info, status, reason, -1, -1)
        return
    _record_held_set(out, si[SI_EVENTS] - 1, held, acc)
    nh = _held_indices(held, hidx)
    tmin, jmin = _next_contact(F, q, p, qs, ps, acc, closed, vfl)
    rem = _time_left(t_end, sf[SF_T_HI], sf[SF_T_LO], si[SI_KV], si[SI_KQ])
    if tmin >= rem or jmin < 0:
        if not math.isfinite(rem):
            _stop(si, info, FAILED, REASON_FAILED_NO_ADVANCE, -1, -1)
            return
        tmin = max(rem, 0.0)
        jmin = -1
    other = -1
    if limits[5] > 0.0 and jmin >= 0:  # the simultaneity window (0: skipped)
        window = math.ldexp(limits[5], si[SI_KV] - si[SI_KQ])
        other = _reached_together(F, q, p, qs, ps, acc, closed, vfl, jmin, tmin + window,
                                  limits[6])  # fmt: skip
    _advance(q, p, qs, ps, acc, tmin)
    if nh > 0:
        _project(q, F, tinv, hidx, nh)
        _project(p, F, tinv, hidx, nh)
    if jmin < 0:
        _end_at_t_end(model, state, out, si, sf, t_end, tmin)
        return
    # the contact reached: its gap exactly zero (with the held ones)
    if nh < 3:
        hidx[nh] = jmin
        _project(q, F, tinv, hidx, nh + 1)
    t_hi, t_lo = _add_time(sf[SF_T_HI], sf[SF_T_LO], math.ldexp(tmin, si[SI_KQ] - si[SI_KV]))
    sf[SF_T_HI] = t_hi
    sf[SF_T_LO] = t_lo
    sf[SF_DT_PENDING] = tmin
    if other >= 0:
        _stop(si, info, SIMULTANEOUS, REASON_WINDOW, jmin, other)


@_helper
def _reached_together(F, q, p, qs, ps, acc, closed, vfl, jmin, t_window, together):
    """The simultaneity window: the open contacts other than jmin that reach
    the ground by t_window (normalised) are reached together with it; they and jmin are
    flagged in `together` (cleared first).  Returns one of them, −1 if none."""
    other = -1
    for c in range(F.shape[0]):
        together[c] = False
    for c in range(F.shape[0]):
        if closed[c] or c == jmin:
            continue
        if _time_to_contact(F, c, q, p, qs, ps, acc, vfl) <= t_window:
            together[c] = True
            other = c
    if other >= 0:
        together[jmin] = True
    return other


# ------------------------------------------------------------------ impact laws

# a contact leaves a law impact when its u⁺ exceeds this many ulps of the velocity scale
LEAVING_ULPS = 64.0
# a bounce series is self-similar when p⁺ and the acceleration after are parallel and
# the law maps −p⁺ to γp⁺, each to this relative residual (roundoff: ~1e-15 measured)
SELF_SIMILAR_TOL = 1e-9


@njit(cache=True)
def law_contacts(F, q, p, qs, ps, vfl, together, with_together, out):
    """The contacts of a simultaneous impact under an impact law, ascending, into out:
    every contact touching the ground within roundoff and not separating beyond it
    (normal velocity f_cᵀp ≤ its roundoff level; held contacts are in, a contact leaving
    is not: a law's impulse on a separating contact could do positive work, docs/laws.md,
    "The laws"), and with `with_together` those the simultaneity window flagged in
    `together` (their gaps, at most T|u|, are not closed: as in the exact core).
    Returns how many."""
    n = 0
    for c in range(F.shape[0]):
        touching = _touching(F, c, q, qs) and _dot(F, c, p) <= _tol(F, c, ps, vfl)
        if touching or (with_together and together[c]):
            out[n] = c
            n += 1
    return n


@_helper
def _law_progress(si, sf, e_true):
    """Whether the law may act at this stop: the time moved since the last law event,
    or the true energy fell below half its value there (a cascade of simultaneous
    impacts whose intervals are below the clock's resolution), or fewer than
    LAW_MAX_REPEATS stops came without either."""
    if sf[SF_T_HI] == sf[SF_LAW_T] and not e_true < 0.5 * sf[SF_LAW_E]:
        si[SI_LAW_REPEATS] += 1
    else:
        si[SI_LAW_REPEATS] = 0
        sf[SF_LAW_T] = sf[SF_T_HI]
        sf[SF_LAW_E] = e_true
    return si[SI_LAW_REPEATS] < LAW_MAX_REPEATS


@_helper
def _law_failed(si, info, together, contacts, k, outcome, hits):
    """End the run undecided by the law (SIMULTANEOUS, REASON_LAW_UNDECIDED): its outcome
    and single impacts into info, the contacts of the impact flagged in `together`."""
    for c in range(together.shape[0]):
        together[c] = False
    for i in range(k):
        together[contacts[i]] = True
    info[INFO_LAW_OUTCOME] = outcome
    info[INFO_LAW_HITS] = hits
    _stop(si, info, SIMULTANEOUS, REASON_LAW_UNDECIDED, -1, -1)


@_helper
def _any_approaching(F, p, ps, vfl, contacts, k):
    """Whether a contact of contacts[:k] approaches beyond roundoff."""
    for i in range(k):
        if _closing(F, contacts[i], p, ps, vfl):
            return True
    return False


@_helper
def _law_impulses(model, law, p, contacts, k, gamma, lawws):
    """(status, single impacts) of the run's law on contacts[:k] (the exact core's law
    functions through its dispatch, law_dispatch.solve_law): Delassus matrix
    W = F_S Θ⁻¹ F_Sᵀ (w_ab = f_aᵀΘ⁻¹f_b, the change of contact a's normal velocity per
    unit impulse at b, from Θ Δp = Σ f_b λ_b: the paper, section 2.5, eqs. Theta and
    impactequ) and u⁻ = F_S p into the scratch; Λ and u⁺ = u⁻ + WΛ out.  With one
    contact this is `_apply_impulse`'s impact, bit for bit (eq. F)."""
    F, w = model[0], model[3]
    mats, vecs, ints, order = lawws
    nc = F.shape[0]
    W, chol = mats[:nc], mats[nc:]
    u_pre, lam, u_post, vec = vecs[:nc], vecs[nc : 2 * nc], vecs[2 * nc : 3 * nc], vecs[3 * nc :]
    active = ints[nc : 2 * nc]
    for a in range(k):
        u_pre[a] = _dot(F, contacts[a], p)
        lam[a] = 0.0
        u_post[a] = 0.0
        active[a] = 0
        for b in range(k):
            W[a, b] = w[contacts[a], contacts[b]]
            chol[a, b] = 0.0
    for i in range(vec.shape[0]):
        vec[i] = 0.0
    work = LawWork(chol, vec, active, order, 0, MAX_SEQUENTIAL_IMPACTS)
    return solve_law(law, W, u_pre, gamma, k, lam, u_post, work)


@_helper
def _add_law_impulses(F, tinv, contacts, k, lam, p):
    """p ← p + Θ⁻¹F_SᵀΛ, contact by contact (as `_apply_impulse`)."""
    for i in range(k):
        if lam[i] != 0.0:
            _add_impulse(F, tinv, contacts[i], lam[i], p)


@_helper
def _law_completes(u_post, k, gamma, below):
    """Whether, with 0 < γ < 1, some contact leaves the impact (u⁺ above LEAVING_ULPS
    ulps of `below`) and every one that does leaves at u⁺ ≤ `below`: the bounces that
    would follow are too small to follow and the impact is taken plastic."""
    if not (0.0 < gamma < 1.0 and below > 0.0):
        return False
    noise = LEAVING_ULPS * EPS * below
    leaving = False
    for i in range(k):
        if u_post[i] > noise:
            if u_post[i] > below:
                return False
            leaving = True
    return leaving


@_helper
def _law_rows(out, si, sf, held, acc, contacts, k, lawws, E, E_post, q, p_pre, p):
    """One IMPACT row per contact that took an impulse, at the impact's time (the first
    carries the interval before it, the others 0)."""
    nc = contacts.shape[0]
    vecs = lawws[1]
    u_pre, lam, u_post = vecs[:nc], vecs[nc : 2 * nc], vecs[2 * nc : 3 * nc]
    dtn = sf[SF_DT_PENDING]
    for i in range(k):
        if lam[i] > 0.0:
            _write_row(out, si[SI_EVENTS], IMPACT, contacts[i], -1, si[SI_KV], si[SI_KQ],
                       held, dtn, sf[SF_T_HI], sf[SF_T_LO], lam[i], u_pre[i], u_post[i], E,
                       E_post, q, p_pre, q, p, acc)  # fmt: skip
            si[SI_EVENTS] += 1
            si[SI_IMPACTS] += 1
            dtn = 0.0
    sf[SF_DT_PENDING] = 0.0


@_helper
def _rest_acceleration(F, tinv, g, rest, m, acc):
    """The constant acceleration with the m ≤ 2 contacts rest[:m] held (F_B Θ⁻¹ F_Bᵀ η
    = g 1, ṗ = Θ⁻¹F_Bᵀη − g u3: the paper, section 2.5, eq. pacccontact) into acc;
    False when a force η comes out negative (or the set is singular).  Unlike
    `_held_solve` every contact must be held, with no roundoff allowance: the series
    rests on all of them."""
    if m == 1:
        return _one_held(F, tinv, g, rest[0], acc) >= 0.0
    if m == 2:
        e0, e1 = _two_held_forces(F, tinv, g, rest[0], rest[1])
        if not (e0 >= 0.0 and e1 >= 0.0):  # (nan: singular)
            return False
        _two_held(F, tinv, g, rest[0], rest[1], e0, e1, acc)
        return True
    for i in range(3):
        acc[i] = 0.0
    acc[2] = -g
    return True


@_helper
def _theta_dot(thd, x, y):
    """xᵀΘy."""
    return x[0] * (thd[0] * y[0]) + x[1] * (thd[1] * y[1]) + x[2] * (thd[2] * y[2])


@_helper
def _series_rate(model, p, contacts, k, u_post, vfl, gt, rest, a):
    """κ of the self-similar bounce series a law impact at q = 0 (every contact touching)
    that left p⁺ = p may start (`_bounce_series`), with the contacts left resting (|u⁺|
    within LEAVING_ULPS ulps of vfl) into rest and their held acceleration into a; 0
    when it starts none: a contact leaves, fewer than rank(F) rest, their forces are
    ≥ 0, and a = −κp⁺ with κ > 0 (to SELF_SIMILAR_TOL, in the Θ norm)."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    noise = LEAVING_ULPS * EPS * vfl
    m = 0
    leaving = False
    for i in range(k):
        if abs(u_post[i]) <= noise:
            if m < 3:
                rest[m] = contacts[i]
            m += 1
        elif u_post[i] > noise:
            leaving = True
    if m >= rank_f or not leaving or not _rest_acceleration(F, tinv, gt, rest, m, a):
        return 0.0, m
    norm2 = _theta_dot(thd, p, p)
    kappa = -_theta_dot(thd, a, p) / norm2
    r2 = 0.0
    for i in range(3):
        r = a[i] + kappa * p[i]
        r2 += r * (thd[i] * r)
    if not kappa > 0.0 or r2 > SELF_SIMILAR_TOL**2 * kappa**2 * norm2:
        return 0.0, m
    return kappa, m


@_helper
def _series_maps_back(model, law, p, contacts, k, lawws, pn, miss):
    """Whether the law maps −p⁺ (p⁺ = p) to γp⁺ (to SELF_SIMILAR_TOL, in the Θ norm):
    every bounce of the series is then the first × γ^(j−1).  Leaves the law's impulses,
    u⁻ and u⁺ of the landing at −p⁺ in the scratch (those of the series' first bounce)."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    for i in range(3):
        pn[i] = -p[i]
    status, _ = _law_impulses(model, law, pn, contacts, k, gamma, lawws)
    if status != SETTLED:
        return False
    nc = F.shape[0]
    _add_law_impulses(F, tinv, contacts, k, lawws[1][nc : 2 * nc], pn)
    for i in range(3):
        miss[i] = pn[i] - gamma * p[i]
    return _theta_dot(thd, miss, miss) <= SELF_SIMILAR_TOL**2 * _theta_dot(thd, p, p)


@_helper
def _series_rows(model, limits, state, scratch, out, si, sf, lawws, contacts, k, flight, m):
    """The bounces of a self-similar series after the law impact at the current time, p⁺
    = p (`_bounce_series`): bounce j at t + flight (1 − γʲ)/(1 − γ), one IMPACT row per
    contact that takes an impulse, impulses and velocities those of the first × γ^(j−1),
    while the energy before a bounce is above the floor and within the impact budget;
    the held set of the rows: the m contacts left resting (lawws' rest).  Returns the
    time of the last row."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    max_impacts, log2_floor = limits[1], limits[2]
    q, p, qs, ps, acc, held, closed = state
    zero, pp, a, pq = scratch[0], scratch[1], scratch[2], scratch[4]
    nc = F.shape[0]
    vecs, rest = lawws[1], lawws[2][2 * nc :]
    lam = vecs[nc : 2 * nc]
    kv, kq, gt = si[SI_KV], si[SI_KQ], sf[SF_GRAVITY]
    t0_hi, t0_lo = sf[SF_T_HI], sf[SF_T_LO]
    last_hi, last_lo = t0_hi, t0_lo
    for i in range(3):
        zero[i] = 0.0
    took = 0
    for i in range(k):
        if lam[i] > 0.0:
            took += 1
    budget = min(max_impacts - si[SI_IMPACTS], out[0].shape[0] - 2 - si[SI_EVENTS])
    n, j = 0, 1
    while took > 0 and n + took <= budget:
        r = gamma ** (j - 1)
        for i in range(3):
            pp[i] = -r * p[i]
            pq[i] = gamma * r * p[i]
        e_pre = _energy(zero, pp, thd, mass, gt)
        if not (e_pre > 0.0 and math.log2(e_pre) + 2 * kv > log2_floor and flight * r > 0.0):
            break
        if j == 1:  # the bounces' held set: the contacts left resting
            for i in range(3):
                held[i] = rest[i] if i < m else -1
        e_post = _energy(zero, pq, thd, mass, gt)
        since = flight * (1.0 - gamma**j) / (1.0 - gamma)
        last_hi, last_lo = _add_time(t0_hi, t0_lo, math.ldexp(since, kq - kv))
        dtn = flight * r
        for i in range(k):
            if lam[i] > 0.0:
                _write_row(out, si[SI_EVENTS], IMPACT, contacts[i], -1, kv, kq, held, dtn,
                           last_hi, last_lo, lam[i] * r, vecs[i] * r, vecs[2 * nc + i] * r,
                           e_pre, e_post, zero, pp, zero, pq, a)  # fmt: skip
                si[SI_EVENTS] += 1
                si[SI_IMPACTS] += 1
                dtn = 0.0
        n += took
        j += 1
    return last_hi, last_lo


@_helper
def _bounce_series(model, limits, state, scratch, out, si, sf, info, lawws, contacts, k, vfl):
    """After a law impact at q = 0 with every contact touching (p⁺ = p): the Zeno series
    of self-similar bounces, completed in closed form when there is one (docs/laws.md,
    "Self-similar bounce series").  With B the contacts resting after the impact held,
    the acceleration a is constant; if a = −κp⁺ (κ > 0) every gap is f_cᵀp⁺ ≥ 0 times one
    bouncing-ball profile and the body is back at q = 0 with p = −p⁺ after 2/κ; if the
    law maps −p⁺ to γp⁺, every later flight is γ times the one before.  Writes the
    bounces (`_series_rows`), then ends the run at rest (SINGULARITY, REASON_SINGULARITY,
    info[INFO_SERIES]) at t + 2/(κ(1 − γ)), if before t_end.  Returns whether it did."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    gt = sf[SF_GRAVITY]
    nc = F.shape[0]
    if not (0.0 < gamma < 1.0 and gt > 0.0) or k < nc:
        return False
    rest, u_post = lawws[2][2 * nc :], lawws[1][2 * nc : 3 * nc]
    kappa, m = _series_rate(model, p, contacts, k, u_post, vfl, gt, rest, scratch[2])
    if kappa == 0.0:
        return False
    if not _series_maps_back(model, limits[7], p, contacts, k, lawws, scratch[3], scratch[4]):
        return False
    flight = 2.0 / kappa
    duration = flight / (1.0 - gamma)
    kv, kq = si[SI_KV], si[SI_KQ]
    if not sf[SF_T_HI] + math.ldexp(duration, kq - kv) <= limits[0]:
        return False
    last_hi, last_lo = _series_rows(model, limits, state, scratch, out, si, sf, lawws, contacts,
                                    k, flight, m)  # fmt: skip
    # at rest at t + 2/(κ(1 − γ)): the coordinates the contacts see are 0 (the rod's roll
    # about its axis, which they do not see, carried on for the tail)
    for i in range(3):
        q[i] = q[i] + p[i] * duration
    _project(q, F, tinv, contacts, min(k, 3))
    _project(p, F, tinv, contacts, min(k, 3))
    t_hi, t_lo = _add_time(sf[SF_T_HI], sf[SF_T_LO], math.ldexp(duration, kq - kv))
    sf[SF_DT_PENDING] = math.ldexp((t_hi - last_hi) + (t_lo - last_lo), kv - kq)
    sf[SF_SERIES_T] = sf[SF_T_HI]
    sf[SF_T_HI], sf[SF_T_LO] = t_hi, t_lo
    info[INFO_SERIES] = 1
    _stop(si, info, SINGULARITY, REASON_SINGULARITY, -1, -1)
    return True


@_helper
def _law_impact(model, limits, state, scratch, out, si, sf, info, lawws, contacts, k, E, vfl):
    """The impact of contacts[:k] under the run's law (`_law_event`): Λ, p⁺ = p⁻ +
    Θ⁻¹F_SᵀΛ, one IMPACT row per contact that took an impulse; bounces too small to
    follow (every contact that leaves, below decouple_tol × the velocity scale) taken
    plastic (γ = 0); then the energy floor and a self-similar bounce series.  Returns
    False when it ended the run."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    law, together, decouple_tol, log2_floor = limits[7], limits[6], limits[4], limits[2]
    nc = F.shape[0]
    status, hits = _law_impulses(model, law, p, contacts, k, gamma, lawws)
    vecs = lawws[1]
    if status == SETTLED and _law_completes(vecs[2 * nc : 3 * nc], k, gamma, decouple_tol * vfl):
        status, hits = _law_impulses(model, law, p, contacts, k, 0.0, lawws)
    if status != SETTLED:
        _law_failed(si, info, together, contacts, k, status, hits)
        return False
    if si[SI_EVENTS] + k + 3 >= out[0].shape[0]:
        _stop(si, info, MAX_IMPACTS, REASON_NONE, -1, -1)
        return False
    q_pre, p_pre = scratch[0], scratch[1]
    for i in range(3):
        q_pre[i] = q[i]
        p_pre[i] = p[i]
    _add_law_impulses(F, tinv, contacts, k, vecs[nc : 2 * nc], p)
    E_post = _energy(q, p, thd, mass, sf[SF_GRAVITY])
    _law_rows(out, si, sf, held, acc, contacts, k, lawws, E, E_post, q_pre, p_pre, p)
    info[INFO_LAW_IMPACTS] += 1
    if _energy_ended(si, info, E_post, log2_floor):
        return False
    return not _bounce_series(model, limits, state, scratch, out, si, sf, info, lawws,
                              contacts, k, vfl)  # fmt: skip


@_helper
def _go_on(model, state, out, si, sf, info):
    """Go on after a law event as from a start (`_start`) at the state (q, p): the
    scales renormalised, the contacts resting there closed, the held set (none until
    the next flight step settles it, recorded on the last row) and the recent impacts
    forgotten (a chatter's history ends at a multi-contact impact)."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    E = _energy(q, p, thd, mass, sf[SF_GRAVITY])
    if not (E > 0.0):
        _stop(si, info, SINGULARITY, REASON_NO_ENERGY, -1, -1)
        return
    E = _normalise_at(model, state, si, sf, E)
    for i in range(3):
        held[i] = -1
    _record_held_set(out, si[SI_EVENTS] - 1, held, acc)
    for c in range(F.shape[0]):
        closed[c] = False
    si[SI_RB_POS] = 0
    si[SI_RB_N] = 0
    sf[SF_DT_PENDING] = 0.0
    _close_resting_contacts(F, q, p, qs, ps, closed, _velocity_scale(E, wmax))


@njit(cache=True)
def _law_event(model, limits, state, scratch, out, si, sf, info, lawws):
    """A stop SIMULTANEOUS under the paper's rule (two contacts reached at once, an impact
    that would push a held contact, a contact at the ground when a chatter accumulates,
    contacts reached within the simultaneity window), resolved by the run's impact law
    (limits[7], a code of reference.core.laws) on the state before the impact, inside
    the loop:

    1. the contacts of the impact (`law_contacts`): every contact touching and not
       separating, and those the window flagged;
    2. when one of them approaches, their impact under the law (`_law_impact`: the
       exact core's law functions on the linear Delassus matrix F_S Θ⁻¹ F_Sᵀ), with a
       self-similar bounce series completed in closed form (`_bounce_series`);
    3. the run goes on from the state after it as from a start (`_go_on`: its contacts
       left at zero normal velocity closed, the held-contact phases).

    A law that does not settle (or a contact no impulse moves), or LAW_MAX_REPEATS stops
    without the time or the energy moving, end the run REASON_LAW_UNDECIDED."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    nc = F.shape[0]
    with_together = si[SI_REASON] == REASON_WINDOW
    si[SI_STATUS] = -1
    si[SI_REASON] = REASON_NONE
    E = _energy(q, p, thd, mass, sf[SF_GRAVITY])
    vfl = _velocity_scale(max(E, 0.0), wmax)
    contacts = lawws[2][:nc]
    k = law_contacts(F, q, p, qs, ps, vfl, limits[6], with_together, contacts)
    if not _law_progress(si, sf, math.ldexp(E, 2 * si[SI_KV])):
        _law_failed(si, info, limits[6], contacts, k, NO_PROGRESS, 0)
        return
    if _any_approaching(F, p, ps, vfl, contacts, k):
        if not _law_impact(model, limits, state, scratch, out, si, sf, info, lawws, contacts,
                           k, E, vfl):  # fmt: skip
            return
    _go_on(model, state, out, si, sf, info)


# ------------------------------------------------------------------ the event loop


@_helper
def _step(model, limits, state, scratch, ring, out, si, sf, info):
    """One pass of the event loop: two contacts hitting at once (undecidable, the paper,
    section 2.3), one (`_impact_step`) or none (`_flight_step`).  Where the paper's rule
    stops undecided, `continue_kernel` has the run's impact law resolve the impact
    (`_law_event`)."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    E = _energy(q, p, thd, mass, sf[SF_GRAVITY])
    vfl = _velocity_scale(E, wmax)
    ncand, cand, cand2 = _impacts_now(F, q, p, qs, ps, closed, vfl)
    if ncand >= 2:
        _stop(si, info, SIMULTANEOUS, REASON_SIMULTANEOUS, cand, cand2)
    elif ncand == 1:
        _impact_step(model, limits, state, scratch, ring, out, si, sf, info, cand, E, vfl)
    else:
        _flight_step(model, limits, state, scratch, out, si, sf, info, vfl)


@_helper
def _normalise_at(model, state, si, sf, E):
    """The scales renormalised at the state (q, p) of energy E > 0 (module docstring,
    Scaling), qs and ps its magnitudes, acc free flight's; returns the energy in the new
    scales."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    _renormalise(F, q, p, qs, ps, E, si, sf, 1)
    for i in range(3):
        qs[i] = abs(q[i])
        ps[i] = abs(p[i])
        acc[i] = 0.0
    acc[2] = -sf[SF_GRAVITY]
    return _energy(q, p, thd, mass, sf[SF_GRAVITY])


@_helper
def _start(model, state, out, si, sf, E):
    """Normalise the initial state of energy E > 0 (module docstring, Scaling), write the
    INITIAL row and close the contacts resting at t = 0."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    E = _normalise_at(model, state, si, sf, E)
    _write_state_row(out, 0, INITIAL, si, held, 0.0, 0.0, 0.0, E, q, p, acc)
    si[SI_EVENTS] = 1
    _close_resting_contacts(F, q, p, qs, ps, closed, _velocity_scale(E, wmax))


@_helper
def _finish(model, state, out, si, sf, info):
    """After the loop: an END row with the final state for a run stopped before t_end
    (if it fits), and the outcome record (bookkeeping, no equation of the paper)."""
    F, thd, tinv, w, wmax, mass, gamma, rank_f = model
    q, p, qs, ps, acc, held, closed = state
    if si[SI_STATUS] != T_END and si[SI_EVENTS] < out[0].shape[0]:
        E = _energy(q, p, thd, mass, sf[SF_GRAVITY])
        _write_state_row(out, si[SI_EVENTS], END, si, held, sf[SF_DT_PENDING], sf[SF_T_HI],
                         sf[SF_T_LO], E, q, p, acc)  # fmt: skip
        si[SI_EVENTS] += 1
    _write_info(si, info)


def new_loop_state(n_contacts: int):
    """The arrays a run carries between calls of `continue_kernel` (module docstring:
    state, ring, si, sf), allocated once by the caller."""
    return (
        np.zeros(3),  # q
        np.zeros(3),  # p
        np.zeros(3),  # qs
        np.zeros(3),  # ps
        np.zeros(3),  # acc
        np.full(3, -1, dtype=np.int64),  # held
        np.zeros(n_contacts, dtype=np.bool_),  # closed
        np.zeros(N_SI, dtype=np.int64),  # si
        np.zeros(N_SF),  # sf
        np.full(RB, -1, dtype=np.int64),  # ring: contact
        np.zeros(RB),  # ring: log2 interval
        np.zeros(RB),  # ring: log2 speed
        np.zeros(n_contacts, dtype=np.bool_),  # together: reached in one window
    )


def new_law_scratch(n_contacts: int, vec_floats: int):
    """The scratch of the run's impact law (`_law_impulses`): W and its factor (2n × n),
    u⁻, Λ, u⁺ and `vec_floats` floats of the law's own (reference.core.laws.work_floats),
    the contacts of the impact, the law's active set and the resting contacts of a
    bounce series (2n + 3 integers), and an empty order (the law's own)."""
    n = n_contacts
    return (
        np.zeros((2 * n, n)),
        np.zeros(3 * n + vec_floats),
        np.zeros(2 * n + 3, dtype=np.int64),
        np.zeros(0, dtype=np.int64),
    )


@_python_entry
def start_kernel(
    F, thd, tinv, w, wmax, mass, g, gamma, rank_f, q_init, p_init, record_states,
    out_i, out_f, out_s, info, q, p, qs, ps, acc, held, closed, si, sf,
):  # fmt: skip
    """Set up a run from (q_init, p_init) at t = 0 (module docstring) in the caller's
    state arrays (`new_loop_state`).  Returns True when the run ended at once (no energy
    above the contacts: SINGULARITY), else False: call `continue_kernel`."""
    model = (F, thd, tinv, w, wmax, mass, gamma, rank_f)
    out = (out_i, out_f, out_s, record_states)
    state = (q, p, qs, ps, acc, held, closed)
    q[:] = q_init
    p[:] = p_init
    qs[:] = 0.0
    ps[:] = 0.0
    held[:] = -1
    acc[:] = 0.0
    acc[2] = -g
    closed[:] = False
    si[:] = 0
    si[SI_STATUS] = -1
    sf[:] = 0.0
    sf[SF_GRAVITY] = g
    sf[SF_LAW_T] = math.nan  # no law event yet
    sf[SF_LAW_E] = math.inf
    info[:] = 0
    E = _energy(q, p, thd, mass, g)
    if not (E > 0.0):
        _write_state_row(out, 0, INITIAL, si, held, 0.0, 0.0, 0.0, E, q, p, acc)
        si[SI_EVENTS] = 1
        _stop(si, info, SINGULARITY, REASON_NO_ENERGY, -1, -1)
        _write_info(si, info)
        return True
    _start(model, state, out, si, sf, E)
    return False


@_python_entry
def continue_kernel(
    F, thd, tinv, w, wmax, mass, gamma, rank_f, t_end, max_impacts, log2_energy_floor,
    chatter_tol, decouple_tol, window, law, record_states, out_i, out_f, out_s, info,
    q, p, qs, ps, acc, held, closed, si, sf, rb_c, rb_ldt, rb_lu, together,
    law_mats, law_vecs, law_ints, law_order, budget,
):  # fmt: skip
    """At most `budget` passes of the event loop (`_step`, then `_law_event` at a stop
    SIMULTANEOUS under a law other than `paper`), so that the caller regains
    control (Ctrl-C) between calls.  Returns the number of events once a status is set
    (after `_finish`: END row, outcome record), else -1: call again.  `law`: the code
    of the run's impact law (reference.core.laws); law_*: its scratch
    (`new_law_scratch`)."""
    nc = F.shape[0]
    model = (F, thd, tinv, w, wmax, mass, gamma, rank_f)
    limits = (t_end, max_impacts, log2_energy_floor, chatter_tol, decouple_tol, window, together,
              law)  # fmt: skip
    lawws = (law_mats, law_vecs, law_ints, law_order)
    out = (out_i, out_f, out_s, record_states)
    state = (q, p, qs, ps, acc, held, closed)
    cidx = np.zeros(nc + 3, dtype=np.int64)
    hidx = np.zeros(3, dtype=np.int64)
    sidx = np.zeros(3, dtype=np.int64)
    scratch = (np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), cidx, hidx, sidx)
    ring = (rb_c, rb_ldt, rb_lu)
    steps = 0
    while si[SI_STATUS] < 0 and steps < budget:
        _step(model, limits, state, scratch, ring, out, si, sf, info)
        if si[SI_STATUS] == SIMULTANEOUS and law != LAW_PAPER:
            _law_event(model, limits, state, scratch, out, si, sf, info, lawws)
        steps += 1
    if si[SI_STATUS] < 0:
        return -1
    _finish(model, state, out, si, sf, info)
    return si[SI_EVENTS]


@_python_entry
def log2_time_to_go(log2_dt, log2_rest):
    """log2(t_f − t_i) for every event i: log2 of the rest after the last event combined
    with the intervals that follow each event, summed from the end in log space
    (log2_dt[i] is the interval before event i; −inf for none)."""
    n = log2_dt.shape[0]
    out = np.empty(n)
    acc = log2_rest
    for i in range(n - 1, -1, -1):
        out[i] = acc
        x = log2_dt[i]
        if x > acc:
            acc = x + math.log2(1.0 + math.exp2(acc - x))
        elif x > -math.inf:
            acc = acc + math.log2(1.0 + math.exp2(x - acc))
    return out


@_python_entry
def log2_segment_sums(log2_dt, idx):
    """log2 of the time from event idx[k] to event idx[k+1] (the intervals
    log2_dt[idx[k]+1 .. idx[k+1]] summed), for consecutive entries of idx."""
    n = idx.shape[0] - 1
    out = np.empty(max(n, 0))
    for k in range(n):
        acc = -math.inf
        for i in range(idx[k] + 1, idx[k + 1] + 1):
            x = log2_dt[i]
            if x == -math.inf:
                continue
            if x > acc:
                acc = x + math.log2(1.0 + math.exp2(acc - x))
            else:
                acc = acc + math.log2(1.0 + math.exp2(x - acc))
        out[k] = acc
    return out
