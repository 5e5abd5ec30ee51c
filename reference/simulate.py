"""`simulate`: the exact reference on a scene, returned as a `Trajectory`.

This module sets the problem up for the compiled event loop (reference.core.loop: the
model, options and state as records), calls it until the run ends, growing the output
arrays when it asks and reporting progress between calls, and turns what it wrote into
a Trajectory with a status, a message and typed `RunStats`.  The physics is all in
reference.core.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import compiled
from .checks import check_reference_options, run_horizon
from .core import records as R
from .core.laws import LAW_PAPER, law_code, law_of, law_of_name, work_floats
from .core.records import (
    N_ACCUMULATIONS,
    N_IMPACTS,
    N_PHASES,
    N_SAMPLES,
    OVERFLOW,
    RETURN_DONE,
    RETURN_GROW,
)
from .core.tolerances import STALL_WINDOW, TILT_FLOOR
from .geometry import initial_state
from .options import ReferenceOptions
from .scene import (
    Scene,
    check_impact_law,
    check_window,
    check_window_bound,
    reference_window,
    scene_from_dict,
    time_unit,
    window_speed_unit,
)
from .stats import RunStats
from .trajectory import ImpactLog, PhaseLog, Status, Trajectory

# Rows of the output arrays: enough for the sample grid and a number of impacts (two
# samples and about two phases per impact; `output_rows`).  A run starts with rows for
# FIRST_IMPACTS impacts (or max_impacts if fewer), and the first time the loop asks for
# more they jump to the rows for max_impacts, doubling after that.  Sizing every run for
# max_impacts would map memory that a short run never writes, first touched page by
# page inside the timed run (about 1.6 µs of the 10 µs one-impact run); small arrays
# come from the allocator's reused heap, and a longer run copies its first rows once.
ROWS_PER_IMPACT = {"samples": 2, "phases": 2}
FIRST_IMPACTS = 1024
MIN_ROWS = 64


def output_rows(impacts: int, t_end: float, opts: ReferenceOptions) -> dict[str, int]:
    """Rows of the sample, impact and phase arrays for `impacts` impacts and the sample
    grid (samples at most opts.max_samples)."""
    n_imp = min(impacts, 10_000_000) + MIN_ROWS
    grid = t_end / (opts.sample_dt or t_end / 2000.0)
    n_s = int(min(max(opts.max_samples, 1), ROWS_PER_IMPACT["samples"] * n_imp + grid + MIN_ROWS))
    return {"samples": n_s, "impacts": n_imp, "phases": ROWS_PER_IMPACT["phases"] * n_imp}


@dataclass
class Problem:
    """The records and arrays one run of the loop reads and writes."""

    run: np.ndarray  # records.RUN, 1 element: model, options, state, counters, scratch
    points: np.ndarray  # (k, 4) contact points and kinds (GroundContacts.core_points)
    sample_t: np.ndarray
    sample_y: np.ndarray
    sample_e: np.ndarray
    impacts: np.ndarray
    phases: np.ndarray
    accumulations: np.ndarray
    contact_ints: np.ndarray  # (4, k) and (4, k): the loop's per-contact lists
    contact_floats: np.ndarray  # (records.new_contact_arrays)
    law_arrays: tuple  # the scratch of a law impact (records.new_law_arrays)
    full_rows: dict[str, int]  # output_rows for max_impacts: the first growth's sizes
    _arguments: tuple | None = None  # (kept until the arrays grow)

    # The parts of the run record, as 1-element record arrays (views: writable)
    model = property(lambda self: self.run["model"])
    options = property(lambda self: self.run["options"])
    state = property(lambda self: self.run["state"])
    counters = property(lambda self: self.run["stats"])
    scratch = property(lambda self: self.run["scratch"])
    counts = property(lambda self: self.run["counts"][0])  # rows written: records.N_*

    def arguments(self) -> tuple:
        if self._arguments is None:
            self._arguments = (
                self.run, self.points, self.sample_t, self.sample_y, self.sample_e,
                self.impacts, self.phases, self.accumulations, self.contact_ints,
                self.contact_floats, *self.law_arrays,
            )  # fmt: skip
        return self._arguments

    def grow(self, max_samples: int) -> None:
        """Grow the arrays the loop ran short of (to their full_rows, or twice their
        rows if that is more): impacts with fewer than options.step_rows free rows,
        phases and accumulation times with fewer than STEP_ROWS (the loop's own test
        before every step); otherwise the
        samples (the only rows a step itself asks for), up to max_samples rows.  Growing
        the large sample arrays only when they are what is short keeps runs with many
        chatter completions from copying them again and again."""
        self._arguments = None
        c = self.counts
        short = False
        step_rows = int(self.options["step_rows"][0])
        for name, col, need in (("impacts", N_IMPACTS, step_rows),
                                ("phases", N_PHASES, R.STEP_ROWS),
                                ("accumulations", N_ACCUMULATIONS, R.STEP_ROWS)):  # fmt: skip
            arr = getattr(self, name)
            if len(arr) - c[col] < need:
                rows = max(2 * len(arr), self.full_rows.get(name, 0), c[col] + need)
                setattr(self, name, _grown(arr, rows))
                short = True
        rows = min(max(2 * len(self.sample_t), self.full_rows["samples"]), max(max_samples, 1))
        if not short and rows > len(self.sample_t):
            self.sample_t = _grown(self.sample_t, rows)
            self.sample_y = _grown(self.sample_y, rows)
            self.sample_e = _grown(self.sample_e, rows)


def _grown(arr: np.ndarray, rows: int) -> np.ndarray:
    new = np.empty((rows, *arr.shape[1:]), dtype=arr.dtype)
    new[: len(arr)] = arr
    return new


def model_record(scene: Scene) -> np.ndarray:
    """The body, ground and impact law as the core reads them."""
    i1, _, i3 = scene.body.inertia_diag
    contacts = scene.contacts
    rec = np.zeros(1, dtype=R.MODEL)
    rec["mass"], rec["i1"], rec["i3"] = scene.body.mass, i1, i3
    rec["radius"], rec["gravity"], rec["gamma"] = (
        scene.body.radius,
        scene.gravity,
        scene.restitution,
    )
    rec["n_contacts"] = contacts.n
    rec["n_rim"] = contacts.n_rim
    rec["invariants"] = contacts.invariants
    rec["sag"] = 1.0 - math.cos(math.pi / scene.body.n)
    rec["all_down"] = contacts.all_down
    rec["window_per_speed"] = reference_window(scene) / window_speed_unit(scene)
    rec["floor_depth"] = scene.ground.floor_below(scene.body)
    rec["law"] = law_code(scene.impact_law)
    rec["law_separating"] = law_of(rec["law"][0]).separating
    rec["time_unit"] = time_unit(scene)
    return rec


def law_arrays(scene: Scene, opts: ReferenceOptions) -> tuple:
    """The scratch of a simultaneous impact under the scene's law (records.new_law_arrays)."""
    k = law_contacts(scene)
    work = work_floats(law_of_name(scene.impact_law), k)
    return R.new_law_arrays(k, opts.sequential_order or (), work)


