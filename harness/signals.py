"""SIGINT and SIGTERM at the command line's edge: each raises its own exception in the
main thread, and each is remembered, so that a command ends with its signal's exit
status (130, 143) even when the exception was swallowed on its way up.

Python delivers a signal by raising from its handler wherever the main thread is; when
that is a finaliser or a weak-reference callback (a figure's `WeakKeyDictionary`, a
thread pool's shutdown), the interpreter prints "Exception ignored in ..." and goes on.
`received()` remembers the signal regardless: `harness.cli.main` turns any exit status
into the signal's, and `harness.outputs` moves no finished file into place after one
(`raise_if_received`), so a terminated command never ends with exit status 0 and never
writes a result after it was told to stop.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

# exit statuses: 128 + the signal's number (the shell's convention)
EXIT_INTERRUPTED = 128 + signal.SIGINT  # 130
EXIT_TERMINATED = 128 + signal.SIGTERM  # 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that every cleanup runs (temporary files removed,
    pools shut down); the command exits 143.  `reason` names it in a run's message."""

    reason = "terminated (SIGTERM)"


_received: list[int] = []


def received() -> int | None:
    """The first signal received while `handled` was active (None: none)."""
    return _received[0] if _received else None


def exit_status() -> int | None:
    """The exit status of the signal received (130, 143), None without one."""
    sig = received()
    if sig is None:
        return None
    return EXIT_TERMINATED if sig == signal.SIGTERM else EXIT_INTERRUPTED


def exception() -> KeyboardInterrupt:
    """The exception of the signal received (Terminated or KeyboardInterrupt)."""
    return Terminated() if received() == signal.SIGTERM else KeyboardInterrupt()


def raise_if_received() -> None:
    """Raise the received signal's exception again (a signal already delivered and
    swallowed must still stop what follows, e.g. moving a file into place)."""
    if received() is not None:
        raise exception()


def _on_sigterm(signum, frame) -> None:
    _received.append(signum)
    raise Terminated


def _on_sigint(signum, frame) -> None:
    _received.append(signum)
    raise KeyboardInterrupt


@contextlib.contextmanager
def deferred() -> Iterator[None]:
    """SIGINT and SIGTERM deferred while the block runs and delivered right after it, so
    that their handlers never cut it (a temporary file created and not yet listed for its
    cleanup).  Their Python handlers are swapped for one that notes the signal: Python
    runs a signal's handler in the main thread whichever thread the kernel delivers the
    signal to, so blocking it in one thread (pthread_sigmask) does not hold it back.
    Outside the main thread, where no handler runs, the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    noted: list[int] = []
    previous = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        if callable(signal.getsignal(sig)):  # not SIG_DFL, SIG_IGN, or a C handler
            previous[sig] = signal.signal(sig, lambda signum, _frame: noted.append(signum))
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        for signum in noted:
            signal.raise_signal(signum)


@contextlib.contextmanager
def handled() -> Iterator[None]:
    """SIGTERM raises Terminated and SIGINT KeyboardInterrupt while the block runs, both
    remembered (main thread only; elsewhere Python's handlers stay)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _received.clear()
    previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, _on_sigterm)}
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not when ignored
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, _on_sigint)
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        _received.clear()  # a later command, or API use in this process, starts afresh
