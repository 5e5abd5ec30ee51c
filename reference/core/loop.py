"""The event loop of the exact reference (the one entry point Python calls).

Phases alternate between closed-form free flight and sustained contact with one or two
points, separated by instantaneous events: single-point Newtonian impacts, lift-off
(a held force reaching zero), activations, chatter completion.  The run stops with an
explicit status and never guesses:

- two contacts reached within the time resolution, or an impact that would drive a
  held contact into the ground, end it as undecidable under the paper's rule; under an
  impact law they are one simultaneous impact, resolved by the law
  (reference.core.law_event), and the run goes on;
- all contacts down, the energy above the resting level exhausted to `energy_floor`
  of its initial value, or the tilt below TILT_FLOOR, end it at the singularity, with
  t_singularity (extrapolated from the geometric sequence of the last impact
  intervals);
- a bump outside the face on the three-point ground ends it `left_model`, and so does
  its rim reaching the floor plane under the bumps, which that ground does not model
  (reference.core.floor: located in flight and in contact phases, or at the start);
- a loop that stops advancing (a window of STALL_WINDOW steps without an impact that
  advanced the clock by less than contact_rtol of the motion's time scale a step:
  `_stalled`) ends it `stalled`, with the time, the contacts held and the law.

Time is a double-double and every phase runs in its own local time, so intervals near
the singularity keep their digits.  The loop returns to Python after `work_budget`
steps (so that a long run can show progress and be interrupted) and when its output
arrays are full; the state record holds everything needed to resume."""

import math

from numba import njit

from .clock import time_until
from .contacts import off_face, velocity_scale
from .ending import end_run
from .events import resolve_touching, start
from .inertia import excess_energy
from .jit import hot, hot_inline
from .layout import QX, QY, STATE_SIZE, WX, WY
from .output import Output
from .phases import (
    NEEDS_ROWS,
    begin_contact_phase,
    close_contact_phase,
    contact_step,
    flat_flight_step,
    flight_step,
)
from .records import (
    N_ACCUMULATIONS,
    N_IMPACTS,
    N_PHASES,
    RETURN_DONE,
    RETURN_GROW,
    RETURN_YIELD,
    STATUS_ENERGY_EXHAUSTED,
    STATUS_FAILED_NONFINITE,
    STATUS_MAX_IMPACTS,
    STATUS_OFF_FACE,
    STATUS_RUNNING,
    STATUS_SINGULARITY,
    STATUS_STALLED,
    STATUS_T_END,
    STATUS_TILT_FLOOR,
    STEP_ROWS,
)
from .tolerances import MAX_PERIOD, PERIOD_RATIO_TOL, STALL_WINDOW, TILT_FLOOR, TINY
from .workspace import contact_lists


@hot
def _span(imp, i, j):
    """Time from impact i to impact j (double-double differences)."""
    return (imp[j, 0] - imp[i, 0]) + (imp[j, 1] - imp[i, 1])


@hot
def extrapolate_singularity(out, t_hi):
    """t_f from the last impacts, assuming geometric intervals with a period of m
    impacts (m = 1 … MAX_PERIOD: the vertices of a polygon often take turns, so single
    intervals alternate while blocks of m shrink by a constant ratio r): the smallest m
    whose last two block ratios agree to PERIOD_RATIO_TOL, with r < 1, gives
    t_f = t_last + S r/(1 − r), S the last block's duration.  The current time when no
    m applies."""
    n = out.counts[N_IMPACTS]
    imp = out.impacts
    last = n - 1
    for m in range(1, MAX_PERIOD + 1):
        if n < 3 * m + 1:
            break
        s1 = _span(imp, last - m, last)
        s0 = _span(imp, last - 2 * m, last - m)
        s_1 = _span(imp, last - 3 * m, last - 2 * m)
        if not (s0 > 0 and s_1 > 0 and s1 > 0):
            continue
        r, r_before = s1 / s0, s0 / s_1
        if r < 1 and abs(r - r_before) <= PERIOD_RATIO_TOL * r:
            return imp[last, 0] + (imp[last, 1] + s1 * r / (1 - r))
    return t_hi


