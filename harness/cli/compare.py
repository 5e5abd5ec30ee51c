"""`harness compare`: the reference against named simulators on one scene."""

from __future__ import annotations

from .common import (
    BadInput,
    add_dt,
    add_engine,
    add_force,
    add_horizon,
    add_impact_law,
    add_json,
    add_max_steps,
    add_scale,
    add_scene,
    add_t_end,
    add_wide,
    emit,
    load_scene_arg,
    log,
    note,
    scene_inputs,
)


def register(sub) -> None:
    c = sub.add_parser(
        "compare",
        help="reference against the named simulators",
        description="The exact reference against the named simulators on one scene: "
        "impacts matched, impact-time, energy and attitude errors.  Ctrl-C stops it "
        "(exit status 130).",
    )
    add_scene(c)
    add_engine(c, many="at least one")
    add_dt(c, many="default: 1e-4")
    add_t_end(c)
    add_impact_law(c)
    add_scale(c)
    add_max_steps(c)
    c.add_argument(
        "--record",
        metavar="FILE.rrd",
        help="also write a rerun recording of all runs to FILE.rrd",
    )
    add_wide(c)
    c.add_argument(
        "--out",
        metavar="FILE",
        help="write the impact-by-impact diff to FILE (.csv or .parquet; docs/output.md)",
    )
    add_horizon(c)
    add_force(c)
    add_json(c)
    c.set_defaults(func=run)


def run(args) -> int:
    from ..compare import compare, format_compare
    from ..outputs import check_distinct
    from ..provenance import attach
    from ..simulators import check_engine, check_run, engine_names

    if not args.engine:
        raise BadInput(
            "compare needs --engine E (repeat for several); installed: "
            + ", ".join(e for e in engine_names() if e != "reference")
        )
    for e in args.engine:
        check_engine(e)
    if args.out:  # before minutes of simulation, not after
        from ..io import check_table_path

        check_table_path(args.out, args.force, scene_inputs(args))
    scene = load_scene_arg(args)
    for e in args.engine:
        for dt in args.dt or [None]:
            check_run(e, scene, dt, args.t_end, args.max_steps)
    check_run("reference", scene, None, args.t_end)
    if args.record:
        from ..outputs import check_recording_path

        check_recording_path(args.record, args.force, scene_inputs(args))
        check_distinct([args.record, args.out])
    recording = None
    result = compare(
        scene,
        args.engine,
        dts=args.dt,
        t_end=args.t_end,
        progress=log,
        max_steps=args.max_steps,
        horizon_runs=args.horizon_runs,
        horizon_seed=args.horizon_seed,
    )
    if args.record:
        from ..recording import record_comparison

        recording = record_comparison(result, args.record, note=note, force=args.force)
        note(f"wrote {recording}")
    if args.out:
        from ..compare.diff import impact_diff
        from ..io import write_table

        path = write_table(impact_diff(result), args.out, force=args.force)
        note(f"wrote {path}")
    doc = result.to_dict()
    if recording is not None:
        doc["recording"] = str(recording)
    emit(attach(doc, args), args.json, format_compare(result, wide=args.wide))
    return 0
