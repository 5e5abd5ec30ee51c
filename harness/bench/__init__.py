"""`harness bench`: speed against error (work-precision) on one scene.

The truth is the exact reference at its tightest setting (`TRUTH`: DOP853 rtol 1e-12 in
contact phases, chatter completed below 1e-6 of the velocity scale).  Every other run is
scored against it with `harness.metrics.evaluate` (impacts matched, impact time error,
energy error, ...), DiffEqDevTools-style:

- fixed-step engines over a sweep of timesteps (`DEFAULT_DTS`, coarse to fine), a setting
  being skipped (and listed under "skipped") when its predicted cost exceeds the budget;
- the reference over its accuracy settings (`REFERENCE_SETTINGS`, loose to tight);
- the linear model once (it is exact for its own model: its error is the linearisation's).

Wall time: one untimed warm-up run per simulator (imports, JIT compilation, caches), then
`repeats` timed runs per setting; the median and the minimum are reported.  Every
simulator runs to the same physical time: the scene's t_end, or the truth's end when the
reference stops earlier (singularity, undecidable impact), so that all costs are for the
same stretch of motion.  (The reference's settings are given the requested t_end, so
that the tightest one repeats the truth exactly, samples included; they stop where the
truth stopped unless their own motion differs.)

Derived numbers (`derived`, per error metric and simulator) come from the log-log
work-precision curves: each curve is reduced to its Pareto front (runs that are more
accurate than every cheaper run of the same simulator) and log(error) is interpolated
linearly in log(time) between front points (`loglog_interp`).  See `derive`.
"""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.scene import Scene, SceneError
from reference.scenes import as_scene
from reference.simulate import ReferenceOptions, simulate
from reference.trajectory import Status, Trajectory

from ..metrics import evaluate
from ..progress import progress_bar
from ..simulators import check_engine, check_run, engine_names, is_fixed_step, run_simulator
from ..text import table

DEFAULT_DTS = (1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 1e-6)
# (contact_rtol, chatter_tol), loose to tight; the last one is the truth.
REFERENCE_SETTINGS = ((1e-6, 1e-3), (1e-8, 1e-4), (1e-10, 1e-5), (1e-12, 1e-6))
TRUTH = REFERENCE_SETTINGS[-1]
# A setting is skipped when repeats × its predicted single-run time exceeds this (s).
DEFAULT_BUDGET_S = 60.0
# Errors below this are drawn (and interpolated) at this value on log axes.
ERROR_FLOOR = 1e-16
# Error metrics of the work-precision curves; the first is the headline one.
METRICS = ("energy_error_agreeing", "energy_error", "impact_time_error")
METRIC_LABELS = {
    "energy_error_agreeing": "energy error before divergence, max |E - E_ref| / E_ref(0)",
    "energy_error": "energy error over the common window, max |E - E_ref| / E_ref(0)",
    "impact_time_error": "impact time error of matched impacts, max |t - t_ref| [s]",
}


@dataclass(frozen=True)
class Setting:
    """One configuration of one simulator."""

    engine: str
    dt: float | None = None
    contact_rtol: float | None = None
    chatter_tol: float | None = None

    @property
    def label(self) -> str:
        if self.dt is not None:
            return f"dt={self.dt:g}"
        if self.contact_rtol is not None:
            return f"rtol={self.contact_rtol:g} chatter={self.chatter_tol:g}"
        return "exact"

    def run(self, scene: Scene, t_end: float) -> Trajectory:
        if self.contact_rtol is not None:
            opts = ReferenceOptions(contact_rtol=self.contact_rtol, chatter_tol=self.chatter_tol)
            return simulate(scene, t_end=t_end, options=opts)
        return run_simulator(self.engine, scene, dt=self.dt, t_end=t_end)


def reference_setting(rtol_chatter: tuple[float, float]) -> Setting:
    return Setting("reference", contact_rtol=rtol_chatter[0], chatter_tol=rtol_chatter[1])


# ----------------------------------------------------------------------------- timing


