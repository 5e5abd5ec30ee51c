"""Named results of the core's functions (namedtuples, compiled as structs) and the record
layouts that cross the Python boundary (numpy structured dtypes, read by field name on
both sides)."""

from collections import namedtuple

import numpy as np

from .layout import STATE_SIZE

# ----------------------------------------------------------------------------- results

# A contact's geometry at a state: gap, unit normal n, lever r (contact point − centre of
# mass, world frame), roundoff level of the gap.
Frame = namedtuple("Frame", ["gap", "nx", "ny", "nz", "rx", "ry", "rz", "noise"])
# Gap, its first and second time derivatives, and the gap's roundoff level.
Jet = namedtuple("Jet", ["gap", "rate", "accel", "noise"])
# An impulse ζ along a contact normal changes (v, ω) by ζ (dv, dw) = ζ M⁻¹Jᵀ and the
# contact's normal velocity by ζ w, w = J M⁻¹ Jᵀ (the inverse effective mass).
Response = namedtuple("Response", ["dvx", "dvy", "dvz", "dwx", "dwy", "dwz", "w"])
# What stays fixed along a free flight: L/A (world), the spin rate λ about e3 relative
# to the precessing frame, |ω| and the precession rate Ω = |L|/A.
FlightConstants = namedtuple("FlightConstants", ["lax", "lay", "laz", "lam", "wabs", "omega"])
# Bounds on |g″| and |g‴| of every gap over a flight, and on how far below the centre
# of mass any rim vertex can be during it (inf for a ground without rim vertices).
Bounds = namedtuple("Bounds", ["K", "B", "depth"])
# An impact's impulse and the contact's normal velocity before and after it.
ImpactOutcome = namedtuple("ImpactOutcome", ["impulse", "u_pre", "u_post"])
# The next event of a free flight: kind (EVENT_*), time s from the flight's start, the
# contact, how many contacts are reached together, search iterations.
FlightEvent = namedtuple("FlightEvent", ["kind", "s", "contact", "n_together", "iterations"])

# The scratch and settings an impact law's function may use (reference.core.laws):
# chol (k × k), vec (2k), active (k integers), the sequential law's order[:n_order] and
# its cap on single impacts.
LawWork = namedtuple("LawWork", ["chol", "vec", "active", "order", "n_order", "max_hits"])

EVENT_NONE = 0  # nothing reached within the horizon
EVENT_IMPACT = 1  # a contact reached while approaching
EVENT_ACTIVATION = 2  # a contact touching at rest with its acceleration into the ground
EVENT_STUCK = 3  # the search did not converge

# ----------------------------------------------------------------------------- contact kinds

# What a contact is (reference.core.contacts answers for each kind; the Python side
# describes a ground with them, reference.ground).
RIM_VERTEX_ON_PLANE = 0  # a body-frame rim vertex against the plane z = 0, normal +z
FLOOR_POINT_ON_FACE = 1  # a fixed world point touching the body's face, normal e3

# The core's contact points are (n, POINT_COLUMNS) rows: the point (body-frame for a rim
# vertex, world for a floor point) and, in column KIND_COLUMN, the contact's kind
# (reference.contact_kinds.GroundContacts.core_points).
KIND_COLUMN = 3
POINT_COLUMNS = 4

# Invariants of the motion that every contact force of a ground keeps (bits): vertical
# forces keep the horizontal momentum and L_z; forces along e3 through the face keep
# the spin ω3 of the axisymmetric body (the energy's resting level, inertia.excess_energy).
KEEPS_PLANE_MOMENTA = 1
KEEPS_SPIN = 2

# ----------------------------------------------------------------------------- layouts

