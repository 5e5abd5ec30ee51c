"""`harness fidelity`: each engine's fidelity limit α* under the paper's scaling."""

from __future__ import annotations

from .common import (
    add_dt,
    add_engine,
    add_force,
    add_horizon,
    add_impact_law,
    add_json,
    budget,
    emit,
    fraction,
    grid,
    int_in,
    log,
    note,
    positive_float,
    scene_inputs,
)


def register(sub) -> None:
    f = sub.add_parser(
        "fidelity",
        help="smallest inclination alpha* each engine follows, against dt (docs/fidelity.md)",
    )
    from ..fidelity import DEFAULT_BUDGET_S, DEFAULT_EPS_GRID, WINDOWS
    from ..fidelity.criteria import DEFAULT_C_TOLERANCE, DEFAULT_LEADING, DEFAULT_MATCH_FRACTION

    f.add_argument("scene", help="a built-in scene or a file, given in (q, p)")
    add_engine(f, many="default: every installed engine but reference and linear")
    add_dt(f, many="default: 1e-3, 1e-4, 1e-5")
    add_impact_law(f)
    a, b, k = DEFAULT_EPS_GRID
    f.add_argument(
        "--eps-grid",
        type=grid,
        default=f"{a:g}:{b:g}:{k}",  # argparse converts a string default with `type`
        metavar="A:B:K",
        help="K scales from A to B, log-spaced",
    )
    f.add_argument(
        "--leading",
        type=int_in(1, 10**6),
        default=DEFAULT_LEADING,
        help="leading impacts of the reference to match",
    )
    f.add_argument(
        "--match-fraction",
        type=fraction,
        default=DEFAULT_MATCH_FRACTION,
        help="fraction of them a run must match",
    )
    f.add_argument(
        "--c-tolerance",
        type=positive_float,
        default=DEFAULT_C_TOLERANCE,
        help="relative tolerance on c where both runs have one",
    )
    f.add_argument(
        "--window",
        choices=WINDOWS,
        default="leading",
        help="run engines just past the leading impacts, or to the reference's end",
    )
    f.add_argument(
        "--budget",
        type=budget,
        default=DEFAULT_BUDGET_S,
        help="seconds per run (predicted, skipped above it)",
    )
    f.add_argument("--plot", metavar="FILE.png", help="alpha* against dt with the fitted k")
    f.add_argument("--out", metavar="FILE.json", help="also write the JSON document here")
    add_horizon(f)
    add_force(f)
    add_json(f)
    f.set_defaults(func=run)


def run(args) -> int:
    from ..fidelity import FidelityCriteria, eps_values, fidelity, format_fidelity
    from ..provenance import attach
    from ..simulators import check_engine
    from .common import load_scene_arg

    for e in args.engine or []:
        check_engine(e)
    check_outputs(args)  # before the runs, not after
    scene = load_scene_arg(args)
    # a scene not given in (q, p) is bad input now, not after the reference
    scene.scaled(1.0, name="fidelity")
    criteria = FidelityCriteria(args.leading, args.match_fraction, args.c_tolerance)
    doc = fidelity(
        scene,
        engines=args.engine,
        dts=args.dt,
        eps=eps_values(*args.eps_grid),
        criteria=criteria,
        window=args.window,
        budget_s=args.budget,
        progress=log,
        horizon_runs=args.horizon_runs,
        horizon_seed=args.horizon_seed,
    )
    attach(doc, args)
    write_outputs(args, doc)
    emit(doc, args.json, format_fidelity(doc))
    return 0


def check_outputs(args) -> None:
    from ..outputs import check_distinct, check_writable

    check_distinct([args.out, args.plot])
    inputs = scene_inputs(args)
    if args.out:
        check_writable(args.out, args.force, inputs, what="--out", suffixes=(".json",))
    if args.plot:
        check_writable(args.plot, args.force, inputs, what="--plot", suffixes=(".png",))


def write_outputs(args, doc: dict) -> None:
    from ..io import json_text
    from ..outputs import atomic_write, write_text

    if args.plot:
        from ..fidelity import alpha_star_figure, save_figure

        fig = alpha_star_figure(doc)
        with atomic_write(args.plot, args.force) as tmp:
            save_figure(fig, tmp)
        doc["plot"] = str(args.plot)
        note(f"wrote {args.plot}")
    if args.out:
        write_text(args.out, json_text(doc, indent=1), args.force)
        note(f"wrote {args.out}")
