"""Importing a library that prints a banner from C (PyBullet: "pybullet build time: …")
without letting it into the user's terminal or a `--json` document.

Python's `contextlib.redirect_stdout` only swaps `sys.stdout`; a C library writes to file
descriptors 1 and 2 directly, so they are pointed at a temporary file for the duration
of the import (`os.dup2`) and restored afterwards.  What was printed is passed on to the
`engines` logger at INFO level, so `harness -v` still shows it.
"""

from __future__ import annotations

import importlib
import logging
import os
import sys
import tempfile
from types import ModuleType

LOG = logging.getLogger("engines")


def quiet_import(name: str, fds: tuple[int, ...] = (1, 2)) -> ModuleType:
    """`importlib.import_module(name)` with file descriptors `fds` sent to a temporary
    file while it runs; the captured text goes to the `engines` logger."""
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    with tempfile.TemporaryFile() as sink:
        saved = [os.dup(fd) for fd in fds]
        try:
            for fd in fds:
                os.dup2(sink.fileno(), fd)
            module = importlib.import_module(name)
        finally:
            for fd, copy in zip(fds, saved, strict=True):
                os.dup2(copy, fd)
                os.close(copy)
        sink.seek(0)
        text = sink.read().decode(errors="replace").strip()
    if text:
        LOG.info("%s: %s", name, text)
    return module
