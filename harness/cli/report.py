"""`harness report`: one self-contained HTML file for compare, bench, fidelity, stress and
sweep results (docs/report.md)."""

from __future__ import annotations

from .common import BadInput, add_force, note

HTML = (".html", ".htm")


def register(sub) -> None:
    r = sub.add_parser(
        "report", help="one self-contained HTML file of result documents (docs/report.md)"
    )
    r.add_argument(
        "inputs",
        nargs="+",
        metavar="INPUT",
        help="JSON of compare/bench/fidelity/stress/sweep/restitution, or a sweep directory",
    )
    r.add_argument(
        "--out", required=True, metavar="FILE.html", help="the HTML file to write (.html)"
    )
    add_force(r)
    r.set_defaults(func=run)


def run(args) -> int:
    from ..outputs import check_writable, write_text
    from ..provenance import provenance
    from ..report import ReportInputError, build_report, load_inputs

    check_writable(args.out, args.force, args.inputs, what="report", suffixes=HTML)
    try:
        items = [item for path in args.inputs for item in load_inputs(path)]
    except ReportInputError as exc:
        raise BadInput(str(exc)) from None
    html = build_report(items, args.out, provenance(getattr(args, "argv", None)))
    path = write_text(args.out, html, args.force)
    note(f"wrote {path} ({len(html) / 1024:.0f} KiB, {len(items)} result(s))")
    return 0
