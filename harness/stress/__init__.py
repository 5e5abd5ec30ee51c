"""`harness stress`: hard cases, every simulator, a verdict per case and simulator.

Cases (`stress_cases`) are Scenes built in code: the inclination α from 1e-3 down to
1e-12 (the paper's scaling q → ε²q, p → εp of one pentagon), a grazing contact, two
near-simultaneous hits, a chatter sequence, an elastic run (γ = 1) at unit scale and a
long one (100,000 impacts, at scale 0.02: bounces of ~1e-5 of the radius), a fast
spin near the singularity, n = 1000, γ = 0 sustained rolling and the three-point ground.

Each case runs on every requested simulator (fixed-step engines at one stated dt,
default 1e-4) to the case's t_end, and is judged (`assess`) on:

- finished: the run returned, is not `failed`, has no NaN, and reached t_end or stopped
  with a physics status (singularity, simultaneous impact, max_impacts);
- nan: a non-finite value in its states or energies;
- energy_gain: max over samples of (E − E0)/|E0|, clipped at 0 (no model here gains
  energy: impacts dissipate or conserve it, flight and frictionless contact conserve it);
- max_penetration: deepest contact gap below the ground, −min gap, from the run's states
  with the reference's contact geometry (`engines.base.contact_kinematics`, plus the
  adapters' per-step `min_gap` and the reference's `max_penetration`), also relative to
  the case's length scale L (`BodyModel.length_scale` at t = 0: height of the centre
  plus the rim's vertical extent);
- missed / spurious impacts against the reference (`unmatched_impacts`: one-to-one
  matching per contact within the metrics' windows, chatter tails left out), plus the
  metrics' leading-match count and first mismatch;
- the final status.

Verdict: `failed` (NaN, not finished, energy gain > 10 %, penetration > L/2, or not one
of the reference's impacts matched, in any order), else `degraded` (energy gain or
penetration above the simulator's tolerance, `TOLERANCES`; any missed or spurious
impact), else `ok`; the reasons are listed.  A run whose predicted cost exceeds the
per-run budget is not run: verdict `skipped (budget)` with the prediction (engines: two
short pilot runs give the setup and per-step cost; the reference: a pilot over a tenth
of the case); an engine or linear run still going at twice the budget is stopped (it
runs in a forked child process) and reported the same way.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from engines.base import contact_kinematics
from reference.body import BodyModel, initial_state
from reference.scene import Body, Ground, InitialState, RunSettings, Scene, SceneError
from reference.simulate import ReferenceOptions, simulate
from reference.trajectory import Status, Trajectory

from ..metrics import (
    chatter_tail,
    common_window,
    impact_windows,
    match_impacts,
    match_tolerance,
)
from ..scenes import resolve_scene
from ..simulators import DEFAULT_DT, ENGINES, FIXED_STEP, check_engine, run_simulator
from ..text import table

DEFAULT_BUDGET_S = 30.0  # per run
# Verdict thresholds.  Energy gain relative to |E0|; penetration relative to L.
FAILED_ENERGY_GAIN = 0.1
FAILED_PENETRATION = 0.5
# (energy gain, penetration) above which a run is degraded: the exact reference must
# keep both at roundoff level; approximate simulators (engines, the linear model, whose
# gaps are the linearised ones) get 1e-3 of the energy and 1 % of the length scale.
TOLERANCES = {"reference": (1e-9, 1e-9), "approximate": (1e-3, 1e-2)}
# Engines: runs longer than this many steps are predicted from pilots first.
PILOT_FREE_STEPS = 5000
# Engines and the linear model run in a child process stopped at this × the budget
# (pilot predictions miss contact-heavy later phases: measured up to 10x+ too low).
HARD_CAP_FACTOR = 2.0
PILOT_STEPS = (200, 2000)
# Reference: pilot over this fraction of t_end and of max_impacts.
REFERENCE_PILOT_FRACTION = 0.1
SKIPPED = "skipped (budget)"
# Physics statuses that end a run legitimately before t_end.
STOPS = {Status.SINGULARITY, Status.SIMULTANEOUS_IMPACT, Status.MAX_IMPACTS}


@dataclass(frozen=True)
class StressCase:
    name: str
    description: str
    scene: Scene


# ----------------------------------------------------------------------------- cases

# One pentagon (γ = 0.5) in linear coordinates; |φ| = 0.01166 at scale 1, and its
# reference run ends (undecidable) at t ≈ 0.84 ε.
_ALPHA_Q = (0.01, -0.006, 0.05)
_ALPHA_P = (0.05, 0.02, -0.1)
ALPHAS = (1e-3, 1e-6, 1e-9, 1e-12)
# elastic-hexagon scaled by ε: its linear model reaches 100,000 impacts at
# t = 13037.9 ε (measured: `simulate_linear` of elastic-hexagon, max_impacts 1e5).
LONG_ELASTIC_EPS = 0.02
LONG_ELASTIC_IMPACTS = 100_000
LONG_ELASTIC_T_PER_EPS = 13040.0


def _polygon(
    name: str, n: int, gamma: float, initial: InitialState, t_end: float, rho: float = 0.5
) -> Scene:
    return Scene(
        name=name,
        body=Body(n=n, gyration=rho),
        ground=Ground(),
        initial=initial,
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=t_end, max_impacts=100_000),
    )


def alpha_scene(alpha: float) -> Scene:
    """The pentagon scaled so that its initial inclination is α: ε = √(α / |φ0|),
    t_end = ε (the motion's time scale is ε)."""
    from reference.scene import initial_from_linear

    base = _polygon("stress-alpha", 5, 0.5, initial_from_linear(_ALPHA_Q, _ALPHA_P), 1.0)
    eps = math.sqrt(alpha / math.hypot(_ALPHA_Q[0], _ALPHA_Q[1]))
    s = base.scaled(eps).with_run(t_end=eps)
    return _renamed(s, f"stress-alpha-{alpha:.0e}".replace("e-0", "e-"))


def fast_spin_scene(n: int = 16, alpha: float = 1e-3, spin: float = 100.0) -> Scene:
    """A 16-gon tilted by α = 1e-3 (rotation about x), its lowest vertex 1e-4 above the
    ground, spinning at 100 rad/s about the vertical: each vertex passes the low point
    every 2π/(n·spin) ≈ 4 ms, the inclination is 1e-3."""
    a = 1.0
    initial = InitialState(
        position=(0.0, 0.0, a * math.sin(alpha) + 1e-4),
        rotation_vector=(alpha, 0.0, 0.0),
        velocity=(0.0, 0.0, 0.0),
        angular_velocity=(0.0, 0.0, spin),
    )
    return _polygon("stress-fast-spin", n, 0.5, initial, 0.3)


def _renamed(scene: Scene, name: str) -> Scene:
    from dataclasses import replace

    return replace(scene, name=name)


def stress_cases() -> list[StressCase]:
    """The hard cases, in order (names are what `--case` selects)."""
    from dataclasses import replace

    cases = [
        StressCase(
            f"alpha-{a:.0e}".replace("e-0", "e-"),
            f"pentagon gamma=0.5 scaled to inclination {a:g} (t_end = time scale)",
            alpha_scene(a),
        )
        for a in ALPHAS
    ]
    grazing = resolve_scene("grazing-contact")
    near = resolve_scene("near-simultaneous")
    chatter = resolve_scene("triangle-chatter").with_run(t_end=1.0)
    elastic_unit = resolve_scene("elastic-hexagon")
    elastic = elastic_unit.scaled(LONG_ELASTIC_EPS)
    elastic = _renamed(elastic, "stress-long-elastic").with_run(
        t_end=LONG_ELASTIC_T_PER_EPS * LONG_ELASTIC_EPS, max_impacts=LONG_ELASTIC_IMPACTS
    )
    pentagon = resolve_scene("pentagon-bounce")
    n1000 = replace(pentagon, name="stress-n1000", body=replace(pentagon.body, n=1000))
    n1000 = n1000.with_run(t_end=1.0)
    rolling = resolve_scene("polygon25-rolling").with_run(t_end=1.0)
    three = resolve_scene("three-point-disk").with_run(t_end=1.0)
    cases += [
        StressCase("grazing", grazing.description, grazing),
        StressCase("near-simultaneous", near.description, near),
        StressCase("chatter", chatter.description + " (t_end 1)", chatter),
        StressCase(
            "elastic",
            elastic_unit.description + " (t_end 20, unit scale)",
            _renamed(elastic_unit, "stress-elastic"),
        ),
        StressCase(
            "long-elastic",
            f"hexagon gamma=1 scaled by {LONG_ELASTIC_EPS:g}: "
            f"{LONG_ELASTIC_IMPACTS:,} impacts for the reference, engines the same time",
            elastic,
        ),
        StressCase(
            "fast-spin",
            "16-gon at inclination 1e-3 spinning at 100 rad/s about the vertical",
            fast_spin_scene(),
        ),
        StressCase("n1000", "pentagon-bounce's state with n = 1000 (t_end 1)", n1000),
        StressCase("rolling-gamma0", rolling.description + " (t_end 1)", rolling),
        StressCase("three-point", three.description + " (t_end 1)", three),
    ]
    return cases


def select_cases(names: Sequence[str] | None) -> list[StressCase]:
    """Cases by exact name or name prefix (`alpha` selects every alpha case)."""
    cases = stress_cases()
    if not names:
        return cases
    out: list[StressCase] = []
    for name in names:
        hit = [c for c in cases if c.name == name] or [c for c in cases if c.name.startswith(name)]
        if not hit:
            raise SceneError(
                f"unknown stress case {name!r}; choose from {', '.join(c.name for c in cases)}"
            )
        out += [c for c in hit if c not in out]
    return out


# ----------------------------------------------------------------------------- judging


def has_nan(run: Trajectory) -> bool:
    """A non-finite value in the samples, or a failure message that reports one."""
    arrays = (
        run.t,
        run.position,
        run.quaternion,
        run.velocity,
        run.angular_velocity,
        run.kinetic_energy,
        run.potential_energy,
    )
    if any(a.size and not np.all(np.isfinite(a)) for a in arrays):
        return True
    msg = run.message.lower()
    return run.status is Status.FAILED and ("nan" in msg or "non-finite" in msg)


def energy_gain(run: Trajectory) -> float | None:
    """max over samples of (E − E0)/|E0|, clipped at 0 (NaN samples ignored); None
    without samples.  |E0| = 0 falls back to the largest |E|."""
    e = run.energy
    if e.size == 0:
        return None
    e0 = float(e[0])
    scale = abs(e0)
    if not (scale > 0 and math.isfinite(scale)):
        finite = np.abs(e[np.isfinite(e)])
        scale = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
    d = (e - e0) / scale
    d = d[np.isfinite(d)]
    return max(0.0, float(d.max())) if d.size else None


def max_penetration(run: Trajectory, scene: Scene) -> float | None:
    """Deepest contact below the ground, max(0, −min gap), over the run's samples
    (reference contact geometry) and whatever the simulator measured itself
    (`stats["min_gap"]` of engine adapters: every step; `stats["max_penetration"]` of
    the reference: at impacts)."""
    depth = []
    if run.n_samples:
        states = np.concatenate(
            [run.position, run.quaternion, run.velocity, run.angular_velocity], axis=1
        )
        ok = np.all(np.isfinite(states), axis=1)
        if np.any(ok):
            gap, _ = contact_kinematics(scene, states[ok])
            depth.append(-float(gap.min()))
    g = run.stats.get("min_gap")
    if g is not None and math.isfinite(g):
        depth.append(-float(g))
    p = run.stats.get("max_penetration")
    if p is not None and math.isfinite(p):
        depth.append(float(p))
    return max(0.0, *depth) if depth else None


def length_scale(scene: Scene) -> float:
    """Height of the centre plus the rim's vertical extent at t = 0 (the case's length
    unit for penetration), the radius if that is 0."""
    y0 = initial_state(scene)
    L = BodyModel.from_scene(scene).length_scale(y0)
    return L if L > 0 else scene.body.radius


def unmatched_impacts(
    run: Trajectory, reference: Trajectory, gravity: float
) -> tuple[int, int, int] | None:
    """(missed, spurious, counted) impacts of `run` against `reference` over their
    common window; `counted` is the number of reference impacts that take part.

    One-to-one matching per contact, order-free: a run impact and a reference impact at
    the same contact match when |t_run − t_ref| ≤ the reference impact's window
    (`metrics.impact_windows` with `metrics.match_tolerance`), closest pairs first.
    Missed: reference impacts in the window left unmatched; spurious: run impacts in
    the window left unmatched (run impacts up to one window past its end may match, as
    in `metrics.match_impacts`).  Chatter-tail impacts (`metrics.chatter_tail`), which
    every simulator truncates somewhere, are not counted.  After the runs diverge
    (chaotic motions do) every later impact counts, so read these with the first
    mismatch.  None when the runs have no common window."""
    window = common_window(run, reference)
    if window is None:
        return None
    t0, t1 = window
    tol = match_tolerance(run, reference, gravity)
    tr = reference.impact_times().astype(float)
    cr = reference.impact_contacts()
    wr = impact_windows(reference, tol)
    te = run.impact_times().astype(float)
    ce = run.impact_contacts()
    keep_r = (tr >= t0) & (tr <= t1) & ~chatter_tail(reference, tol.tail_speed)
    reach = t1 + float(tol.window(t1))
    keep_e = (te >= t0) & (te <= reach) & ~chatter_tail(run, tol.tail_speed)
    used_r = np.zeros(len(tr), dtype=bool)
    used_e = np.zeros(len(te), dtype=bool)
    for k in np.union1d(cr[keep_r], ce[keep_e]):
        ir = np.flatnonzero(keep_r & (cr == k))
        ie = np.flatnonzero(keep_e & (ce == k))
        if not ir.size or not ie.size:
            continue
        tek = te[ie]
        pairs = []
        for i in ir:
            lo = np.searchsorted(tek, tr[i] - wr[i], side="left")
            hi = np.searchsorted(tek, tr[i] + wr[i], side="right")
            pairs += [(abs(tek[j] - tr[i]), i, ie[j]) for j in range(lo, hi)]
        for _, i, j in sorted(pairs):
            if not used_r[i] and not used_e[j]:
                used_r[i] = used_e[j] = True
    missed = int(np.sum(keep_r & ~used_r))
    spurious = int(np.sum(keep_e & ~used_e & (te <= t1)))
    return missed, spurious, int(np.sum(keep_r))


def assess(
    run: Trajectory,
    reference: Trajectory | None,
    scene: Scene,
    t_target: float,
    exact: bool = False,
    error: str | None = None,
) -> dict[str, Any]:
    """Measurements and verdict of one run (module docstring).  `exact`: judge with the
    reference's tolerances.  `error`: the exception the run raised, if any."""
    nan = has_nan(run)
    # fixed-step runs take whole steps: up to one step short of t_end counts as reached
    slack = max(float(run.dt or 0.0), 1e-9 * t_target)
    reached = run.t_final >= t_target - slack
    finished = (
        error is None
        and run.status is not Status.FAILED
        and not nan
        and (reached or run.status in STOPS)
    )
    gain = energy_gain(run)
    depth = max_penetration(run, scene)
    L = length_scale(scene)
    row: dict[str, Any] = {
        "status": run.status.value,
        "message": error or run.message,
        "finished": finished,
        "nan": nan,
        "energy_gain": gain,
        "max_penetration": depth,
        "penetration_relative": None if depth is None else depth / L,
        "length_scale": L,
        "t_final": run.t_final,
        "t_target": t_target,
        "impacts": len(run.impacts),
        "missed_impacts": None,
        "spurious_impacts": None,
        "reference_impacts": None,
        "impacts_matched": None,
        "first_mismatch": None,
        "reference_impacts_counted": None,
    }
    if reference is not None and reference.n_samples and run.n_samples:
        counts = unmatched_impacts(run, reference, scene.gravity)
        if counts is not None:
            row["missed_impacts"], row["spurious_impacts"], counted = counts
            row["reference_impacts_counted"] = counted
        m = match_impacts(run, reference, match_tolerance(run, reference, scene.gravity))
        row["reference_impacts"] = m.n_reference
        row["impacts_matched"] = m.n_matched
        row["first_mismatch"] = m.reason
    failed, degraded = [], []
    if error is not None:
        failed.append(f"raised {error}")
    if nan:
        failed.append("NaN in the state")
    if not finished and error is None:
        if run.status is Status.FAILED:
            failed.append(f"status failed: {run.message}")
        elif not reached:
            failed.append(f"stopped at t={run.t_final:.6g} before t_end={t_target:.6g}")
    gain_tol, depth_tol = TOLERANCES["reference" if exact else "approximate"]
    if gain is not None and gain > FAILED_ENERGY_GAIN:
        failed.append(f"energy gain {gain:.3g} > {FAILED_ENERGY_GAIN:g}")
    elif gain is not None and gain > gain_tol:
        degraded.append(f"energy gain {gain:.3g} > {gain_tol:g}")
    if depth is not None and depth > FAILED_PENETRATION * L:
        failed.append(f"penetration {depth:.3g} > {FAILED_PENETRATION:g} L (L={L:.3g})")
    elif depth is not None and depth > depth_tol * L:
        degraded.append(f"penetration {depth:.3g} = {depth / L:.3g} L > {depth_tol:g} L")
    missed, spurious = row["missed_impacts"], row["spurious_impacts"]
    counted = row.get("reference_impacts_counted")
    if counted and missed == counted and finished:
        failed.append(f"matched none of the reference's {counted} impacts")
    if missed or spurious:
        text = f"{missed} missed, {spurious} spurious impacts"
        if row["first_mismatch"]:
            text += f" (first mismatch: {row['first_mismatch']})"
        degraded.append(text)
    notes = []
    if run.status is Status.SIMULTANEOUS_IMPACT:
        notes.append("stopped undecidable (simultaneous impact)")
    row["verdict"] = "failed" if failed else "degraded" if degraded else "ok"
    row["reason"] = "; ".join(failed or degraded or notes)
    return row


# ----------------------------------------------------------------------------- running


def _timed(fn: Callable[[], Trajectory]) -> tuple[Trajectory | None, float, str | None]:
    start = time.perf_counter()
    try:
        traj, err = fn(), None
    except SceneError:
        raise
    except Exception as exc:  # a broken simulator is a result
        traj, err = None, f"{type(exc).__name__}: {exc}"
    return traj, time.perf_counter() - start, err


def run_reference(scene: Scene, budget_s: float) -> tuple[Trajectory | None, float, float, bool]:
    """The reference on a case within the budget: (trajectory, wall, predicted, skipped).

    A pilot runs the first REFERENCE_PILOT_FRACTION of the case (of t_end and of
    max_impacts, same sample grid).  If it ends on its own (singularity, undecidable
    impact, failure) it is the whole run; else the full run is predicted to cost
    wall / (fraction of the case done) and is run only within the budget.  When it is
    skipped the pilot is returned (skipped = True) as the basis for the engines."""
    t_end, n_max = scene.run.t_end, scene.run.max_impacts
    opts = ReferenceOptions(sample_dt=t_end / 2000.0)
    f = REFERENCE_PILOT_FRACTION
    pilot_scene = scene.with_run(max_impacts=max(100, int(f * n_max)))
    pilot, wall, err = _timed(lambda: simulate(pilot_scene, t_end=f * t_end, options=opts))
    if pilot is None:
        raise RuntimeError(f"the reference raised on {scene.name}: {err}")
    if pilot.status not in (Status.T_END, Status.MAX_IMPACTS):
        return pilot, wall, wall, False
    done = max(pilot.t_final / t_end, len(pilot.impacts) / max(n_max, 1), 1e-9)
    predicted = wall / done
    if predicted > budget_s:
        return pilot, wall, predicted, True
    full, wall, err = _timed(lambda: simulate(scene, options=opts))
    if full is None:
        raise RuntimeError(f"the reference raised on {scene.name}: {err}")
    return full, wall, predicted, False


def predict_engine_time(engine: str, scene: Scene, dt: float) -> float | None:
    """Predicted wall time of a fixed-step engine run of the whole case: pilots of
    PILOT_STEPS steps (the short one twice, the first as warm-up) give setup a and
    per-step cost c, predicted = a + c·steps.  None when the run is short enough to
    just run (≤ PILOT_FREE_STEPS steps)."""
    steps = scene.run.t_end / dt
    if steps <= PILOT_FREE_STEPS:
        return None
    short, long_ = PILOT_STEPS
    run_simulator(engine, scene, dt=dt, t_end=short * dt)  # warm-up: imports, caches
    _, t_long, _ = _timed(lambda: run_simulator(engine, scene, dt=dt, t_end=long_ * dt))
    _, t_short, _ = _timed(lambda: run_simulator(engine, scene, dt=dt, t_end=short * dt))
    c = max((t_long - t_short) / (long_ - short), 0.5 * t_long / long_)
    return max(t_short - c * short, 0.0) + c * steps


def _skipped_row(
    case: StressCase, engine: str, dt, predicted: float | None, reason: str
) -> dict[str, Any]:
    return {
        "case": case.name,
        "engine": engine,
        "dt": dt,
        "verdict": SKIPPED,
        "status": None,
        "finished": None,
        "nan": None,
        "energy_gain": None,
        "max_penetration": None,
        "missed_impacts": None,
        "spurious_impacts": None,
        "predicted_wall_time_s": predicted,
        "wall_time_s": None,
        "reason": reason,
    }


def _over_budget(predicted: float, budget: float) -> str:
    return f"predicted {predicted:.3g} s > budget {budget:g} s"


def run_capped(fn: Callable[[], Any], cap_s: float) -> tuple[Any, str | None]:
    """fn() in a forked child process, stopped after cap_s seconds of wall time.

    Returns (result, None) when it answered, (None, None) when it was stopped at the
    cap (the child, and only it, is terminated by its pid), and (None, message) when
    it died without answering (a crash inside an engine).  An exception inside fn is
    fn's business: it should return it as data."""
    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)

    def child() -> None:
        send.send(fn())
        send.close()

    proc = ctx.Process(target=child, daemon=True)
    proc.start()
    send.close()
    try:
        if recv.poll(cap_s):
            try:
                out = recv.recv()
            except EOFError:
                proc.join()
                return None, f"simulator process died (exit code {proc.exitcode})"
            proc.join()
            return out, None
        proc.terminate()
        proc.join(5.0)
        if proc.is_alive():
            proc.kill()
            proc.join()
        return None, None
    finally:
        recv.close()


