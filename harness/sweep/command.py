"""`harness sweep exponent`: arguments to SweepConfig, the run (or resumption) of a sweep
into its study directory, the comparison figures (package docstring: harness.sweep)."""

from __future__ import annotations

import contextlib
import os
import time
from pathlib import Path

from reference.scene import SceneError

from ..simulators import check_engine, check_law_options, check_run, is_fixed_step
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
from .summary import format_summary, summarise


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
        simultaneity_window=sweep_window(args),
        **extra,
    )
    check_law_options(
        args.engine, getattr(args, "impact_law", None), getattr(args, "simultaneity_window", None)
    )
    check_config(config)
    return config


def sweep_window(args) -> float:
    """The simultaneity window of the reference and the linear model: the option, else
    the simulator's default (the reference's `reference.scene.default_window` of the
    law, the linear model's LINEAR_DEFAULT_WINDOW); 0 (none) for the other engines."""
    from reference.linear.simulate import LINEAR_DEFAULT_WINDOW
    from reference.scene import default_window

    window = getattr(args, "simultaneity_window", None)
    if window is not None:
        return float(window)
    if args.engine == "reference":
        return default_window(getattr(args, "impact_law", None) or "paper")
    return LINEAR_DEFAULT_WINDOW if args.engine == "linear" else 0.0


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
        # closing: the executor stops (its pool shut down, its workers ended) as soon as
        # the loop ends, on a signal or an error too, not whenever the generator is
        # collected
        with (
            progress_bar(
                config.n_tasks,
                f"sweep {config.engine}",
                show=bar and bool(missing),
                initial=len(done),
            ) as pbar,
            contextlib.closing(results),
        ):
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

    df, refused = load_results(store.dir)
    figs: dict = {}
    t_fig = time.perf_counter()
    if figures and len(df):
        from .plots import make_sweep_figures

        say("sweep: drawing figures")
        figs = make_sweep_figures(store.dir, df, config)
        figs.update(_comparisons(root, config))
    figures_s = time.perf_counter() - t_fig
    doc = summarise(config, df, store, statuses, len(done), len(missing), refused)
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
