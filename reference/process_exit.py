"""Ending a process without Python's teardown: the set-up's steps (`make setup`: the
core's build, `reference.core.aot`; the warm-ups, `reference.warm`, `tests.warm_mjx`,
`tests.warm_bytecode`) and the tests' workers (tests/conftest.py).

Each is a process that has loaded numba's and LLVM's state (the build: the whole
core's), JAX's, Drake's or ~3,000 modules, and has written all it makes (a worker: sent
its results) by the time it ends.  Python's teardown of that state took 2 s after the
build, 1 s after the bytecode's warm-up and 0.6 s after MJX's, on the set-up's two
longest paths, and 1.6 s at the end of the tests, which wait for their last worker."""

from __future__ import annotations

import os
import sys


def exit_now(status: int) -> None:
    """Flush stdout and stderr, then end the process with `status` (os._exit: no
    teardown, no atexit handlers).  Only for a process whose files are all closed."""
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