def _engine_row(
    case: StressCase,
    engine: str,
    dt: float,
    ref: Trajectory,
    ref_partial: bool,
    budget_s: float,
) -> dict[str, Any]:
    """Run one non-reference simulator on a case (unless predicted over the budget) and
    judge it against the reference run `ref` (a prefix of the case if `ref_partial`)."""
    scene, t_end = case.scene, case.scene.run.t_end
    step = dt if engine in FIXED_STEP else None
    predicted = None
    if step is not None:
        try:
            predicted = predict_engine_time(engine, scene, step)
        except SceneError:
            raise
        except Exception:  # the run itself will report the failure
            predicted = None
        if predicted is not None and predicted > budget_s:
            return _skipped_row(case, engine, step, predicted, _over_budget(predicted, budget_s))

    def judged_run() -> dict[str, Any]:
        traj, wall, err = _timed(lambda: run_simulator(engine, scene, step, t_end))
        if traj is None:
            traj = Trajectory.failed(engine, scene.name, step, err or "")
        return {**assess(traj, ref, scene, t_end, error=err), "wall_time_s": wall}

    cap = HARD_CAP_FACTOR * budget_s
    row, crashed = run_capped(judged_run, cap)
    if row is None and crashed is None:
        guess = "not predicted" if predicted is None else f"predicted {predicted:.3g} s"
        why = f"stopped at the hard cap of {cap:g} s ({guess}, budget {budget_s:g} s)"
        skipped = _skipped_row(case, engine, step, predicted, why)
        skipped["wall_time_s"] = cap
        return skipped
    if row is None:  # the child died without an answer (e.g. a segfault in the engine)
        traj = Trajectory.failed(engine, scene.name, step, crashed or "")
        row = {**assess(traj, ref, scene, t_end, error=crashed), "wall_time_s": None}
    wall = row.pop("wall_time_s")
    if ref_partial and row["missed_impacts"] is not None:
        note = (
            f"compared with the reference's first {len(ref.impacts)} impacts "
            f"(t <= {ref.t_final:.6g}) only"
        )
        row["reason"] = f"{row['reason']}; {note}" if row["reason"] else note
    row = {"case": case.name, "engine": engine, "dt": step, **row}
    row["predicted_wall_time_s"] = predicted
    row["wall_time_s"] = wall
    return row


