"""`harness compare`: the reference against named simulators on one scene."""

from __future__ import annotations

from .common import BadInput, emit, load_scene_arg, log, note, positive_float


def register(sub) -> None:
    c = sub.add_parser("compare", help="reference against the named simulators")
    c.add_argument("scene")
    c.add_argument("--engine", action="append", required=True)
    c.add_argument("--dt", type=positive_float, action="append")
    c.add_argument("--t-end", type=positive_float)
    c.add_argument("--scale", type=positive_float)
    c.add_argument("--record", metavar="FILE.rrd")
    c.add_argument(
        "--wide",
        action="store_true",
        help="every column in the terminal table (wider than 100 characters)",
    )
    c.add_argument(
        "--out",
        metavar="FILE",
        help="write the impact-by-impact diff to FILE (.csv or .parquet; docs/output.md)",
    )
    c.add_argument("--force", action="store_true", help="let --out replace an existing file")
    c.add_argument("--json", action="store_true")
    c.set_defaults(func=run)


def run(args) -> int:
    from ..compare import compare, format_compare
    from ..provenance import attach
    from ..simulators import check_engine

    for e in args.engine:
        check_engine(e)
    if args.out:
        from ..io import check_table_path

        try:  # before minutes of simulation, not after
            check_table_path(args.out, args.force)
        except ValueError as exc:
            raise BadInput(str(exc)) from None
    scene = load_scene_arg(args)
    result = compare(scene, args.engine, dts=args.dt, t_end=args.t_end, progress=log)
    recording = None
    if args.record:
        from ..recording import record_comparison

        recording = record_comparison(result, args.record, note=note)
        note(f"wrote {recording}")
    if args.out:
        from ..compare.diff import impact_diff
        from ..io import write_table

        try:
            path = write_table(impact_diff(result), args.out, force=args.force)
        except ValueError as exc:
            raise BadInput(str(exc)) from None
        note(f"wrote {path}")
    doc = result.to_dict()
    if recording is not None:
        doc["recording"] = str(recording)
    emit(attach(doc, args), args.json, format_compare(result, wide=args.wide))
    return 0
