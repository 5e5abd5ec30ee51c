"""What every command shares: the parser, argument types with their ranges, the options
several commands take, JSON/text output, stderr logging and progress.

Numbers on the command line are checked here, at the edge, against the same ranges as
scene files (reference.scene; docs/inputs.md): a bad value is one line and exit status 2
before any work starts.
"""

from __future__ import annotations

import argparse
import logging
import math
import re
import sys
import textwrap
from typing import Any

from reference.scene import DIMENSION_RANGE, GYRATION_RANGE, MAX_VERTICES, SCALE_RANGE

from ..io import json_safe, json_text  # noqa: F401 (json_text re-exported)
from ..progress import LOGGERS  # ours: INFO with -v/--verbose
from ..text import terminal_safe

# A number that starts with '-' (also -1e-3, -.5, -inf, -nan): argparse must read it as a
# value, never as an option.  argparse decides with its parser attribute
# `_negative_number_matcher` (Python 3.11: only '-1' and '-1.5'; 3.12+: anything starting
# '-.d' or '-d'); setting it to this pattern gives every version the same behaviour, and
# tests/test_cli_inputs.py checks `--dt -1e-3` gives "must be > 0".
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.I)


class BadInput(Exception):
    """Raised for user errors: printed as one line, exit status 2."""


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Options' help with their default appended (when there is a meaningful one);
    description and epilog printed as given (Parser wraps the description)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if (
            "%(default)" not in text
            and action.option_strings
            and not any(default is x for x in (None, False, argparse.SUPPRESS))
            and not isinstance(default, list)
        ):
            text += " (default: %(default)s)"
        return text


class Parser(argparse.ArgumentParser):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        if kwargs.get("description"):  # wrapped here: the epilog (legends) stays as written
            kwargs["description"] = textwrap.fill(" ".join(kwargs["description"].split()), 88)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message: str) -> None:  # one clear line, exit 2
        """main() prints `harness: error: …`: the message names the sub-command (`simulate:
        …`), not the program a second time."""
        command = self.prog.partition(" ")[2]
        raise BadInput(f"{command}: {message}" if command else message)


# ----------------------------------------------------------------------------- types


def _float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None


