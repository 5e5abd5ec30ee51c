"""`harness bench`: speed against error (work-precision)."""

from __future__ import annotations

from .common import (
    BadInput,
    add_dt,
    add_engine,
    add_force,
    add_impact_law,
    add_json,
    add_scene,
    add_t_end,
    add_wide,
    budget,
    emit,
    int_in,
    load_scene_arg,
    log,
    note,
    scene_inputs,
)


def register(sub) -> None:
    b = sub.add_parser(
        "bench",
        help="speed against error (work-precision)",
        description="Work-precision study of one scene: every simulator's wall time "
        "against its errors versus the reference at its tightest setting.  Fixed-step "
        "engines run over a sweep of timesteps (coarse to fine, stopping where the "
        "predicted cost exceeds the budget); timesteps longer than the run or beyond "
        "the step ceiling are listed as skipped.  Ctrl-C stops it (exit status 130).",
    )
    add_scene(b)
    add_engine(b, many="default: every installed engine")
    add_dt(b, many="default: 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 1e-6")
    add_t_end(b)
    add_impact_law(b)
    b.add_argument(
        "--repeats",
        type=int_in(1, 1000),
        default=3,
        metavar="N",
        help="timed runs per setting (their median is reported), after one warm-up run",
    )
    b.add_argument(
        "--budget",
        type=budget,
        default=60.0,
        metavar="S",
        help="seconds [s] a setting may take (repeats x predicted run time); finer "
        "timesteps beyond it are skipped",
    )
    b.add_argument(
        "--plot",
        metavar="FILE.png",
        help="also draw the work-precision curves (format from the suffix: png, pdf, svg)",
    )
    b.add_argument("--out", metavar="FILE.json", help="also write the JSON document to FILE")
    add_wide(b)
    add_force(b)
    add_json(b)
    b.set_defaults(func=run)


def check_outputs(args) -> None:
    from ..outputs import check_distinct, check_writable

    check_distinct([args.plot, args.out])
    inputs = scene_inputs(args)
    if args.plot:
        check_writable(args.plot, force=args.force, inputs=inputs, what="--plot")
    if args.out:
        check_writable(args.out, args.force, inputs, what="--out", suffixes=(".json",))
    if args.plot:
        check_plot_format(args.plot)


def check_plot_format(path: str) -> None:
    """The plot's suffix must be a format matplotlib writes (it picks it from the name)."""
    from pathlib import Path

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    formats = FigureCanvasAgg(Figure()).get_supported_filetypes()
    suffix = Path(path).suffix.lstrip(".").lower()
    if suffix not in formats:
        raise BadInput(
            f"--plot {path}: the suffix must name an image format ({', '.join(sorted(formats))})"
        )


def run(args) -> int:
    from ..bench import bench, format_bench, plot_work_precision
    from ..io import json_text
    from ..outputs import atomic_write, write_text
    from ..provenance import attach
    from ..simulators import check_engine, check_run

    scene = load_scene_arg(args)
    for e in args.engine or []:
        check_engine(e)
    check_run("reference", scene, None, args.t_end)
    for e in args.engine or []:
        for dt in args.dt or []:
            check_run(e, scene, dt, args.t_end)
    check_outputs(args)
    doc = bench(
        scene,
        engines=args.engine,
        dts=args.dt,
        t_end=args.t_end,
        repeats=args.repeats,
        progress=log,
        budget_s=args.budget,
    )
    attach(doc, args)
    if args.plot:
        with atomic_write(args.plot, args.force) as tmp:
            plot_work_precision(doc, tmp)
        doc["plot"] = str(args.plot)
        note(f"wrote {args.plot}")
    if args.out:
        write_text(args.out, json_text(doc, indent=1), force=args.force)
        note(f"wrote {args.out}")
    emit(doc, args.json, format_bench(doc, wide=args.wide))
    return 0