def timed(setting: Setting, scene: Scene, t_end: float) -> tuple[Trajectory, float]:
    """One run and its wall time (perf_counter around the whole call: model building,
    simulation, Trajectory assembly).  An exception becomes a `failed` Trajectory."""
    start = time.perf_counter()
    try:
        traj = setting.run(scene, t_end)
    except SceneError:
        raise
    except Exception as exc:  # a broken simulator is a result
        traj = Trajectory.failed(
            setting.engine, scene.name, setting.dt, f"{type(exc).__name__}: {exc}"
        )
    return traj, time.perf_counter() - start


def predict_time(measured: Sequence[tuple[float, float]], dt: float) -> float:
    """Predicted wall time at timestep dt from measured (dt, time) pairs of the same
    engine: time ∝ dt^(−s), s from the two finest measured steps (at least 1: a step
    never costs less), s = 1 with a single measurement."""
    pts = sorted(measured, reverse=True)
    d1, t1 = pts[-1]
    s = 1.0
    if len(pts) >= 2:
        d0, t0 = pts[-2]
        if d0 > d1 and t0 > 0 and t1 > 0:
            s = max(1.0, math.log(t1 / t0) / math.log(d0 / d1))
    return t1 * (d1 / dt) ** s


# ----------------------------------------------------------------------------- rows


def score(
    setting: Setting, traj: Trajectory, times: list[float], truth: Trajectory, gravity: float
) -> dict[str, Any]:
    """The bench row of one setting: contract fields plus the other metrics."""
    m = evaluate(traj, truth, gravity)
    return {
        "engine": setting.engine,
        "setting": setting.label,
        "dt": setting.dt,
        "contact_rtol": setting.contact_rtol,
        "chatter_tol": setting.chatter_tol,
        "wall_time_s": statistics.median(times),
        "wall_time_min_s": min(times),
        "wall_times_s": list(times),
        "repeats": len(times),
        "status": traj.status.value,
        "message": traj.message,
        "t_final": traj.t_final,
        "impacts": len(traj.impacts),
        "reference_impacts": m.reference_impacts,
        "impacts_matched": m.impacts_matched,
        "impact_time_error": m.impact_time_error,
        "energy_error": m.energy_error,
        "energy_error_agreeing": m.energy_error_agreeing,
        "attitude_error": m.attitude_error,
        "attitude_error_agreeing": m.attitude_error_agreeing,
        "first_divergence_time": m.first_divergence_time,
        "divergence_reason": m.divergence_reason,
    }


