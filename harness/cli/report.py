"""`harness report`: one self-contained HTML file for compare, bench, fidelity, stress and
sweep results (docs/report.md)."""

from __future__ import annotations

from .common import BadInput, note


def register(sub) -> None:
    r = sub.add_parser(
        "report", help="one self-contained HTML file of result documents (docs/report.md)"
    )
    r.add_argument(
        "inputs",
        nargs="+",
        metavar="INPUT",
        help="JSON of compare/bench/fidelity/stress/sweep, or a sweep directory",
    )
    r.add_argument("--out", required=True, metavar="FILE.html")
    r.add_argument("--force", action="store_true", help="replace an existing FILE.html")
    r.set_defaults(func=run)


def run(args) -> int:
    from ..provenance import provenance
    from ..report import ReportInputError, build_report, load_inputs
    from ..result_files import check_result_path, write_result_text

    suffixes = (".html", ".htm")
    try:
        check_result_path(args.out, suffixes, args.force)
        items = [item for path in args.inputs for item in load_inputs(path)]
    except (ValueError, ReportInputError) as exc:
        raise BadInput(str(exc)) from None
    html = build_report(items, args.out, provenance(getattr(args, "argv", None)))
    try:
        path = write_result_text(html, args.out, suffixes, args.force)
    except ValueError as exc:
        raise BadInput(str(exc)) from None
    note(f"wrote {path} ({len(html) / 1024:.0f} KiB, {len(items)} result(s))")
    return 0
