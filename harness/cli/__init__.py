"""The `harness` command line.

One module per command: `register` adds its parser, `run` executes it.

Quiet by default: results on stdout, warnings on stderr; -v/--verbose (before or after
the command) adds progress and diagnostics on stderr.

Exit status: 0 done (also when the physics ends undecidable), 2 bad input (one line on
stderr), 1 internal failure.  With --json exactly one JSON document goes to stdout;
progress and logs go to stderr.
"""

from __future__ import annotations

import argparse
import sys
import traceback

from reference.scene import SceneError

from . import (
    analyze,
    bench,
    compare,
    engines,
    fidelity,
    figures,
    report,
    scenes,
    simulate,
    stress,
    sweep,
)
from .common import BadInput, Parser, add_verbose, configure_logging

COMMANDS = (
    scenes,
    engines,
    simulate,
    compare,
    bench,
    stress,
    fidelity,
    analyze,
    sweep,
    figures,
    report,
)


def build_parser() -> Parser:
    p = Parser(prog="harness", description=__doc__.splitlines()[0])
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


def main(argv: list[str] | None = None) -> int:
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        args = build_parser().parse_args(argv)
        args.argv = argv  # the exact command, for the results' provenance
        configure_logging(args.verbose)
        return args.func(args)
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