def bench(
    scene: Scene | str,
    engines: Sequence[str] | None = None,
    dts: Sequence[float] | None = None,
    t_end: float | None = None,
    repeats: int = 3,
    plot: str | os.PathLike | None = None,
    progress: Callable[[str], None] | None = None,
    budget_s: float = DEFAULT_BUDGET_S,
    reference_settings: Sequence[tuple[float, float]] | None = None,
) -> dict[str, Any]:
    """Work-precision study of `scene` (module docstring).  Returns the contract's bench
    document plus `truth`, `skipped`, `derived`, `load` and the study's settings.

    engines: simulators to sweep (default every installed engine, `engine_names()`); the
    reference at its tightest setting is always run and timed, its looser settings only when
    "reference" is among `engines`.  dts: timesteps for the fixed-step engines (default
    `DEFAULT_DTS`).  budget_s: a setting whose predicted cost (repeats × predicted
    single-run time) exceeds it is skipped, and so are the finer timesteps after it.
    reference_settings: (contact_rtol, chatter_tol) pairs; the truth is always `TRUTH`.
    `scene` may be a Scene, a file or a built-in name."""
    say = progress or (lambda _msg: None)
    scene = as_scene(scene)
    if repeats < 1:
        raise SceneError(f"--repeats must be >= 1, got {repeats}")
    engines = list(engines) if engines else engine_names()
    for e in engines:
        check_engine(e)
    dts = sorted({float(d) for d in (dts or DEFAULT_DTS)}, reverse=True)
    ref_settings = list(reference_settings or REFERENCE_SETTINGS)
    if "reference" not in engines:
        ref_settings = []
    ref_settings = [s for s in ref_settings if tuple(s) != TRUTH] + [TRUTH]
    t_request = float(t_end if t_end is not None else scene.run.t_end)
    load_before = os.getloadavg()

    truth_setting = reference_setting(TRUTH)
    truth, truth_wall = timed(truth_setting, scene, t_request)
    if truth.status is Status.FAILED or truth.t_final <= 0:
        raise RuntimeError(f"the reference failed on {scene.name}: {truth.message}")
    horizon = truth.t_final
    say(
        f"bench: truth (reference {truth_setting.label}): {truth.status.value}, "
        f"{len(truth.impacts)} impacts, t_final={horizon:.6g} ({truth_wall:.2f} s, warm-up)"
    )

    results: list[dict[str, Any]] = []
    skipped: list[dict[str, Any]] = []

    def measure(setting: Setting) -> dict[str, Any]:
        times, traj = [], None
        # the reference stops by itself where the truth did: same t_end, same samples
        until = t_request if setting.engine == "reference" else horizon
        for _ in range(repeats):
            traj, wall = timed(setting, scene, until)
            times.append(wall)
        row = score(setting, traj, times, truth, scene.gravity)
        results.append(row)
        say(
            f"bench: {setting.engine} {setting.label}: {row['status']}, "
            f"median {row['wall_time_s']:.3g} s, matched {row['impacts_matched']}/"
            f"{row['reference_impacts']}, E_err<div {_fmt(row['energy_error_agreeing'])}"
        )
        return row

    plan = _ordered(engines)
    total = len(ref_settings) if "reference" in engines else 1
    total += sum(len(dts) if is_fixed_step(e) else 1 for e in plan if e != "reference")
    with progress_bar(total, f"bench {scene.name}", unit="setting") as bar:

        def measured_once(setting: Setting) -> dict[str, Any]:
            bar.set_postfix_str(f"{setting.engine} {setting.label}", refresh=False)
            row = measure(setting)
            bar.update()
            return row

        for engine in plan:
            if engine == "reference":
                for rc in ref_settings:
                    measured_once(reference_setting(rc))
            elif not is_fixed_step(engine):
                setting = Setting(engine)
                timed(setting, scene, horizon)  # warm-up (e.g. numba compilation)
                measured_once(setting)
            else:
                before = len(skipped)
                _fixed_step_sweep(
                    engine, scene, dts, horizon, repeats, budget_s, measured_once, skipped, say
                )
                bar.update(len(skipped) - before)
        if "reference" not in engines:  # the truth setting is always timed
            measured_once(truth_setting)

    derived = derive(results)
    doc: dict[str, Any] = {
        "scene": scene.name,
        "t_end": horizon,
        "t_end_requested": t_request,
        "truth": {
            "engine": "reference",
            "setting": truth_setting.label,
            "status": truth.status.value,
            "message": truth.message,
            "t_final": truth.t_final,
            "impacts": len(truth.impacts),
            "wall_time_s": truth_wall,
        },
        "repeats": repeats,
        "budget_s": budget_s,
        "dts": dts,
        "results": results,
        "skipped": skipped,
        "derived": derived,
        "error_floor": ERROR_FLOOR,
        "load": {"before": list(load_before), "after": list(os.getloadavg())},
        "cpu_count": os.cpu_count(),
        "notes": [
            "errors against the reference at " + truth_setting.label,
            "wall_time_s: median of `repeats` runs after one warm-up run per simulator",
            "derived: Pareto front per simulator, log(error) linear in log(time) between "
            f"front points; errors below {ERROR_FLOOR:g} count as {ERROR_FLOOR:g}",
        ],
    }
    if plot:
        doc["plot"] = str(plot_work_precision(doc, plot))
        say(f"bench: wrote {doc['plot']}")
    return doc


