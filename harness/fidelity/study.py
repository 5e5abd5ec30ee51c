"""Running the fidelity study: the reference and every engine over the ε grid and dts.

For each ε: the scene scaled by the paper's invariance (Scene.scaled: q → ε²q, p → εp)
with its t_end scaled too (t → εt: the motion's time scale is ε), and the reference run
on it (exact at every scale: scaled impact times agree to 1e-12 and better, README).
For each engine and dt, the scales are run from the smallest ε up (the cheapest first),
each to `leading.run_end`, and scored against that scale's reference
(harness.metrics.evaluate, the leading impacts, the exponent).

Budget (the rules of `harness stress` and `harness bench`, by calling their functions):
each fixed-step run's wall time is predicted (`predict_run_time`: pilot runs for long
ones, and an extrapolation from the same engine and dt at the smaller scales already
run) and the run is skipped when the prediction exceeds the per-run budget; a run of
more than PILOT_FREE_STEPS steps runs in a child process (harness.child_processes)
stopped at HARD_CAP_FACTOR × the budget (predictions can miss costly later phases).
Once a scale is skipped or stopped, the larger scales of that engine and dt are
skipped too: they cover the same motion with more steps.
"""

from __future__ import annotations

import functools
import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.exponent import ExponentFit
from reference.scene import Scene, SceneError
from reference.scenes import as_scene
from reference.trajectory import Trajectory

from ..bench import predict_time
from ..metrics import evaluate, run_exponent
from ..progress import progress_bar
from ..simulators import engine_names, is_fixed_step, run_simulator, warm_up
from ..stress.budget import (
    HARD_CAP_FACTOR,
    PILOT_FREE_STEPS,
    engine_run,
    over_budget,
    predict_engine_time,
    run_capped,
)
from ..text import run_label
from .criteria import FidelityCriteria, alpha_star, exponent_check, impacts_pass, power_law_fit
from .leading import LeadingImpacts, inclination_scale, leading_impacts, run_end
from .settings import DEFAULT_BUDGET_S, DEFAULT_DTS, DEFAULT_EPS_GRID, WINDOWS

NOT_ENGINES = ("reference", "linear")  # the default engines are every other one
MESSAGE_CHARS = 300


def eps_values(first: float, last: float, count: int) -> list[float]:
    """`count` values of ε from `first` to `last`, evenly spaced in log ε, largest first."""
    if not (first > 0 and last > 0) or count < 1:
        raise SceneError(f"--eps-grid needs A:B:K with A, B > 0 and K >= 1, got {first}:{last}")
    return sorted((float(x) for x in np.geomspace(first, last, count)), reverse=True)


def default_engines() -> list[str]:
    """Every installed engine but the reference and the linear model."""
    return [e for e in engine_names() if e not in NOT_ENGINES]


# ----------------------------------------------------------------------------- scales


@dataclass(frozen=True)
class ScaleCase:
    """The reference at one scale ε: the scaled scene, its run and what it defines."""

    eps: float
    scene: Scene
    reference: Trajectory
    wall_time_s: float
    leading: LeadingImpacts
    alpha: float
    alpha0: float
    exponent: ExponentFit

    def to_dict(self, first: ScaleCase | None = None) -> dict[str, Any]:
        ref = self.reference
        doc = {
            "eps": self.eps,
            "alpha": self.alpha,
            "alpha0": self.alpha0,
            "t_end": self.scene.run.t_end,
            "status": ref.status.value,
            "impacts": len(ref.impacts),
            "t_final": ref.t_final,
            "t_final_scaled": ref.t_final / self.eps,
            "leading": self.leading.n,
            "leading_t_last_scaled": None
            if self.leading.t_last is None
            else self.leading.t_last / self.eps,
            "wall_time_s": self.wall_time_s,
            "c": self.exponent.c,
            "c_stderr": self.exponent.c_stderr,
            "c_reason": self.exponent.reason or None,
        }
        doc.update(self._same_motion(first))
        return doc

    def _same_motion(self, first: ScaleCase | None) -> dict[str, Any]:
        """Whether the leading impacts are those of the first scale's (same contacts in
        the same order), and the largest shift of their scaled times (t/ε): the check
        that every scale tests the same motion (it differs by O(α))."""
        if first is None or first.leading.n != self.leading.n or self.leading.n == 0:
            return {"same_contacts_as_first": None, "scaled_time_shift": None}
        a, b = self.reference, first.reference
        ia, ib = self.leading.indices, first.leading.indices
        same = bool(np.array_equal(a.impact_contacts()[ia], b.impact_contacts()[ib]))
        shift = np.abs(a.impact_times()[ia] / self.eps - b.impact_times()[ib] / first.eps)
        return {"same_contacts_as_first": same, "scaled_time_shift": float(shift.max())}