def stress(
    engines: Sequence[str] | None = None,
    cases: Sequence[str] | None = None,
    dt: float | None = None,
    progress: Callable[[str], None] | None = None,
    budget_s: float = DEFAULT_BUDGET_S,
) -> dict[str, Any]:
    """Run the hard cases (`--case` names or prefixes; default all) on the simulators
    (default all of `ENGINES`; fixed-step engines at `dt`, default 1e-4) and judge each
    run.  The reference always runs (it is the basis of missed/spurious impacts); its
    row is listed when "reference" is requested.  Returns the contract's stress
    document plus the settings, thresholds, case descriptions and the machine load."""
    say = progress or (lambda _msg: None)
    engines = list(dict.fromkeys(engines)) if engines else list(ENGINES)
    for e in engines:
        check_engine(e)
    dt = float(dt) if dt is not None else DEFAULT_DT
    selected = select_cases(cases)
    load_before = os.getloadavg()
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    for case in selected:
        ref, ref_wall, ref_pred, ref_skipped = run_reference(case.scene, budget_s)
        say(
            f"stress: {case.name}: reference {ref.status.value}, {len(ref.impacts)} impacts, "
            f"t_final={ref.t_final:.6g} ({ref_wall:.2f} s"
            + (f", full run predicted {ref_pred:.3g} s: skipped)" if ref_skipped else ")")
        )
        for engine in ["reference"] + [e for e in engines if e != "reference"]:
            if engine == "reference" and "reference" not in engines:
                continue
            if engine == "reference" and ref_skipped:
                note = (
                    f"; ran the first {len(ref.impacts)} impacts (t <= {ref.t_final:.6g}) "
                    "as the basis for the engines"
                )
                row = _skipped_row(
                    case, engine, None, ref_pred, _over_budget(ref_pred, budget_s) + note
                )
            elif engine == "reference":
                row = assess(ref, ref, case.scene, case.scene.run.t_end, exact=True)
                row = {"case": case.name, "engine": engine, "dt": None, **row}
                row["wall_time_s"] = ref_wall
            else:
                row = _engine_row(case, engine, dt, ref, ref_skipped, budget_s)
            rows.append(row)
            say(
                f"stress: {case.name}: {engine}: {row['verdict']} ({row['status']}, "
                f"{_num(row['wall_time_s'], '.2f')} s)"
                f"{': ' + row['reason'] if row['reason'] else ''}"
            )
    return {
        "cases": rows,
        "dt": dt,
        "budget_s": budget_s,
        "engines": engines,
        "case_descriptions": {c.name: c.description for c in selected},
        "thresholds": {
            "failed_energy_gain": FAILED_ENERGY_GAIN,
            "failed_penetration_relative": FAILED_PENETRATION,
            "degraded": {
                k: {"energy_gain": v[0], "penetration_relative": v[1]}
                for k, v in TOLERANCES.items()
            },
        },
        "wall_time_s": time.perf_counter() - start,
        "load": {"before": list(load_before), "after": list(os.getloadavg())},
        "cpu_count": os.cpu_count(),
    }