def _fixed_step_sweep(
    engine: str,
    scene: Scene,
    dts: list[float],
    horizon: float,
    repeats: int,
    budget_s: float,
    measure: Callable[[Setting], dict[str, Any]],
    skipped: list[dict[str, Any]],
    say: Callable[[str], None],
) -> None:
    """A fixed-step engine over the timesteps, coarse to fine: one warm-up run, then
    `measure` each runnable timestep until the predicted cost exceeds the budget (the
    rest go to `skipped` with their predicted cost)."""
    runnable = _runnable_dts(engine, scene, dts, horizon, skipped, say)
    if runnable:
        timed(Setting(engine, dt=runnable[0]), scene, horizon)  # warm-up
    measured: list[tuple[float, float]] = []
    for i, dt in enumerate(runnable):
        if measured:
            predicted = predict_time(measured, dt)
            if repeats * predicted > budget_s:
                for dt_skip in runnable[i:]:
                    p = predict_time(measured, dt_skip)
                    skipped.append(
                        {
                            "engine": engine,
                            "setting": f"dt={dt_skip:g}",
                            "dt": dt_skip,
                            "predicted_wall_time_s": p,
                            "reason": f"predicted {repeats} x {p:.3g} s > budget {budget_s:g} s",
                        }
                    )
                    say(f"bench: {engine} dt={dt_skip:g}: skipped ({p:.3g} s predicted)")
                break
        row = measure(Setting(engine, dt=dt))
        measured.append((dt, row["wall_time_s"]))


def _runnable_dts(
    engine: str,
    scene: Scene,
    dts: list[float],
    horizon: float,
    skipped: list[dict[str, Any]],
    say: Callable[[str], None],
) -> list[float]:
    """The timesteps the engine can run to `horizon` (harness.simulators.check_run: at
    most t_end, within the step ceiling); the others go to `skipped` with the reason."""
    out = []
    for dt in dts:
        try:
            check_run(engine, scene, dt, horizon)
        except SceneError as exc:
            skipped.append(
                {
                    "engine": engine,
                    "setting": f"dt={dt:g}",
                    "dt": dt,
                    "predicted_wall_time_s": None,
                    "reason": str(exc),
                }
            )
            say(f"bench: {engine} dt={dt:g}: skipped ({exc})")
        else:
            out.append(dt)
    return out


def _ordered(engines: list[str]) -> list[str]:
    """Reference first, then the rest in the order given (no duplicates)."""
    out = ["reference"] if "reference" in engines else []
    for e in engines:
        if e not in out:
            out.append(e)
    return out


# ----------------------------------------------------------------------------- derived


