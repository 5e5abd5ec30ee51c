"""How the harness starts a child process (the sweep's pool, an engine run stopped at a
hard cap): by fork, so that the child shares the parent's imports and compiled code,
unless the platform cannot fork or a runtime that starts threads at import is loaded in
this process.  A process forked then may deadlock on a lock that one of the parent's
threads held at the fork (JAX warns so at the fork; docs/engines.md, "MJX", has the
measured case).  Such a child is spawned instead: it imports and compiles what it needs
itself, and what it runs must be picklable."""

from __future__ import annotations

import sys

# runtimes that start thread pools at import
THREADED_RUNTIMES = ("jax",)


def start_method(methods: list[str]) -> str:
    """'fork' unless the platform lacks it (`methods`: multiprocessing's start methods)
    or a threaded runtime is loaded in this process; then 'spawn'."""
    threaded = any(name in sys.modules for name in THREADED_RUNTIMES)
    return "fork" if "fork" in methods and not threaded else "spawn"