def scale_case(scene: Scene, eps: float, criteria: FidelityCriteria) -> ScaleCase:
    """Scale the scene by ε (t_end by ε too) and run the reference on it."""
    scaled = scene.scaled(eps, name="fidelity")
    scaled = scaled.with_run(t_end=eps * scene.run.t_end)
    start = time.perf_counter()
    ref = run_simulator("reference", scaled, t_end=scaled.run.t_end)
    wall = time.perf_counter() - start
    if ref.n_samples == 0 or ref.status.value == "failed":
        raise RuntimeError(f"the reference failed on {scene.name} at eps={eps:g}: {ref.message}")
    lead = leading_impacts(ref, criteria.leading, scaled.gravity)
    alpha0 = float(ref.inclination[0])
    return ScaleCase(
        eps,
        scaled,
        ref,
        wall,
        lead,
        inclination_scale(ref, lead.t_last),
        alpha0,
        run_exponent(ref, scaled),
    )


# ----------------------------------------------------------------------------- one run


def score(
    traj: Trajectory,
    case: ScaleCase,
    criteria: FidelityCriteria,
    band: list[float] | None = None,
) -> dict[str, Any]:
    """The metrics of one engine run at one scale and its verdicts: `passes` (the
    criteria) and `horizon_pass` (it passes, or its leading impacts matched are at least
    the 10 % quantile of the horizon band at this scale and dt, `band`: it fails only
    below the band)."""
    m = evaluate(traj, case.reference, case.scene.gravity)
    pairs = m.match.pairs if m.match is not None else np.zeros((0, 2), int)
    in_leading = np.isin(pairs[:, 0], case.leading.indices)
    matched = int(in_leading.sum())
    t_err = float(np.max(np.abs(m.match.time_errors[in_leading]))) if matched else None
    # c by the project's one estimator; a run has one only where it reached the end of the
    # motion (its own singularity, or the reference's when it followed it there), so a
    # fixed-step engine cut at the leading impacts has none (`--window whole` needed)
    fit = run_exponent(traj, case.scene, case.reference, m.match)
    ref_fit = case.exponent
    c_ok, c_why = exponent_check(fit.c, ref_fit.c, criteria, fit.reason, ref_fit.reason)
    impacts_ok = impacts_pass(matched, case.leading.n, criteria)
    return {
        "status": traj.status.value,
        "message": (traj.message or "")[:MESSAGE_CHARS] or None,
        "impacts": len(traj.impacts),
        "leading_matched": matched,
        "match_fraction": matched / case.leading.n if case.leading.n else None,
        "first_mismatch": m.match.reason if m.match is not None else None,
        "first_divergence_time_scaled": None
        if m.first_divergence_time is None
        else m.first_divergence_time / case.eps,
        "impact_time_error_s": t_err,
        "impact_time_error_scaled": None if t_err is None else t_err / case.eps,
        "energy_error": m.energy_error_agreeing,
        "energy_error_window": m.energy_error,
        "c": fit.c,
        "c_stderr": fit.c_stderr,
        "c_reason": fit.reason or None,
        "c_reference": ref_fit.c,
        "c_relative_error": None
        if fit.c is None or ref_fit.c is None
        else abs(fit.c - ref_fit.c) / abs(ref_fit.c),
        "c_check": c_why,
        "criterion": "impacts and c" if c_ok is not None else "impacts only",
        "impacts_pass": impacts_ok,
        "passes": bool(impacts_ok and c_ok is not False),
        **horizon_verdict(matched, band, impacts_ok, c_ok),
    }


def horizon_verdict(
    matched: int, band: list[float] | None, impacts_ok: bool, c_ok: bool | None
) -> dict[str, Any]:
    """`horizon_band` (leading impacts the grid model matches, 10/50/90 %), `within_horizon`
    (matched ≥ its 10 % value) and `horizon_pass` (impacts pass or within, and c not
    failed); None without a band (event-driven runs, --horizon-runs 0)."""
    if band is None:
        return {"horizon_band": None, "within_horizon": None, "horizon_pass": None}
    within = matched >= band[0]
    return {
        "horizon_band": band,
        "within_horizon": within,
        "horizon_pass": bool((impacts_ok or within) and c_ok is not False),
    }