def law_contacts(scene: Scene) -> int:
    """How many contacts a simultaneous impact of the scene's law may take at most (the
    rows of its scratch): none under `paper` (a row of scratch), else all of them up
    to MAX_LAW_CONTACTS."""
    if law_code(scene.impact_law) == LAW_PAPER:
        return 1
    from .core.impact_laws import MAX_LAW_CONTACTS  # here: the core's modules import numba

    return min(scene.contacts.n, MAX_LAW_CONTACTS)


def options_record(scene: Scene, t_end: float, opts: ReferenceOptions) -> np.ndarray:
    rec = np.zeros(1, dtype=R.OPTIONS)
    rec["t_end"] = t_end
    rec["sample_dt"] = opts.sample_dt or t_end / 2000.0
    rec["chatter_tol"] = opts.chatter_tol
    rec["contact_rtol"] = opts.contact_rtol
    rec["energy_floor"] = opts.energy_floor
    rec["max_samples"] = opts.max_samples
    rec["max_impacts"] = scene.run.max_impacts
    rec["window_search"] = opts.window_search
    rec["work_budget"] = opts.work_budget
    rec["n_order"] = len(opts.sequential_order or ())
    paper = law_code(scene.impact_law) == LAW_PAPER
    rec["step_rows"] = R.STEP_ROWS + (0 if paper else law_contacts(scene))
    return rec


def initial_record(y0: np.ndarray) -> np.ndarray:
    rec = np.zeros(1, dtype=R.STATE)
    rec["y"][0] = y0
    rec["status"] = R.STATUS_RUNNING
    rec["info_contact"] = -1
    rec["t_singularity"] = math.nan
    return rec


