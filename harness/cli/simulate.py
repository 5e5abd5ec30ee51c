"""`harness simulate`: one run of one simulator."""

from __future__ import annotations

from pathlib import Path

from .common import (
    StepProgress,
    add_dt,
    add_engine,
    add_force,
    add_impact_law,
    add_json,
    add_max_steps,
    add_scale,
    add_scene,
    add_t_end,
    add_wide,
    emit,
    load_scene_arg,
    note,
    scene_inputs,
)

# exit status of a run stopped by Ctrl-C (128 + SIGINT, the shell's convention)
INTERRUPTED = 130


def work_bound_text() -> str:
    """The reference's bound on its work (reference.core.loop._stalled), for --help."""
    from reference.core.tolerances import STALL_WINDOW
    from reference.options import ReferenceOptions

    rtol = ReferenceOptions().contact_rtol
    return (
        f"The reference's work is bounded: every {STALL_WINDOW:,} loop steps without an "
        f"impact must advance t by at least contact_rtol ({rtol:g}) of the motion's time "
        "scale T = min(sqrt(a/g), a/V) a step (V = |v| + a|w|), else the run ends "
        "'stalled' (its message names t, the contacts held and the impact law); so a run "
        f"takes at most {STALL_WINDOW:,} x (max_impacts + 1) steps plus t_end / "
        "(contact_rtol T) contact chunks."
    )


def register(sub) -> None:
    s = sub.add_parser(
        "simulate",
        help="one run of one simulator",
        description="One run of one simulator on one scene.  Prints the run's summary "
        "(status, impacts, energy, final state).  Exit status 0 done (whatever the "
        "physics), 2 bad input, 130 stopped by Ctrl-C, 143 by SIGTERM (the summary of the "
        "part computed is printed, no file is written).  " + work_bound_text(),
    )
    add_scene(s)
    add_engine(s)
    add_dt(s)
    add_t_end(s)
    add_impact_law(s)
    add_scale(s)
    add_max_steps(s)
    s.add_argument(
        "--record",
        metavar="FILE.rrd",
        help="also write a rerun recording to FILE.rrd",
    )
    s.add_argument(
        "--out",
        metavar="FILE.parquet",
        help="also write the samples to FILE and the impacts to FILE with .impacts "
        "before its suffix (Parquet; the summary in the schema metadata)",
    )
    add_force(s)
    add_json(s)
    add_wide(s)
    s.set_defaults(func=run)


def planned_outputs(args) -> list:
    """The files this run will write, as harness.outputs sees them."""
    from ..io import trajectory_paths

    paths = trajectory_paths(args.out) if args.out else []
    if args.record:
        paths.append(Path(args.record))
    return paths


def check_outputs(args, paths) -> None:
    from ..outputs import check_distinct, check_recording_path, check_writable

    check_distinct(paths)
    inputs = scene_inputs(args)
    if args.out:
        check_writable(args.out, args.force, inputs, what="--out", suffixes=(".parquet",))
    if args.record:
        check_recording_path(args.record, args.force, inputs)
    for path in paths:
        check_writable(path, force=args.force, inputs=inputs)


def run(args) -> int:
    from ..simulators import check_engine, check_law_options, check_run, run_simulator
    from ..text import format_simulate

    check_engine(args.engine)
    check_law_options(args.engine, args.impact_law, args.simultaneity_window)
    scene = load_scene_arg(args)
    check_run(args.engine, scene, args.dt, args.t_end, args.max_steps)
    check_outputs(args, planned_outputs(args))
    progress = StepProgress(args.engine)
    try:
        traj = run_simulator(
            args.engine,
            scene,
            dt=args.dt,
            t_end=args.t_end,
            max_steps=args.max_steps,
            progress=progress,
        )
    finally:
        progress.close()
    interrupted = bool(traj.stats.get("interrupted"))
    if interrupted:
        note("harness: interrupted; the summary covers the part computed, no file written")
    else:
        write_or_say(args, traj, scene)
    text = format_simulate(traj, scale=args.scale, wide=args.wide, label=scene.contacts.label)
    emit(summary_with_kinds(traj, scene), args.json, text)
    return INTERRUPTED if interrupted else 0


def summary_with_kinds(traj, scene) -> dict:
    """The run's summary; on a bumpy ground each impact row also says which kind of
    contact took it (`kind`: rim or bump)."""
    from reference.bumpy import contact_kind_names, is_bumpy

    doc = traj.summary(with_impacts=True)
    if is_bumpy(scene):
        names = contact_kind_names(scene)
        for row in doc["impacts"]:
            row["kind"] = names[row["contact"]]
    return doc


def write_or_say(args, traj, scene) -> None:
    """`write_outputs`; memory exhausted while writing is OutputError (exit 2, one line)
    that keeps the run's own status and message, with nothing written (the writers are
    atomic: harness.outputs)."""
    from ..outputs import OutputError

    try:
        write_outputs(args, traj, scene)
    except MemoryError as exc:  # pyarrow's ArrowMemoryError too
        raise OutputError(
            f"out of memory while writing the outputs ({type(exc).__name__}); nothing "
            f"written; the run itself ended {traj.status.value}: {traj.message}"
        ) from None


def write_outputs(args, traj, scene) -> None:
    if args.out:
        from ..io import trajectory_paths, write_trajectory_parquet

        samples, impacts = trajectory_paths(args.out)
        write_trajectory_parquet(traj, args.out, force=args.force)
        note(f"wrote {samples} (samples) and {impacts} (impacts)")
    if args.record:
        from ..recording import record_trajectories

        path = record_trajectories([traj], args.record, scene=scene, force=args.force)
        note(f"wrote {path}")
