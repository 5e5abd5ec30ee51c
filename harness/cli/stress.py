"""`harness stress`: the hard-case suite, a verdict per case and simulator."""

from __future__ import annotations

from .common import emit, log, positive_float


def register(sub) -> None:
    st = sub.add_parser("stress", help="hard-case suite, a verdict per case and engine")
    st.add_argument("--engine", action="append")
    st.add_argument("--case", action="append")
    st.add_argument("--dt", type=positive_float)
    st.add_argument("--budget", type=positive_float, default=30.0, help="seconds per run")
    st.add_argument("--json", action="store_true")
    st.set_defaults(func=run)


def run(args) -> int:
    from ..provenance import attach
    from ..stress import format_stress, stress

    doc = stress(
        engines=args.engine, cases=args.case, dt=args.dt, progress=log, budget_s=args.budget
    )
    emit(attach(doc, args), args.json, format_stress(doc))
    return 0