def positive_float(text: str) -> float:
    x = _float(text)
    if not (math.isfinite(x) and x > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return x


def float_in(lo: float, hi: float, what: str = "a number"):
    """An argparse type: a finite float in [lo, hi]."""

    def parse(text: str) -> float:
        x = _float(text)
        if lo > 0 and not x > 0:
            raise argparse.ArgumentTypeError(f"must be > 0, got {text!r}")
        if not (math.isfinite(x) and lo <= x <= hi):
            raise argparse.ArgumentTypeError(f"must be {what} in [{lo:g}, {hi:g}], got {text!r}")
        return x

    parse.__name__ = what
    return parse


def int_in(lo: int, hi: int):
    """An argparse type: an integer in [lo, hi] ('2e7' is read as 20000000)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            x = _float(text)
            if not (math.isfinite(x) and x == int(x)):
                raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
            value = int(x)
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"must be an integer in [{lo}, {hi}], got {text!r}")
        return value

    parse.__name__ = "integer"
    return parse


def fraction(text: str) -> float:
    x = _float(text)
    if not (math.isfinite(x) and 0 <= x <= 1):
        raise argparse.ArgumentTypeError(f"must be in [0, 1], got {text!r}")
    return x


# the command line's quantities, with the ranges of reference.scene
duration = float_in(*DIMENSION_RANGE, what="a duration [s]")
timestep = float_in(*DIMENSION_RANGE, what="a timestep [s]")
scale = float_in(*SCALE_RANGE, what="a scale factor")
gyration = float_in(*GYRATION_RANGE, what="a radius of gyration")
vertices = int_in(2, MAX_VERTICES)
budget = float_in(1e-3, 1e7, what="a time budget [s]")
# the largest K of a sweep's A:B:K (one axis); the runs of a sweep are capped as well
MAX_GRID_POINTS = 10_000


def grid(text: str) -> tuple[float, float, int]:
    """A:B:K, K values from A to B inclusive (a single number A: A alone)."""
    parts = text.split(":")
    try:
        if len(parts) == 1:
            a = float(parts[0])
            a_b_k = (a, a, 1)
        elif len(parts) == 3:
            a_b_k = (float(parts[0]), float(parts[1]), int(parts[2]))
        else:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected A:B:K (K an integer), got {text!r}") from None
    a, b, k = a_b_k
    if not (math.isfinite(a) and math.isfinite(b)):
        raise argparse.ArgumentTypeError(f"A and B must be finite, got {text!r}")
    if not 1 <= k <= MAX_GRID_POINTS:
        raise argparse.ArgumentTypeError(f"K must be in [1, {MAX_GRID_POINTS}], got {text!r}")
    return a_b_k


# ----------------------------------------------------------------------------- options


def add_scene(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", help="a scene file (TOML) or the name of a built-in scene")


def add_json(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print exactly one JSON document on stdout")


def add_force(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--force",
        action="store_true",
        help="replace output files that exist (never an input file)",
    )


def add_t_end(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--t-end",
        type=duration,
        metavar="T",
        help="simulated time [s], in [1e-50, 1e50] (default: the scene's run.t_end)",
    )


def add_engine(p: argparse.ArgumentParser, many: str | None = None, **kw: Any) -> None:
    """--engine E; `many`: it may be repeated, and what happens without it."""
    text = "simulator: reference, linear, mujoco, pybullet, ... (`harness engines` lists them)"
    if many is not None:
        kw.setdefault("action", "append")
        text += f"; repeat for several ({many})"
    else:
        kw.setdefault("default", "reference")
    p.add_argument("--engine", metavar="E", help=text, **kw)


def add_dt(p: argparse.ArgumentParser, many: str | None = None) -> None:
    """--dt DT; `many`: it may be repeated, and what happens without it."""
    text = "timestep of fixed-step engines [s], > 0 and <= t_end; event-driven simulators "
    if many is not None:
        text += f"ignore it; repeat for several ({many})"
        p.add_argument("--dt", type=timestep, metavar="DT", action="append", help=text)
    else:
        text += "ignore it (default: 1e-4)"
        p.add_argument("--dt", type=timestep, metavar="DT", help=text)


def add_wide(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--wide",
        action="store_true",
        help="every column in the terminal table (wider than 100 characters)",
    )


def add_scale(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--scale",
        type=scale,
        metavar="EPS",
        help="scale the linear initial coordinates, q by EPS^2 and p by EPS (scenes "
        "given by q and p; EPS in [1e-50, 1e50])",
    )


def add_impact_law(p: argparse.ArgumentParser) -> None:
    """--impact-law NAME and --simultaneity-window T: how the reference resolves contacts
    touching together (docs/architecture.md, "Impact laws"); default: the scene's."""
    from reference.core.laws import LAW_NAMES, law_help

    p.add_argument(
        "--impact-law",
        choices=LAW_NAMES,
        metavar="NAME",
        help=f"impact law of simultaneous impacts in the reference ({law_help()}; "
        "default: the scene's impact_law, else paper)",
    )
    p.add_argument(
        "--simultaneity-window",
        type=float_in(0.0, 1e50, what="a time window [s]"),
        metavar="T",
        help="contacts reaching the ground within T of each other are one simultaneous "
        "impact under every law; at most the motion's time unit sqrt(a/g) (t_end without "
        "gravity), the time of a contact's own bounce, beyond which later bounces merge "
        "(default: the scene's, else 0: strictly sequential)",
    )


def add_max_steps(p: argparse.ArgumentParser) -> None:
    from ..simulators import DEFAULT_MAX_STEPS

    p.add_argument(
        "--max-steps",
        type=int_in(1, 10**12),
        default=DEFAULT_MAX_STEPS,
        metavar="N",
        help="most steps a fixed-step engine may take (t_end / dt); a longer run is "
        "refused before it starts",
    )


# ----------------------------------------------------------------------------- output


def add_horizon(p: argparse.ArgumentParser) -> None:
    """--horizon-runs, --horizon-seed: the ensembles of the horizon verdict
    (harness.horizon; docs/fidelity.md, "Horizon")."""
    from ..horizon.settings import DEFAULT_RUNS, DEFAULT_SEED

    p.add_argument(
        "--horizon-runs",
        type=int_in(0, 10_000),
        default=DEFAULT_RUNS,
        metavar="N",
        help="members of each horizon ensemble (reference runs: grid model at the run's dt, "
        "perturbed at its own error, perturbed at 1e-8 for the growth per impact); 0: no "
        "horizon verdict",
    )
    p.add_argument(
        "--horizon-seed",
        type=int_in(0, 2**63 - 1),
        default=DEFAULT_SEED,
        metavar="SEED",
        help="seed of the horizon ensembles (a member depends only on it and its number)",
    )


def emit(doc: Any, as_json: bool, text: str) -> None:
    """Exactly one JSON document on stdout with --json, else the text."""
    if as_json:
        sys.stdout.write(json_text(doc) + "\n")
    else:
        print(terminal_safe(text))


class SafeFormatter(logging.Formatter):
    """Log lines with control characters escaped (harness.text.terminal_safe)."""

    def format(self, record: logging.LogRecord) -> str:
        return terminal_safe(super().format(record))


def configure_logging(verbose: bool) -> None:
    """Our loggers write bare lines to stderr: warnings always, progress (INFO) only with
    -v/--verbose.  Third-party loggers keep Python's default (warnings and above)."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(SafeFormatter("%(message)s"))
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
    print(terminal_safe(msg), file=sys.stderr, flush=True)


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


# JSON has no NaN/inf: the one mapping lives in harness.io
finite = json_safe


class StepProgress:
    """`progress(done, total)` for long fixed-step runs: a tqdm bar on stderr when it is a
    terminal, else plain lines (harness.progress.PlainProgress: the first after 5 s, then
    every 15 s, with the steps done and an estimate of the time left)."""

    def __init__(self, label: str) -> None:
        self.label = label
        self.bar = None

    def __call__(self, done: int, total: int) -> None:
        if self.bar is None:
            self.bar = self._bar(total)
        self.bar.update(done - self.bar.n)

    def _bar(self, total: int):
        from ..progress import PlainProgress

        if not sys.stderr.isatty():
            return PlainProgress(total, self.label, unit="step")
        from tqdm import tqdm

        return tqdm(
            total=total,
            desc=self.label,
            unit="step",
            unit_scale=True,
            file=sys.stderr,
            mininterval=0.5,
            dynamic_ncols=True,
        )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def load_scene_arg(args):
    """The SCENE argument (a file, a built-in name, or one of `branches --suite`'s
    landings, which start on several contacts), with --scale applied (the scaled scene
    passes the same checks as a scene file, below-ground included)."""
    from pathlib import Path

    from ..branches.suite import LANDINGS, landing
    from ..scenes import resolve_scene

    if args.scene in LANDINGS and not Path(args.scene).exists():
        scene = landing(args.scene)
    else:
        scene = resolve_scene(args.scene)
    if getattr(args, "scale", None) is not None:
        scene = scene.scaled(args.scale)
    return with_impact_law_args(scene, args)


def with_impact_law_args(scene, args):
    """The scene with --impact-law / --simultaneity-window applied (when given)."""
    return scene.with_impact_law(
        getattr(args, "impact_law", None), getattr(args, "simultaneity_window", None)
    )


def scene_inputs(args) -> list:
    """The file the SCENE argument names (to keep outputs off it), if any."""
    from ..scenes import scene_file

    path = scene_file(args.scene)
    return [path] if path is not None else []