def horizon_band(case: ScaleCase, dt: float | None, runs: int, seed: int) -> list[float] | None:
    """The grid model's leading impacts matched at this scale and dt (harness.horizon:
    `runs` grid phases, each run stopped after the last leading impact), as 10/50/90 %
    quantiles; None for event-driven runs, no runs or no leading impacts."""
    if dt is None or runs <= 0 or case.leading.n == 0:
        return None
    from ..horizon.ensemble import grid_ensemble
    from ..horizon.verdict import quantiles

    limit = int(case.leading.indices[-1]) + 2
    members = grid_ensemble(case.scene, case.reference, dt, runs, seed, limit=limit)
    counts = [int(np.isin(m.match.pairs[:, 0], case.leading.indices).sum()) for m in members]
    return quantiles(np.array(counts))


def _base_row(engine: str, dt: float | None, case: ScaleCase, t_run: float) -> dict[str, Any]:
    return {
        "engine": engine,
        "dt": dt,
        "eps": case.eps,
        "alpha": case.alpha,
        "alpha0": case.alpha0,
        "t_end": t_run,
        "t_end_scaled": t_run / case.eps,
        "steps": None if dt is None else int(math.ceil(t_run / dt - 1e-9)),
        "leading": case.leading.n,
        "passes": None,
        "skipped": None,
        "predicted_wall_time_s": None,
        "wall_time_s": None,
        "compile_time_s": None,
    }


def engine_row(
    engine: str,
    dt: float | None,
    case: ScaleCase,
    criteria: FidelityCriteria,
    window: str,
    budget_s: float,
    measured: Sequence[tuple[float, float]] = (),
    blocked: str | None = None,
    band: list[float] | None = None,
) -> dict[str, Any]:
    """Run one engine at one scale within the budget (module docstring) and score it.
    `measured`: (steps, wall time) of this engine and dt at the smaller scales already
    run; `blocked`: the reason a smaller scale of this engine and dt was not run (this
    one, costlier, is skipped with it); `band`: the horizon band there (`score`)."""
    t_run = run_end(case.leading, case.reference.t_final, case.scene.run.t_end, dt, window)
    row = _base_row(engine, dt, case, t_run)
    if case.leading.n == 0:
        row["note"] = "not assessed: the reference has no leading impact at this scale"
        return row
    if blocked:
        row["skipped"] = blocked
        return row
    scene = case.scene.with_run(t_end=t_run)
    if dt is not None and dt > t_run:  # not one step fits: it cannot follow any impact
        why = f"dt = {dt:g} s is longer than the whole run at this scale ({t_run:.3g} s)"
        failed = Trajectory.failed(engine, scene.name, dt, why)
        return {**row, **score(failed, case, criteria, band)}
    predicted = predict_run_time(engine, scene, dt, row["steps"], measured)
    row["predicted_wall_time_s"] = predicted
    if predicted is not None and predicted > budget_s:
        row["skipped"] = over_budget(predicted, budget_s)
        return row

    scored_run = functools.partial(_scored_run, engine, scene, dt, t_run, case, criteria, band)
    if row["steps"] is None or row["steps"] <= PILOT_FREE_STEPS:  # short: run here
        return {**row, **scored_run()}
    cap = HARD_CAP_FACTOR * budget_s
    result, crashed = run_capped(scored_run, cap)
    if result is None and crashed is None:
        row["skipped"] = f"stopped at the hard cap of {cap:g} s (predicted {predicted:.3g} s)"
        return row
    if result is None:  # the child died without answering (a crash inside the engine)
        failed = Trajectory.failed(engine, scene.name, dt, crashed or "")
        result = {**score(failed, case, criteria, band), "wall_time_s": None}
    return {**row, **result}


def _scored_run(engine, scene, dt, t_run, case, criteria, band) -> dict[str, Any]:
    """One engine run at one scale, scored (module level: a spawned child runs it)."""
    traj, wall, _ = engine_run(engine, scene, dt, t_run)
    compile_s = traj.stats.get("compile_time_s")  # inside wall (MJX's JIT)
    return {**score(traj, case, criteria, band), "wall_time_s": wall, "compile_time_s": compile_s}


