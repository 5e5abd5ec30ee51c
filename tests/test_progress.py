"""Progress off a terminal: plain lines with the count, the time spent and an estimate of
what is left (harness.progress.PlainProgress), none for quick work; stress says what it
predicts and why it skips."""

from __future__ import annotations

import io

from harness.cli import main
from harness.progress import PLAIN_EVERY_S, PLAIN_FIRST_S, PlainProgress, duration


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def test_quick_work_prints_nothing():
    out, clock = io.StringIO(), Clock()
    with PlainProgress(4, "bench x", "setting", clock=clock, out=out) as bar:
        for _ in range(4):
            clock.t += PLAIN_FIRST_S / 5
            bar.update()
    assert out.getvalue() == ""


def test_lines_say_what_is_done_and_estimate_what_is_left():
    out, clock = io.StringIO(), Clock()
    with PlainProgress(10, "stress", clock=clock, out=out) as bar:
        bar.set_postfix_str("alpha-1e-3: mujoco")
        clock.t += 30.0  # 3 runs in 30 s: 10 s each, 7 left
        bar.update(3)
        clock.t += PLAIN_EVERY_S / 2  # not due yet
        bar.refresh()
        clock.t += PLAIN_EVERY_S  # a long run: still a line, naming it
        bar.refresh()
        bar.update(7)
    lines = out.getvalue().splitlines()
    assert lines[0] == (
        "stress: 3/10 runs, 30 s so far, about 1 min 10 s left; now alpha-1e-3: mujoco (for 30 s)"
    )
    # 52.5 s for 3 runs: 17.5 s each, 7 left
    assert lines[1] == (
        "stress: 3/10 runs, 52 s so far, about 2 min 2 s left; now alpha-1e-3: mujoco (for 52 s)"
    )
    assert lines[-1] == "stress: 10/10 runs in 52 s"
    assert len(lines) == 3


def test_durations_read_as_a_person_reads_them():
    texts = [duration(s) for s in (0.4, 59, 130, 3900)]
    assert texts == ["0 s", "59 s", "2 min 10 s", "1 h 05 min"]


def test_stress_says_why_it_skips(capsys):
    argv = ["stress", "--engine", "mujoco", "--case", "alpha-1e-12"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "stress: alpha-1e-12: mujoco skipped: dt (0.0001 s) must not exceed t_end" in err
    assert "--dt" not in err  # an option the user did not give


def test_a_long_fixed_step_run_off_a_terminal_gets_plain_lines():
    from harness.cli.common import StepProgress

    progress = StepProgress("mujoco")
    progress(10, 100)
    progress(30, 100)
    assert isinstance(progress.bar, PlainProgress) and progress.bar.n == 30
    progress.close()


def test_a_bar_with_a_long_text_keeps_its_width_and_stays_within_100_columns():
    import io
    import re

    from tqdm import tqdm

    from harness.progress import BAR_FORMAT

    out = io.StringIO()
    bar = tqdm(total=80, desc="stress", ncols=100, bar_format=BAR_FORMAT, file=out)
    bar.update(40)
    bar.set_postfix_str("alpha-1e-12: drake-continuous, predicted 4.4 s, hard cap 60 s " * 3)
    line = str(bar)
    bar.close()
    assert len(line) <= 100
    assert re.search(r"\|[#█]{10} {10}\|", line), line  # 20 characters, half full