# The body, its ground and the impact law, as the core reads them.
MODEL = np.dtype(
    [
        ("mass", np.float64),
        ("i1", np.float64),  # inertia about in-plane axes, m (ρa)²
        ("i3", np.float64),  # inertia about the symmetry axis, 2 m (ρa)²
        ("radius", np.float64),  # a
        ("gravity", np.float64),  # g (along −z)
        ("gamma", np.float64),  # Newton's restitution coefficient γ
        ("n_contacts", np.int64),  # the ground's contacts: its rim vertices (kind
        ("n_rim", np.int64),  # RIM_VERTEX_ON_PLANE) 0 … n_rim − 1, then its floor points
        ("invariants", np.int64),  # KEEPS_* the ground's contact forces all keep
        ("sag", np.float64),  # 1 − cos(π/n): how far a vertex sits above the circle's
        # lowest point, per a sin α, when that point is midway between two vertices
        ("all_down", np.int64),  # contacts held together that end the motion
        # simultaneity window per unit approach speed, T/U (U: the scene's velocity unit):
        # zeros within T |u|/U of a contact reached at speed |u| are reached together
        ("window_per_speed", np.float64),
        ("floor_depth", np.float64),  # d: the floor plane z = −d, a model limit of a ground
        # without rim vertices (reference.core.floor); inf: none
        ("law", np.int64),  # the impact law's code (reference.core.laws)
        ("law_separating", np.bool_),  # its impact takes separating contacts too
        ("time_unit", np.float64),  # τ = √(a/g) (t_end without gravity): scene.time_unit
    ]
)

# Run settings and tolerances (reference.options.ReferenceOptions).
OPTIONS = np.dtype(
    [
        ("t_end", np.float64),
        ("sample_dt", np.float64),
        ("chatter_tol", np.float64),
        ("contact_rtol", np.float64),
        ("energy_floor", np.float64),
        ("max_samples", np.int64),
        ("max_impacts", np.int64),
        ("window_search", np.bool_),  # large polygons: examine only the vertices near the ground
        ("work_budget", np.int64),  # loop steps per call before control returns to Python
        ("n_order", np.int64),  # the sequential law's order: ContactLists.order[:n_order]
        ("step_rows", np.int64),  # impact rows a step may add: STEP_ROWS, + the law's
        # contacts when a law resolves simultaneous impacts (one row per contact)
    ]
)

# The loop's state: everything needed to resume it after it returns to Python.
STATE = np.dtype(
    [
        ("y", np.float64, (STATE_SIZE,)),  # x, q (w, x, y, z), v, ω (world): layout.py
        ("t_hi", np.float64),  # time as a double-double t_hi + t_lo
        ("t_lo", np.float64),
        ("excess0", np.float64),  # initial energy above the resting level
        ("n_active", np.int64),  # contacts held
        ("active", np.int64, (3,)),
        ("in_contact", np.bool_),  # inside a contact phase
        ("phase_t0", np.float64),  # the current phase's start
        ("phase_energy0", np.float64),  # energy at the contact phase's start
        ("gap_res", np.float64),  # the contact phase's gap resolution
        ("has_trend", np.bool_),  # lam_prev / h_prev hold the previous chunk's forces
        ("lam_prev", np.float64, (2,)),
        ("h_prev", np.float64),
        ("h_next", np.float64),  # DOP853's next step at the end of the last chunk (0: none)
        ("started", np.bool_),  # the initial contacts have been resolved
        ("status", np.int64),  # STATUS_* once the run has ended
        ("info_t", np.float64),  # time of the event that ended the run
        ("info_contact", np.int64),  # contact of that event (−1: none)
        ("n_info", np.int64),  # contacts involved (simultaneous impact)
        ("info", np.int64, (16,)),
        ("t_singularity", np.float64),  # NaN unless the run reached the singularity
        ("stall_t", np.float64),  # the start of the stall window (loop._stalled): its
        ("stall_t_lo", np.float64),  # time, the impacts recorded by then and the steps
        ("stall_impacts", np.int64),  # taken since
        ("stall_steps", np.int64),
        ("stall_advance", np.float64),  # a stalled run's last window: the time it
        ("stall_bound", np.float64),  # advanced and the least it had to
        ("recheck", np.bool_),  # after a law impact: resolve the touching contacts
        ("law_t_hi", np.float64),  # the time of the last law impact and how many
        ("law_t_lo", np.float64),  # happened at it (reference.core.law_event)
        ("law_repeats", np.int64),
        ("law_outcome", np.int64),  # why a law left the impact undecided (law_event)
        ("flat_u", np.float64),  # > 0: flying after a flat bounce at this speed (law_event)
    ]
)

