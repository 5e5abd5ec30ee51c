"""`harness analyze selfsimilar|chatter`: analyses of the linearised model."""

from __future__ import annotations

from .common import BadInput, Parser, add_json, emit, fraction, gyration, vertices

ANALYSES = {
    "selfsimilar": (
        "self-similar motions of the linearised n-gon (paper sections 3.1-3.3)",
        3,
    ),
    "chatter": (
        "gravity-free chatter: eigenvalues of R^-1 U0, CC and PCC, the rod's beta_p, beta_q, "
        "c_lin (paper section 4)",
        2,
    ),
}


def register(sub) -> None:
    a = sub.add_parser("analyze", help="analyses of the linearised model")
    from reference.linear._text import CHATTER_LEGEND, SELFSIMILAR_LEGEND

    legends = {"selfsimilar": SELFSIMILAR_LEGEND, "chatter": CHATTER_LEGEND}
    asub = a.add_subparsers(dest="analysis", required=True, parser_class=Parser)
    for name, (text, n_min) in ANALYSES.items():
        x = asub.add_parser(name, help=text, description=text, epilog=legends[name])
        x.add_argument(
            "--n",
            type=vertices,
            required=True,
            metavar="N",
            help=f"number of vertices of the regular polygon, >= {n_min}"
            + (" (2 is the rod)" if n_min == 2 else ""),
        )
        x.add_argument(
            "--gyration",
            type=gyration,
            required=True,
            metavar="RHO",
            help="radius of gyration in units of the radius, in [1e-6, 1e6] "
            "(inertia m (rho a)^2 diag(1, 1, 2))",
        )
        x.add_argument(
            "--restitution",
            type=fraction,
            required=True,
            metavar="GAMMA",
            help="Newtonian coefficient of restitution, in [0, 1]",
        )
        add_json(x)
    a.set_defaults(func=run)


def run(args) -> int:
    n_min = ANALYSES[args.analysis][1]
    if args.n < n_min:
        raise BadInput(f"analyze {args.analysis}: --n must be >= {n_min}, got {args.n}")
    if args.analysis == "selfsimilar":
        from reference.linear.selfsimilar import analyze_selfsimilar, format_selfsimilar

        doc = analyze_selfsimilar(args.n, args.gyration, args.restitution)
        emit(doc, args.json, format_selfsimilar(doc))
    else:
        from reference.linear.chatter import analyze_chatter, format_chatter

        doc = analyze_chatter(args.n, args.gyration, args.restitution)
        emit(doc, args.json, format_chatter(doc))
    return 0
