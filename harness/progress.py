"""Progress bars for long runs (tqdm on stderr), one way for every command.

Shown when stderr is a terminal: a bar in a file or a pipe is a stream of carriage
returns, and there -v/--verbose gives one progress line per run instead (a long
background run: `nohup harness fidelity ... -v 2> log`).  A caller may force a bar
(`show=True`, e.g. the sweep, which draws one in files too): it is redrawn at most every
0.5 s on a terminal and every 10 s otherwise.  While a bar is shown, our loggers' lines
go through `tqdm.write` so that they do not break it (`logging_redirect_tqdm`).
"""

from __future__ import annotations

import contextlib
import logging
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from tqdm import tqdm

# Our loggers (the CLI shows them at INFO with -v/--verbose: cli.common.configure_logging).
LOGGERS = ("harness", "engines", "reference")
REFRESH_TERMINAL_S = 0.5
REFRESH_FILE_S = 10.0


def bars_wanted() -> bool:
    """Whether to draw a bar by default: stderr is a terminal."""
    return sys.stderr.isatty()


@contextlib.contextmanager
def progress_bar(
    total: int, desc: str, unit: str = "run", show: bool | None = None, initial: int = 0
) -> Iterator[tqdm]:
    """A tqdm bar on stderr (module docstring); `show` None means `bars_wanted()`.  A
    hidden bar still counts, so callers update it unconditionally."""
    from tqdm import tqdm
    from tqdm.contrib.logging import logging_redirect_tqdm

    shown = bars_wanted() if show is None else show
    tqdm.monitor_interval = 0  # no monitor thread: some callers fork worker processes
    bar = tqdm(
        total=total,
        initial=initial,
        desc=desc,
        unit=unit,
        file=sys.stderr,
        disable=not shown,
        mininterval=REFRESH_TERMINAL_S if sys.stderr.isatty() else REFRESH_FILE_S,
        smoothing=0.05,
        dynamic_ncols=True,
    )
    loggers = [logging.getLogger(name) for name in LOGGERS]
    redirect = logging_redirect_tqdm(loggers=loggers) if shown else contextlib.nullcontext()
    with bar, redirect:
        yield bar


class _Lines:
    """A counter that prints one plain line to stderr at most every `every` seconds (and
    at the end): progress of a long run in a log file without carriage returns."""

    def __init__(self, total: int, desc: str, unit: str, every: float) -> None:
        import time

        self.total, self.desc, self.unit, self.every = total, desc, unit, every
        self.n = 0
        self._clock = time.perf_counter
        self.start = self.last = self._clock()

    def update(self, k: int = 1) -> None:
        self.n += k
        now = self._clock()
        if now - self.last >= self.every:
            self.last = now
            self._line(now)

    def _line(self, now: float) -> None:
        print(
            f"{self.desc}: {self.n}/{self.total} {self.unit}s, {now - self.start:.0f} s",
            file=sys.stderr,
            flush=True,
        )

    def close(self) -> None:
        if self.n:
            self._line(self._clock())


@contextlib.contextmanager
def progress_counter(total: int, desc: str, unit: str = "run") -> Iterator:
    """Progress of a long grid, always shown: a tqdm bar on a terminal, else a plain line
    every REFRESH_FILE_S seconds and one at the end (no carriage returns in a log).
    The object yielded has `update(k)`."""
    if bars_wanted():
        with progress_bar(total, desc, unit, show=True) as bar:
            yield bar
        return
    lines = _Lines(total, desc, unit, REFRESH_FILE_S)
    try:
        yield lines
    finally:
        lines.close()
