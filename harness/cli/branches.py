"""`harness branches SCENE`: the reference run to its first undecidable state and
continued from there under every impact law (harness.branches)."""

from __future__ import annotations

from .common import (
    add_force,
    add_json,
    add_scale,
    add_scene,
    add_t_end,
    emit,
    load_scene_arg,
    log,
    note,
    scene_inputs,
)


def register(sub) -> None:
    b = sub.add_parser(
        "branches",
        help="continue the reference past its first undecidable state under every law",
        description="Run the reference under the paper's rule to its first undecidable "
        "state (simultaneous_impact), then continue the same scene under each impact law "
        "(moreau, sequential, and the sequential law in each order of the touching "
        "contacts when at most three touch); print the spread of the branches: energy "
        "after the impact, the next impacts, final status, t_f and the exponent c.",
    )
    add_scene(b)
    add_t_end(b)
    add_scale(b)
    b.add_argument("--plot", metavar="FILE.png", help="draw the branches' energies")
    add_force(b)
    add_json(b)
    b.set_defaults(func=run)


def run(args) -> int:
    from ..branches.plot import plot_spread
    from ..branches.spread import branches
    from ..branches.text import format_spread
    from ..outputs import atomic_write, check_writable
    from ..provenance import attach
    from ..simulators import check_run

    scene = load_scene_arg(args)
    check_run("reference", scene, None, args.t_end)
    if args.plot:
        check_writable(args.plot, force=args.force, inputs=scene_inputs(args))
    spread = branches(scene, args.t_end, progress=log)
    doc = attach(spread.to_dict(), args)
    if args.plot:
        with atomic_write(args.plot, args.force) as tmp:
            plot_spread(spread, tmp)
        doc["plot"] = str(args.plot)
        note(f"wrote {args.plot}")
    emit(doc, args.json, format_spread(spread, label=scene.contacts.label))
    return 0