# ----------------------------------------------------------------------------- text


def _num(x: Any, spec: str = ".2e") -> str:
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    return format(x, spec) if math.isfinite(x) else "-"


def format_stress(doc: dict[str, Any]) -> str:
    """Verdict table, then the reason of every verdict that is not ok."""
    header = [
        "case",
        "engine",
        "verdict",
        "status",
        "finished",
        "nan",
        "E_gain",
        "pen[m]",
        "pen/L",
        "missed",
        "spurious",
        "wall[s]",
    ]
    rows = [
        [
            r["case"],
            r["engine"],
            r["verdict"],
            r["status"] or "-",
            _num(r["finished"]),
            _num(r["nan"]),
            _num(r["energy_gain"]),
            _num(r["max_penetration"]),
            _num(r.get("penetration_relative")),
            _num(r["missed_impacts"]),
            _num(r["spurious_impacts"]),
            _num(r.get("wall_time_s"), ".2f"),
        ]
        for r in doc["cases"]
    ]
    lines = [
        f"stress: fixed-step engines at dt={doc['dt']:g}, budget {doc['budget_s']:g} s per run",
        table(rows, header),
        "",
    ]
    for r in doc["cases"]:
        if r["verdict"] != "ok" and r.get("reason"):
            lines.append(f"{r['case']} / {r['engine']}: {r['verdict']}: {r['reason']}")
    load = doc["load"]
    lines.append(
        f"total {doc['wall_time_s']:.1f} s; load average before "
        f"{' '.join(f'{v:.2f}' for v in load['before'])}, after "
        f"{' '.join(f'{v:.2f}' for v in load['after'])}; {doc['cpu_count']} cpus"
    )
    return "\n".join(lines)
