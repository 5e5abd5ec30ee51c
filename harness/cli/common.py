"""What every command shares: argument types, JSON/text output, stderr logging."""

from __future__ import annotations

import argparse
import json
import logging
import math
import sys
from typing import Any

from ..progress import LOGGERS  # ours: INFO with -v/--verbose


class BadInput(Exception):
    """Raised for user errors: printed as one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one clear line, exit 2
        raise BadInput(f"{self.prog}: {message}")


def positive_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(x) and x > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return x


def fraction(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(x) and 0 <= x <= 1):
        raise argparse.ArgumentTypeError(f"must be in [0, 1], got {text!r}")
    return x


def grid(text: str) -> tuple[float, float, int]:
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


def emit(doc: Any, as_json: bool, text: str) -> None:
    """Exactly one JSON document on stdout with --json, else the text."""
    if as_json:
        json.dump(finite(doc), sys.stdout, indent=None, allow_nan=False)
        sys.stdout.write("\n")
    else:
        print(text)


def configure_logging(verbose: bool) -> None:
    """Our loggers write bare lines to stderr: warnings always, progress (INFO) only with
    -v/--verbose.  Third-party loggers keep Python's default (warnings and above)."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(message)s"))
    for name in LOGGERS:
        logger = logging.getLogger(name)
        logger.handlers[:] = [handler]
        logger.setLevel(logging.INFO if verbose else logging.WARNING)
        logger.propagate = False


def log(msg: str) -> None:
    """Progress and diagnostics: stderr, shown with -v/--verbose."""
    logging.getLogger("harness").info(msg)


def note(msg: str) -> None:
    """What the user must see whatever the verbosity (a file written, a run left out):
    one line on stderr."""
    print(msg, file=sys.stderr, flush=True)


def add_verbose(parser: argparse.ArgumentParser, top: bool = False) -> None:
    """-v/--verbose on a parser.  Sub-commands take it too (`harness compare X -v`), with
    no default of their own so that they do not reset the top-level flag."""
    parser.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        default=False if top else argparse.SUPPRESS,
        help="show progress and diagnostics on stderr",
    )


def finite(x: Any) -> Any:
    """JSON has no NaN/inf: map them to null (numpy scalars and arrays to Python)."""
    import numpy as np

    if isinstance(x, dict):
        return {k: finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [finite(v) for v in x]
    if isinstance(x, np.ndarray):
        return finite(x.tolist())
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def load_scene_arg(args):
    """The SCENE argument (a file or a built-in name), with --scale applied."""
    from ..scenes import resolve_scene

    scene = resolve_scene(args.scene)
    if getattr(args, "scale", None) is not None:
        scene = scene.scaled(args.scale)
    return scene
