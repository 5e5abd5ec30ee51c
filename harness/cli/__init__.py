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


def build_parser(argv: list[str] | None = None) -> Parser:
    """The command line's parser.  With `argv`, only the command it names is built in
    full; every other one is its name and help (enough for `harness --help` and for
    argparse to name the choices), so that a command's start-up does not import the
    modules behind the other commands' options and defaults."""
    p = Parser(prog=PROGRAM, description=__doc__.splitlines()[0])
    p.add_argument("--version", action=VersionAction)
    add_verbose(p, top=True)
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser, metavar="COMMAND")
    wanted = _command_named(argv)
    for command in COMMANDS:
        try:
            command.register(_Only(sub, wanted))
        except _Listed:
            pass
    for parser in _subparsers(p):
        add_verbose(parser)
    return p


class VersionAction(argparse.Action):
    """--version: prints 'harness X.Y.Z' (the installed distribution's version, looked up
    only when asked) and exits."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, **kwargs):
        kwargs.setdefault("help", "show the program's version and exit")
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"{PROGRAM} {distribution_version(PACKAGE)}")
        parser.exit()


class _Listed(Exception):
    """A command registered by name and help only (build_parser)."""


class _Only:
    """The sub-command action `register` sees: the command `wanted` (every one when None)
    is added in full, any other one by its name and help, after which its `register`
    stops (_Listed)."""

    def __init__(self, sub, wanted: str | None) -> None:
        self.sub, self.wanted = sub, wanted

    def add_parser(self, name: str, **kwargs):
        if self.wanted is None or name == self.wanted:
            return self.sub.add_parser(name, **kwargs)
        self.sub.add_parser(name, help=kwargs.get("help"))
        raise _Listed


def _command_named(argv: list[str] | None) -> str | None:
    """The command argv names (its first word that is not an option), None without one."""
    words = [a for a in argv or [] if not a.startswith("-")]
    return words[0] if words else None


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
        args = build_parser(argv).parse_args(argv)
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
