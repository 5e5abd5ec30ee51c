"""`harness branches SCENE`: the reference run to its first undecidable state and
continued from there under every impact law (harness.branches); with --engine, each
engine started just before that state and set against every branch
(harness.branches.engines)."""

from __future__ import annotations

from .common import (
    add_dt,
    add_engine,
    add_force,
    add_json,
    add_scale,
    add_t_end,
    emit,
    load_scene_arg,
    log,
    note,
    scene_inputs,
)

DEFAULT_DTS = (1e-3, 1e-4)


def register(sub) -> None:
    b = sub.add_parser(
        "branches",
        help="continue the reference past its first undecidable state under every law",
        description="Run the reference under the paper's rule to its first undecidable "
        "state (simultaneous_impact), then continue the same scene under each impact law "
        "(moreau, sequential, compliant, compliant-mass, and the sequential law in each "
        "order of the touching contacts when at most three touch); print the spread of "
        "the branches: energy after the impact, the next impacts, final status, t_f and "
        "the exponent c. With --engine: start each engine just before that state, run it "
        "through the impact and print its distance to every branch at each dt and the "
        "law it follows (docs/laws.md).",
    )
    b.add_argument("scene", nargs="?", help="a scene file (TOML) or the name of a built-in "
                   "scene (not with --suite)")  # fmt: skip
    add_t_end(b)
    add_scale(b)
    add_engine(b, many="each engine is set against the branches at the impact")
    add_dt(b, many="default: " + ", ".join(f"{x:g}" for x in DEFAULT_DTS))
    b.add_argument("--suite", action="store_true",
                   help="with --engine: the canonical landings instead of SCENE "
                   "(harness.branches.suite)")  # fmt: skip
    b.add_argument(
        "--plot", metavar="FILE.png",
        help="draw the branches' energies (with --engine: distance against dt)",
    )  # fmt: skip
    add_force(b)
    add_json(b)
    b.set_defaults(func=run)


def run(args) -> int:
    from reference.scene import SceneError

    if args.suite and not args.engine:
        raise SceneError("--suite needs at least one --engine")
    if args.suite == (args.scene is not None):
        raise SceneError("give a SCENE or --suite (one of them)")
    if args.engine:
        return run_engines(args)
    return run_spread(args)


def run_spread(args) -> int:
    from ..branches.plot import plot_spread
    from ..branches.spread import branches
    from ..branches.text import format_spread
    from ..outputs import atomic_write, check_writable
    from ..provenance import attach
    from ..simulators import check_run

    scene = load_scene_arg(args)
    check_run("reference", scene, None, args.t_end)
    if args.plot:
        check_writable(args.plot, args.force, scene_inputs(args), what="--plot", suffixes=(".png",))
    spread = branches(scene, args.t_end, progress=log)
    doc = attach(spread.to_dict(), args)
    if args.plot:
        with atomic_write(args.plot, args.force) as tmp:
            plot_spread(spread, tmp)
        doc["plot"] = str(args.plot)
        note(f"wrote {args.plot}")
    emit(doc, args.json, format_spread(spread, label=scene.contacts.label))
    return 0


def run_engines(args) -> int:
    from ..branches.engines import planned_runs, study
    from ..branches.plot import plot_engines
    from ..branches.suite import suite
    from ..branches.text import format_study
    from ..outputs import atomic_write, check_writable
    from ..progress import progress_bar
    from ..provenance import attach
    from ..simulators import check_engine, check_run

    scenes = suite() if args.suite else [_scene(args)]
    dts = list(args.dt or DEFAULT_DTS)
    for engine in args.engine:
        check_engine(engine)
    for scene in scenes:
        check_run("reference", scene, None, args.t_end)
    if args.plot:
        inputs = [] if args.suite else scene_inputs(args)
        check_writable(args.plot, args.force, inputs, what="--plot", suffixes=(".png",))
    total = len(scenes) * planned_runs(args.engine, dts)
    with progress_bar(total, "branches", unit="run") as bar:
        studies = [study(s, args.engine, dts, args.t_end, bar=bar) for s in scenes]
    doc = attach({"command": "branches", "mode": "engines",
                  "studies": [s.to_dict() for s in studies]}, args)  # fmt: skip
    if args.plot:
        with atomic_write(args.plot, args.force) as tmp:
            plot_engines(studies, tmp)
        doc["plot"] = str(args.plot)
        note(f"wrote {args.plot}")
    text = "\n\n".join(
        format_study(st, label=sc.contacts.label) for sc, st in zip(scenes, studies, strict=True)
    )
    emit(doc, args.json, text)
    return 0


def _scene(args):
    """SCENE: a file, a built-in scene or one of the suite's landings."""
    return load_scene_arg(args)
