"""`harness sweep exponent`: the energy-exponent map over (γ, ρ) (paper section 4.3).

For every grid point and sample: the paper's random initial state (grid), a run of
the chosen simulator and its exponent c (run), persisted at once as a Parquet part
(store), on a local process pool or a Dask cluster (executors); then the map, the
simultaneous-impact fraction and the sections as PNGs (plots).

Directory layout (design): --out is a study directory holding one subdirectory per
simulator, ROOT/<engine>/ with its manifest, parts and PNGs.  Running the same command
again resumes (only missing runs are computed); the same ROOT with another engine adds
that engine's sweep beside the first (its grid may differ, e.g. a subgrid for the slow
simulators), and ROOT/compare-<engine>-vs-<base>.png then shows it beside the base
map (`linear`, else `reference`).  Reusing ROOT/<engine> with other parameters is
refused.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

from reference.scene import SceneError

from ..simulators import check_engine, check_run, is_fixed_step
from .executors import ExecutorError, check_scheduler
from .grid import (
    SweepConfig,
    all_keys,
    config_problem,
    default_chunk_size,
    default_min_decades,
    initial_state,
    make_chunks,
)
from .store import KEY, StoreError, SweepStore, engines_in, load_results


class SweepError(SceneError):
    """Bad sweep input (arguments, a reused directory, an unreachable scheduler): the
    CLI reports it as one line with exit status 2, like a bad scene."""


def _bad(msg: str) -> SweepError:
    return SweepError(msg)


def config_from_args(args) -> SweepConfig:
    """Validate the CLI arguments into a SweepConfig (SweepError on nonsense), before
    anything is written: the grid (`grid.config_problem`) and one run of it
    (harness.simulators.check_run: t_end, dt <= t_end, the step ceiling, the engine's
    largest n)."""
    check_engine(args.engine)
    if args.seed < 0:
        raise _bad(f"--seed must be >= 0, got {args.seed}")
    dt = getattr(args, "dt", None)
    t_end = getattr(args, "t_end", None)
    extra = {"t_end": float(t_end)} if t_end is not None and args.engine != "linear" else {}
    config = SweepConfig(
        n=int(args.n),
        gyration=tuple(args.gyration),
        restitution=tuple(args.restitution),
        samples=int(args.samples),
        seed=int(args.seed),
        engine=args.engine,
        dt=float(dt) if (dt is not None and is_fixed_step(args.engine)) else None,
        min_decades=default_min_decades(args.engine),
        impact_law=getattr(args, "impact_law", None) or "paper",
        simultaneity_window=float(getattr(args, "simultaneity_window", None) or 0.0),
        **extra,
    )
    if getattr(args, "simultaneity_window", None) and args.engine != "reference":
        raise _bad("--simultaneity-window applies to the reference engine only")
    check_config(config)
    return config


def check_config(config: SweepConfig) -> None:
    """SweepError unless the sweep can run (see `config_from_args`)."""
    from .run import polygon_scene

    problem = config_problem(config)
    if problem:
        raise _bad(problem)
    q0, p0 = initial_state(config.seed, 0, 0, 0)
    scene = polygon_scene(
        config, float(config.rho_values[0]), float(config.gamma_values[0]), q0, p0
    )
    t_end = None if config.engine == "linear" else config.t_end
    check_run(config.engine, scene, config.dt, t_end)


def run_exponent_sweep(args, progress=None) -> dict:
    """The CLI entry point (harness.cli.cmd_sweep): returns the JSON document, with a
    readable summary in doc["text"]."""
    config = config_from_args(args)
    executor = getattr(args, "executor", "local") or "local"
    scheduler = getattr(args, "scheduler", None)
    workers = getattr(args, "workers", None)
    if executor == "dask" and not scheduler:
        raise _bad("--executor dask needs --scheduler ADDR (e.g. tcp://127.0.0.1:8786)")
    if executor == "dask":
        try:
            check_scheduler(scheduler)
        except ExecutorError as exc:
            raise _bad(str(exc)) from None
    if workers is not None and workers < 1:
        raise _bad(f"--workers must be >= 1, got {workers}")
    chunk_size = getattr(args, "chunk_size", None)  # optional flag (not in cli.py yet)
    if chunk_size is not None and chunk_size < 1:
        raise _bad(f"--chunk-size must be >= 1, got {chunk_size}")
    if getattr(args, "dt", None) is not None and config.dt is None and progress:
        progress(f"sweep: --dt applies to fixed-step engines only; ignored for {config.engine}")
    try:
        return exponent_sweep(
            config,
            args.out,
            executor=executor,
            scheduler=scheduler,
            workers=workers,
            chunk_size=chunk_size,
            progress=progress,
        )
    except (StoreError, ExecutorError) as exc:
        raise _bad(str(exc)) from None


def exponent_sweep(
    config: SweepConfig,
    out: str | Path,
    executor: str = "local",
    scheduler: str | None = None,
    workers: int | None = None,
    chunk_size: int | None = None,
    figures: bool = True,
    progress=None,
    bar: bool = True,
    run_fn=None,
) -> dict:
    """Run (or resume) a sweep into the study directory `out` and summarise it.

    `run_fn` replaces run.run_chunk (tests); `figures=False` skips the PNGs."""
    from ..progress import progress_bar
    from . import executors as sweep_exec
    from .run import run_chunk

    run_fn = run_fn or run_chunk
    say = progress or (lambda msg: None)
    t0 = time.perf_counter()
    load_start = os.getloadavg()
    root = Path(out)
    check_config(config)  # before the manifest is written
    store = SweepStore(root, config).open()
    for note in store.notes:
        say(f"sweep: {note}")
    statuses: dict[str, int] = {}
    try:
        done_df, _ = store.results
        done = set(zip(*(done_df[k].tolist() for k in KEY), strict=True)) if len(done_df) else set()
        missing = [k for k in all_keys(config) if k not in done]
        chunk_size = chunk_size or default_chunk_size(config.engine)
        chunks = make_chunks(config, missing, chunk_size)
        say(
            f"sweep {config.engine}: {config.n_tasks} runs "
            f"({config.restitution[2]} γ x {config.gyration[2]} ρ x {config.samples}); "
            f"{len(done)} stored, {len(missing)} to compute in {len(chunks)} chunks "
            f"({executor}) -> {store.dir}"
        )
        if executor == "dask":
            results = sweep_exec.run_dask(chunks, scheduler, fn=run_fn)
        else:
            if missing and run_fn is run_chunk:
                from .run import warm_up

                warm_up(config)
            results = sweep_exec.run_local(chunks, workers=workers, fn=run_fn)
        t_compute = time.perf_counter()
        with progress_bar(
            config.n_tasks,
            f"sweep {config.engine}",
            show=bar and bool(missing),
            initial=len(done),
        ) as pbar:
            for chunk, rows in results:
                store.write_part(rows, chunk.label)
                for r in rows:
                    statuses[r["status"]] = statuses.get(r["status"], 0) + 1
                pbar.update(len(rows))
                pbar.set_postfix(
                    simultaneous=statuses.get("simultaneous_impact", 0),
                    failed=statuses.get("failed", 0),
                    refresh=False,
                )
        compute_s = time.perf_counter() - t_compute
    finally:
        store.close()

    df, duplicates = load_results(store.dir)
    figs: dict = {}
    t_fig = time.perf_counter()
    if figures and len(df):
        from .plots import make_sweep_figures

        say("sweep: drawing figures")
        figs = make_sweep_figures(store.dir, df, config)
        figs.update(_comparisons(root, config))
    figures_s = time.perf_counter() - t_fig
    doc = summarise(config, df, store, statuses, len(done), len(missing), duplicates)
    doc.update(
        executor=executor,
        scheduler=scheduler,
        workers=workers or (os.cpu_count() if executor == "local" else None),
        figures=figs,
        wall_time_s=time.perf_counter() - t0,
        compute_time_s=compute_s,
        figures_time_s=figures_s,
        load_average_start=list(load_start),
        load_average_end=list(os.getloadavg()),
    )
    doc["text"] = format_summary(doc)
    return doc


def _comparisons(root: Path, config: SweepConfig) -> dict:
    """compare-<engine>-vs-<base>.png for the engines stored beside this one."""
    from .plots import make_compare_figure

    found = {e: c for e, c in engines_in(root).items() if c.n == config.n}
    base = "linear" if "linear" in found else ("reference" if "reference" in found else None)
    if base is None or len(found) < 2:
        return {}
    others = [e for e in found if e != base] if config.engine == base else [config.engine]
    out = {}
    b_df, _ = load_results(root / base)
    for eng in others:
        e_df, _ = load_results(root / eng)
        if len(b_df) and len(e_df):
            out[f"compare_{eng}"] = make_compare_figure(
                root, (base, b_df, found[base]), (eng, e_df, found[eng])
            )
    return out


def _f(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def summarise(config, df, store, statuses_now, n_before, n_missing, duplicates) -> dict:
    """The JSON document: grid, counts by status, mean c per grid point, where things are."""
    from .stats import STATUSES, grid_stats

    stats = grid_stats(df, config)
    counts = {s: int((df["status"] == s).sum()) for s in STATUSES} if len(df) else {}
    points = [
        {
            "restitution": float(r.restitution),
            "gyration": float(r.gyration),
            "runs": int(r.runs),
            "n_c": int(r.n_c),
            "mean_c": _f(r.mean_c),
            "std_c": _f(r.std_c),
            "median_c": _f(r.median_c),
            "frac_simultaneous": _f(r.frac_simultaneous),
            "status": {s: int(getattr(r, s)) for s in STATUSES},
        }
        for r in stats.itertuples()
    ]
    failed = df[df["status"] == "failed"] if len(df) else df
    return {
        "command": "sweep exponent",
        "engine": config.engine,
        "impact_law": config.impact_law,
        "simultaneity_window": config.simultaneity_window,
        "n": config.n,
        "out": str(store.root),
        "dir": str(store.dir),
        "parts": {"dir": str(store.parts_dir), "count": len(store.part_paths())},
        "manifest": config.to_dict(),
        "grid": {
            "restitution": [float(x) for x in config.gamma_values],
            "gyration": [float(x) for x in config.rho_values],
            "samples": config.samples,
            "seed": config.seed,
        },
        "tasks": {
            "total": config.n_tasks,
            "stored_before": n_before,
            "computed": n_missing,
            "rows": int(len(df)),
            "missing": int(config.n_tasks - len(df)),
            "duplicates_dropped": int(duplicates),
        },
        "counts": counts,
        "counts_this_run": dict(statuses_now),
        "mean_c": _f(df["c"].mean()) if len(df) else None,
        # summed over every stored run (also those of earlier invocations)
        "run_time_sum_s": {
            "wall": _f(df["wall_time_s"].sum()) if len(df) else 0.0,
            "cpu": _f(df["cpu_time_s"].sum()) if len(df) else 0.0,
        },
        "points": points,
        "failed_examples": [
            {
                "restitution": float(r.restitution),
                "gyration": float(r.gyration),
                "sample": int(r.sample),
                "error": str(r.error)[-300:],
            }
            for r in failed.head(5).itertuples()
        ],
    }


def format_summary(doc: dict) -> str:
    g = doc["grid"]
    t = doc["tasks"]
    lines = [
        f"exponent sweep: engine {doc['engine']}, n = {doc['n']}, "
        f"{len(g['restitution'])} γ x {len(g['gyration'])} ρ x {g['samples']} runs, "
        f"seed {g['seed']}",
        f"runs: {t['rows']} of {t['total']} stored ({t['stored_before']} before, "
        f"{t['computed']} computed now" + (f", {t['missing']} missing)" if t["missing"] else ")"),
        "status: " + ", ".join(f"{k} {v}" for k, v in doc["counts"].items() if v),
        f"wall time {doc['wall_time_s']:.1f} s (runs {doc['compute_time_s']:.1f} s, "
        f"figures {doc['figures_time_s']:.1f} s), executor {doc['executor']}, "
        f"load average {doc['load_average_start'][0]:.2f} -> {doc['load_average_end'][0]:.2f}",
        f"runs' own time, summed over all stored runs: {doc['run_time_sum_s']['wall']:.1f} s "
        f"wall, {doc['run_time_sum_s']['cpu'] or 0.0:.1f} s CPU",
        "",
        "mean c (rows ρ, columns γ; '-' no run with a c)",
    ]
    gam, rho = g["restitution"], g["gyration"]
    if len(gam) <= 25:
        by = {(p["restitution"], p["gyration"]): p for p in doc["points"]}
        lines.append("   ρ \\ γ " + "".join(f"{x:6.2f}" for x in gam))
        for r in reversed(rho):
            cells = []
            for x in gam:
                m = by[(x, r)]["mean_c"]
                cells.append(f"{m:6.2f}" if m is not None else "     -")
            lines.append(f"  {r:6.3f} " + "".join(cells))
    lines.append("")
    lines.append(f"parts: {doc['parts']['dir']} ({doc['parts']['count']} files)")
    for name, path in doc["figures"].items():
        lines.append(f"{name}: {path}")
    return "\n".join(lines)