def make_problem(scene: Scene, t_end: float, opts: ReferenceOptions) -> Problem:
    rows = output_rows(min(scene.run.max_impacts, FIRST_IMPACTS), t_end, opts)
    points = np.array(scene.contacts.core_points)  # (the loop's own, writable copy)
    contact_ints, contact_floats = R.new_contact_arrays(len(points))
    run = np.zeros(1, dtype=R.RUN)
    run["model"] = model_record(scene)
    run["options"] = options_record(scene, t_end, opts)
    run["state"] = initial_record(initial_state(scene.initial))
    return Problem(
        run=run,
        points=points,
        sample_t=np.empty((rows["samples"], 2)),
        sample_y=np.empty((rows["samples"], 13)),
        sample_e=np.empty((rows["samples"], 2)),
        impacts=np.empty((rows["impacts"], 6)),
        phases=np.empty((rows["phases"], 6)),
        accumulations=np.empty(MIN_ROWS),
        contact_ints=contact_ints,
        contact_floats=contact_floats,
        law_arrays=law_arrays(scene, opts),
        full_rows=output_rows(scene.run.max_impacts, t_end, opts),
    )


def run_problem(
    kernel, problem: Problem, max_samples: int, progress: Callable[[float], None] | None = None
) -> None:
    """Call the loop until the run ends: grow the outputs when it asks, report the time
    reached between calls (a KeyboardInterrupt lands between calls, on a consistent
    state)."""
    while True:
        code = kernel(*problem.arguments())
        if code == RETURN_DONE:
            return
        if code == RETURN_GROW:
            problem.grow(max_samples)
        elif progress is not None:
            progress(float(problem.state["t_hi"][0]))


def simulate(
    scene: Scene | str,
    t_end: float | None = None,
    options: ReferenceOptions | None = None,
    progress: Callable[[float], None] | None = None,
) -> Trajectory:
    """Run the exact reference on `scene` (a Scene, a scene file or a built-in name)
    until t_end (default scene.run.t_end).

    `progress(t)` is called with the time reached whenever the loop returns to Python
    (every `options.work_budget` steps).  stats.wall_time_s is the run alone;
    stats.compile_s the one-time compilation or loading that preceded it."""
    from .scenes import as_scene

    scene = as_scene(scene)
    opts = ReferenceOptions() if options is None else options
    t_end = run_horizon(scene, t_end)  # SceneError before any work (reference.checks)
    check_reference_options(opts, scene)
    law, window = impact_law_of(scene, opts)
    if (law, window) != (scene.impact_law, scene.simultaneity_window):
        scene = scene.with_impact_law(law, window)  # the options' choice, for the core
    compile_s = load_event_loop()
    problem = make_problem(scene, t_end, opts)
    kernel = compiled.run_events()
    t0 = time.perf_counter()
    run_problem(kernel, problem, opts.max_samples, progress)
    wall = time.perf_counter() - t0
    traj = _trajectory(scene, problem, opts, t_end, wall, compile_s)
    traj.impact_law, traj.simultaneity_window = law, window
    return traj


def impact_law_of(scene: Scene, opts: ReferenceOptions) -> tuple[str, float]:
    """The impact law and simultaneity window of a run: the options' if set, else the
    scene's, else (the window) the law's default (scene.reference_window)."""
    law = opts.impact_law if opts.impact_law is not None else scene.impact_law
    window = (
        opts.simultaneity_window
        if opts.simultaneity_window is not None
        else reference_window(scene, law)
    )
    return check_impact_law(law), check_window_bound(scene, check_window(window))


# A rough cost of compiling the loop just in time on a 2-core machine (measured: 169 s of
# CPU, numba's compile events; docs/development.md).
JIT_COMPILE_ESTIMATE_S = 170
_event_loop_loaded = False


def load_event_loop() -> float:
    """Compile or load the event loop once per process (a tiny run); returns the seconds
    it took (0 when already done).  The first compilation on a machine is announced on
    stderr with its rough duration."""
    global _event_loop_loaded
    if _event_loop_loaded:
        return 0.0
    t0 = time.perf_counter()
    kernel = compiled.run_events()
    if compiled.kernel_source() == "just-in-time" and not compiled.jit_cached():
        print(
            f"reference: compiling the event loop (first run on this machine, about "
            f"{JIT_COMPILE_ESTIMATE_S} s; `make setup` builds it ahead of time)",
            file=sys.stderr,
            flush=True,
        )
    tiny_run(kernel)
    _event_loop_loaded = True
    return time.perf_counter() - t0


