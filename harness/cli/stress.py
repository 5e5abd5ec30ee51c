"""`harness stress`: the hard-case suite, a verdict per case and simulator."""

from __future__ import annotations

from .common import add_engine, add_json, add_wide, budget, emit, log, timestep


def register(sub) -> None:
    st = sub.add_parser(
        "stress",
        help="hard-case suite, a verdict per case and engine",
        description="The hard cases (tiny tilts, near-simultaneous impacts, long elastic "
        "runs, ...) on every simulator, each judged ok / degraded / failed against the "
        "reference.  A run predicted over the budget, or that cannot run at this dt (dt "
        "longer than the case, too many steps), is listed as skipped with the reason.  "
        "Ctrl-C stops it (exit status 130).",
    )
    add_engine(st, many="default: every installed engine")
    st.add_argument(
        "--case",
        action="append",
        metavar="NAME",
        help="a case by name or name prefix (alpha selects every alpha case); repeat for "
        "several (default: all)",
    )
    st.add_argument(
        "--dt",
        type=timestep,
        metavar="DT",
        help="timestep of the fixed-step engines [s] (default: 1e-4)",
    )
    st.add_argument(
        "--budget",
        type=budget,
        default=30.0,
        metavar="S",
        help="seconds [s] a run may take; runs predicted longer are skipped",
    )
    add_wide(st)
    add_json(st)
    st.set_defaults(func=run)


def run(args) -> int:
    from ..provenance import attach
    from ..stress import format_stress, stress

    doc = stress(
        engines=args.engine, cases=args.case, dt=args.dt, progress=log, budget_s=args.budget
    )
    emit(attach(doc, args), args.json, format_stress(doc, wide=args.wide))
    return 0
