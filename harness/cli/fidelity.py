"""`harness fidelity`: each engine's fidelity limit α* under the paper's scaling."""

from __future__ import annotations

import json

from .common import BadInput, emit, finite, fraction, grid, log, note, positive_float


def register(sub) -> None:
    from ..fidelity import DEFAULT_BUDGET_S, DEFAULT_EPS_GRID, WINDOWS
    from ..fidelity.criteria import DEFAULT_C_TOLERANCE, DEFAULT_LEADING, DEFAULT_MATCH_FRACTION

    f = sub.add_parser(
        "fidelity",
        help="smallest inclination alpha* each engine follows, against dt (docs/fidelity.md)",
    )
    f.add_argument("scene", help="a built-in scene or a file, given in (q, p)")
    f.add_argument(
        "--engine", action="append", help="default: every installed engine but reference, linear"
    )
    f.add_argument("--dt", type=positive_float, action="append", help="default 1e-3, 1e-4, 1e-5")
    a, b, k = DEFAULT_EPS_GRID
    f.add_argument(
        "--eps-grid",
        type=grid,
        default=DEFAULT_EPS_GRID,
        metavar="A:B:K",
        help=f"K scales from A to B, log-spaced (default {a:g}:{b:g}:{k})",
    )
    f.add_argument(
        "--leading",
        type=int,
        default=DEFAULT_LEADING,
        help=f"leading impacts of the reference to match (default {DEFAULT_LEADING})",
    )
    f.add_argument(
        "--match-fraction",
        type=fraction,
        default=DEFAULT_MATCH_FRACTION,
        help=f"fraction of them a run must match (default {DEFAULT_MATCH_FRACTION:g})",
    )
    f.add_argument(
        "--c-tolerance",
        type=positive_float,
        default=DEFAULT_C_TOLERANCE,
        help=f"relative tolerance on c where both runs have one (default {DEFAULT_C_TOLERANCE:g})",
    )
    f.add_argument(
        "--window",
        choices=WINDOWS,
        default="leading",
        help="run engines just past the leading impacts (default) or to the reference's end",
    )
    f.add_argument(
        "--budget",
        type=positive_float,
        default=DEFAULT_BUDGET_S,
        help=f"seconds per run (default {DEFAULT_BUDGET_S:g}; predicted, skipped above it)",
    )
    f.add_argument("--plot", metavar="FILE.png", help="alpha* against dt with the fitted k")
    f.add_argument("--out", metavar="FILE.json", help="also write the JSON document here")
    f.add_argument("--force", action="store_true", help="let --out/--plot replace a file")
    f.add_argument("--json", action="store_true")
    f.set_defaults(func=run)


def run(args) -> int:
    from ..fidelity import FidelityCriteria, eps_values, fidelity, format_fidelity
    from ..provenance import attach
    from ..result_files import check_result_path, write_result_text
    from ..simulators import check_engine
    from .common import load_scene_arg

    for e in args.engine or []:
        check_engine(e)
    try:  # before the runs, not after
        for path, suffix in ((args.out, ".json"), (args.plot, ".png")):
            if path:
                check_result_path(path, (suffix,), args.force)
    except ValueError as exc:
        raise BadInput(str(exc)) from None
    scene = load_scene_arg(args)
    scene.scaled(1.0)  # a scene not given in (q, p) is bad input now, not after the reference
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
    )
    attach(doc, args)
    if args.plot:
        from ..fidelity import alpha_star_figure, save_figure
        from ..result_files import write_result_atomic

        path = check_result_path(args.plot, (".png",), args.force)
        fig = alpha_star_figure(doc)
        write_result_atomic(path, lambda tmp: save_figure(fig, tmp), args.force)
        doc["plot"] = str(path)
        note(f"wrote {path}")
    if args.out:
        write_result_text(json.dumps(finite(doc), indent=1), args.out, (".json",), args.force)
        note(f"wrote {args.out}")
    emit(doc, args.json, format_fidelity(doc))
    return 0
