"""The `harness` command line.

One module per command: `register` adds its parser, `run` executes it.

Exit status: 0 done (also when the physics ends undecidable, or the simulator failed:
the status says so), 2 bad input (one line on stderr: a scene, an argument or an output
path), 1 internal failure (a traceback), 130 stopped by Ctrl-C.  With --json exactly one
JSON document goes to stdout; progress and logs go to stderr.  Quiet by default:
results on stdout, warnings on stderr; -v/--verbose (before or after the command) adds
progress and diagnostics on stderr.  docs/inputs.md lists the
accepted ranges.
"""

from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import threading
import traceback

from reference.scene import SceneError

from ..outputs import OutputError
from ..provenance import PACKAGE, PROGRAM, distribution_version
from ..text import terminal_safe
from . import (
    analyze,
    bench,
    branches,
    compare,
    engines,
    fidelity,
    figures,
    report,
    restitution,
    scenes,
    simulate,
    stress,
    sweep,
    transition,
)
from .common import BadInput, Parser, add_verbose, configure_logging

COMMANDS = (
    scenes,
    engines,
    simulate,
    compare,
    branches,
    bench,
    stress,
    fidelity,
    restitution,
    analyze,
    sweep,
    figures,
    report,
    transition,
)


def build_parser() -> Parser:
    p = Parser(prog=PROGRAM, description=__doc__.splitlines()[0])
    p.add_argument(
        "--version", action="version", version=f"{PROGRAM} {distribution_version(PACKAGE)}"
    )
    add_verbose(p, top=True)
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for command in COMMANDS:
        command.register(sub)
    for parser in _subparsers(p):
        add_verbose(parser)
    return p


def _subparsers(parser: argparse.ArgumentParser) -> list[argparse.ArgumentParser]:
    """Every sub-command parser below `parser`, nested ones included."""
    found = []
    for action in parser._actions:  # argparse keeps sub-commands only here
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                found += [child, *_subparsers(child)]
    return found


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that every cleanup runs (temporary files removed,
    pools shut down); the command exits 143."""


def _terminate(signum, frame) -> None:
    raise Terminated


@contextlib.contextmanager
def _sigterm_as_interrupt():
    """SIGTERM raises Terminated while the command runs (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def main(argv: list[str] | None = None) -> int:
    with _sigterm_as_interrupt():
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        args = build_parser().parse_args(argv)
        args.argv = argv  # the exact command, for the results' provenance
        configure_logging(args.verbose)
        return args.func(args)
    except (BadInput, SceneError, OutputError) as exc:
        print(f"harness: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except SystemExit as exc:  # --help, --version: argparse exits
        return exc.code if isinstance(exc.code, int) else 0
    except Terminated:
        print("harness: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("harness: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    except Exception:
        traceback.print_exc()
        print("harness: internal failure (traceback above)", file=sys.stderr)
        return 1


def one_line(text: str) -> str:
    """A message as one line (a TOML error may quote the offending line)."""
    return terminal_safe(" ".join(text.split()))


if __name__ == "__main__":
    sys.exit(main())
