"""The `harness` command line (CONTRACT.md).

Exit status: 0 done (also when the physics ends undecidable), 2 bad input (one line on
stderr), 1 internal failure.  With --json exactly one JSON document goes to stdout;
progress and logs go to stderr.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import traceback
from pathlib import Path
from typing import Any

from reference.scene import SceneError


class BadInput(Exception):
    """Raised for user errors: printed as one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one clear line, exit 2
        raise BadInput(f"{self.prog}: {message}")


def _positive_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(x) and x > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return x


def _fraction(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(x) and 0 <= x <= 1):
        raise argparse.ArgumentTypeError(f"must be in [0, 1], got {text!r}")
    return x


def _grid(text: str) -> tuple[float, float, int]:
    """A:B:K, K values from A to B inclusive."""
    parts = text.split(":")
    try:
        if len(parts) == 1:
            a = float(parts[0])
            return a, a, 1
        if len(parts) != 3:
            raise ValueError
        a, b, k = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected A:B:K, got {text!r}") from None
    if k < 1 or not (math.isfinite(a) and math.isfinite(b)):
        raise argparse.ArgumentTypeError(f"expected A:B:K with K >= 1, got {text!r}")
    return a, b, k


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="harness", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    sub.add_parser("scenes", help="list built-in scenes")

    s = sub.add_parser("simulate", help="one run of one simulator")
    s.add_argument("scene")
    s.add_argument("--engine", default="reference")
    s.add_argument("--dt", type=_positive_float)
    s.add_argument("--t-end", type=_positive_float)
    s.add_argument("--scale", type=_positive_float)
    s.add_argument("--record", metavar="FILE.rrd")
    s.add_argument("--out", metavar="FILE.parquet")
    s.add_argument("--json", action="store_true")

    c = sub.add_parser("compare", help="reference against the named simulators")
    c.add_argument("scene")
    c.add_argument("--engine", action="append", required=True)
    c.add_argument("--dt", type=_positive_float, action="append")
    c.add_argument("--t-end", type=_positive_float)
    c.add_argument("--scale", type=_positive_float)
    c.add_argument("--record", metavar="FILE.rrd")
    c.add_argument("--json", action="store_true")

    b = sub.add_parser("bench", help="speed against error (work-precision)")
    b.add_argument("scene")
    b.add_argument("--engine", action="append")
    b.add_argument("--dt", type=_positive_float, action="append")
    b.add_argument("--t-end", type=_positive_float)
    b.add_argument("--repeats", type=int, default=3)
    b.add_argument("--json", action="store_true")
    b.add_argument("--plot", metavar="FILE.png")
    b.add_argument("--out", metavar="FILE.json")
    b.add_argument("--budget", type=_positive_float, default=60.0, help="seconds per setting")

    st = sub.add_parser("stress", help="hard-case suite, a verdict per case and engine")
    st.add_argument("--engine", action="append")
    st.add_argument("--case", action="append")
    st.add_argument("--dt", type=_positive_float)
    st.add_argument("--budget", type=_positive_float, default=30.0, help="seconds per run")
    st.add_argument("--json", action="store_true")

    a = sub.add_parser("analyze", help="analyses of the linearised model")
    asub = a.add_subparsers(dest="analysis", required=True, parser_class=_Parser)
    for name in ("selfsimilar", "chatter"):
        x = asub.add_parser(name)
        x.add_argument("--n", type=int, required=True)
        x.add_argument("--gyration", type=_positive_float, required=True)
        x.add_argument("--restitution", type=_fraction, required=True)
        x.add_argument("--json", action="store_true")

    sw = sub.add_parser("sweep", help="parameter sweeps")
    swsub = sw.add_subparsers(dest="sweep", required=True, parser_class=_Parser)
    e = swsub.add_parser("exponent", help="energy-exponent map over (gamma, rho)")
    e.add_argument("--n", type=int, default=3)
    e.add_argument("--gyration", type=_grid, required=True)
    e.add_argument("--restitution", type=_grid, required=True)
    e.add_argument("--samples", type=int, default=100)
    e.add_argument("--seed", type=int, default=0)
    e.add_argument("--engine", default="linear")
    e.add_argument("--dt", type=_positive_float)
    e.add_argument("--executor", choices=("local", "dask"), default="local")
    e.add_argument("--scheduler")
    e.add_argument("--workers", type=int)
    e.add_argument("--t-end", type=_positive_float, help="cap the run length (non-linear engines)")
    e.add_argument("--chunk-size", type=int, help="runs per task (default 25 linear, 1 others)")
    e.add_argument("--out", required=True)
    e.add_argument("--json", action="store_true")

    f = sub.add_parser("figures", help="the paper's figures as PNGs")
    f.add_argument("--out", default="figures")
    f.add_argument("--json", action="store_true")
    return p


