"""The `harness` command line.

One module per command: `register` adds its parser, `run` executes it.

Exit status: 0 done (also when the physics ends undecidable, or the simulator failed:
the status says so), 2 bad input or an output that cannot be written (one line on
stderr: a scene, an argument, an output path, a full or closed stdout, memory exhausted),
1 internal failure (a traceback), 130 stopped by Ctrl-C (SIGINT), 143 terminated
(SIGTERM); a command that received a signal never exits 0 (harness.signals).  With
--json exactly one JSON document goes to stdout; progress and logs go to stderr.  Quiet
by default: results on stdout, warnings on stderr; -v/--verbose (before or after the
command) adds progress and diagnostics on stderr.  docs/inputs.md lists the accepted
ranges.
"""

from __future__ import annotations

import argparse
import errno
import os
import sys
import traceback

from reference.scene import SceneError

from .. import signals
from ..outputs import OutputError
from ..provenance import PACKAGE, PROGRAM, distribution_version
from ..signals import Terminated
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


SIGNAL_LINES = {
    signals.EXIT_INTERRUPTED: "harness: interrupted",
    signals.EXIT_TERMINATED: "harness: terminated",
}


class StdoutError(OSError):
    """Writing the results to stdout failed (a full device, a closed pipe)."""


class GuardedStdout:
    """sys.stdout while a command runs: an OSError of a write or flush becomes a
    StdoutError (exit status 2 with one line), distinct from the files a command writes."""

    def __init__(self, stream) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._open().write(text)
        except OSError as exc:
            raise StdoutError(exc.errno, exc.strerror or str(exc)) from None

    def flush(self) -> None:
        try:
            self._open().flush()
        except OSError as exc:
            raise StdoutError(exc.errno, exc.strerror or str(exc)) from None

    def _open(self):
        if self._stream is None:  # started with stdout closed: Python sets it to None
            raise StdoutError(errno.EBADF, "stdout is closed")
        return self._stream

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def main(argv: list[str] | None = None) -> int:
    stream = sys.stdout
    sys.stdout = GuardedStdout(stream)
    try:
        with signals.handled():
            return _signal_status(_main(argv))
    finally:
        sys.stdout = stream


def _signal_status(code: int) -> int:
    """The command's exit status, or its signal's when it received one: a SIGTERM or
    Ctrl-C swallowed on its way up (a finaliser's "Exception ignored") still ends the
    command with 143 or 130, never 0."""
    status = signals.exit_status()
    if status is None or code == status:
        return code
    print(SIGNAL_LINES[status], file=sys.stderr)
    return status


def _main(argv: list[str] | None) -> int:
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        args = build_parser(argv).parse_args(argv)
        args.argv = argv  # the exact command, for the results' provenance
        configure_logging(args.verbose)
        code = args.func(args)
        sys.stdout.flush()  # a full device shows here, not at exit
        return code
    except StdoutError as exc:
        _silence_stdout()
        print(f"harness: error: cannot write to stdout: {exc.strerror}", file=sys.stderr)
        return 2
    except (BadInput, SceneError, OutputError) as exc:
        print(f"harness: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except SystemExit as exc:  # --help, --version: argparse exits
        return exc.code if isinstance(exc.code, int) else 0
    except Terminated:
        print(SIGNAL_LINES[signals.EXIT_TERMINATED], file=sys.stderr)
        return signals.EXIT_TERMINATED
    except KeyboardInterrupt:
        status = signals.exit_status() or signals.EXIT_INTERRUPTED
        print(SIGNAL_LINES[status], file=sys.stderr)
        return status
    except Exception as exc:
        lack = memory_exhaustion(exc)
        if lack is not None:
            detail = f": {one_line(str(lack))}" if str(lack) else ""
            print(f"harness: error: out of memory{detail}; nothing written", file=sys.stderr)
            return 2
        traceback.print_exc()
        print("harness: internal failure (traceback above)", file=sys.stderr)
        return 1


# what the loader (dlopen) and the C library say when memory or address space runs out
_NO_MEMORY_TEXTS = ("failed to map segment", "cannot allocate memory")


def memory_exhaustion(exc: BaseException) -> BaseException | None:
    """The exception in `exc`'s chain of causes that says memory ran out, or None: a
    MemoryError (pyarrow's ArrowMemoryError too), or an OSError with errno ENOMEM or the
    loader unable to map a shared library into the address space (`ulimit -v`).  A
    library that fails to load this way is often reported by its importer as another
    OSError ("could not find/load …") raised while handling the first."""
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        seen.add(id(cause))
        text = str(cause).lower()
        if isinstance(cause, MemoryError) or (
            isinstance(cause, OSError)
            and (cause.errno == errno.ENOMEM or any(t in text for t in _NO_MEMORY_TEXTS))
        ):
            return cause
        cause = cause.__cause__ or cause.__context__
    return None


def _silence_stdout() -> None:
    """After stdout failed: point its descriptor at /dev/null, so that the interpreter's
    own flush at exit has nothing to complain about."""
    try:
        fd = sys.__stdout__.fileno()
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, fd)
        os.close(null)
    except (OSError, ValueError, AttributeError):
        pass


def one_line(text: str) -> str:
    """A message as one line (a TOML error may quote the offending line)."""
    return terminal_safe(" ".join(text.split()))


if __name__ == "__main__":
    sys.exit(main())
