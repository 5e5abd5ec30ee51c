"""`harness sweep exponent`: the energy-exponent map over (γ, ρ)."""

from __future__ import annotations

from .common import (
    MAX_GRID_POINTS,
    Parser,
    add_engine,
    add_impact_law,
    add_json,
    duration,
    emit,
    grid,
    int_in,
    json_text,
    log,
    timestep,
    vertices,
)


def register(sub) -> None:
    sw = sub.add_parser("sweep", help="parameter sweeps")
    swsub = sw.add_subparsers(dest="sweep", required=True, parser_class=Parser)
    e = swsub.add_parser(
        "exponent",
        help="energy-exponent map over (gamma, rho)",
        description="The energy exponent c of E ~ (t_f - t)^c over a grid of (gamma, rho), "
        "S runs per grid point from the paper's random initial states, stored as Parquet "
        "parts under DIR/<engine>/.  Rerunning the same command resumes; damaged parts "
        "or manifests are set aside (renamed *.corrupt-<time>) and recomputed.  At most "
        "1e6 runs per sweep.  Ctrl-C stops it; finished runs are kept.",
    )
    e.add_argument(
        "--n", type=vertices, default=3, metavar="N", help="vertices of the polygon, >= 2"
    )
    e.add_argument(
        "--gyration",
        type=grid,
        required=True,
        metavar="A:B:K",
        help="radii of gyration rho: K values from A to B inclusive (a single number: that "
        f"value alone); each in [1e-6, 1e6], K <= {MAX_GRID_POINTS}",
    )
    e.add_argument(
        "--restitution",
        type=grid,
        required=True,
        metavar="A:B:K",
        help="coefficients of restitution gamma: K values from A to B inclusive; each in "
        f"[0, 1], K <= {MAX_GRID_POINTS}",
    )
    e.add_argument(
        "--samples",
        type=int_in(1, 1_000_000),
        default=100,
        metavar="S",
        help="runs per grid point",
    )
    e.add_argument(
        "--seed",
        type=int_in(0, 2**63 - 1),
        default=0,
        metavar="SEED",
        help="seed of the random initial states (a run's state depends only on the seed "
        "and its grid point and sample number)",
    )
    add_engine(e, default="linear")
    add_impact_law(e)
    e.add_argument(
        "--dt",
        type=timestep,
        metavar="DT",
        help="timestep of fixed-step engines [s] (default: 1e-4; others ignore it)",
    )
    e.add_argument(
        "--t-end",
        type=duration,
        metavar="T",
        help="cap on each run's simulated time [s] for non-linear engines (default: 200)",
    )
    e.add_argument(
        "--executor",
        choices=("local", "dask"),
        default="local",
        help="where runs execute: a local process pool or a Dask cluster",
    )
    e.add_argument(
        "--scheduler", metavar="ADDR", help="Dask scheduler address (with --executor dask)"
    )
    e.add_argument(
        "--workers",
        type=int_in(1, 1024),
        metavar="W",
        help="local worker processes (default: one per CPU)",
    )
    e.add_argument(
        "--chunk-size",
        type=int_in(1, 1_000_000),
        metavar="C",
        help="runs per task (default: 25 for the event-driven linear model and reference, "
        "1 for fixed-step engines)",
    )
    e.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help="study directory: new, empty, or one a sweep wrote (results go to DIR/<engine>/)",
    )
    add_json(e)
    sw.set_defaults(func=run)


def run(args) -> int:
    from ..provenance import attach
    from ..sweep import run_exponent_sweep

    doc = attach(run_exponent_sweep(args, progress=log), args)
    emit(doc, args.json, doc.get("text", json_text(doc, indent=1)))
    return 0