def pareto_front(points: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """(time, error) points sorted by time, keeping each point only if its error is
    below that of every cheaper point: the best accuracy reachable for a given cost."""
    front: list[tuple[float, float]] = []
    for t, e in sorted(points):
        if not front or e < front[-1][1]:
            front.append((t, e))
    return front


def loglog_interp(x: float, xs: Sequence[float], ys: Sequence[float]) -> tuple[float, str]:
    """y at x on the piecewise log-log-linear curve through (xs, ys) (xs increasing):
    log y = log y_i + (log x − log x_i)/(log x_{i+1} − log x_i) · (log y_{i+1} − log y_i).
    Outside [xs[0], xs[-1]] the end value is returned.  The second item says which:
    "interpolated", "below" (x < xs[0]) or "above" (x > xs[-1])."""
    if x <= xs[0]:
        return ys[0], ("interpolated" if x == xs[0] else "below")
    if x >= xs[-1]:
        return ys[-1], ("interpolated" if x == xs[-1] else "above")
    i = int(np.searchsorted(xs, x)) - 1
    lx0, lx1 = math.log(xs[i]), math.log(xs[i + 1])
    ly0, ly1 = math.log(ys[i]), math.log(ys[i + 1])
    return math.exp(ly0 + (math.log(x) - lx0) / (lx1 - lx0) * (ly1 - ly0)), "interpolated"


def _curve(rows: list[dict[str, Any]], engine: str, metric: str) -> list[tuple[float, float]]:
    pts = []
    for r in rows:
        if r["engine"] == engine and r.get(metric) is not None and r["status"] != "failed":
            pts.append((float(r["wall_time_s"]), max(float(r[metric]), ERROR_FLOOR)))
    return pts


def derive(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per error metric and non-reference simulator (Pareto fronts, `loglog_interp`):

    - reference_cost_s: median wall time of the reference at its tightest setting;
    - error_at_reference_cost: the simulator's error on its front at that cost (the
      best accuracy it reached for at most that cost).  `bound` "upper": the reference
      costs more than every measured run of the simulator, and the value is its best
      error (finer steps might do better); "none": the simulator's cheapest run already costs more
      than the reference (value null); "single setting": a simulator without an
      accuracy knob (linear), whose one error is given whatever its cost;
    - cost_ratio: simulator time / reference time at equal accuracy, at the
      simulator's most accurate run (error ε): reference time to reach ε is read off
      the reference's front (log time linear in log error).  `bound` "lower": every
      reference setting is more accurate than ε, so the reference needs at most its
      cheapest time and the ratio is at least the value given; "upper" (reference never
      reaches ε): the ratio is at most the value, computed with the tightest setting;
    - cost_ratios: the same at every point of the simulator's front."""
    out: dict[str, Any] = {}
    engines = [e for e in dict.fromkeys(r["engine"] for r in rows) if e != "reference"]
    truth_rows = [r for r in rows if r["engine"] == "reference" and r["contact_rtol"] == TRUTH[0]]
    if not truth_rows:
        return out
    t_ref = float(truth_rows[-1]["wall_time_s"])
    for metric in METRICS:
        ref_front = pareto_front(_curve(rows, "reference", metric))
        per: dict[str, Any] = {}
        for engine in engines:
            front = pareto_front(_curve(rows, engine, metric))
            if not front:
                continue
            ts, es = [p[0] for p in front], [p[1] for p in front]
            if len(front) == 1 and not is_fixed_step(engine):
                err, bound = es[0], "single setting"
            elif t_ref < ts[0]:
                err, bound = None, "none"
            else:
                err, _ = loglog_interp(t_ref, ts, es)
                # beyond every measured run: finer settings might do better
                measured = max(p[0] for p in _curve(rows, engine, metric))
                bound = "upper" if t_ref > measured else "exact"
            ratios = [_cost_ratio(t, e, ref_front) for t, e in front]
            best = ratios[-1] if ratios else None
            per[engine] = {
                "reference_cost_s": t_ref,
                "error_at_reference_cost": err,
                "error_at_reference_cost_bound": bound,
                "best_error": es[-1],
                "best_error_cost_s": ts[-1],
                "cost_ratio": best["ratio"] if best else None,
                "cost_ratio_bound": best["bound"] if best else None,
                "cost_ratios": ratios,
            }
        out[metric] = per
    return out


def _cost_ratio(t: float, err: float, ref_front: list[tuple[float, float]]) -> dict[str, Any]:
    """Simulator cost t at accuracy err over the reference's cost at the same accuracy."""
    if not ref_front:
        return {"error": err, "time_s": t, "reference_time_s": None, "ratio": None, "bound": None}
    # reference front: time increasing, error decreasing; invert error -> time
    rt = [p[0] for p in ref_front][::-1]
    re_ = [p[1] for p in ref_front][::-1]  # increasing error
    t_r, where = loglog_interp(err, re_, rt)
    bound = {"above": "lower", "below": "upper", "interpolated": "exact"}[where]
    return {"error": err, "time_s": t, "reference_time_s": t_r, "ratio": t / t_r, "bound": bound}


# ----------------------------------------------------------------------------- output


def plot_work_precision(doc: dict[str, Any], path: str | os.PathLike) -> str:
    """The work-precision figure (`work_precision_figure`) as a PNG file."""
    import matplotlib.pyplot as plt

    fig = work_precision_figure(doc)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


def work_precision_figure(doc: dict[str, Any]):
    """Log-log: one panel per error metric, error against median wall time, one curve
    per simulator, points labelled with their setting; drawn from the bench document's
    rows alone (so `harness report` can redraw it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = doc["results"]
    engines = list(dict.fromkeys(r["engine"] for r in rows))
    fig, axes = plt.subplots(1, len(METRICS), figsize=(6 * len(METRICS), 5.2))
    markers = "osD^v<>ph"
    for ax, metric in zip(axes, METRICS, strict=True):
        for k, engine in enumerate(engines):
            sel = [r for r in rows if r["engine"] == engine and r.get(metric) is not None]
            # in setting order (coarse to fine), as work-precision curves are drawn
            if not sel:
                continue
            x = [r["wall_time_s"] for r in sel]
            y = [max(r[metric], ERROR_FLOOR) for r in sel]
            ax.loglog(x, y, marker=markers[k % len(markers)], label=engine)
            for r, xi, yi in zip(sel, x, y, strict=True):
                tag = (
                    f"{r['dt']:g}"
                    if r["dt"] is not None
                    else (f"{r['contact_rtol']:g}" if r["contact_rtol"] is not None else "")
                )
                if tag:
                    ax.annotate(
                        tag, (xi, yi), fontsize=6, xytext=(3, 3), textcoords="offset points"
                    )
        ax.set_xlabel("wall time per run [s] (median)")
        ax.set_ylabel(METRIC_LABELS[metric], fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    load = doc.get("load", {}).get("before", [None])[0]
    fig.suptitle(
        f"work-precision on scene '{doc['scene']}' (t = 0 .. {doc['t_end']:.4g}, errors vs "
        f"reference at its tightest setting; below {ERROR_FLOOR:g} drawn at {ERROR_FLOOR:g}; "
        f"load {load:.2f})"
        if load is not None
        else f"work-precision on scene '{doc['scene']}'",
        fontsize=9,
    )
    fig.tight_layout()
    return fig


def _fmt(x: float | None, spec: str = ".2e") -> str:
    return "-" if x is None or not math.isfinite(x) else format(x, spec)


def format_bench(doc: dict[str, Any]) -> str:
    """The work-precision table, skipped settings, derived numbers and the load."""
    tr = doc["truth"]
    lines = [
        f"scene {doc['scene']}: t = 0 .. {doc['t_end']:.6g} (truth: reference "
        f"{tr['setting']}, {tr['status']}, {tr['impacts']} impacts)",
        "",
    ]
    header = [
        "engine",
        "setting",
        "status",
        "median[s]",
        "min[s]",
        "matched",
        "t_err[s]",
        "E_err",
        "E_err<div",
    ]
    rows = [
        [
            r["engine"],
            r["setting"],
            r["status"],
            _fmt(r["wall_time_s"], ".3g"),
            _fmt(r["wall_time_min_s"], ".3g"),
            f"{r['impacts_matched']}/{r['reference_impacts']}",
            _fmt(r["impact_time_error"]),
            _fmt(r["energy_error"]),
            _fmt(r["energy_error_agreeing"]),
        ]
        for r in doc["results"]
    ]
    lines.append(table(rows, header))
    for s in doc.get("skipped", []):
        lines.append(f"skipped: {s['engine']} {s['setting']}: {s['reason']}")
    lines.append("")
    for metric, per in doc.get("derived", {}).items():
        lines.append(f"at the reference's cost, and cost ratio at equal accuracy ({metric}):")
        for engine, d in per.items():
            err = _fmt(d["error_at_reference_cost"])
            lines.append(
                f"  {engine:17s} error at {d['reference_cost_s']:.3g} s: {err} "
                f"({d['error_at_reference_cost_bound']}); best {_fmt(d['best_error'])} at "
                f"{d['best_error_cost_s']:.3g} s costs {_fmt(d['cost_ratio'], '.3g')}x the "
                f"reference ({d['cost_ratio_bound']} bound)"
                if d["cost_ratio_bound"] != "exact"
                else f"  {engine:17s} error at {d['reference_cost_s']:.3g} s: {err} "
                f"({d['error_at_reference_cost_bound']}); best {_fmt(d['best_error'])} at "
                f"{d['best_error_cost_s']:.3g} s costs {_fmt(d['cost_ratio'], '.3g')}x the "
                "reference"
            )
    load = doc["load"]
    lines.append(
        f"load average (1, 5, 15 min) before {_triple(load['before'])}, after "
        f"{_triple(load['after'])}; {doc['cpu_count']} cpus; median of {doc['repeats']} "
        "repeats after a warm-up"
    )
    return "\n".join(lines)


def _triple(x: Sequence[float]) -> str:
    return " ".join(f"{v:.2f}" for v in x)
