"""`harness figures`: the paper's figures as PNGs."""

from __future__ import annotations

import os
from pathlib import Path

from .common import BadInput, add_force, add_json, emit, log


def register(sub) -> None:
    f = sub.add_parser(
        "figures",
        help="the paper's figures as PNGs",
        description="Recompute the paper's figures from the linearised model and save them "
        "as PNGs in a folder, each with what the paper states and what we measured.",
    )
    f.add_argument(
        "--out",
        default="figures",
        metavar="DIR",
        help="folder for the PNGs (created if missing; files there are replaced only with --force)",
    )
    f.add_argument(
        "--only",
        action="append",
        metavar="NAME",
        help="this figure only (repeatable; default: every figure): beta_vs_rho, "
        "feasibility_border, beta_vs_gamma, boundaries, energy_precession, rod_clin, "
        "triangle_c_vs_clin",
    )
    add_force(f)
    add_json(f)
    f.set_defaults(func=run)


def check_out(out: Path, force: bool, names=None) -> None:
    """DIR is a folder (or will be one) and every figure in it may be written."""
    from ..figures import figure_paths
    from ..outputs import check_writable, show

    if os.path.lexists(out) and not os.path.isdir(out):
        raise BadInput(f"--out {show(out)} is not a directory")
    for path in figure_paths(out, names):
        check_writable(path, force=force)


def run(args) -> int:
    from ..figures import FIGURES, format_figures, make_figures

    unknown = sorted(set(args.only or ()) - set(FIGURES))
    if unknown:
        raise BadInput(f"--only {unknown[0]}: no such figure; the figures: {', '.join(FIGURES)}")
    out = Path(args.out)
    check_out(out, args.force, args.only)
    doc = make_figures(out, progress=log, names=args.only)
    emit(doc, args.json, format_figures(doc, out))
    return 0
