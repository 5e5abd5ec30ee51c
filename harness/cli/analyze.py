"""`harness analyze selfsimilar|chatter`: analyses of the linearised model."""

from __future__ import annotations

from .common import BadInput, Parser, emit, fraction, positive_float


def register(sub) -> None:
    a = sub.add_parser("analyze", help="analyses of the linearised model")
    asub = a.add_subparsers(dest="analysis", required=True, parser_class=Parser)
    for name in ("selfsimilar", "chatter"):
        x = asub.add_parser(name)
        x.add_argument("--n", type=int, required=True)
        x.add_argument("--gyration", type=positive_float, required=True)
        x.add_argument("--restitution", type=fraction, required=True)
        x.add_argument("--json", action="store_true")
    a.set_defaults(func=run)


def run(args) -> int:
    if args.n < 2:
        raise BadInput(f"--n must be >= 2, got {args.n}")
    if args.analysis == "selfsimilar":
        from reference.linear.selfsimilar import analyze_selfsimilar, format_selfsimilar

        doc = analyze_selfsimilar(args.n, args.gyration, args.restitution)
        emit(doc, args.json, format_selfsimilar(doc))
    else:
        from reference.linear.chatter import analyze_chatter, format_chatter

        doc = analyze_chatter(args.n, args.gyration, args.restitution)
        emit(doc, args.json, format_chatter(doc))
    return 0