STATUS_RUNNING = -1
STATUS_T_END = 0
STATUS_SINGULARITY = 1  # all contacts down
STATUS_ENERGY_EXHAUSTED = 2  # singularity: excess energy ≤ floor × initial
STATUS_SIMULTANEOUS = 3  # contacts reached together
STATUS_PUSHED = 4  # an impact would push a held contact into the ground
STATUS_MAX_IMPACTS = 5
STATUS_FAILED_NONFINITE = 6
STATUS_FAILED_LCP = 7  # the complementarity problem has no solution
STATUS_FAILED_STUCK = 8  # the event search did not converge
STATUS_FAILED_INTEGRATION = 9  # the contact integrator's step fell below roundoff
STATUS_FAILED_NO_ADVANCE = 10  # a contact phase cannot advance before t_end
STATUS_AT_REST = 11  # singularity at the start: all contacts down and at rest
STATUS_TILT_FLOOR = 12  # singularity: tilt below TILT_FLOOR after impacts
STATUS_OFF_FACE = 13  # a floor point outside the face's rim (contacts.off_face): left the bumps
STATUS_BELOW_FLOOR = 14  # the rim reached the floor plane of a ground without rim contacts
STATUS_LAW_UNDECIDED = 15  # the impact law left a simultaneous impact undecided
STATUS_FLAT_REST = 16  # singularity: flat bounces completed, at rest (law_event)
STATUS_STALLED = 17  # a stall window advanced below the motion's resolution (loop._stalled)

# Counters of a run (reference.stats.RunStats reads them by name).
STATS = np.dtype(
    [
        ("flight_searches", np.int64),
        ("search_iterations", np.int64),
        ("contact_phases", np.int64),
        ("contact_chunks", np.int64),
        ("contact_rhs_evals", np.int64),
        ("chatter_completions", np.int64),
        ("max_completion_u_rel", np.float64),
        ("activations", np.int64),
        ("lift_offs", np.int64),
        ("horizon_backstops", np.int64),
        ("contact_energy_drift_max", np.float64),
        ("max_penetration", np.float64),
        ("loop_steps", np.int64),
        ("simultaneous_impacts", np.int64),  # resolved by the impact law in the loop
    ]
)

# Scratch space of one run (reference.core.workspace): contact systems of up to three
# contacts, the DOP853 stages, and states and lists of one event.  A record, so that the
# many small functions it is passed to need no reference counting.
SCRATCH = np.dtype(
    [
        ("A", np.float64, (3, 3)),  # J M⁻¹ Jᵀ of up to three contacts
        ("b", np.float64, (3,)),  # their normal accelerations without contact forces
        ("r", np.float64, (3,)),  # a right-hand side
        ("lam", np.float64, (3,)),  # forces or impulses
        ("lam_chunk", np.float64, (3,)),  # held forces at a contact chunk's start
        ("As", np.float64, (3, 3)),  # the LCP's system of one active set
        ("sol", np.float64, (3,)),  # and its solution
        ("sel", np.int64, (3,)),  # and its contacts
        ("resp", np.float64, (3, 7)),  # M⁻¹J_iᵀ and w_i per contact
        ("geo", np.float64, (3, 6)),  # normal and lever per contact
        ("K", np.float64, (16, STATE_SIZE)),  # DOP853 stages, f(y_new), dense-output stages
        ("F", np.float64, (7, STATE_SIZE)),  # dense-output coefficients of a step
        # stages of one-step evaluations (K's shape: dop853_step has one signature)
        ("Ks", np.float64, (16, STATE_SIZE)),
        ("f", np.float64, (STATE_SIZE,)),
        ("f1", np.float64, (STATE_SIZE,)),  # f at the end of heun_euler_step's Euler step
        ("y_new", np.float64, (STATE_SIZE,)),
        ("ys", np.float64, (STATE_SIZE,)),
        ("scale", np.float64, (STATE_SIZE,)),
        ("tmp", np.float64, (STATE_SIZE,)),
        ("lam_cur", np.float64, (3,)),  # held forces at the current state
        ("lam_new", np.float64, (3,)),  # held forces at the end of the step accepted
        ("y_event", np.float64, (STATE_SIZE,)),
        ("y_chunk", np.float64, (STATE_SIZE,)),
        ("y_start", np.float64, (STATE_SIZE,)),
        ("atol", np.float64, (STATE_SIZE,)),
        ("res", np.float64, (5,)),  # the search's step / hit / landing bookkeeping
        ("cand", np.int64, (4,)),  # candidates of an impact or activation
        ("active", np.int64, (4,)),  # the LCP's answer
        ("before", np.int64, (4,)),  # held contacts before an activation; pushed contacts
        ("held", np.int64, (4,)),  # the held contacts when a contact phase ends
    ]
)

