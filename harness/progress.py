"""Progress of long runs, one way for every command.

On a terminal: a tqdm bar on stderr, redrawn at most every 0.5 s.  Elsewhere (a log
file, CI, a notebook): plain lines (`PlainProgress`), the first once the work has taken
PLAIN_FIRST_S, then one every PLAIN_EVERY_S, each with the count done, the time spent,
an estimate of what is left (time per item so far × items left) and what is running now;
quick commands print none.  A caller may force a tqdm bar (`show=True`, e.g. the sweep,
which draws one in files too: redrawn every 10 s there) or hide it (`show=False`).
While a bar is shown, our loggers' lines go through `tqdm.write` so that they do not
break it (`logging_redirect_tqdm`); `bar.write(line)` prints a line that must be seen
(e.g. why a run is skipped) in every mode (pass file=sys.stderr: tqdm's default is
stdout).
"""

from __future__ import annotations

import contextlib
import logging
import sys
import time
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

from .text import WIDTH

if TYPE_CHECKING:
    from tqdm import tqdm

# Our loggers (the CLI shows them at INFO with -v/--verbose: cli.common.configure_logging).
LOGGERS = ("harness", "engines", "reference")
REFRESH_TERMINAL_S = 0.5
REFRESH_FILE_S = 10.0
PLAIN_FIRST_S = 5.0
PLAIN_EVERY_S = 15.0


def bars_wanted() -> bool:
    """Whether to draw a bar by default: stderr is a terminal."""
    return sys.stderr.isatty()


@contextlib.contextmanager
def progress_bar(
    total: int, desc: str, unit: str = "run", show: bool | None = None, initial: int = 0
) -> Iterator[tqdm | PlainProgress]:
    """A tqdm bar on stderr when `show` (None: when stderr is a terminal), else plain
    lines (module docstring).  Both count, so callers update unconditionally."""
    if show is None and not bars_wanted():
        plain = PlainProgress(total, desc, unit, initial=initial)
        with plain:
            yield plain
        return
    from tqdm import tqdm
    from tqdm.contrib.logging import logging_redirect_tqdm

    shown = bool(show) or show is None
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
        ncols=bar_columns(),
        bar_format=BAR_FORMAT,
    )
    loggers = [logging.getLogger(name) for name in LOGGERS]
    redirect = logging_redirect_tqdm(loggers=loggers) if shown else contextlib.nullcontext()
    with bar, redirect:
        yield bar


# a bar of fixed width, so that a long "now running" text cannot squeeze it: the line is
# cut at `bar_columns()` instead (tqdm trims a line to ncols)
BAR_FORMAT = (
    "{desc}: {percentage:3.0f}%|{bar:20}| {n_fmt}/{total_fmt} [{elapsed}<{remaining}]{postfix}"
)


def bar_columns() -> int:
    """The progress line's width: the terminal's, at most WIDTH (100) columns."""
    import shutil

    return min(shutil.get_terminal_size((WIDTH, 24)).columns, WIDTH)


class PlainProgress:
    """The part of tqdm's interface the commands use, as plain lines on stderr for
    output that is not a terminal (module docstring):

        stress: 14/80 runs, 2 min 10 s so far, about 10 min left; now alpha-1e-12: drake
        (predicted 4.4 s; running for 45 s)

    `clock` and `out` are for tests."""

    def __init__(
        self,
        total: int,
        desc: str,
        unit: str = "run",
        initial: int = 0,
        clock: Callable[[], float] = time.monotonic,
        out=None,
    ) -> None:
        self.total, self.desc, self.unit = total, desc, unit
        self.n = self.initial = initial
        self.clock = clock
        self.out = out
        self.start = self.now_since = clock()
        self.next_line = self.start + PLAIN_FIRST_S
        self.now = ""
        self.printed = False

    def __enter__(self) -> PlainProgress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def update(self, k: int = 1) -> None:
        self.n += k
        self.refresh(due_only=True)

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        if s != self.now:
            self.now, self.now_since = s, self.clock()
        self.refresh(due_only=True)

    def set_postfix(self, ordered_dict=None, refresh: bool = True, **kwargs) -> None:
        items = {**(ordered_dict or {}), **kwargs}
        self.set_postfix_str(", ".join(f"{k}={v}" for k, v in items.items()))

    def refresh(self, due_only: bool = True) -> None:
        """Print the progress line if one is due (every PLAIN_EVERY_S)."""
        t = self.clock()
        if due_only and t < self.next_line:
            return
        self.next_line = t + PLAIN_EVERY_S
        self.write(self.line(t))
        self.printed = True

    def line(self, t: float) -> str:
        done = self.n - self.initial
        spent = t - self.start
        text = f"{self.desc}: {self.n}/{self.total} {self.unit}s, {duration(spent)} so far"
        if 0 < done and self.n < self.total:
            text += f", about {duration(spent / done * (self.total - self.n))} left"
        if self.now and self.n < self.total:
            text += f"; now {self.now} (for {duration(t - self.now_since)})"
        return text

    def write(self, line: str, file=None) -> None:
        """tqdm.write's signature (callers pass file=sys.stderr: tqdm's default is stdout);
        a line longer than WIDTH is wrapped, its continuation indented."""
        import textwrap

        text = "\n".join(textwrap.wrap(line, WIDTH, subsequent_indent="  ")) or line
        print(text, file=self.out or file or sys.stderr, flush=True)

    def close(self) -> None:
        """A last line (done, total time) when any line was printed."""
        if self.printed:
            t = self.clock()
            self.write(
                f"{self.desc}: {self.n}/{self.total} {self.unit}s in {duration(t - self.start)}"
            )
            self.printed = False


def duration(seconds: float) -> str:
    """'45 s', '2 min 10 s', '1 h 05 min' (the precision a person reads in a log)."""
    s = max(0, round(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"
