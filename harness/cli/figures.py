"""`harness figures`: the paper's figures as PNGs."""

from __future__ import annotations

from pathlib import Path

from .common import emit, log


def register(sub) -> None:
    f = sub.add_parser("figures", help="the paper's figures as PNGs")
    f.add_argument("--out", default="figures")
    f.add_argument("--json", action="store_true")
    f.set_defaults(func=run)


def run(args) -> int:
    from ..figures import format_figures, make_figures

    doc = make_figures(Path(args.out), progress=log)
    emit(doc, args.json, format_figures(doc, Path(args.out)))
    return 0