@hot
def _below_tilt_floor(state, model, opts, y, out):
    """After impacts, the tilt α ≈ 2 |(x, y)| of the attitude quaternion is below
    TILT_FLOOR: nonzero, or exactly zero with a contact held and not tilting (the rim
    speed a|ω_h| of the rotation about horizontal axes at most chatter_tol × V).  A body
    exactly flat with no contact held has just landed flat: the event search reports its
    simultaneous contacts; one exactly flat but tilting away (a vertex leaving a
    simultaneous impact beside held ones, under an impact law) is not at rest either."""
    if out.counts[N_IMPACTS] == 0:
        return False
    h = math.hypot(y[QX], y[QY])
    if not h < 0.5 * TILT_FLOOR:
        return False
    if h > 0.0:
        return True
    tilting = model.radius * math.hypot(y[WX], y[WY])
    return state.n_active > 0 and tilting <= opts.chatter_tol * velocity_scale(y, model.radius)


@hot
def _motion_ended(state, model, opts, out):
    """The end checks between phases (max_impacts, all contacts down, energy exhausted,
    tilt below TILT_FLOOR, t_end); sets the status and returns True when one applies."""
    none = state.info  # (no contacts to name)
    if out.counts[N_IMPACTS] >= opts.max_impacts:
        end_run(state, STATUS_MAX_IMPACTS, none, 0)
        return True
    if state.n_active >= model.all_down:
        end_run(state, STATUS_SINGULARITY, state.active, min(state.n_active, 3))
        state.t_singularity = state.t_hi
        return True
    y = state.y
    if state.excess0 > 0:
        e = excess_energy(y, model.invariants, model.mass, model.i1, model.i3, model.gravity)
        # |e|: a negative excess (three-point ground, the centre beyond the bumps'
        # triangle, where the disk has no rest) is not an exhausted one
        if abs(e) <= opts.energy_floor * state.excess0:
            end_run(state, STATUS_ENERGY_EXHAUSTED, none, 0)
            state.t_singularity = extrapolate_singularity(out, state.t_hi)
            return True
    if _below_tilt_floor(state, model, opts, y, out):
        end_run(state, STATUS_TILT_FLOOR, none, 0)
        state.t_singularity = extrapolate_singularity(out, state.t_hi)
        return True
    if time_until(state.t_hi, state.t_lo, opts.t_end) <= 0:
        end_run(state, STATUS_T_END, none, 0)
        return True
    return False


@hot
def _rows_short(out, opts):
    """Whether impacts have fewer than opts.step_rows free rows, phases or accumulation
    times fewer than STEP_ROWS."""
    c = out.counts
    return (
        out.impacts.shape[0] - c[N_IMPACTS] < opts.step_rows
        or out.phases.shape[0] - c[N_PHASES] < STEP_ROWS
        or out.accumulations.shape[0] - c[N_ACCUMULATIONS] < STEP_ROWS
    )


@hot
def _finite(y):
    for c in range(STATE_SIZE):
        if not math.isfinite(y[c]):
            return False
    return True


@hot
def motion_time_scale(y, model):
    """T = min(τ, a/V): the motion's own time scale, the shorter of gravity's τ = √(a/g)
    (scene.time_unit: t_end without gravity) and the time a/V in which the rim moves by
    its own radius at the velocity scale V = |v| + a|ω| (the scales of the contact
    phases' chunk horizon, reference.core.candidates)."""
    a = model.radius
    return min(model.time_unit, a / max(velocity_scale(y, a), TINY))


@hot
def _stalled(state, model, opts, out):
    """Whether the run has stopped advancing: a window of STALL_WINDOW loop steps without
    an impact advanced the clock by less than STALL_WINDOW × contact_rtol × T (T the
    motion's time scale, `motion_time_scale`).

    Why this bound: free flights are exact and end at an event, contact phases are
    integrated to a relative tolerance rtol = contact_rtol of the state's scale, so a
    step shorter than rtol·T moves the state by less than the integrator's own error in
    it.  A run whose steps average below that has stopped advancing: it only adds
    roundoff (the bumpy ground's contact phases can creep at 1e-19 s a step, 15 decades
    below their own time scale, and would take 10¹⁷ steps to t_end).  Impacts are
    progress whatever their intervals (a run approaching its singularity advances by
    ever shorter ones, down to the tilt floor), each counted against max_impacts: an
    impact starts a new window.  So between impacts a run advances by at least
    STALL_WINDOW rtol T per window: its work is bounded by STALL_WINDOW (max_impacts +
    1) steps plus t_end / (rtol T) chunks.  A stalled run ends STATUS_STALLED, the
    window's advance and its bound in state.stall_advance and state.stall_bound."""
    n = out.counts[N_IMPACTS]
    if n != state.stall_impacts or state.stall_steps >= STALL_WINDOW:
        if n == state.stall_impacts:  # a full window without an impact: its advance
            advance = (state.t_hi - state.stall_t) + (state.t_lo - state.stall_t_lo)
            bound = STALL_WINDOW * opts.contact_rtol * motion_time_scale(state.y, model)
            if advance < bound:
                state.stall_advance, state.stall_bound = advance, bound
                return True
        state.stall_t, state.stall_t_lo, state.stall_impacts = state.t_hi, state.t_lo, n
        state.stall_steps = 0
    state.stall_steps += 1
    return False