def emit(doc: Any, as_json: bool, text: str) -> None:
    if as_json:
        json.dump(doc, sys.stdout, indent=None, allow_nan=False, default=_default)
        sys.stdout.write("\n")
    else:
        print(text)


def _default(x: Any) -> Any:
    import numpy as np

    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    raise TypeError(f"not JSON serialisable: {type(x)}")


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------- commands


def cmd_scenes(args) -> int:
    from .scenes import list_builtin

    for name, desc in list_builtin():
        print(f"{name:24s} {desc}")
    return 0


def _load(args):
    from .scenes import resolve_scene

    scene = resolve_scene(args.scene)
    if getattr(args, "scale", None) is not None:
        scene = scene.scaled(args.scale)
    return scene


def cmd_simulate(args) -> int:
    from .simulators import check_engine, run_simulator
    from .text import format_simulate

    check_engine(args.engine)
    scene = _load(args)
    traj = run_simulator(args.engine, scene, dt=args.dt, t_end=args.t_end)
    if args.out:
        from .io import write_trajectory_parquet

        write_trajectory_parquet(traj, args.out)
        log(f"wrote {args.out}")
    if args.record:
        from .recording import record_trajectories

        path = record_trajectories([traj], args.record, scene=scene)
        log(f"wrote {path}")
    doc = traj.summary(with_impacts=True)
    emit(_finite(doc), args.json, format_simulate(traj))
    return 0


def cmd_compare(args) -> int:
    from .compare import compare, format_compare
    from .simulators import check_engine

    for e in args.engine:
        check_engine(e)
    scene = _load(args)
    result = compare(scene, args.engine, dts=args.dt, t_end=args.t_end, progress=log)
    if args.record:
        from .recording import record_trajectories

        runs = [r.trajectory for r in result.runs if r.trajectory.n_samples > 0]
        skipped = len(result.runs) - len(runs)
        if skipped:
            log(f"recording leaves out {skipped} run(s) that produced no samples")
        path = record_trajectories([result.reference, *runs], args.record, scene=scene)
        log(f"wrote {path}")
    emit(_finite(result.to_dict()), args.json, format_compare(result))
    return 0


def cmd_bench(args) -> int:
    from .bench import bench, format_bench

    scene = _load(args)
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
    if args.out:
        Path(args.out).write_text(json.dumps(_finite(doc), indent=1))
    emit(_finite(doc), args.json, format_bench(doc))
    return 0


def cmd_stress(args) -> int:
    from .stress import format_stress, stress

    doc = stress(
        engines=args.engine, cases=args.case, dt=args.dt, progress=log, budget_s=args.budget
    )
    emit(_finite(doc), args.json, format_stress(doc))
    return 0


def cmd_analyze(args) -> int:
    if args.n < 2:
        raise BadInput(f"--n must be >= 2, got {args.n}")
    if args.analysis == "selfsimilar":
        from reference.linear.selfsimilar import analyze_selfsimilar, format_selfsimilar

        doc = analyze_selfsimilar(args.n, args.gyration, args.restitution)
        emit(_finite(doc), args.json, format_selfsimilar(doc))
    else:
        from reference.linear.chatter import analyze_chatter, format_chatter

        doc = analyze_chatter(args.n, args.gyration, args.restitution)
        emit(_finite(doc), args.json, format_chatter(doc))
    return 0


def cmd_sweep(args) -> int:
    from .sweep import run_exponent_sweep

    doc = run_exponent_sweep(args, progress=log)
    emit(_finite(doc), args.json, doc.get("text", json.dumps(_finite(doc), indent=1)))
    return 0


def cmd_figures(args) -> int:
    from .figures import make_figures

    doc = make_figures(Path(args.out), progress=log)
    emit(_finite(doc), args.json, "\n".join(f"{k}: {v}" for k, v in doc.items()))
    return 0


def _finite(x: Any) -> Any:
    """JSON has no NaN/inf: map them to null."""
    import numpy as np

    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, np.ndarray):
        return _finite(x.tolist())
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


COMMANDS = {
    "scenes": cmd_scenes,
    "simulate": cmd_simulate,
    "compare": cmd_compare,
    "bench": cmd_bench,
    "stress": cmd_stress,
    "analyze": cmd_analyze,
    "sweep": cmd_sweep,
    "figures": cmd_figures,
}


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
        return COMMANDS[args.command](args)
    except (BadInput, SceneError) as exc:
        print(f"harness: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("harness: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    except Exception:
        traceback.print_exc()
        print("harness: internal failure (traceback above)", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