# Everything one run of the loop reads and writes but its output rows and per-contact
# lists, in one record (one argument: each array passed from Python costs the call
# ~40 ns): the model, options, state, counters, scratch space, and the row counts of
# the output arrays (`counts[N_SAMPLES]` …).
RUN = np.dtype(
    [
        ("model", MODEL),
        ("options", OPTIONS),
        ("state", STATE),
        ("stats", STATS),
        ("scratch", SCRATCH),
        ("counts", np.int64, (5,)),
    ]
)

# The loop's per-contact lists (workspace.ContactLists), rows of two (4, n) arrays the
# caller allocates once per run (`new_contact_arrays`), so the loop allocates nothing.
CONTACT_INT_ROWS = ("cand", "together", "hitting", "near")
CONTACT_FLOAT_ROWS = ("gap", "rate", "accel", "noise")


def new_contact_arrays(n):
    """The int64 and float arrays of the per-contact lists of n contacts."""
    return (
        np.empty((len(CONTACT_INT_ROWS), n), dtype=np.int64),
        np.empty((len(CONTACT_FLOAT_ROWS), n)),
    )


def new_law_arrays(k, order=(), work=None):
    """The float (2k, k), float (3k + work,) and int (3k + len(order),) arrays of a
    simultaneous impact of up to k contacts under an impact law (workspace.ContactLists):
    `work` floats of the law's scratch (laws.work_floats; None: 2k), the sequential
    law's order of contacts after the int rows."""
    ints = np.zeros(3 * k + len(order), dtype=np.int64)
    ints[3 * k :] = order
    return np.zeros((2 * k, k)), np.zeros(3 * k + (2 * k if work is None else work)), ints


# Columns of the impact rows the loop writes.
IMPACT_COLUMNS = ("t", "t_lo", "contact", "impulse", "v_normal_pre", "v_normal_post")
# Columns of the phase rows: kind 0 = flight, 1 = contact (held contacts, −1 padded).
PHASE_COLUMNS = ("t_start", "t_end", "kind", "contact0", "contact1", "contact2")
PHASE_FLIGHT, PHASE_CONTACT = 0, 1

# What run_events returns
RETURN_DONE = 0  # the run has ended (state.status)
RETURN_YIELD = 1  # work_budget steps done: call again to go on
RETURN_GROW = 2  # an output array needs more rows: grow it and call again

# counts[...] of the output arrays: rows written of each, and the overflow flag
N_SAMPLES, N_IMPACTS, N_PHASES, N_ACCUMULATIONS, OVERFLOW = range(5)

# rows every loop step may add at most to impacts, phases and accumulation times (the
# loop asks for more below it, and Problem.grow grows exactly those)
STEP_ROWS = 4