def tiny_run(kernel) -> None:
    """A run of a few events, to compile or load the loop (`load_event_loop`)."""
    scene = scene_from_dict(
        {
            "body": {"n": 3},
            "initial": {"q": [0.01, 0.0, 0.02], "p": [0.0, 0.1, -0.1]},
            "run": {"t_end": 0.05, "max_impacts": 3},
        }
    )
    opts = ReferenceOptions(max_samples=64)
    problem = make_problem(scene, 0.05, opts)
    run_problem(kernel, problem, opts.max_samples)


# ----------------------------------------------------------------------------- result

_STATUS = {
    R.STATUS_T_END: Status.T_END,
    R.STATUS_SINGULARITY: Status.SINGULARITY,
    R.STATUS_ENERGY_EXHAUSTED: Status.SINGULARITY,
    R.STATUS_AT_REST: Status.SINGULARITY,
    R.STATUS_TILT_FLOOR: Status.SINGULARITY,
    R.STATUS_SIMULTANEOUS: Status.SIMULTANEOUS_IMPACT,
    R.STATUS_PUSHED: Status.SIMULTANEOUS_IMPACT,
    R.STATUS_MAX_IMPACTS: Status.MAX_IMPACTS,
    R.STATUS_OFF_FACE: Status.LEFT_MODEL,
    R.STATUS_BELOW_FLOOR: Status.LEFT_MODEL,
    R.STATUS_LAW_UNDECIDED: Status.SIMULTANEOUS_IMPACT,
    R.STATUS_FLAT_REST: Status.SINGULARITY,
    R.STATUS_STALLED: Status.STALLED,
}


def _law_name(md) -> str:
    """The name of the model record's impact law."""
    from .core.laws import LAWS

    return next(x.name for x in LAWS if x.code == int(md["law"]))


def _law_undecided(st, md, t, cs) -> str:
    """Why the run's impact law left a simultaneous impact undecided (law_event)."""
    # here: the core's modules import numba (this runs only for such a run's message)
    from .core.law_message import undecided_message

    return undecided_message(_law_name(md), int(st["law_outcome"]), t, cs)


# One-sentence messages per loop status: (state, options, model, t, the info contacts'
# names) → text, formatted only for the status a run ends with.  Contacts are named as in
# every table (v2: rim vertex 2, b1: bump 1; GroundContacts.label).
_MESSAGES = {
    R.STATUS_T_END: lambda st, op, md, t, cs: f"reached t_end = {float(op['t_end']):g}",
    R.STATUS_SINGULARITY: lambda st, op, md, t, cs: f"all contacts down at t = {t:.17g}",
    R.STATUS_ENERGY_EXHAUSTED: lambda st, op, md, t, cs: (
        f"energy exhausted to {float(op['energy_floor']):g} of its initial excess; "
        "t_singularity extrapolated from the impact intervals"
    ),
    R.STATUS_TILT_FLOOR: lambda st, op, md, t, cs: (
        f"inclination below {TILT_FLOOR:g} rad at t = {t:.17g}: the singularity for "
        "double precision; t_singularity extrapolated from the impact intervals"
    ),
    R.STATUS_AT_REST: lambda st, op, md, t, cs: (
        f"at rest on {cs} at t = {t:.17g}: the motion has ended"
    ),
    R.STATUS_SIMULTANEOUS: lambda st, op, md, t, cs: f"{cs} hit simultaneously at t = {t:.17g}",
    R.STATUS_PUSHED: lambda st, op, md, t, cs: (
        f"an impact at {md['label'](int(st['info_contact']))} at t = {t:.17g} would push "
        f"{cs}, resting, into the ground (undecidable)"
    ),
    R.STATUS_MAX_IMPACTS: lambda st, op, md, t, cs: (
        f"reached max_impacts = {int(op['max_impacts'])}"
    ),
    R.STATUS_FAILED_NONFINITE: lambda st, op, md, t, cs: f"non-finite state at t = {t:.17g}",
    R.STATUS_OFF_FACE: lambda st, op, md, t, cs: (
        f"{cs or 'a bump'} meets the face's plane outside its rim "
        f"at t = {t:.17g}: the body has left the bumps (outside the three_point model)"
    ),
    R.STATUS_BELOW_FLOOR: lambda st, op, md, t, cs: (
        f"the rim reached the floor plane z = {-float(md['floor_depth']):g} (floor_depth "
        f"below the bumps' tops) at t = {t:.17g}, which the three_point ground does not "
        "model: the body has left the model"
    ),
    R.STATUS_LAW_UNDECIDED: lambda st, op, md, t, cs: _law_undecided(st, md, t, cs),
    R.STATUS_FLAT_REST: lambda st, op, md, t, cs: (
        f"flat bounces from t = {t:.17g} completed in closed form (t_f = t + 2u/(g(1 - "
        f"gamma))): at rest on all contacts at t = {float(st['t_hi']):.17g}"
    ),
    R.STATUS_FAILED_LCP: lambda st, op, md, t, cs: (
        f"contact complementarity problem of {cs} has no solution (at t = {t:.17g})"
    ),
    R.STATUS_FAILED_STUCK: lambda st, op, md, t, cs: (
        f"event search did not converge (at t = {t:.17g})"
    ),
    R.STATUS_FAILED_INTEGRATION: lambda st, op, md, t, cs: (
        f"contact integration failed: step size below roundoff (at t = {t:.17g})"
    ),
    R.STATUS_FAILED_NO_ADVANCE: lambda st, op, md, t, cs: (
        f"contact phase cannot advance at t = {t:.17g} (chunk horizon 0, with {cs} held)"
    ),
    R.STATUS_STALLED: lambda st, op, md, t, cs: _stalled(st, op, md, t, cs),
}


