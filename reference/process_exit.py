"""Ending a set-up step's process without Python's teardown (`make setup`: the core's
build, `reference.core.aot`; the warm-ups, `reference.warm`, `tests.warm_mjx`,
`tests.warm_bytecode`).

Each step is a short-lived process that has loaded numba's and LLVM's state (the build:
the whole core's), JAX's, or ~3,000 modules, and has written all it makes by the time
its `main` returns.  Python's teardown of that state took 2 s after the build, 1 s after
the bytecode's warm-up and 0.6 s after MJX's, on the set-up's two longest paths."""

from __future__ import annotations

import os
import sys


def exit_now(status: int) -> None:
    """Flush stdout and stderr, then end the process with `status` (os._exit: no
    teardown, no atexit handlers).  Only for a process whose files are all closed."""
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
