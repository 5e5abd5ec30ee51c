"""`harness simulate`: one run of one simulator."""

from __future__ import annotations

from .common import emit, load_scene_arg, note, positive_float


def register(sub) -> None:
    s = sub.add_parser("simulate", help="one run of one simulator")
    s.add_argument("scene")
    s.add_argument("--engine", default="reference")
    s.add_argument("--dt", type=positive_float)
    s.add_argument("--t-end", type=positive_float)
    s.add_argument("--scale", type=positive_float)
    s.add_argument("--record", metavar="FILE.rrd")
    s.add_argument("--out", metavar="FILE.parquet")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=run)


def run(args) -> int:
    from ..simulators import check_engine, run_simulator
    from ..text import format_simulate

    check_engine(args.engine)
    scene = load_scene_arg(args)
    traj = run_simulator(args.engine, scene, dt=args.dt, t_end=args.t_end)
    if args.out:
        from ..io import write_trajectory_parquet

        write_trajectory_parquet(traj, args.out)
        note(f"wrote {args.out}")
    if args.record:
        from ..recording import record_trajectories

        path = record_trajectories([traj], args.record, scene=scene)
        note(f"wrote {path}")
    emit(traj.summary(with_impacts=True), args.json, format_simulate(traj))
    return 0