def _stalled(st, op, md, t, cs) -> str:
    """Why the loop ended a run that stopped advancing (loop._stalled)."""
    law = _law_name(md)
    held = f"{cs} held" if cs else "no contact held"
    return (
        f"the run stopped advancing at t = {t:.17g} ({held}, {law} law): {STALL_WINDOW} loop steps "
        f"without an impact advanced t by {float(st['stall_advance']):.3g} s, less than "
        f"{float(st['stall_bound']):.3g} s (contact_rtol = {float(op['contact_rtol']):g} "
        "of the motion's time scale a step, the integrator's own error): the run would "
        "not end"
    )


def status_message(
    state: np.void, opts: np.void, model: np.void, label: Callable[[int], str] | None = None
) -> tuple[Status, str]:
    """The Trajectory status and its one-sentence message for the loop's end state (the
    run's options and model records; `label` names contact k, 'contact k' without it)."""
    code = int(state["status"])
    message = _MESSAGES.get(code)
    if message is None:
        return _STATUS.get(code, Status.FAILED), f"loop status {code}"
    name = label or (lambda k: f"contact {k}")
    contacts = ", ".join(
        name(k) for k in sorted(int(c) for c in state["info"][: int(state["n_info"])])
    )
    t = float(state["info_t"])
    fields = {field: model[field] for field in model.dtype.names} | {"label": name}
    return _STATUS.get(code, Status.FAILED), message(state, opts, fields, t, contacts)


def _trajectory(
    scene: Scene, p: Problem, opts: ReferenceOptions, t_end: float, wall: float, compile_s: float
) -> Trajectory:
    c = p.counts
    if c[OVERFLOW]:  # the loop checks for free rows before each step: a bug if reached
        raise RuntimeError(
            "reference: an output array ran out of rows during the run, so the trajectory "
            "would be incomplete (internal error; please report it with the scene)"
        )
    ns, ni, nph, nacc = (int(c[i]) for i in (N_SAMPLES, N_IMPACTS, N_PHASES, N_ACCUMULATIONS))
    state = p.state[0]
    status, message = status_message(state, p.options[0], p.model[0], scene.contacts.label)
    t_sing = float(state["t_singularity"])
    stats = RunStats.from_counters(
        p.counters[0],
        wall,
        compile_s,
        ni,
        chatter_accumulation_times=tuple(float(x) for x in p.accumulations[:nacc]),
        samples=ns,
    )
    return Trajectory.from_states(
        "reference",
        scene.name,
        p.sample_t[:ns, 0].copy(),
        p.sample_y[:ns],
        p.sample_e[:ns, 0].copy(),
        p.sample_e[:ns, 1].copy(),
        ImpactLog.from_rows(p.impacts[:ni]),
        status,
        t_lo=p.sample_t[:ns, 1].copy(),
        phases=PhaseLog(p.phases[:nph]),
        message=message,
        t_final=float(state["t_hi"]),
        t_singularity=None if math.isnan(t_sing) else t_sing,
        stats=stats,
    )
