"""`harness sweep exponent`: the energy-exponent map over (γ, ρ)."""

from __future__ import annotations

import json

from .common import Parser, emit, finite, grid, log, positive_float


def register(sub) -> None:
    sw = sub.add_parser("sweep", help="parameter sweeps")
    swsub = sw.add_subparsers(dest="sweep", required=True, parser_class=Parser)
    e = swsub.add_parser("exponent", help="energy-exponent map over (gamma, rho)")
    e.add_argument("--n", type=int, default=3)
    e.add_argument("--gyration", type=grid, required=True)
    e.add_argument("--restitution", type=grid, required=True)
    e.add_argument("--samples", type=int, default=100)
    e.add_argument("--seed", type=int, default=0)
    e.add_argument("--engine", default="linear")
    e.add_argument("--dt", type=positive_float)
    e.add_argument("--executor", choices=("local", "dask"), default="local")
    e.add_argument("--scheduler")
    e.add_argument("--workers", type=int)
    e.add_argument("--t-end", type=positive_float, help="cap the run length (non-linear engines)")
    e.add_argument("--chunk-size", type=int, help="runs per task (default 25 linear, 1 others)")
    e.add_argument("--out", required=True)
    e.add_argument("--json", action="store_true")
    sw.set_defaults(func=run)


def run(args) -> int:
    from ..provenance import attach
    from ..sweep import run_exponent_sweep

    doc = attach(run_exponent_sweep(args, progress=log), args)
    emit(doc, args.json, doc.get("text", json.dumps(finite(doc), indent=1)))
    return 0