def predict_run_time(
    engine: str,
    scene: Scene,
    dt: float | None,
    steps: int | None,
    measured: Sequence[tuple[float, float]],
) -> float | None:
    """Predicted wall time of a fixed-step run of `steps` steps: the larger of
    - two pilot runs' setup + per-step cost (stress.budget.predict_engine_time; runs of
      more than PILOT_FREE_STEPS steps only), and
    - the same engine and dt at the smaller scales already run, extrapolated in steps as
      time ∝ steps^s with s ≥ 1 from the two largest (bench.predict_time): the same
      motion with fewer steps, so it sees the costly later phases that pilots miss.
    None for an event-driven engine or a short run with nothing measured."""
    if dt is None or steps is None:
        return None
    guesses = []
    if measured:
        guesses.append(predict_time([(1.0 / n, wall) for n, wall in measured], 1.0 / steps))
    try:
        guesses.append(predict_engine_time(engine, scene, dt))
    except SceneError:
        raise
    except Exception:  # noqa: BLE001  (the run itself will report the failure)
        pass
    guesses = [g for g in guesses if g is not None]
    return max(guesses) if guesses else None


# ----------------------------------------------------------------------------- study


def fidelity(
    scene: Scene | str,
    engines: Sequence[str] | None = None,
    dts: Sequence[float] | None = None,
    eps: Sequence[float] | None = None,
    criteria: FidelityCriteria | None = None,
    window: str = "leading",
    budget_s: float = DEFAULT_BUDGET_S,
    progress: Callable[[str], None] | None = None,
    horizon_runs: int = 0,
    horizon_seed: int = 0,
) -> dict[str, Any]:
    """The fidelity study of `scene` (module docstring; definitions in harness.fidelity).
    Returns the JSON document: criteria, the reference at every scale, one row per
    engine, dt and scale, α* per engine and dt, the power-law fit per engine.  `scene`
    may be a Scene, a file or a built-in name.  With `horizon_runs` > 0 each fixed-step
    row also gets the horizon band of its scale and dt (`horizon_band`, grid phases
    seeded with `horizon_seed`) and each α* entry a `horizon` α*: the engine fails at a
    scale only below that band."""
    say = progress or (lambda _msg: None)
    scene = as_scene(scene)
    criteria = criteria or FidelityCriteria()
    if criteria.leading < 1:
        raise SceneError(f"--leading must be >= 1, got {criteria.leading}")
    if window not in WINDOWS:
        raise SceneError(f"--window must be one of {', '.join(WINDOWS)}, got {window!r}")
    engines = list(dict.fromkeys(engines)) if engines else default_engines()
    dts = sorted({float(d) for d in (dts or DEFAULT_DTS)}, reverse=True)
    eps = sorted({float(e) for e in (eps or eps_values(*DEFAULT_EPS_GRID))}, reverse=True)
    plan = [(e, d) for e in engines for d in (dts if is_fixed_step(e) else [None])]
    load_before = os.getloadavg()
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    with progress_bar(len(eps) * (1 + len(plan)), f"fidelity {scene.name}") as bar:
        cases = []
        for e in eps:
            bar.set_postfix_str(f"reference eps={e:.3g}", refresh=False)
            cases.append(scale_case(scene, e, criteria))
            bar.update()
        say(_reference_line(scene, cases))
        bands: dict[tuple[float, float | None], list[float] | None] = {}
        for engine, dt in plan:
            warm_up(engine, cases[0].scene, dt)
            for c in cases:
                if (c.eps, dt) not in bands:
                    bands[c.eps, dt] = horizon_band(c, dt, horizon_runs, horizon_seed)
            mine = {c.eps: bands[c.eps, dt] for c in cases}
            rows += _engine_scales(engine, dt, cases, criteria, window, budget_s, bar, say, mine)
    stars = _alpha_stars(rows, plan)
    return {
        "kind": "fidelity",
        "scene": scene.name,
        "restitution": scene.restitution,
        "scaling": "q -> eps^2 q, p -> eps p, t -> eps t (t_end scaled too)",
        "window": window,
        "criteria": criteria.to_dict(),
        "engines": engines,
        "dts": dts,
        "eps": eps,
        "budget_s": budget_s,
        "hard_cap_s": HARD_CAP_FACTOR * budget_s,
        "horizon_runs": horizon_runs,
        "horizon_seed": horizon_seed,
        "reference": [c.to_dict(cases[0]) for c in cases],
        "runs": rows,
        "alpha_star": stars,
        "fits": _fits(stars, engines),
        "wall_time_s": time.perf_counter() - start,
        "load": {"before": list(load_before), "after": list(os.getloadavg())},
        "cpu_count": os.cpu_count(),
    }


