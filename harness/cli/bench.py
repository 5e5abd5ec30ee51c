"""`harness bench`: speed against error (work-precision)."""

from __future__ import annotations

import json
from pathlib import Path

from .common import emit, finite, load_scene_arg, log, positive_float


def register(sub) -> None:
    b = sub.add_parser("bench", help="speed against error (work-precision)")
    b.add_argument("scene")
    b.add_argument("--engine", action="append")
    b.add_argument("--dt", type=positive_float, action="append")
    b.add_argument("--t-end", type=positive_float)
    b.add_argument("--repeats", type=int, default=3)
    b.add_argument("--json", action="store_true")
    b.add_argument("--plot", metavar="FILE.png")
    b.add_argument("--out", metavar="FILE.json")
    b.add_argument("--budget", type=positive_float, default=60.0, help="seconds per setting")
    b.set_defaults(func=run)


def run(args) -> int:
    from ..bench import bench, format_bench
    from ..provenance import attach

    scene = load_scene_arg(args)
    doc = bench(
        scene,
        engines=args.engine,
        dts=args.dt,
        t_end=args.t_end,
        repeats=args.repeats,
        plot=args.plot,
        progress=log,
        budget_s=args.budget,
    )
    attach(doc, args)
    if args.out:
        Path(args.out).write_text(json.dumps(finite(doc), indent=1))
    emit(doc, args.json, format_bench(doc))
    return 0
