"""`harness compare`: the reference against named simulators on one scene."""

from __future__ import annotations

from .common import emit, load_scene_arg, log, note, positive_float


def register(sub) -> None:
    c = sub.add_parser("compare", help="reference against the named simulators")
    c.add_argument("scene")
    c.add_argument("--engine", action="append", required=True)
    c.add_argument("--dt", type=positive_float, action="append")
    c.add_argument("--t-end", type=positive_float)
    c.add_argument("--scale", type=positive_float)
    c.add_argument("--record", metavar="FILE.rrd")
    c.add_argument("--json", action="store_true")
    c.set_defaults(func=run)


def run(args) -> int:
    from ..compare import compare, format_compare
    from ..simulators import check_engine

    for e in args.engine:
        check_engine(e)
    scene = load_scene_arg(args)
    result = compare(scene, args.engine, dts=args.dt, t_end=args.t_end, progress=log)
    if args.record:
        from ..recording import record_trajectories

        runs = [r.trajectory for r in result.runs if r.trajectory.n_samples > 0]
        skipped = len(result.runs) - len(runs)
        if skipped:
            note(f"recording leaves out {skipped} run(s) that produced no samples")
        path = record_trajectories([result.reference, *runs], args.record, scene=scene)
        note(f"wrote {path}")
    emit(result.to_dict(), args.json, format_compare(result))
    return 0