def _engine_scales(engine, dt, cases, criteria, window, budget_s, bar, say, bands) -> list[dict]:
    """One engine at one dt over every scale, smallest ε first (budget: module docstring);
    `bands`: the horizon band per ε."""
    rows, blocked, measured = [], None, []
    for case in sorted(cases, key=lambda c: c.eps):
        label = run_label(engine, dt)
        bar.set_postfix_str(f"{label} eps={case.eps:.3g}", refresh=False)
        band = bands.get(case.eps)
        row = engine_row(engine, dt, case, criteria, window, budget_s, measured, blocked, band)
        if row["skipped"] and not blocked:
            blocked = f"skipped: eps={case.eps:.3g} was not run ({row['skipped']})"
        if row["wall_time_s"] and row["steps"]:  # the time that grows with the steps
            measured.append((row["steps"], row["wall_time_s"] - (row["compile_time_s"] or 0.0)))
        rows.append(row)
        say(_run_line(label, row))
        bar.update()
    return rows


def _alpha_stars(rows: list[dict], plan: list[tuple[str, float | None]]) -> list[dict]:
    out = []
    for engine, dt in plan:
        mine = [r for r in rows if r["engine"] == engine and r["dt"] == dt]
        star = {"engine": engine, "dt": dt, **alpha_star(mine)}
        if any(r.get("horizon_pass") is not None for r in mine):
            judged = [{**r, "passes": r.get("horizon_pass")} for r in mine]
            star["horizon"] = alpha_star(judged)  # fails only below the band
        out.append(star)
    return out


def _fits(stars: list[dict], engines: list[str]) -> list[dict]:
    """k of α* ∝ dt^k per engine over its "bracket" values (criteria.power_law_fit), and
    `lowest`: the same for the smallest α passed, over the dts where a failing α lies
    below it."""
    out = []
    for engine in engines:
        mine = [s for s in stars if s["engine"] == engine and s["dt"] is not None]
        used = [s for s in mine if s["bound"] == "bracket"]
        fit = power_law_fit(
            [s["dt"] for s in used],
            [s["alpha_star"] for s in used],
            [s["alpha_first_fail"] for s in used],
        )
        fit["dts_used"] = [s["dt"] for s in used]
        fit["dts_left_out"] = {f"{s['dt']:g}": s["bound"] for s in mine if s["bound"] != "bracket"}
        low = [s for s in mine if s["alpha_below_lowest_pass"] is not None]
        fit["lowest"] = power_law_fit(
            [s["dt"] for s in low],
            [s["alpha_lowest_pass"] for s in low],
            [s["alpha_below_lowest_pass"] for s in low],
        )
        out.append({"engine": engine, **fit})
    return out


def _reference_line(scene: Scene, cases: list[ScaleCase]) -> str:
    c = [f"{x.exponent.c:.3f}" for x in cases if x.exponent.c is not None]
    return (
        f"fidelity: {scene.name}: reference at {len(cases)} scales, alpha "
        f"{cases[0].alpha:.3g} .. {cases[-1].alpha:.3g}, leading impacts "
        f"{min(x.leading.n for x in cases)}..{max(x.leading.n for x in cases)}, "
        + (f"c at {len(c)} scales" if c else "no c at any scale")
    )


def _run_line(label: str, row: dict) -> str:
    text = f"fidelity: {label} eps={row['eps']:.3g} (alpha={row['alpha']:.3g}): "
    if row["skipped"]:
        return text + row["skipped"]
    if row["passes"] is None:
        return text + row.get("note", "not run")
    verdict = "pass" if row["passes"] else "fail"
    wall = "-" if row["wall_time_s"] is None else f"{row['wall_time_s']:.3g} s"
    return (
        text + f"{row['leading_matched']}/{row['leading']} leading matched, {verdict} "
        f"({row['status']}, {wall})"
    )
