"""The stress study: hard cases, every simulator, a verdict per case and simulator.

Cases (`stress_cases`) are Scenes built in code: the inclination α from 1e-3 down to
1e-12 (the paper's scaling q → ε²q, p → εp of one pentagon), a grazing contact, two
near-simultaneous hits, a chatter sequence, an elastic run (γ = 1) at unit scale and a
long one (100,000 impacts, at scale 0.02: bounces of ~1e-5 of the radius), a fast
spin near the singularity, n = 1000, γ = 0 sustained rolling and the three-point ground.

Each case runs on every requested simulator (fixed-step engines at one stated dt,
default 1e-4) to the case's t_end, and is judged (`assess`) on:

- finished: the run returned, is not `failed`, has no NaN, and reached t_end or stopped
  with a physics status (singularity, simultaneous impact, max_impacts, left_model);
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
runs in a child process: harness.child_processes) and reported the same way.
"""

from __future__ import annotations

import functools
import os
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

from reference.scene import SceneError
from reference.trajectory import Trajectory

from ..progress import progress_bar
from ..simulators import (
    DEFAULT_DT,
    check_engine,
    check_run,
    engine_names,
    is_fixed_step,
)
from .budget import (
    HARD_CAP_FACTOR,
    engine_run,
    over_budget,
    predict_engine_time,
    run_capped,
    run_reference,
)
from .cases import StressCase, select_cases
from .judge import FAILED_ENERGY_GAIN, FAILED_PENETRATION, TOLERANCES, assess
from .text import num

DEFAULT_BUDGET_S = 30.0  # per run
SKIPPED = "skipped (budget)"
NOT_RUNNABLE = "skipped (not runnable)"  # e.g. dt longer than the case (check_run says why)


def _case_rows(case, engines, others, dt, budget_s, say, bar) -> list[dict[str, Any]]:
    """The reference and every other simulator on one case (the stress rows)."""
    rows: list[dict[str, Any]] = []
    bar.set_postfix_str(f"{case.name}: reference", refresh=False)
    ref, ref_wall, ref_pred, ref_skipped = run_reference(case.scene, budget_s)
    say(
        f"stress: {case.name}: reference {ref.status.value}, {len(ref.impacts)} impacts, "
        f"t_final={ref.t_final:.6g} ({ref_wall:.2f} s"
        + (f", full run predicted {ref_pred:.3g} s: skipped)" if ref_skipped else ")")
    )
    bar.update()
    for engine in ["reference", *others]:
        if engine == "reference" and "reference" not in engines:
            continue
        bar.set_postfix_str(f"{case.name}: {engine}, predicting its time", refresh=False)
        if engine == "reference" and ref_skipped:
            note = (
                f"; ran the first {len(ref.impacts)} impacts (t <= {ref.t_final:.6g}) "
                "as the basis for the engines"
            )
            row = _skipped_row(case, engine, None, ref_pred, over_budget(ref_pred, budget_s) + note)
        elif engine == "reference":
            row = assess(ref, ref, case.scene, case.scene.run.t_end, exact=True)
            row = {"case": case.name, "engine": engine, "dt": None, **row}
            row["wall_time_s"] = ref_wall
        else:
            row = _engine_row(case, engine, dt, ref, ref_skipped, budget_s, bar)
        if row["verdict"] in (SKIPPED, NOT_RUNNABLE):
            bar.write(f"stress: {case.name}: {engine} skipped: {row['reason']}", file=sys.stderr)
        rows.append(row)
        say(
            f"stress: {case.name}: {engine}: {row['verdict']} ({row['status']}, "
            f"{num(row['wall_time_s'], '.2f')} s)"
            f"{': ' + row['reason'] if row['reason'] else ''}"
        )
        if engine != "reference":
            bar.update()
    return rows


def _skipped_row(
    case: StressCase,
    engine: str,
    dt,
    predicted: float | None,
    reason: str,
    verdict: str = SKIPPED,
) -> dict[str, Any]:
    return {
        "case": case.name,
        "engine": engine,
        "dt": dt,
        "verdict": verdict,
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


def _judged_run(engine, scene, step, t_end, ref) -> dict[str, Any]:
    """One engine run of a case, judged (module level: a spawned child runs it)."""
    traj, wall, err = engine_run(engine, scene, step, t_end)
    return {**assess(traj, ref, scene, t_end, error=err), "wall_time_s": wall}


def _engine_row(
    case: StressCase,
    engine: str,
    dt: float,
    ref: Trajectory,
    ref_partial: bool,
    budget_s: float,
    bar,
) -> dict[str, Any]:
    """Run one non-reference simulator on a case (unless predicted over the budget) and
    judge it against the reference run `ref` (a prefix of the case if `ref_partial`).
    The progress `bar` shows the prediction while the run goes on."""
    scene, t_end = case.scene, case.scene.run.t_end
    step = dt if is_fixed_step(engine) else None
    predicted = None
    try:
        check_run(engine, scene, step, t_end)  # e.g. dt longer than the case
    except SceneError as exc:
        return _skipped_row(case, engine, step, None, str(exc), verdict=NOT_RUNNABLE)
    if step is not None:
        try:
            predicted = predict_engine_time(engine, scene, step)
        except SceneError:
            raise
        except Exception:  # the run itself will report the failure
            predicted = None
        if predicted is not None and predicted > budget_s:
            return _skipped_row(case, engine, step, predicted, over_budget(predicted, budget_s))

    judged_run = functools.partial(_judged_run, engine, scene, step, t_end, ref)
    cap = HARD_CAP_FACTOR * budget_s
    guess = "not predicted" if predicted is None else f"predicted {predicted:.3g} s"
    bar.set_postfix_str(f"{case.name}: {engine}, {guess}, hard cap {cap:g} s", refresh=True)
    row, crashed = run_capped(judged_run, cap, tick=bar.refresh)
    if row is None and crashed is None:
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
    (default every installed engine, `engine_names()`; fixed-step engines at `dt`, default
    1e-4) and judge each run.  The reference always runs (it is the basis of
    missed/spurious impacts); its row is listed when "reference" is requested.  Returns
    the contract's stress document plus the settings, thresholds, case descriptions and
    the machine load."""
    say = progress or (lambda _msg: None)
    engines = list(dict.fromkeys(engines)) if engines else engine_names()
    for e in engines:
        check_engine(e)
    dt = float(dt) if dt is not None else DEFAULT_DT
    selected = select_cases(cases)
    load_before = os.getloadavg()
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    others = [e for e in engines if e != "reference"]
    with progress_bar(len(selected) * (1 + len(others)), "stress", unit="run") as bar:
        for case in selected:
            rows += _case_rows(case, engines, others, dt, budget_s, say, bar)
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