@hot
def _held_off_face(state, model, pts, found):
    """Whether a held contact has slid outside the face's rim (`contacts.off_face`;
    into found[0]).  An impact there is caught before it is applied
    (`events.resolve_impact`); a held contact is caught at the end of the step that
    carried it out."""
    for i in range(state.n_active):
        if off_face(state.y, model, pts, state.active[i]):
            found[0] = state.active[i]
            return True
    return False


@hot_inline
def loop_step(state, model, pts, opts, stats, out, ws, cs):
    """One step: the run's start, a contact chunk (or the event ending the phase), or a
    flight to its event, after the end checks between phases.  Inlined into
    `run_steps` (numba's IR inlining), as `phases.flight_step` into it: a call passes
    the output and per-contact lists by value, about 150 machine words."""
    if not state.started:
        start(state, model, pts, opts, stats, out, ws, cs)
        return 0
    if state.recheck:
        resolve_touching(state, model, pts, opts, stats, out, ws, cs)
        return 0
    if state.in_contact:
        return contact_step(state, model, pts, opts, stats, out, ws, cs)
    if _motion_ended(state, model, opts, out):
        return 0
    if state.flat_u > 0.0:
        return flat_flight_step(state, model, pts, opts, stats, out, ws, cs)
    if state.n_active > 0:
        begin_contact_phase(state, model, opts)
        return contact_step(state, model, pts, opts, stats, out, ws, cs)
    return flight_step(state, model, pts, opts, stats, out, ws, cs)


@njit(cache=True)
def run_events(
    run_rec, pts, sample_t, sample_y, sample_e, impacts, phases, accumulations,
    contact_ints, contact_floats, law_mats, law_vecs, law_ints,
):  # fmt: skip
    """Run the loop from the state in run_rec until the run ends (RETURN_DONE), an output
    array needs rows (RETURN_GROW) or work_budget steps are done (RETURN_YIELD).
    run_rec is a 1-element records.RUN array the caller owns (model, options, state,
    counters, scratch and output row counts), so that it outlives the call (a record
    does not keep its array alive); the output arrays are those of output.Output;
    contact_ints and contact_floats hold the per-contact lists
    (records.new_contact_arrays), law_mats, law_vecs and law_ints the scratch of a
    simultaneous impact under an impact law (records.new_law_arrays)."""
    run = run_rec[0]
    out = Output(sample_t, sample_y, sample_e, impacts, phases, accumulations, run.counts)
    cs = contact_lists(contact_ints, contact_floats, law_mats, law_vecs, law_ints)
    return run_steps(run.model, run.options, run.state, run.stats, run.scratch, pts, out, cs)


@hot
def run_steps(model, opts, state, stats, ws, pts, out, cs):
    """`run_events`' loop, compiled without numba's reference counting (`jit.hot`):
    `run_events` needs it to build the lists of views, and in its own loop each step's
    reads of those lists counted references (NRT_incref/NRT_decref: 1.4 % of the
    compiled loop's perf samples on `triangle-chatter` under `moreau`; here 0.2 %)."""
    for _ in range(opts.work_budget):
        if state.status != STATUS_RUNNING:
            return RETURN_DONE
        if _rows_short(out, opts):
            return RETURN_GROW
        if loop_step(state, model, pts, opts, stats, out, ws, cs) == NEEDS_ROWS:
            return RETURN_GROW
        stats.loop_steps += 1
        if state.status == STATUS_RUNNING and not _finite(state.y):
            end_run(state, STATUS_FAILED_NONFINITE, cs.together, 0)
        elif state.status == STATUS_RUNNING and _stalled(state, model, opts, out):
            if state.in_contact:
                close_contact_phase(state, model, stats, out)
            end_run(state, STATUS_STALLED, state.active, state.n_active)
        elif state.status == STATUS_RUNNING and _held_off_face(state, model, pts, cs.together):
            if state.in_contact:
                close_contact_phase(state, model, stats, out)
            end_run(state, STATUS_OFF_FACE, cs.together, 1)
    return RETURN_DONE if state.status != STATUS_RUNNING else RETURN_YIELD
